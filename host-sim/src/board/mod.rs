//! `host-sim board`: a scene sent to a board running octrace's live
//! firmware over its serial port (octrace-link's protocol,
//! docs/board-protocol.md); the board's errors printed as host-sim prints
//! its own, its picture received, written and checked against host-sim's.
//!
//! Invariants: the conversation with the board (hello, the scene, its
//! whole answer) goes on while the board moves it on and ends when it
//! stops doing so (`patience`, times `--patience`), or at `--timeout` if
//! given, and what the
//! board says is checked as `link` says; the picture takes memory only as its rows
//! arrive, never for a size the board only claims; `--check` passes only
//! when every pixel of the panel was compared and each is host-sim's.

mod answer;
mod link;
mod patience;
mod port;

pub use answer::{Answer, BoardDescription, BoardSceneError, BoardTiming, PlayedFrame, Progress};
pub use link::{BoardLink, LinkError};
pub use patience::{Waits, LOADING, SILENCE};
pub use port::{Port, SerialLine};

use crate::arguments::{not_the_scene, output_format, parse_format};
use crate::exit::{CliError, ShownPath};
use crate::output::panel_preview;
use crate::terminal::{progress_bar, shown};
use crate::{all_cores, load_frame_bytes, new_scene, render_with_progress, LoadError, RenderOptions, RgbImage};
use embedded_graphics_core::pixelcolor::RgbColor;
use octrace_core::panel::Dithering;
use octrace_core::render::PanelColor;
use octrace_images::formats::{self, Format, Image};
use octrace_link::{Panel, PixelFormat, Reason, VERSION};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

// A panel the protocol allows is an image host-sim renders.
const _: () = assert!(Panel::MAX_SIDE as u32 == octrace_core::scene::MAX_SIDE);

/// The frames of an animation `host-sim board` follows (and checks) unless
/// told otherwise (`--frames`): the first, which traces every pixel, and
/// two that re-trace only what moved, the second of them from counts a
/// partly traced frame recorded; a few seconds on the emulated Pico.
pub(crate) const DEFAULT_FRAMES: u32 = 3;

/// `host-sim board [PORT] [SCENE] [OUT]`.
#[derive(clap::Args, Debug)]
pub struct BoardArgs {
    /// The board's serial port: a serial device (a character device, or a
    /// port the system lists, such as COM3), which a scene file never is.
    /// Without it, the serial ports are listed.
    pub port: Option<PathBuf>,
    /// The scene file to send. Without it, the board says what it is.
    pub scene: Option<PathBuf>,
    /// Where to write the board's picture, received row by row.
    pub out: Option<PathBuf>,
    /// Compare the board's picture with host-sim's own render of the scene
    /// at the panel's size and in its format (as `--size WxH --color
    /// rgb565`): says "bit-identical", or how many pixels differ (exit 3).
    #[arg(long)]
    pub check: bool,
    /// Seconds the whole conversation with the board may take at most: its
    /// hello, sending the scene, and its answer (every error, or every row
    /// of the drawing). Without it, a board is followed as long as it
    /// keeps drawing (rows, runs, or its word that it is still working),
    /// and given up when it says nothing for 8 s (120 s while it loads a
    /// scene).
    #[arg(long, value_name = "SECONDS", value_parser = clap::value_parser!(u64).range(1..=86_400))]
    pub timeout: Option<u64>,
    /// Wait N times as long for a board that says nothing (N times 8 s,
    /// and 120 s while it loads a scene): for a board far slower than a
    /// Pico, such as the emulated Pico on a busy machine.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1_000))]
    pub patience: u32,
    /// Of an animation (a scene with FRAMES), the frames to follow before
    /// stopping the board with a hello: OUT gets the last of them, and
    /// --check compares each with `host-sim SCENE --frame K` at the
    /// panel's size and in its format.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_FRAMES, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub frames: u32,
    /// OUT's file format; by default from its extension (png, tga, ras),
    /// or PNG when it has none.
    #[arg(long, value_parser = parse_format)]
    pub format: Option<Format>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Whether `arg` names a serial port: a character device, or a port the
/// system lists (COM3 on Windows).
pub(crate) fn is_port(arg: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if std::fs::metadata(arg).is_ok_and(|m| m.file_type().is_char_device()) {
            return true;
        }
    }
    ports().iter().any(|port| Path::new(&port.port_name) == arg)
}

