//! The messages a host and a board exchange, each a [`Kind`] and a payload
//! laid out byte by byte (docs/board-protocol.md has the same table).
//!
//! Invariants: [`Message::encode`] and [`Message::decode`] are each
//! other's inverse; decoding never panics and takes no payload whose
//! length or values do not fit the kind's layout exactly; strings are
//! UTF-8 and at most 255 bytes where a length byte precedes them.

use crate::cobs::Sink;
use crate::frame::{FrameWriter, Reason, VERSION};
use crate::kind::Kind;
use crate::list::{Capacities, Counters};
use crate::wire::{put_str8, Reader};
use core::fmt;
use core::time::Duration;
use embedded_graphics_core::pixelcolor::raw::RawU16;
use embedded_graphics_core::pixelcolor::{Rgb565, Rgb888};

/// How a panel takes its pixels, and so how a row's pixels are sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum PixelFormat {
    /// 5, 6 and 5 bits of red, green and blue in a big-endian `u16`, as
    /// an ST7789 takes them (embedded-graphics' `Rgb565`'s raw value).
    Rgb565 = 1,
}

impl PixelFormat {
    /// Every format.
    pub const ALL: [PixelFormat; 1] = [PixelFormat::Rgb565];

    /// The format whose byte is `byte`.
    pub fn from_byte(byte: u8) -> Option<PixelFormat> {
        PixelFormat::ALL.into_iter().find(|f| *f as u8 == byte)
    }

    /// Bytes a pixel.
    pub const fn bytes_per_pixel(self) -> usize {
        match self {
            PixelFormat::Rgb565 => 2,
        }
    }

    /// Its name, as host-sim's `--color` says it.
    pub const fn name(self) -> &'static str {
        match self {
            PixelFormat::Rgb565 => "rgb565",
        }
    }

    /// The colours of a row's pixels in this format, widened to 8 bits a
    /// channel as embedded-graphics widens them (what the panel shows);
    /// a last incomplete pixel is left out.
    ///
    /// ```
    /// use embedded_graphics_core::pixelcolor::Rgb888;
    /// use octrace_link::PixelFormat;
    ///
    /// let row = [0xF8, 0x00, 0x00, 0x1F];
    /// let colors: Vec<Rgb888> = PixelFormat::Rgb565.colors(&row).collect();
    /// assert_eq!(colors, [Rgb888::new(255, 0, 0), Rgb888::new(0, 0, 255)]);
    /// ```
    pub fn colors(self, pixels: &[u8]) -> impl Iterator<Item = Rgb888> + '_ {
        match self {
            PixelFormat::Rgb565 => pixels
                .chunks_exact(2)
                .map(|pair| Rgb565::from(RawU16::new(u16::from_be_bytes([pair[0], pair[1]]))).into()),
        }
    }
}

impl fmt::Display for PixelFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A board's panel: what it draws scenes at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Panel {
    /// Pixels across.
    pub width: u16,
    /// Pixels down.
    pub height: u16,
    /// How it takes pixels.
    pub format: PixelFormat,
}

impl Panel {
    /// The longest side of a panel, in pixels: octrace-core's largest image
    /// side (`octrace_core::scene::MAX_SIDE`), so that a host can render
    /// what a board draws and compare.
    pub const MAX_SIDE: u16 = 16384;

    /// Whether both sides are from 1 to [`Panel::MAX_SIDE`], as the protocol
    /// allows; a host refuses any other panel before it sets anything
    /// aside for its picture.
    ///
    /// ```
    /// use octrace_link::{Panel, PixelFormat};
    ///
    /// let panel = |width, height| Panel { width, height, format: PixelFormat::Rgb565 };
    /// assert!(panel(240, 240).within_limits());
    /// assert!(!panel(0, 240).within_limits());
    /// assert!(!panel(65535, 65535).within_limits());
    /// ```
    pub const fn within_limits(&self) -> bool {
        self.width >= 1 && self.width <= Self::MAX_SIDE && self.height >= 1 && self.height <= Self::MAX_SIDE
    }

