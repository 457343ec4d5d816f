//! A frame: the version byte, the message's kind, the request's tag, the
//! payload and a CRC-32, stuffed by COBS between two 0x00 delimiters; and
//! the reasons a received frame is refused.
//!
//! Invariants (frozen across protocol versions, so that ends of different
//! releases can refuse each other clearly): the header is
//! `[version, kind, tag_hi, tag_lo]`, the CRC-32 of everything before it
//! closes the frame, big-endian, and integers are big-endian throughout.

use crate::cobs::{BlockEncoder, Sink};
use crate::crc::Crc32;
use crate::kind::Kind;
use core::fmt;

/// The protocol version this crate speaks: the first byte of every frame.
pub const VERSION: u8 = 3;

/// The header's bytes: version, kind, tag (2).
pub(crate) const HEADER: usize = 4;
/// The CRC-32 closing a frame.
pub(crate) const CRC: usize = 4;
/// A frame's bytes beyond its payload.
pub const OVERHEAD: usize = HEADER + CRC;

/// Why a received frame was refused. A board sends it back in a
/// [`Message::Refused`](crate::Message::Refused); a host's decoder gives it
/// for a frame it cannot read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reason {
    /// The frame is of another protocol version than the receiver's.
    WrongVersion {
        /// The receiver's version.
        expected: u8,
        /// The frame's.
        found: u8,
    },
    /// The frame's CRC-32 is not that of its bytes: damaged on the way.
    BadChecksum {
        /// The CRC the frame carries.
        sent: u32,
        /// The CRC of the bytes received.
        computed: u32,
    },
    /// Bytes between two delimiters that are no frame: cut off inside a
    /// block, or shorter than a header and a CRC.
    Undecodable {
        /// How many bytes came between the delimiters.
        length: u32,
    },
    /// A frame longer than the receiver's buffer.
    TooLong {
        /// The frame's length without its stuffing (saturating).
        length: u32,
        /// The longest frame the receiver holds.
        max: u32,
    },
    /// A message kind the receiver does not take: unknown to it, or one
    /// that only it sends.
    Unexpected {
        /// The kind byte.
        kind: u8,
    },
    /// A message whose payload does not fit its kind's layout.
    Malformed {
        /// The kind byte.
        kind: u8,
    },
}

impl fmt::Display for Reason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Reason::WrongVersion { expected, found } => {
                write!(f, "a frame of protocol version {found}, where version {expected} is spoken")
            }
            Reason::BadChecksum { sent, computed } => {
                write!(f, "a damaged frame: its bytes have the CRC-32 {computed:08x}, but it carries {sent:08x}")
            }
            Reason::Undecodable { length } => {
                write!(f, "{length} bytes that are no frame (cut off, or not octrace's protocol)")
            }
            Reason::TooLong { length, max } => {
                write!(f, "a frame of {length} bytes, longer than the {max} bytes the receiver holds")
            }
            Reason::Unexpected { kind } => match Kind::from_byte(kind) {
                Some(known) => write!(f, "a {known} message, which the receiver does not take"),
                None => write!(f, "a message of the unknown kind {kind:#04x}"),
            },
            Reason::Malformed { kind } => match Kind::from_byte(kind) {
                Some(known) => write!(f, "a {known} message whose payload does not fit its layout"),
                None => write!(f, "a malformed message of the unknown kind {kind:#04x}"),
            },
        }
    }
}

impl core::error::Error for Reason {}

/// A frame that cannot be taken: why, and the tag of the request it
/// answers (0 where the frame's header cannot be trusted: its CRC failed or
/// was never read).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// The refused frame's tag, or 0.
    pub tag: u16,
    /// Why.
    pub reason: Reason,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.reason.fmt(f)
    }
}

impl core::error::Error for Refusal {}

/// A frame whose CRC and version are right: its kind, tag and payload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct RawFrame<'a> {
    pub(crate) kind: u8,
    pub(crate) tag: u16,
    pub(crate) payload: &'a [u8],
}

