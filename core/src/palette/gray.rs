//! `gray`: 256 gray levels by luma, Y = (77 R + 150 G + 29 B) / 256, the
//! ITU-R BT.601 weights 0.299, 0.587 and 0.114 in 8 bits (they sum to 256,
//! so white stays 255), rounded.

use super::{ColorTable, Quantizer};
use crate::scene::ObjectId;
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};

/// The gray ramp: entry i is (i, i, i).
static GRAY_TABLE: ColorTable = {
    let mut t = [Rgb888::new(0, 0, 0); 256];
    let mut i = 0;
    while i < 256 {
        t[i] = Rgb888::new(i as u8, i as u8, i as u8);
        i += 1;
    }
    t
};

/// 256 gray levels.
#[derive(Clone, Copy, Debug, Default)]
pub struct Gray;

impl Gray {
    /// The luma of a colour, 0 to 255.
    pub fn luma(c: Rgb888) -> u8 {
        ((77 * c.r() as u32 + 150 * c.g() as u32 + 29 * c.b() as u32 + 128) >> 8) as u8
    }
}

impl Quantizer for Gray {
    fn quantize(&mut self, _: u32, _: u32, color: Rgb888, _: Option<ObjectId>) -> u8 {
        Gray::luma(color)
    }

    fn table(&self) -> &ColorTable {
        &GRAY_TABLE
    }

    fn used(&self) -> usize {
        256
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn luma_keeps_grays_and_weights_green_most() {
        for v in [0u8, 1, 127, 128, 254, 255] {
            assert_eq!(Gray::luma(Rgb888::new(v, v, v)), v);
        }
        assert_eq!(Gray::luma(Rgb888::new(255, 0, 0)), 77);
        assert_eq!(Gray::luma(Rgb888::new(0, 255, 0)), 149);
        assert_eq!(Gray::luma(Rgb888::new(0, 0, 255)), 29);
        assert_eq!(Gray.table()[200], Rgb888::new(200, 200, 200));
    }
}