    /// The bytes of one of its rows.
    pub const fn row_bytes(&self) -> usize {
        self.width as usize * self.format.bytes_per_pixel()
    }
}

/// What a board says of itself, answering [`Message::Hello`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardInfo<'a> {
    /// What it draws on.
    pub panel: Panel,
    /// The longest scene text it takes, in bytes.
    pub max_scene: u32,
    /// Its capacity profile's name.
    pub profile: &'a str,
    /// Its firmware's name and version.
    pub firmware: &'a str,
    /// What its profile holds.
    pub capacities: Capacities<'a>,
}

/// A capacity a scene needs more of than the board holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CapacityNeed<'a> {
    /// The capacity's `profile!` field name (`"rectangles"`).
    pub name: &'a str,
    /// How many the scene needs, when the board knows.
    pub needed: Option<u32>,
    /// How many the board holds.
    pub holds: u32,
}

/// One error of a scene, as the board's parser reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneError<'a> {
    /// Its line, from 1 (0: the error concerns the whole scene).
    pub line: u32,
    /// Its column in characters, from 1 (0 with line 0).
    pub column: u32,
    /// For an error of capacity, which one and the counts.
    pub capacity: Option<CapacityNeed<'a>>,
    /// The message, exactly as octrace-core's `Display` writes it (without
    /// the position).
    pub message: &'a str,
}

/// A message between a host and a board: what a frame carries.
///
/// ```
/// use octrace_link::{Decoder, Message};
///
/// let mut wire = Vec::new();
/// Message::Scene { pixels: true, text: b"SPHERE 1 1 0 0 0" }.encode(42, &mut wire).unwrap();
/// let mut buffer = [0u8; 256];
/// let mut decoder = Decoder::new(&mut buffer);
/// for &byte in &wire[..wire.len() - 1] {
///     assert!(decoder.push(byte).is_none(), "the frame ends at its last delimiter");
/// }
/// let frame = decoder.push(0).unwrap().unwrap();
/// assert_eq!(frame.tag, 42);
/// assert_eq!(frame.message, Message::Scene { pixels: true, text: b"SPHERE 1 1 0 0 0" });
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Message<'a> {
    /// Host: who are you?
    Hello,
    /// Host: draw this scene text; send the pixels of each row if `pixels`.
    Scene {
        /// Whether rows come back with their pixels.
        pixels: bool,
        /// The scene text (not checked here: the parser reports invalid
        /// UTF-8 at its line and column).
        text: &'a [u8],
    },
    /// Board: what it is.
    Board(BoardInfo<'a>),
    /// Board: an error of the scene (one message each).
    SceneError(SceneError<'a>),
    /// Board: the scene had this many errors, all sent; nothing is drawn.
    Rejected {
        /// How many [`Message::SceneError`]s were sent.
        errors: u32,
    },
    /// Board: the scene loaded; rows follow, or an animation's runs.
    Drawing {
        /// What it is drawn at.
        panel: Panel,
        /// Whether the rows (or runs) carry their pixels.
        pixels: bool,
        /// 0 for a still; an animation's frames, played in a loop.
        frames: u32,
    },
    /// Board: row `y` is drawn.
    Row {
        /// The row, from 0 at the top.
        y: u16,
        /// Its pixels in the panel's format, or none if they were not asked for.
        pixels: &'a [u8],
    },
    /// Board: every row is drawn, and what it measured of the scene.
    Done(Timing<'a>),
    /// Board: it stopped drawing when another frame came.
    Cancelled {
        /// How many rows were drawn.
        rows: u16,
    },
    /// Board: `width` pixels of row `y` from column `x` of an animation's
    /// frame are drawn (the pixels its motion may have changed).
    Run {
        /// The row, from 0 at the top.
        y: u16,
        /// The run's first column, from 0 at the left.
        x: u16,
        /// Its pixels.
        width: u16,
        /// Its pixels in the panel's format, or none if they were not asked for.
        pixels: &'a [u8],
    },
    /// Board: frame `frame` of the animation is on the panel, every run
    /// of it sent.
    FrameDrawn {
        /// The frame, from 0 (after the last comes 0 again).
        frame: u32,
        /// Pixels traced for it (the others kept their value).
        traced: u32,
        /// How long loading and drawing it took, by the board's clock, if it has one.
        elapsed: Option<Duration>,
    },
    /// Board: it stopped playing the animation when another frame came.
    Stopped {
        /// How many frames were drawn whole since it began.
        frames: u32,
    },
    /// Board: it is still working on the request, though it has sent
    /// nothing else for a while (a pixel may take hours): a host keeps
    /// waiting.
    Working {
        /// Since the request came, by the board's clock, if it has one.
        elapsed: Option<Duration>,
    },
    /// Board: it could not take a frame.
    Refused(Reason),
}

/// What a board measured of a scene it drew ([`Message::Done`]), by its own
/// clock and hardware counters: a board without a clock sends no times, one
/// that counts nothing no counters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timing<'a> {
    /// From the scene received to its last row drawn: parse, index and render.
    pub elapsed: Option<Duration>,
    /// Parsing and indexing the scene.
    pub load: Option<Duration>,
    /// Drawing it, its first row to its last.
    pub render: Option<Duration>,
    /// What the board's hardware counted over the load and the render.
    pub counters: Counters<'a>,
}

impl Timing<'_> {
    /// A board without a clock or counters.
    pub const NONE: Timing<'static> = Timing { elapsed: None, load: None, render: None, counters: Counters::new(&[]) };
}

