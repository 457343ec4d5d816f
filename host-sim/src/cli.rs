//! The `host-sim` command line.

use crate::output::{write_atomically, FileSink};
use crate::parts::{self, MergeError, PartInfo, PartSpec};
use crate::{all_cores, load_bytes, new_scene, render_streamed, AccelMode, LoadError, Partition, RenderOptions};
use crate::{Canvas, HostScene, RgbImage, StreamError, Streamed};
use clap::Parser;
use indicatif::{ProgressBar, ProgressStyle};
use octrace_core::accel::OctreeConfig;
use octrace_core::render::PanelColor;
use octrace_core::scene::MAX_SIDE;
use octrace_images::formats::{self, Format, FormatError, Header, Image};
use octrace_images::palette::PaletteMode;
use octrace_images::panel;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;
use std::time::Instant;

pub use crate::exit::{CliError, EXIT_IO, EXIT_MISMATCH, EXIT_SCENE, EXIT_STOPPED};

/// Render an octrace scene file to an image (PNG, Targa or Sun raster), in
/// truecolour or with a 256-entry colour table.
///
/// Exit codes: 0 success, 1 a file could not be read or written (or a
/// board could not be talked to), 2 the scene or the arguments are invalid
/// (every error is printed as file:line:col), 3 a board's picture differs
/// from host-sim's (`board --check`), 130 stopped by Ctrl-C.
/// Nothing is written unless the whole image renders: the image goes to a
/// temporary file that is renamed into place at the end. Ctrl-C stops a
/// render before its next ray, even inside a pixel that takes hours, and
/// leaves no file.
#[derive(Parser, Debug)]
#[command(
    name = "host-sim",
    version,
    about,
    long_about,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Args {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The scene file (octrace scene format, see the README).
    #[arg(required = true)]
    pub scene: Option<PathBuf>,
    /// Where to write the image; defaults to the scene's IMAGEFILE (relative
    /// to the current directory).
    pub out: Option<PathBuf>,
    /// Map the image onto a 256-entry colour table (written as an indexed
    /// image): scan (the thesis's hash-scan table), dither (6×6×6 cube,
    /// ordered), coarse (dither with outlines around objects), gray.
    #[arg(long, value_name = "MODE", default_value = "none", value_parser = parse_palette)]
    pub palette: PaletteMode,
    /// Preview a panel: the pixels as a display of this format shows them
    /// (the firmware's OCTRACE_COLOR): rgb888; rgb565 (written back as
    /// RGB); gray4, 16 levels (an 8-bit gray PNG, level × 17); dither (as
    /// --palette dither).
    #[arg(long, value_name = "COLOR", default_value = "rgb888", value_parser = parse_color)]
    pub color: PanelColor,
    /// The file format; by default from OUT's extension (png, tga, ras), or
    /// PNG when OUT has none. Any other extension is refused without it.
    #[arg(long, value_parser = parse_format)]
    pub format: Option<Format>,
    /// Render at WxH pixels instead of the scene's RASTER (for a quick
    /// preview; a default VIEWPORT follows the new aspect ratio).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Intersection strategy: auto picks the fastest for the scene (naive
    /// for a handful of objects, else dda). All give the same image.
    #[arg(long, value_name = "MODE", default_value = "auto", value_parser = parse_accel)]
    pub accel: AccelMode,
    /// Octree criterion: a box holding more objects than this is subdivided.
    #[arg(long, value_name = "N", default_value_t = crate::OCTREE.max_objects)]
    pub max_objects: usize,
    /// Octree criterion: boxes are not subdivided below this depth (at most 18).
    #[arg(long, value_name = "D", default_value_t = crate::OCTREE.max_depth,
          value_parser = clap::value_parser!(u32).range(0..=18))]
    pub max_depth: u32,
    /// Threads to render on (default: every core). Any number gives the
    /// same image.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// How the image is cut between threads: small tiles handed out as
    /// threads become free, or the thesis's four equal rectangles.
    #[arg(long, value_enum, default_value_t = Partition::Tiles)]
    pub partition: Partition,
    /// Render only part I of N horizontal bands of the image (1-based), as an
    /// image of its own that `host-sim merge` puts together with the others;
    /// `auto/N` takes I from SLURM_ARRAY_TASK_ID (counted from
    /// SLURM_ARRAY_TASK_MIN) or JOB_COMPLETION_INDEX (counted from 0). Parts
    /// are PNG or Targa files: they carry the scene's hash, the image's size,
    /// the palette and their rows.
    #[arg(long, value_name = "I/N")]
    pub part: Option<PartSpec>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Other things host-sim does.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Convert an image between PNG, Targa and Sun raster (truecolour or
    /// colour-mapped, kept as it is).
    Convert {
        /// The image to read (the format is told from its content).
        input: PathBuf,
        /// The image to write.
        output: PathBuf,
        /// The output format; by default from OUTPUT's extension (png, tga,
        /// ras), or PNG when OUTPUT has none.
        #[arg(long, value_parser = parse_format)]
        format: Option<Format>,
    },
    /// Stack the parts rendered with `--part I/N` into the whole image,
    /// bit-identical to rendering it at once. Refuses (exit 2, nothing
    /// written) parts of other scenes, sizes or palettes, and parts that
    /// leave rows out or hold a row twice.
    Merge {
        /// The image to write.
        output: PathBuf,
        /// The part files, in any order.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// The output format; by default from OUTPUT's extension, else PNG.
        #[arg(long, value_parser = parse_format)]
        format: Option<Format>,
    },
    /// The scene studio: edit, place and render a scene in the browser,
    /// on this core compiled to WebAssembly (serves 127.0.0.1 only); with
    /// --board, send it to a board and see its errors or its picture.
    Studio(crate::studio::StudioArgs),
    /// Send a scene to a board running octrace's live firmware over its
    /// serial port: the board's errors are printed as file:line:col (exit
    /// 2); with OUT, its picture is received and written, and --check
    /// compares it with host-sim's own. Without PORT, lists the serial
    /// ports; with PORT alone, the board says what it is.
    Board(crate::board::BoardArgs),
}

