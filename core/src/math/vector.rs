//! Three-component vectors: [`Vec3`] for points and offsets (Q16.16), [`Dir`]
//! for unit directions (Q2.30).
//!
//! Invariant: a [`Dir`] built by [`Dir::normalize`] has length 1 within 2^-29.
//! Arithmetic on [`Vec3`] uses `fixed`'s operators, which panic on overflow in
//! debug builds; the scene normalisation keeps every value in range.

use super::{mul_u32_wide, mul_wide, part_wise_or, square_u32_wide, square_wide, Scalar, Unit, ARMV6M, UNIT_ONE};
use core::ops::{Add, Neg, Sub};

// On ARMv6-M sign tests of dot products try the coarse product first (see
// [`coarse_dot`]); elsewhere the exact product is as cheap.

/// `H = Σ (a_i >> 17)·(b_i >> 17)`, three 32-bit products: for any i32
/// components, `|Σ a_i·b_i − H·2^34| < 2^51`.
///
/// Why: with `a = h·2^17 + l` (`|h| ≤ 2^14`, `0 ≤ l < 2^17`), each
/// `a·b − h_a·h_b·2^34 = (h_a·l_b + l_a·h_b)·2^17 + l_a·l_b` is below
/// `2·2^31·2^17 + 2^34` in magnitude; three of them below 2^51. Each
/// `h_a·h_b` is at most 2^28, so `H` fits an i32.
#[inline(always)]
pub(crate) fn coarse_dot(a: [i32; 3], b: [i32; 3]) -> i32 {
    (a[0] >> 17) * (b[0] >> 17) + (a[1] >> 17) * (b[1] >> 17) + (a[2] >> 17) * (b[2] >> 17)
}

/// `H ≥ 2^17` makes `Σ a_i·b_i > H·2^34 − 2^51 ≥ 0`; `H ≤ −2^17` makes it
/// negative (see [`coarse_dot`]).
const COARSE_SURE: i32 = 1 << 17;

/// Whether `Σ a_i·b_i ≤ limit` when the coarse product decides it
/// (`H·2^34 ± 2^51` both on one side of `limit`), else `None`.
#[inline(always)]
fn coarse_at_most(a: [i32; 3], b: [i32; 3], limit: i64) -> Option<bool> {
    let scaled = (coarse_dot(a, b) as i64) << 34;
    if scaled + (1 << 51) <= limit {
        Some(true)
    } else if scaled - (1 << 51) > limit {
        Some(false)
    } else {
        None
    }
}

/// The sign of `Σ a_i·b_i` (−1, 1) when the coarse product decides it, else
/// `None` (0 included: the exact product may be zero).
#[inline(always)]
fn coarse_sign(a: [i32; 3], b: [i32; 3]) -> Option<i32> {
    let h = coarse_dot(a, b);
    if h >= COARSE_SURE {
        Some(1)
    } else if h <= -COARSE_SURE {
        Some(-1)
    } else {
        None
    }
}

/// Whether the ray from `origin` along `dir` surely meets the plane
/// `n·p = offset` at no positive parameter, from coarse products: true only
/// when `den = ⌊n·dir⌋` (Q2.30) and `num = offset·2^30 − n·origin` (Q18.46)
/// are surely of opposite signs or `num` surely zero-or-against (`den > 0`
/// and `num ≤ 0`, or `den < 0` and `num ≥ 0`).
///
/// `den > 0` needs `n·dir ≥ 2^30` (Q4.60): sure when `H ≥ 2^17 + 1`
/// (`H·2^34 − 2^51 ≥ 2^34`); `den < 0` when `H ≤ −2^17`.
#[inline(always)]
fn coarse_plane_behind(dir: [i32; 3], origin: [i32; 3], n: [i32; 3], offset: i32) -> bool {
    let h_den = coarse_dot(n, dir);
    let den_positive = h_den > COARSE_SURE;
    let den_negative = h_den <= -COARSE_SURE;
    if !den_positive && !den_negative {
        return false;
    }
    let along = (coarse_dot(origin, n) as i64) << 34;
    let target = (offset as i64) << 30;
    // num ≤ 0 when n·origin ≥ target; num ≥ 0 when n·origin ≤ target.
    (den_positive && along - (1 << 51) >= target) || (den_negative && along + (1 << 51) <= target)
}

