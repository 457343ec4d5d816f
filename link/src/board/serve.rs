//! The board's loop, which a firmware runs for ever around its hardware: a
//! frame read from the line byte by byte, answered, a scene drawn while
//! the line is watched, each answer written as fast as the host takes it.
//! The firmware keeps only the hardware: its [`Line`] (the serial port and
//! its rings, a clock, sleep, a watchdog) and how it renders a drawing's
//! rows (one core, two).
//!
//! Invariants:
//! - every frame that ends on the line is answered, in the order they came:
//!   one that ends while a scene is drawn stops the drawing (`cancelled`,
//!   unless its last row was drawn: `done`), then is answered;
//! - the bytes of a frame that ends while drawing stay on the line, unread,
//!   until it is answered (the decoder holds one frame);
//! - a host that does not take an answer is waited for at most
//!   [`STALL_GRACE_US`] beyond the time the answer takes at
//!   [`SLOWEST_HOST_BYTES_PER_SECOND`]; then the rest of that answer is
//!   dropped, what waits on the line for it too ([`Line::discard`]), and the
//!   next answer starts whole. A slow host cannot pace a drawing by more;
//! - a drawing goes on when its host stops taking rows (the panel shows the
//!   picture); only a frame from the host stops it;
//! - a drawing that has sent the host nothing for [`KEEP_ALIVE_US`] of the
//!   board's clock sends `working` at its next look at the line (every
//!   [`POLL_PERIOD_US`], between rays), so the host hears from a board at
//!   work at least that often, however long a pixel takes;
//! - an animation plays until a byte comes from the host (its text is the
//!   frame the decoder holds, which the next frame's bytes overwrite); each
//!   frame is loaded from that text, planned, drawn and closed by
//!   `frame-drawn`, and the animation by `stopped`.

use super::play;
use super::{Board, Drawing, Panel, Shown};
use crate::cobs::Sink;
use crate::decoder::{Decoder, Frame};
use crate::list::{Counter, Counters};
use crate::message::{Message, Timing};
use core::cell::RefCell;
use core::time::Duration;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::Rgb565;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::animation::Animation;
use octrace_core::profile::Profile;
use octrace_core::scene::Frames;
use octrace_core::Raytracer;

/// How long a board waits for a host that does not take its answer,
/// beyond what the answer's length allows at
/// [`SLOWEST_HOST_BYTES_PER_SECOND`]: a second.
pub const STALL_GRACE_US: u64 = 1_000_000;

/// How often a drawing reads the line at most: every millisecond of the
/// board's clock. [`Rows::poll`] is asked before every ray; between two
/// reads it only looks at the clock, so that the asks cost a drawing
/// nothing it can measure, and a frame stops it within a millisecond and a
/// ray.
pub const POLL_PERIOD_US: u64 = 1_000;

/// The longest a drawing goes without a word to the host, by the board's
/// clock: 40 ms. A drawing that has sent nothing (no row, no run) for this
/// long sends [`Message::Working`] at its next look at the line, so that a
/// host can tell a board at work on a pixel of hours from one that is gone
/// within seconds (docs/board-protocol.md, Timing), even on an emulated
/// board a hundred times slower than a Pico. A drawing whose rows come
/// more often sends none: the live firmware's rows of fig5_1 come within
/// it on both cores (at 20 ms it sent 56 `working`s there, 0.5 % of the
/// picture's time), fig5_3's all but one.
pub const KEEP_ALIVE_US: u64 = 40_000;

/// The slowest a host may take an answer and still get all of it: 16 KiB a
/// second (a USB full-speed port takes a megabyte; a drawing's rows with
/// pixels are a few tens of KiB a second on a Pico).
pub const SLOWEST_HOST_BYTES_PER_SECOND: u64 = 16 * 1024;

/// The longest one wait for room in the line lasts ([`Line::wait_for_room`]):
/// a millisecond, so that a board whose wake-up on the host's taking is
/// held back (its input full, its USB interrupt masked) still looks at
/// the line a thousand times a second, 64 KiB a second in USB packets.
const ROOM_WAIT_US: u64 = 1_000;

/// The board's serial line and the little else of its hardware the loop
/// needs: what a firmware implements (over its USB serial port's rings, on
/// a Pico), and a test or fuzz target on a host.
pub trait Line {
    /// The next byte from the host, if one has come; never waits.
    fn read(&mut self) -> Option<u8>;

    /// Takes as many of `bytes` as it has room for on their way to the
    /// host; never waits.
    fn write(&mut self, bytes: &[u8]) -> usize;

    /// Drops every byte taken by [`Line::write`] not yet gone to the host:
    /// the rest of an answer the host did not take.
    fn discard(&mut self);

    /// Microseconds by the board's clock.
    fn now_us(&mut self) -> u64;

    /// Nothing to do until the host sends: sleeps until a byte may have
    /// come (a firmware's `wfi`, its watchdog paused), or returns at once.
    /// False when no byte will ever come (a host's test, at its end).
    fn sleep(&mut self) -> bool;

    /// [`Line::write`] had no room: waits until the host may have taken
    /// some bytes or sent some, for at most `at_most_us` microseconds (the
    /// loop then looks at its clock again), so that a firmware sleeps
    /// (`wfi`) instead of spinning while a host is slow or not reading. By
    /// default returns at once.
    fn wait_for_room(&mut self, at_most_us: u64) {
        let _ = at_most_us;
    }

    /// The board is at work: called each time a drawing reads the line (at
    /// most every [`POLL_PERIOD_US`]), at every piece of an answer written
    /// and at every turn of a wait for the host to take it (a firmware
    /// feeds its watchdog here).
    fn alive(&mut self);

    /// The events the board's hardware counts over a scene's load and its
    /// render, which the `done` answer reports (a Pico: its bus fabric's
    /// contested accesses, `sram0_contested`); at most [`MAX_COUNTERS`].
    /// None by default.
    fn counter_names(&self) -> &'static [&'static str] {
        &[]
    }

    /// Each of [`Line::counter_names`]'s counts since the last call, into
    /// `counts` (as long as the names), and starts them again: called as a
    /// scene starts loading, as it starts drawing and once it is drawn.
    fn take_counts(&mut self, counts: &mut [u32]) {
        let _ = counts;
    }
}

/// The most counters a [`Line`] reports.
pub const MAX_COUNTERS: usize = 8;

