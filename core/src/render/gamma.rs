//! Gamma correction and the final rounding: `round(255 · min(1, max(0, C))^(1/γ))`.
//!
//! Instead of a table indexed by the colour (large) this stores the 255
//! colours at which the output steps up (`((k + ½)/255)^γ`, rounded up to
//! Q0.16): the output is the number of thresholds at or below the colour,
//! found by binary search. 510 bytes, exact rounding to nearest up to the
//! Q0.16 resolution, and built with integer `pow` so every target agrees.

use crate::math::{pow_unit, Scalar, Wide};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GammaTable {
    pub(crate) thresholds: [u16; 255],
}

impl GammaTable {
    /// The table for display gamma `gamma` (> 0; 1 disables correction).
    // The renderer fills its own table in place; only the tests build one.
    #[cfg(test)]
    pub fn new(gamma: Wide) -> GammaTable {
        let mut table = GammaTable { thresholds: [0; 255] };
        table.fill(gamma);
        table
    }

    /// Recomputes the table in place for `gamma`.
    pub fn fill(&mut self, gamma: Wide) {
        let g = gamma.to_bits();
        let thresholds = &mut self.thresholds;
        for (k, t) in thresholds.iter_mut().enumerate() {
            // ((2k + 1) / 510) in Q2.30, raised to γ, rounded up to Q0.16.
            let x = ((2 * k as i64 + 1) << 30) / 510;
            let v = if g == 1 << 32 {
                // γ = 1 exactly: no power, so exact ties round as they should.
                ((2 * k as u64 + 1) << 16).div_ceil(510) as u32
            } else {
                (pow_unit(x as i32, g) as u32).div_ceil(1 << 14)
            };
            *t = v.min(u16::MAX as u32) as u16;
        }
        // Monotone by construction of pow; enforce it against rounding.
        for k in 1..255 {
            thresholds[k] = thresholds[k].max(thresholds[k - 1]);
        }
    }

    /// The 8-bit display value of the linear intensity `c` (clamped to 0..1).
    #[inline]
    pub fn encode(&self, c: Scalar) -> u8 {
        let c = c.to_bits();
        if c >= 1 << 16 {
            return 255;
        }
        if c <= 0 {
            return 0;
        }
        self.thresholds.partition_point(|&t| t as i32 <= c) as u8
    }

    /// [`GammaTable::encode`], starting from `near` (the neighbouring
    /// pixel's value: most often this one's or a step away): a few
    /// comparisons instead of a binary search, which it falls back to.
    #[inline]
    pub fn encode_near(&self, c: Scalar, near: u8) -> u8 {
        let bits = c.to_bits();
        if bits >= 1 << 16 || bits <= 0 {
            return self.encode(c);
        }
        // The answer is the number of thresholds ≤ c: k with
        // thresholds[k − 1] ≤ c < thresholds[k].
        let t = &self.thresholds;
        let mut k = near as usize;
        for _ in 0..4 {
            if k > 0 && t[k - 1] as i32 > bits {
                k -= 1;
            } else if k < t.len() && t[k] as i32 <= bits {
                k += 1;
            } else {
                return k as u8;
            }
        }
        self.encode(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_one_is_plain_rounding() {
        let g = GammaTable::new(Wide::ONE);
        for level in 0..=255i64 {
            // The exact colour of each level maps back to it.
            let c = Scalar::from_bits(((level << 16) / 255) as i32);
            assert_eq!(g.encode(c) as i64, level, "level {level}");
        }
        assert_eq!(g.encode(Scalar::from_num(-3)), 0);
        assert_eq!(g.encode(Scalar::from_num(7)), 255);
        assert_eq!(g.encode(Scalar::from_num(0.5)), 128); // 127.5 rounds up
    }

    #[test]
    fn encoding_from_a_neighbour_is_the_encoding() {
        for gamma in [1i64 << 32, (22 << 32) / 10, 9 << 32] {
            let g = GammaTable::new(Wide::from_bits(gamma));
            for c in (-3..(1 << 16) + 3).step_by(7) {
                let c = Scalar::from_bits(c);
                for near in [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 100, 200, 250, 253, 254, 255] {
                    assert_eq!(g.encode_near(c, near), g.encode(c), "gamma {gamma}, {c:?} near {near}");
                }
                let e = g.encode(c);
                for near in e.saturating_sub(5)..=e.saturating_add(5) {
                    assert_eq!(g.encode_near(c, near), e, "gamma {gamma}, {c:?} near {near}");
                }
            }
        }
    }

    #[test]
    fn gamma_two_point_two() {
        let g = GammaTable::new(Wide::from_bits((22 << 32) / 10));
        // 0.5^(1/2.2) = 0.7297 → 186.08 → 186; 0.01 → 0.1233 → 31.4 → 31.
        assert_eq!(g.encode(Scalar::from_num(0.5)), 186);
        assert_eq!(g.encode(Scalar::from_num(0.01)), 31);
        assert_eq!(g.encode(Scalar::from_num(1)), 255);
        assert_eq!(g.encode(Scalar::from_bits(1)), 2); // 2^-16 → 0.00655 → 1.67
    }
}