/// A point or an offset in normalised scene space.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Vec3 {
    /// Q16.16, along X.
    pub x: Scalar,
    /// Q16.16, along Y.
    pub y: Scalar,
    /// Q16.16, along Z.
    pub z: Scalar,
}

/// A unit vector (one made by `Dir::from_bits` is the caller's to keep of
/// unit length).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Dir {
    /// Q2.30, along X.
    pub x: Unit,
    /// Q2.30, along Y.
    pub y: Unit,
    /// Q2.30, along Z.
    pub z: Unit,
}

/// What [`Vec3`] and [`Dir`] both have: their components' raw bits and
/// back, the components widened for exact products, and one by its axis.
macro_rules! components {
    ($vector:ident, $component:ident, $format:literal) => {
        impl $vector {
            #[doc = concat!("The vector whose components have these raw ", $format, " bits.")]
            #[inline]
            pub const fn from_bits(b: [i32; 3]) -> Self {
                $vector {
                    x: $component::from_bits(b[0]),
                    y: $component::from_bits(b[1]),
                    z: $component::from_bits(b[2]),
                }
            }

            #[doc = concat!("The raw ", $format, " bits of the components, for hashing and exact comparisons.")]
            #[inline]
            pub const fn bits(self) -> [i32; 3] {
                [self.x.to_bits(), self.y.to_bits(), self.z.to_bits()]
            }

            #[doc = concat!("The components widened to `i64` (still ", $format, "), ready for exact products.")]
            #[inline]
            pub const fn wide(self) -> [i64; 3] {
                let b = self.bits();
                [b[0] as i64, b[1] as i64, b[2] as i64]
            }

            /// The component along `axis` (0, 1, 2 for X, Y, Z).
            #[inline]
            pub fn axis(self, axis: usize) -> $component {
                match axis {
                    0 => self.x,
                    1 => self.y,
                    _ => self.z,
                }
            }
        }
    };
}

components!(Vec3, Scalar, "Q16.16");
components!(Dir, Unit, "Q2.30");

impl Vec3 {
    /// The origin.
    pub const ZERO: Vec3 = Vec3::from_bits([0; 3]);

    /// `self · d` in Q16.16, rounded towards minus infinity.
    #[inline]
    pub fn dot_dir(self, d: Dir) -> Scalar {
        Scalar::from_bits((self.dot_dir_q46(d) >> 30) as i32)
    }

    /// `self · d` exactly, in Q18.46.
    #[inline]
    pub fn dot_dir_q46(self, d: Dir) -> i64 {
        let v = self.bits();
        let e = d.bits();
        mul_wide(v[0], e[0]) + mul_wide(v[1], e[1]) + mul_wide(v[2], e[2])
    }

    /// `self.dot_dir_q46(d) <= limit`, cheaper on ARMv6-M when the two are
    /// far apart.
    #[inline]
    pub fn dot_dir_q46_at_most(self, d: Dir, limit: i64) -> bool {
        part_wise_or(|| coarse_at_most(self.bits(), d.bits(), limit), || self.dot_dir_q46(d) <= limit)
    }

    /// `|self|²` exactly, in Q32.32. Components must be within ±2^15.
    #[inline]
    pub fn length_squared_q32(self) -> i64 {
        let v = self.bits();
        (square_wide(v[0]) + square_wide(v[1]) + square_wide(v[2])) as i64
    }

    /// `|self|` in Q16.16, rounded down.
    #[inline]
    pub fn length(self) -> Scalar {
        Scalar::from_bits(super::isqrt(self.length_squared_q32() as u64) as i32)
    }