/// A time missing on the wire.
const NO_TIME: u64 = u64::MAX;
/// A [`CapacityNeed`] without the count needed on the wire.
const NO_COUNT: u32 = u32::MAX;

impl<'a> Message<'a> {
    /// Its kind.
    pub const fn kind(&self) -> Kind {
        match self {
            Message::Hello => Kind::Hello,
            Message::Scene { .. } => Kind::Scene,
            Message::Board(_) => Kind::Board,
            Message::SceneError(_) => Kind::SceneError,
            Message::Rejected { .. } => Kind::Rejected,
            Message::Drawing { .. } => Kind::Drawing,
            Message::Row { .. } => Kind::Row,
            Message::Done(_) => Kind::Done,
            Message::Cancelled { .. } => Kind::Cancelled,
            Message::Run { .. } => Kind::Run,
            Message::FrameDrawn { .. } => Kind::FrameDrawn,
            Message::Stopped { .. } => Kind::Stopped,
            Message::Working { .. } => Kind::Working,
            Message::Refused(_) => Kind::Refused,
        }
    }

    /// Writes the message as one frame answering (or asking, from a host)
    /// the request `tag`. The sink gets at most [`CHUNK`](crate::CHUNK)
    /// bytes a write; nothing is buffered beyond one COBS block.
    pub fn encode<S: Sink + ?Sized>(&self, tag: u16, sink: &mut S) -> Result<(), S::Error> {
        let mut w = FrameWriter::begin(sink, VERSION, self.kind().byte(), tag)?;
        match *self {
            Message::Hello => {}
            Message::Scene { pixels, text } => {
                w.put(&[pixels as u8])?;
                w.put(text)?;
            }
            Message::Board(info) => {
                put_panel(&mut w, &info.panel)?;
                w.put(&info.max_scene.to_be_bytes())?;
                put_str8(&mut w, info.profile)?;
                put_str8(&mut w, info.firmware)?;
                info.capacities.write(&mut w)?;
            }
            Message::SceneError(e) => put_scene_error(&mut w, e.line, e.column, e.capacity, &e.message)?,
            Message::Rejected { errors } => w.put(&errors.to_be_bytes())?,
            Message::Drawing { panel, pixels, frames } => {
                put_panel(&mut w, &panel)?;
                w.put(&[pixels as u8])?;
                w.put(&frames.to_be_bytes())?;
            }
            Message::Row { y, pixels } => {
                w.put(&y.to_be_bytes())?;
                w.put(pixels)?;
            }
            Message::Done(timing) => {
                for time in [timing.elapsed, timing.load, timing.render] {
                    w.put(&time_on_wire(time).to_be_bytes())?;
                }
                timing.counters.write(&mut w)?;
            }
            Message::Cancelled { rows } => w.put(&rows.to_be_bytes())?,
            Message::Run { y, x, width, pixels } => {
                for field in [y, x, width] {
                    w.put(&field.to_be_bytes())?;
                }
                w.put(pixels)?;
            }
            Message::FrameDrawn { frame, traced, elapsed } => {
                w.put(&frame.to_be_bytes())?;
                w.put(&traced.to_be_bytes())?;
                w.put(&time_on_wire(elapsed).to_be_bytes())?;
            }
            Message::Stopped { frames } => w.put(&frames.to_be_bytes())?,
            Message::Working { elapsed } => w.put(&time_on_wire(elapsed).to_be_bytes())?,
            Message::Refused(reason) => put_reason(&mut w, reason)?,
        }
        w.finish()
    }