/// What [`Link::serve`] did with a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Served {
    /// Answered with a refusal, the board's description or a scene's errors.
    Answered,
    /// A scene drawn: `rows` rows, in order; fewer than the panel's height
    /// when a frame came (it is answered next).
    Drawn {
        /// Rows drawn.
        rows: u16,
    },
    /// An animation played until the host sent something (it is answered
    /// next).
    Played {
        /// Frames drawn whole.
        frames: u32,
    },
    /// The host did not take the answer: the rest of it was dropped.
    Stalled,
}

/// The board's end of the link: its [`Board`], its decoder (a board's:
/// [`Decoder::for_board`]), whether a frame came while it drew, and the
/// animation it plays animated scenes in.
#[derive(Debug)]
pub struct Link<'a, B> {
    board: Board<'a>,
    decoder: Decoder<B>,
    /// A frame ended while a scene was drawn: it is answered next.
    pending: bool,
    /// A byte came since the last frame was received: an animation stops,
    /// its text (that frame, in the decoder) being overwritten.
    heard: bool,
    animation: Option<Animation<'a>>,
}

impl<'a, B: AsRef<[u8]> + AsMut<[u8]>> Link<'a, B> {
    /// The board drawing on `panel`, running `firmware` (its name and
    /// version), keeping frames in `buffer` (its length bounds a scene's).
    /// It plays no animation until given one ([`Link::with_animations`]).
    pub fn new(panel: Panel, firmware: &'a str, buffer: B) -> Link<'a, B> {
        let decoder = Decoder::for_board(buffer);
        let board = Board::new(panel, firmware, &decoder);
        Link { board, decoder, pending: false, heard: false, animation: None }
    }

    /// The board plays animations in `animation` (an
    /// [`AnimationRoom`](octrace_core::animation::AnimationRoom)'s, at the
    /// panel's size): an animated scene that does not fit it is rejected,
    /// naming what runs out.
    pub fn with_animations(mut self, animation: Animation<'a>) -> Link<'a, B> {
        self.board = self.board.playing_in(animation.room());
        self.animation = Some(animation);
        self
    }

    /// What the board says it is.
    pub fn board(&self) -> &Board<'a> {
        &self.board
    }

    /// Waits for the next frame on `line` (sleeping while nothing comes),
    /// or takes the one that came while the last scene was drawn, and
    /// answers it; a scene that loads into `raytracer` is drawn by `draw`,
    /// which renders the rows in its own way, sends each as it is drawn
    /// ([`Rows::send`]), polls the line between rays ([`Rows::poll`],
    /// through a [`Stop`](octrace_core::render::Stop)) and returns how many
    /// rows it drew, in order. An animation is played in a loop, `draw`
    /// called for each frame ([`Drawing::frame`]: it draws the planned
    /// runs, sends each with [`Rows::send_run`], and returns the panel's
    /// height when the frame is whole), until the host sends a byte. None
    /// when the line says no byte will come.
    pub fn serve<P: Profile, L: Line>(
        &mut self,
        line: &mut L,
        raytracer: &mut Raytracer<P>,
        mut draw: impl FnMut(&Drawing<'_, P>, &mut Rows<'_, '_, L, B>) -> u16,
    ) -> Option<Served> {
        if !self.pending {
            loop {
                match line.read() {
                    Some(byte) if self.decoder.push(byte).is_some() => break,
                    Some(_) => {}
                    None if line.sleep() => {}
                    None => return None,
                }
            }
        }
        (self.pending, self.heard) = (false, false);
        // The board's time from the whole frame received to the last row
        // drawn: parse, index and render; and its counters over each.
        let names = &line.counter_names()[..line.counter_names().len().min(MAX_COUNTERS)];
        let (mut load_counts, mut render_counts) = ([0; MAX_COUNTERS], [0; MAX_COUNTERS]);
        line.take_counts(&mut load_counts[..names.len()]);
        let start = line.now_us();
        let mut output = Output { line, waited_us: 0, taken: 0, stalled: false, keep_alive: None };
        // There: a frame just ended, or ended while the last scene was drawn
        // and nothing was pushed since.
        let received = self.decoder.received()?;
        let drawing = match self.board.answer(received, raytracer, self.animation.as_mut(), &mut output) {
            Ok(None) => return Some(Served::Answered),
            Err(Stalled) => return Some(Served::Stalled),
            Ok(Some(drawing)) => drawing,
        };
        let loaded = output.line.now_us();
        output.keep_alive =
            Some(KeepAlive { tag: drawing.tag, since_us: start, spoke_at_us: loaded, spoken: output.taken });
        if let Some(frames) = play::animated(drawing.scene()) {
            let (tag, pixels) = (drawing.tag, drawing.pixels);
            return Some(self.play(&mut output, raytracer, frames, tag, pixels, &mut draw));
        }
        output.line.take_counts(&mut load_counts[..names.len()]);
        // Field by field: a scene loaded through the animation borrows it.
        let listener = Listener {
            decoder: &mut self.decoder,
            pending: &mut self.pending,
            heard: &mut self.heard,
            any_byte: false,
        };
        let mut rows = Rows { output: &mut output, listener, read_at_us: start };
        let drawn = draw(&drawing, &mut rows).min(drawing.panel().height);
        // Every row drawn is done, even if a frame came with the last.
        let closed = match drawn == drawing.panel().height {
            true => {
                let end = output.line.now_us();
                output.line.take_counts(&mut render_counts[..names.len()]);
                let counters: [Counter<'_>; MAX_COUNTERS] = core::array::from_fn(|k| Counter {
                    name: names.get(k).copied().unwrap_or(""),
                    load: load_counts[k],
                    render: render_counts[k],
                });
                let micros = |from: u64, to: u64| Some(Duration::from_micros(to.saturating_sub(from)));
                let timing = Timing {
                    elapsed: micros(start, end),
                    load: micros(start, loaded),
                    render: micros(loaded, end),
                    counters: Counters::new(&counters[..names.len()]),
                };
                drawing.finish(&timing, &mut output)
            }
            false => drawing.cancel(drawn, &mut output),
        };
        Some(match closed {
            Ok(()) => Served::Drawn { rows: drawn },
            Err(Stalled) => Served::Stalled,
        })
    }

    /// Plays the animation of `frames` that the frame just received holds
    /// (loaded into the board's animation as it was answered, every frame
    /// checked), answering it with `tag`: frame after frame in a loop, each
    /// loaded from the text and drawn by `draw`, then `frame-drawn`, until
    /// the host sends a byte; then `stopped`.
    fn play<P: Profile, L: Line>(
        &mut self,
        output: &mut Output<'_, L>,
        raytracer: &mut Raytracer<P>,
        frames: Frames,
        tag: u16,
        pixels: bool,
        draw: &mut impl FnMut(&Drawing<'_, P>, &mut Rows<'_, '_, L, B>) -> u16,
    ) -> Served {
        let panel = self.board.panel;
        // Answered: the board has an animation, which holds this scene.
        let Some(animation) = self.animation.as_mut() else {
            return close(Message::Stopped { frames: 0 }.encode(tag, output), Served::Played { frames: 0 });
        };
        let (mut frame, mut drawn) = (0, 0u32);
        loop {
            let begun = output.line.now_us();
            // The text is the frame received, in the decoder, until a byte
            // comes from the host.
            let Some(text) = scene_text(&self.decoder).filter(|_| !self.heard) else { break };
            let Ok(loaded) = animation.load(raytracer, text, frame) else { break };
            let traced = u32::try_from(loaded.tiles().traced_pixels()).unwrap_or(u32::MAX);
            let drawing = Drawing { shown: Shown::Frame(loaded), tag, pixels, panel };
            let listener = Listener {
                decoder: &mut self.decoder,
                pending: &mut self.pending,
                heard: &mut self.heard,
                any_byte: true,
            };
            let mut rows = Rows { output: &mut *output, listener, read_at_us: begun };
            if draw(&drawing, &mut rows) < panel.height {
                break;
            }
            let elapsed = Some(Duration::from_micros(output.line.now_us().saturating_sub(begun)));
            // Not taken: the animation goes on on the panel (see Timing).
            let _ = Message::FrameDrawn { frame, traced, elapsed }.encode(tag, output);
            drawn = drawn.saturating_add(1);
            frame = (frame + 1) % frames.count;
            // A frame that traced nothing asked the line nothing.
            let (decoder, pending, heard) = (&mut self.decoder, &mut self.pending, &mut self.heard);
            Listener { decoder, pending, heard, any_byte: true }.take(output.line);
        }
        close(Message::Stopped { frames: drawn }.encode(tag, output), Served::Played { frames: drawn })
    }
}

/// `served`, unless the answer's last message was not taken.
fn close(sent: Result<(), Stalled>, served: Served) -> Served {
    match sent {
        Ok(()) => served,
        Err(Stalled) => Served::Stalled,
    }
}

/// The scene text of the frame `decoder` received last, while nothing has
/// been pushed since.
fn scene_text<B: AsRef<[u8]> + AsMut<[u8]>>(decoder: &Decoder<B>) -> Option<&str> {
    match decoder.received()? {
        Ok(Frame { message: Message::Scene { text, .. }, .. }) => core::str::from_utf8(text).ok(),
        _ => None,
    }
}

/// What a drawing's renderer sends its rows by and polls the line with:
/// see [`Link::serve`].
pub struct Rows<'o, 'l, L, B> {
    output: &'o mut Output<'l, L>,
    listener: Listener<'o, B>,
    /// When [`Rows::poll`] last read the line.
    read_at_us: u64,
}

impl<L, B> core::fmt::Debug for Rows<'_, '_, L, B> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Rows").field("stops", &self.listener.stops()).finish_non_exhaustive()
    }
}