    /// The unit vector along `self`, or `None` for the zero vector.
    #[inline]
    pub fn direction(self) -> Option<Dir> {
        Dir::normalize_small_with_length(self.bits()).map(|(d, _, _)| d)
    }

    /// The unit vector along `self` and its length (rounded to nearest), with
    /// one square root; `None` for the zero vector.
    #[inline]
    pub fn direction_and_length(self) -> Option<(Dir, Scalar)> {
        let (d, len, shift) = Dir::normalize_small_with_length(self.bits())?;
        Some((d, unscaled_length(len as u32, shift)))
    }

    /// [`Vec3::direction_and_length`] without the steps to exact rounding,
    /// a fifth fewer instructions on a Cortex-M0: each component
    /// within 5 units in the last place of the rounded quotient (the length
    /// of the direction within 2^-27 of 1), the length within 2^-27 of the
    /// exact one plus its rounding. For the directions to the lights, which
    /// shade and aim shadow rays, where no picture can tell.
    #[inline]
    pub fn direction_and_length_estimate(self) -> Option<(Dir, Scalar)> {
        let (negative, scaled, shift) = scaled_magnitudes(self.bits())?;
        let len2 = scaled.iter().map(|&c| square_u32_wide(c)).sum::<u64>();
        // 1/√len2 ≈ g·2^-e, e = 60 or 61 for len2 in [2^58, 2^62):
        // c·2^30/√len2 = c·g / 2^(e − 30), c·g below 2^61.
        let (len, g, e) = super::sqrt_and_rsqrt_estimates_58_62(len2);
        // Rounded at bit e − 30 (30 or 31): shifts by constants, as a
        // variable 64-bit shift is a library call on a 32-bit core.
        debug_assert!(e == 60 || e == 61);
        let round = |x: u64| if e == 60 { (x + (1 << 29)) >> 30 } else { (x + (1 << 30)) >> 31 };
        let d = Dir::from_bits([0, 1, 2].map(|a| {
            let m = round(mul_u32_wide(scaled[a], g)) as i32;
            if negative[a] {
                -m
            } else {
                m
            }
        }));
        Some((d, unscaled_length(len, shift)))
    }
}

/// The magnitudes of `v` scaled by a power of two (`shift`: right, negative
/// left) so that the largest is in [2^29, 2^30), with their signs; `None`
/// for the zero vector. In 32-bit steps.
#[inline]
fn scaled_magnitudes(v: [i32; 3]) -> Option<([bool; 3], [u32; 3], i32)> {
    let magnitude = v.map(|c| c.unsigned_abs());
    let largest = magnitude[0].max(magnitude[1]).max(magnitude[2]);
    if largest == 0 {
        return None;
    }
    let shift = 2 - super::leading_zeros_u32(largest) as i32;
    let scaled = magnitude.map(|m| if shift > 0 { m >> shift } else { m << -shift });
    Some((v.map(|c| c < 0), scaled, shift))
}

/// A scaled length `len · 2^shift` (`len` below 2^31, `shift` at most 2) in
/// Q16.16, rounded to nearest and saturating; in 32 bits (a variable
/// 64-bit shift is a library call on a 32-bit core).
#[inline]
fn unscaled_length(len: u32, shift: i32) -> Scalar {
    let length = if shift >= 0 {
        // `len << shift` saturated, told by a comparison before the shift.
        if len <= i32::MAX as u32 >> shift {
            len << shift
        } else {
            i32::MAX as u32
        }
    } else {
        (len + (1 << (-shift - 1))) >> -shift
    };
    Scalar::from_bits(length.min(i32::MAX as u32) as i32)
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline]
    fn add(self, o: Vec3) -> Vec3 {
        Vec3 { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
    }
}

impl Sub for Vec3 {
    type Output = Vec3;
    #[inline]
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3 { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
    }
}

impl Neg for Vec3 {
    type Output = Vec3;
    #[inline]
    fn neg(self) -> Vec3 {
        Vec3 { x: -self.x, y: -self.y, z: -self.z }
    }
}

