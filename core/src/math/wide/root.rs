//! Square roots without division: Newton's iteration for 1/√x needs only
//! products, from a 192-entry table built at compile time. The exact floor
//! on every target. (`isqrt_u128`, with divisions, is for the tables built
//! at compile time and for a scene's set-up.)

use super::bits::{leading_zeros, shr_saturating_u32, shr_signed_to_u32};
use super::product::{mul_u32_wide, square_u32_wide};

/// Floor of the square root of a `u128` (also usable in constants).
pub const fn isqrt_u128(n: u128) -> u128 {
    if n < 2 {
        return n;
    }
    let mut x = 1u128 << (128 - n.leading_zeros()).div_ceil(2);
    loop {
        let y = (x + n / x) / 2;
        if y >= x {
            return x;
        }
        x = y;
    }
}

/// 2^30 / √f at f = m/256 for m from 64 to 256: the end points of 192
/// intervals, interpolated linearly for the start of Newton's iteration.
static RSQRT_TABLE: [u32; 193] = {
    let mut t = [0u32; 193];
    let mut i = 0;
    while i < 193 {
        // 2^30/√(m/256) = √(2^60 · 256 / m), rounded down.
        t[i] = isqrt_u128((1u128 << 68) / (i as u128 + 64)) as u32;
        i += 1;
    }
    t
};

/// `1/√x` for `x > 0` as `(g, e)` with `1/√x ≈ g · 2^-e`, `g` in [2^30, 2^31]
/// to about 30 bits.
// The tests' reference for `sqrt_and_rsqrt`, which the tracer uses instead.
#[cfg(test)]
#[inline]
pub fn rsqrt(x: u64) -> (u32, i32) {
    let (f, shift) = rsqrt_argument(x);
    (rsqrt_normalised(f), 46 + shift / 2)
}

/// `x = f · 2^shift` with `f` in [2^30, 2^32) and an even `shift`, so that
/// 1/√x = (1/√(f / 2^32)) · 2^-(16 + shift/2).
#[inline(always)]
fn rsqrt_argument(x: u64) -> (u32, i32) {
    let bits = 64 - leading_zeros(x) as i32;
    let shift = (bits - 31) & !1;
    let f = shr_signed_to_u32(x, shift);
    (f, shift)
}

/// 2^30/√(f / 2^32) for `f` in [2^30, 2^32), in Q2.30.
#[inline(always)]
fn rsqrt_normalised(f: u32) -> u32 {
    // Linear interpolation is good to about 2^-15; one Newton step then
    // gives about 29 bits. The table falls by less than 2^24 per interval,
    // so the products here stay in a u32.
    let i = ((f >> 24) - 64) as usize;
    let (lo, hi) = (RSQRT_TABLE[i], RSQRT_TABLE[i + 1]);
    let g = lo - ((((lo - hi) >> 8) * ((f >> 8) & 0xffff)) >> 8); // Q2.30
                                                                  // g' = g (3 − f g²) / 2; g² in Q3.29 and f·g² in Q2.30 stay in u32.
    let g2 = (square_u32_wide(g) >> 31) as u32;
    let fg2 = (mul_u32_wide(f, g2) >> 31) as u32;
    let t = (3u32 << 30).wrapping_sub(fg2);
    (mul_u32_wide(g, t) >> 31) as u32
}

/// Floor of the square root of a `u64`, without division.
// Out of line on a board: long code, and its callers (a sphere's exact
// test, a cone's and a screen bound's set-up) each had their own copy
// whenever LLVM chose to inline it (the RISC-V firmware's flash +1.4 %).
#[cfg_attr(target_os = "none", inline(never))]
#[cfg_attr(not(target_os = "none"), inline)]
pub fn isqrt(n: u64) -> u64 {
    if n < 2 {
        return n;
    }
    let (f, shift) = rsqrt_argument(n);
    isqrt_from(n, rsqrt_normalised(f), f, shift)
}

/// `(⌊√n⌋, g, e)` with `1/√n ≈ g · 2^-e` as [`rsqrt`] gives it, from one
/// table look-up, for `n ≥ 2`.
#[inline]
pub fn sqrt_and_rsqrt(n: u64) -> (u64, u32, i32) {
    let (f, shift) = rsqrt_argument(n);
    let g = rsqrt_normalised(f);
    (isqrt_from(n, g, f, shift), g, 46 + shift / 2)
}

/// [`sqrt_and_rsqrt`] for `n` in [2^58, 2^62) — the squared length of a unit
/// vector's scaled magnitudes (the largest in [2^29, 2^30)) — where the
/// argument's scale is one of two, known without counting leading zeros.
#[inline]
pub(crate) fn sqrt_and_rsqrt_58_62(n: u64) -> (u64, u32, i32) {
    let Some((f, shift)) = argument_58_62(n) else {
        return sqrt_and_rsqrt(n);
    };
    let g = rsqrt_normalised(f);
    (isqrt_from(n, g, f, shift), g, 46 + shift / 2)
}