impl<L: Line, B: AsRef<[u8]> + AsMut<[u8]>> Rows<'_, '_, L, B> {
    /// Whether the drawing stops for what came from the host (it is
    /// answered next): a frame that ended, or for an animation any byte.
    /// Asked before every ray on the core that owns the line (as a
    /// [`Stop`](octrace_core::render::Stop)). Every [`POLL_PERIOD_US`] at
    /// most it reads what the host has sent, tells the [`Line`] the board
    /// is [alive](Line::alive), and tells the host so too when it has sent
    /// nothing for [`KEEP_ALIVE_US`]; between, it only reads the clock.
    pub fn poll(&mut self) -> bool {
        let now = self.output.line.now_us();
        if self.listener.stops() || now.wrapping_sub(self.read_at_us) < POLL_PERIOD_US {
            return self.listener.stops();
        }
        self.read_at_us = now;
        self.output.line.alive();
        if self.listener.take(self.output.line) {
            return true;
        }
        self.keep_alive(now);
        self.listener.stops()
    }

    /// Sends `working` if the line has taken nothing of the answer for
    /// [`KEEP_ALIVE_US`] (`now`: the clock at this look at the line). Kept
    /// out of [`Rows::poll`], which a drawing asks before every ray: the
    /// ask stays as small as it was (asked once a millisecond, this costs
    /// a call).
    #[inline(never)]
    fn keep_alive(&mut self, now: u64) {
        let taken = self.output.taken;
        let Some(alive) = &mut self.output.keep_alive else { return };
        if alive.spoken != taken {
            (alive.spoken, alive.spoke_at_us) = (taken, now);
            return;
        }
        if now.wrapping_sub(alive.spoke_at_us) < KEEP_ALIVE_US {
            return;
        }
        alive.spoke_at_us = now;
        let (tag, elapsed) = (alive.tag, Duration::from_micros(now.saturating_sub(alive.since_us)));
        let mut polled = Polled { output: self.output, listener: &mut self.listener };
        // Not taken: the host has stopped reading, and gets no more of the answer.
        let _ = Message::Working { elapsed: Some(elapsed) }.encode(tag, &mut polled);
        let taken = self.output.taken;
        if let Some(alive) = &mut self.output.keep_alive {
            alive.spoken = taken;
        }
    }

    /// Sends row `y` of `drawing`, its pixels `row` (the panel's width of
    /// them) if the host asked for them; the line is read while the board
    /// waits for the host to take it. A host that does not take it is not
    /// sent the rest of the drawing's answer (the drawing goes on).
    pub fn send<P: Profile>(&mut self, drawing: &Drawing<'_, P>, y: u16, row: &[Rgb565]) {
        let mut polled = Polled { output: self.output, listener: &mut self.listener };
        // A row the host did not take is dropped with the rest: the panel
        // still shows it.
        let _ = drawing.send_row(y, row, &mut polled);
    }