/// What a `color` panel shows of `image` ([`octrace_images::panel`]), or
/// `None` for the colours that need no conversion.
pub(crate) fn panel_preview(image: &RgbImage, color: PanelColor) -> Option<Image> {
    match color {
        PanelColor::Rgb888 | PanelColor::Dither => None,
        PanelColor::Rgb565 => Some(Image::Rgb(panel::rgb565(image))),
        PanelColor::Gray4 => Some(panel::gray4(image)),
    }
}

/// Writes a panel preview: gray4 as an 8-bit gray PNG (level × 17) where
/// the format is PNG, else as a 16-entry gray colour table.
fn write_preview(preview: &Image, color: PanelColor, format: Format, out: &mut dyn Write) -> Result<(), FormatError> {
    match (color, format) {
        (PanelColor::Gray4, Format::Png) => formats::write_gray_png(preview, out),
        _ => formats::write(preview, format, out),
    }
}

/// An `--accel` name: the core's [`AccelMode`] vocabulary.
fn parse_accel(text: &str) -> Result<AccelMode, String> {
    parse_name(text, &AccelMode::ALL, AccelMode::name)
}

/// A `--color` name: the core's [`PanelColor`] vocabulary.
fn parse_color(text: &str) -> Result<PanelColor, String> {
    parse_name(text, &PanelColor::ALL, PanelColor::name)
}

/// A `--palette` name: [`PaletteMode`]'s vocabulary.
fn parse_palette(text: &str) -> Result<PaletteMode, String> {
    parse_name(text, &PaletteMode::ALL, PaletteMode::name)
}

/// A `--format` name: [`Format`]'s vocabulary.
pub(crate) fn parse_format(text: &str) -> Result<Format, String> {
    parse_name(text, &Format::ALL, Format::name)
}

/// The one of `all` that `text` names (case-insensitive).
fn parse_name<T: Copy>(text: &str, all: &[T], name: fn(T) -> &'static str) -> Result<T, String> {
    all.iter().copied().find(|&v| name(v).eq_ignore_ascii_case(text)).ok_or_else(|| {
        let names: Vec<&str> = all.iter().map(|&v| name(v)).collect();
        format!("expected one of {}", names.join(", "))
    })
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WxH (for example 160x128), found `{s}`"))?;
    let dim = |v: &str| -> Result<u32, String> {
        let n: u32 = v.parse().map_err(|_| format!("`{v}` is not a whole number"))?;
        if (1..=MAX_SIDE).contains(&n) {
            Ok(n)
        } else {
            Err(format!("{n} is outside 1 to {MAX_SIDE}"))
        }
    };
    Ok((dim(w)?, dim(h)?))
}