/// `(s, g, e)` with `s ≈ √n` and `1/√n ≈ g · 2^-e`, both within 2^-27
/// (relative), for `n` in [2^58, 2^62): [`sqrt_and_rsqrt_58_62`] without
/// the steps to the exact floor.
#[inline]
pub(crate) fn sqrt_and_rsqrt_estimates_58_62(n: u64) -> (u32, u32, i32) {
    let (f, shift) = argument_58_62(n).unwrap_or_else(|| rsqrt_argument(n));
    let g = rsqrt_normalised(f);
    (sqrt_estimate(g, f, shift), g, 46 + shift / 2)
}

/// What [`rsqrt_argument`] gives for `n` in [2^58, 2^62), where `n / 2^shift`
/// is in [2^30, 2^32) for one of two shifts; `None` outside.
#[inline(always)]
fn argument_58_62(n: u64) -> Option<(u32, i32)> {
    if n >> 62 != 0 || n >> 58 == 0 {
        None
    } else if n >> 60 != 0 {
        Some(((n >> 30) as u32, 30))
    } else {
        Some(((n >> 28) as u32, 28))
    }
}

/// `√n` from `n = f · 2^shift` and `g ≈ 2^30/√(f / 2^32)`: √n = f · (1/√f) ·
/// 2^(shift/2) = f·g · 2^(shift/2 − 46), capped below 2^32 (√n < 2^32).
#[inline(always)]
fn sqrt_estimate(g: u32, f: u32, shift: i32) -> u32 {
    shr_saturating_u32(mul_u32_wide(f, g), (46 - shift / 2) as u32)
}

/// ⌊√n⌋ for `n ≥ 2` given [`rsqrt_argument`]'s `f · 2^shift = n` and
/// `g ≈ 2^30/√(f / 2^32)`.
#[inline]
fn isqrt_from(n: u64, g: u32, f: u32, shift: i32) -> u64 {
    // The estimate corrected to the exact floor (at most a couple of
    // steps). The shift is 30 to 61 for every n ≥ 2; s² fits a u64, and the
    // steps keep it as `square` (one product in all).
    let mut s = sqrt_estimate(g, f, shift) as u64;
    let mut square = square_u32_wide(s as u32);
    while square > n {
        square -= 2 * s - 1;
        s -= 1;
    }
    while n - square > 2 * s {
        square += 2 * s + 1;
        s += 1;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::wide::tests::spread;

    #[test]
    fn sqrt_and_rsqrt_agree_with_the_separate_ones() {
        for n in spread(20_000).filter(|&n| n >= 2) {
            assert_eq!(sqrt_and_rsqrt(n), (n.isqrt(), rsqrt(n).0, rsqrt(n).1), "{n}");
        }
    }

    #[test]
    fn the_two_scale_square_root_is_the_general_one() {
        let ends = [1 << 58, (1 << 58) - 1, 1 << 60, (1 << 60) - 1, (1 << 62) - 1, 1 << 62, 3 << 60];
        for n in spread(50_000).map(|v| v | 1 << 58 >> (v % 3)).chain(ends) {
            assert_eq!(sqrt_and_rsqrt_58_62(n), sqrt_and_rsqrt(n), "{n}");
        }
    }

    #[test]
    fn the_estimates_are_within_two_to_the_minus_27() {
        for n in spread(50_000).map(|v| (v | 1 << 58) >> (v % 4)).filter(|&n| n >> 58 != 0) {
            let (s, g, e) = sqrt_and_rsqrt_estimates_58_62(n);
            let root = n.isqrt();
            assert!(root.abs_diff(s as u64) <= root >> 27, "{n}: {s} for {root}");
            // g²·n ≈ 2^(2e), so g within 2^-27 of 2^e/√n when this is within 2^-26.
            let err = ((g as u128 * g as u128) * n as u128).abs_diff(1u128 << (2 * e));
            assert!(err <= (1u128 << (2 * e)) >> 26, "{n}: {g} 2^-{e}");
        }
    }

    #[test]
    fn isqrt_is_the_exact_floor() {
        for n in spread(20_000).chain([0, 1, 2, 3, 4, 8, 9, 15, 16, (1 << 62) - 1, 1 << 62, u64::MAX, u64::MAX - 1]) {
            assert_eq!(isqrt(n), n.isqrt(), "{n}");
        }
        for k in 0..64 {
            let n = 1u64 << k;
            assert_eq!(isqrt(n), n.isqrt());
            assert_eq!(isqrt(n - 1), (n - 1).isqrt());
        }
    }

    #[test]
    fn rsqrt_is_accurate_to_thirty_bits() {
        for n in spread(5_000).filter(|&n| n > 0) {
            let (g, e) = rsqrt(n);
            // g²·n ≈ 2^(2e) within 2^-28 relative.
            let lhs = (g as u128 * g as u128) * n as u128;
            let rhs = 1u128 << (2 * e);
            let err = lhs.abs_diff(rhs);
            assert!(err <= rhs >> 27, "{n}: {g} 2^-{e}");
        }
    }
}
