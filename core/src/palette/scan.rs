//! `scan`: the thesis's colour-table method, which builds the table from
//! the image itself.
//!
//! - **Closeness.** An entry is close enough when its squared RGB distance
//!   to the colour is at most a limit, [`CLOSE_ENOUGH`] = 3·8² unless set
//!   (about 8 levels per channel).
//! - **Hash.** Colour space is cut into cubes about as wide as the
//!   closeness diameter (a power of two: 16 levels for the default limit),
//!   so that colours close to each other mostly share a home; a colour's
//!   key is its cube's coordinates, and the key times 0x9E37_79B1
//!   (Fibonacci hashing), top 8 bits, is its home entry.
//! - **Probing.** Linear, from the home entry: the first close entry found is
//!   used; a free entry ends the run and is taken for the colour (while
//!   learning). When the table is full, or no longer learning, a colour with
//!   no close entry in its run gets the closest entry of the whole table.
//!
//! Two ways to use it. One pass ([`Scan::quantize`]): learn while
//! streaming, so a pixel's index is known at once and an entry never
//! changes after its first use — a display with a writable colour table can
//! take each new entry as it appears. Its weakness is the thesis's: the
//! first 256 distinct colours in scan order take the table, and later ones
//! make do with the closest. Two passes: [`Scan::learn`] every pixel (or
//! those of a low-resolution pre-render, on a board), then [`Scan::freeze`]
//! and map the image; if the table [`Scan::overflowed`] while learning,
//! learn again with twice the closeness limit ([`Scan::with_closeness`]),
//! so that every region of colour space the image uses gets an entry.
//! host-sim uses two passes over the full-resolution image.

use super::{distance_squared, ColorTable, Quantizer};
use crate::scene::ObjectId;
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};

/// The largest squared RGB distance at which an entry stands for a colour.
pub const CLOSE_ENOUGH: u32 = 3 * 8 * 8;

/// The colour table being built and the rule that fills it.
#[derive(Clone, Debug)]
pub struct Scan {
    table: ColorTable,
    occupied: [bool; 256],
    used: usize,
    learning: bool,
    close_enough: u32,
    /// log2 of the hash cubes' side.
    cube_log2: u32,
    overflowed: bool,
    /// The last colour mapped and its entry: neighbouring pixels repeat.
    last: Option<(Rgb888, u8)>,
}

impl Default for Scan {
    fn default() -> Self {
        Scan::new()
    }
}

impl Scan {
    /// An empty table that learns, with the [`CLOSE_ENOUGH`] limit.
    pub fn new() -> Scan {
        Scan::with_closeness(CLOSE_ENOUGH)
    }

    /// An empty table that learns, an entry standing for colours within a
    /// squared RGB distance of `close_enough`.
    pub fn with_closeness(close_enough: u32) -> Scan {
        Scan {
            table: [Rgb888::new(0, 0, 0); 256],
            occupied: [false; 256],
            used: 0,
            learning: true,
            close_enough,
            cube_log2: Scan::cube_log2(close_enough),
            overflowed: false,
            last: None,
        }
    }

    /// The closeness limit in use.
    pub fn closeness(&self) -> u32 {
        self.close_enough
    }

    /// Whether a colour found neither a close entry nor room while learning.
    pub fn overflowed(&self) -> bool {
        self.overflowed
    }

    /// log2 of the smallest power of two at least the closeness diameter
    /// 2·√(limit/3), at most 8.
    fn cube_log2(close_enough: u32) -> u32 {
        let radius = crate::math::isqrt((close_enough / 3) as u64) as u32;
        (32 - (2 * radius).saturating_sub(1).leading_zeros()).min(8)
    }

    /// The home entry of a colour.
    pub fn home(&self, c: Rgb888) -> u8 {
        let k = self.cube_log2;
        let key = ((c.r() as u32 >> k) << 16) | ((c.g() as u32 >> k) << 8) | (c.b() as u32 >> k);
        (key.wrapping_mul(0x9E37_79B1) >> 24) as u8
    }

    /// First pass: makes sure the table has an entry for `color` if there is
    /// room.
    pub fn learn(&mut self, color: Rgb888) {
        self.map(color);
    }

