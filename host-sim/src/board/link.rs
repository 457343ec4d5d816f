//! The host's side of a conversation with one board over its serial line
//! (octrace-link's protocol, docs/board-protocol.md): its hello, then a
//! scene and the answer, each frame checked against what the board said
//! before.
//!
//! Invariants: the conversation, writes included, goes on while the board
//! moves it on and ends once the board stops doing so for the allowance
//! (`patience.rs`), or at the cap (`--timeout`) if one is set, however the
//! board trickles or floods; before the board answers this link's hello,
//! a frame answering another request (an earlier run's, another host's) is
//! skipped by its tag, a bounded number of them; after, every frame answers
//! this link's request; the board's panel is within the protocol's limits
//! and every drawing is at that panel, so nothing is set aside for a
//! picture the board only claims; every row arrives exactly once, in the
//! panel's format and width, before the board says it is done; the board's
//! errors are at most as many as the scene can have, each within the
//! scene's lines and of a bounded length; the board's text (names,
//! messages) reaches the caller with its control characters escaped.

use super::answer::{Answer, BoardDescription, BoardSceneError, BoardTiming, PlayedFrame, Progress};
use super::patience::{Expired, Patience, Step, Waits, LOADING, SILENCE};
use super::port::{Port, SerialLine};
use crate::terminal::shown;
use octrace_link::{Decoder, Message, Panel, Reason, VERSION};
use std::io;
use std::time::Duration;

/// Why talking to a board failed.
#[derive(Debug)]
pub enum LinkError {
    /// The port could not be opened, read or written.
    Io(io::Error),
    /// The board said nothing that moved the conversation on for `waited`,
    /// after `after` (None: it never answered).
    Silent {
        /// How long.
        waited: Duration,
        /// What it last did, as said to a user.
        after: Option<String>,
    },
    /// The board took nothing host-sim sent for `waited`, after `after`.
    Unread {
        /// How long.
        waited: Duration,
        /// What it last did.
        after: String,
    },
    /// The conversation did not end within the cap (`--timeout`).
    TimedOut(Duration),
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
            LinkError::Silent { waited, after: None } => write!(
                f,
                "no answer within {} s (is octrace's live firmware running there?)",
                waited.as_secs_f64()
            ),
            LinkError::Silent { waited, after: Some(after) } => {
                write!(f, "the board fell silent: nothing for {} s after {after}", waited.as_secs_f64())
            }
            LinkError::Unread { waited, after } => write!(
                f,
                "the board took nothing host-sim sent for {} s, after {after} (is octrace's live firmware running there?)",
                waited.as_secs_f64()
            ),
            LinkError::TimedOut(cap) => {
                write!(f, "the board's answer did not end within {} s (--timeout)", cap.as_secs_f64())
            }
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

/// The most frames host-sim skips before the board answers its hello (the
/// tail of an earlier run's answer, which the board's buffers bound to a
/// few hundred): a board that sends more answers no one.
const MAX_SKIPPED: u64 = 10_000;

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
    /// How long the link waits for the board now, and for what.
    patience: Patience,
    last_tag: u16,
    /// Whether the board has answered a request of this link: from then on
    /// every frame it sends is in answer to this link's requests.
    in_step: bool,
    /// Frames skipped before then.
    skipped: u64,
    /// The panel the board described: every drawing is at it.
    panel: Option<Panel>,
}

impl BoardLink<SerialLine> {
    /// Opens the serial port `path`, to wait for the board as `waits` says.
    pub fn open(path: &str, waits: Waits) -> Result<Self, LinkError> {
        let line = SerialLine::open(path)
            .map_err(|e| io::Error::new(e.kind(), format!("cannot open it as a serial port: {e}")))?;
        Ok(BoardLink::new(line, waits))
    }
}

impl<P: Port> BoardLink<P> {
    /// A link over `port` that waits for the board while it moves the
    /// conversation on (see `patience.rs`, times `waits.patience`), and
    /// ends it within `waits.cap` from now (every request sent and every
    /// answer received), if one is given.
    pub fn new(mut port: P, waits: Waits) -> Self {
        // Tags of this run unlike an earlier run's, whose answers may still
        // be on the way.
        let clock = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
        let last_tag = (clock.subsec_nanos() ^ std::process::id()) as u16;
        let patience = Patience::new(port.now(), waits);
        BoardLink {
            port,
            decoder: Decoder::new(vec![0; MAX_FRAME]),
            input: Vec::new(),
            taken: 0,
            patience,
            last_tag,
            in_step: false,
            skipped: 0,
            panel: None,
        }
    }

    /// The next request's tag (never 0, which refusals of unreadable frames carry).
    fn next_tag(&mut self) -> u16 {
        self.last_tag = self.last_tag.wrapping_add(1).max(1);
        self.last_tag
    }

    /// The board did `step`, moving the conversation on; it may then say
    /// nothing that does so for `allowance`.
    fn moved(&mut self, step: Step, allowance: Duration) {
        let now = self.port.now();
        self.patience.moved(now, step, allowance);
    }