    /// The message of `kind` in `payload`; [`Reason::Unexpected`] for an
    /// unknown kind, [`Reason::Malformed`] for a payload that does not fit.
    pub(crate) fn decode(kind: u8, payload: &'a [u8]) -> Result<Message<'a>, Reason> {
        let known = Kind::from_byte(kind).ok_or(Reason::Unexpected { kind })?;
        let mut r = Reader(payload);
        let message = match known {
            Kind::Hello => Some(Message::Hello),
            Kind::Scene => r.flag().map(|pixels| Message::Scene { pixels, text: r.rest() }),
            Kind::Board => read_board(&mut r).map(Message::Board),
            Kind::SceneError => read_scene_error(&mut r).map(Message::SceneError),
            Kind::Rejected => r.u32().map(|errors| Message::Rejected { errors }),
            Kind::Drawing => read_panel(&mut r)
                .and_then(|panel| Some(Message::Drawing { panel, pixels: r.flag()?, frames: r.u32()? })),
            Kind::Row => r.u16().map(|y| Message::Row { y, pixels: r.rest() }),
            Kind::Done => read_timing(&mut r).map(Message::Done),
            Kind::Cancelled => r.u16().map(|rows| Message::Cancelled { rows }),
            Kind::Run => (|| Some(Message::Run { y: r.u16()?, x: r.u16()?, width: r.u16()?, pixels: r.rest() }))(),
            Kind::FrameDrawn => {
                (|| Some(Message::FrameDrawn { frame: r.u32()?, traced: r.u32()?, elapsed: time_from_wire(r.u64()?) }))(
                )
            }
            Kind::Stopped => r.u32().map(|frames| Message::Stopped { frames }),
            Kind::Working => r.u64().map(|micros| Message::Working { elapsed: time_from_wire(micros) }),
            Kind::Refused => read_reason(&mut r).map(Message::Refused),
        };
        message.filter(|_| r.0.is_empty()).ok_or(Reason::Malformed { kind })
    }
}

/// A board's time as the wire carries it: microseconds, the longest it
/// carries for a longer one, [`NO_TIME`] for none.
fn time_on_wire(elapsed: Option<Duration>) -> u64 {
    elapsed.map_or(NO_TIME, |t| u64::try_from(t.as_micros()).unwrap_or(u64::MAX).min(NO_TIME - 1))
}

fn time_from_wire(micros: u64) -> Option<Duration> {
    (micros != NO_TIME).then(|| Duration::from_micros(micros))
}

fn put_panel<S: Sink + ?Sized>(w: &mut FrameWriter<'_, S>, panel: &Panel) -> Result<(), S::Error> {
    w.put(&panel.width.to_be_bytes())?;
    w.put(&panel.height.to_be_bytes())?;
    w.put(&[panel.format as u8])
}

fn read_panel(r: &mut Reader<'_>) -> Option<Panel> {
    Some(Panel { width: r.u16()?, height: r.u16()?, format: PixelFormat::from_byte(r.u8()?)? })
}

/// A [`Message::SceneError`]'s payload, its message from any `Display`:
/// the board writes octrace-core's error straight into the frame.
pub(crate) fn put_scene_error<S: Sink + ?Sized>(
    w: &mut FrameWriter<'_, S>,
    line: u32,
    column: u32,
    capacity: Option<CapacityNeed<'_>>,
    message: &dyn fmt::Display,
) -> Result<(), S::Error> {
    w.put(&line.to_be_bytes())?;
    w.put(&column.to_be_bytes())?;
    match capacity {
        None => w.put(&[0])?,
        Some(need) => {
            w.put(&[1])?;
            put_str8(w, need.name)?;
            let needed = need.needed.map_or(NO_COUNT, |n| n.min(NO_COUNT - 1));
            w.put(&needed.to_be_bytes())?;
            w.put(&need.holds.to_be_bytes())?;
        }
    }
    w.put_display(message)
}

fn read_scene_error<'a>(r: &mut Reader<'a>) -> Option<SceneError<'a>> {
    let (line, column) = (r.u32()?, r.u32()?);
    let capacity = match r.flag()? {
        false => None,
        true => {
            let (name, needed, holds) = (r.str8()?, r.u32()?, r.u32()?);
            Some(CapacityNeed { name, needed: (needed != NO_COUNT).then_some(needed), holds })
        }
    };
    Some(SceneError { line, column, capacity, message: core::str::from_utf8(r.rest()).ok()? })
}

