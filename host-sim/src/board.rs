//! `host-sim board`: a scene sent to a board running octrace's live
//! firmware over its serial port (octrace-link's protocol,
//! docs/board-protocol.md); the board's errors printed as host-sim prints
//! its own, its picture received, written and checked against host-sim's.
//!
//! Invariants: every wait for the board ends within the timeout; a frame
//! answering another request (an earlier run's, another host's) is skipped
//! by its tag; every row of a picture arrives exactly once, in the panel's
//! format and width, before the board says it is done, or the run fails.

use crate::cli::{output_format, panel_preview, parse_format, progress_bar, same_file};
use crate::exit::CliError;
use crate::{all_cores, load_bytes, new_scene, render_with_progress, LoadError, RenderOptions, RgbImage};
use embedded_graphics_core::pixelcolor::RgbColor;
use octrace_core::render::PanelColor;
use octrace_images::formats::{self, Format, Image};
use octrace_link::{Decoder, Message, Panel, PixelFormat, Reason, Timing, VERSION};
use serialport::SerialPort as _;
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

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
    /// Seconds to wait for each answer of the board (a row of a slow scene
    /// included).
    #[arg(long, value_name = "SECONDS", default_value_t = 30, value_parser = clap::value_parser!(u64).range(1..=86_400))]
    pub timeout: u64,
    /// OUT's file format; by default from its extension (png, tga, ras),
    /// or PNG when it has none.
    #[arg(long, value_parser = parse_format)]
    pub format: Option<Format>,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
}

/// A serial line to a board: bytes both ways, reads that give up after a
/// short while (so that the timeout can be kept).
pub trait Port: Read + Write {
    /// Drops what the board sent before this run.
    fn discard_input(&mut self) -> io::Result<()>;
}

/// A board's serial port, opened for this run alone.
pub struct SerialLine(Device);

#[cfg(unix)]
type Device = serialport::TTYPort;
#[cfg(not(unix))]
type Device = Box<dyn serialport::SerialPort>;

impl SerialLine {
    /// Opens `path` exclusively: no other program can open it meanwhile.
    pub fn open(path: &str) -> io::Result<SerialLine> {
        // The rate means nothing to a USB serial class or a pseudo-terminal.
        let builder = serialport::new(path, 115_200).timeout(Duration::from_millis(50));
        #[cfg(unix)]
        let device = serialport::TTYPort::open(&builder)?;
        #[cfg(not(unix))]
        let device = builder.open()?;
        Ok(SerialLine(device))
    }
}

/// A pseudo-terminal (an emulated board's) stays exclusive after its last
/// close while its other end is open, which would refuse the next run of
/// anyone but root: the mode is given up explicitly.
#[cfg(unix)]
impl Drop for SerialLine {
    fn drop(&mut self) {
        let _ = self.0.set_exclusive(false);
    }
}

impl Read for SerialLine {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.0.read(buf)
    }
}

impl Write for SerialLine {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.0.flush()
    }
}

impl Port for SerialLine {
    fn discard_input(&mut self) -> io::Result<()> {
        self.0.clear(serialport::ClearBuffer::Input).map_err(io::Error::from)
    }
}

/// Why talking to a board failed.
#[derive(Debug)]
pub enum LinkError {
    /// The port could not be opened, read or written.
    Io(io::Error),
    /// Nothing answered within the timeout.
    Silent(Duration),
    /// The board speaks another protocol version.
    Version {
        /// The board's.
        board: u8,
    },
    /// The board refused a frame of ours.
    Refused(Reason),
    /// The board sent what the protocol does not allow there.
    Protocol(String),
    /// The board stopped drawing after `rows` rows: another frame reached it.
    Cancelled {
        /// Rows drawn.
        rows: u16,
    },
}

impl std::fmt::Display for LinkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinkError::Io(e) => write!(f, "{e}"),
            LinkError::Silent(waited) => write!(
                f,
                "no answer within {} s (is octrace's live firmware running there? --timeout waits longer)",
                waited.as_secs_f64()
            ),
            LinkError::Version { board } => write!(
                f,
                "the board speaks protocol version {board} and this host-sim version {VERSION}: \
                 use a host-sim and a firmware of the same release"
            ),
            LinkError::Refused(reason) => write!(f, "the board refused what host-sim sent: {reason}"),
            LinkError::Protocol(what) => write!(f, "the board broke the protocol: {what}"),
            LinkError::Cancelled { rows } => write!(
                f,
                "the board stopped drawing after {rows} rows: another frame reached it (is another program using the port?)"
            ),
        }
    }
}

