//! Consistent overhead byte stuffing (COBS): a frame's bytes rewritten
//! without any 0x00, so that 0x00 can delimit frames. A receiver that joins
//! the line at any point, or loses bytes, is back in step at the next 0x00.
//!
//! Each block is a code byte `c` (1 to 255) and `c − 1` data bytes; a block
//! whose code is below 255 stands for its data followed by a 0x00, except
//! the frame's last block, whose 0x00 is dropped.
//!
//! Invariants: the encoder never writes 0x00 inside a frame and writes at
//! most [`CHUNK`] bytes in one [`Sink::write_all`]; the decoder takes one
//! byte at a time and yields at most one byte for each.

/// The most bytes the encoder hands a [`Sink`] at once: a USB full-speed
/// bulk packet.
pub const CHUNK: usize = 64;

/// Where encoded frames go: a serial port, a USB endpoint's buffer, memory.
///
/// A board implements it over its USB serial class; on a host, the `std`
/// feature implements it for every `std::io::Write`.
///
/// ```
/// use octrace_link::{Message, Sink};
///
/// /// Counts the bytes of the frames written to it.
/// struct Counter(usize);
///
/// impl Sink for Counter {
///     type Error = core::convert::Infallible;
///     fn write_all(&mut self, bytes: &[u8]) -> Result<(), Self::Error> {
///         assert!(bytes.len() <= octrace_link::CHUNK);
///         self.0 += bytes.len();
///         Ok(())
///     }
/// }
///
/// let mut counter = Counter(0);
/// Message::Hello.encode(7, &mut counter).unwrap();
/// // Two delimiters, a code byte, the 4-byte header and the 4-byte CRC.
/// assert_eq!(counter.0, 11);
/// ```
pub trait Sink {
    /// Why a write failed.
    type Error;
    /// Writes all of `bytes` (at most [`CHUNK`]), in order.
    fn write_all(&mut self, bytes: &[u8]) -> Result<(), Self::Error>;
}

#[cfg(feature = "std")]
impl<W: std::io::Write + ?Sized> Sink for W {
    type Error = std::io::Error;

    fn write_all(&mut self, bytes: &[u8]) -> Result<(), std::io::Error> {
        std::io::Write::write_all(self, bytes)
    }
}

/// The longest run of data bytes in one block.
const MAX_RUN: usize = 254;

/// Encodes a frame as it comes, one block behind: a block is written once
/// its end is known.
pub(crate) struct BlockEncoder {
    /// The code byte's place, then the block's data bytes.
    block: [u8; MAX_RUN + 1],
    /// Data bytes in `block`.
    run: usize,
    /// The encoded bytes on their way to the sink.
    pieces: Pieces,
}

impl BlockEncoder {
    pub(crate) const fn new() -> BlockEncoder {
        BlockEncoder { block: [0; MAX_RUN + 1], run: 0, pieces: Pieces { bytes: [0; CHUNK], len: 0 } }
    }

    /// The delimiter before a frame: it ends whatever half frame the
    /// receiver holds.
    pub(crate) fn open<S: Sink + ?Sized>(&mut self, sink: &mut S) -> Result<(), S::Error> {
        self.pieces.add(&[0], sink)
    }

    /// Takes the frame's next bytes.
    pub(crate) fn put<S: Sink + ?Sized>(&mut self, bytes: &[u8], sink: &mut S) -> Result<(), S::Error> {
        for &byte in bytes {
            if byte == 0 {
                self.end_block(sink)?;
                continue;
            }
            self.run += 1;
            self.block[self.run] = byte;
            if self.run == MAX_RUN {
                self.end_block(sink)?;
            }
        }
        Ok(())
    }

    /// Writes the last block (its 0x00 is the delimiter's) and the closing
    /// delimiter, and hands the sink all that is left.
    pub(crate) fn finish<S: Sink + ?Sized>(&mut self, sink: &mut S) -> Result<(), S::Error> {
        self.end_block(sink)?;
        self.pieces.add(&[0], sink)?;
        self.pieces.flush(sink)
    }

    /// Writes the block so far with its code and starts the next.
    fn end_block<S: Sink + ?Sized>(&mut self, sink: &mut S) -> Result<(), S::Error> {
        // `run` is at most 254: the code is at most 255 and never 0.
        self.block[0] = (self.run + 1) as u8;
        let block = &self.block[..self.run + 1];
        self.run = 0;
        self.pieces.add(block, sink)
    }
}

/// Encoded bytes gathered into whole [`CHUNK`]s for the sink: a run of
/// zeros (a black row) is a block a byte, but a write a packet, not a byte.
struct Pieces {
    bytes: [u8; CHUNK],
    /// Bytes in `bytes`.
    len: usize,
}

impl Pieces {
    /// Adds `bytes`, handing the sink each [`CHUNK`] filled.
    fn add<S: Sink + ?Sized>(&mut self, mut bytes: &[u8], sink: &mut S) -> Result<(), S::Error> {
        while !bytes.is_empty() {
            let taken = bytes.len().min(CHUNK - self.len);
            self.bytes[self.len..self.len + taken].copy_from_slice(&bytes[..taken]);
            self.len += taken;
            bytes = &bytes[taken..];
            if self.len == CHUNK {
                self.flush(sink)?;
            }
        }
        Ok(())
    }

