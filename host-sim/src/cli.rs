//! The `host-sim` command line.

use crate::animation::{animate, check_frames, AnimationOptions, FramePattern, Request};
use crate::arguments::{not_the_scene, parse_size};
use crate::arguments::{output_format, parse_accel, parse_color, parse_dithering, parse_format, parse_palette};
use crate::exit::ShownPath;
use crate::options::{all_cores, Partition, RenderOptions};
use crate::output::{panel_preview, write_atomically, FileSink};
use crate::parts::{self, PartInfo, PartSpec};
use crate::render::{render_streamed, Streamed};
use crate::rows::{Canvas, StreamError};
use crate::scene::{load_frame_bytes, new_scene, HostScene, LoadError};
use crate::terminal::{progress_bar, Threads};
use crate::{convert, merge};
use clap::Parser;
use octrace_core::accel::OctreeConfig;
use octrace_core::panel::{Dithering, Panel};
use octrace_core::parse::Pos;
use octrace_core::render::PanelColor;
use octrace_core::AccelMode;
use octrace_images::formats::{self, Format, FormatError, Header, Image};
use octrace_images::palette::PaletteMode;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use crate::exit::{CliError, EXIT_IO, EXIT_MISMATCH, EXIT_SCENE, EXIT_STOPPED};

/// Render an octrace scene file to an image (PNG, Targa or Sun raster), in
/// truecolour or with a 256-entry colour table, or a scene that moves to an
/// animation (GIF, APNG, or a file a frame).
///
/// Exit codes: 0 success, 1 a file could not be read or written (or a
/// board could not be talked to), 2 the scene or the arguments are invalid
/// (every error is printed as file:line:col), 3 a board's picture differs
/// from host-sim's (`board --check`), 130 stopped by Ctrl-C (143 by
/// SIGTERM, 129 by SIGHUP). Nothing is written unless the whole image
/// renders: the image goes to a temporary file that is renamed into place
/// at the end. Ctrl-C, SIGTERM and SIGHUP stop a render before its next ray,
/// even inside a pixel that takes hours, and leave no file.
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
    /// The scene file (the octrace scene format: docs/scene-format.md).
    #[arg(required = true)]
    pub scene: Option<PathBuf>,
    /// Where to write the image; defaults to the scene's IMAGEFILE (relative
    /// to the current directory).
    pub out: Option<PathBuf>,
    /// Map the image onto a 256-entry colour table (written as an indexed
    /// image): scan (the thesis's hash-scan table), dither (6×6×6 cube,
    /// ordered), coarse (dither with outlines around objects), gray; none
    /// (the default) keeps truecolour. An animated GIF without it gets
    /// colours chosen for the whole loop (docs/animation.md).
    #[arg(long, value_name = "MODE", value_parser = parse_palette)]
    pub palette: Option<PaletteMode>,
    /// Preview a panel: the pixels as a display of this format shows them
    /// (the firmware's OCTRACE_COLOR): rgb888; rgb565 (written back as
    /// RGB); mono, gray2 and gray4, one bit, 4 and 16 grays, dithered (an
    /// 8-bit gray PNG of the levels' grays); bwr, black/white/red e-paper,
    /// dithered (an indexed image); dither (as --palette dither).
    #[arg(long, value_name = "COLOR", default_value = "rgb888", value_parser = parse_color)]
    pub color: PanelColor,
    /// How mono, gray2, gray4 and bwr are dithered: fs-pe (the default,
    /// Floyd–Steinberg with pure-error feedback), fs (Floyd–Steinberg),
    /// bayer (ordered, 4×4), nearest (none: each pixel's nearest level).
    #[arg(long, value_name = "METHOD", value_parser = parse_dithering)]
    pub dither: Option<Dithering>,
    /// The file format; by default from OUT's extension (png, tga, ras), or
    /// PNG when OUT has none. Any other extension is refused without it,
    /// and one that names another format is refused with it.
    #[arg(long, value_parser = parse_format)]
    pub format: Option<Format>,
    /// Render at WxH pixels instead of the scene's RASTER (for a quick
    /// preview; a default VIEWPORT follows the new aspect ratio).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Intersection strategy: naive (every object for every ray), octree
    /// (the octree walked the thesis's way), dda (the octree walked by
    /// integer 3DDDA), or auto, the fastest for the scene (naive for a
    /// handful of objects, else dda). All give the same image.
    #[arg(long, value_name = "MODE", default_value_t = AccelMode::default(), value_parser = parse_accel)]
    pub accel: AccelMode,
    /// Octree criterion: a box holding more objects than this is subdivided
    /// (refused where no octree is built).
    #[arg(long, value_name = "N", help = format!(
        "Octree criterion: a box holding more objects than this is subdivided (refused where no octree is built: \
         --accel naive, or auto on 16 objects or fewer) [default: {}]",
        crate::options::OCTREE.max_objects
    ))]
    pub max_objects: Option<usize>,
    /// Octree criterion: boxes are not subdivided below this depth (at most
    /// 18; refused where no octree is built).
    #[arg(long, value_name = "D", value_parser = clap::value_parser!(u32).range(0..=18), help = format!(
        "Octree criterion: boxes are not subdivided below this depth (at most 18; refused where no octree is \
         built) [default: {}]",
        crate::options::OCTREE.max_depth
    ))]
    pub max_depth: Option<u32>,
    /// Threads to render on, 1 to 1024 (default: every core). Any number
    /// gives the same image.
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
    /// For a scene with FRAMES: render frame K alone, from scratch, as a
    /// still image. Without it an animation is written whole: an animated
    /// GIF (OUT.gif), an APNG (OUT.png) or one file a frame (a name with
    /// %d or %04d).
    #[arg(long, value_name = "K")]
    pub frame: Option<u32>,
    /// Render every frame of an animation whole, instead of re-tracing only
    /// the pixels the motion can change (the same images; for benchmarks
    /// and checks).
    #[arg(long)]
    pub no_coherence: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Other things host-sim does.