    /// Ends learning: from now on colours only map to existing entries.
    pub fn freeze(&mut self) {
        self.learning = false;
        self.last = None;
    }

    /// The entry for `color` under the rules in the module doc.
    pub fn map(&mut self, color: Rgb888) -> u8 {
        if let Some((c, i)) = self.last {
            if c == color {
                return i;
            }
        }
        let index = self.probe(color).unwrap_or_else(|| self.closest(color));
        self.last = Some((color, index));
        index
    }

    /// The run from the home entry: a close entry, or a free one taken.
    fn probe(&mut self, color: Rgb888) -> Option<u8> {
        let home = self.home(color);
        for step in 0..=255u8 {
            let i = home.wrapping_add(step);
            if !self.occupied[i as usize] {
                if !self.learning {
                    return None;
                }
                self.occupied[i as usize] = true;
                self.table[i as usize] = color;
                self.used += 1;
                return Some(i);
            }
            if distance_squared(self.table[i as usize], color) <= self.close_enough {
                return Some(i);
            }
        }
        self.overflowed |= self.learning;
        None
    }

    /// The occupied entry nearest to `color` (entry 0 when none is).
    fn closest(&self, color: Rgb888) -> u8 {
        let mut best = (u32::MAX, 0u8);
        for (i, (&c, &taken)) in self.table.iter().zip(&self.occupied).enumerate() {
            if taken {
                best = best.min((distance_squared(c, color), i as u8));
            }
        }
        best.1
    }
}

impl Quantizer for Scan {
    fn quantize(&mut self, _: u32, _: u32, color: Rgb888, _: Option<ObjectId>) -> u8 {
        self.map(color)
    }

    fn table(&self) -> &ColorTable {
        &self.table
    }

    fn used(&self) -> usize {
        self.used
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_colours_share_an_entry_and_far_ones_do_not() {
        let mut scan = Scan::new();
        let a = scan.map(Rgb888::new(100, 100, 100));
        // Same hash cube (16 levels wide) and close: the same entry.
        assert_eq!(scan.map(Rgb888::new(104, 97, 109)), a);
        let b = scan.map(Rgb888::new(200, 10, 10));
        assert_ne!(a, b);
        assert_eq!(scan.used(), 2);
        assert_eq!(scan.table()[a as usize], Rgb888::new(100, 100, 100));
    }

    #[test]
    fn a_full_table_gives_the_closest_entry() {
        let mut scan = Scan::new();
        // 512 colours 16 levels apart in red and blue: far more than fit.
        let colours: [Rgb888; 512] =
            core::array::from_fn(|i| Rgb888::new((i % 16 * 16) as u8, (i / 256 * 200) as u8, (i / 16 % 16 * 16) as u8));
        for &c in &colours {
            scan.learn(c);
        }
        assert_eq!(scan.used(), 256);
        scan.freeze();
        for &c in &colours {
            let i = scan.map(c);
            let d = distance_squared(scan.table()[i as usize], c);
            let best = scan.table().iter().map(|&t| distance_squared(t, c)).min().unwrap();
            assert!(d == best || d <= CLOSE_ENOUGH, "{c:?}: {d} > {best}");
        }
    }

    #[test]
    fn hash_cubes_follow_the_closeness_limit() {
        assert_eq!(Scan::cube_log2(CLOSE_ENOUGH), 4);
        assert_eq!(Scan::cube_log2(3 * 16 * 16), 5);
        assert_eq!(Scan::cube_log2(0), 0);
        assert_eq!(Scan::cube_log2(u32::MAX), 8);
    }

    #[test]
    fn one_colour_uses_one_entry_and_frozen_tables_do_not_grow() {
        let mut scan = Scan::new();
        for _ in 0..100 {
            assert_eq!(scan.map(Rgb888::new(7, 7, 7)), scan.home(Rgb888::new(7, 7, 7)));
        }
        assert_eq!(scan.used(), 1);
        scan.freeze();
        scan.map(Rgb888::new(250, 0, 0));
        assert_eq!(scan.used(), 1);
    }
}
