//! `dither` and `coarse`: ordered dithering onto a fixed colour cube.
//!
//! The palette is the 6×6×6 cube: entry `36 r + 6 g + b` is
//! (51 r, 51 g, 51 b) for levels 0 to 5 ([`CUBE_LEVELS`]); entries 216 to
//! 255 are unused (black). Each channel is placed between its two nearest
//! levels and rounded up where its fraction beats the 8×8 Bayer threshold
//! of the pixel ([`BAYER_8X8`]), so a region's mean colour is kept to
//! 1/64 of a level step. `coarse` adds black outlines: a pixel whose object
//! differs from its left or upper neighbour's is drawn in entry 0.

use super::{ColorTable, Quantizer};
use crate::scene::ObjectId;
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};

/// Levels per channel of the cube.
pub const CUBE_LEVELS: u32 = 6;

/// The 8×8 Bayer matrix: thresholds 0 to 63, each once, spread so that any
/// 2^k × 2^k block holds an even spread.
pub const BAYER_8X8: [[u8; 8]; 8] = {
    let mut m = [[0u8; 8]; 8];
    let mut y = 0;
    while y < 8 {
        let mut x = 0;
        while x < 8 {
            // Interleave the bits of x ^ y and y, most significant first.
            let (a, b) = (x ^ y, y);
            let mut v = 0;
            let mut bit = 0;
            while bit < 3 {
                v |= ((a >> bit) & 1) << (5 - 2 * bit);
                v |= ((b >> bit) & 1) << (4 - 2 * bit);
                bit += 1;
            }
            m[y][x] = v as u8;
            x += 1;
        }
        y += 1;
    }
    m
};

static CUBE_TABLE: ColorTable = {
    let mut t = [Rgb888::new(0, 0, 0); 256];
    let mut i = 0;
    while i < 216 {
        let step = (255 / (CUBE_LEVELS - 1)) as usize;
        t[i] = Rgb888::new(((i / 36) * step) as u8, ((i / 6 % 6) * step) as u8, ((i % 6) * step) as u8);
        i += 1;
    }
    t
};

/// Ordered dithering onto the 6×6×6 cube.
#[derive(Clone, Copy, Debug, Default)]
pub struct Dither;

impl Dither {
    /// The cube entry for `color` at (`x`, `y`).
    pub fn index(x: u32, y: u32, color: Rgb888) -> u8 {
        let threshold = BAYER_8X8[(y % 8) as usize][(x % 8) as usize] as u32;
        let level = |v: u8| {
            let scaled = v as u32 * (CUBE_LEVELS - 1); // level · 255 + fraction
            let (level, fraction) = (scaled / 255, scaled % 255);
            // Round up where fraction/255 > (threshold + ½)/64.
            level + (fraction * 128 > (2 * threshold + 1) * 255) as u32
        };
        (level(color.r()) * 36 + level(color.g()) * 6 + level(color.b())) as u8
    }
}

impl Quantizer for Dither {
    fn quantize(&mut self, x: u32, y: u32, color: Rgb888, _: Option<ObjectId>) -> u8 {
        Dither::index(x, y, color)
    }

    fn table(&self) -> &ColorTable {
        &CUBE_TABLE
    }

    fn used(&self) -> usize {
        216
    }
}

/// [`Dither`] with outlines where the object changes. It remembers the
/// objects of the row above in caller-owned storage (one `u32` per column),
/// so pixels must come in raster order over whole rows.
#[derive(Debug)]
pub struct Coarse<'a> {
    above: &'a mut [u32],
    left: u32,
}

/// No object (background) in [`Coarse`]'s row memory.
const NONE: u32 = u32::MAX;

impl<'a> Coarse<'a> {
    /// `above` holds at least the image's width of entries; columns beyond
    /// it get no vertical outlines.
    pub fn new(above: &'a mut [u32]) -> Coarse<'a> {
        above.fill(NONE);
        Coarse { above, left: NONE }
    }
}

impl Quantizer for Coarse<'_> {
    fn quantize(&mut self, x: u32, y: u32, color: Rgb888, object: Option<ObjectId>) -> u8 {
        let id = object.map_or(NONE, |o| o.0);
        if x == 0 {
            self.left = id;
        }
        let above = match self.above.get_mut(x as usize) {
            Some(slot) => core::mem::replace(slot, id),
            None => id,
        };
        let edge = (x > 0 && self.left != id) || (y > 0 && above != id);
        self.left = id;
        if edge {
            0
        } else {
            Dither::index(x, y, color)
        }
    }

    fn table(&self) -> &ColorTable {
        &CUBE_TABLE
    }

    fn used(&self) -> usize {
        216
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bayer_holds_each_threshold_once() {
        let mut seen = [false; 64];
        for row in BAYER_8X8 {
            for v in row {
                assert!(!seen[v as usize], "{v} twice");
                seen[v as usize] = true;
            }
        }
        assert_eq!(BAYER_8X8[0][0], 0);
        // Neighbours differ most: the 2×2 pattern 0 2 / 3 1 (× 16) at the top.
        assert_eq!([BAYER_8X8[0][1], BAYER_8X8[1][0], BAYER_8X8[1][1]], [32, 48, 16]);
    }

    #[test]
    fn cube_colours_are_exact_and_mean_is_kept() {
        // Levels of the cube map to themselves everywhere.
        for (x, y) in [(0, 0), (3, 5), (7, 7)] {
            assert_eq!(Dither::index(x, y, Rgb888::new(0, 51, 255)), 11);
            assert_eq!(Dither::index(x, y, Rgb888::new(255, 255, 255)), 215);
        }
        // A gray between two levels: over an 8×8 block the mean matches.
        for v in [10u8, 25, 77, 128, 200, 250] {
            let mut sum = 0;
            for y in 0..8 {
                for x in 0..8 {
                    let i = Dither::index(x, y, Rgb888::new(v, v, v));
                    sum += Dither.table()[i as usize].r() as u32;
                }
            }
            // A float in a test only: the core itself never uses one.
            let mean = sum as f64 / 64.0;
            assert!((mean - v as f64).abs() <= 51.0 / 64.0 + 0.5, "{v}: {mean}");
        }
    }

    #[test]
    fn coarse_outlines_object_changes() {
        // 4×3: object 1 on the left half, background on the right; row 2
        // all object 1.
        let objects = [[Some(1), Some(1), None, None], [Some(1), Some(1), None, None], [Some(1); 4]];
        let mut above = [0u32; 4];
        let mut coarse = Coarse::new(&mut above);
        let white = Rgb888::new(255, 255, 255);
        let mut out = [[0u8; 4]; 3];
        for (y, row) in objects.iter().enumerate() {
            for (x, o) in row.iter().enumerate() {
                out[y][x] = coarse.quantize(x as u32, y as u32, white, o.map(ObjectId));
            }
        }
        assert_eq!(out, [[215, 215, 0, 215], [215, 215, 0, 215], [215, 215, 0, 0]]);
    }
}
