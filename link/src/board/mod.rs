//! The board's side of the protocol on an octrace-core [`Raytracer`]: the
//! loop a firmware runs ([`Link`], over its [`Line`]: `serve.rs`), each
//! received frame answered ([`Board::answer`]), and a scene that loaded
//! handed back as a [`Drawing`] whose rows the firmware renders its own way
//! (one core, two) and sends as they are drawn; an animation played frame
//! after frame in the [`Animation`] a firmware gives it (its room checked
//! in `play.rs`; each frame a [`Drawing`] of its own, [`Drawing::frame`]);
//! the byte rings a firmware keeps between its serial port and the loop
//! ([`Ring`]: `ring.rs`).
//!
//! Invariants: every frame gets exactly one answer — a [`Message::Board`],
//! a [`Message::Refused`], the scene's [`Message::SceneError`]s closed by a
//! [`Message::Rejected`], or a [`Message::Drawing`] whose [`Drawing`] is
//! closed by [`Drawing::finish`] or [`Drawing::cancel`] (an animation's
//! frames, each closed by a [`Message::FrameDrawn`], by a
//! [`Message::Stopped`]; a [`Message::Working`] wherever a drawing has
//! sent nothing for a while) — all with the frame's tag; a scene with errors
//! draws nothing, nor does an animation its room cannot hold, nor one
//! whose camera cannot be set up at any of its frames (checked, every
//! frame, before its `drawing`).
//!
//! A firmware's loop, on one core (`Usb` stands for its serial port and
//! clock as a [`Line`]; the rows go to its panel as well):
//!
//! ```
//! use embedded_graphics_core::pixelcolor::Rgb565;
//! use octrace_core::{profile::Board16K, Raytracer};
//! use octrace_link::board::{Line, Link, Served};
//! use octrace_link::{Decoder, Message, Panel, PixelFormat};
//! # use std::collections::VecDeque;
//! # struct Usb { from_host: VecDeque<u8>, to_host: Vec<u8>, clock: u64 }
//! # impl Line for Usb {
//! #     fn read(&mut self) -> Option<u8> { self.from_host.pop_front() }
//! #     fn write(&mut self, bytes: &[u8]) -> usize { self.to_host.extend_from_slice(bytes); bytes.len() }
//! #     fn discard(&mut self) {}
//! #     fn now_us(&mut self) -> u64 { self.clock += 1; self.clock }
//! #     fn sleep(&mut self) -> bool { !self.from_host.is_empty() }
//! #     fn alive(&mut self) {}
//! # }
//! # let mut host = Vec::new();
//! # Message::Hello.encode(1, &mut host).unwrap();
//! # Message::Scene { pixels: true, text: b"BACKGROUND 0 0 1\n" }.encode(2, &mut host).unwrap();
//! # let mut usb = Usb { from_host: host.into(), to_host: Vec::new(), clock: 0 };
//!
//! let panel = Panel { width: 8, height: 4, format: PixelFormat::Rgb565 };
//! let mut link = Link::new(panel, "my-board 0.1.0", [0u8; 4096]);
//! let mut raytracer = Raytracer::<Board16K>::new(); // a `static` on a board
//! let mut row = [Rgb565::default(); 8];
//! // On a board, `serve` never returns None: loop for ever.
//! while let Some(served) = link.serve(&mut usb, &mut raytracer, |drawing, rows| {
//!     // Each row to the panel (here: nowhere) and to the host.
//!     rows.draw_on_one_core(drawing, &mut row, |_area, _pixels| {})
//! }) {
//!     assert_ne!(served, Served::Stalled);
//! }
//! # let mut buffer = vec![0u8; 1024];
//! # let mut reader = Decoder::new(&mut buffer);
//! # let kinds: Vec<_> = usb.to_host.iter().filter_map(|&b| reader.push(b).map(|r| r.unwrap().message.kind().name())).collect();
//! # assert_eq!(kinds, ["board", "drawing", "row", "row", "row", "row", "done"]);
//! ```
//!
//! To play animations, give the link an
//! [`Animation`] in a `static`
//! [`AnimationRoom`](octrace_core::animation::AnimationRoom)
//! ([`Link::with_animations`]). On two cores, each renders its rows with a
//! `Renderer` of its own over [`Drawing::scene`] (see octrace-core's
//! `SharedScene`), or its bands of [`Drawing::frame`], the other core
//! stopped through a flag that the line's core sets when [`Rows::poll`]
//! says so, and the core that owns the line sends the rows in order.