    /// Hands the sink what is gathered, if anything.
    fn flush<S: Sink + ?Sized>(&mut self, sink: &mut S) -> Result<(), S::Error> {
        let len = core::mem::take(&mut self.len);
        if len == 0 {
            return Ok(());
        }
        sink.write_all(&self.bytes[..len])
    }
}

/// Where a decoder is in a frame's blocks.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct BlockDecoder {
    /// Data bytes left in the current block; the next byte is a code when 0.
    left: u8,
    /// Whether the current block stands for a 0x00 after its data (its code
    /// is below 255), written only once another block follows.
    zero_after: bool,
}

impl BlockDecoder {
    /// At the start of a frame.
    pub(crate) const fn new() -> BlockDecoder {
        BlockDecoder { left: 0, zero_after: false }
    }

    /// The decoded byte `byte` stands for, if any. The caller ends the frame
    /// at a 0x00 instead (here a 0x00 would read as a code of 1).
    pub(crate) fn byte(&mut self, byte: u8) -> Option<u8> {
        if self.left > 0 {
            self.left -= 1;
            return Some(byte);
        }
        let zero = self.zero_after.then_some(0);
        self.left = byte.saturating_sub(1);
        self.zero_after = byte != 0xFF;
        zero
    }

    /// Whether a frame may end here: not inside a block.
    pub(crate) fn at_block_end(&self) -> bool {
        self.left == 0
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// Collects what the encoder writes, and the length of each write.
    struct Bytes(Vec<u8>, Vec<usize>);

    impl Sink for Bytes {
        type Error = core::convert::Infallible;
        fn write_all(&mut self, bytes: &[u8]) -> Result<(), Self::Error> {
            self.1.push(bytes.len());
            self.0.extend_from_slice(bytes);
            Ok(())
        }
    }

    /// The encoded blocks of `data` (the closing delimiter checked and left
    /// out), written in whole chunks but the last.
    fn encode(data: &[u8]) -> Vec<u8> {
        let mut sink = Bytes(Vec::new(), Vec::new());
        let mut encoder = BlockEncoder::new();
        encoder.put(data, &mut sink).unwrap();
        encoder.finish(&mut sink).unwrap();
        let (last, whole) = sink.1.split_last().expect("a write");
        assert!(whole.iter().all(|&len| len == CHUNK) && (1..=CHUNK).contains(last), "writes of {:?} bytes", sink.1);
        assert_eq!(sink.0.pop(), Some(0), "the closing delimiter");
        sink.0
    }

    fn decode(encoded: &[u8]) -> Option<Vec<u8>> {
        let mut decoder = BlockDecoder::new();
        let out = encoded.iter().filter_map(|&b| decoder.byte(b)).collect();
        decoder.at_block_end().then_some(out)
    }

    #[test]
    fn the_textbook_examples() {
        assert_eq!(encode(&[]), [1]);
        assert_eq!(encode(&[0]), [1, 1]);
        assert_eq!(encode(&[0, 0]), [1, 1, 1]);
        assert_eq!(encode(&[0x11, 0x22, 0, 0x33]), [3, 0x11, 0x22, 2, 0x33]);
        assert_eq!(encode(&[0x11, 0, 0, 0]), [2, 0x11, 1, 1, 1]);
    }

    #[test]
    fn a_run_of_zeros_is_written_a_chunk_at_a_time() {
        // A black row of a 240-pixel RGB565 panel: a block a byte, 8 writes.
        let mut sink = Bytes(Vec::new(), Vec::new());
        let mut encoder = BlockEncoder::new();
        encoder.open(&mut sink).unwrap();
        encoder.put(&[0; 480], &mut sink).unwrap();
        encoder.finish(&mut sink).unwrap();
        assert_eq!(sink.0.len(), 483);
        assert_eq!(sink.1, [64, 64, 64, 64, 64, 64, 64, 35]);
    }

    #[test]
    fn runs_of_254_and_more() {
        let run: Vec<u8> = (1..=254).collect();
        let encoded = encode(&run);
        assert_eq!((encoded[0], encoded.len()), (0xFF, 256), "a full block, then an empty last one");
        // The shorter form other encoders write (no empty last block) reads the same.
        assert_eq!(decode(&encoded[..255]).unwrap(), run);
        let long: Vec<u8> = (0..1000u32).map(|i| (i % 255) as u8 + 1).collect();
        assert_eq!(decode(&encode(&long)).unwrap(), long);
    }

    #[test]
    fn every_frame_reads_back_and_has_no_zero() {
        let mut rng = crate::tests::Rng::from_env("cobs every_frame_reads_back_and_has_no_zero");
        for _ in 0..2000 {
            let len = rng.below(700) as usize;
            let zeros = rng.below(4);
            let data: Vec<u8> = (0..len).map(|_| if rng.below(4) < zeros { 0 } else { rng.next() as u8 }).collect();
            let encoded = encode(&data);
            assert!(!encoded.contains(&0), "{data:?}");
            assert_eq!(decode(&encoded).as_deref(), Some(&data[..]));
        }
    }

    #[test]
    fn a_frame_cut_inside_a_block_cannot_end() {
        assert_eq!(decode(&[3, 0x11]), None);
        assert_eq!(decode(&[3, 0x11, 0x22]).unwrap(), [0x11, 0x22]);
    }
}
