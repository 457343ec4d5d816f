//! One channel of error diffusion in raster order: Floyd–Steinberg, and
//! FS-PE, Floyd–Steinberg with pure-error feedback.
//!
//! A pixel of value `g` (0 to 255) and accumulated error `a` is shown as
//! the level `o` the panel picks for `v = 16 g + a` (values in 1/16 gray,
//! "Q4"). Its error `E = v − 16 o` goes to the four Floyd–Steinberg
//! neighbours, 7, 3, 5 and 1 sixteenths (right; below left, below, below
//! right), split so that the four parts sum to `E` exactly: the picture's
//! mean is kept. FS-PE also sends the pure error `P = g − o`, in gray
//! units, to the same neighbours with the weights 7, 4, 7, 4 (sixteenths,
//! so exact in Q4): a pixel whose neighbours came out lighter than their
//! own values leans darker. That loop is finite (it carries `P`, never
//! its own sums), so it neither drifts nor leaves a dead zone near a
//! level.
//!
//! Storage: one row of `i16`s for the next row's accumulators, filled as
//! the current row's are read (column `x − 1` of the next row is complete
//! once pixel `x` is done), plus three registers. Invariants: every sum is
//! in `i32`, far from its range; the row's `i16`s saturate, never wrap
//! (the largest ever seen, on noise, stripes, ramps and every scene, is
//! about 7,200 of 32,767).

/// The registers of one channel along the current row.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Accumulators {
    /// To the pixel on the right.
    carry: i32,
    /// The next row's pixels below left and below the current one, still
    /// collecting.
    below_left: i32,
    below: i32,
}

impl Accumulators {
    /// `v`, in Q4, for the pixel at column `x` of value `value`.
    #[inline]
    pub(super) fn value(&self, row: &[i16], x: usize, value: i32) -> i32 {
        (value << 4) + row[x] as i32 + self.carry
    }

    /// Spreads the pixel at `x`'s error `error` (Q4) and, for FS-PE, its
    /// pure error `pure` (gray units; 0 for plain Floyd–Steinberg).
    #[inline]
    pub(super) fn push(&mut self, row: &mut [i16], x: usize, error: i32, pure: i32) {
        let below_left = (3 * error + 8) >> 4;
        let below = (5 * error + 8) >> 4;
        let below_right = (error + 8) >> 4;
        let right = error - below_left - below - below_right;
        self.carry = right + 7 * pure;
        if x > 0 {
            row[x - 1] = saturate(self.below_left + below_left + 4 * pure);
        }
        self.below_left = self.below + below + 7 * pure;
        self.below = below_right + 4 * pure;
    }

    /// Closes the row whose last column is `last`: what fell right of the
    /// image or below right of its last pixel is dropped.
    #[inline]
    pub(super) fn end_row(&mut self, row: &mut [i16], last: usize) {
        row[last] = saturate(self.below_left);
        *self = Accumulators::default();
    }
}

#[inline]
fn saturate(value: i32) -> i16 {
    value.clamp(i16::MIN as i32, i16::MAX as i32) as i16
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One bit, white from 128: every pixel's level, rows in order.
    fn one_bit(values: &[&[i32]], pure: bool) -> std::vec::Vec<std::vec::Vec<u8>> {
        let w = values[0].len();
        let mut row = std::vec![0i16; w];
        let mut acc = Accumulators::default();
        let mut out = std::vec::Vec::new();
        for line in values {
            let mut levels = std::vec::Vec::new();
            for (x, &g) in line.iter().enumerate() {
                let v = acc.value(&row, x, g);
                let o = if v >= 128 << 4 { 255 } else { 0 };
                levels.push((o / 255) as u8);
                acc.push(&mut row, x, v - (o << 4), if pure { g - o } else { 0 });
            }
            acc.end_row(&mut row, w - 1);
            out.push(levels);
        }
        out
    }

    extern crate std;

    #[test]
    fn a_flat_tone_keeps_its_mean() {
        // 25 % gray over 8×8: 16 of 64 white, plain FS and FS-PE alike (the
        // error leaving at the right and bottom edges is under a pixel).
        let rows: std::vec::Vec<[i32; 8]> = std::vec![[64; 8]; 8];
        let rows: std::vec::Vec<&[i32]> = rows.iter().map(|r| &r[..]).collect();
        for pure in [false, true] {
            let white: usize = one_bit(&rows, pure).iter().flatten().map(|&l| l as usize).sum();
            assert!((15..=17).contains(&white), "pure {pure}: {white}");
        }
    }

    #[test]
    fn the_error_splits_exactly() {
        // Any error: the four parts sum to it, and the parts of 16 are the
        // weights themselves.
        let mut row = [0i16; 3];
        for error in -5000..5000 {
            let mut acc = Accumulators::default();
            row.fill(0);
            acc.push(&mut row, 1, error, 0);
            let pushed = acc.carry + acc.below_left + acc.below + row[0] as i32;
            assert_eq!(pushed, error);
        }
        let mut acc = Accumulators::default();
        acc.push(&mut row, 1, 16, 0);
        assert_eq!([acc.carry, row[0] as i32, acc.below_left, acc.below], [7, 3, 5, 1]);
    }

    #[test]
    fn pure_error_feeds_back_with_its_weights() {
        // A white pixel over gray 0 (P = −255) and no error to spread.
        let mut row = [0i16; 3];
        let mut acc = Accumulators::default();
        acc.push(&mut row, 1, 0, -255);
        assert_eq!([acc.carry, row[0] as i32, acc.below_left, acc.below], [-7 * 255, -4 * 255, -7 * 255, -4 * 255]);
    }

    #[test]
    fn the_row_saturates_instead_of_wrapping() {
        let mut row = [0i16; 2];
        let mut acc = Accumulators { carry: 0, below_left: 40_000, below: 0 };
        acc.end_row(&mut row, 1);
        assert_eq!(row[1], i16::MAX);
        let mut acc = Accumulators { carry: 0, below_left: -40_000, below: 0 };
        acc.push(&mut row, 1, 0, 0);
        assert_eq!(row[0], i16::MIN);
    }
}