#[derive(clap::Subcommand, Debug)]
pub enum Command {
    /// Convert an image between PNG, Targa and Sun raster, its pixels kept:
    /// truecolour stays truecolour, a colour-mapped or 8-bit gray image is
    /// written colour-mapped. Reads PNGs of 8-bit RGB, 8-bit gray or
    /// indexed colour, with alpha where every pixel is opaque (a
    /// transparent pixel is refused: no format here holds it).
    Convert {
        /// The image to read (the format is told from its content).
        input: PathBuf,
        /// The image to write.
        output: PathBuf,
        /// The output format; by default from OUTPUT's extension (png, tga,
        /// ras), or PNG when OUTPUT has none; it may not contradict the
        /// extension.
        #[arg(long, value_parser = parse_format)]
        format: Option<Format>,
    },
    /// Stack the parts rendered with `--part I/N` into the whole image,
    /// bit-identical to rendering it at once; or assemble an animation's
    /// frame files (rendered to `OUT 'f%04d.png'`, given as `f*.png`) into
    /// its GIF (OUTPUT.gif) or APNG (OUTPUT.png). Refuses (exit 2, nothing written) parts or frames of
    /// other scenes, sizes or palettes, parts that leave rows out or hold a
    /// row twice, and frames missing or given twice.
    Merge {
        /// The image or animation to write.
        output: PathBuf,
        /// The part or frame files, in any order.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// The output format of parts merged; by default from OUTPUT's
        /// extension, else PNG (frames: OUTPUT's extension, .gif or .png).
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

/// Whether `color` is previewed from the finished image (not streamed).
fn previewed(color: PanelColor) -> bool {
    !matches!(color, PanelColor::Rgb888 | PanelColor::Dither)
}

/// Writes a panel preview: a gray panel's as an 8-bit gray PNG (each
/// level's gray) where the format is PNG, else as its colour table.
fn write_preview(preview: &Image, color: PanelColor, format: Format, out: &mut dyn Write) -> Result<(), FormatError> {
    let gray = matches!(color.panel(), Some(Panel::Mono | Panel::Gray2 | Panel::Gray4));
    match format {
        Format::Png if gray => formats::write_gray_png(preview, out),
        _ => formats::write(preview, format, out),
    }
}

/// Runs the command line `args` (including the program name); help goes to
/// `stdout`, diagnostics to `stderr`. Returns the process exit code. The
/// binary is this call, so tests drive exactly what a user runs.
pub fn run<I, T>(args: I, stdout: &mut dyn Write, stderr: &mut dyn Write) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let args = match Args::try_parse_from(args) {
        Ok(a) => a,
        Err(e) if e.use_stderr() => {
            let _ = write!(stderr, "{}", argument_error(&e));
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

/// clap's message for arguments it refuses, but for a third positional
/// argument: clap, which lets subcommands stand where the scene does, takes
/// it for a subcommand "that cannot be used with <SCENE>", where the user
/// gave one file too many.
fn argument_error(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    use clap::CommandFactory;
    let extra = match (e.kind(), e.get(ContextKind::InvalidSubcommand)) {
        (ErrorKind::ArgumentConflict, Some(ContextValue::String(name))) => name,
        _ => return e.render().to_string(),
    };
    if Args::command().get_subcommands().any(|command| command.get_name() == extra) {
        return e.render().to_string();
    }
    format!(
        "error: unexpected argument '{extra}': host-sim takes a scene file and at most one image file\n\n\
         Usage: host-sim [OPTIONS] <SCENE> [OUT]\n\nFor more information, try '--help'.\n"
    )
}

/// The rows to render and the text to carry for `--part`, checked against the image and the options.
fn part_of(
    spec: PartSpec,
    palette_mode: PaletteMode,
    color: PanelColor,
    scene_bytes: &[u8],
    (w, h): (u32, u32),
    format: Format,
    frame: Option<u32>,
) -> Result<(std::ops::Range<u32>, String), CliError> {
    let refuse = |message: String| Err(CliError::Invalid(format!("--part: {message}")));
    if format == Format::Ras {
        return refuse("parts are PNG or Targa files (a Sun raster has no room for the part's metadata)".into());
    }
    if previewed(color) {
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
        let rows = if h == 1 { "row" } else { "rows" };
        return refuse(format!("{} parts of an image {h} {rows} high: at most {h}", spec.count));
    }
    let index = match spec.index {
        Some(i) => i,
        None => match parts::auto_index(spec.count, |name| std::env::var(name).ok()) {
            Ok(i) => i,
            Err(e) => return refuse(e.to_string()),
        },
    };
    let rows = parts::band_rows(h, index, spec.count);
    let render = parts::Render {
        version: env!("CARGO_PKG_VERSION").into(),
        scene: parts::scene_hash(scene_bytes),
        width: w,
        height: h,
        palette: palette_mode,
    };
    let info = PartInfo { render, rows: rows.clone(), index, count: spec.count, frame };
    Ok((rows, info.to_string()))
}

/// `--color rgb565|mono|gray2|gray4|bwr [--dither METHOD]`: a panel's
/// preview, converted or dithered from the whole image (panels are small;
/// every other image streams).
fn preview(
    scene: &mut HostScene,
    options: &RenderOptions,
    args: &Args,
    format: Format,
    out: &Path,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    let (color, dithering) = (args.color, args.dither.unwrap_or_default());
    let started = Instant::now();
    let (w, h) = options.size.unwrap_or((scene.view().settings.raster[0], scene.view().settings.raster[1]));
    let mut canvas = Canvas::new(w, h);
    let rendered = match render_streamed(scene, options, 0..h, &|_| {}, &mut canvas) {
        Ok(rendered) => rendered,
        Err(StreamError::Stopped) => return Err(CliError::stopped()),
        // The parser rejects a camera that cannot be set up; a scene built
        // by hand may not.
        Err(e) => return Err(CliError::Invalid(format!("cannot set up the camera: {e}"))),
    };
    let image = canvas.image;
    let preview = panel_preview(&image, color, dithering).unwrap_or_else(|| Image::Rgb(image.clone()));
    write_atomically(out, |f| write_preview(&preview, color, format, f).map_err(std::io::Error::other))
        .map_err(|e| CliError::write(out, e))?;
    if !args.quiet {
        let (image, stats) = (&image, rendered.stats);
        let _ = writeln!(
            stderr,
            "{}x{} in {:.3} s ({}, {}): {} rays, {} shadow rays, {} cells -> {} ({} panel{})",
            image.width,
            image.height,
            started.elapsed().as_secs_f64(),
            rendered.accel.name(),
            Threads(options.threads),
            stats.rays,
            stats.shadow_rays,
            stats.cells,
            ShownPath(out),
            color.name(),
            match color.panel() {
                Some(_) => format!(", {}", dithering.name()),
                None => String::new(),
            }
        );
    }
    Ok(())
}

fn execute(args: &Args, stderr: &mut dyn Write) -> Result<(), CliError> {
    match &args.command {
        Some(Command::Convert { input, output, format }) => return convert::run(input, output, *format, stderr),
        Some(Command::Merge { output, parts, format }) => return merge::run(output, parts, *format, stderr),
        // run() serves the studio and talks to boards (both need stdout)
        // instead of calling this.
        Some(Command::Studio(_) | Command::Board(_)) => return Ok(()),
        None => {}
    }
    let Some(scene_path) = &args.scene else {
        return Err(CliError::Invalid("no scene file given".into()));
    };
    let mut scene = new_scene();
    let scene_bytes = crate::scene::read_scene_file(scene_path).map_err(|e| CliError::read(scene_path, e))?;
    let frame = args.frame.unwrap_or(0);
    let name = ShownPath(scene_path).to_string();
    let loaded = load_frame_bytes(&name, &scene_bytes, frame, &mut scene).map_err(|e| match e {
        LoadError::Io(e) => CliError::read(scene_path, e),
        LoadError::Scene(errors) => CliError::Scene { file: name.clone(), errors },
    })?;
    match (loaded.frames, args.frame) {
        (None, Some(_)) => {
            return Err(CliError::Invalid(format!("--frame: {name} is no animation (it has no FRAMES)")))
        }
        // Said rather than ignored: a still, or a frame alone, is always
        // traced whole.
        (Some(_), Some(k)) if args.no_coherence => {
            return Err(CliError::Invalid(format!(
                "--no-coherence: --frame {k} traces that frame alone, whole; --no-coherence is for a whole loop"
            )))
        }
        (None, None) if args.no_coherence => {
            return Err(CliError::Invalid(format!(
                "--no-coherence: {name} is no animation (it has no FRAMES); a still is traced whole"
            )))
        }
        (Some(frames), Some(k)) if k >= frames.count => {
            return Err(CliError::Invalid(format!(
                "--frame {k}: {name} has {} frame{}, 0 to {}",
                frames.count,
                if frames.count == 1 { "" } else { "s" },
                frames.count - 1
            )))
        }
        _ => {}
    }
    // What is wrong with the file the scene's IMAGEFILE names is an error
    // at that statement.
    let imagefile_error = |pos: Pos, message: String| CliError::Scene {
        file: name.clone(),
        errors: vec![format!("{name}:{}:{}: IMAGEFILE {message}", pos.line, pos.column)],
    };
    let still = loaded.frames.is_none() || args.frame.is_some();
    if let (Some(_), None, true) = (args.part, &args.out, still) {
        // Every band would take the IMAGEFILE's name, each over the one
        // before.
        return Err(CliError::Invalid(
            "--part writes one band of the image: give each part an OUT of its own (part-1.png, part-2.png, …), \
             then `host-sim merge OUT part-*.png`"
                .into(),
        ));
    }
    let out = match (&args.out, &loaded.imagefile) {
        (Some(o), _) => o.clone(),
        // Longer than a path can be (Linux's PATH_MAX): refused without
        // printing it.
        (None, Some((f, pos))) if f.len() >= 4096 => {
            let message =
                format!("names a path of {} bytes, longer than a path can be: give OUT on the command line", f.len());
            return Err(imagefile_error(*pos, message));
        }
        (None, Some((f, pos))) if f.is_empty() => return Err(imagefile_error(*pos, "names no file".into())),
        (None, Some((f, _))) => PathBuf::from(f),
        (None, None) => {
            return Err(CliError::Invalid(format!(
                "no output file: give OUT on the command line or IMAGEFILE in {name}"
            )))
        }
    };
    if let (Some(k), Some(_), Ok(_)) = (args.frame, loaded.frames, FramePattern::parse(&out.to_string_lossy())) {
        return Err(CliError::Invalid(format!(
            "--frame {k} writes one still image, and {} is a pattern for one file a frame: name the frame's \
             file, or leave --frame out to write every frame",
            ShownPath(&out)
        )));
    }
    let palette = args.palette.unwrap_or(PaletteMode::None);
    if args.color != PanelColor::Rgb888 && palette != PaletteMode::None {
        return Err(CliError::Invalid("--color and --palette both choose the pixels: give one".into()));
    }
    if args.dither.is_some() && args.color.panel().is_none() {
        let panels: Vec<&str> = PanelColor::ALL.iter().filter(|c| c.panel().is_some()).map(|c| c.name()).collect();
        return Err(CliError::Invalid(format!(
            "--dither chooses how a panel of few levels is dithered: give it with --color {}",
            panels.join("|")
        )));
    }
    not_the_scene(scene_path, &out)?;
    let objects = scene.view().objects.len();
    if args.accel.resolve(objects) == AccelMode::Naive && (args.max_objects.is_some() || args.max_depth.is_some()) {
        let option = if args.max_objects.is_some() { "--max-objects" } else { "--max-depth" };
        let why = match args.accel {
            AccelMode::Auto => format!(
                "--accel auto tests {name}'s {objects} objects without one (up to {})",
                AccelMode::AUTO_NAIVE_UP_TO
            ),
            _ => "--accel naive builds none".into(),
        };
        return Err(CliError::Invalid(format!("{option} shapes the octree, and {why}: give --accel octree or dda")));
    }
    let options = |(w, h)| RenderOptions {
        size: Some((w, h)),
        accel: args.accel,
        octree: OctreeConfig {
            max_objects: args.max_objects.unwrap_or(crate::OCTREE.max_objects),
            max_depth: args.max_depth.unwrap_or(crate::OCTREE.max_depth),
            ..crate::OCTREE
        },
        threads: args.threads.map_or_else(all_cores, |n| n as usize),
        partition: args.partition,
        // Ctrl-C, SIGTERM or SIGHUP stops a render before its next ray, a
        // still's or an animation's frame's, and the run leaves no file.
        stop: Some(crate::signals::stop_flag()),
    };
    let raster = scene.view().settings.raster;
    let (w, h) = args.size.unwrap_or((raster[0], raster[1]));
    if let (Some(frames), None) = (loaded.frames, args.frame) {
        // `--color dither` is `--palette dither`, for a loop as for a still.
        let palette = match args.color {
            PanelColor::Rgb888 => args.palette,
            PanelColor::Dither => Some(PaletteMode::Dither),
            _ => return Err(CliError::Invalid("--color previews one panel: give --frame K".into())),
        };
        let request = Request {
            scene_path,
            bytes: &scene_bytes,
            frames,
            out: &out,
            palette,
            format: args.format,
            part: args.part,
            size: (w, h),
            options: AnimationOptions { render: options((w, h)), coherence: !args.no_coherence },
            quiet: args.quiet,
        };
        return animate(&request, stderr);
    }
    let format = output_format(args.format, &out).map_err(|e| match (&args.out, &loaded.imagefile, args.frame, e) {
        // An animation's IMAGEFILE names its GIF or APNG: it is the frame
        // asked for that wants another file.
        (None, Some(_), Some(k), CliError::Invalid(message)) => {
            CliError::Invalid(format!("{message}; --frame {k} writes one still image: give OUT on the command line"))
        }
        (None, Some((_, pos)), None, CliError::Invalid(message)) => imagefile_error(*pos, message),
        (_, _, _, e) => e,
    })?;
    let palette_mode = if args.color == PanelColor::Dither { PaletteMode::Dither } else { palette };
    let (rows, text) = match args.part {
        Some(spec) => {
            let (rows, text) = part_of(spec, palette_mode, args.color, &scene_bytes, (w, h), format, args.frame)?;
            (rows, Some(text))
        }
        None => (0..h, None),
    };
    if args.frame.is_some() {
        // A scene is valid or not whichever frame is asked for: a camera
        // lost at another frame refuses this one as it refuses the loop.
        check_frames(scene_path, &scene_bytes, &out)?;
    }
    let started = Instant::now();
    let options = options((w, h));
    if previewed(args.color) {
        return preview(&mut scene, &options, args, format, &out, stderr);
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
        match render_streamed(&mut scene, &options, render_rows, &progress, &mut sink) {
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
        (Some(Err(StreamError::Stopped)), _) => return Err(CliError::stopped()),
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
            "{w}x{h}{} in {:.3} s ({}, {}, tracing {:.3} s{}{}): {} rays, {} shadow rays, {} cells{} -> {}",
            match args.part {
                Some(_) => format!(" rows {}..{}", rows.start, rows.end),
                None => String::new(),
            },
            elapsed.as_secs_f64(),
            rendered.accel.name(),
            Threads(options.threads),
            rendered.tracing().as_secs_f64(),
            if options.threads == 1 { "" } else { " summed over the threads" },
            // Shown from a millisecond: what a scene of many objects spends
            // before its first pixel.
            match rendered.indexing() {
                indexing if indexing < Duration::from_millis(1) => String::new(),
                indexing => format!(", {:.3} s of it indexing the scene", indexing.as_secs_f64()),
            },
            stats.rays,
            stats.shadow_rays,
            stats.cells,
            if stats.truncated > 0 {
                format!(" ({} ray-tree branches cut at the per-sample limits)", stats.truncated)
            } else {
                String::new()
            },
            ShownPath(&out)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RgbImage;

    /// Every 8-bit gray a gray4 panel can show, written out apart from
    /// embedded-graphics: luma by ITU-R BT.601 in 8 bits, rounded to 16
    /// levels, widened as level × 17.
    fn gray4_by_hand(r: u32, g: u32, b: u32) -> u8 {
        let luma = (r * 77 + g * 150 + b * 29 + 128) / 256;
        ((luma * 15 + 127) / 255 * 17) as u8
    }

    fn one_pixel_preview(rgb: [u8; 3], color: PanelColor) -> Option<Image> {
        panel_preview(&RgbImage { width: 1, height: 1, data: rgb.to_vec() }, color, Dithering::Nearest)
    }

    #[test]
    fn gray4_preview_is_the_panels_level_times_17() {
        for rgb in [[0, 0, 0], [255, 255, 255], [255, 0, 0], [0, 255, 0], [0, 0, 255], [8, 9, 10], [200, 17, 90]] {
            let expected = gray4_by_hand(rgb[0].into(), rgb[1].into(), rgb[2].into());
            let preview = one_pixel_preview(rgb, PanelColor::Gray4).expect("gray4 is previewed");
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
    fn a_dithered_preview_is_the_core_ditherers_levels() {
        // A 16×4 ramp: each level the core gives, written as its gray (one
        // bit as 0 and 255).
        let data: Vec<u8> = (0..64u32).flat_map(|i| [(i * 4) as u8; 3]).collect();
        let image = RgbImage { width: 16, height: 4, data };
        for color in [PanelColor::Mono, PanelColor::Gray2, PanelColor::Gray4] {
            let panel = color.panel().unwrap();
            let mut rows = vec![0; 16];
            let mut ditherer =
                octrace_core::panel::Ditherer::new(panel, Dithering::FsPe, Default::default(), 16, &mut rows).unwrap();
            let expected: Vec<u8> = image
                .data
                .chunks(3)
                .map(|p| panel.color(ditherer.next(embedded_graphics_core::pixelcolor::Rgb888::new(p[0], p[1], p[2]))))
                .map(|c| embedded_graphics_core::pixelcolor::RgbColor::r(&c))
                .collect();
            let preview = panel_preview(&image, color, Dithering::FsPe).unwrap();
            let mut png = Vec::new();
            write_preview(&preview, color, Format::Png, &mut png).unwrap();
            let mut decoder = png::Decoder::new(std::io::Cursor::new(&png)).read_info().unwrap();
            assert_eq!(decoder.info().color_type, png::ColorType::Grayscale, "{color}");
            let mut gray = vec![0; decoder.output_buffer_size().unwrap()];
            decoder.next_frame(&mut gray).unwrap();
            assert_eq!(gray, expected, "{color}");
        }
    }

    /// What host-sim prints when it refuses fig5_1 at 4×4 with `options`
    /// (exit 2, nothing written).
    fn refusal(options: &[&str]) -> String {
        let dir = std::env::temp_dir().join(format!("host-sim-cli-{}-{}", std::process::id(), options.join("")));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("x.png");
        let mut stderr = Vec::new();
        let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/fig5_1.txt");
        let args =
            ["host-sim", scene, out.to_str().unwrap(), "--size", "4x4"].into_iter().chain(options.iter().copied());
        assert_eq!(run(args, &mut Vec::new(), &mut stderr), EXIT_SCENE);
        assert!(!out.exists());
        let _ = std::fs::remove_dir_all(dir);
        String::from_utf8_lossy(&stderr).into_owned()
    }

    #[test]
    fn dither_without_a_panel_is_refused() {
        let said = refusal(&["--color", "rgb565", "--dither", "bayer"]);
        assert!(said.contains("--color mono|gray2|gray4|bwr"), "{said}");
    }

    #[test]
    fn a_third_file_is_named_as_one_too_many() {
        let said = |args: &[&str]| {
            let mut stderr = Vec::new();
            let code = run(["host-sim"].iter().chain(args), &mut Vec::new(), &mut stderr);
            (code, String::from_utf8_lossy(&stderr).into_owned())
        };
        let (code, message) = said(&["a.txt", "b.png", "c.png"]);
        assert_eq!(code, EXIT_SCENE);
        assert!(message.starts_with("error: unexpected argument 'c.png': host-sim takes a scene file"), "{message}");
        // A subcommand after a scene is clap's own conflict.
        let (code, message) = said(&["a.txt", "b.png", "merge"]);
        assert_eq!(code, EXIT_SCENE);
        assert!(message.contains("the subcommand 'merge' cannot be used with"), "{message}");
    }

    #[test]
    fn color_and_palette_together_are_refused() {
        assert!(refusal(&["--color", "gray4", "--palette", "dither"]).contains("give one"));
    }
}