impl<'a> RawFrame<'a> {
    /// Checks the unstuffed bytes of a frame; `length` is how many bytes
    /// came on the line.
    pub(crate) fn check(bytes: &'a [u8], length: u32) -> Result<RawFrame<'a>, Refusal> {
        let refuse = |tag, reason| Err(Refusal { tag, reason });
        let Some((body, crc)) = bytes.split_last_chunk::<CRC>() else {
            return refuse(0, Reason::Undecodable { length });
        };
        let Some((&[version, kind, tag_hi, tag_lo], payload)) = body.split_first_chunk::<HEADER>() else {
            return refuse(0, Reason::Undecodable { length });
        };
        let (sent, computed) = (u32::from_be_bytes(*crc), Crc32::of(body));
        if sent != computed {
            return refuse(0, Reason::BadChecksum { sent, computed });
        }
        let tag = u16::from_be_bytes([tag_hi, tag_lo]);
        if version != VERSION {
            return refuse(tag, Reason::WrongVersion { expected: VERSION, found: version });
        }
        Ok(RawFrame { kind, tag, payload })
    }
}

/// Writes one frame into a [`Sink`] as its payload comes: the delimiter,
/// the header, the payload, the CRC and the closing delimiter. Holds one
/// COBS block (255 bytes) and one piece for the sink
/// ([`CHUNK`](crate::CHUNK) bytes), never the frame.
pub(crate) struct FrameWriter<'s, S: Sink + ?Sized> {
    sink: &'s mut S,
    blocks: BlockEncoder,
    crc: Crc32,
    /// The sink's error, kept while a `Display` writes through `fmt::Write`.
    failed: Option<S::Error>,
}

impl<'s, S: Sink + ?Sized> FrameWriter<'s, S> {
    /// Starts a frame of `version` (anything but [`VERSION`] only to test
    /// a receiver's refusal).
    pub(crate) fn begin(sink: &'s mut S, version: u8, kind: u8, tag: u16) -> Result<Self, S::Error> {
        let mut blocks = BlockEncoder::new();
        blocks.open(sink)?;
        let mut writer = FrameWriter { sink, blocks, crc: Crc32::new(), failed: None };
        let [tag_hi, tag_lo] = tag.to_be_bytes();
        writer.put(&[version, kind, tag_hi, tag_lo])?;
        Ok(writer)
    }

    pub(crate) fn put(&mut self, bytes: &[u8]) -> Result<(), S::Error> {
        self.crc.update(bytes);
        self.blocks.put(bytes, self.sink)
    }

    /// Writes `text`'s `Display`: a payload's last field, so it needs no
    /// length.
    pub(crate) fn put_display(&mut self, text: &dyn fmt::Display) -> Result<(), S::Error> {
        let written = fmt::write(self, format_args!("{text}"));
        match (written, self.failed.take()) {
            (Err(_), Some(e)) => Err(e),
            // A `Display` that fails of its own accord ends the text there.
            _ => Ok(()),
        }
    }

    /// Closes the frame: the CRC, the last block, the delimiter.
    pub(crate) fn finish(mut self) -> Result<(), S::Error> {
        let crc = self.crc.value().to_be_bytes();
        self.blocks.put(&crc, self.sink)?;
        self.blocks.finish(self.sink)
    }
}

impl<S: Sink + ?Sized> fmt::Write for FrameWriter<'_, S> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.put(s.as_bytes()).map_err(|e| {
            self.failed = Some(e);
            fmt::Error
        })
    }
}

/// Writes a frame of any version, kind and payload: what a test sends to
/// see a receiver refuse a version or a kind. Everything else is written
/// with [`Message::encode`](crate::Message::encode).
///
/// ```
/// use octrace_link::{encode_raw, Decoder, Reason, VERSION};
///
/// let mut wire = Vec::new();
/// encode_raw(1, 0x01, 9, &[], &mut wire).unwrap();
/// let mut buffer = [0u8; 64];
/// let mut decoder = Decoder::new(&mut buffer);
/// let received = wire.iter().find_map(|&b| decoder.push(b).map(|r| r.map(|f| f.tag)));
/// let refused = received.unwrap().unwrap_err();
/// assert_eq!((refused.tag, refused.reason), (9, Reason::WrongVersion { expected: VERSION, found: 1 }));
/// ```
pub fn encode_raw<S: Sink + ?Sized>(
    version: u8,
    kind: u8,
    tag: u16,
    payload: &[u8],
    sink: &mut S,
) -> Result<(), S::Error> {
    let mut writer = FrameWriter::begin(sink, version, kind, tag)?;
    writer.put(payload)?;
    writer.finish()
}
