//! The host's side of a conversation with one board over its serial line
//! (octrace-link's protocol, docs/board-protocol.md): its hello, then a
//! scene and the answer, each frame checked against what the board said
//! before.
//!
//! Invariants: the whole conversation, writes included, ends by the link's
//! deadline (its timeout after it opened), however the board trickles or
//! floods; a frame answering another request (an earlier run's, another
//! host's) is skipped by its tag; the board's panel is within the
//! protocol's limits and every drawing is at that panel, so nothing is set
//! aside for a picture the board only claims; every row arrives exactly
//! once, in the panel's format and width, before the board says it is
//! done; the board's errors are at most as many as the scene can have,
//! each of a bounded length; the board's text (names, messages) reaches
//! the caller with its control characters escaped.

use crate::terminal::shown;
use octrace_link::{Decoder, Message, Panel, Reason, Timing, VERSION};
use serialport::SerialPort as _;
use std::io::{self, Read, Write};
use std::time::{Duration, Instant};

/// A serial line to a board: bytes both ways, reads and writes that give
/// up after a short while (so that the deadline can be kept).
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

    /// Nothing to do: what `write` took is the system's. (The device's own
    /// flush waits until the board has read it all, with no time limit.)
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
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
    /// The board's answer began but did not end within the timeout: a
    /// drawing slower than that, or a board that keeps talking.
    Unfinished(Duration),
    /// The board did not read what host-sim sent within the timeout.
    Unread(Duration),
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
            LinkError::Unfinished(waited) => write!(
                f,
                "the board's answer did not end within {} s (--timeout waits longer for a slow drawing)",
                waited.as_secs_f64()
            ),
            LinkError::Unread(waited) => write!(
                f,
                "the board did not read what host-sim sent within {} s (is octrace's live firmware running there?)",
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
    /// Each counter: its name (control characters escaped), its count
    /// over the load and over the render.
    pub counters: Vec<(String, u32, u32)>,
}

impl BoardTiming {
    fn of(timing: &Timing<'_>) -> BoardTiming {
        BoardTiming {
            elapsed: timing.elapsed,
            load: timing.load,
            render: timing.render,
            counters: timing.counters.iter().map(|c| (shown(c.name), c.load, c.render)).collect(),
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
    /// It played the animation at its panel's size: the frames followed,
    /// in order, before host-sim stopped it.
    Played { panel: Panel, frames: Vec<PlayedFrame> },
    /// The scene has errors (all of them, in the order found); nothing drawn.
    Rejected(Vec<BoardSceneError>),
}

/// A frame of an animation the board drew whole.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlayedFrame {
    /// Which, from 0.
    pub frame: u32,
    /// Pixels the board traced for it.
    pub traced: u32,
    /// Its time by the board's clock, if it has one.
    pub elapsed: Option<Duration>,
}

/// What happens while a board draws.
#[derive(Debug)]
pub enum Progress<'a> {
    /// The scene loaded; its rows follow.
    Drawing(Panel),
    /// Row `y` is drawn: its pixels in the panel's format, if asked for.
    Row { y: u16, pixels: &'a [u8] },
    /// The scene is an animation of `frames` frames; its runs follow.
    Playing { panel: Panel, frames: u32 },
    /// A run of row `y` from column `x` of the frame being played is
    /// drawn: its pixels in the panel's format, if asked for.
    Run { y: u16, x: u16, pixels: &'a [u8] },
    /// A frame is whole: every run of it has come.
    FrameDrawn(PlayedFrame),
}

/// The longest frame host-sim takes from a board: a `board` description
/// of 255 capacities of 255-byte names, and more.
const MAX_FRAME: usize = 1 << 18;

/// The longest error message host-sim takes from a board, in bytes:
/// octrace-core's are under 400 (scene text in them is cut to 40
/// characters), so a longer one is no error of a scene.
pub(crate) const MAX_MESSAGE: usize = 4096;

/// The most errors a scene of `length` bytes can have: every error but a
/// few of the whole scene (its camera, its capacities) is at a token of
/// its own, and a token and the space after it take two bytes.
pub(crate) fn most_errors(length: usize) -> usize {
    length / 2 + 64
}

/// Whether an error of the port only says that nothing could be read or
/// written yet.
fn waiting(e: &io::Error) -> bool {
    matches!(e.kind(), io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted)
}

/// A conversation with one board.
pub struct BoardLink<P: Port> {
    port: P,
    decoder: Decoder<Vec<u8>>,
    /// Bytes read from the port, and how many of them the decoder has had.
    input: Vec<u8>,
    taken: usize,
    timeout: Duration,
    /// When the conversation must be over: `timeout` after the link opened.
    deadline: Instant,
    last_tag: u16,
    /// Whether the board has answered a request of this link: from then on
    /// every frame it sends is in answer to this link's requests.
    in_step: bool,
    /// The panel the board described: every drawing is at it.
    panel: Option<Panel>,
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
    /// A link over `port` whose whole conversation (every request sent and
    /// every answer received) ends within `timeout` from now.
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
            deadline: Instant::now() + timeout,
            last_tag,
            in_step: false,
            panel: None,
        }
    }