impl std::error::Error for LinkError {}

impl From<io::Error> for LinkError {
    fn from(e: io::Error) -> LinkError {
        LinkError::Io(e)
    }
}

/// What a board says it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoardDescription {
    pub panel: Panel,
    /// The longest scene text it takes, in bytes.
    pub max_scene: u32,
    /// Its capacity profile's name.
    pub profile: String,
    pub firmware: String,
    /// Its profile's capacities by `profile!` field name.
    pub capacities: Vec<(String, u32)>,
}

/// One error of a scene, as the board reported it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoardSceneError {
    /// From 1; 0 for an error of the whole scene.
    pub line: u32,
    pub column: u32,
    /// For an error of capacity: its `profile!` field name, how many the
    /// scene needs (when the board knows) and how many the board holds.
    pub capacity: Option<(String, Option<u32>, u32)>,
    /// The message, as octrace-core writes it.
    pub message: String,
}

impl BoardSceneError {
    /// `file:line:col: message`, as host-sim prints its own errors.
    pub fn located(&self, file: &str) -> String {
        match self.line {
            0 => format!("{file}: {}", self.message),
            line => format!("{file}:{line}:{}: {}", self.column, self.message),
        }
    }
}

/// What a board measured of a scene it drew (the protocol's `done`): its
/// times by its own clock, and what its hardware counted over the load and
/// the render.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BoardTiming {
    /// From the scene received to its last row drawn.
    pub elapsed: Option<Duration>,
    /// Parsing and indexing the scene.
    pub load: Option<Duration>,
    /// Drawing it.
    pub render: Option<Duration>,
    /// Each counter: its name, its count over the load and over the render.
    pub counters: Vec<(String, u32, u32)>,
}

impl BoardTiming {
    fn of(timing: &Timing<'_>) -> BoardTiming {
        BoardTiming {
            elapsed: timing.elapsed,
            load: timing.load,
            render: timing.render,
            counters: timing.counters.iter().map(|c| (c.name.to_owned(), c.load, c.render)).collect(),
        }
    }

    /// "in 1.850 s by its clock (load 0.011 s, render 1.839 s; sram0_contested 12 + 3456, …)",
    /// or the host's time when the board has no clock.
    pub fn describe(&self, here: Duration) -> String {
        let seconds = |t: Duration| format!("{:.3} s", t.as_secs_f64());
        let mut text = match self.elapsed {
            Some(t) => format!("in {} by its clock", seconds(t)),
            None => format!("in {} here", seconds(here)),
        };
        let mut parts = Vec::new();
        if let (Some(load), Some(render)) = (self.load, self.render) {
            parts.push(format!("load {}, render {}", seconds(load), seconds(render)));
        }
        if !self.counters.is_empty() {
            let counters: Vec<_> =
                self.counters.iter().map(|(name, load, render)| format!("{name} {load} + {render}")).collect();
            parts.push(counters.join(", "));
        }
        if !parts.is_empty() {
            text.push_str(&format!(" ({})", parts.join("; ")));
        }
        text
    }
}

/// How the board answered a scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Answer {
    /// It drew the scene at its panel's size, and measured it so.
    Drawn { panel: Panel, timing: BoardTiming },
    /// The scene has errors (all of them, in the order found); nothing drawn.
    Rejected(Vec<BoardSceneError>),
}

/// What happens while a board draws.
#[derive(Debug)]
pub enum Progress<'a> {
    /// The scene loaded; its rows follow.
    Drawing(Panel),
    /// Row `y` is drawn: its pixels in the panel's format, if asked for.
    Row { y: u16, pixels: &'a [u8] },
}

/// The longest frame host-sim takes from a board: a row of the widest
/// panel the protocol describes (65,535 pixels of 2 bytes) and more.
const MAX_FRAME: usize = 1 << 18;

/// A conversation with one board.
pub struct BoardLink<P: Port> {
    port: P,
    decoder: Decoder<Vec<u8>>,
    /// Bytes read from the port, and how many of them the decoder has had.
    input: Vec<u8>,
    taken: usize,
    timeout: Duration,
    last_tag: u16,
    /// Whether the board has answered a request of this link: from then on
    /// every frame it sends is in answer to this link's requests.
    in_step: bool,
}