fn read_board<'a>(r: &mut Reader<'a>) -> Option<BoardInfo<'a>> {
    let panel = read_panel(r)?;
    let (max_scene, profile, firmware) = (r.u32()?, r.str8()?, r.str8()?);
    Some(BoardInfo { panel, max_scene, profile, firmware, capacities: Capacities::read(r)? })
}

fn read_timing<'a>(r: &mut Reader<'a>) -> Option<Timing<'a>> {
    let mut time = || r.u64().map(time_from_wire);
    let (elapsed, load, render) = (time()?, time()?, time()?);
    Some(Timing { elapsed, load, render, counters: Counters::read(r)? })
}

/// The codes of [`Reason`]s on the wire. `WrongVersion`'s (1, then the
/// expected and the found version) is frozen across versions.
mod reason_code {
    pub(super) const WRONG_VERSION: u8 = 1;
    pub(super) const BAD_CHECKSUM: u8 = 2;
    pub(super) const UNDECODABLE: u8 = 3;
    pub(super) const TOO_LONG: u8 = 4;
    pub(super) const UNEXPECTED: u8 = 5;
    pub(super) const MALFORMED: u8 = 6;
}

fn put_reason<S: Sink + ?Sized>(w: &mut FrameWriter<'_, S>, reason: Reason) -> Result<(), S::Error> {
    use reason_code::*;
    match reason {
        Reason::WrongVersion { expected, found } => w.put(&[WRONG_VERSION, expected, found]),
        Reason::BadChecksum { sent, computed } => {
            w.put(&[BAD_CHECKSUM])?;
            w.put(&sent.to_be_bytes())?;
            w.put(&computed.to_be_bytes())
        }
        Reason::Undecodable { length } => {
            w.put(&[UNDECODABLE])?;
            w.put(&length.to_be_bytes())
        }
        Reason::TooLong { length, max } => {
            w.put(&[TOO_LONG])?;
            w.put(&length.to_be_bytes())?;
            w.put(&max.to_be_bytes())
        }
        Reason::Unexpected { kind } => w.put(&[UNEXPECTED, kind]),
        Reason::Malformed { kind } => w.put(&[MALFORMED, kind]),
    }
}

