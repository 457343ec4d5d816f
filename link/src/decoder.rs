//! The receiving end: bytes from the line, one at a time, into a buffer the
//! caller provides (a borrowed slice or a `static` array on a board, a
//! `Vec` on a host); a [`Frame`] or a [`Refusal`] at each delimiter.
//!
//! Invariants: [`Decoder::push`] never panics, allocates nothing and does a
//! bounded amount of work a byte (a frame's CRC and payload are checked at
//! its delimiter, in time linear in its length); a frame cut off anywhere
//! ends at the next delimiter, so the frame after it is read whole; bytes
//! beyond the buffer are counted, not kept.

use crate::cobs::BlockDecoder;
use crate::frame::{RawFrame, Reason, Refusal, OVERHEAD};
use crate::kind::Kind;
use crate::message::Message;

/// A message received whole, with the tag of the request it asks or answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frame<'a> {
    /// The request's tag: chosen by the host, echoed by the board.
    pub tag: u16,
    /// What it says.
    pub message: Message<'a>,
}

/// How a frame ended.
#[derive(Clone, Copy, Debug)]
enum Ended {
    /// Its unstuffed bytes fill the buffer up to this length.
    Held(usize),
    Refused(Refusal),
}

/// Reads frames out of the bytes of a line.
///
/// ```
/// use octrace_link::{Decoder, Kind, Message, Reason};
///
/// let mut wire = Vec::new();
/// Message::Hello.encode(1, &mut wire).unwrap();
/// let cut = wire.len() / 2;
/// // A frame cut off half-way, then a whole one.
/// let line = [&wire[..cut], &wire[..]].concat();
/// let mut buffer = [0u8; 64];
/// let mut decoder = Decoder::new(&mut buffer);
/// let mut received = Vec::new();
/// for byte in line {
///     if let Some(result) = decoder.push(byte) {
///         received.push(result.map(|frame| frame.message.kind()).map_err(|refused| refused.reason));
///     }
/// }
/// assert!(matches!(received[0], Err(Reason::Undecodable { .. })), "{received:?}");
/// assert_eq!(received[1], Ok(Kind::Hello));
/// ```
#[derive(Debug)]
pub struct Decoder<B> {
    buffer: B,
    /// Unstuffed bytes of the frame so far, at most the buffer's length.
    held: usize,
    /// Unstuffed bytes of the frame so far, counted past the buffer
    /// (saturating).
    unstuffed: u32,
    /// Bytes on the line since the last delimiter (saturating).
    length: u32,
    blocks: BlockDecoder,
    /// The frame the last byte ended, and its length on the line.
    ended: Option<(Ended, u32)>,
    /// The kinds it takes: sent by hosts, by boards, or (None) either.
    takes_from_hosts: Option<bool>,
}

impl<B> Decoder<B> {
    /// A decoder keeping frames in `buffer` (`&mut [u8]`, `[u8; N]`,
    /// `Vec<u8>`): a frame longer than it is refused ([`Reason::TooLong`]).
    pub const fn new(buffer: B) -> Decoder<B> {
        Decoder::taking(buffer, None)
    }

    const fn taking(buffer: B, takes_from_hosts: Option<bool>) -> Decoder<B> {
        Decoder { buffer, held: 0, unstuffed: 0, length: 0, blocks: BlockDecoder::new(), ended: None, takes_from_hosts }
    }

    /// A board's decoder: as [`Decoder::new`], but a frame of a kind that
    /// boards send is refused as [`Reason::Unexpected`] before its payload
    /// is read (the protocol checks the kind first).
    ///
    /// ```
    /// use octrace_link::{Decoder, Kind, Message, Reason};
    ///
    /// let mut wire = Vec::new();
    /// Message::Row { y: 0, pixels: &[1, 2, 3] }.encode(9, &mut wire).unwrap();
    /// let mut decoder = Decoder::for_board([0u8; 64]);
    /// let refused = wire.iter().find_map(|&byte| decoder.push(byte).map(|r| r.map(|_| ()))).unwrap().unwrap_err();
    /// assert_eq!((refused.tag, refused.reason), (9, Reason::Unexpected { kind: Kind::Row.byte() }));
    /// ```
    pub const fn for_board(buffer: B) -> Decoder<B> {
        Decoder::taking(buffer, Some(true))
    }

    /// A host's decoder: a frame of a kind that hosts send is refused as
    /// [`Reason::Unexpected`], as [`Decoder::for_board`] does the other way.
    pub const fn for_host(buffer: B) -> Decoder<B> {
        Decoder::taking(buffer, Some(false))
    }
}

impl<B: AsRef<[u8]> + AsMut<[u8]>> Decoder<B> {
    /// The longest frame it holds, in bytes before stuffing.
    pub fn max_frame(&self) -> usize {
        self.buffer.as_ref().len()
    }