pub fn run<I, T>(args: I, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let args = match Args::try_parse_from(args) {
        Ok(a) => a,
        Err(e) if e.use_stderr() => {
            let _ = write!(stderr, "{}", e.render());
            return EXIT_SCENE;
        }
        Err(e) => {
            // --help and --version.
            let _ = write!(stdout, "{}", e.render());
            return 0;
        }
    };
    let result = match &args.command {
        Some(Command::Studio(studio)) => crate::studio::run(studio, stdout, stderr),
        Some(Command::Board(board)) => crate::board::run(board, stdout, stderr),
        _ => execute(&args, stderr),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            let _ = writeln!(stderr, "{e}");
            e.exit_code()
        }
    }
}

/// The format to write `path` in: the one asked for, else the one its
/// extension names, else (no extension) PNG. Any other extension is refused
/// before anything is rendered: a PNG named `.bmp` would mislead whatever
/// opens it.
pub(crate) fn output_format(asked: Option<Format>, path: &Path) -> Result<Format, CliError> {
    if let Some(format) = asked {
        return Ok(format);
    }
    let Some(extension) = path.extension() else {
        return Ok(Format::Png);
    };
    Format::from_path(path).ok_or_else(|| {
        let names: Vec<&str> = Format::ALL.iter().map(|f| f.name()).collect();
        CliError::Invalid(format!(
            "cannot write {}: `.{}` is not a format host-sim writes; it writes {} \
             (chosen by the extension, or by --format <{}>)",
            path.display(),
            extension.to_string_lossy(),
            names.join(", "),
            names.join("|"),
        ))
    })
}

fn convert(input: &Path, output: &Path, format: Option<Format>) -> Result<(), CliError> {
    let format = output_format(format, output)?;
    let bytes = std::fs::read(input).map_err(|e| CliError::read(input, e))?;
    let image = formats::read(&bytes).map_err(|e| CliError::Invalid(format!("{}: {e}", input.display())))?;
    write_atomically(output, |f| formats::write(&image, format, f).map_err(std::io::Error::other))
        .map_err(|e| CliError::write(output, e))
}

fn merge(output: &Path, parts: &[PathBuf], format: Option<Format>) -> Result<(), CliError> {
    let format = output_format(format, output)?;
    let (ordered, header) = parts::check_parts(parts).map_err(|e| {
        let message = format!("merge: {e}; nothing written");
        match e {
            MergeError::Io { .. } => CliError::Io(message),
            MergeError::Refused(_) => CliError::Invalid(message),
        }
    })?;
    write_atomically(output, |f| parts::write_merged(&ordered, &header, format, f).map_err(std::io::Error::other))
        .map_err(|e| CliError::Io(format!("merge: cannot write {}: {e}", output.display())))
}

/// The rows to render and the text to carry for `--part`, checked against the image and the options.
fn part_of(
    spec: PartSpec,
    palette_mode: PaletteMode,
    color: PanelColor,
    scene_bytes: &[u8],
    (w, h): (u32, u32),
    format: Format,
) -> Result<(std::ops::Range<u32>, String), CliError> {
    let refuse = |message: String| Err(CliError::Invalid(format!("--part: {message}")));
    if format == Format::Ras {
        return refuse("parts are PNG or Targa files (a Sun raster has no room for the part's metadata)".into());
    }
    if matches!(color, PanelColor::Rgb565 | PanelColor::Gray4) {
        return refuse("a --color preview is written whole: render it without --part".into());
    }
    if palette_mode == PaletteMode::Scan {
        return refuse(
            "--palette scan learns its colour table from the whole image, so a band cannot be mapped on its \
             own; use dither, coarse or gray, or none"
                .into(),
        );
    }
    if spec.count > h {
        return refuse(format!("{} parts of an image {h} rows high: at most {h}", spec.count));
    }
    let index = match spec.index {
        Some(i) => i,
        None => match parts::auto_index(spec.count, |name| std::env::var(name).ok()) {
            Ok(i) => i,
            Err(e) => return refuse(e.to_string()),
        },
    };
    let rows = parts::band_rows(h, index, spec.count);
    let info = PartInfo {
        version: env!("CARGO_PKG_VERSION").into(),
        scene: parts::scene_hash(scene_bytes),
        width: w,
        height: h,
        palette: palette_mode,
        rows: rows.clone(),
        index,
        count: spec.count,
    };
    Ok((rows, info.to_string()))
}