mod play;
mod ring;
mod serve;

use play::saturate;
pub use ring::Ring;
pub use serve::{
    Line, Link, Rows, Served, Stalled, KEEP_ALIVE_US, MAX_COUNTERS, POLL_PERIOD_US, SLOWEST_HOST_BYTES_PER_SECOND,
    STALL_GRACE_US,
};

use crate::cobs::Sink;
use crate::decoder::{Decoder, Frame};
use crate::frame::{FrameWriter, Reason, Refusal, VERSION};
use crate::kind::Kind;
use crate::list::{Capacities, Capacity};
use crate::message::{put_scene_error, BoardInfo, CapacityNeed, Message, Panel, Timing};
use core::fmt;
use embedded_graphics_core::pixelcolor::{IntoStorage, Rgb565};
use octrace_core::animation::{Animation, AnimationNeeds};
use octrace_core::capacity::CapacityKind;
use octrace_core::parse::{ErrorKind, ParseError};
use octrace_core::profile::Profile;
use octrace_core::scene::SceneCapacities;
use octrace_core::{AccelMode, AnimationError, Frame as AnimationFrame, LoadedScene, Raytracer};

/// What a board is: its panel, the longest scene its decoder holds, its
/// firmware's name. Its profile and capacities come from the
/// [`Raytracer`] each answer is given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Board<'a> {
    panel: Panel,
    max_scene: u32,
    firmware: &'a str,
    /// What its [`Animation`] holds (none: it plays no animation).
    room: AnimationNeeds,
}

impl<'a> Board<'a> {
    /// The board drawing on `panel`, taking scenes as long as `decoder`
    /// holds, running `firmware` (its name and version, for hosts to show).
    pub fn new<B: AsRef<[u8]> + AsMut<[u8]>>(panel: Panel, firmware: &'a str, decoder: &Decoder<B>) -> Board<'a> {
        let max_scene = u32::try_from(decoder.max_scene()).unwrap_or(u32::MAX);
        Board { panel, max_scene, firmware, room: AnimationNeeds::default() }
    }

    /// Its panel.
    pub fn panel(&self) -> Panel {
        self.panel
    }

    /// The board plays animations in an [`Animation`] that holds `room`.
    pub fn playing_in(self, room: AnimationNeeds) -> Board<'a> {
        Board { room, ..self }
    }