impl BoardLink<SerialLine> {
    /// Opens the serial port `path`.
    pub fn open(path: &str, timeout: Duration) -> Result<Self, LinkError> {
        let line = SerialLine::open(path)
            .map_err(|e| io::Error::new(e.kind(), format!("cannot open it as a serial port: {e}")))?;
        Ok(BoardLink::new(line, timeout))
    }
}

impl<P: Port> BoardLink<P> {
    /// A link over `port`, waiting at most `timeout` for each answer.
    pub fn new(port: P, timeout: Duration) -> Self {
        // Tags of this run unlike an earlier run's, whose answers may still
        // be on the way.
        let clock = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
        let last_tag = (clock.subsec_nanos() ^ std::process::id()) as u16;
        BoardLink {
            port,
            decoder: Decoder::new(vec![0; MAX_FRAME]),
            input: Vec::new(),
            taken: 0,
            timeout,
            last_tag,
            in_step: false,
        }
    }

    /// The next request's tag (never 0, which refusals of unreadable frames carry).
    fn next_tag(&mut self) -> u16 {
        self.last_tag = self.last_tag.wrapping_add(1).max(1);
        self.last_tag
    }

    /// Sends `message` as the request `tag`.
    fn send(&mut self, tag: u16, message: &Message<'_>) -> Result<(), LinkError> {
        message.encode(tag, &mut self.port)?;
        self.port.flush()?;
        Ok(())
    }

    /// Asks the board what it is; the first request of a link, which
    /// brings the board in step whatever it was doing.
    pub fn hello(&mut self) -> Result<BoardDescription, LinkError> {
        self.port.discard_input()?;
        let tag = self.next_tag();
        self.send(tag, &Message::Hello)?;
        let info = match self.receive(tag)? {
            Message::Board(info) => info,
            Message::Refused(reason) => return Err(refused(reason)),
            other => return Err(unexpected(other.kind(), "the board's description")),
        };
        Ok(BoardDescription {
            panel: info.panel,
            max_scene: info.max_scene,
            profile: info.profile.into(),
            firmware: info.firmware.into(),
            capacities: info.capacities.iter().map(|c| (c.name.into(), c.count)).collect(),
        })
    }