/// `--color rgb565|gray4`: a panel's preview, converted from the whole
/// image (panels are small; every other image streams).
fn preview(
    scene: &HostScene,
    options: &RenderOptions,
    color: PanelColor,
    format: Format,
    out: &Path,
    quiet: bool,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    let started = Instant::now();
    let (w, h) = options.size.unwrap_or((scene.view().settings.raster[0], scene.view().settings.raster[1]));
    let mut canvas = Canvas::new(w, h);
    let rendered = match render_streamed(scene, options, 0..h, &|_| {}, &mut canvas) {
        Ok(rendered) => rendered,
        Err(StreamError::Stopped) => return Err(CliError::Stopped),
        // The parser rejects a camera that cannot be set up; a scene built
        // by hand may not.
        Err(e) => return Err(CliError::Invalid(e.to_string())),
    };
    let image = canvas.image;
    let preview = panel_preview(&image, color).unwrap_or_else(|| Image::Rgb(image.clone()));
    write_atomically(out, |f| write_preview(&preview, color, format, f).map_err(std::io::Error::other))
        .map_err(|e| CliError::write(out, e))?;
    if !quiet {
        let (image, stats) = (&image, rendered.stats);
        let _ = writeln!(
            stderr,
            "{}x{} in {:.3} s ({}, {} threads): {} rays, {} shadow rays, {} cells -> {} ({} panel)",
            image.width,
            image.height,
            started.elapsed().as_secs_f64(),
            rendered.accel.name(),
            options.threads,
            stats.rays,
            stats.shadow_rays,
            stats.cells,
            out.display(),
            color.name()
        );
    }
    Ok(())
}