    /// Answers what the decoder `received`: a refusal is sent back, a
    /// hello gets the board's description, a scene is loaded into
    /// `raytracer` and gets its errors, or a [`Drawing`] to render. A
    /// scene whose animation fits `animation` (the board's, if it plays
    /// them) is loaded through it: every frame's camera is checked then.
    /// `Err` when `sink` failed; a scene that loaded is handed back even
    /// when its `drawing` message was not taken (the panel still shows
    /// it; the sink's next writes say whether the host gets the rows).
    pub fn answer<'r, P: Profile, S: Sink + ?Sized>(
        &self,
        received: Result<Frame<'_>, Refusal>,
        raytracer: &'r mut Raytracer<P>,
        animation: Option<&'r mut Animation<'_>>,
        sink: &mut S,
    ) -> Result<Option<Drawing<'r, P>>, S::Error> {
        let Frame { tag, message } = match received {
            Ok(frame) => frame,
            Err(refusal) => return Message::Refused(refusal.reason).encode(refusal.tag, sink).map(|()| None),
        };
        match message {
            Message::Hello => self.hello::<P, S>(tag, sink).map(|()| None),
            Message::Scene { pixels, text } => self.load(Scene { tag, pixels, text }, raytracer, animation, sink),
            other => {
                let refused = Message::Refused(Reason::Unexpected { kind: other.kind().byte() });
                refused.encode(tag, sink).map(|()| None)
            }
        }
    }

    fn hello<P: Profile, S: Sink + ?Sized>(&self, tag: u16, sink: &mut S) -> Result<(), S::Error> {
        let list = CapacityKind::ALL.map(|kind| Capacity { name: kind.field(), count: saturate(P::COUNTS.get(kind)) });
        let info = BoardInfo {
            panel: self.panel,
            max_scene: self.max_scene,
            profile: <P as SceneCapacities>::NAME,
            firmware: self.firmware,
            capacities: Capacities::new(&list),
        };
        Message::Board(info).encode(tag, sink)
    }

    fn load<'r, P: Profile, S: Sink + ?Sized>(
        &self,
        Scene { tag, pixels, text }: Scene<'_>,
        raytracer: &'r mut Raytracer<P>,
        animation: Option<&'r mut Animation<'_>>,
        sink: &mut S,
    ) -> Result<Option<Drawing<'r, P>>, S::Error> {
        let mut failed = None;
        let mut report = |error: ParseError<'_>| {
            if failed.is_none() {
                let capacity = match error.kind {
                    ErrorKind::Capacity(c) => Some(CapacityNeed {
                        name: c.kind.field(),
                        needed: c.needed.map(saturate),
                        holds: saturate(c.capacity),
                    }),
                    _ => None,
                };
                let (line, column) = (error.pos.line, error.pos.column);
                failed = send_error(tag, line, column, capacity, &error.kind, sink).err();
            }
        };
        // An animation the board has room for loads through it: every
        // frame's camera is checked before anything plays.
        let shorts = play::short_of(&self.room, text, self.panel);
        let fits = shorts.iter().all(Option::is_none);
        let loaded = match animation.filter(|_| fits) {
            Some(animation) => match animation.load_with(raytracer, text, &mut report) {
                Ok(frame) => Ok(frame.into_scene()),
                Err(AnimationError::Scene(e)) => Err(e.count),
                // Its room was checked against the scene's needs.
                Err(AnimationError::NoRoom(short)) => {
                    let (line, column) = play::position(&short, text);
                    send_error(tag, line, column, Some(play::capacity(&short)), &short, sink)?;
                    Err(1)
                }
            },
            None => raytracer.load_with(text, AccelMode::Auto, &mut report).map_err(|e| e.count),
        };
        if let Some(e) = failed {
            return Err(e);
        }
        let scene = match loaded {
            Ok(scene) => scene,
            Err(count) => return Message::Rejected { errors: saturate(count) }.encode(tag, sink).map(|()| None),
        };
        // The parser refuses a camera that cannot be set up; this is the
        // check at the panel's size that a renderer makes.
        if let Err(e) = scene.view().check_camera(self.panel.width.into(), self.panel.height.into()) {
            send_error(tag, 0, 0, None, &e, sink)?;
            return Message::Rejected { errors: 1 }.encode(tag, sink).map(|()| None);
        }
        // An animation: its frames, if the board has room to play it.
        let frames = match play::animated(&scene) {
            None => 0,
            Some(frames) => {
                let mut errors = 0;
                for short in shorts.iter().flatten() {
                    let (line, column) = play::position(short, text);
                    send_error(tag, line, column, Some(play::capacity(short)), short, sink)?;
                    errors += 1;
                }
                if errors > 0 {
                    return Message::Rejected { errors }.encode(tag, sink).map(|()| None);
                }
                frames.count
            }
        };
        // Not taken: the rows are not either (see `answer`).
        let _ = Message::Drawing { panel: self.panel, pixels, frames }.encode(tag, sink);
        Ok(Some(Drawing { shown: Shown::Still(scene), tag, pixels, panel: self.panel }))
    }
}