    /// Sends scene `text` (after [`BoardLink::hello`]) and follows the
    /// drawing, handing each step to `progress`; rows carry their pixels
    /// if `pixels`.
    pub fn draw(
        &mut self,
        text: &[u8],
        pixels: bool,
        progress: &mut dyn FnMut(Progress<'_>),
    ) -> Result<Answer, LinkError> {
        let tag = self.next_tag();
        self.send(tag, &Message::Scene { pixels, text })?;
        let mut errors = Vec::new();
        // The panel and which of its rows have come.
        let mut drawing: Option<(Panel, Vec<bool>)> = None;
        loop {
            match (self.receive(tag)?, &mut drawing) {
                (Message::SceneError(e), None) => errors.push(BoardSceneError {
                    line: e.line,
                    column: e.column,
                    capacity: e.capacity.map(|c| (c.name.into(), c.needed, c.holds)),
                    message: e.message.into(),
                }),
                (Message::Rejected { errors: count }, None) if count as usize == errors.len() && count > 0 => {
                    return Ok(Answer::Rejected(errors));
                }
                (Message::Rejected { errors: count }, None) => {
                    let sent = errors.len();
                    return Err(LinkError::Protocol(format!("it counted {count} errors of the scene and sent {sent}")));
                }
                (Message::Drawing { panel, pixels: with_pixels }, None) if errors.is_empty() => {
                    if with_pixels != pixels {
                        return Err(LinkError::Protocol(format!("rows with pixels: {with_pixels}, asked: {pixels}")));
                    }
                    progress(Progress::Drawing(panel));
                    drawing = Some((panel, vec![false; panel.height.into()]));
                }
                (Message::Row { y, pixels: row }, Some((panel, seen))) => {
                    let bytes = if pixels { panel.row_bytes() } else { 0 };
                    match seen.get_mut(usize::from(y)) {
                        Some(seen) if !*seen && row.len() == bytes => *seen = true,
                        Some(_) if row.len() != bytes => {
                            let got = row.len();
                            return Err(LinkError::Protocol(format!("row {y} has {got} bytes, not {bytes}")));
                        }
                        Some(_) => return Err(LinkError::Protocol(format!("row {y} came twice"))),
                        None => return Err(LinkError::Protocol(format!("row {y} of a {}-row panel", panel.height))),
                    }
                    progress(Progress::Row { y, pixels: row });
                }
                (Message::Done(timing), Some((panel, seen))) => {
                    return match seen.iter().position(|seen| !seen) {
                        None => Ok(Answer::Drawn { panel: *panel, timing: BoardTiming::of(&timing) }),
                        Some(y) => Err(LinkError::Protocol(format!("done without row {y}"))),
                    };
                }
                (Message::Cancelled { rows }, _) => return Err(LinkError::Cancelled { rows }),
                (Message::Refused(reason), _) => return Err(refused(reason)),
                (other, _) => return Err(unexpected(other.kind(), "the answer to the scene")),
            }
        }
    }

    /// The next message answering request `tag`, skipping any other.
    fn receive(&mut self, tag: u16) -> Result<Message<'_>, LinkError> {
        let deadline = Instant::now() + self.timeout;
        loop {
            if self.taken == self.input.len() {
                self.fill(deadline)?;
                continue;
            }
            let byte = self.input[self.taken];
            self.taken += 1;
            let in_step = self.in_step;
            let ours = match self.decoder.push(byte) {
                None => false,
                // The board's refusal of a frame whose header it could not
                // trust carries tag 0: once the board is in step with this
                // link, that frame was this link's.
                Some(Ok(frame)) => {
                    frame.tag == tag || (in_step && frame.tag == 0 && matches!(frame.message, Message::Refused(_)))
                }
                // A frame of the board's that this host cannot read. Before
                // the board is in step, it may be the tail of an earlier
                // run's answer; after, it belongs to this one.
                Some(Err(refusal)) => match refusal.reason {
                    Reason::WrongVersion { found, .. } => return Err(LinkError::Version { board: found }),
                    reason if refusal.tag == tag || (in_step && refusal.tag == 0) => {
                        return Err(LinkError::Protocol(format!("it sent {reason}")));
                    }
                    _ => false,
                },
            };
            if ours {
                self.in_step = true;
                return match self.decoder.received() {
                    Some(Ok(frame)) => Ok(frame.message),
                    _ => Err(LinkError::Protocol("the frame just read is gone".into())),
                };
            }
        }
    }

    /// Reads what the port has, waiting until `deadline` at most.
    fn fill(&mut self, deadline: Instant) -> Result<(), LinkError> {
        self.input.resize(4096, 0);
        self.taken = 0;
        loop {
            if Instant::now() >= deadline {
                self.input.clear();
                return Err(LinkError::Silent(self.timeout));
            }
            match self.port.read(&mut self.input) {
                Ok(0) => std::thread::sleep(Duration::from_millis(5)),
                Ok(n) => {
                    self.input.truncate(n);
                    return Ok(());
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
                    ) => {}
                Err(e) => {
                    self.input.clear();
                    return Err(LinkError::Io(e));
                }
            }
        }
    }
}

/// The board refusing a frame of ours: another version is said as such.
fn refused(reason: Reason) -> LinkError {
    match reason {
        Reason::WrongVersion { expected, .. } => LinkError::Version { board: expected },
        reason => LinkError::Refused(reason),
    }
}