    /// The next request's tag (never 0, which refusals of unreadable frames carry).
    fn next_tag(&mut self) -> u16 {
        self.last_tag = self.last_tag.wrapping_add(1).max(1);
        self.last_tag
    }

    /// Sends `message` as the request `tag`, however slowly the board
    /// reads, until the deadline.
    fn send(&mut self, tag: u16, message: &Message<'_>) -> Result<(), LinkError> {
        let mut frame = Vec::new();
        message.encode(tag, &mut frame)?;
        let mut sent = 0;
        while sent < frame.len() {
            if Instant::now() >= self.deadline {
                return Err(LinkError::Unread(self.timeout));
            }
            match self.port.write(&frame[sent..]) {
                Ok(0) => std::thread::sleep(Duration::from_millis(5)),
                Ok(n) => sent += n,
                Err(e) if waiting(&e) => {}
                Err(e) => return Err(LinkError::Io(e)),
            }
        }
        self.port.flush()?;
        Ok(())
    }

    /// Asks the board what it is; the first request of a link, which
    /// brings the board in step whatever it was doing. A panel beyond the
    /// protocol's limits is refused here.
    pub fn hello(&mut self) -> Result<BoardDescription, LinkError> {
        self.port.discard_input()?;
        let tag = self.next_tag();
        self.send(tag, &Message::Hello)?;
        let info = match self.receive(tag)? {
            Message::Board(info) => info,
            Message::Refused(reason) => return Err(refused(reason)),
            other => return Err(unexpected(other.kind(), "the board's description")),
        };
        let Panel { width, height, .. } = info.panel;
        if !info.panel.within_limits() {
            return Err(LinkError::Protocol(format!(
                "it describes a {width}x{height} panel; a panel's sides are 1 to {} pixels",
                Panel::MAX_SIDE
            )));
        }
        let board = BoardDescription {
            panel: info.panel,
            max_scene: info.max_scene,
            profile: shown(info.profile),
            firmware: shown(info.firmware),
            capacities: info.capacities.iter().map(|c| (shown(c.name), c.count)).collect(),
        };
        self.panel = Some(board.panel);
        Ok(board)
    }

