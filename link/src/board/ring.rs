//! A ring of bytes of a fixed capacity: what a board keeps between its
//! serial line and its main loop, each way (the Pico's USB interrupt fills
//! one and empties the other).
//!
//! Invariants: never more than `N` bytes are held, bytes come out in the
//! order they went in, and no operation panics or waits; a push beyond the
//! capacity takes what fits and says how much.

/// `N` bytes at most, first in first out; a `static` on a board (behind the
/// firmware's lock, shared with its interrupt).
///
/// ```
/// use octrace_link::board::Ring;
///
/// let mut ring = Ring::<4>::new();
/// assert_eq!(ring.push(b"hello"), 4, "what fits");
/// assert_eq!(ring.pop(), Some(b'h'));
/// assert_eq!(ring.push(b"!"), 1);
/// // The oldest bytes, as far as they run on in memory, then the rest.
/// assert_eq!(ring.front(), b"ell");
/// ring.consume(3);
/// assert_eq!(ring.front(), b"!");
/// ```
#[derive(Clone, Debug)]
pub struct Ring<const N: usize> {
    bytes: [u8; N],
    /// Where the oldest byte is.
    head: usize,
    len: usize,
}

impl<const N: usize> Default for Ring<N> {
    fn default() -> Self {
        Ring::new()
    }
}

impl<const N: usize> Ring<N> {
    /// An empty ring.
    pub const fn new() -> Ring<N> {
        Ring { bytes: [0; N], head: 0, len: 0 }
    }

    /// Bytes held.
    pub const fn len(&self) -> usize {
        self.len
    }

    /// Whether it holds none.
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Bytes it has room for.
    pub const fn room(&self) -> usize {
        N - self.len
    }

    /// Appends what fits of `bytes`; returns how many.
    pub fn push(&mut self, bytes: &[u8]) -> usize {
        let taken = bytes.len().min(self.room());
        for &byte in &bytes[..taken] {
            let at = (self.head + self.len) % N;
            self.bytes[at] = byte;
            self.len += 1;
        }
        taken
    }

    /// The oldest byte, taken out.
    pub fn pop(&mut self) -> Option<u8> {
        let byte = self.front().first().copied()?;
        self.consume(1);
        Some(byte)
    }

    /// The oldest bytes, as many as lie in one piece (all of them, or up
    /// to the end of the storage): what a USB endpoint is handed.
    pub fn front(&self) -> &[u8] {
        let end = (self.head + self.len).min(N);
        &self.bytes[self.head.min(end)..end]
    }

    /// Drops the `count` oldest bytes (all, if it holds fewer).
    pub fn consume(&mut self, count: usize) {
        let count = count.min(self.len);
        self.head = match N {
            0 => 0,
            _ => (self.head + count) % N,
        };
        self.len -= count;
    }

    /// Drops every byte.
    pub fn clear(&mut self) {
        self.consume(self.len);
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::tests::Rng;
    use std::collections::VecDeque;
    use std::vec::Vec;

    #[test]
    fn it_keeps_what_a_queue_keeps_across_its_end() {
        let mut rng = Rng::from_env("ring it_keeps_what_a_queue_keeps_across_its_end");
        let mut ring = Ring::<7>::new();
        let mut queue = VecDeque::new();
        for _ in 0..20_000 {
            match rng.below(4) {
                0 => {
                    let bytes: Vec<u8> = (0..rng.below(10)).map(|_| rng.next() as u8).collect();
                    let taken = ring.push(&bytes);
                    assert_eq!(taken, bytes.len().min(7 - queue.len()));
                    queue.extend(&bytes[..taken]);
                }
                1 => assert_eq!(ring.pop(), queue.pop_front()),
                2 => {
                    let count = rng.below(5) as usize;
                    let front = ring.front();
                    assert!(!front.is_empty() || queue.is_empty());
                    assert!(front.iter().eq(queue.iter().take(front.len())));
                    ring.consume(count);
                    queue.drain(..count.min(queue.len()));
                }
                _ if rng.below(20) == 0 => {
                    ring.clear();
                    queue.clear();
                }
                _ => {}
            }
            assert_eq!((ring.len(), ring.room(), ring.is_empty()), (queue.len(), 7 - queue.len(), queue.is_empty()));
        }
    }

    #[test]
    fn a_ring_of_nothing_holds_nothing() {
        let mut ring = Ring::<0>::new();
        assert_eq!((ring.push(b"x"), ring.pop(), ring.front()), (0, None, &[][..]));
        ring.consume(3);
        assert!(ring.is_empty());
    }
}