impl Dir {
    /// The unit X axis.
    pub const X: Dir = Dir::from_bits([1 << 30, 0, 0]);
    /// The unit Y axis.
    pub const Y: Dir = Dir::from_bits([0, 1 << 30, 0]);
    /// The unit Z axis.
    pub const Z: Dir = Dir::from_bits([0, 0, 1 << 30]);

    /// The unit vector along the axis `axis` (0, 1, 2), negated if `negative`.
    #[inline]
    pub fn axis_unit(axis: usize, negative: bool) -> Dir {
        let one = if negative { -(1 << 30) } else { 1 << 30 };
        let mut b = [0; 3];
        b[axis.min(2)] = one;
        Dir::from_bits(b)
    }

    /// `self · o` exactly, in Q4.60.
    #[inline]
    pub fn dot_q60(self, o: Dir) -> i64 {
        let a = self.bits();
        let b = o.bits();
        mul_wide(a[0], b[0]) + mul_wide(a[1], b[1]) + mul_wide(a[2], b[2])
    }

    /// `self.dot_q60(o) > 0`, cheaper on ARMv6-M unless the two are nearly
    /// perpendicular.
    #[inline]
    pub fn dot_is_positive(self, o: Dir) -> bool {
        part_wise_or(|| coarse_sign(self.bits(), o.bits()).map(|sign| sign > 0), || self.dot_q60(o) > 0)
    }

    /// `self.dot_q60(o) < 0`, cheaper on ARMv6-M unless the two are nearly
    /// perpendicular.
    #[inline]
    pub fn dot_is_negative(self, o: Dir) -> bool {
        part_wise_or(|| coarse_sign(self.bits(), o.bits()).map(|sign| sign < 0), || self.dot_q60(o) < 0)
    }

    /// Whether the ray from `origin` along `self` surely meets the plane
    /// `n·p = offset` at no positive parameter: on ARMv6-M from 32-bit
    /// products when they decide, and `false` (unsure) otherwise and on
    /// other targets. `true` means `⌊n·self⌋` (Q2.30) and `offset·2^30 −
    /// n·origin` (Q18.46) are nonzero-and-positive against non-positive or
    /// negative against non-negative.
    #[inline]
    pub fn plane_surely_behind(self, origin: Vec3, n: Dir, offset: Scalar) -> bool {
        ARMV6M && coarse_plane_behind(self.bits(), origin.bits(), n.bits(), offset.to_bits())
    }

    /// `self · o` in Q2.30, rounded towards minus infinity.
    #[inline]
    pub fn dot(self, o: Dir) -> Unit {
        Unit::from_bits((self.dot_q60(o) >> 30) as i32)
    }

    /// `t · self` in Q16.16; `|t|` below 2^15.
    #[inline]
    pub fn scale(self, t: Scalar) -> Vec3 {
        let t = t.to_bits();
        let d = self.bits();
        Vec3::from_bits(d.map(|c| (mul_wide(c, t) >> 30) as i32))
    }

    /// The unit vector along the integer vector `v` (any common scale), or
    /// `None` when `v` is zero. Rounding is symmetric: `normalize(-v) ==
    /// -normalize(v)`.
    pub fn normalize(v: [i64; 3]) -> Option<Dir> {
        Self::normalize_with_length(v).map(|(d, _, _)| d)
    }

    /// [`Dir::normalize`], also giving the length of `v` as `len · 2^shift`
    /// (`len` between 2^29 and 2^31, the exact floor of the scaled length).
    ///
    /// `v` is first scaled by a power of two (`shift`: right, negative left)
    /// so that its largest component is in [2^29, 2^30): the squared length
    /// then fits a u64 with 29 bits of precision whatever the input scale.
    pub fn normalize_with_length(v: [i64; 3]) -> Option<(Dir, u64, i32)> {
        let magnitude = v.map(|c| c.unsigned_abs());
        let largest = magnitude[0].max(magnitude[1]).max(magnitude[2]);
        if largest == 0 {
            return None;
        }
        let shift = 64 - super::leading_zeros(largest) as i32 - 30;
        // Left shifts only happen to magnitudes below 2^30.
        let scaled = magnitude.map(|m| super::shr_signed_to_u32(m, shift));
        Some(Self::from_scaled(v.map(|c| c < 0), scaled, shift))
    }

