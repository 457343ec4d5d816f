//! octrace's board protocol: a host sends scene text to a board over a
//! serial line (USB CDC on a Pico), the board answers with the scene's
//! errors, or draws it on its panel and sends the rows back. The whole
//! protocol, byte by byte, is `docs/board-protocol.md`.
//!
//! `#![no_std]`, no allocation: the [`Decoder`] keeps frames in a buffer
//! the caller owns, fed one byte at a time; [`Message::encode`] writes a
//! frame into any [`Sink`] in pieces of at most [`CHUNK`] bytes, holding
//! one COBS block. With the feature `board`, `board` is the board's side
//! on an octrace-core `Raytracer`, so that a
//! firmware is a loop around it and a host test runs exactly the board's
//! behaviour; with `std`, every `std::io::Write` is a [`Sink`].
//!
//! Modules, each using only those before it: `crc` (CRC-32), `cobs` (the
//! byte stuffing and the [`Sink`]), `kind` (each message's [`Kind`]),
//! `frame` (the header, the CRC and [`Refusal`]s), `wire` (a payload's
//! fields as bytes), `list` (the [`Capacities`] and [`Counters`] a message
//! carries), `message` ([`Message`] and its payloads), `decoder`
//! ([`Decoder`]) and `board`.
//!
//! ```
//! use octrace_link::{Decoder, Message, PixelFormat, Panel};
//!
//! // A host asks; a board reads the frame byte by byte.
//! let mut line = Vec::new();
//! Message::Hello.encode(5, &mut line).unwrap();
//! let mut buffer = [0u8; 512];
//! let mut decoder = Decoder::new(&mut buffer);
//! assert!(line.iter().any(|&byte| decoder.push(byte).is_some()), "a frame ended");
//! let frame = decoder.received().unwrap().unwrap();
//! assert_eq!((frame.tag, frame.message), (5, Message::Hello));
//!
//! // The board answers with the same tag.
//! let panel = Panel { width: 240, height: 240, format: PixelFormat::Rgb565 };
//! let mut answer = Vec::new();
//! Message::Drawing { panel, pixels: true, frames: 0 }.encode(frame.tag, &mut answer).unwrap();
//! assert!(!answer[1..answer.len() - 1].contains(&0), "0x00 only delimits frames");
//! ```

#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(feature = "std")]
extern crate std;

#[cfg(feature = "board")]
pub mod board;
mod cobs;
mod crc;
mod decoder;
mod frame;
mod kind;
mod list;
mod message;
mod wire;

pub use cobs::{Sink, CHUNK};
pub use decoder::{Decoder, Frame};
pub use frame::{encode_raw, Reason, Refusal, OVERHEAD, VERSION};
pub use kind::Kind;
pub use list::{Capacities, Capacity, Counter, Counters};
pub use message::{BoardInfo, CapacityNeed, Message, Panel, PixelFormat, SceneError, Timing};

#[cfg(test)]
mod tests {
    extern crate std;

    /// The property tests' generator (xorshift64*), seeded from
    /// `OCTRACE_SEED` or the clock; the seed is printed so that a failure
    /// can be replayed.
    pub(crate) struct Rng(u64);

    impl Rng {
        pub(crate) fn from_env(test: &str) -> Rng {
            let seed = std::env::var("OCTRACE_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or_else(|| {
                let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH);
                now.map_or(1, |d| d.as_nanos() as u64)
            });
            std::println!("{test}: seed {seed} (replay with OCTRACE_SEED={seed})");
            Rng(seed.max(1))
        }

        pub(crate) fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
        }

        /// A number below `n` (at least 1).
        pub(crate) fn below(&mut self, n: u64) -> u64 {
            self.next() % n.max(1)
        }
    }
}