    /// The error of a wait that has ended, if it has (`writing`: a wait
    /// for the board to take what host-sim sends).
    fn expired(&mut self, writing: bool) -> Option<LinkError> {
        let now = self.port.now();
        Some(match self.patience.expired(now)? {
            Expired::Capped(cap) if self.patience.last() == Step::Opened => {
                LinkError::Silent { waited: cap, after: None }
            }
            Expired::Capped(cap) => LinkError::TimedOut(cap),
            Expired::Silent { waited, after, idle } if writing => {
                LinkError::Unread { waited, after: said(after, idle) }
            }
            Expired::Silent { waited, after: Step::Opened, .. } => LinkError::Silent { waited, after: None },
            Expired::Silent { waited, after, idle } => LinkError::Silent { waited, after: Some(said(after, idle)) },
        })
    }

    /// Sends `message` as the request `tag`, however slowly the board
    /// reads (each byte it takes moves the conversation on); once it has
    /// taken all of it, it does `then`'s step and may say nothing for
    /// `then`'s allowance.
    fn send(&mut self, tag: u16, message: &Message<'_>, then: (Step, Duration)) -> Result<(), LinkError> {
        let mut frame = Vec::new();
        message.encode(tag, &mut frame)?;
        let mut sent = 0;
        while sent < frame.len() {
            if let Some(e) = self.expired(true) {
                return Err(e);
            }
            match self.port.write(&frame[sent..]) {
                Ok(0) => std::thread::sleep(Duration::from_millis(5)),
                Ok(n) => {
                    sent += n;
                    if sent < frame.len() {
                        self.moved(Step::Took { taken: sent, of: frame.len() }, SILENCE);
                    }
                }
                Err(e) if waiting(&e) => {}
                Err(e) => return Err(LinkError::Io(e)),
            }
        }
        self.port.flush()?;
        self.moved(then.0, then.1);
        Ok(())
    }