    /// [`Dir::normalize_with_length`] for 32-bit components (points and
    /// their differences), in 32-bit steps only: the same bits, cheaper on
    /// a 32-bit core.
    #[inline]
    pub fn normalize_small_with_length(v: [i32; 3]) -> Option<(Dir, u64, i32)> {
        let (negative, scaled, shift) = scaled_magnitudes(v)?;
        Some(Self::from_scaled(negative, scaled, shift))
    }

    /// The direction and scaled length from the scaled magnitudes.
    #[inline]
    fn from_scaled(negative: [bool; 3], scaled: [u32; 3], shift: i32) -> (Dir, u64, i32) {
        let len2 = scaled.iter().map(|&c| square_u32_wide(c)).sum::<u64>();
        // The largest magnitude is in [2^29, 2^30): len2 in [2^58, 3·2^60).
        let (len, g, e) = super::sqrt_and_rsqrt_58_62(len2);
        (Self::divided(negative, scaled, g, e, len as u32), len, shift)
    }

    /// The scaled magnitudes divided by their length `len` (= ⌊√len2⌋,
    /// `1/√len2 ≈ g · 2^-e`), with the given signs: `round(c · 2^30 / len)`
    /// exactly, without a division: one product with the reciprocal of
    /// `len` and one 32-bit check per component.
    ///
    /// Why it is exact: with `R = ⌊(2^61 − 1)/len⌋` and `c < 2^30`,
    /// `c·R/2^31` lies in `(c·2^30/len − ½, c·2^30/len]`, so
    /// `m' = ⌊c·R/2^31 + ½⌋` is the wanted `m = ⌊(c·2^30 + ⌊len/2⌋)/len⌋`
    /// or `m − 1` (it cannot pass `m + 1`, which is at least `1/len` above
    /// the quotient while the estimate exceeds it by at most `1/(2·len)`).
    /// The rest `c·2^30 + ⌊len/2⌋ − m'·len` is then in `[0, 2·len)`, below
    /// 2^32: its low word, a 32-bit product, tells which.
    #[inline]
    fn divided(negative: [bool; 3], scaled: [u32; 3], g: u32, e: i32, len: u32) -> Dir {
        let reciprocal = reciprocal_of_length(g, e, len);
        Dir::from_bits([0, 1, 2].map(|a| {
            let c = scaled[a];
            let mut m = ((mul_u32_wide(c, reciprocal) + (1 << 30)) >> 31) as u32;
            let rest = (c << 30).wrapping_add(len / 2).wrapping_sub(m.wrapping_mul(len));
            if rest >= len {
                m += 1;
            }
            if negative[a] {
                -(m as i32)
            } else {
                m as i32
            }
        }))
    }

    /// Cross product, renormalised; `None` for parallel inputs.
    pub fn cross(self, o: Dir) -> Option<Dir> {
        let a = self.wide();
        let b = o.wide();
        let m = |x: usize, y: usize| mul_wide(a[x] as i32, b[y] as i32);
        Dir::normalize([m(1, 2) - m(2, 1), m(2, 0) - m(0, 2), m(0, 1) - m(1, 0)])
    }

    /// The mirror image of `self` about the unit normal `n`: `2(n·self)n − self`.
    /// The result stays unit length to rounding, so it is not renormalised.
    #[inline]
    pub fn reflect_about(self, n: Dir) -> Dir {
        let d = (self.dot_q60(n) >> 30) as i32; // n·self in Q2.30
        let nb = n.bits();
        let s = self.wide();
        Dir::from_bits([0, 1, 2].map(|i| ((mul_wide(d, nb[i]) >> 29) - s[i]).clamp(-UNIT_ONE, UNIT_ONE) as i32))
    }
}