/// A scene the host sent: its frame's tag, whether it wants the rows'
/// pixels, and the text.
struct Scene<'t> {
    tag: u16,
    pixels: bool,
    text: &'t [u8],
}

/// Sends one [`Message::SceneError`], its message written by `message`'s
/// `Display` straight into the frame.
fn send_error<S: Sink + ?Sized>(
    tag: u16,
    line: u32,
    column: u32,
    capacity: Option<CapacityNeed<'_>>,
    message: &dyn fmt::Display,
    sink: &mut S,
) -> Result<(), S::Error> {
    let mut w = FrameWriter::begin(sink, VERSION, Kind::SceneError.byte(), tag)?;
    put_scene_error(&mut w, line, column, capacity, message)?;
    w.finish()
}

/// A scene that loaded, being drawn at the panel's size: render its rows
/// from [`Drawing::scene`], send each with [`Drawing::send_row`] as it is
/// drawn, and close it with [`Drawing::finish`], or with
/// [`Drawing::cancel`] when a frame comes from the host between rows.
pub struct Drawing<'r, P: Profile> {
    shown: Shown<'r, P>,
    tag: u16,
    pixels: bool,
    panel: Panel,
}

/// What a drawing draws.
enum Shown<'r, P: Profile> {
    Still(LoadedScene<'r, P>),
    /// A frame of an animation.
    Frame(AnimationFrame<'r, 'r, P>),
}

impl<P: Profile> fmt::Debug for Drawing<'_, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Drawing")
            .field("tag", &self.tag)
            .field("pixels", &self.pixels)
            .field("panel", &self.panel)
            .field("frame", &self.frame().map(AnimationFrame::number))
            .finish_non_exhaustive()
    }
}

