//! Colours handed from one core to another without a lock or a heap: a ring
//! of slots, each holding up to `LEN` colours and the number of the piece
//! of work they belong to.
//!
//! One core (the producer) renders pieces `n` (rows, or a progressive pass's
//! units) and [`Handoff::send`]s their colours; the other (the consumer,
//! typically the core that drives the display) [`Handoff::take`]s them in
//! order. Piece `n` goes to slot `n mod SLOTS`, so the producer runs at
//! most `SLOTS` pieces ahead.
//!
//! Invariants: a slot's tag is 0 while it is free and `n + 1` while it
//! holds piece `n`; only the producer writes a free slot's colours (then
//! publishes them with a release store of the tag), and only the consumer
//! reads a full one (then frees it with a release store of 0). Every access
//! is an atomic load or store of 32 bits, which every target octrace
//! supports (a Cortex-M0 too), so the ring needs no `unsafe` and no lock.

use core::sync::atomic::{AtomicU32, Ordering};
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};

/// A ring of `SLOTS` slots of up to `LEN` colours, for handing rendered
/// pieces from one core to another. Put it in a `static`: it is `Sync`, and
/// [`Handoff::new`] is a constant.
///
/// ```
/// use embedded_graphics::pixelcolor::{Rgb888, RgbColor};
/// use octrace_core::render::Handoff;
///
/// static RING: Handoff<4, 2> = Handoff::new();
/// // The producer (core 1) sends piece 0 when its slot is free…
/// assert!(RING.is_free_for(0));
/// RING.send(0, [Rgb888::RED, Rgb888::GREEN]).unwrap();
/// assert!(!RING.is_free_for(2)); // piece 2 shares piece 0's slot
/// // …and the consumer (core 0) takes it: the slot is free again once the
/// // colours have been read.
/// let colors: Vec<Rgb888> = RING.take(0).unwrap().collect();
/// assert_eq!(colors, [Rgb888::RED, Rgb888::GREEN]);
/// assert!(RING.is_free_for(2));
/// assert!(!RING.holds(1) && RING.take(1).is_none()); // not sent yet
/// ```
pub struct Handoff<const LEN: usize, const SLOTS: usize> {
    slots: [Slot<LEN>; SLOTS],
}

struct Slot<const LEN: usize> {
    /// 0 while free; the piece's number plus one while it holds that piece.
    tag: AtomicU32,
    /// How many of `colors` the piece has.
    len: AtomicU32,
    /// Packed `0x00RRGGBB`.
    colors: [AtomicU32; LEN],
}

/// [`Handoff::send`] found the piece's slot still holding an earlier piece
/// the consumer has not taken.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlotBusy;

impl core::fmt::Display for SlotBusy {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("the slot still holds a piece the consumer has not taken")
    }
}

impl core::error::Error for SlotBusy {}

impl<const LEN: usize, const SLOTS: usize> Handoff<LEN, SLOTS> {
    /// Every slot free.
    pub const fn new() -> Self {
        const { assert!(SLOTS > 0 && LEN <= u32::MAX as usize, "a handoff needs at least one slot") };
        Handoff {
            slots: [const {
                Slot { tag: AtomicU32::new(0), len: AtomicU32::new(0), colors: [const { AtomicU32::new(0) }; LEN] }
            }; SLOTS],
        }
    }

    fn slot(&self, piece: u32) -> &Slot<LEN> {
        &self.slots[piece as usize % SLOTS]
    }

    /// Whether the producer may [`send`](Handoff::send) piece `piece` now
    /// (its slot is free). A producer waits for this (spinning, or with
    /// the core's wait-for-event) before rendering into the slot.
    pub fn is_free_for(&self, piece: u32) -> bool {
        self.slot(piece).tag.load(Ordering::Acquire) == 0
    }

    /// Frees every slot, dropping what they hold: for a consumer that
    /// stopped taking (a picture cut short), before the producer starts
    /// again. Call it only while the producer is not sending.
    pub fn clear(&self) {
        for slot in &self.slots {
            slot.tag.store(0, Ordering::Release);
        }
    }

    /// Whether the producer has sent piece `piece` and the consumer has not
    /// taken it yet: what a consumer waits for before [`take`](Handoff::take).
    pub fn holds(&self, piece: u32) -> bool {
        self.slot(piece).tag.load(Ordering::Acquire) == piece.wrapping_add(1)
    }

    /// The producer's side: puts `colors` (the first `LEN` of them; the rest
    /// are not drawn from the iterator) into piece `piece`'s slot and
    /// publishes it. `colors` is only consumed when the slot is free, so a
    /// lazy iterator (a [`Renderer::row`](super::Renderer::row)) traces
    /// nothing when the answer is [`SlotBusy`]. Returns how many colours
    /// the piece holds.
    pub fn send(&self, piece: u32, colors: impl IntoIterator<Item = Rgb888>) -> Result<usize, SlotBusy> {
        let slot = self.slot(piece);
        if slot.tag.load(Ordering::Acquire) != 0 {
            return Err(SlotBusy);
        }
        let mut len = 0;
        for (cell, color) in slot.colors.iter().zip(colors) {
            cell.store(pack(color), Ordering::Relaxed);
            len += 1;
        }
        slot.len.store(len as u32, Ordering::Relaxed);
        slot.tag.store(piece.wrapping_add(1), Ordering::Release);
        Ok(len)
    }

