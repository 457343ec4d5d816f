//! Colours and `SURFACE` materials.
//!
//! Invariant: colour arithmetic saturates (a colour channel is at most
//! 32767.99); it never wraps, so an over-bright light clamps to white as the
//! shading model's final `min(1, …)` says.

use crate::math::{mul_wide, part_wise_or, Scalar, Unit};
use fixed::types::I48F16;

/// A linear RGB colour, Q16.16 per channel (1.0 is full intensity; values
/// above 1 are kept until the final clamp).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Color {
    /// Red, linear, Q16.16 (1.0 is full).
    pub r: Scalar,
    /// Green, linear, Q16.16.
    pub g: Scalar,
    /// Blue, linear, Q16.16.
    pub b: Scalar,
}

impl Color {
    /// No light.
    pub const BLACK: Color = Color::from_bits([0; 3]);

    /// The colour whose components have these raw Q16.16 bits.
    pub const fn from_bits(c: [i32; 3]) -> Color {
        Color { r: Scalar::from_bits(c[0]), g: Scalar::from_bits(c[1]), b: Scalar::from_bits(c[2]) }
    }

    /// The raw Q16.16 bits of the components.
    pub const fn bits(self) -> [i32; 3] {
        [self.r.to_bits(), self.g.to_bits(), self.b.to_bits()]
    }

    #[inline]
    /// The sum, saturating where light piles up past what Q16.16 holds.
    pub fn saturating_add(self, o: Color) -> Color {
        Color { r: self.r.saturating_add(o.r), g: self.g.saturating_add(o.g), b: self.b.saturating_add(o.b) }
    }

    /// Each channel times `k` (Q16.16), saturating.
    #[inline]
    pub fn scale(self, k: Scalar) -> Color {
        let k = k.to_bits();
        // A full weight (every primary ray's) leaves the colour as it is:
        // c · 2^16 >> 16 = c, without the products.
        if k == 1 << 16 {
            return self;
        }
        Color::from_bits(self.bits().map(|c| scale_channel_q16(c, k)))
    }

    /// Each channel times a cosine in Q2.30.
    #[inline]
    pub fn scale_unit(self, k: Unit) -> Color {
        let k = k.to_bits();
        Color::from_bits(self.bits().map(|c| scale_channel_q30(c, k)))
    }

    /// Channel-wise product (filtering one colour by another).
    #[inline]
    pub fn modulate(self, o: Color) -> Color {
        let o = o.bits();
        let s = self.bits();
        Color::from_bits([0, 1, 2].map(|i| sat(mul_wide(s[i], o[i]) >> 16)))
    }

    /// Whether every component is zero (nothing to trace for).
    pub fn is_black(self) -> bool {
        self == Color::BLACK
    }
}

// On ARMv6-M the channel products below take two 32-bit products when one
// factor is at most 1.0 (nearly always: material coefficients, cosines,
// weights), instead of the four of a 32×32→64 product. Elsewhere the plain
// product is as cheap.

/// `sat((c · k) >> 16)`, the product of two Q16.16 values.
///
/// Why the two-product form is exact: with `0 ≤ s ≤ 2^16` and `0 ≤ l`
/// (`l = h·2^16 + m`, `h < 2^15`, `m < 2^16`), `⌊s·l / 2^16⌋ = s·h +
/// ⌊s·m / 2^16⌋`; `s·m < 2^32` and the sum is below `2^31 + 2^16`, so it
/// fits a u32 and saturates to `i32::MAX` as `sat` would.
#[inline(always)]
fn scale_channel_q16(c: i32, k: i32) -> i32 {
    part_wise_or(|| scale_channel_q16_by_parts(c, k), || sat(mul_wide(c, k) >> 16))
}

/// [`scale_channel_q16`] in two 32-bit products, when one factor is in
/// `[0, 2^16]` and the other non-negative.
#[inline(always)]
fn scale_channel_q16_by_parts(c: i32, k: i32) -> Option<i32> {
    if c < 0 || k < 0 || c.min(k) > 1 << 16 {
        return None;
    }
    let (small, large) = (c.min(k) as u32, c.max(k) as u32);
    let product = small * (large >> 16) + ((small * (large & 0xffff)) >> 16);
    Some(product.min(i32::MAX as u32) as i32)
}

/// `sat((c · k) >> 30)`, a Q16.16 channel times a Q2.30 factor.
///
/// Why the two-product form is exact: with `0 ≤ c ≤ 2^16` and `0 ≤ k`
/// (`k = h·2^15 + m`, `h < 2^16`, `m < 2^15`), `⌊c·k / 2^30⌋ = ⌊(c·h +
/// ⌊c·m / 2^15⌋) / 2^15⌋`; `c·h ≤ 2^32 − 2^16` and `⌊c·m / 2^15⌋ < 2^16`,
/// so the sum fits a u32 and the result (below 2^17) needs no saturation.
#[inline(always)]
fn scale_channel_q30(c: i32, k: i32) -> i32 {
    part_wise_or(|| scale_channel_q30_by_parts(c, k), || sat(mul_wide(c, k) >> 30))
}