/// The serial ports the system lists (none where it cannot list them).
fn ports() -> Vec<serialport::SerialPortInfo> {
    // serialport scans /sys/class/tty on Linux and panics where it is missing.
    if cfg!(target_os = "linux") && !Path::new("/sys/class/tty").is_dir() {
        return Vec::new();
    }
    serialport::available_ports().unwrap_or_default()
}

/// Each port on a line: its name, and what it is when the system knows.
pub(crate) fn write_ports(out: &mut dyn Write) -> io::Result<()> {
    let ports = ports();
    if ports.is_empty() {
        return writeln!(
            out,
            "no serial ports found (a board with octrace's live firmware shows up as a USB serial port)"
        );
    }
    for port in ports {
        let what = match port.port_type {
            serialport::SerialPortType::UsbPort(usb) => {
                let names = [usb.manufacturer, usb.product].into_iter().flatten().collect::<Vec<_>>().join(" ");
                let serial = usb.serial_number.map(|s| format!(" (serial {s})")).unwrap_or_default();
                format!("USB {:04x}:{:04x} {names}{serial}", usb.vid, usb.pid)
            }
            serialport::SerialPortType::PciPort => "PCI".into(),
            serialport::SerialPortType::BluetoothPort => "Bluetooth".into(),
            serialport::SerialPortType::Unknown => "serial".into(),
        };
        writeln!(out, "{}\t{what}", port.port_name)?;
    }
    Ok(())
}

/// Runs `host-sim board`.
pub fn run(args: &BoardArgs, stdout: &mut dyn Write, stderr: &mut dyn Write) -> Result<(), CliError> {
    let Some(first) = &args.port else {
        return write_ports(stdout).map_err(|e| CliError::Io(format!("board: {e}")));
    };
    if !is_port(first) {
        let _ = writeln!(stderr, "host-sim board: the serial ports:");
        let _ = write_ports(stderr);
        return Err(CliError::Invalid(format!(
            "board: {} is no serial port: give the board's port first (host-sim board PORT SCENE [OUT])",
            ShownPath(first)
        )));
    }
    let port = first.display().to_string();
    let out = args.out.as_ref();
    let waits = Waits { cap: args.timeout.map(Duration::from_secs), patience: args.patience };
    let Some(scene) = &args.scene else {
        let mut link = BoardLink::open(&port, waits).map_err(|e| link_error(&port, e))?;
        let board = link.hello().map_err(|e| link_error(&port, e))?;
        return describe(&port, &board, stdout).map_err(|e| CliError::Io(format!("board: {e}")));
    };
    if out.is_none() && args.format.is_some() {
        return Err(CliError::Invalid("board: --format names OUT's format: give OUT".into()));
    }
    // OUT's format, known before the board is asked.
    out.map(|out| output_format(args.format, out)).transpose()?;
    out.map(|out| not_the_scene(scene, out)).transpose()?;
    let text = crate::scene::read_scene_file(scene).map_err(|e| CliError::read(scene, e))?;
    // Before the board draws: a picture it sent could not be kept.
    out.map(|out| crate::output::check_writable(out).map_err(|e| CliError::write(out, e))).transpose()?;
    let file = ShownPath(scene).to_string();
    let pixels = out.is_some() || args.check;
    let started = Instant::now();
    let mut bar = None;
    let sent = send_scene(&port, waits, &file, &text, pixels, args.frames, &mut |step| match step {
        Progress::Drawing(panel) => bar = progress_bar(panel.height.into(), args.quiet),
        Progress::Playing { .. } => bar = progress_bar(args.frames.into(), args.quiet),
        Progress::Row { .. } | Progress::FrameDrawn(_) => {
            if let Some(bar) = &bar {
                bar.inc(1);
            }
        }
        Progress::Run { .. } | Progress::Working { .. } => {}
    });
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let (panel, timing, picture) = match sent? {
        Sent::Rejected(errors) => {
            let errors = errors.iter().map(|e| e.located(&file)).collect();
            return Err(CliError::Scene { file, errors });
        }
        Sent::Drawn { panel, timing, picture } => (panel, timing, picture),
        Sent::Played { panel, frames } => return played(args, &port, &file, &text, panel, frames, stderr),
    };
    let (w, h) = (panel.width, panel.height);
    if !args.quiet {
        let time = timing.describe(started.elapsed());
        let _ = writeln!(stderr, "{w}x{h} {} drawn by the board at {} {time}", panel.format, shown(&port));
    }
    let Some(image) = picture else {
        return match args.check {
            true => Err(CliError::Mismatch("board --check: the board sent no pixels to compare".into())),
            false => Ok(()),
        };
    };
    write_picture(args, &image, stderr)?;
    if args.check {
        let differ = differing_pixels(&file, &text, 0, panel, &image)?;
        if differ > 0 {
            return Err(CliError::Mismatch(format!(
                "board --check: {differ} of {} pixels differ from host-sim's {} render at {w}x{h}",
                w as usize * h as usize,
                panel.format
            )));
        }
        if !args.quiet {
            let _ = writeln!(stderr, "--check: bit-identical to host-sim's {} render at {w}x{h}", panel.format);
        }
    }
    Ok(())
}