    /// Sends the run `run` of row `y` from column `x` of an animation's
    /// frame `drawing`, as [`Rows::send`] sends a row.
    pub fn send_run<P: Profile>(&mut self, drawing: &Drawing<'_, P>, y: u16, x: u16, run: &[Rgb565]) {
        let mut polled = Polled { output: self.output, listener: &mut self.listener };
        let _ = drawing.send_run(y, x, run, &mut polled);
    }

    /// Draws `drawing` on one core into `row` (the panel's width of
    /// pixels): a still row by row, an animation's frame
    /// ([`Drawing::frame`]) run by run, only the runs its tiles' plan
    /// traces. Each whole row or run is shown (`show`: the panel, given the
    /// pixels' rectangle, one row high) and sent once drawn, the line
    /// polled between rays. Returns the rows drawn, fewer than the panel's
    /// height when the host sent something (for an animation's frame: the
    /// panel's height once every run is drawn, else 0). What a firmware
    /// with one core, or a host standing in for a board, draws with.
    pub fn draw_on_one_core<P: Profile>(
        &mut self,
        drawing: &Drawing<'_, P>,
        row: &mut [Rgb565],
        show: impl FnMut(&Rectangle, &[Rgb565]),
    ) -> u16 {
        let panel = drawing.panel();
        let rows = RefCell::new(self);
        let mut sent = Sent { rows: &rows, drawing, row, show, whole: 0 };
        // Asked while a row's pixels are traced; the row is sent after.
        let mut stop: Asked<'_> = &mut || rows.borrow_mut().poll();
        match drawing.frame() {
            Some(frame) => match frame.image().try_draw_until(&mut sent, &mut stop) {
                Ok(_) => panel.height,
                Err(_) => 0,
            },
            None => {
                let size = Size::new(panel.width.into(), panel.height.into());
                let _ = drawing.scene().image(size).try_draw_until(&mut sent, &mut stop);
                sent.whole
            }
        }
    }
}

/// The panel as a drawing on one core draws into it: each whole row (a
/// still's) or run (a frame's) is shown and sent; one cut short by a stop
/// goes nowhere.
struct Sent<'x, 'o, 'l, 'd, L, B, P: Profile, F> {
    rows: &'x RefCell<&'x mut Rows<'o, 'l, L, B>>,
    drawing: &'x Drawing<'d, P>,
    row: &'x mut [Rgb565],
    show: F,
    /// A still's rows whole so far.
    whole: u16,
}

impl<L, B, P: Profile, F> OriginDimensions for Sent<'_, '_, '_, '_, L, B, P, F> {
    fn size(&self) -> Size {
        let panel = self.drawing.panel();
        Size::new(panel.width.into(), panel.height.into())
    }
}

impl<L, B, P, F> DrawTarget for Sent<'_, '_, '_, '_, L, B, P, F>
where
    L: Line,
    B: AsRef<[u8]> + AsMut<[u8]>,
    P: Profile,
    F: FnMut(&Rectangle, &[Rgb565]),
{
    type Color = Rgb565;
    type Error = core::convert::Infallible;

    /// Never called: a drawing hands over rows and runs whole.
    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb565>>>(&mut self, _: I) -> Result<(), Self::Error> {
        Ok(())
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb565>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), Self::Error> {
        let mut width = 0;
        for (pixel, color) in self.row.iter_mut().zip(colors) {
            *pixel = color;
            width += 1;
        }
        if width < area.size.width as usize {
            return Ok(());
        }
        let run = &self.row[..width];
        (self.show)(area, run);
        let (x, y) = (area.top_left.x as u16, area.top_left.y as u16);
        match self.drawing.frame() {
            Some(_) => self.rows.borrow_mut().send_run(self.drawing, y, x, run),
            None => {
                self.rows.borrow_mut().send(self.drawing, y, run);
                self.whole = y + 1;
            }
        }
        Ok(())
    }
}

/// How a drawing asks whether to stop, before every ray: one type for
/// every render path, so that a firmware links the tracer once for its
/// stills and its animations (octrace-pico's cores ask the same way).
type Asked<'s> = &'s mut dyn FnMut() -> bool;

/// What came from the host while a scene is drawn: the decoder takes it,
/// and says whether the drawing stops.
struct Listener<'o, B> {
    decoder: &'o mut Decoder<B>,
    /// A frame ended.
    pending: &'o mut bool,
    /// A byte came.
    heard: &'o mut bool,
    /// Any byte stops the drawing (an animation), not only a frame's end.
    any_byte: bool,
}

impl<B> Listener<'_, B> {
    /// Whether the drawing stops.
    fn stops(&self) -> bool {
        *self.pending || (self.any_byte && *self.heard)
    }
}

impl<B: AsRef<[u8]> + AsMut<[u8]>> Listener<'_, B> {
    /// Reads bytes from `line` into the decoder until the drawing stops or
    /// nothing more has come; whether it stops.
    fn take<L: Line>(&mut self, line: &mut L) -> bool {
        while !self.stops() {
            match line.read() {
                Some(byte) => {
                    *self.heard = true;
                    *self.pending = self.decoder.push(byte).is_some();
                }
                None => break,
            }
        }
        self.stops()
    }
}

/// The host did not take an answer in time: the rest of it is dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stalled;

/// One answer on its way to the host, with the time the board has waited
/// for room and the bytes the line has taken.
struct Output<'l, L> {
    line: &'l mut L,
    waited_us: u64,
    taken: u64,
    stalled: bool,
    /// While a drawing is answered: what it needs to tell the host it is
    /// still at work ([`Rows::poll`]).
    keep_alive: Option<KeepAlive>,
}

/// A drawing's word to the host when it has sent nothing for a while.
#[derive(Clone, Copy, Debug)]
struct KeepAlive {
    /// The drawing's request.
    tag: u16,
    /// When the request came, by the board's clock.
    since_us: u64,
    /// When the answer last grew (or the drawing began), as seen at a look
    /// at the line, and how many bytes the line had taken of it then.
    spoke_at_us: u64,
    spoken: u64,
}