/// `⌊(2^61 − 1) / len⌋` for `len` in [2^29, 2^31) (below 2^32). On ARMv6-M,
/// which has no divider, from `1/√len2 ≈ g·2^-e` (`len = ⌊√len2⌋`, e 60 or
/// 61): the estimate `g·2^(61−e)` is within a few dozen units, then stepped
/// to the exact floor on the remainder; elsewhere one division.
#[inline]
fn reciprocal_of_length(g: u32, e: i32, len: u32) -> u32 {
    if !ARMV6M {
        return (((1u64 << 61) - 1) / len as u64) as u32;
    }
    let estimate = if e == 60 { (g as u64) << 1 } else { g as u64 };
    let mut r = estimate.min(u32::MAX as u64) as u32;
    // r·len < 2^63: the remainder fits an i64.
    let mut rest = ((1i64 << 61) - 1) - mul_u32_wide(r, len) as i64;
    while rest < 0 {
        r -= 1;
        rest += len as i64;
    }
    while rest >= len as i64 {
        r += 1;
        rest -= len as i64;
    }
    r
}

impl Neg for Dir {
    type Output = Dir;
    #[inline]
    fn neg(self) -> Dir {
        Dir::from_bits(self.bits().map(|c| -c))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    fn len2(d: Dir) -> i64 {
        d.dot_q60(d)
    }

    #[test]
    fn normalize_gives_unit_length_at_any_scale() {
        for v in [
            [1i64, 0, 0],
            [3, 4, 0],
            [-7, 2, 9],
            [1 << 50, -(1 << 49), 12345],
            [i64::MAX / 4, i64::MIN / 4, 0],
            [0, 0, -1],
        ] {
            let d = Dir::normalize(v).unwrap();
            let err = (len2(d) - (1i64 << 60)).abs();
            assert!(err < 1 << 32, "{v:?} -> {d:?} off by {err}");
            // Same direction: the cross product with the input is tiny.
            let n = Dir::normalize(v.map(|c| -c)).unwrap();
            assert_eq!(n, -d, "symmetric rounding");
        }
        assert_eq!(Dir::normalize([0, 0, 0]), None);
    }

    #[test]
    fn small_and_wide_normalisation_agree() {
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for i in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = [x as i32 >> (i % 31), (x >> 32) as i32 >> (i % 17), (x >> 16) as i32 >> (i % 29)];
            let wide = v.map(|c| c as i64);
            assert_eq!(Dir::normalize_small_with_length(v), Dir::normalize_with_length(wide), "{v:?}");
        }
        assert_eq!(
            Dir::normalize_small_with_length([i32::MIN, 0, i32::MAX]).map(|r| r.0),
            Dir::normalize([i32::MIN as i64, 0, i32::MAX as i64])
        );
        assert_eq!(Dir::normalize_small_with_length([0, 0, 0]), None);
    }

    #[test]
    fn normalize_three_four_five() {
        let d = Dir::normalize([3, 4, 0]).unwrap();
        assert_eq!(d.bits()[2], 0);
        assert!((d.bits()[0] as i64 - (3i64 << 30) / 5).abs() <= 2);
        assert!((d.bits()[1] as i64 - (4i64 << 30) / 5).abs() <= 2);
    }

    #[test]
    fn reflection_about_axis_flips_one_component() {
        let d = Dir::normalize([1, -1, 0]).unwrap();
        let r = (-d).reflect_about(Dir::Y);
        let b = r.bits();
        let e = d.bits();
        assert!((b[0] - e[0]).abs() <= 1 && (b[1] + e[1]).abs() <= 1, "{r:?}");
    }