/// Writes the board's picture to OUT, if asked.
fn write_picture(args: &BoardArgs, image: &RgbImage, stderr: &mut dyn Write) -> Result<(), CliError> {
    let Some(out) = &args.out else { return Ok(()) };
    let format = output_format(args.format, out)?;
    crate::output::write_atomically(out, |f| {
        formats::write(&Image::Rgb(image.clone()), format, f).map_err(io::Error::other)
    })
    .map_err(|e| CliError::write(out, e))?;
    if !args.quiet {
        let _ = writeln!(stderr, "the board's picture -> {}", ShownPath(out));
    }
    Ok(())
}

/// What `host-sim board` says of an animation the board played: each
/// frame followed, OUT the last, and with `--check` each compared with
/// `host-sim --frame K`'s.
fn played(
    args: &BoardArgs,
    port: &str,
    file: &str,
    text: &[u8],
    panel: Panel,
    frames: Vec<(PlayedFrame, Option<RgbImage>)>,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    let (w, h) = (panel.width, panel.height);
    for (frame, _) in frames.iter().filter(|_| !args.quiet) {
        let time = frame.elapsed.map_or("".into(), |t| format!(" in {:.3} s by its clock", t.as_secs_f64()));
        let traced = frame.traced;
        let _ = writeln!(
            stderr,
            "frame {} drawn by the board at {}{time}, {traced} pixels traced",
            frame.frame,
            shown(port)
        );
    }
    if let Some((_, Some(last))) = frames.last() {
        write_picture(args, last, stderr)?;
    }
    if !args.check {
        return Ok(());
    }
    for (frame, picture) in &frames {
        let Some(picture) = picture else {
            return Err(CliError::Mismatch("board --check: the board sent no pixels to compare".into()));
        };
        let differ = differing_pixels(file, text, frame.frame, panel, picture)?;
        if differ > 0 {
            return Err(CliError::Mismatch(format!(
                "board --check: frame {}: {differ} of {} pixels differ from host-sim's --frame {} {} render at {w}x{h}",
                frame.frame,
                w as usize * h as usize,
                frame.frame,
                panel.format
            )));
        }
    }
    if !args.quiet {
        let _ = writeln!(
            stderr,
            "--check: {} frames, each bit-identical to host-sim's --frame K {} render at {w}x{h}",
            frames.len(),
            panel.format
        );
    }
    Ok(())
}