impl<L: Line> Output<'_, L> {
    /// Writes all of `bytes`, waiting for room (`while_waiting` at each
    /// turn) within the answer's allowance. Each write is a sign of life: a
    /// long answer (thousands of errors) keeps a watchdog fed.
    fn write(&mut self, bytes: &[u8], mut while_waiting: impl FnMut(&mut L)) -> Result<(), Stalled> {
        self.line.alive();
        if self.stalled {
            return Err(Stalled);
        }
        let mut rest = bytes;
        let mut last = None;
        loop {
            let taken = self.line.write(rest);
            rest = &rest[taken..];
            self.taken += taken as u64;
            if rest.is_empty() {
                return Ok(());
            }
            let now = self.line.now_us();
            self.waited_us += last.map_or(0, |last| now.saturating_sub(last));
            last = Some(now);
            let allowed = STALL_GRACE_US + self.taken.saturating_mul(1_000_000) / SLOWEST_HOST_BYTES_PER_SECOND;
            if self.waited_us > allowed {
                self.stalled = true;
                self.line.discard();
                return Err(Stalled);
            }
            self.line.alive();
            while_waiting(self.line);
            // A host taking bytes wakes the line at once; one that reads
            // nothing lets it sleep until the allowance is spent.
            self.line.wait_for_room((allowed - self.waited_us).clamp(1, ROOM_WAIT_US));
        }
    }
}

impl<L: Line> Sink for Output<'_, L> {
    type Error = Stalled;

    fn write_all(&mut self, bytes: &[u8]) -> Result<(), Stalled> {
        self.write(bytes, |_| {})
    }
}

/// An [`Output`] that reads the line while it waits (a drawing's rows: the
/// decoder is free, the scene's text no longer needed, or an animation's
/// stopping at the first byte).
struct Polled<'a, 'l, 'o, L, B> {
    output: &'a mut Output<'l, L>,
    listener: &'a mut Listener<'o, B>,
}