    #[test]
    fn direction_and_length_agree_with_the_separate_ones() {
        for v in [[3 << 16, 4 << 16, 0], [-7, 2, 9], [1 << 28, -(1 << 27), 12345], [0, 0, -1], [5, 0, 0]] {
            let v = Vec3::from_bits(v);
            let (d, l) = v.direction_and_length().unwrap();
            assert_eq!(d, v.direction().unwrap());
            assert!((l.to_bits() - v.length().to_bits()).abs() <= 1, "{v:?}: {l} vs {}", v.length());
        }
        assert_eq!(Vec3::ZERO.direction_and_length(), None);
    }

    #[test]
    fn the_estimated_direction_and_length_are_within_their_bounds() {
        // Against the exact forms, for vectors of every scale and ratio: each
        // component within 5 units in the last place, the length within
        // 2^-27 (relative) plus one unit, its sign and zero kept.
        let mut next = crate::test_rng::seeded(0xe571_3a7e_u64);
        for i in 0..300_000 {
            let v = Vec3::from_bits([0; 3].map(|_| {
                let x = next();
                ((x as i32) >> ((x >> 32) % 32)) * ((x >> 40) % 4 != 0) as i32
            }));
            let Some((exact, length)) = v.direction_and_length() else {
                assert_eq!(v.direction_and_length_estimate(), None);
                continue;
            };
            let (d, estimate) = v.direction_and_length_estimate().unwrap();
            for (got, want) in d.bits().iter().zip(exact.bits()) {
                assert!((got - want).abs() <= 5 && got.signum() == want.signum(), "case {i}: {v:?}: {d:?} {exact:?}");
            }
            let slack = 1 + (length.to_bits() >> 27);
            assert!((estimate.to_bits() - length.to_bits()).abs() <= slack, "case {i}: {v:?}: {estimate} {length}");
        }
    }

    #[test]
    fn coarse_dot_decisions_agree_with_the_exact_products() {
        let mut next = crate::test_rng::seeded(0xd07_c0a5e_u64);
        let (mut signs, mut limits, mut undecided) = (0, 0, 0);
        for round in 0..300_000 {
            // Unit-scale directions, points of every scale, and the extremes.
            let mut component = |shift: u64| -> i32 {
                let r = next();
                match round % 5 {
                    4 => [i32::MIN, i32::MAX, 0, -1, 1 << 30, -(1 << 30)][(r % 6) as usize],
                    _ => (r as i32) >> (shift + (r >> 60)),
                }
            };
            let a = [component(1), component(1), component(1)];
            let b = [component(0), component(0), component(0)];
            let exact = a.iter().zip(&b).map(|(&x, &y)| x as i128 * y as i128).sum::<i128>();
            // Only sums the plain i64 form holds are meaningful.
            if exact.abs() >= 1 << 62 {
                continue;
            }
            let exact = exact as i64;
            match coarse_sign(a, b) {
                Some(sign) => {
                    assert_eq!(sign as i64, exact.signum(), "{a:?} · {b:?}");
                    signs += 1;
                }
                None => undecided += 1,
            }
            let limit = [-(1i64 << 33), -(1 << 40), 0, 1 << 50, exact, exact - 1][round % 6];
            if let Some(at_most) = coarse_at_most(a, b, limit) {
                assert_eq!(at_most, exact <= limit, "{a:?} · {b:?} against {limit}");
                limits += 1;
            }
        }
        // Both outcomes of both tests were exercised.
        assert!(signs > 100_000 && limits > 50_000 && undecided > 1_000, "{signs} {limits} {undecided}");
    }