    /// The consumer's side: piece `piece`'s colours, if the producer has
    /// sent it. The slot is freed when the returned iterator is dropped
    /// (read the colours, then let it go).
    pub fn take(&self, piece: u32) -> Option<Taken<'_, LEN>> {
        let slot = self.slot(piece);
        self.holds(piece).then(|| {
            let len = (slot.len.load(Ordering::Relaxed) as usize).min(LEN);
            Taken { slot, next: 0, len }
        })
    }
}

impl<const LEN: usize, const SLOTS: usize> Default for Handoff<LEN, SLOTS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const LEN: usize, const SLOTS: usize> core::fmt::Debug for Handoff<LEN, SLOTS> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let full = self.slots.iter().filter(|s| s.tag.load(Ordering::Relaxed) != 0).count();
        f.debug_struct("Handoff").field("slots", &SLOTS).field("full", &full).finish()
    }
}

/// A piece's colours on the consumer's side ([`Handoff::take`]); dropping
/// it frees the slot for the producer.
pub struct Taken<'h, const LEN: usize> {
    slot: &'h Slot<LEN>,
    next: usize,
    len: usize,
}

impl<const LEN: usize> Iterator for Taken<'_, LEN> {
    type Item = Rgb888;

    fn next(&mut self) -> Option<Rgb888> {
        let color = unpack(self.slot.colors[..self.len].get(self.next)?.load(Ordering::Relaxed));
        self.next += 1;
        Some(color)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.len - self.next;
        (left, Some(left))
    }
}

impl<const LEN: usize> ExactSizeIterator for Taken<'_, LEN> {}

impl<const LEN: usize> Drop for Taken<'_, LEN> {
    fn drop(&mut self) {
        self.slot.tag.store(0, Ordering::Release);
    }
}

impl<const LEN: usize> core::fmt::Debug for Taken<'_, LEN> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Taken").field("left", &(self.len - self.next)).finish()
    }
}

fn pack(c: Rgb888) -> u32 {
    (c.r() as u32) << 16 | (c.g() as u32) << 8 | c.b() as u32
}

fn unpack(word: u32) -> Rgb888 {
    Rgb888::new((word >> 16) as u8, (word >> 8) as u8, word as u8)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn color(n: u32) -> Rgb888 {
        unpack(n.wrapping_mul(0x9e37_79b9) & 0x00ff_ffff)
    }

    #[test]
    fn a_piece_goes_through_whole_and_frees_its_slot() {
        let ring: Handoff<3, 2> = Handoff::new();
        assert_eq!(ring.send(5, (0..3).map(color)), Ok(3));
        assert_eq!(ring.send(7, (0..3).map(color)), Err(SlotBusy), "7 shares 5's slot");
        assert!(ring.take(3).is_none(), "3 shares the slot but is not what it holds");
        assert_eq!(ring.take(5).unwrap().collect::<Vec<_>>(), (0..3).map(color).collect::<Vec<_>>());
        assert!(ring.take(5).is_none(), "taken once");
        assert_eq!(ring.send(7, (0..2).map(color)), Ok(2), "a shorter piece");
        assert_eq!(ring.take(7).unwrap().len(), 2);
    }

    #[test]
    fn clear_frees_every_slot() {
        let ring: Handoff<1, 3> = Handoff::new();
        for n in 0..3 {
            ring.send(n, [Rgb888::WHITE]).unwrap();
        }
        ring.clear();
        assert!((3..6).all(|n| ring.is_free_for(n)));
        assert!((0..3).all(|n| !ring.holds(n)));
    }

    #[test]
    fn a_busy_slot_draws_nothing_from_the_iterator() {
        let ring: Handoff<2, 1> = Handoff::new();
        ring.send(0, [Rgb888::RED]).unwrap();
        let mut drawn = 0;
        assert_eq!(
            ring.send(
                1,
                core::iter::from_fn(|| {
                    drawn += 1;
                    Some(Rgb888::BLUE)
                })
            ),
            Err(SlotBusy)
        );
        assert_eq!(drawn, 0);
    }

    #[test]
    fn a_long_piece_is_cut_to_the_slot() {
        let ring: Handoff<2, 1> = Handoff::new();
        assert_eq!(ring.send(0, (0..5).map(color)), Ok(2));
        assert_eq!(ring.take(0).unwrap().count(), 2);
    }

    #[test]
    fn two_threads_hand_over_every_piece_in_order() {
        static RING: Handoff<64, 3> = Handoff::new();
        const PIECES: u32 = 2000;
        std::thread::scope(|s| {
            s.spawn(|| {
                for n in 0..PIECES {
                    while !RING.is_free_for(n) {
                        std::hint::spin_loop();
                    }
                    let len = (n % 64 + 1) as usize;
                    assert_eq!(RING.send(n, (0..len as u32).map(|i| color(n * 64 + i))), Ok(len));
                }
            });
            for n in 0..PIECES {
                let taken = loop {
                    if let Some(t) = RING.take(n) {
                        break t;
                    }
                    std::hint::spin_loop();
                };
                let expected: Vec<_> = (0..n % 64 + 1).map(|i| color(n * 64 + i)).collect();
                assert_eq!(taken.collect::<Vec<_>>(), expected, "piece {n}");
            }
        });
    }
}