    /// Sends scene `text` (after [`BoardLink::hello`], which it asks for
    /// first if this link has not) and follows the drawing, handing each
    /// step to `progress`; rows carry their pixels if `pixels`. An
    /// animation is followed for `follow` frames (at least 1), then
    /// stopped with a hello.
    pub fn draw(
        &mut self,
        text: &[u8],
        pixels: bool,
        follow: u32,
        progress: &mut dyn FnMut(Progress<'_>),
    ) -> Result<Answer, LinkError> {
        let panel = match self.panel {
            Some(panel) => panel,
            None => self.hello()?.panel,
        };
        let tag = self.next_tag();
        self.send(tag, &Message::Scene { pixels, text })?;
        let mut errors = Vec::new();
        // Which rows of the drawing have come, once it began.
        let mut drawing: Option<Vec<bool>> = None;
        loop {
            let began = drawing.is_some() || !errors.is_empty();
            let message = match self.receive(tag) {
                Err(LinkError::Silent(waited)) if began => return Err(LinkError::Unfinished(waited)),
                received => received?,
            };
            match (message, &mut drawing) {
                (Message::SceneError(e), None) => {
                    if errors.len() == most_errors(text.len()) {
                        return Err(LinkError::Protocol(format!(
                            "it sent more errors than a scene of {} bytes can have ({})",
                            text.len(),
                            errors.len()
                        )));
                    }
                    if e.message.len() > MAX_MESSAGE {
                        return Err(LinkError::Protocol(format!(
                            "it sent an error message of {} bytes (octrace's are under {MAX_MESSAGE})",
                            e.message.len()
                        )));
                    }
                    errors.push(BoardSceneError {
                        line: e.line,
                        column: e.column,
                        capacity: e.capacity.map(|c| (shown(c.name), c.needed, c.holds)),
                        message: shown(e.message),
                    });
                }
                (Message::Rejected { errors: count }, None) if count as usize == errors.len() && count > 0 => {
                    return Ok(Answer::Rejected(errors));
                }
                (Message::Rejected { errors: count }, None) => {
                    let sent = errors.len();
                    return Err(LinkError::Protocol(format!("it counted {count} errors of the scene and sent {sent}")));
                }
                (Message::Drawing { panel: drawn, pixels: with_pixels, frames }, None) if errors.is_empty() => {
                    if drawn != panel {
                        return Err(LinkError::Protocol(format!(
                            "it draws at {}x{} {}, but described a {}x{} {} panel",
                            drawn.width, drawn.height, drawn.format, panel.width, panel.height, panel.format
                        )));
                    }
                    if with_pixels != pixels {
                        return Err(LinkError::Protocol(format!("rows with pixels: {with_pixels}, asked: {pixels}")));
                    }
                    if frames > 0 {
                        progress(Progress::Playing { panel, frames });
                        return self.follow(tag, panel, pixels, frames, follow.max(1), progress);
                    }
                    progress(Progress::Drawing(panel));
                    drawing = Some(vec![false; panel.height.into()]);
                }
                (Message::Row { y, pixels: row }, Some(seen)) => {
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
                (Message::Done(timing), Some(seen)) => {
                    return match seen.iter().position(|seen| !seen) {
                        None => Ok(Answer::Drawn { panel, timing: BoardTiming::of(&timing) }),
                        Some(y) => Err(LinkError::Protocol(format!("done without row {y}"))),
                    };
                }
                (Message::Cancelled { rows }, _) => return Err(LinkError::Cancelled { rows }),
                (Message::Refused(reason), _) => return Err(refused(reason)),
                (other, _) => return Err(unexpected(other.kind(), "the answer to the scene")),
            }
        }
    }

    /// Follows the animation of `frames` frames that request `tag` plays
    /// on `panel` for `follow` frames, then stops it with a hello. Every
    /// run lies in the panel, of its width's pixels, each pixel at most
    /// once a frame, and the first frame covers the panel.
    fn follow(
        &mut self,
        tag: u16,
        panel: Panel,
        pixels: bool,
        frames: u32,
        follow: u32,
        progress: &mut dyn FnMut(Progress<'_>),
    ) -> Result<Answer, LinkError> {
        let width = usize::from(panel.width);
        // The pixels of each row that came in this frame, a row set aside
        // only when a run of it comes; and how many came in all.
        let mut came: Vec<Vec<bool>> = vec![Vec::new(); panel.height.into()];
        let (mut touched, mut covered) = (Vec::new(), 0usize);
        let mut played = Vec::new();
        while played.len() < follow as usize {
            let message = match self.receive(tag) {
                Err(LinkError::Silent(waited)) => return Err(LinkError::Unfinished(waited)),
                received => received?,
            };
            match message {
                Message::Run { y, x, width: run, pixels: bytes } => {
                    let (x0, x1) = (usize::from(x), usize::from(x) + usize::from(run));
                    let row = came.get_mut(usize::from(y)).filter(|_| x1 <= width && run > 0).ok_or_else(|| {
                        LinkError::Protocol(format!(
                            "a run of {run} pixels at ({x}, {y}) on a {}x{} panel",
                            width, panel.height
                        ))
                    })?;
                    let expected = if pixels { usize::from(run) * panel.format.bytes_per_pixel() } else { 0 };
                    if bytes.len() != expected {
                        return Err(LinkError::Protocol(format!(
                            "the run at ({x}, {y}) has {} bytes, not {expected}",
                            bytes.len()
                        )));
                    }
                    if row.is_empty() {
                        *row = vec![false; width];
                        touched.push(usize::from(y));
                    }
                    if row[x0..x1].iter().any(|&seen| seen) {
                        return Err(LinkError::Protocol(format!(
                            "a pixel of the run at ({x}, {y}) came twice in a frame"
                        )));
                    }
                    row[x0..x1].fill(true);
                    covered += usize::from(run);
                    progress(Progress::Run { y, x, pixels: bytes });
                }
                Message::FrameDrawn { frame, traced, elapsed } => {
                    let expected = played.last().map_or(0, |last: &PlayedFrame| (last.frame + 1) % frames);
                    if frame != expected {
                        return Err(LinkError::Protocol(format!("frame {frame} drawn where frame {expected} was due")));
                    }
                    if played.is_empty() && covered != width * usize::from(panel.height) {
                        return Err(LinkError::Protocol(format!(
                            "the first frame drew {covered} of the panel's {} pixels",
                            width * usize::from(panel.height)
                        )));
                    }
                    for y in touched.drain(..) {
                        came[y].clear();
                    }
                    let drawn = PlayedFrame { frame, traced, elapsed };
                    played.push(drawn);
                    progress(Progress::FrameDrawn(drawn));
                }
                Message::Stopped { frames } => {
                    return Err(LinkError::Protocol(format!("it stopped playing after {frames} frames unasked")));
                }
                Message::Refused(reason) => return Err(refused(reason)),
                other => return Err(unexpected(other.kind(), "the animation's runs")),
            }
        }
        // Stopped as a host that starts stops it: the answer ends with
        // `stopped`, then the board describes itself.
        let hello = self.next_tag();
        self.send(hello, &Message::Hello)?;
        loop {
            match self.receive(tag)? {
                Message::Run { .. } | Message::FrameDrawn { .. } => {}
                Message::Stopped { .. } => break,
                other => return Err(unexpected(other.kind(), "the end of the animation")),
            }
        }
        match self.receive(hello)? {
            Message::Board(_) => Ok(Answer::Played { panel, frames: played }),
            other => Err(unexpected(other.kind(), "the board's description")),
        }
    }

    /// The next message answering request `tag`, skipping any other, by
    /// the deadline.
    fn receive(&mut self, tag: u16) -> Result<Message<'_>, LinkError> {
        loop {
            if self.taken == self.input.len() {
                self.fill()?;
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

    /// Reads what the port has, waiting until the deadline at most.
    fn fill(&mut self) -> Result<(), LinkError> {
        self.input.resize(4096, 0);
        self.taken = 0;
        loop {
            if Instant::now() >= self.deadline {
                self.input.clear();
                return Err(LinkError::Silent(self.timeout));
            }
            match self.port.read(&mut self.input) {
                Ok(0) => std::thread::sleep(Duration::from_millis(5)),
                Ok(n) => {
                    self.input.truncate(n);
                    return Ok(());
                }
                Err(e) if waiting(&e) => {}
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

#[cfg(test)]
mod tests {
    use super::*;
    use octrace_link::{PixelFormat, SceneError};
    use std::collections::VecDeque;

    /// A board played by a function: each frame host-sim writes is
    /// answered with the bytes it returns. It reads nothing before
    /// `reads_from` (each write times out, as a serial port's does), and
    /// once `chatter` is set it sends it again whenever host-sim has read
    /// all it sent.
    struct Played<F> {
        decoder: Decoder<Vec<u8>>,
        answer: F,
        out: VecDeque<u8>,
        reads_from: Instant,
        chatter: Chatter,
    }

    /// What a board keeps sending, how often, and when it last did.
    type Chatter = std::rc::Rc<std::cell::RefCell<(Vec<u8>, Duration, Instant)>>;

    impl<F: FnMut(u16, Message<'_>) -> Vec<u8>> Write for Played<F> {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if Instant::now() < self.reads_from {
                std::thread::sleep(Duration::from_millis(5));
                return Err(io::ErrorKind::TimedOut.into());
            }
            // A byte at a time: a line that drains slowly.
            let Some(&byte) = buf.first() else { return Ok(0) };
            if let Some(Ok(frame)) = self.decoder.push(byte) {
                let bytes = (self.answer)(frame.tag, frame.message);
                self.out.extend(bytes);
            }
            Ok(1)
        }

        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl<F> Read for Played<F> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let (chatter, every, last) = &mut *self.chatter.borrow_mut();
            if self.out.is_empty() && !chatter.is_empty() && last.elapsed() >= *every {
                self.out.extend(chatter.iter());
                *last = Instant::now();
            }
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
        BoardLink::new(played_port(answer), Duration::from_millis(200))
    }

    fn played_port<F: FnMut(u16, Message<'_>) -> Vec<u8>>(answer: F) -> Played<F> {
        let chatter = std::rc::Rc::new(std::cell::RefCell::new((Vec::new(), Duration::ZERO, Instant::now())));
        Played {
            decoder: Decoder::new(vec![0; 4096]),
            answer,
            out: VecDeque::new(),
            reads_from: Instant::now(),
            chatter,
        }
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
        link.draw(b"scene", true, 1, &mut |_| {})
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
                (Message::Drawing { panel: PANEL, pixels: true, frames: 0 }, tag),
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
                let mut messages = vec![(Message::Drawing { panel: PANEL, pixels: true, frames: 0 }, tag)];
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
            frames(&[
                (Message::Drawing { panel: PANEL, pixels: true, frames: 0 }, tag),
                (Message::Cancelled { rows: 0 }, tag),
            ])
        });
        assert!(matches!(draw(&mut link), Err(LinkError::Cancelled { rows: 0 })));
    }

    #[test]
    fn a_panel_beyond_the_protocols_limits_or_another_than_described_is_refused_before_anything_is_kept() {
        for (width, height) in [(0, 0), (0, 240), (Panel::MAX_SIDE + 1, 1), (65535, 65535)] {
            let panel = Panel { width, height, format: PixelFormat::Rgb565 };
            let mut link = played(move |tag, _| {
                frames(&[(
                    Message::Board(octrace_link::BoardInfo {
                        panel,
                        max_scene: 100,
                        profile: "P",
                        firmware: "f",
                        capacities: octrace_link::Capacities::new(&[]),
                    }),
                    tag,
                )])
            });
            let said = link.hello().unwrap_err().to_string();
            let want = format!("it describes a {width}x{height} panel; a panel's sides are 1 to 16384 pixels");
            assert!(said.ends_with(&want), "{said}");
            // A drawing at any panel but the one described.
            let mut link = drawing_board(move |tag| {
                frames(&[
                    (Message::Drawing { panel, pixels: true, frames: 0 }, tag),
                    (Message::Done(Timing::NONE), tag),
                ])
            });
            let said = draw(&mut link).unwrap_err().to_string();
            let want = format!("it draws at {width}x{height} rgb565, but described a 2x2 rgb565 panel");
            assert!(said.ends_with(&want), "{said}");
        }
    }

    /// A board that describes itself (as `info`), then answers a scene
    /// with scene errors `message`, one every `every`, and never ends.
    fn chatty_board(info: Message<'static>, message: &'static str, every: Duration) -> BoardLink<impl Port> {
        let port = played_port(|_, _| Vec::new());
        let chatter = port.chatter.clone();
        let scene = chatter.clone();
        let mut port = played_port(move |tag, received| match received {
            Message::Hello => frames(&[(info, tag)]),
            _ => {
                let error = SceneError { line: 1, column: 1, capacity: None, message };
                *scene.borrow_mut() = (frames(&[(Message::SceneError(error), tag)]), every, Instant::now());
                Vec::new()
            }
        });
        port.chatter = chatter;
        BoardLink::new(port, Duration::from_millis(300))
    }

    #[test]
    fn one_deadline_holds_across_a_board_that_keeps_sending_errors() {
        let mut link = chatty_board(board_info(), "bad", Duration::from_millis(10));
        let started = Instant::now();
        link.hello().unwrap();
        let said = link.draw("x\n".repeat(1000).as_bytes(), true, 1, &mut |_| {}).unwrap_err();
        assert!(matches!(said, LinkError::Unfinished(_)), "{said}");
        assert!(said.to_string().starts_with("the board's answer did not end within 0.3 s"), "{said}");
        let took = started.elapsed();
        assert!(took >= Duration::from_millis(300) && took < Duration::from_secs(1), "{took:?}");
        // Faster than the deadline, more errors than the scene can have.
        let mut link = chatty_board(board_info(), "bad", Duration::ZERO);
        let said = link.draw("x\n".repeat(1000).as_bytes(), true, 1, &mut |_| {}).unwrap_err().to_string();
        assert!(said.ends_with("it sent more errors than a scene of 2000 bytes can have (1064)"), "{said}");
        // An error longer than any of octrace's.
        let long: &'static str = "e".repeat(MAX_MESSAGE + 1).leak();
        let mut link = chatty_board(board_info(), long, Duration::ZERO);
        let said = link.draw(b"x", true, 1, &mut |_| {}).unwrap_err().to_string();
        assert!(said.ends_with("it sent an error message of 4097 bytes (octrace's are under 4096)"), "{said}");
    }

    #[test]
    fn one_deadline_holds_for_writes_to_a_line_that_drains_slowly_or_not_at_all() {
        // Nothing read for 100 ms, then a byte at a time: well within 1 s.
        let mut port = played_port(|tag, _| frames(&[(board_info(), tag)]));
        port.reads_from = Instant::now() + Duration::from_millis(100);
        let mut link = BoardLink::new(port, Duration::from_secs(1));
        assert_eq!(link.hello().unwrap().panel, PANEL);
        // Nothing read at all: said when the deadline comes.
        let mut port = played_port(|tag, _| frames(&[(board_info(), tag)]));
        port.reads_from = Instant::now() + Duration::from_secs(3600);
        let started = Instant::now();
        let said = BoardLink::new(port, Duration::from_millis(200)).hello().unwrap_err();
        assert!(said.to_string().starts_with("the board did not read what host-sim sent within 0.2 s"), "{said}");
        assert!(started.elapsed() < Duration::from_secs(1), "{:?}", started.elapsed());
    }

    #[test]
    fn the_boards_text_comes_with_its_control_characters_escaped() {
        let info = Message::Board(octrace_link::BoardInfo {
            panel: PANEL,
            max_scene: 100,
            profile: "P\u{1b}]0;title\u{7}",
            firmware: "\u{1b}[2Jfake\nhost-sim: ok",
            capacities: octrace_link::Capacities::new(&[octrace_link::Capacity { name: "\u{1b}[31m", count: 1 }]),
        });
        let mut link = played(move |tag, message| match message {
            Message::Hello => frames(&[(info, tag)]),
            _ => {
                let need = octrace_link::CapacityNeed { name: "\u{1b}[0m", needed: Some(2), holds: 1 };
                let error =
                    SceneError { line: 1, column: 1, capacity: Some(need), message: "\u{1b}[1A\rline 1 is fine" };
                frames(&[(Message::SceneError(error), tag), (Message::Rejected { errors: 1 }, tag)])
            }
        });
        let board = link.hello().unwrap();
        assert_eq!(board.firmware, "\\u{1b}[2Jfake\\u{a}host-sim: ok");
        assert_eq!(board.profile, "P\\u{1b}]0;title\\u{7}");
        assert_eq!(board.capacities, [("\\u{1b}[31m".to_string(), 1)]);
        let Answer::Rejected(errors) = link.draw(b"x", true, 1, &mut |_| {}).unwrap() else { panic!("rejected") };
        assert_eq!(errors[0].message, "\\u{1b}[1A\\u{d}line 1 is fine");
        assert_eq!(errors[0].capacity, Some(("\\u{1b}[0m".to_string(), Some(2), 1)));
    }
}