impl<'r, P: Profile> Drawing<'r, P> {
    /// The loaded scene: its view and accelerator for the renderers (a
    /// frame's, for an animation).
    pub fn scene(&self) -> &LoadedScene<'r, P> {
        match &self.shown {
            Shown::Still(scene) => scene,
            Shown::Frame(frame) => frame.scene(),
        }
    }

    /// The panel it is drawn at.
    pub fn panel(&self) -> Panel {
        self.panel
    }

    /// Whether the host asked for the rows' pixels.
    pub fn sends_pixels(&self) -> bool {
        self.pixels
    }

    /// For a frame of an animation, the frame: its draw traces only the
    /// runs its tiles planned, each sent with [`Drawing::send_run`]. None
    /// for a still, drawn row by row.
    pub fn frame(&self) -> Option<&AnimationFrame<'r, 'r, P>> {
        match &self.shown {
            Shown::Still(_) => None,
            Shown::Frame(frame) => Some(frame),
        }
    }

    /// Tells the host row `y` is drawn: `row` is its pixels (the panel's
    /// width of them), sent only if the host asked for them.
    pub fn send_row<S: Sink + ?Sized>(&self, y: u16, row: &[Rgb565], sink: &mut S) -> Result<(), S::Error> {
        let mut w = FrameWriter::begin(sink, VERSION, Kind::Row.byte(), self.tag)?;
        w.put(&y.to_be_bytes())?;
        self.put_pixels(&mut w, row)?;
        w.finish()
    }

    /// Tells the host the pixels `run` of row `y` from column `x` of an
    /// animation's frame are drawn, sent only if the host asked for them.
    pub fn send_run<S: Sink + ?Sized>(&self, y: u16, x: u16, run: &[Rgb565], sink: &mut S) -> Result<(), S::Error> {
        let mut w = FrameWriter::begin(sink, VERSION, Kind::Run.byte(), self.tag)?;
        let width = u16::try_from(run.len()).unwrap_or(u16::MAX);
        for field in [y, x, width] {
            w.put(&field.to_be_bytes())?;
        }
        self.put_pixels(&mut w, &run[..usize::from(width)])?;
        w.finish()
    }

    /// `pixels` in the panel's format, if the host asked for them.
    fn put_pixels<S: Sink + ?Sized>(&self, w: &mut FrameWriter<'_, S>, pixels: &[Rgb565]) -> Result<(), S::Error> {
        if !self.pixels {
            return Ok(());
        }
        for chunk in pixels.chunks(32) {
            let mut bytes = [0u8; 64];
            for (pair, color) in bytes.chunks_exact_mut(2).zip(chunk) {
                pair.copy_from_slice(&color.into_storage().to_be_bytes());
            }
            w.put(&bytes[..2 * chunk.len()])?;
        }
        Ok(())
    }

    /// Every row is drawn: `timing` is what the board measured of the
    /// scene (loading and drawing), by its clock and counters if it has
    /// them ([`Timing::NONE`] if not).
    pub fn finish<S: Sink + ?Sized>(self, timing: &Timing<'_>, sink: &mut S) -> Result<(), S::Error> {
        Message::Done(*timing).encode(self.tag, sink)
    }

    /// The drawing stops after `rows` rows, because a frame came.
    pub fn cancel<S: Sink + ?Sized>(self, rows: u16, sink: &mut S) -> Result<(), S::Error> {
        Message::Cancelled { rows }.encode(self.tag, sink)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::frame::{encode_raw, Reason};
    use crate::list::{Counter, Counters};
    use crate::message::PixelFormat;
    use core::time::Duration;
    use embedded_graphics_core::pixelcolor::Rgb888;
    use octrace_core::profile::Board16K;
    use octrace_core::render::Renderer;
    use std::string::{String, ToString};
    use std::vec::Vec;

    const PANEL: Panel = Panel { width: 12, height: 8, format: PixelFormat::Rgb565 };
    const SCENE: &[u8] = b"SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n";

    /// Hands each frame in `wire` to `each`.
    fn frames(wire: &[u8], mut each: impl FnMut(Frame<'_>)) {
        let mut buffer = std::vec![0u8; 4096];
        let mut decoder = Decoder::new(&mut buffer);
        for &byte in wire {
            if let Some(received) = decoder.push(byte) {
                each(received.expect("the board's frames read"));
            }
        }
    }

    fn kinds(wire: &[u8]) -> Vec<Kind> {
        let mut kinds = Vec::new();
        frames(wire, |f| kinds.push(f.message.kind()));
        kinds
    }

    /// The board's answer to `message` sent with `tag`, and what it drew
    /// (every row, in order), as the firmware's loop does on one core.
    fn ask(raytracer: &mut Raytracer<Board16K>, message: Message<'_>, tag: u16) -> Vec<u8> {
        let mut host = Vec::new();
        message.encode(tag, &mut host).unwrap();
        let mut buffer = [0u8; 1024];
        let mut decoder = Decoder::new(&mut buffer);
        let board = Board::new(PANEL, "test 1", &decoder);
        let mut answer = Vec::new();
        for byte in host {
            let Some(received) = decoder.push(byte) else { continue };
            if let Some(drawing) = board.answer(received, raytracer, None, &mut answer).unwrap() {
                let (w, h) = (PANEL.width as u32, PANEL.height as u32);
                let accelerator = drawing.scene().accelerator();
                let mut renderer = Renderer::with_size(drawing.scene().view(), &accelerator, w, h).unwrap();
                for y in 0..h {
                    let row: Vec<Rgb565> = renderer.row(y, 0..w).map(|p| p.color.into()).collect();
                    drawing.send_row(y as u16, &row, &mut answer).unwrap();
                }
                let counters = [Counter { name: "sram0_contested", load: 7, render: 99 }];
                let timing = Timing {
                    elapsed: Some(Duration::from_millis(12)),
                    load: Some(Duration::from_millis(2)),
                    render: Some(Duration::from_millis(10)),
                    counters: Counters::new(&counters),
                };
                drawing.finish(&timing, &mut answer).unwrap();
            }
        }
        answer
    }

    #[test]
    fn hello_is_answered_with_the_panel_the_buffer_and_the_profile() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let answer = ask(&mut raytracer, Message::Hello, 21);
        let mut seen = 0;
        frames(&answer, |frame| {
            let Message::Board(info) = frame.message else { panic!("{frame:?}") };
            assert_eq!((frame.tag, info.panel, info.max_scene), (21, PANEL, 1024 - 9));
            assert_eq!((info.profile, info.firmware), ("Board16K", "test 1"));
            assert_eq!(info.capacities.len(), CapacityKind::ALL.len());
            for (capacity, kind) in info.capacities.iter().zip(CapacityKind::ALL) {
                assert_eq!((capacity.name, capacity.count as usize), (kind.field(), Board16K::COUNTS.get(kind)));
            }
            seen += 1;
        });
        assert_eq!(seen, 1);
    }

    #[test]
    fn a_scene_is_drawn_row_by_row_as_the_core_draws_it() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let answer = ask(&mut raytracer, Message::Scene { pixels: true, text: SCENE }, 4);
        let expected: Vec<u8> = {
            let mut roomy = Raytracer::<Board16K>::new();
            let scene = roomy.load(core::str::from_utf8(SCENE).unwrap()).unwrap();
            let size = embedded_graphics_core::geometry::Size::new(PANEL.width.into(), PANEL.height.into());
            let mut pixels = std::vec![Rgb565::default(); size.width as usize * size.height as usize];
            let mut grid = Grid(&mut pixels, size);
            scene.image::<Rgb565>(size).try_draw(&mut grid).unwrap();
            pixels.iter().flat_map(|c| c.into_storage().to_be_bytes()).collect()
        };
        let mut received = Vec::new();
        let mut rows = 0;
        frames(&answer, |frame| {
            assert_eq!(frame.tag, 4);
            match frame.message {
                Message::Drawing { panel, pixels, frames } => assert_eq!((panel, pixels, frames), (PANEL, true, 0)),
                Message::Row { y, pixels } => {
                    assert_eq!((y, pixels.len()), (rows, PANEL.row_bytes()));
                    received.extend_from_slice(pixels);
                    rows += 1;
                }
                Message::Done(timing) => {
                    assert_eq!(
                        (timing.elapsed, timing.render),
                        (Some(Duration::from_millis(12)), Some(Duration::from_millis(10)))
                    );
                    let counters: Vec<_> = timing.counters.iter().collect();
                    assert_eq!(counters, [Counter { name: "sram0_contested", load: 7, render: 99 }]);
                }
                other => panic!("{other:?}"),
            }
        });
        assert_eq!(rows, PANEL.height);
        assert_eq!(received, expected);
        assert_ne!(expected.iter().max(), expected.iter().min(), "the sphere is seen");
    }

    #[test]
    fn rows_not_asked_for_carry_no_pixels() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let answer = ask(&mut raytracer, Message::Scene { pixels: false, text: SCENE }, 4);
        frames(&answer, |frame| {
            if let Message::Row { pixels, .. } = frame.message {
                assert!(pixels.is_empty());
            }
        });
        assert_eq!(kinds(&answer).len(), 1 + PANEL.height as usize + 1);
    }

    #[test]
    fn every_error_comes_with_its_position_and_the_cores_message_and_nothing_is_drawn() {
        let text = b"SPHERE 1 -1 0 0 0\nFOO 3\nRASTER 0 5\n";
        let mut expected = Vec::new();
        let _ = Raytracer::<Board16K>::new().load_with(text, AccelMode::Auto, &mut |e| {
            expected.push((e.pos.line, e.pos.column, e.kind.to_string()));
        });
        assert!(expected.len() >= 3, "{expected:?}");
        let mut raytracer = Raytracer::<Board16K>::new();
        let answer = ask(&mut raytracer, Message::Scene { pixels: true, text }, 8);
        let mut errors = Vec::new();
        let mut rejected = None;
        frames(&answer, |frame| match frame.message {
            Message::SceneError(e) => errors.push((e.line, e.column, String::from(e.message))),
            Message::Rejected { errors } => rejected = Some(errors),
            other => panic!("nothing else is sent: {other:?}"),
        });
        assert_eq!(errors, expected);
        assert_eq!(rejected, Some(expected.len() as u32));
        assert_eq!(kinds(&answer).last(), Some(&Kind::Rejected));
    }

    #[test]
    fn a_scene_over_the_capacity_names_it_with_both_counts() {
        let rectangle = "RECTANGLE 1 0 0 0 1 0 0 1 1 0 0 1 0\n";
        let text = std::format!("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n{}", rectangle.repeat(3));
        let mut raytracer = Raytracer::<Board16K>::new();
        let answer = ask(&mut raytracer, Message::Scene { pixels: false, text: text.as_bytes() }, 8);
        let mut needs = Vec::new();
        frames(&answer, |frame| {
            if let Message::SceneError(e) = frame.message {
                let need = e.capacity.expect("a capacity error");
                needs.push((e.line, need.name.to_string(), need.needed, need.holds, e.message.to_string()));
            }
        });
        assert_eq!(needs.len(), 1, "{needs:?}");
        let (line, name, needed, holds, message) = &needs[0];
        assert_eq!((*line, name.as_str(), *needed, *holds), (4, "rectangles", Some(3), 2));
        assert!(message.starts_with("too many rectangles: the capacity profile Board16K holds 2"), "{message}");
    }

    #[test]
    fn refusals_are_sent_back_and_a_boards_own_kinds_are_unexpected() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let answer = ask(&mut raytracer, Message::Rejected { errors: 1 }, 13);
        let mut got = Vec::new();
        frames(&answer, |frame| got.push((frame.tag, frame.message.kind())));
        assert_eq!(got, [(13, Kind::Refused)]);
        let mut wire = Vec::new();
        encode_raw(9, Kind::Hello.byte(), 14, &[], &mut wire).unwrap();
        let mut buffer = [0u8; 64];
        let mut decoder = Decoder::new(&mut buffer);
        let board = Board::new(PANEL, "test 1", &decoder);
        let mut answer = Vec::new();
        for byte in wire {
            if let Some(received) = decoder.push(byte) {
                assert!(board.answer(received, &mut raytracer, None, &mut answer).unwrap().is_none());
            }
        }
        let mut reasons = Vec::new();
        frames(&answer, |frame| match frame.message {
            Message::Refused(reason) => reasons.push((frame.tag, reason)),
            other => panic!("{other:?}"),
        });
        assert_eq!(reasons, [(14, Reason::WrongVersion { expected: VERSION, found: 9 })]);
    }

    /// A row-major picture as a `DrawTarget`.
    struct Grid<'p>(&'p mut [Rgb565], embedded_graphics_core::geometry::Size);

    impl embedded_graphics_core::geometry::OriginDimensions for Grid<'_> {
        fn size(&self) -> embedded_graphics_core::geometry::Size {
            self.1
        }
    }

    impl embedded_graphics_core::draw_target::DrawTarget for Grid<'_> {
        type Color = Rgb565;
        type Error = core::convert::Infallible;

        fn draw_iter<I: IntoIterator<Item = embedded_graphics_core::Pixel<Rgb565>>>(
            &mut self,
            pixels: I,
        ) -> Result<(), Self::Error> {
            for embedded_graphics_core::Pixel(p, c) in pixels {
                self.0[p.y as usize * self.1.width as usize + p.x as usize] = c;
            }
            Ok(())
        }
    }

    #[test]
    fn the_wire_pixel_is_the_raw_rgb565_big_endian() {
        let color: Rgb565 = Rgb888::new(255, 130, 8).into();
        // Red 31 (5 bits), green 32 (6 bits), blue 1 (5 bits): 11111 100000 00001.
        assert_eq!(color.into_storage(), 0b1111_1100_0000_0001);
        assert_eq!(color.into_storage().to_be_bytes(), [0xFC, 0x01]);
    }
}