fn execute(args: &Args, stderr: &mut dyn Write) -> Result<(), CliError> {
    match &args.command {
        Some(Command::Convert { input, output, format }) => return convert(input, output, *format),
        Some(Command::Merge { output, parts, format }) => return merge(output, parts, *format),
        // run() serves the studio and talks to boards (both need stdout)
        // instead of calling this.
        Some(Command::Studio(_) | Command::Board(_)) => return Ok(()),
        None => {}
    }
    let Some(scene_path) = &args.scene else {
        return Err(CliError::Invalid("no scene file given".into()));
    };
    let mut scene = new_scene();
    let scene_bytes = std::fs::read(scene_path).map_err(|e| CliError::read(scene_path, e))?;
    let loaded = load_bytes(&scene_path.display().to_string(), &scene_bytes, &mut scene).map_err(|e| match e {
        LoadError::Io(e) => CliError::read(scene_path, e),
        LoadError::Scene(errors) => CliError::Scene { file: scene_path.display().to_string(), errors },
    })?;
    let out = match (&args.out, &loaded.imagefile) {
        (Some(o), _) => o.clone(),
        (None, Some(f)) => PathBuf::from(f),
        (None, None) => {
            return Err(CliError::Invalid(format!(
                "no output file: give OUT on the command line or IMAGEFILE in {}",
                scene_path.display()
            )))
        }
    };
    if args.color != PanelColor::Rgb888 && args.palette != PaletteMode::None {
        return Err(CliError::Invalid("--color and --palette both choose the pixels: give one".into()));
    }
    if same_file(scene_path, &out) {
        return Err(CliError::Invalid(format!(
            "refusing to overwrite the scene file {} with the image",
            out.display()
        )));
    }
    let format = output_format(args.format, &out)?;
    let view = scene.view();
    let (w, h) = args.size.unwrap_or((view.settings.raster[0], view.settings.raster[1]));
    let palette_mode = if args.color == PanelColor::Dither { PaletteMode::Dither } else { args.palette };
    let (rows, text) = match args.part {
        Some(spec) => {
            let (rows, text) = part_of(spec, palette_mode, args.color, &scene_bytes, (w, h), format)?;
            (rows, Some(text))
        }
        None => (0..h, None),
    };
    let started = Instant::now();
    let options = RenderOptions {
        size: Some((w, h)),
        accel: args.accel,
        octree: OctreeConfig { max_objects: args.max_objects, max_depth: args.max_depth, ..crate::OCTREE },
        threads: args.threads.map_or_else(all_cores, |n| n as usize),
        partition: args.partition,
        light_buffer: crate::LIGHT_BUFFER,
        stop: Some(ctrl_c()),
    };
    if matches!(args.color, PanelColor::Rgb565 | PanelColor::Gray4) {
        return preview(&scene, &options, args.color, format, &out, args.quiet, stderr);
    }
    // `coarse` outlines need the objects of the row above a part.
    let render_rows = match palette_mode {
        PaletteMode::Coarse => rows.start.saturating_sub(1)..rows.end,
        _ => rows.clone(),
    };
    let bar = progress_bar(w as u64 * render_rows.len() as u64, args.quiet);
    let header = Header { width: w, height: rows.len() as u32, palette: None, text };
    let spool_dir = out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let spool_name = out.file_name().map_or_else(|| "image".into(), |n| n.to_string_lossy().into_owned());
    let mut outcome: Option<Result<Streamed, StreamError>> = None;
    let mut summary = None;
    let written = write_atomically(&out, |f| {
        let io = |e: FormatError| match e {
            FormatError::Io(e) => e,
            e => std::io::Error::other(e),
        };
        let mut sink =
            FileSink::new(palette_mode, format, header, rows.start, f, spool_dir, &spool_name).map_err(io)?;
        let progress = |pixels| {
            if let Some(b) = &bar {
                b.inc(pixels);
            }
        };
        match render_streamed(&scene, &options, render_rows, &progress, &mut sink) {
            Ok(streamed) => outcome = Some(Ok(streamed)),
            Err(StreamError::Sink(e)) => return Err(e),
            Err(e) => {
                outcome = Some(Err(e));
                return Err(std::io::Error::other("no image"));
            }
        }
        summary = sink.finish().map_err(io)?;
        Ok(())
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let rendered = match (outcome, written) {
        (Some(Err(StreamError::Stopped)), _) => return Err(CliError::Stopped),
        // The parser rejects a camera that cannot be set up; a scene built
        // by hand may not.
        (Some(Err(e)), _) => return Err(CliError::Invalid(e.to_string())),
        (_, Err(e)) => return Err(CliError::write(&out, e)),
        (Some(Ok(rendered)), Ok(())) => rendered,
        (None, Ok(())) => return Err(CliError::write(&out, "the render stopped before its first row")),
    };
    let elapsed = started.elapsed();
    let stats = rendered.stats;
    if !args.quiet {
        if let Some((report, _)) = &rendered.build {
            if let Some(kind) = report.exhausted {
                let _ = writeln!(
                    stderr,
                    "host-sim: the octree ran out of {}: {} boxes left unsplit (slower, same image)",
                    kind.what(),
                    report.unsplit
                );
            }
        }
        let _ = writeln!(
            stderr,
            "{w}x{h}{} in {:.3} s ({}, {} thread{}, tracing {:.3} s): {} rays, {} shadow rays, {} cells{} -> {}",
            match args.part {
                Some(_) => format!(" rows {}..{}", rows.start, rows.end),
                None => String::new(),
            },
            elapsed.as_secs_f64(),
            rendered.accel.name(),
            options.threads,
            if options.threads == 1 { "" } else { "s" },
            rendered.tracing().as_secs_f64(),
            stats.rays,
            stats.shadow_rays,
            stats.cells,
            if stats.truncated > 0 {
                format!(" ({} ray-tree branches cut at the per-sample limits)", stats.truncated)
            } else {
                String::new()
            },
            out.display()
        );
        if let Some(summary) = summary {
            let _ = writeln!(
                stderr,
                "{} palette: {} colours of 256, {:.1} dB against truecolour ({})",
                palette_mode.name(),
                summary.colors_used,
                summary.psnr,
                format.name()
            );
        }
    }
    Ok(())
}

/// Set by Ctrl-C, once this process has its handler ([`ctrl_c`]).
static CTRL_C: AtomicBool = AtomicBool::new(false);

/// The flag Ctrl-C sets, its handler installed on the first call: a render
/// that asks it stops before its next ray and writes nothing. A process
/// that has a handler already (the studio's, in a test that ran it) keeps
/// it, and Ctrl-C ends it as before.
fn ctrl_c() -> &'static AtomicBool {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        let _ = ctrlc::set_handler(|| CTRL_C.store(true, Ordering::SeqCst));
    });
    &CTRL_C
}