/// A failure to talk to the board at `port`, as host-sim reports it.
fn link_error(port: &str, e: LinkError) -> CliError {
    let message = format!("board at {}: {e}", shown(port));
    match e {
        // The board's own answer to the scene: a scene error in all but name.
        LinkError::Refused(Reason::TooLong { .. }) => CliError::Invalid(message),
        _ => CliError::Io(message),
    }
}

/// What a board made of a scene sent to it.
#[derive(Debug)]
pub(crate) enum Sent {
    /// The scene's errors, as the board found them; nothing drawn.
    Rejected(Vec<BoardSceneError>),
    /// Drawn at the panel's size (`timing` as the board measured it), with
    /// the picture if its pixels were asked for.
    Drawn { panel: Panel, timing: BoardTiming, picture: Option<RgbImage> },
    /// An animation played at the panel's size: the frames followed, each
    /// with the panel's picture then if its pixels were asked for.
    Played { panel: Panel, frames: Vec<(PlayedFrame, Option<RgbImage>)> },
}

/// Sends scene `text` (named `file` in errors) to the board at `port`,
/// after its hello and a check of the scene's length against what it
/// takes, and follows the drawing (an animation for `follow` frames),
/// handing each step to `progress`, waiting for the board as `waits` says.
/// `host-sim board` and the studio send through this.
pub(crate) fn send_scene(
    port: &str,
    waits: Waits,
    file: &str,
    text: &[u8],
    pixels: bool,
    follow: u32,
    progress: &mut dyn FnMut(Progress<'_>),
) -> Result<Sent, CliError> {
    let mut link = BoardLink::open(port, waits).map_err(|e| link_error(port, e))?;
    let board = link.hello().map_err(|e| link_error(port, e))?;
    if text.len() > board.max_scene as usize {
        return Err(CliError::Invalid(format!(
            "{file} is {} bytes; the board at {} takes scenes of at most {} bytes",
            text.len(),
            shown(port),
            board.max_scene
        )));
    }
    // The picture's rows in RGB, each kept as it comes: memory follows
    // what the board sent, not the size it claims.
    let mut rows: Vec<Vec<u8>> = Vec::new();
    // An animation's pictures, one at each frame followed.
    let mut pictures = Vec::new();
    let picture = |rows: &[Vec<u8>], panel: Panel| RgbImage {
        width: panel.width.into(),
        height: panel.height.into(),
        data: rows.concat(),
    };
    let answer = link.draw(text, pixels, follow, &mut |step| {
        match &step {
            Progress::Drawing(panel) | Progress::Playing { panel, .. } if pixels => {
                rows = vec![Vec::new(); panel.height.into()]
            }
            Progress::Drawing(_) | Progress::Playing { .. } => {}
            Progress::Row { y, pixels: row } => {
                if let Some(rgb) = rows.get_mut(usize::from(*y)) {
                    *rgb = board.panel.format.colors(row).flat_map(|c| [c.r(), c.g(), c.b()]).collect();
                }
            }
            Progress::Run { y, x, pixels: run } => {
                // A row is set aside when a run of it comes.
                if let Some(rgb) = rows.get_mut(usize::from(*y)) {
                    rgb.resize(3 * usize::from(board.panel.width), 0);
                    let colors = board.panel.format.colors(run).flat_map(|c| [c.r(), c.g(), c.b()]);
                    rgb.iter_mut().skip(3 * usize::from(*x)).zip(colors).for_each(|(byte, c)| *byte = c);
                }
            }
            Progress::FrameDrawn(frame) => pictures.push((*frame, pixels.then(|| picture(&rows, board.panel)))),
            Progress::Working { .. } => {}
        }
        progress(step);
    });
    Ok(match answer.map_err(|e| link_error(port, e))? {
        Answer::Rejected(errors) => Sent::Rejected(errors),
        Answer::Drawn { panel, timing } => {
            Sent::Drawn { panel, timing, picture: pixels.then(|| picture(&rows, panel)) }
        }
        Answer::Played { panel, .. } => Sent::Played { panel, frames: pictures },
    })
}

/// How many pixels of the board's `picture` differ from host-sim's render
/// of the scene's frame `frame` (0 for a still) at the panel's size, as
/// the panel shows it (`host-sim SCENE OUT --size WxH --color rgb565
/// --frame K`). `host-sim board --check` and the studio judge the board's
/// picture by this. A picture that is not the panel's size, or has no
/// pixel, is no picture to judge: an error.
pub(crate) fn differing_pixels(
    file: &str,
    text: &[u8],
    frame: u32,
    panel: Panel,
    picture: &RgbImage,
) -> Result<usize, CliError> {
    let pixels = usize::from(panel.width) * usize::from(panel.height);
    let size = (u32::from(panel.width), u32::from(panel.height));
    if pixels == 0 || (picture.width, picture.height) != size || picture.data.len() != 3 * pixels {
        return Err(CliError::Mismatch(format!(
            "board --check: no pixel to compare: a {}x{} picture ({} bytes) of a {}x{} panel",
            picture.width,
            picture.height,
            picture.data.len(),
            panel.width,
            panel.height
        )));
    }
    let ours = host_render(file, text, frame, panel)?;
    Ok(ours.data.chunks_exact(3).zip(picture.data.chunks_exact(3)).filter(|(a, b)| a != b).count())
}

/// host-sim's render of the scene's frame `frame` at the panel's size, as
/// the panel shows it.
fn host_render(file: &str, text: &[u8], frame: u32, panel: Panel) -> Result<RgbImage, CliError> {
    let mismatch = |why: String| CliError::Mismatch(format!("board --check: {why}"));
    let mut scene = new_scene();
    load_frame_bytes(file, text, frame, &mut scene).map_err(|e| match e {
        LoadError::Io(e) => mismatch(format!("host-sim cannot read the scene: {e}")),
        LoadError::Scene(errors) => {
            mismatch(format!("the board drew a scene host-sim refuses:\n{}", errors.join("\n")))
        }
    })?;
    let options = RenderOptions {
        size: Some((panel.width.into(), panel.height.into())),
        threads: all_cores(),
        ..RenderOptions::default()
    };
    let rendered = render_with_progress(&mut scene, &options, &|_| {})
        .map_err(|e| mismatch(format!("host-sim cannot set up the camera: {e}")))?;
    let color = match panel.format {
        PixelFormat::Rgb565 => PanelColor::Rgb565,
    };
    Ok(match panel_preview(&rendered.image, color, Dithering::default()) {
        Some(preview) => preview.to_rgb(),
        None => rendered.image,
    })
}

/// What `host-sim board PORT` prints.
fn describe(port: &str, board: &BoardDescription, out: &mut dyn Write) -> io::Result<()> {
    let Panel { width, height, format } = board.panel;
    writeln!(out, "{}: {} (protocol version {VERSION})", shown(port), board.firmware)?;
    writeln!(out, "panel: {width}x{height} {format}; scenes of at most {} bytes", board.max_scene)?;
    let capacities: Vec<String> = board.capacities.iter().map(|(name, count)| format!("{name} {count}")).collect();
    writeln!(out, "profile {}: {}", board.profile, capacities.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_check_that_compares_no_pixel_fails() {
        let scene = b"SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\n";
        let panel = |width, height| Panel { width, height, format: PixelFormat::Rgb565 };
        let picture = |width, height| RgbImage { width, height, data: vec![0; 3 * (width * height) as usize] };
        for (board, got) in [(panel(0, 0), picture(0, 0)), (panel(4, 2), picture(2, 4)), (panel(4, 2), picture(4, 1))] {
            let said = differing_pixels("s.txt", scene, 0, board, &got).unwrap_err();
            assert!(
                matches!(&said, CliError::Mismatch(m) if m.starts_with("board --check: no pixel to compare")),
                "{said}"
            );
        }
        assert!(differing_pixels("s.txt", scene, 0, panel(4, 2), &picture(4, 2)).is_ok());
    }
}