fn unexpected(kind: octrace_link::Kind, awaited: &str) -> LinkError {
    LinkError::Protocol(format!("it sent a {kind} message where {awaited} was due"))
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
            first.display()
        )));
    }
    let port = first.display().to_string();
    let out = args.out.as_ref();
    let timeout = Duration::from_secs(args.timeout);
    let Some(scene) = &args.scene else {
        let mut link = BoardLink::open(&port, timeout).map_err(|e| link_error(&port, e))?;
        let board = link.hello().map_err(|e| link_error(&port, e))?;
        return describe(&port, &board, stdout).map_err(|e| CliError::Io(format!("board: {e}")));
    };
    if out.is_none() && args.format.is_some() {
        return Err(CliError::Invalid("board: --format names OUT's format: give OUT".into()));
    }
    let format = out.map(|out| output_format(args.format, out)).transpose()?;
    if let Some(out) = out.filter(|out| same_file(scene, out)) {
        return Err(CliError::Invalid(format!(
            "refusing to overwrite the scene file {} with the image",
            out.display()
        )));
    }
    let text = std::fs::read(scene).map_err(|e| CliError::read(scene, e))?;
    let file = scene.display().to_string();
    let pixels = out.is_some() || args.check;
    let started = Instant::now();
    let mut bar = None;
    let sent = send_scene(&port, timeout, &file, &text, pixels, &mut |step| match step {
        Progress::Drawing(panel) => bar = progress_bar(panel.height.into(), args.quiet),
        Progress::Row { .. } => {
            if let Some(bar) = &bar {
                bar.inc(1);
            }
        }
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
    };
    let (w, h) = (panel.width, panel.height);
    if !args.quiet {
        let time = timing.describe(started.elapsed());
        let _ = writeln!(stderr, "{w}x{h} {} drawn by the board at {port} {time}", panel.format);
    }
    let Some(image) = picture else { return Ok(()) };
    if let (Some(out), Some(format)) = (out, format) {
        crate::output::write_atomically(out, |f| {
            formats::write(&Image::Rgb(image.clone()), format, f).map_err(io::Error::other)
        })
        .map_err(|e| CliError::write(out, e))?;
        if !args.quiet {
            let _ = writeln!(stderr, "the board's picture -> {}", out.display());
        }
    }
    if args.check {
        let differ = differing_pixels(&file, &text, panel, &image)?;
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

/// A failure to talk to the board at `port`, as host-sim reports it.
fn link_error(port: &str, e: LinkError) -> CliError {
    let message = format!("board at {port}: {e}");
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
}

/// Sends scene `text` (named `file` in errors) to the board at `port`,
/// after its hello and a check of the scene's length against what it
/// takes, and follows the drawing, handing each step to `progress`. Waits
/// at most `timeout` for each answer. `host-sim board` and the studio send
/// through this.
pub(crate) fn send_scene(
    port: &str,
    timeout: Duration,
    file: &str,
    text: &[u8],
    pixels: bool,
    progress: &mut dyn FnMut(Progress<'_>),
) -> Result<Sent, CliError> {
    let mut link = BoardLink::open(port, timeout).map_err(|e| link_error(port, e))?;
    let board = link.hello().map_err(|e| link_error(port, e))?;
    if text.len() > board.max_scene as usize {
        return Err(CliError::Invalid(format!(
            "{file} is {} bytes; the board at {port} takes scenes of at most {} bytes",
            text.len(),
            board.max_scene
        )));
    }
    // The picture, assembled as its rows come.
    let mut picture: Option<(PixelFormat, RgbImage)> = None;
    let answer = link.draw(text, pixels, &mut |step| {
        match &step {
            Progress::Drawing(panel) => {
                let image = RgbImage::new(panel.width.into(), panel.height.into());
                picture = pixels.then_some((panel.format, image));
            }
            Progress::Row { y, pixels } => {
                if let Some((format, image)) = &mut picture {
                    let row = image.data.chunks_exact_mut(3).skip(*y as usize * image.width as usize);
                    for (rgb, color) in row.zip(format.colors(pixels)) {
                        rgb.copy_from_slice(&[color.r(), color.g(), color.b()]);
                    }
                }
            }
        }
        progress(step);
    });
    Ok(match answer.map_err(|e| link_error(port, e))? {
        Answer::Rejected(errors) => Sent::Rejected(errors),
        Answer::Drawn { panel, timing } => Sent::Drawn { panel, timing, picture: picture.map(|(_, image)| image) },
    })
}

/// How many pixels of the board's `picture` differ from host-sim's render
/// of the scene at the panel's size, as the panel shows it (`host-sim
/// SCENE OUT --size WxH --color rgb565`). `host-sim board --check` and the
/// studio judge the board's picture by this.
pub(crate) fn differing_pixels(file: &str, text: &[u8], panel: Panel, picture: &RgbImage) -> Result<usize, CliError> {
    let ours = host_render(file, text, panel)?;
    Ok(ours.data.chunks_exact(3).zip(picture.data.chunks_exact(3)).filter(|(a, b)| a != b).count())
}

/// host-sim's render of the scene at the panel's size, as the panel shows
/// it.
fn host_render(file: &str, text: &[u8], panel: Panel) -> Result<RgbImage, CliError> {
    let mismatch = |why: String| CliError::Mismatch(format!("board --check: {why}"));
    let mut scene = new_scene();
    load_bytes(file, text, &mut scene).map_err(|e| match e {
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
    let rendered = render_with_progress(&scene, &options, &|_| {})
        .map_err(|e| mismatch(format!("host-sim cannot set up the camera: {e}")))?;
    let color = match panel.format {
        PixelFormat::Rgb565 => PanelColor::Rgb565,
    };
    Ok(match panel_preview(&rendered.image, color) {
        Some(preview) => preview.to_rgb(),
        None => rendered.image,
    })
}

/// What `host-sim board PORT` prints.
fn describe(port: &str, board: &BoardDescription, out: &mut dyn Write) -> io::Result<()> {
    let Panel { width, height, format } = board.panel;
    writeln!(out, "{port}: {} (protocol version {VERSION})", board.firmware)?;
    writeln!(out, "panel: {width}x{height} {format}; scenes of at most {} bytes", board.max_scene)?;
    let capacities: Vec<String> = board.capacities.iter().map(|(name, count)| format!("{name} {count}")).collect();
    writeln!(out, "profile {}: {}", board.profile, capacities.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use octrace_link::SceneError;
    use std::collections::VecDeque;

    /// A board played by a function: each frame host-sim writes is
    /// answered with the bytes it returns.
    struct Played<F> {
        decoder: Decoder<Vec<u8>>,
        answer: F,
        out: VecDeque<u8>,
    }

    impl<F: FnMut(u16, Message<'_>) -> Vec<u8>> Write for Played<F> {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            for &byte in buf {
                if let Some(Ok(frame)) = self.decoder.push(byte) {
                    let bytes = (self.answer)(frame.tag, frame.message);
                    self.out.extend(bytes);
                }
            }
            Ok(buf.len())
        }

        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl<F> Read for Played<F> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if self.out.is_empty() {
                std::thread::sleep(Duration::from_millis(1));
                return Err(io::ErrorKind::TimedOut.into());
            }
            let n = buf.len().min(self.out.len());
            for (slot, byte) in buf.iter_mut().zip(self.out.drain(..n)) {
                *slot = byte;
            }
            Ok(n)
        }
    }

    impl<F: FnMut(u16, Message<'_>) -> Vec<u8>> Port for Played<F> {
        fn discard_input(&mut self) -> io::Result<()> {
            self.out.clear();
            Ok(())
        }
    }

    fn played(answer: impl FnMut(u16, Message<'_>) -> Vec<u8>) -> BoardLink<impl Port> {
        let port = Played { decoder: Decoder::new(vec![0; 4096]), answer, out: VecDeque::new() };
        BoardLink::new(port, Duration::from_millis(200))
    }

    fn frames(messages: &[(Message<'_>, u16)]) -> Vec<u8> {
        let mut bytes = Vec::new();
        for (message, tag) in messages {
            message.encode(*tag, &mut bytes).unwrap();
        }
        bytes
    }

    const PANEL: Panel = Panel { width: 2, height: 2, format: PixelFormat::Rgb565 };

    fn board_info() -> Message<'static> {
        Message::Board(octrace_link::BoardInfo {
            panel: PANEL,
            max_scene: 100,
            profile: "P",
            firmware: "f",
            capacities: octrace_link::Capacities::new(&[]),
        })
    }

    /// A board that answers hello and then each scene with `answer(tag)`.
    fn drawing_board(mut answer: impl FnMut(u16) -> Vec<u8>) -> BoardLink<impl Port> {
        played(move |tag, message| match message {
            Message::Hello => frames(&[(board_info(), tag)]),
            _ => answer(tag),
        })
    }

    fn draw(link: &mut BoardLink<impl Port>) -> Result<Answer, LinkError> {
        link.hello().unwrap();
        link.draw(b"scene", true, &mut |_| {})
    }

    #[test]
    fn what_came_before_the_boards_answer_to_hello_is_skipped() {
        let mut link = played(|tag, _| {
            let mut bytes = frames(&[(Message::Row { y: 3, pixels: &[] }, tag.wrapping_sub(1))]);
            bytes.extend_from_slice(b"\0garbage\0");
            bytes.extend(frames(&[(Message::Refused(Reason::Undecodable { length: 7 }), 0), (board_info(), tag)]));
            bytes
        });
        assert_eq!(link.hello().unwrap().panel, PANEL);
    }

    #[test]
    fn a_drawing_is_followed_to_its_last_row() {
        let pixels = [0u8; 4];
        let mut link = drawing_board(|tag| {
            frames(&[
                (Message::Drawing { panel: PANEL, pixels: true }, tag),
                (Message::Row { y: 1, pixels: &pixels }, tag),
                (Message::Row { y: 0, pixels: &pixels }, tag),
                (Message::Done(Timing::NONE), tag),
            ])
        });
        assert_eq!(draw(&mut link).unwrap(), Answer::Drawn { panel: PANEL, timing: BoardTiming::default() });
    }

    #[test]
    fn rows_twice_short_or_missing_break_the_protocol() {
        let pixels = [0u8; 4];
        /// The rows a board sends (their numbers and pixels), and what host-sim says.
        type Case<'a> = (&'a [(u16, &'a [u8])], &'a str);
        let cases: [Case<'_>; 4] = [
            (&[(0, &pixels), (0, &pixels)], "row 0 came twice"),
            (&[(0, &pixels[..3])], "row 0 has 3 bytes, not 4"),
            (&[(2, &pixels)], "row 2 of a 2-row panel"),
            (&[(1, &pixels)], "done without row 0"),
        ];
        for (rows, said) in cases {
            let mut link = drawing_board(|tag| {
                let mut messages = vec![(Message::Drawing { panel: PANEL, pixels: true }, tag)];
                messages.extend(rows.iter().map(|&(y, pixels)| (Message::Row { y, pixels }, tag)));
                messages.push((Message::Done(Timing::NONE), tag));
                frames(&messages)
            });
            let error = draw(&mut link).unwrap_err();
            assert!(matches!(&error, LinkError::Protocol(what) if what == said), "{said}: {error}");
        }
    }

    #[test]
    fn the_errors_come_all_and_counted() {
        let error = |line| SceneError { line, column: 2, capacity: None, message: "bad" };
        let mut link = drawing_board(|tag| {
            frames(&[
                (Message::SceneError(error(1)), tag),
                (Message::SceneError(error(0)), tag),
                (Message::Rejected { errors: 2 }, tag),
            ])
        });
        let Answer::Rejected(errors) = draw(&mut link).unwrap() else { panic!("rejected") };
        let located: Vec<String> = errors.iter().map(|e| e.located("s.txt")).collect();
        assert_eq!(located, ["s.txt:1:2: bad", "s.txt: bad"]);
        let mut link = drawing_board(|tag| {
            frames(&[(Message::SceneError(error(1)), tag), (Message::Rejected { errors: 3 }, tag)])
        });
        assert!(matches!(draw(&mut link), Err(LinkError::Protocol(_))));
    }

    #[test]
    fn once_in_step_a_refusal_without_a_tag_is_of_our_frame_and_garbage_is_an_error() {
        let checksum = Reason::BadChecksum { sent: 1, computed: 2 };
        let mut link = drawing_board(|_| frames(&[(Message::Refused(checksum), 0)]));
        assert!(matches!(draw(&mut link), Err(LinkError::Refused(reason)) if reason == checksum));
        let mut link = drawing_board(|_| b"\0garbage\0".to_vec());
        assert!(matches!(draw(&mut link), Err(LinkError::Protocol(_))));
    }

    #[test]
    fn a_board_of_another_version_and_a_silent_one_are_said_as_such() {
        let mut link = played(|tag, _| {
            let mut bytes = Vec::new();
            octrace_link::encode_raw(VERSION + 1, octrace_link::Kind::Board.byte(), tag, &[], &mut bytes).unwrap();
            bytes
        });
        assert!(matches!(link.hello(), Err(LinkError::Version { board }) if board == VERSION + 1));
        let refusal = Message::Refused(Reason::WrongVersion { expected: 7, found: VERSION });
        let mut link = played(move |tag, _| frames(&[(refusal, tag)]));
        assert!(matches!(link.hello(), Err(LinkError::Version { board: 7 })));
        let mut link = played(|_, _| Vec::new());
        let silent = link.hello().unwrap_err();
        assert!(silent.to_string().starts_with("no answer within 0.2 s"), "{silent}");
    }

    #[test]
    fn a_drawing_cut_short_by_another_host_is_said() {
        let mut link = drawing_board(|tag| {
            frames(&[(Message::Drawing { panel: PANEL, pixels: true }, tag), (Message::Cancelled { rows: 0 }, tag)])
        });
        assert!(matches!(draw(&mut link), Err(LinkError::Cancelled { rows: 0 })));
    }
}