/// A progress bar of `total` steps on stderr, if it is a terminal and
/// the run is not `quiet`.
pub(crate) fn progress_bar(total: u64, quiet: bool) -> Option<ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent}%, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    Some(bar)
}

/// Whether two paths name the same existing file.
pub(crate) fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("160x128"), Ok((160, 128)));
        assert_eq!(parse_size("8X8"), Ok((8, 8)));
        assert!(parse_size("0x5").is_err());
        assert!(parse_size("12").is_err());
        assert!(parse_size("20000x5").is_err());
    }

    /// Every 8-bit gray a gray4 panel can show, written out apart from
    /// embedded-graphics: luma by ITU-R BT.601 in 8 bits, rounded to 16
    /// levels, widened as level × 17.
    fn gray4_by_hand(r: u32, g: u32, b: u32) -> u8 {
        let luma = (r * 77 + g * 150 + b * 29 + 128) / 256;
        ((luma * 15 + 127) / 255 * 17) as u8
    }

    fn one_pixel_preview(rgb: [u8; 3], color: PanelColor) -> Option<Image> {
        panel_preview(&RgbImage { width: 1, height: 1, data: rgb.to_vec() }, color)
    }

    #[test]
    fn gray4_preview_is_the_panels_level_times_17() {
        for rgb in [[0, 0, 0], [255, 255, 255], [255, 0, 0], [0, 255, 0], [0, 0, 255], [8, 9, 10], [200, 17, 90]] {
            let expected = gray4_by_hand(rgb[0].into(), rgb[1].into(), rgb[2].into());
            let preview = one_pixel_preview(rgb, PanelColor::Gray4).expect("gray4 is converted");
            assert_eq!(preview.to_rgb().data, [expected; 3], "{rgb:?}");
            let mut png = Vec::new();
            write_preview(&preview, PanelColor::Gray4, Format::Png, &mut png).unwrap();
            let decoder = png::Decoder::new(std::io::Cursor::new(&png)).read_info().unwrap();
            assert_eq!(decoder.info().color_type, png::ColorType::Grayscale, "gray4 as PNG is an 8-bit gray image");
            let mut tga = Vec::new();
            write_preview(&preview, PanelColor::Gray4, Format::Tga, &mut tga).unwrap();
            assert!(matches!(formats::read(&tga).unwrap(), Image::Indexed { .. }), "gray4 as Targa is colour-mapped");
        }
    }

    #[test]
    fn rgb565_preview_rounds_each_channel_to_its_width() {
        // 5 bits: 8 -> 1 -> 8; 6 bits: 130 -> 32 -> 130; 5 bits: 255 stays.
        let shown = |rgb| one_pixel_preview(rgb, PanelColor::Rgb565).expect("rgb565 is converted").to_rgb().data;
        assert_eq!(shown([8, 130, 255]), [8, 130, 255]);
        assert_eq!(shown([5, 3, 4]), [8, 4, 0]);
        assert!(one_pixel_preview([1, 2, 3], PanelColor::Rgb888).is_none());
    }

    #[test]
    fn color_and_palette_together_are_refused() {
        let dir = tempfile_dir();
        let out = dir.join("x.png");
        let mut stderr = Vec::new();
        let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/fig5_1.txt");
        let args =
            ["host-sim", scene, out.to_str().unwrap(), "--color", "gray4", "--palette", "dither", "--size", "4x4"];
        assert_eq!(run(args, &mut Vec::new(), &mut stderr), EXIT_SCENE);
        assert!(String::from_utf8_lossy(&stderr).contains("give one"));
        assert!(!out.exists());
        let _ = std::fs::remove_dir_all(dir);
    }

    fn tempfile_dir() -> PathBuf {
        let dir = std::env::temp_dir().join(format!("host-sim-cli-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }
}