    /// The longest scene text it holds: a [`Message::Scene`] frame's
    /// header, flag byte and CRC take 9 bytes of the buffer.
    pub fn max_scene(&self) -> usize {
        self.max_frame().saturating_sub(OVERHEAD + 1)
    }

    /// Takes the next byte of the line. At a delimiter that ends a frame,
    /// gives the frame, or why it cannot be taken; an empty frame (two
    /// delimiters in a row) gives nothing.
    pub fn push(&mut self, byte: u8) -> Option<Result<Frame<'_>, Refusal>> {
        self.ended = None;
        if byte != 0 {
            self.length = self.length.saturating_add(1);
            if let Some(unstuffed) = self.blocks.byte(byte) {
                if let Some(slot) = self.buffer.as_mut().get_mut(self.held) {
                    *slot = unstuffed;
                    self.held += 1;
                }
                self.unstuffed = self.unstuffed.saturating_add(1);
            }
            return None;
        }
        if self.length == 0 {
            return None;
        }
        let length = self.length;
        let ended = if !self.blocks.at_block_end() {
            Ended::Refused(Refusal { tag: 0, reason: Reason::Undecodable { length } })
        } else if self.unstuffed as usize > self.max_frame() {
            let max = u32::try_from(self.max_frame()).unwrap_or(u32::MAX);
            Ended::Refused(Refusal { tag: 0, reason: Reason::TooLong { length: self.unstuffed, max } })
        } else {
            Ended::Held(self.held)
        };
        (self.held, self.unstuffed, self.length, self.blocks) = (0, 0, 0, BlockDecoder::new());
        self.ended = Some((ended, length));
        self.received()
    }

    /// What the last byte pushed ended, again: a board that stopped drawing
    /// for a frame reads it here once the drawing has let go of its scene.
    pub fn received(&self) -> Option<Result<Frame<'_>, Refusal>> {
        let (ended, length) = self.ended?;
        Some(match ended {
            Ended::Refused(refusal) => Err(refusal),
            Ended::Held(held) => RawFrame::check(&self.buffer.as_ref()[..held], length).and_then(|raw| {
                let other_ends = Kind::from_byte(raw.kind)
                    .zip(self.takes_from_hosts)
                    .is_some_and(|(kind, from_hosts)| kind.from_host() != from_hosts);
                let message = match other_ends {
                    true => Err(Reason::Unexpected { kind: raw.kind }),
                    false => Message::decode(raw.kind, raw.payload),
                };
                message
                    .map(|message| Frame { tag: raw.tag, message })
                    .map_err(|reason| Refusal { tag: raw.tag, reason })
            }),
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::frame::{encode_raw, VERSION};
    use crate::kind::Kind;
    use crate::tests::Rng;
    use std::vec::Vec;

    fn scene(tag: u16, text: &[u8]) -> Vec<u8> {
        let mut wire = Vec::new();
        Message::Scene { pixels: false, text }.encode(tag, &mut wire).unwrap();
        wire
    }

    /// Every frame or refusal `line` gives, as (tag, kind) or the refusal.
    fn read(line: &[u8], buffer_len: usize) -> Vec<Result<(u16, Kind), Refusal>> {
        let mut decoder = Decoder::new(std::vec![0u8; buffer_len]);
        line.iter().filter_map(|&b| decoder.push(b).map(|r| r.map(|f| (f.tag, f.message.kind())))).collect()
    }

    fn refused(tag: u16, reason: Reason) -> Result<(u16, Kind), Refusal> {
        Err(Refusal { tag, reason })
    }

    #[test]
    fn delimiters_alone_are_no_frames() {
        assert!(read(&[0, 0, 0, 0], 16).is_empty());
    }

    #[test]
    fn a_frame_cut_anywhere_is_refused_and_the_next_one_read() {
        let first = scene(1, b"SPHERE 1 1 0 0 0\nLIGHT 1 2 3 4\n");
        let second = scene(2, b"RASTER 8 8\n");
        // Cut after the opening delimiter and at least one byte.
        for cut in 2..first.len() - 1 {
            let line = [&first[..cut], &second[..]].concat();
            let received = read(&line, 256);
            assert_eq!(received.len(), 2, "cut at {cut}: {received:?}");
            let refusal = received[0].unwrap_err();
            assert_eq!(refusal.tag, 0, "an untrusted header's tag is not echoed");
            assert!(
                matches!(refusal.reason, Reason::Undecodable { .. } | Reason::BadChecksum { .. }),
                "cut at {cut}: {refusal:?}"
            );
            assert_eq!(received[1], Ok((2, Kind::Scene)), "cut at {cut}");
        }
    }

    #[test]
    fn a_short_frame_is_undecodable() {
        // A code byte and three bytes: shorter than a header and a CRC.
        assert_eq!(read(&[0, 4, 1, 2, 3, 0], 16), [refused(0, Reason::Undecodable { length: 4 })]);
    }

    #[test]
    fn a_frame_longer_than_the_buffer_is_refused_with_both_lengths_and_the_next_one_read() {
        let text = [b'x'; 100];
        let line = [scene(1, &text), scene(2, &text[..40])].concat();
        let received = read(&line, 60);
        assert_eq!(received[0], refused(0, Reason::TooLong { length: 109, max: 60 }));
        assert_eq!(received[1], Ok((2, Kind::Scene)));
        assert_eq!(Decoder::new([0; 60]).max_scene(), 51);
    }

    #[test]
    fn a_damaged_frame_fails_its_checksum() {
        let mut line = scene(9, b"SPHERE 1 1 0 0 0");
        let at = line.len() / 2;
        line[at] ^= 0x20;
        let received = read(&line, 256);
        assert!(matches!(received[..], [Err(Refusal { tag: 0, reason: Reason::BadChecksum { .. } })]), "{received:?}");
    }

    #[test]
    fn another_version_is_refused_with_both_versions() {
        let mut line = Vec::new();
        encode_raw(VERSION + 1, Kind::Hello.byte(), 0x1234, &[], &mut line).unwrap();
        let wrong = Reason::WrongVersion { expected: VERSION, found: VERSION + 1 };
        assert_eq!(read(&line, 64), [refused(0x1234, wrong)]);
    }

    #[test]
    fn each_end_refuses_the_kinds_it_never_receives_before_their_payload() {
        // Every kind, with a payload that fits no kind's layout.
        for kind in Kind::ALL {
            let mut line = Vec::new();
            encode_raw(VERSION, kind.byte(), 0x4b1d, &[0xff], &mut line).unwrap();
            let unexpected = refused(0x4b1d, Reason::Unexpected { kind: kind.byte() });
            let malformed = refused(0x4b1d, Reason::Malformed { kind: kind.byte() });
            let mut board = Decoder::for_board([0u8; 64]);
            let mut host = Decoder::for_host([0u8; 64]);
            let mut either = Decoder::new([0u8; 64]);
            let read = |decoder: &mut Decoder<[u8; 64]>| {
                line.iter().find_map(|&b| decoder.push(b).map(|r| r.map(|f| (f.tag, f.message.kind()))))
            };
            let (at_board, at_host) = match kind.from_host() {
                true => (malformed, unexpected),
                false => (unexpected, malformed),
            };
            assert_eq!(read(&mut board), Some(at_board), "{kind} at a board");
            assert_eq!(read(&mut host), Some(at_host), "{kind} at a host");
            assert_eq!(read(&mut either), Some(malformed), "{kind} at either");
        }
    }

    #[test]
    fn received_gives_the_last_frame_again_until_the_next_byte() {
        let line = scene(5, b"RASTER 1 1");
        let mut decoder = Decoder::new([0u8; 64]);
        for &b in &line {
            let _ = decoder.push(b);
        }
        assert_eq!(decoder.received().map(|r| r.map(|f| f.tag)), Some(Ok(5)));
        assert_eq!(decoder.received().map(|r| r.map(|f| f.tag)), Some(Ok(5)));
        let _ = decoder.push(0);
        assert_eq!(decoder.received(), None);
    }

    #[test]
    fn arbitrary_bytes_never_panic_and_a_whole_frame_after_them_is_read() {
        let mut rng = Rng::from_env("decoder arbitrary_bytes_never_panic_and_a_whole_frame_after_them_is_read");
        let good = scene(0xBEEF, b"VIEWPOINT 0 0 10\nSPHERE 1 1 0 0 0\n");
        for round in 0..3000 {
            let len = rng.below(400) as usize;
            let mut garbage: Vec<u8> = match round % 3 {
                // Any bytes.
                0 => (0..len).map(|_| rng.next() as u8).collect(),
                // Frames with bytes changed, dropped or repeated.
                1 => {
                    let mut frames = [scene(1, b"abc"), good.clone()].concat();
                    for _ in 0..1 + rng.below(4) {
                        let at = rng.below(frames.len() as u64) as usize;
                        match rng.below(3) {
                            0 => frames[at] = rng.next() as u8,
                            1 => drop(frames.remove(at)),
                            _ => frames.insert(at, frames[at]),
                        }
                    }
                    frames
                }
                // Few zeros: long runs that overflow the buffer.
                _ => (0..len * 4).map(|_| 1 + rng.below(255) as u8).collect(),
            };
            let buffer_len = [8, 20, 64, 300][rng.below(4) as usize];
            let received = read(&garbage, buffer_len);
            for result in &received {
                if let Err(refusal) = result {
                    let _ = std::format!("{refusal}");
                }
            }
            garbage.extend_from_slice(&good);
            let received = read(&garbage, 300);
            assert_eq!(received.last(), Some(&Ok((0xBEEF, Kind::Scene))), "round {round}");
        }
    }
}