    /// Asks the board what it is; the first request of a link, which
    /// brings the board in step whatever it was doing. A panel beyond the
    /// protocol's limits is refused here.
    pub fn hello(&mut self) -> Result<BoardDescription, LinkError> {
        self.port.discard_input()?;
        let tag = self.next_tag();
        // Nothing from the board yet: silence is no answer.
        self.send(tag, &Message::Hello, (Step::Opened, SILENCE))?;
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
        self.moved(Step::Described, SILENCE);
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
        self.send(tag, &Message::Scene { pixels, text }, (Step::TookScene, LOADING))?;
        // An error at the end of the text is on the line after its last.
        let lines = text.iter().filter(|&&byte| byte == b'\n').count() + 1;
        let mut errors = Vec::new();
        // Which rows of the drawing have come, once it began, and how many.
        let mut drawing: Option<Vec<bool>> = None;
        let mut drawn = 0;
        loop {
            match (self.receive(tag)?, &mut drawing) {
                (Message::SceneError(e), None) => {
                    if errors.len() == most_errors(text.len()) {
                        return Err(LinkError::Protocol(format!(
                            "it sent more errors than a scene of {} bytes can have ({})",
                            text.len(),
                            errors.len()
                        )));
                    }
                    if e.line as usize > lines {
                        return Err(LinkError::Protocol(format!(
                            "it sent an error at line {} of a scene of {lines} lines",
                            e.line
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
                    // Errors are bounded, not progress: the load's wait goes on.
                    self.patience.idle_frame();
                }
                (Message::Rejected { errors: count }, None) if count as usize == errors.len() && count > 0 => {
                    return Ok(Answer::Rejected(errors));
                }
                (Message::Rejected { errors: count }, None) => {
                    let sent = errors.len();
                    return Err(LinkError::Protocol(format!("it counted {count} errors of the scene and sent {sent}")));
                }
                (Message::Drawing { panel: drawn_at, pixels: with_pixels, frames }, None) if errors.is_empty() => {
                    if drawn_at != panel {
                        return Err(LinkError::Protocol(format!(
                            "it draws at {}x{} {}, but described a {}x{} {} panel",
                            drawn_at.width, drawn_at.height, drawn_at.format, panel.width, panel.height, panel.format
                        )));
                    }
                    if with_pixels != pixels {
                        return Err(LinkError::Protocol(format!("rows with pixels: {with_pixels}, asked: {pixels}")));
                    }
                    if frames > 0 {
                        // It loads the first frame without a word.
                        self.moved(Step::Playing { frames }, LOADING);
                        progress(Progress::Playing { panel, frames });
                        return self.follow(tag, panel, pixels, frames, follow.max(1), progress);
                    }
                    self.moved(Step::Began { rows: panel.height }, SILENCE);
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
                    drawn += 1;
                    progress(Progress::Row { y, pixels: row });
                    self.moved(Step::Row { y, drawn, rows: panel.height }, SILENCE);
                }
                (Message::Working { elapsed }, Some(_)) => {
                    progress(Progress::Working { elapsed });
                    self.moved(Step::Working { elapsed }, SILENCE);
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
            // The frame the board draws now.
            let due = played.last().map_or(0, |last: &PlayedFrame| (last.frame + 1) % frames);
            match self.receive(tag)? {
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
                    self.moved(Step::Run { y, frame: due }, SILENCE);
                }
                Message::FrameDrawn { frame, traced, elapsed } => {
                    if frame != due {
                        return Err(LinkError::Protocol(format!("frame {frame} drawn where frame {due} was due")));
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
                    // The board loads the next frame without a word.
                    self.moved(Step::FrameDrawn { frame }, LOADING);
                }
                Message::Working { elapsed } => {
                    progress(Progress::Working { elapsed });
                    self.moved(Step::Working { elapsed }, SILENCE);
                }
                Message::Stopped { frames } => {
                    return Err(LinkError::Protocol(format!("it stopped playing after {frames} frames unasked")));
                }
                Message::Refused(reason) => return Err(refused(reason)),
                other => return Err(unexpected(other.kind(), "the animation's runs")),
            }
        }
        // Stopped as a host that starts stops it: the answer ends with
        // `stopped`, then the board describes itself. The board may be
        // loading a frame when the hello comes; what it sends before it
        // stops is no progress, and bounded.
        let hello = self.next_tag();
        self.send(hello, &Message::Hello, (Step::TookStop, LOADING))?;
        let mut after_stop = 0u64;
        loop {
            match self.receive(tag)? {
                Message::Run { .. } | Message::FrameDrawn { .. } | Message::Working { .. } => {}
                Message::Stopped { .. } => break,
                other => return Err(unexpected(other.kind(), "the end of the animation")),
            }
            after_stop += 1;
            self.patience.idle_frame();
            if after_stop > MAX_SKIPPED {
                return Err(LinkError::Protocol(format!("it played on for {after_stop} frames after the hello")));
            }
        }
        self.moved(Step::Stopped, SILENCE);
        match self.receive(hello)? {
            Message::Board(_) => Ok(Answer::Played { panel, frames: played }),
            other => Err(unexpected(other.kind(), "the board's description")),
        }
    }

    /// The next message answering request `tag`, skipping (before the
    /// board is in step) any other, while the wait lasts.
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
                Some(Ok(frame))
                    if frame.tag == tag
                        || (in_step && frame.tag == 0 && matches!(frame.message, Message::Refused(_))) =>
                {
                    true
                }
                // Once in step, the board answers this link's requests in
                // order: nothing else is due.
                Some(Ok(frame)) if in_step => {
                    return Err(LinkError::Protocol(format!(
                        "it sent a {} message answering request {}, where request {tag}'s answer was due",
                        frame.message.kind(),
                        frame.tag
                    )));
                }
                // The tail of an earlier run's answer: a few hundred frames at most.
                Some(Ok(_)) => {
                    self.skipped += 1;
                    self.patience.idle_frame();
                    if self.skipped > MAX_SKIPPED {
                        return Err(LinkError::Protocol(format!(
                            "it sent {} frames answering no request of host-sim's before its hello's answer",
                            self.skipped
                        )));
                    }
                    false
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

    /// Reads what the port has, while the wait lasts.
    fn fill(&mut self) -> Result<(), LinkError> {
        self.input.resize(4096, 0);
        self.taken = 0;
        loop {
            if let Some(e) = self.expired(false) {
                self.input.clear();
                return Err(e);
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

/// What the board last did, as a user reads it, with the frames it sent
/// since that did not move the conversation on.
fn said(after: Step, idle: u64) -> String {
    match idle {
        0 => after.to_string(),
        idle => format!("{after}, and {idle} frames since that did not move it on"),
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
    use octrace_link::{PixelFormat, SceneError, Timing};
    use std::cell::{Cell, RefCell};
    use std::collections::VecDeque;
    use std::io::{Read, Write};
    use std::rc::Rc;
    use std::time::Instant;

    /// How long a read or write of a serial port waits for the board
    /// before it gives up: [`SerialLine`]'s.
    const PORT_WAIT: Duration = Duration::from_millis(50);

    /// A board's answer to a frame: pieces of bytes, each after a pause of
    /// the board's (the first from the frame's last byte).
    type Timed = Vec<(Duration, Vec<u8>)>;

    /// What a board keeps sending once set: the bytes, how often, and until
    /// when (on the board's clock).
    type Chatter = Rc<RefCell<Option<(Vec<u8>, Duration, Duration)>>>;

    /// A board played by a function, on a clock of its own that only the
    /// port's waits move (a read with nothing to read, a write the board
    /// does not take): each frame host-sim writes is answered with the
    /// pieces it returns, each readable from its time. It takes nothing
    /// before `reads_from`, then a byte every `byte_every`; once `chatter`
    /// is set it sends it again and again.
    struct Played<F> {
        decoder: Decoder<Vec<u8>>,
        answer: F,
        out: VecDeque<(Duration, Vec<u8>)>,
        clock: Rc<Cell<Duration>>,
        start: Instant,
        reads_from: Duration,
        byte_every: Duration,
        chatter: Chatter,
        chatter_next: Option<Duration>,
    }

    impl<F> Played<F> {
        /// Waits for what comes next, a port's wait at most.
        fn wait(&mut self, next: Option<Duration>) {
            let now = self.clock.get();
            let step =
                next.map_or(PORT_WAIT, |next| next.saturating_sub(now).clamp(Duration::from_micros(1), PORT_WAIT));
            self.clock.set(now + step);
        }
    }

    impl<F: FnMut(u16, Message<'_>) -> Timed> Write for Played<F> {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            if self.clock.get() < self.reads_from {
                self.wait(Some(self.reads_from));
                return Err(io::ErrorKind::TimedOut.into());
            }
            // A byte at a time: a line that drains slowly.
            let Some(&byte) = buf.first() else { return Ok(0) };
            self.clock.set(self.clock.get() + self.byte_every);
            if let Some(Ok(frame)) = self.decoder.push(byte) {
                let mut at = self.clock.get();
                for (pause, bytes) in (self.answer)(frame.tag, frame.message) {
                    at += pause;
                    self.out.push_back((at, bytes));
                }
            }
            Ok(1)
        }

        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl<F> Read for Played<F> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let now = self.clock.get();
            if let Some((due, piece)) = self.out.front_mut().filter(|(due, _)| *due <= now) {
                let _ = due;
                let n = buf.len().min(piece.len());
                for (slot, byte) in buf.iter_mut().zip(piece.drain(..n)) {
                    *slot = byte;
                }
                if piece.is_empty() {
                    self.out.pop_front();
                }
                return Ok(n);
            }
            let chatter = self.chatter.borrow().clone();
            if let Some((bytes, every, until)) = chatter.filter(|&(_, _, until)| now < until) {
                let next = *self.chatter_next.get_or_insert(now);
                if next <= now {
                    // Before what comes later.
                    let at = self.out.iter().position(|&(due, _)| due > now).unwrap_or(self.out.len());
                    self.out.insert(at, (now, bytes));
                    self.chatter_next = Some(now + every);
                    return self.read(buf);
                }
                let _ = until;
            }
            let next = self.out.front().map(|&(due, _)| due);
            let next = match (next, self.chatter_next.filter(|_| self.chatter.borrow().is_some())) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
            self.wait(next);
            Err(io::ErrorKind::TimedOut.into())
        }
    }

    impl<F: FnMut(u16, Message<'_>) -> Timed> Port for Played<F> {
        fn discard_input(&mut self) -> io::Result<()> {
            let now = self.clock.get();
            self.out.retain(|&(due, _)| due > now);
            Ok(())
        }

        fn now(&mut self) -> Instant {
            self.start + self.clock.get()
        }
    }

    fn played_port<F: FnMut(u16, Message<'_>) -> Timed>(answer: F) -> Played<F> {
        Played {
            decoder: Decoder::new(vec![0; 4096]),
            answer,
            out: VecDeque::new(),
            clock: Rc::new(Cell::new(Duration::ZERO)),
            start: Instant::now(),
            reads_from: Duration::ZERO,
            byte_every: Duration::ZERO,
            chatter: Rc::new(RefCell::new(None)),
            chatter_next: None,
        }
    }

    /// A link to a board played by `answer`, with no cap; and the board's clock.
    fn played(answer: impl FnMut(u16, Message<'_>) -> Timed) -> (BoardLink<impl Port>, Rc<Cell<Duration>>) {
        let port = played_port(answer);
        let clock = port.clock.clone();
        (BoardLink::new(port, Waits::BOARD), clock)
    }

    fn frames(messages: &[(Message<'_>, u16)]) -> Vec<u8> {
        let mut bytes = Vec::new();
        for (message, tag) in messages {
            message.encode(*tag, &mut bytes).unwrap();
        }
        bytes
    }

    /// `bytes`, sent at once.
    fn at_once(bytes: Vec<u8>) -> Timed {
        vec![(Duration::ZERO, bytes)]
    }

    fn seconds(s: u64) -> Duration {
        Duration::from_secs(s)
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

    /// A board that answers hello at once and then each scene with `answer(tag)`.
    fn drawing_board(mut answer: impl FnMut(u16) -> Timed) -> (BoardLink<impl Port>, Rc<Cell<Duration>>) {
        played(move |tag, message| match message {
            Message::Hello => at_once(frames(&[(board_info(), tag)])),
            _ => answer(tag),
        })
    }

    fn draw(link: &mut BoardLink<impl Port>) -> Result<Answer, LinkError> {
        link.hello().unwrap();
        link.draw(b"scene", true, 1, &mut |_| {})
    }

    const PIXELS: [u8; 4] = [0; 4];

    fn drawing_message(frames: u32) -> Message<'static> {
        Message::Drawing { panel: PANEL, pixels: true, frames }
    }

    fn row(y: u16) -> Message<'static> {
        Message::Row { y, pixels: &PIXELS }
    }

    #[test]
    fn what_came_before_the_boards_answer_to_hello_is_skipped() {
        let (mut link, _) = played(|tag, _| {
            let mut bytes = frames(&[(Message::Row { y: 3, pixels: &[] }, tag.wrapping_sub(1))]);
            bytes.extend_from_slice(b"\0garbage\0");
            bytes.extend(frames(&[(Message::Refused(Reason::Undecodable { length: 7 }), 0), (board_info(), tag)]));
            at_once(bytes)
        });
        assert_eq!(link.hello().unwrap().panel, PANEL);
    }

    #[test]
    fn a_drawing_is_followed_to_its_last_row() {
        let (mut link, _) = drawing_board(|tag| {
            at_once(frames(&[
                (drawing_message(0), tag),
                (row(1), tag),
                (row(0), tag),
                (Message::Done(Timing::NONE), tag),
            ]))
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
            let (mut link, _) = drawing_board(|tag| {
                let mut messages = vec![(drawing_message(0), tag)];
                messages.extend(rows.iter().map(|&(y, pixels)| (Message::Row { y, pixels }, tag)));
                messages.push((Message::Done(Timing::NONE), tag));
                at_once(frames(&messages))
            });
            let error = draw(&mut link).unwrap_err();
            assert!(matches!(&error, LinkError::Protocol(what) if what == said), "{said}: {error}");
        }
    }

    #[test]
    fn the_errors_come_all_and_counted_each_within_the_scenes_lines() {
        let error = |line| SceneError { line, column: 2, capacity: None, message: "bad" };
        let (mut link, _) = drawing_board(|tag| {
            at_once(frames(&[
                (Message::SceneError(error(1)), tag),
                (Message::SceneError(error(0)), tag),
                (Message::Rejected { errors: 2 }, tag),
            ]))
        });
        let Answer::Rejected(errors) = draw(&mut link).unwrap() else { panic!("rejected") };
        let located: Vec<String> = errors.iter().map(|e| e.located("s.txt")).collect();
        assert_eq!(located, ["s.txt:1:2: bad", "s.txt: bad"]);
        let (mut link, _) = drawing_board(|tag| {
            at_once(frames(&[(Message::SceneError(error(1)), tag), (Message::Rejected { errors: 3 }, tag)]))
        });
        assert!(matches!(draw(&mut link), Err(LinkError::Protocol(_))));
        // At the line after the text's last (its end), not beyond.
        for (line, fine) in [(2, true), (3, false)] {
            let (mut link, _) = drawing_board(move |tag| {
                at_once(frames(&[(Message::SceneError(error(line)), tag), (Message::Rejected { errors: 1 }, tag)]))
            });
            link.hello().unwrap();
            let answer = link.draw(b"SPHERE\n", true, 1, &mut |_| {});
            match fine {
                true => assert!(matches!(answer, Ok(Answer::Rejected(_))), "{answer:?}"),
                false => {
                    let said = answer.unwrap_err().to_string();
                    assert!(said.ends_with("it sent an error at line 3 of a scene of 2 lines"), "{said}");
                }
            }
        }
    }

    #[test]
    fn once_in_step_a_refusal_without_a_tag_is_of_our_frame_and_garbage_is_an_error() {
        let checksum = Reason::BadChecksum { sent: 1, computed: 2 };
        let (mut link, _) = drawing_board(|_| at_once(frames(&[(Message::Refused(checksum), 0)])));
        assert!(matches!(draw(&mut link), Err(LinkError::Refused(reason)) if reason == checksum));
        let (mut link, _) = drawing_board(|_| at_once(b"\0garbage\0".to_vec()));
        assert!(matches!(draw(&mut link), Err(LinkError::Protocol(_))));
    }

    #[test]
    fn once_in_step_an_answer_to_another_request_is_an_error_and_before_only_so_many_are_skipped() {
        // The hello answered again, with the hello's tag, where the
        // scene's answer is due.
        let (mut link, _) = played(|tag, message| match message {
            Message::Hello => at_once(frames(&[(board_info(), tag)])),
            _ => at_once(frames(&[(board_info(), tag - 1)])),
        });
        let said = draw(&mut link).unwrap_err().to_string();
        assert!(said.contains("it sent a board message answering request "), "{said}");
        assert!(said.ends_with("'s answer was due"), "{said}");
        // Descriptions answering no request of ours, without end, before
        // the hello's answer: no answer, at most so many skipped.
        let port = played_port(|_, _| Vec::new());
        let clock = port.clock.clone();
        let other = frames(&[(board_info(), 0xfff)]);
        *port.chatter.borrow_mut() = Some((other, Duration::from_micros(100), seconds(3600)));
        let mut link = BoardLink::new(port, Waits::BOARD);
        let said = link.hello().unwrap_err().to_string();
        assert!(
            said.ends_with("it sent 10001 frames answering no request of host-sim's before its hello's answer"),
            "{said}"
        );
        assert!(clock.get() < seconds(2), "{:?}", clock.get());
    }

    #[test]
    fn a_board_of_another_version_and_a_silent_one_are_said_as_such() {
        let (mut link, _) = played(|tag, _| {
            let mut bytes = Vec::new();
            octrace_link::encode_raw(VERSION + 1, octrace_link::Kind::Board.byte(), tag, &[], &mut bytes).unwrap();
            at_once(bytes)
        });
        assert!(matches!(link.hello(), Err(LinkError::Version { board }) if board == VERSION + 1));
        let refusal = Message::Refused(Reason::WrongVersion { expected: 7, found: VERSION });
        let (mut link, _) = played(move |tag, _| at_once(frames(&[(refusal, tag)])));
        assert!(matches!(link.hello(), Err(LinkError::Version { board: 7 })));
        // Said when the board has been silent for 8 s (the protocol's
        // allowance), not later.
        let (mut link, clock) = played(|_, _| Vec::new());
        let silent = link.hello().unwrap_err();
        assert!(silent.to_string().starts_with("no answer within 8 s"), "{silent}");
        assert!(clock.get() >= seconds(8) && clock.get() <= seconds(8) + PORT_WAIT, "{:?}", clock.get());
    }

    #[test]
    fn a_board_gone_silent_mid_drawing_is_said_within_10_s_with_what_it_did_last() {
        let (mut link, clock) = drawing_board(|tag| {
            vec![(Duration::ZERO, frames(&[(drawing_message(0), tag)])), (seconds(5), frames(&[(row(1), tag)]))]
        });
        link.hello().unwrap();
        let mut rows_at = Vec::new();
        let said = link
            .draw(b"scene", true, 1, &mut |step| {
                if let Progress::Row { .. } = step {
                    rows_at.push(clock.get());
                }
            })
            .unwrap_err();
        assert_eq!(said.to_string(), "the board fell silent: nothing for 8 s after row 1 (1 of 2 rows drawn)");
        // Given up 8 s after the row, with a port's wait at most: within
        // 10 s of it.
        let waited = clock.get() - rows_at[0];
        assert!(waited >= seconds(8) && waited <= seconds(8) + PORT_WAIT, "{waited:?}");
    }

    #[test]
    fn a_board_at_a_drawing_of_hours_is_followed_while_it_says_it_is_working_and_not_after() {
        // An hour a row, `working` every second meanwhile.
        let chatter: Chatter = Rc::new(RefCell::new(None));
        let during = chatter.clone();
        let mut port = played_port(move |tag, message| match message {
            Message::Hello => at_once(frames(&[(board_info(), tag)])),
            _ => {
                let working = frames(&[(Message::Working { elapsed: Some(seconds(1)) }, tag)]);
                *during.borrow_mut() = Some((working, seconds(1), seconds(7200)));
                vec![
                    (Duration::ZERO, frames(&[(drawing_message(0), tag)])),
                    (seconds(3600), frames(&[(row(0), tag)])),
                    (seconds(3599), frames(&[(row(1), tag), (Message::Done(Timing::NONE), tag)])),
                ]
            }
        });
        port.chatter = chatter;
        let clock = port.clock.clone();
        let mut link = BoardLink::new(port, Waits::BOARD);
        let mut said_working = 0;
        link.hello().unwrap();
        let answer =
            link.draw(b"scene", true, 1, &mut |step| said_working += matches!(step, Progress::Working { .. }) as u32);
        assert_eq!(answer.unwrap(), Answer::Drawn { panel: PANEL, timing: BoardTiming::default() });
        assert!(clock.get() >= seconds(7199), "{:?}", clock.get());
        assert!(said_working >= 7000, "{said_working}");
        // The same board, whose word stops after 3 s: given up 8 s later.
        let chatter: Chatter = Rc::new(RefCell::new(None));
        let during = chatter.clone();
        let mut port = played_port(move |tag, message| match message {
            Message::Hello => at_once(frames(&[(board_info(), tag)])),
            _ => {
                let working = frames(&[(Message::Working { elapsed: Some(Duration::from_millis(2500)) }, tag)]);
                *during.borrow_mut() = Some((working, seconds(1), seconds(3)));
                at_once(frames(&[(drawing_message(0), tag)]))
            }
        });
        port.chatter = chatter;
        let clock = port.clock.clone();
        let mut link = BoardLink::new(port, Waits::BOARD);
        link.hello().unwrap();
        let said = link.draw(b"scene", true, 1, &mut |_| {}).unwrap_err().to_string();
        assert_eq!(
            said,
            "the board fell silent: nothing for 8 s after it said it was still working, 2.500 s into the scene by its clock"
        );
        assert!(clock.get() >= seconds(10) && clock.get() <= seconds(10) + PORT_WAIT, "{:?}", clock.get());
    }

    #[test]
    fn a_board_loading_a_scene_is_given_two_minutes_without_a_word() {
        for (load, drawn) in [(100, true), (121, false)] {
            let (mut link, clock) = drawing_board(move |tag| {
                vec![(
                    seconds(load),
                    frames(&[
                        (drawing_message(0), tag),
                        (row(0), tag),
                        (row(1), tag),
                        (Message::Done(Timing::NONE), tag),
                    ]),
                )]
            });
            let answer = draw(&mut link);
            match drawn {
                true => assert!(answer.is_ok(), "{answer:?}"),
                false => {
                    let said = answer.unwrap_err().to_string();
                    let want = "the board fell silent: nothing for 120 s after it took the scene \
                                (a board loads a scene without a word)";
                    assert_eq!(said, want);
                    assert!(clock.get() <= seconds(120) + PORT_WAIT, "{:?}", clock.get());
                }
            }
        }
    }

    /// `frames`' runs covering the 2×2 panel, then `frame-drawn(frame)`.
    fn whole_frame(frame: u32, tag: u16) -> Vec<u8> {
        let run = |y| Message::Run { y, x: 0, width: 2, pixels: &PIXELS };
        frames(&[(run(0), tag), (run(1), tag), (Message::FrameDrawn { frame, traced: 4, elapsed: None }, tag)])
    }

    #[test]
    fn an_animation_is_waited_for_while_it_loads_each_frame_and_no_longer_once_stopped() {
        // A minute and a half to load each frame.
        let (mut link, _) = played(|tag, message| match message {
            Message::Hello if tag == 2 => at_once(frames(&[(board_info(), tag)])),
            Message::Hello => at_once(frames(&[(Message::Stopped { frames: 2 }, tag - 1), (board_info(), tag)])),
            _ => vec![
                (Duration::ZERO, frames(&[(drawing_message(2), tag)])),
                (seconds(90), whole_frame(0, tag)),
                (seconds(90), whole_frame(1, tag)),
            ],
        });
        // Tags 2, 3 and 4: the link's hello, the scene, the stopping hello.
        link.last_tag = 1;
        link.hello().unwrap();
        let answer = link.draw(b"scene", true, 2, &mut |_| {}).unwrap();
        assert!(matches!(answer, Answer::Played { ref frames, .. } if frames.len() == 2), "{answer:?}");
        // A board that plays on after the hello: no progress, and bounded.
        let chatter: Chatter = Rc::new(RefCell::new(None));
        let after_hello = chatter.clone();
        let mut port = played_port(move |tag, message| match message {
            Message::Hello if tag == 2 => at_once(frames(&[(board_info(), tag)])),
            Message::Hello => {
                let run = frames(&[(Message::Run { y: 0, x: 0, width: 2, pixels: &PIXELS }, tag - 1)]);
                *after_hello.borrow_mut() = Some((run, Duration::from_micros(100), seconds(3600)));
                Vec::new()
            }
            _ => at_once([frames(&[(drawing_message(2), tag)]), whole_frame(0, tag)].concat()),
        });
        port.chatter = chatter;
        let clock = port.clock.clone();
        let mut link = BoardLink::new(port, Waits::BOARD);
        link.last_tag = 1;
        link.hello().unwrap();
        let said = link.draw(b"scene", true, 1, &mut |_| {}).unwrap_err().to_string();
        assert!(said.ends_with("it played on for 10001 frames after the hello"), "{said}");
        assert!(clock.get() < seconds(5), "{:?}", clock.get());
    }

    #[test]
    fn a_drawing_cut_short_by_another_host_is_said() {
        let (mut link, _) =
            drawing_board(|tag| at_once(frames(&[(drawing_message(0), tag), (Message::Cancelled { rows: 0 }, tag)])));
        assert!(matches!(draw(&mut link), Err(LinkError::Cancelled { rows: 0 })));
    }

    #[test]
    fn a_panel_beyond_the_protocols_limits_or_another_than_described_is_refused_before_anything_is_kept() {
        for (width, height) in [(0, 0), (0, 240), (Panel::MAX_SIDE + 1, 1), (65535, 65535)] {
            let panel = Panel { width, height, format: PixelFormat::Rgb565 };
            let (mut link, _) = played(move |tag, _| {
                at_once(frames(&[(
                    Message::Board(octrace_link::BoardInfo {
                        panel,
                        max_scene: 100,
                        profile: "P",
                        firmware: "f",
                        capacities: octrace_link::Capacities::new(&[]),
                    }),
                    tag,
                )]))
            });
            let said = link.hello().unwrap_err().to_string();
            let want = format!("it describes a {width}x{height} panel; a panel's sides are 1 to 16384 pixels");
            assert!(said.ends_with(&want), "{said}");
            // A drawing at any panel but the one described.
            let (mut link, _) = drawing_board(move |tag| {
                at_once(frames(&[
                    (Message::Drawing { panel, pixels: true, frames: 0 }, tag),
                    (Message::Done(Timing::NONE), tag),
                ]))
            });
            let said = draw(&mut link).unwrap_err().to_string();
            let want = format!("it draws at {width}x{height} rgb565, but described a 2x2 rgb565 panel");
            assert!(said.ends_with(&want), "{said}");
        }
    }

    /// A board that describes itself, then answers a scene with scene
    /// errors `message`, one every `every`, and never ends; capped at `cap`.
    fn chatty_board(
        message: &'static str,
        every: Duration,
        cap: Option<Duration>,
    ) -> (BoardLink<impl Port>, Rc<Cell<Duration>>) {
        let chatter: Chatter = Rc::new(RefCell::new(None));
        let scene = chatter.clone();
        let mut port = played_port(move |tag, received| match received {
            Message::Hello => at_once(frames(&[(board_info(), tag)])),
            _ => {
                let error = SceneError { line: 1, column: 1, capacity: None, message };
                *scene.borrow_mut() = Some((frames(&[(Message::SceneError(error), tag)]), every, seconds(1 << 20)));
                Vec::new()
            }
        });
        port.chatter = chatter;
        let clock = port.clock.clone();
        (BoardLink::new(port, Waits::capped(cap)), clock)
    }

    #[test]
    fn a_board_that_keeps_sending_errors_ends_by_their_count_the_silence_or_the_cap() {
        let scene = "x\n".repeat(1000);
        // Faster than the wait, more errors than the scene can have.
        let (mut link, _) = chatty_board("bad", Duration::from_millis(10), None);
        let said = link.draw(scene.as_bytes(), true, 1, &mut |_| {}).unwrap_err().to_string();
        assert!(said.ends_with("it sent more errors than a scene of 2000 bytes can have (1064)"), "{said}");
        // Slower: errors move nothing on, so the load's two minutes end it.
        let (mut link, clock) = chatty_board("bad", seconds(1), None);
        link.hello().unwrap();
        let sent = clock.get();
        let said = link.draw(scene.as_bytes(), true, 1, &mut |_| {}).unwrap_err().to_string();
        let want = "the board fell silent: nothing for 120 s after it took the scene \
                    (a board loads a scene without a word), and 120 frames since that did not move it on";
        assert_eq!(said, want);
        assert!(clock.get() - sent <= seconds(120) + PORT_WAIT, "{:?}", clock.get() - sent);
        // With a cap: at the cap.
        let (mut link, clock) = chatty_board("bad", Duration::from_millis(10), Some(Duration::from_millis(300)));
        let said = link.draw(scene.as_bytes(), true, 1, &mut |_| {}).unwrap_err();
        assert!(matches!(said, LinkError::TimedOut(_)), "{said}");
        assert_eq!(said.to_string(), "the board's answer did not end within 0.3 s (--timeout)");
        assert!(clock.get() >= Duration::from_millis(300) && clock.get() <= Duration::from_millis(350));
        // An error longer than any of octrace's.
        let long: &'static str = "e".repeat(MAX_MESSAGE + 1).leak();
        let (mut link, _) = chatty_board(long, Duration::ZERO, None);
        let said = link.draw(b"x", true, 1, &mut |_| {}).unwrap_err().to_string();
        assert!(said.ends_with("it sent an error message of 4097 bytes (octrace's are under 4096)"), "{said}");
    }

    #[test]
    fn a_board_reading_slowly_is_waited_for_while_it_reads_and_not_when_it_stops() {
        // A byte every 100 ms: the 1 KB scene takes nearly two minutes.
        let scene = "x".repeat(1000);
        let mut port = played_port(|tag, message| match message {
            Message::Hello => at_once(frames(&[(board_info(), tag)])),
            _ => at_once(frames(&[
                (drawing_message(0), tag),
                (row(0), tag),
                (row(1), tag),
                (Message::Done(Timing::NONE), tag),
            ])),
        });
        port.byte_every = Duration::from_millis(100);
        let clock = port.clock.clone();
        let mut link = BoardLink::new(port, Waits::BOARD);
        assert!(draw_text(&mut link, &scene).is_ok());
        assert!(clock.get() > seconds(100), "{:?}", clock.get());
        // Nothing read at all: said 8 s after the port opened.
        let mut port = played_port(|tag, _| at_once(frames(&[(board_info(), tag)])));
        port.reads_from = seconds(3600);
        let clock = port.clock.clone();
        let said = BoardLink::new(port, Waits::BOARD).hello().unwrap_err().to_string();
        assert_eq!(
            said,
            "the board took nothing host-sim sent for 8 s, after the port was opened (is octrace's live firmware running there?)"
        );
        assert!(clock.get() >= seconds(8) && clock.get() <= seconds(8) + PORT_WAIT, "{:?}", clock.get());
        // Half read, then nothing.
        let port = played_port(|tag, _| at_once(frames(&[(board_info(), tag)])));
        let mut link = BoardLink::new(port, Waits::BOARD);
        link.hello().unwrap();
        link.port.reads_from = seconds(3600);
        let said = link.draw(scene.as_bytes(), true, 1, &mut |_| {}).unwrap_err().to_string();
        assert!(said.starts_with("the board took nothing host-sim sent for 8 s, after it described itself"), "{said}");
    }

    fn draw_text(link: &mut BoardLink<impl Port>, text: &str) -> Result<Answer, LinkError> {
        link.draw(text.as_bytes(), true, 1, &mut |_| {})
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
        let (mut link, _) = played(move |tag, message| match message {
            Message::Hello => at_once(frames(&[(info, tag)])),
            _ => {
                let need = octrace_link::CapacityNeed { name: "\u{1b}[0m", needed: Some(2), holds: 1 };
                let error =
                    SceneError { line: 1, column: 1, capacity: Some(need), message: "\u{1b}[1A\rline 1 is fine" };
                at_once(frames(&[(Message::SceneError(error), tag), (Message::Rejected { errors: 1 }, tag)]))
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