/// [`scale_channel_q30`] in two 32-bit products, for a channel in
/// `[0, 2^16]` and a non-negative factor.
#[inline(always)]
fn scale_channel_q30_by_parts(c: i32, k: i32) -> Option<i32> {
    if c as u32 > 1 << 16 || k < 0 {
        return None;
    }
    let (c, k) = (c as u32, k as u32);
    Some(((c * (k >> 15) + ((c * (k & 0x7fff)) >> 15)) >> 15) as i32)
}

/// `v` saturated to an i32: it fits when its high word is the sign of its
/// low word (two 32-bit comparisons instead of two 64-bit ones).
#[inline]
fn sat(v: i64) -> i32 {
    let low = v as i32;
    if (v >> 32) as i32 == low >> 31 {
        low
    } else if v < 0 {
        i32::MIN
    } else {
        i32::MAX
    }
}

/// A `SURFACE` definition: the material of every object that names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Surface {
    /// Ambient reflection coefficients, per channel.
    pub ambient: Color,
    /// Diffuse reflection coefficients, per channel.
    pub diffuse: Color,
    /// Specular reflection coefficients, per channel.
    pub specular: Color,
    /// The Phong exponent k ≥ 0 (0: a constant specular term).
    pub exponent: I48F16,
    /// Reflectivity r, 0 to 1.
    pub reflectivity: Scalar,
    /// Transparency t, 0 to 1.
    pub transparency: Scalar,
}

/// A surface with the number the scene gave it and where it was defined (for
/// "defined twice" errors).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceEntry {
    /// The number the scene gave it.
    pub number: u32,
    /// The line of its SURFACE statement.
    pub line: u32,
    /// The column of its SURFACE statement.
    pub column: u32,
    /// The material.
    pub surface: Surface,
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn a_full_weight_is_the_product_by_one() {
        for c in [i32::MIN, -1, 0, 1, 65_536, 123_456_789, i32::MAX] {
            let color = Color::from_bits([c, c / 3, c.wrapping_neg() / 7]);
            let product = Color::from_bits(color.bits().map(|v| sat(mul_wide(v, 1 << 16) >> 16)));
            assert_eq!(color.scale(Scalar::ONE), product);
        }
    }

    #[test]
    fn saturating_colour_arithmetic() {
        let big = Color::from_bits([i32::MAX - 5, 1 << 16, 0]);
        let sum = big.saturating_add(Color::from_bits([100, 1 << 16, -5]));
        assert_eq!(sum.bits(), [i32::MAX, 2 << 16, -5]);
        assert_eq!(big.scale(Scalar::from_num(4)).bits()[0], i32::MAX);
        let half = Color::from_bits([1 << 16; 3]).scale_unit(Unit::from_num(0.5));
        assert_eq!(half.bits(), [1 << 15; 3]);
        let m = Color::from_bits([1 << 16, 1 << 15, 0]).modulate(Color::from_bits([1 << 15; 3]));
        assert_eq!(m.bits(), [1 << 15, 1 << 14, 0]);
    }

    #[test]
    fn channel_products_by_parts_are_the_plain_products() {
        let mut next = crate::test_rng::seeded(0x5ca1_ab1e_u64);
        let edges =
            [0, 1, 2, 0x7fff, 0x8000, 0xffff, 1 << 16, (1 << 16) + 1, 1 << 30, (1 << 30) + 1, i32::MAX, -1, i32::MIN];
        let mut pairs = std::vec::Vec::new();
        for &a in &edges {
            for &b in &edges {
                pairs.push((a, b));
            }
        }
        for _ in 0..200_000 {
            let r = next();
            // Mostly the ranges the fast forms take, with their edges.
            let a = (r as i32) >> (r >> 59);
            let b = ((r >> 32) as i32) >> ((r >> 54) & 31);
            pairs.push((a, b));
            pairs.push((a & 0x1ffff, b));
        }
        let (mut q16, mut q30) = (0, 0);
        for (a, b) in pairs {
            if let Some(p) = scale_channel_q16_by_parts(a, b) {
                assert_eq!(p, sat(mul_wide(a, b) >> 16), "{a} · {b} >> 16");
                q16 += 1;
            }
            if let Some(p) = scale_channel_q30_by_parts(a, b) {
                assert_eq!(p, sat(mul_wide(a, b) >> 30), "{a} · {b} >> 30");
                q30 += 1;
            }
            assert_eq!(scale_channel_q16(a, b), sat(mul_wide(a, b) >> 16));
            assert_eq!(scale_channel_q30(a, b), sat(mul_wide(a, b) >> 30));
        }
        // The fast forms were exercised, not skipped.
        assert!(q16 > 50_000 && q30 > 50_000, "{q16} {q30}");
    }

    #[test]
    fn saturation_matches_clamping() {
        let edges = [0i64, 1, -1, i32::MAX as i64, i32::MIN as i64, 1 << 31, -(1 << 31) - 1, i64::MAX, i64::MIN];
        for v in edges.into_iter().chain((0..64).map(|k| 0x5bd1_e995_u64.wrapping_mul(k * 2654435761) as i64 >> k)) {
            assert_eq!(sat(v), v.clamp(i32::MIN as i64, i32::MAX as i64) as i32, "{v}");
        }
    }
}