    #[test]
    fn coarse_plane_test_rejects_only_what_the_exact_test_rejects() {
        let mut next = crate::test_rng::seeded(0x9_1a2e_u64);
        let (mut rejected, mut unsure) = (0, 0);
        for round in 0..200_000 {
            let r = next();
            let unit = |bits: u64| ((bits as i32) >> 1) >> ((bits >> 29) & 7);
            let point = |bits: u64| (bits as i32) >> ((bits >> 30) & 15);
            let dir = [unit(r), unit(r >> 8), unit(r >> 16)];
            let n = [unit(r >> 24), unit(r >> 32), unit(r >> 40)];
            let s = next();
            let origin = [point(s), point(s >> 11), point(s >> 22)];
            let offset = match round % 3 {
                0 => point(s >> 33),
                // Planes through or near the origin's projection.
                _ => ((origin.iter().zip(&n).map(|(&o, &c)| o as i64 * c as i64).sum::<i64>() >> 30) as i32)
                    .wrapping_add((s >> 60) as i32 - 8),
            };
            let den = (dir.iter().zip(&n).map(|(&a, &b)| a as i64 * b as i64).sum::<i64>()) >> 30;
            let num = ((offset as i64) << 30) - origin.iter().zip(&n).map(|(&a, &b)| a as i64 * b as i64).sum::<i64>();
            if coarse_plane_behind(dir, origin, n, offset) {
                assert!((den > 0 && num <= 0) || (den < 0 && num >= 0), "{dir:?} {origin:?} {n:?} {offset}");
                rejected += 1;
            } else {
                unsure += 1;
            }
        }
        assert!(rejected > 10_000 && unsure > 10_000, "{rejected} {unsure}");
    }

    #[test]
    fn unscaled_lengths_are_the_wide_shifts_saturated() {
        let mut next = crate::test_rng::seeded(0x1e9_5ca1e);
        for i in 0..200_000 {
            let len = (next() as u32 >> 1) >> (next() % 8);
            // `scaled_magnitudes` gives shifts from −29 (a largest magnitude of 1) to 2.
            let shift = (next() % 32) as i32 - 29;
            let wide = if shift >= 0 {
                ((len as u64) << shift).min(i32::MAX as u64)
            } else {
                (len as u64 + (1 << (-shift - 1))) >> -shift
            };
            let wide = wide.min(i32::MAX as u64) as i32;
            assert_eq!(unscaled_length(len, shift).to_bits(), wide, "case {i}: {len} {shift}");
        }
    }

    #[test]
    fn dot_and_scale() {
        let v = Vec3::from_bits([3 << 16, 4 << 16, 0]);
        assert_eq!(v.length().to_bits(), 5 << 16);
        assert_eq!(v.dot_dir(Dir::X).to_bits(), 3 << 16);
        let s = Dir::Y.scale(Scalar::from_bits(-(5 << 16)));
        assert_eq!(s.bits(), [0, -(5 << 16), 0]);
        assert_eq!(Dir::X.cross(Dir::Y), Some(Dir::Z));
    }
    #[test]
    fn unit_components_are_the_rounded_quotients() {
        // Against u64 division: every component is round(c·2^30/len), ties
        // up, for magnitudes at every ratio (the largest in [2^29, 2^30)).
        let mut next = crate::test_rng::seeded(0xd171_ded0);
        for i in 0..300_000 {
            let x = next();
            let largest = (1 << 29) | (x as u32 & ((1 << 29) - 1));
            let other = |k: u32| match (x >> (32 + k)) % 4 {
                0 => largest,
                1 => (x >> k) as u32 % (largest + 1),
                2 => ((x >> k) as u32 % (largest + 1)) >> ((x >> (40 + k)) % 30),
                _ => 0,
            };
            let scaled = [largest, other(3), other(11)];
            let scaled = [scaled[i % 3], scaled[(i + 1) % 3], scaled[(i + 2) % 3]];
            let (d, len, _) = Dir::from_scaled([false, true, false], scaled, 0);
            let len2: u64 = scaled.iter().map(|&c| c as u64 * c as u64).sum();
            assert_eq!(len, len2.isqrt(), "case {i}");
            let want = scaled.map(|c| (((c as u64) << 30) + len / 2) / len);
            assert_eq!(d.bits(), [want[0] as i32, -(want[1] as i32), want[2] as i32], "case {i}: {scaled:?}");
        }
    }
}