fn read_reason(r: &mut Reader<'_>) -> Option<Reason> {
    use reason_code::*;
    Some(match r.u8()? {
        WRONG_VERSION => Reason::WrongVersion { expected: r.u8()?, found: r.u8()? },
        BAD_CHECKSUM => Reason::BadChecksum { sent: r.u32()?, computed: r.u32()? },
        UNDECODABLE => Reason::Undecodable { length: r.u32()? },
        TOO_LONG => Reason::TooLong { length: r.u32()?, max: r.u32()? },
        UNEXPECTED => Reason::Unexpected { kind: r.u8()? },
        MALFORMED => Reason::Malformed { kind: r.u8()? },
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::decoder::Decoder;
    use crate::frame::{encode_raw, Refusal};
    use crate::list::{Capacity, Counter};
    use crate::tests::Rng;
    use std::string::String;
    use std::vec::Vec;

    /// `message` through a frame and a decoder.
    fn round_trip(message: &Message<'_>, tag: u16) {
        let mut wire = Vec::new();
        message.encode(tag, &mut wire).unwrap();
        assert_eq!((wire[0], *wire.last().unwrap()), (0, 0), "delimited");
        assert!(!wire[1..wire.len() - 1].contains(&0), "no 0x00 inside");
        let mut buffer = std::vec![0u8; wire.len()];
        let mut decoder = Decoder::new(&mut buffer);
        let mut frames = 0;
        for &byte in &wire {
            if let Some(received) = decoder.push(byte) {
                assert_eq!(received, Ok(crate::Frame { tag, message: *message }));
                frames += 1;
            }
        }
        assert_eq!(frames, 1);
    }

    /// What a payload of `kind` decodes to.
    fn decode_payload(kind: Kind, payload: &[u8]) -> Result<Kind, Refusal> {
        let mut wire = Vec::new();
        encode_raw(VERSION, kind.byte(), 3, payload, &mut wire).unwrap();
        let mut buffer = [0u8; 512];
        let mut decoder = Decoder::new(&mut buffer);
        wire.iter().find_map(|&b| decoder.push(b).map(|r| r.map(|f| f.message.kind()))).unwrap()
    }

    /// Up to `most` characters of one to three bytes.
    fn text(rng: &mut Rng, most: u64) -> String {
        const LETTERS: [char; 6] = ['a', 'Z', ' ', '\n', 'ü', '∑'];
        (0..rng.below(most)).map(|_| LETTERS[rng.below(6) as usize]).collect()
    }

    #[test]
    fn every_kind_reads_back() {
        let mut rng = Rng::from_env("message every_kind_reads_back");
        for _ in 0..300 {
            let tag = rng.next() as u16;
            let words = text(&mut rng, 300);
            let bytes: Vec<u8> = (0..rng.below(600)).map(|_| rng.next() as u8).collect();
            let panel = Panel { width: rng.next() as u16, height: rng.next() as u16, format: PixelFormat::Rgb565 };
            let names: Vec<String> = (0..rng.below(20)).map(|_| text(&mut rng, 30)).collect();
            let list: Vec<Capacity<'_>> =
                names.iter().map(|name| Capacity { name, count: rng.next() as u32 }).collect();
            let counted: Vec<Counter<'_>> =
                names.iter().map(|name| Counter { name, load: rng.next() as u32, render: rng.next() as u32 }).collect();
            let time = |rng: &mut Rng| (rng.below(2) == 1).then(|| Duration::from_micros(rng.below(1 << 40)));
            let timing = Timing {
                elapsed: time(&mut rng),
                load: time(&mut rng),
                render: time(&mut rng),
                counters: Counters::new(&counted),
            };
            let short = &words[..words.floor_char_boundary(rng.below(255) as usize)];
            let info = BoardInfo {
                panel,
                max_scene: rng.next() as u32,
                profile: short,
                firmware: "octrace 0.1",
                capacities: Capacities::new(&list),
            };
            let need = CapacityNeed { name: "spheres", needed: Some(rng.below(1000) as u32), holds: 7 };
            let error = SceneError { line: 1 + rng.below(99) as u32, column: 3, capacity: None, message: &words };
            let reasons = [
                Reason::WrongVersion { expected: 1, found: rng.next() as u8 },
                Reason::BadChecksum { sent: rng.next() as u32, computed: rng.next() as u32 },
                Reason::Undecodable { length: rng.next() as u32 },
                Reason::TooLong { length: rng.next() as u32, max: rng.next() as u32 },
                Reason::Unexpected { kind: rng.next() as u8 },
                Reason::Malformed { kind: rng.next() as u8 },
            ];
            let messages = [
                Message::Hello,
                Message::Scene { pixels: rng.below(2) == 1, text: &bytes },
                Message::Board(info),
                Message::SceneError(error),
                Message::SceneError(SceneError { capacity: Some(need), ..error }),
                Message::SceneError(SceneError { capacity: Some(CapacityNeed { needed: None, ..need }), ..error }),
                Message::Rejected { errors: rng.next() as u32 },
                Message::Drawing { panel, pixels: rng.below(2) == 1, frames: rng.next() as u32 },
                Message::Run { y: rng.next() as u16, x: rng.next() as u16, width: rng.next() as u16, pixels: &bytes },
                Message::FrameDrawn {
                    frame: rng.next() as u32,
                    traced: rng.next() as u32,
                    elapsed: Some(Duration::from_micros(rng.below(1 << 40))),
                },
                Message::FrameDrawn { frame: 0, traced: 0, elapsed: None },
                Message::Stopped { frames: rng.next() as u32 },
                Message::Working { elapsed: Some(Duration::from_micros(rng.below(1 << 40))) },
                Message::Working { elapsed: None },
                Message::Row { y: rng.next() as u16, pixels: &bytes },
                Message::Done(timing),
                Message::Done(Timing::NONE),
                Message::Cancelled { rows: rng.next() as u16 },
                Message::Refused(reasons[rng.below(6) as usize]),
            ];
            for message in &messages {
                round_trip(message, tag);
            }
        }
    }

    /// The hex of `bytes` as the documentation writes it.
    fn hex(bytes: &[u8]) -> String {
        bytes.iter().map(|b| std::format!("{b:02x}")).collect::<Vec<_>>().join(" ")
    }

    #[test]
    fn the_frames_of_the_documentation_are_what_is_written() {
        let doc = include_str!("../../docs/board-protocol.md");
        let examples = [
            (Message::Hello, 1),
            (Message::Scene { pixels: true, text: b"RASTER 4 2\n" }, 0x1234),
            (Message::Row { y: 1, pixels: &[0xF8, 0, 0x07, 0xE0, 0, 0x1F, 0xFF, 0xFF] }, 0x1234),
            (Message::Refused(Reason::WrongVersion { expected: 3, found: 2 }), 0x1234),
            (Message::Run { y: 1, x: 2, width: 2, pixels: &[0xF8, 0, 0x07, 0xE0] }, 0x1234),
            (Message::Working { elapsed: Some(Duration::from_micros(2_500_000)) }, 0x1234),
        ];
        for (message, tag) in examples {
            let mut wire = Vec::new();
            message.encode(tag, &mut wire).unwrap();
            let on_line = std::format!("on line:  {}\n", hex(&wire));
            assert!(doc.contains(&on_line), "{message:?}: {on_line}");
        }
        for kind in Kind::ALL {
            let row = std::format!("| 0x{:02X} | `{}` |", kind.byte(), kind.name());
            assert!(doc.contains(&row), "{kind} is documented: {row}");
        }
    }

    #[test]
    fn pixel_formats_and_bytes_agree() {
        assert_eq!(PixelFormat::from_byte(1), Some(PixelFormat::Rgb565));
        assert_eq!(PixelFormat::from_byte(2), None);
    }

    #[test]
    fn long_strings_are_cut_at_a_character() {
        let long = "∑".repeat(100); // 300 bytes
        let info = BoardInfo {
            panel: Panel { width: 1, height: 1, format: PixelFormat::Rgb565 },
            max_scene: 0,
            profile: &long,
            firmware: "",
            capacities: Capacities::new(&[]),
        };
        let mut wire = Vec::new();
        Message::Board(info).encode(0, &mut wire).unwrap();
        let mut buffer = [0u8; 512];
        let mut decoder = Decoder::new(&mut buffer);
        assert!(wire.iter().any(|&b| decoder.push(b).is_some()));
        let frame = decoder.received().unwrap().unwrap();
        let Message::Board(received) = frame.message else { panic!("{frame:?}") };
        assert_eq!(received.profile, "∑".repeat(85), "255 bytes hold 85 whole characters");
    }

    #[test]
    fn a_payload_that_does_not_fit_its_kind_is_malformed() {
        let malformed = |kind: Kind| Err(Refusal { tag: 3, reason: Reason::Malformed { kind: kind.byte() } });
        let cases: [(Kind, &[u8]); 23] = [
            (Kind::Hello, &[0]),
            (Kind::Scene, &[]),
            (Kind::Scene, &[2, b'x']),
            (Kind::Board, &[0, 1, 0, 1, 1, 0, 0, 0, 9, 0, 0]),
            (Kind::Board, &[0, 1, 0, 1, 1, 0, 0, 0, 9, 0, 0, 1, 1, b'a']),
            (Kind::Board, &[0, 1, 0, 1, 9, 0, 0, 0, 9, 0, 0, 0]),
            (Kind::SceneError, &[0, 0, 0, 1, 0, 0, 0, 1, 2]),
            (Kind::SceneError, &[0, 0, 0, 1, 0, 0, 0, 1, 0, 0xFF]),
            (Kind::SceneError, &[0, 0, 0, 1, 0, 0, 0, 1, 1, 1, b'a', 0, 0]),
            (Kind::Rejected, &[0, 0, 1]),
            (Kind::Drawing, &[0, 1, 0, 1, 1, 2, 0, 0, 0, 0]),
            (Kind::Drawing, &[0, 1, 0, 1, 1, 1]),
            (Kind::Run, &[0, 1, 0, 2, 0]),
            (Kind::FrameDrawn, &[0; 15]),
            (Kind::Row, &[7]),
            (Kind::Done, &[0; 9]),
            (Kind::Done, &[0; 24]),
            (Kind::Cancelled, &[0, 0, 0]),
            (Kind::Stopped, &[0, 0, 0]),
            (Kind::Working, &[0; 7]),
            (Kind::Working, &[0; 9]),
            (Kind::Refused, &[9, 0]),
            (Kind::Refused, &[1, 1]),
        ];
        for (kind, payload) in cases {
            assert_eq!(decode_payload(kind, payload), malformed(kind), "{kind} {payload:?}");
        }
        // And the same layouts, whole, read.
        assert_eq!(decode_payload(Kind::Board, &[0, 1, 0, 1, 1, 0, 0, 0, 9, 0, 0, 0]), Ok(Kind::Board));
        assert_eq!(decode_payload(Kind::SceneError, &[0, 0, 0, 1, 0, 0, 0, 1, 0, b'a']), Ok(Kind::SceneError));
        assert_eq!(decode_payload(Kind::Refused, &[1, 1, 2]), Ok(Kind::Refused));
        assert_eq!(decode_payload(Kind::Done, &[0; 25]), Ok(Kind::Done));
    }

    #[test]
    fn unknown_kinds_are_unexpected() {
        for byte in (0..=255).filter(|&b| Kind::from_byte(b).is_none()) {
            let mut wire = Vec::new();
            encode_raw(VERSION, byte, 77, &[1, 2, 3], &mut wire).unwrap();
            let mut buffer = [0u8; 64];
            let mut decoder = Decoder::new(&mut buffer);
            let received = wire.iter().find_map(|&b| decoder.push(b).map(|r| r.map(|f| f.tag))).unwrap();
            assert_eq!(received, Err(Refusal { tag: 77, reason: Reason::Unexpected { kind: byte } }));
        }
    }

    #[test]
    fn reasons_say_what_was_wrong() {
        let said = |reason: Reason| std::format!("{reason}");
        assert_eq!(
            said(Reason::WrongVersion { expected: 1, found: 2 }),
            "a frame of protocol version 2, where version 1 is spoken"
        );
        assert_eq!(said(Reason::Unexpected { kind: 0x45 }), "a row message, which the receiver does not take");
        assert_eq!(said(Reason::Unexpected { kind: 0x30 }), "a message of the unknown kind 0x30");
        assert_eq!(said(Reason::Malformed { kind: 0x02 }), "a scene message whose payload does not fit its layout");
        assert!(said(Reason::TooLong { length: 70000, max: 16384 }).contains("70000 bytes"));
    }
}