impl<L: Line, B: AsRef<[u8]> + AsMut<[u8]>> Sink for Polled<'_, '_, '_, L, B> {
    type Error = Stalled;

    fn write_all(&mut self, bytes: &[u8]) -> Result<(), Stalled> {
        let listener = &mut *self.listener;
        self.output.write(bytes, |line| {
            listener.take(line);
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::kind::Kind;
    use crate::message::{Message, PixelFormat};
    use octrace_core::animation::AnimationRoom;
    use octrace_core::profile::Board64K;
    use std::boxed::Box;
    use std::collections::VecDeque;
    use std::string::{String, ToString};
    use std::vec::Vec;

    /// Two facing mirrors with the eye between them, eight lights, 16²
    /// samples: a pixel of it takes hours on a Pico.
    pub(crate) const WEDGING: &[u8] = b"VIEWPOINT 0 0 0 ORIGIN 0 0 -1 RDEPTH 1000000 SAMPLES 16\n\
        LIGHT 1 0 1 0 LIGHT 1 0 -1 0 LIGHT 1 1 0 0 LIGHT 1 -1 0 0\n\
        LIGHT 1 1 1 0 LIGHT 1 -1 1 0 LIGHT 1 1 -1 0 LIGHT 1 -1 -1 0\n\
        RECTANGLE 1 -5 -5 -3 5 -5 -3 5 5 -3 -5 5 -3\n\
        RECTANGLE 1 -5 -5 3 -5 5 3 5 5 3 5 -5 3\n\
        SURFACE 1 0.01 0.01 0.01 0.1 0.1 0.1 0 0 0 0 1 0\n";

    const SCENE: &[u8] = b"SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n";

    /// A host at the end of a simulated line: bytes it sends become
    /// readable once the board has given `after` signs of life; it takes
    /// what the board writes at `bytes_per_second` (None: at once) through a
    /// ring of 48 bytes, on a clock that moves 100 µs each time it is read.
    struct Wire {
        sent: VecDeque<(u32, Vec<u8>)>,
        readable: VecDeque<u8>,
        /// Signs of life the board gave: polls and writes.
        polls: u32,
        ring: VecDeque<u8>,
        received: Vec<u8>,
        /// The clock when each byte of `received` reached the host.
        received_at: Vec<u64>,
        bytes_per_second: Option<u64>,
        clock_us: u64,
        /// When the host last took a byte (its pace).
        taken_at_us: u64,
        /// How often the board took its counts: each count is that number
        /// times ten, plus the counter's index.
        counts_taken: u32,
        /// Each wait for room the board made: how long it let the line sleep.
        waits_for_room: Vec<u64>,
    }

    impl Wire {
        fn new() -> Wire {
            Wire {
                sent: VecDeque::new(),
                readable: VecDeque::new(),
                polls: 0,
                ring: VecDeque::new(),
                received: Vec::new(),
                received_at: Vec::new(),
                bytes_per_second: None,
                clock_us: 0,
                taken_at_us: 0,
                counts_taken: 0,
                waits_for_room: Vec::new(),
            }
        }

        /// `message` from the host with `tag`, readable after `after` polls.
        fn send(&mut self, after: u32, message: Message<'_>, tag: u16) {
            let mut bytes = Vec::new();
            message.encode(tag, &mut bytes).unwrap();
            self.sent.push_back((after, bytes));
        }

        fn host_reads(&mut self) {
            let before = self.received.len();
            match self.bytes_per_second {
                None => self.received.extend(self.ring.drain(..)),
                Some(rate) => {
                    let due = (self.clock_us - self.taken_at_us) * rate / 1_000_000;
                    for _ in 0..due.min(self.ring.len() as u64) {
                        self.received.extend(self.ring.pop_front());
                        self.taken_at_us = self.clock_us;
                    }
                }
            }
            self.received_at.resize(self.received.len().max(before), self.clock_us);
        }

        /// Every frame the host received: its tag, its message's kind, the
        /// message, and the clock when its last byte came.
        fn frames(&mut self, mut each: impl FnMut(u16, Message<'_>, u64)) {
            self.host_reads();
            let mut decoder = Decoder::for_host(std::vec![0u8; 4096]);
            for (&byte, &at) in self.received.iter().zip(&self.received_at) {
                if let Some(frame) = decoder.push(byte) {
                    let frame = frame.expect("the board's frames read");
                    each(frame.tag, frame.message, at);
                }
            }
        }

        /// The board's answers as (tag, kind), all read.
        fn answers(&mut self) -> Vec<(u16, Kind)> {
            self.host_reads();
            let mut decoder = Decoder::for_host(std::vec![0u8; 4096]);
            let mut answers = Vec::new();
            for &byte in &self.received {
                if let Some(frame) = decoder.push(byte) {
                    let frame = frame.expect("the board's frames read");
                    answers.push((frame.tag, frame.message.kind()));
                }
            }
            answers
        }
    }

    impl Line for Wire {
        fn read(&mut self) -> Option<u8> {
            while let Some((after, _)) = self.sent.front() {
                if *after > self.polls {
                    break;
                }
                let (_, bytes) = self.sent.pop_front()?;
                self.readable.extend(bytes);
            }
            self.readable.pop_front()
        }

        fn write(&mut self, bytes: &[u8]) -> usize {
            self.host_reads();
            let taken = bytes.len().min(48 - self.ring.len());
            self.ring.extend(&bytes[..taken]);
            // A host that takes at once has it now.
            if self.bytes_per_second.is_none() {
                self.host_reads();
            }
            taken
        }

        fn discard(&mut self) {
            self.ring.clear();
        }

        fn now_us(&mut self) -> u64 {
            self.clock_us += 100;
            self.clock_us
        }

        fn sleep(&mut self) -> bool {
            // Nothing readable: the next bytes come now, if any will.
            match self.sent.front_mut() {
                Some((after, _)) => {
                    *after = self.polls;
                    true
                }
                None => false,
            }
        }

        fn alive(&mut self) {
            self.polls += 1;
        }

        fn wait_for_room(&mut self, at_most_us: u64) {
            // Nothing wakes the board early: it sleeps all it may.
            self.waits_for_room.push(at_most_us);
            self.clock_us += at_most_us;
        }

        fn counter_names(&self) -> &'static [&'static str] {
            &["fetches", "stores"]
        }

        fn take_counts(&mut self, counts: &mut [u32]) {
            self.counts_taken += 1;
            for (k, count) in counts.iter_mut().enumerate() {
                *count = self.counts_taken * 10 + k as u32;
            }
        }
    }

    const PANEL: Panel = Panel { width: 4, height: 3, format: PixelFormat::Rgb565 };

    /// Serves every frame `wire` brings, drawing on one core; what each
    /// serve did.
    fn serve_all(wire: &mut Wire) -> Vec<Served> {
        serve_with(Link::new(PANEL, "test 1", std::vec![0u8; 1024]), wire)
    }

    /// [`serve_all`] by `link`.
    fn serve_with(mut link: Link<'_, Vec<u8>>, wire: &mut Wire) -> Vec<Served> {
        let mut raytracer = Box::new(Raytracer::<Board64K>::new());
        let mut served = Vec::new();
        while let Some(one) = link.serve(wire, &mut raytracer, |drawing, rows| {
            rows.draw_on_one_core(drawing, &mut [Rgb565::default(); 4], |_, _| {})
        }) {
            served.push(one);
        }
        served
    }

    #[test]
    fn a_hello_stops_a_drawing_inside_its_first_pixel_and_is_answered_next() {
        let mut wire = Wire::new();
        wire.send(0, Message::Scene { pixels: false, text: WEDGING }, 1);
        // The board has polled 50 times inside the first pixel.
        wire.send(50, Message::Hello, 2);
        let served = serve_all(&mut wire);
        assert_eq!(served, [Served::Drawn { rows: 0 }, Served::Answered]);
        // The board said it was working while it traced (50 ms): see below.
        let answers: Vec<_> = wire.answers().into_iter().filter(|&answer| answer != (1, Kind::Working)).collect();
        assert_eq!(answers, [(1, Kind::Drawing), (1, Kind::Cancelled), (2, Kind::Board)]);
        // The hello was read at the first poll that could: after it, only
        // the two answers' writes through the 48-byte ring (a pixel of this
        // scene is millions of polls).
        assert!(wire.polls <= 50 + 100, "{} polls", wire.polls);
    }

    #[test]
    fn done_carries_the_load_and_the_render_by_the_lines_clock_and_counters() {
        let mut wire = Wire::new();
        wire.send(0, Message::Scene { pixels: false, text: SCENE }, 1);
        assert_eq!(serve_all(&mut wire), [Served::Drawn { rows: PANEL.height }]);
        wire.host_reads();
        let mut decoder = Decoder::for_host(std::vec![0u8; 4096]);
        let mut done = None;
        for &byte in &wire.received {
            if let Some(Ok(frame)) = decoder.push(byte) {
                if let Message::Done(timing) = frame.message {
                    let counters: Vec<Counter<'_>> = timing.counters.iter().collect();
                    let names: Vec<String> = counters.iter().map(|c| c.name.to_string()).collect();
                    let counts: Vec<(u32, u32)> = counters.iter().map(|c| (c.load, c.render)).collect();
                    done = Some((timing.elapsed, timing.load, timing.render, names, counts));
                }
            }
        }
        let (elapsed, load, render, names, counts) = done.expect("a done answer");
        let (elapsed, load, render) = (elapsed.unwrap(), load.unwrap(), render.unwrap());
        assert_eq!(elapsed, load + render);
        assert!(load > Duration::ZERO && render > Duration::ZERO, "{load:?} {render:?}");
        assert_eq!(names, ["fetches", "stores"]);
        // Taken as the scene came (dropped), once loaded, once drawn.
        assert_eq!(counts, [(20, 30), (21, 31)]);
    }

    #[test]
    fn a_frame_with_the_last_row_leaves_the_drawing_done() {
        let mut wire = Wire::new();
        wire.send(0, Message::Scene { pixels: true, text: SCENE }, 1);
        wire.send(0, Message::Hello, 2);
        let mut link = Link::new(PANEL, "test 1", std::vec![0u8; 1024]);
        let mut raytracer = Box::new(Raytracer::<Board64K>::new());
        // Every row drawn and sent, then the poll after the last finds the hello.
        let served = link.serve(&mut wire, &mut raytracer, |drawing, rows| {
            for y in 0..PANEL.height {
                rows.send(drawing, y, &[Rgb565::default(); 4]);
            }
            // Read within a millisecond.
            assert!((0..20).any(|_| rows.poll()), "the hello has come");
            PANEL.height
        });
        assert_eq!(served, Some(Served::Drawn { rows: PANEL.height }));
        assert_eq!(link.serve(&mut wire, &mut raytracer, |_, _| 0), Some(Served::Answered));
        let kinds: Vec<Kind> = wire.answers().into_iter().map(|(_, kind)| kind).collect();
        assert_eq!(kinds, [Kind::Drawing, Kind::Row, Kind::Row, Kind::Row, Kind::Done, Kind::Board]);
    }

    #[test]
    fn a_host_that_stops_reading_loses_the_rest_of_the_answer_and_gets_the_next_whole() {
        let mut wire = Wire::new();
        wire.bytes_per_second = Some(0);
        wire.send(0, Message::Scene { pixels: true, text: SCENE }, 1);
        let served = serve_all(&mut wire);
        assert_eq!(served, [Served::Stalled]);
        assert!(wire.ring.is_empty(), "what waited for the host is dropped");
        // Waited a second, not a second a row.
        assert!(wire.clock_us < STALL_GRACE_US + 100_000, "{} µs", wire.clock_us);
        // Most of it asleep, a millisecond at most at a time, not spinning.
        let waits = &wire.waits_for_room;
        assert!(waits.iter().all(|&us| (1..=ROOM_WAIT_US).contains(&us)), "{waits:?}");
        assert!(waits.iter().sum::<u64>() > STALL_GRACE_US * 9 / 10, "{waits:?}");
        // The host reads again, and asks.
        wire.bytes_per_second = None;
        wire.send(wire.polls, Message::Hello, 2);
        assert_eq!(serve_all(&mut wire), [Served::Answered]);
        assert_eq!(wire.answers(), [(2, Kind::Board)], "the next answer, whole and alone");
    }

    #[test]
    fn a_host_taking_a_byte_a_second_does_not_pace_the_drawing() {
        let mut wire = Wire::new();
        wire.bytes_per_second = Some(1);
        wire.send(0, Message::Scene { pixels: true, text: SCENE }, 1);
        assert_eq!(serve_all(&mut wire), [Served::Stalled]);
        assert!(wire.clock_us < STALL_GRACE_US + 100_000, "{} µs", wire.clock_us);
    }

    #[test]
    fn a_burst_of_frames_is_answered_frame_by_frame() {
        let mut wire = Wire::new();
        for tag in 1..=300 {
            wire.send(0, Message::Hello, tag);
        }
        wire.send(0, Message::Scene { pixels: false, text: SCENE }, 301);
        let served = serve_all(&mut wire);
        assert_eq!(served.len(), 301);
        let answers = wire.answers();
        assert_eq!(answers.len(), 300 + 2 + PANEL.height as usize);
        assert!(answers[..300].iter().zip(1..).all(|(&answer, tag)| answer == (tag, Kind::Board)));
        assert_eq!(answers.last(), Some(&(301, Kind::Done)));
    }

    const ANIMATION: &[u8] = b"FRAMES 3\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\n\
        SPHERE 1 1 0 0 0\nSPHERE 1 0.5 -2 0 1 MOVE 0 0 0 0  2 4 0 0\n";

    /// Serves every frame `wire` brings with room for `ANIMATION`.
    fn play_all(wire: &mut Wire) -> Vec<Served> {
        let mut room = AnimationRoom::<1, 1, 2>::new();
        let animation = room.animation(Size::new(PANEL.width.into(), PANEL.height.into())).unwrap();
        serve_with(Link::new(PANEL, "test 1", std::vec![0u8; 1024]).with_animations(animation), wire)
    }

    #[test]
    fn an_animation_plays_in_a_loop_until_a_hello_stops_it() {
        let mut wire = Wire::new();
        wire.send(0, Message::Scene { pixels: true, text: ANIMATION }, 1);
        wire.send(400, Message::Hello, 2);
        let served = play_all(&mut wire);
        let Some(&Served::Played { frames }) = served.first() else { panic!("{served:?}") };
        assert!(frames >= 4, "round the loop: {frames} frames");
        assert_eq!(served[1..], [Served::Answered]);
        wire.host_reads();
        let mut decoder = Decoder::for_host(std::vec![0u8; 4096]);
        let (mut drawn, mut runs, mut stopped) = (Vec::new(), 0, None);
        let mut kinds = Vec::new();
        for &byte in &wire.received {
            let Some(frame) = decoder.push(byte) else { continue };
            let frame = frame.unwrap();
            match frame.message {
                Message::FrameDrawn { frame, traced, .. } => drawn.push((frame, traced)),
                Message::Run { .. } => runs += 1,
                Message::Stopped { frames } => {
                    stopped = Some(frames);
                    kinds.push((frame.tag, Kind::Stopped));
                }
                other => kinds.push((frame.tag, other.kind())),
            }
        }
        assert_eq!(kinds, [(1, Kind::Drawing), (1, Kind::Stopped), (2, Kind::Board)]);
        assert_eq!(drawn.len() as u32, frames);
        // `stopped` counts the frames drawn whole, not the frame it was at
        // (past the loop's end, the two differ).
        assert_eq!(stopped, Some(frames), "stopped after {frames} frames drawn");
        let order: Vec<u32> = drawn.iter().map(|&(frame, _)| frame).collect();
        assert_eq!(order[..4], [0, 1, 2, 0], "the loop's order");
        // The first frame traces every pixel: a 4x3 panel is one tile.
        assert_eq!(drawn[0].1, 12);
        assert!(runs >= 3, "{runs} runs");
    }

    #[test]
    fn an_animation_whose_camera_breaks_at_a_later_frame_is_rejected_before_drawing() {
        // The eye moves onto the point looked at at frame 2.
        let broken = b"FRAMES 3\nVIEWPOINT 0 0 5 MOVE 0 0 0 0  2 0 0 -5\nORIGIN 0 0 0\n\
            SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 3\n";
        let mut wire = Wire::new();
        wire.send(0, Message::Scene { pixels: false, text: broken }, 1);
        assert_eq!(play_all(&mut wire), [Served::Answered]);
        wire.host_reads();
        let mut decoder = Decoder::for_host(std::vec![0u8; 4096]);
        let mut answers = Vec::new();
        for &byte in &wire.received {
            if let Some(Ok(frame)) = decoder.push(byte) {
                answers.push(match frame.message {
                    Message::SceneError(e) => std::format!("{}:{}: {}", e.line, e.column, e.message),
                    other => other.kind().name().to_string(),
                });
            }
        }
        assert_eq!(answers, ["2:17: at frame 2, VIEWPOINT equals ORIGIN: there is no view direction", "rejected"]);
    }

    #[test]
    fn an_animation_the_room_cannot_hold_is_rejected_naming_each_capacity() {
        let mut wire = Wire::new();
        wire.send(0, Message::Scene { pixels: false, text: ANIMATION }, 1);
        assert_eq!(serve_all(&mut wire), [Served::Answered]);
        wire.host_reads();
        let mut decoder = Decoder::for_host(std::vec![0u8; 4096]);
        let mut named = Vec::new();
        for &byte in &wire.received {
            if let Some(Ok(Frame { message: Message::SceneError(e), .. })) = decoder.push(byte) {
                let need = e.capacity.unwrap();
                named.push((need.name.to_string(), need.needed, need.holds, (e.line, e.column)));
                let names = std::format!("room for it ({})", need.name);
                assert!(e.message.starts_with("too many ") && e.message.contains(&names), "{}", e.message);
            }
        }
        // Each at the statement that goes past it: the tiles at FRAMES, the
        // track and the keys at the MOVE.
        let holds = |name: &str, needed, at| (name.to_string(), Some(needed), 0, at);
        assert_eq!(named, [holds("tiles", 1, (1, 1)), holds("tracks", 1, (5, 21)), holds("keys", 2, (5, 21))]);
        assert_eq!(wire.answers().last(), Some(&(1, Kind::Rejected)));
    }

    #[test]
    fn a_drawing_that_sends_nothing_says_it_is_working_every_keep_alive_period_and_no_more() {
        let mut wire = Wire::new();
        wire.send(0, Message::Scene { pixels: false, text: WEDGING }, 1);
        // Long inside the first pixel.
        wire.send(1_000, Message::Hello, 2);
        assert_eq!(serve_all(&mut wire), [Served::Drawn { rows: 0 }, Served::Answered]);
        let mut heard = Vec::new();
        wire.frames(|tag, message, at| {
            let elapsed = match message {
                Message::Working { elapsed } => elapsed,
                _ => None,
            };
            heard.push((tag, message.kind(), at, elapsed));
        });
        let kinds: Vec<(u16, Kind)> = heard.iter().map(|&(tag, kind, ..)| (tag, kind)).collect();
        let working = kinds.iter().filter(|&&kind| kind == (1, Kind::Working)).count();
        assert_eq!(kinds[0], (1, Kind::Drawing));
        assert!(kinds[1..=working].iter().all(|&kind| kind == (1, Kind::Working)), "{kinds:?}");
        assert_eq!(kinds[working + 1..], [(1, Kind::Cancelled), (2, Kind::Board)]);
        // From `drawing` to `cancelled`, the host never waited more than the
        // protocol's 40 ms and one look at the line (and a ray: 100 µs on
        // this clock), nor heard `working` more often than the period.
        let promised_us = 40_000;
        assert!(include_str!("../../../docs/board-protocol.md").contains("every 40 ms of its clock"));
        for pair in heard[..working + 2].windows(2) {
            let gap = pair[1].2 - pair[0].2;
            assert!(gap <= promised_us + POLL_PERIOD_US + 200, "{gap} µs without a word: {:?}", pair[1]);
            if pair[1].1 == Kind::Working {
                assert!(gap >= KEEP_ALIVE_US, "working after {gap} µs: {:?}", pair[1]);
            }
        }
        assert!(working >= 10, "{working} times working");
        // Each says how long the board has been at the request, by its clock.
        let elapsed: Vec<Duration> = heard.iter().filter_map(|&(.., elapsed)| elapsed).collect();
        assert_eq!(elapsed.len(), working);
        assert!(elapsed.windows(2).all(|pair| pair[1] >= pair[0] + Duration::from_micros(KEEP_ALIVE_US)));
    }

    /// [`ANIMATION`]'s room, with a scene whose every pixel takes hours:
    /// the wedging scene with a light that moves.
    const WEDGING_ANIMATION: &[u8] = b"FRAMES 2\nVIEWPOINT 0 0 0 ORIGIN 0 0 -1 RDEPTH 1000000 SAMPLES 16\n\
        LIGHT 1 0 1 0 MOVE 0 0 0 0  1 0 1 1\nLIGHT 1 0 -1 0\n\
        RECTANGLE 1 -5 -5 -3 5 -5 -3 5 5 -3 -5 5 -3\n\
        RECTANGLE 1 -5 -5 3 -5 5 3 5 5 3 5 -5 3\n\
        SURFACE 1 0.01 0.01 0.01 0.1 0.1 0.1 0 0 0 0 1 0\n";

    #[test]
    fn a_stray_byte_stops_an_animations_frame_inside_its_pixel_and_no_run_cut_short_goes_out() {
        let mut wire = Wire::new();
        wire.send(0, Message::Scene { pixels: true, text: WEDGING_ANIMATION }, 1);
        // One byte that ends no frame, 50 ms into the first pixel; a hello
        // (whose opening delimiter would end that byte's frame, stopping
        // any drawing) 10 s of the board's clock later.
        wire.sent.push_back((50, std::vec![b'x']));
        wire.send(10_000, Message::Hello, 2);
        let served = play_all(&mut wire);
        assert_eq!(served[0], Served::Played { frames: 0 }, "{served:?}");
        let mut heard = Vec::new();
        wire.frames(|tag, message, _| {
            let width = match message {
                Message::Run { width, .. } => Some(width),
                _ => None,
            };
            heard.push((tag, message.kind(), width));
        });
        let stop = heard.iter().position(|&(_, kind, _)| kind == Kind::Stopped).expect("stopped");
        // No run of the frame went out: the stray byte came in its first
        // pixel, and a run cut short is not sent.
        let runs: Vec<_> = heard.iter().filter(|&&(_, kind, _)| kind == Kind::Run).collect();
        assert!(runs.is_empty(), "runs sent: {runs:?}");
        // Stopped at the byte, not at the hello: within a look at the line
        // of it, so after no more than the `working`s of its first 50 ms.
        let working = heard[..stop].iter().filter(|&&(_, kind, _)| kind == Kind::Working).count();
        assert!(working <= 3, "stopped after {working} times working: not at the stray byte");
        assert_eq!(heard[stop].0, 1);
        assert_eq!(heard.last().map(|&(tag, kind, _)| (tag, kind)), Some((2, Kind::Board)));
    }
}
