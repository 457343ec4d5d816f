//! Exact wide products: 32×32→64 and the 3DDDA's 64×64 crossings.
//!
//! ARMv6-M (Cortex-M0) has only a 32-bit multiply: a Rust `i64 * i64`
//! becomes a call to a general 64×64 routine. A 32×32→64 product needs only
//! four 16×16 ones, so [`mul_wide`] does that there (and is the plain
//! product elsewhere). Every function returns the same bits on every target.

use super::super::ARMV6M;

/// `a · b` exactly, for unsigned 32-bit operands.
#[inline(always)]
pub fn mul_u32_wide(a: u32, b: u32) -> u64 {
    if ARMV6M {
        mul_u32_wide_by_parts(a, b)
    } else {
        a as u64 * b as u64
    }
}

/// `a · b` exactly, for signed 32-bit operands.
#[inline(always)]
pub fn mul_wide(a: i32, b: i32) -> i64 {
    if ARMV6M {
        mul_wide_by_parts(a, b)
    } else {
        a as i64 * b as i64
    }
}

/// `a²` exactly.
#[inline(always)]
pub fn square_wide(a: i32) -> u64 {
    if ARMV6M {
        square_by_parts(a)
    } else {
        (a as i64 * a as i64) as u64
    }
}

/// `a · k`, exact when it fits an i64 (wrapping otherwise): two 32-bit
/// products on ARMv6-M instead of the library's 64×64 routine.
#[inline(always)]
pub fn mul_i64_i32(a: i64, k: i32) -> i64 {
    if ARMV6M {
        mul_i64_i32_by_parts(a, k)
    } else {
        a.wrapping_mul(k as i64)
    }
}

/// `a · k` exactly, in 128 bits: on ARMv6-M from three 32×32 products
/// instead of the library's 128-bit multiplication.
#[inline(always)]
pub fn mul_i64_i32_wide(a: i64, k: i32) -> i128 {
    if ARMV6M {
        mul_i64_i32_wide_by_parts(a, k)
    } else {
        a as i128 * k as i128
    }
}

/// `a · b` exactly, in 128 bits. Not inlined: 128-bit products are long
/// code on a 32-bit core, and their callers (a camera's and an object's
/// set-up) run once per render, not per ray. On ARMv6-M an operand that
/// fits 32 bits (a box's side from the eye, a gap) takes three 32×32
/// products instead of the library's 128-bit multiplication, which makes
/// its own 64×64 ones by library calls (fig5_3's 200 screen windows spent
/// 2.9 M cycles of a Pico in them).
#[inline(never)]
pub fn mul_i64_wide(a: i64, b: i64) -> i128 {
    if ARMV6M {
        if let Ok(k) = i32::try_from(b) {
            return mul_i64_i32_wide_by_parts(a, k);
        }
        if let Ok(k) = i32::try_from(a) {
            return mul_i64_i32_wide_by_parts(b, k);
        }
    }
    a as i128 * b as i128
}

/// `a²` exactly, for an unsigned operand.
#[inline(always)]
pub fn square_u32_wide(a: u32) -> u64 {
    if ARMV6M {
        square_u32_by_parts(a)
    } else {
        a as u64 * a as u64
    }
}

/// Four 16×16 products.
#[inline(always)]
fn mul_u32_wide_by_parts(a: u32, b: u32) -> u64 {
    let (al, ah) = (a & 0xffff, a >> 16);
    let (bl, bh) = (b & 0xffff, b >> 16);
    let mid = (al * bh) as u64 + (ah * bl) as u64;
    (((ah * bh) as u64) << 32) + (mid << 16) + (al * bl) as u64
}

/// Signed high halves and unsigned low ones: every partial product fits an
/// i32 (low × low a u32), so no sign fix-up is needed.
#[inline(always)]
fn mul_wide_by_parts(a: i32, b: i32) -> i64 {
    let (ah, al) = (a >> 16, (a & 0xffff) as u32);
    let (bh, bl) = (b >> 16, (b & 0xffff) as u32);
    let mid = (ah * bl as i32) as i64 + (al as i32 * bh) as i64;
    (((ah * bh) as i64) << 32) + (mid << 16) + (al * bl) as i64
}

/// The high word times `k` (only its low 32 bits matter) plus the low word
/// times `k`.
#[inline(always)]
fn mul_i64_i32_by_parts(a: i64, k: i32) -> i64 {
    let (high, low) = ((a >> 32) as i32, a as u32);
    let low_part = mul_u32_wide_by_parts(low, k.unsigned_abs()) as i64;
    let low_part = if k < 0 { low_part.wrapping_neg() } else { low_part };
    ((high.wrapping_mul(k) as i64) << 32).wrapping_add(low_part)
}

/// The signed high word's product, and the unsigned low word's (below
/// 2^63 in magnitude: it fits an i64).
#[inline(always)]
fn mul_i64_i32_wide_by_parts(a: i64, k: i32) -> i128 {
    let (high, low) = ((a >> 32) as i32, a as u32);
    let low_part = mul_u32_wide_by_parts(low, k.unsigned_abs()) as i64;
    let low_part = if k < 0 { -low_part } else { low_part };
    ((mul_wide_by_parts(high, k) as i128) << 32) + low_part as i128
}

/// Three products: the two middle ones are equal.
#[inline(always)]
fn square_by_parts(a: i32) -> u64 {
    square_u32_by_parts(a.unsigned_abs())
}

#[inline(always)]
fn square_u32_by_parts(m: u32) -> u64 {
    let (h, l) = (m >> 16, m & 0xffff);
    (((h * h) as u64) << 32) + (((h * l) as u64) << 17) + (l * l) as u64
}

/// `⌊x · y / 2^24⌋` clamped to `[−LIMIT, LIMIT]` (`LIMIT` below 2^63): the
/// 3DDDA's plane crossings. On ARMv6-M, from four 32×32 products instead of
/// the library's 128-bit multiplication: the same bits.
#[inline(always)]
pub(crate) fn mul_u64_shr24_clamped<const LIMIT: i64>(x: i64, y: u64) -> i64 {
    if ARMV6M {
        mul_u64_shr24_clamped_by_parts(x, y, LIMIT)
    } else {
        ((x as i128 * y as i128) >> 24).clamp(-(LIMIT as i128), LIMIT as i128) as i64
    }
}

/// `⌊x · y / 2^24⌋` for products known to stay below 2^84 in magnitude
/// (no clamp needed: the 3DDDA's crossings on axes the ray is not almost
/// parallel to). The same bits as [`mul_u64_shr24_clamped`] there.
#[inline(always)]
pub(crate) fn mul_u64_shr24(x: i64, y: u64) -> i64 {
    if ARMV6M {
        mul_u64_shr24_by_parts(x, y)
    } else {
        ((x as i128 * y as i128) >> 24) as i64
    }
}

/// `|x| · y` as high and low 64-bit words, from 32×32 products: two when
/// `|x| < 2^32` (every difference of scene coordinates), else four.
#[inline(always)]
fn magnitude_product(x: i64, y: u64) -> (u64, u64) {
    let m = x.unsigned_abs();
    let (mh, ml, yh, yl) = ((m >> 32) as u32, m as u32, (y >> 32) as u32, y as u32);
    let low_low = mul_u32_wide(ml, yl);
    if mh == 0 {
        let cross = mul_u32_wide(ml, yh);
        let (low, carry_low) = low_low.overflowing_add(cross << 32);
        ((cross >> 32) + carry_low as u64, low)
    } else {
        let (cross1, cross2) = (mul_u32_wide(ml, yh), mul_u32_wide(mh, yl));
        let (cross, carry) = cross1.overflowing_add(cross2);
        let (low, carry_low) = low_low.overflowing_add(cross << 32);
        (mul_u32_wide(mh, yh) + (cross >> 32) + ((carry as u64) << 32) + carry_low as u64, low)
    }
}

/// [`mul_u64_shr24`] on ARMv6-M: the product's bits 24 to 87 (below 2^84
/// in magnitude, so no clamp), rounded towards −∞.
#[inline]
fn mul_u64_shr24_by_parts(x: i64, y: u64) -> i64 {
    let (high, low) = magnitude_product(x, y);
    let round = (x < 0 && low & 0xff_ffff != 0) as u64;
    let magnitude = (((high << 40) | (low >> 24)) + round) as i64;
    if x < 0 {
        -magnitude
    } else {
        magnitude
    }
}

#[inline]
fn mul_u64_shr24_clamped_by_parts(x: i64, y: u64, limit: i64) -> i64 {
    let (high, low) = magnitude_product(x, y);
    // A negative product rounds towards −∞: the magnitude rounds up.
    let round = if x < 0 && low & 0xff_ffff != 0 { 1 } else { 0 };
    if high >> 24 != 0 {
        return if x < 0 { -limit } else { limit };
    }
    let magnitude = ((high << 40) | (low >> 24)).saturating_add(round);
    let magnitude = magnitude.min(limit as u64) as i64;
    if x < 0 {
        -magnitude
    } else {
        magnitude
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::wide::tests::spread;

    #[test]
    fn part_wise_products_match_the_native_ones() {
        let edges = [0, 1, 0xffff, 0x1_0000, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff];
        let words = spread(20_000).map(|v| v as u32).chain(edges);
        for (i, a) in words.enumerate() {
            let b = a.rotate_left(i as u32 % 32) ^ (i as u32).wrapping_mul(2_654_435_761);
            assert_eq!(mul_u32_wide_by_parts(a, b), a as u64 * b as u64, "{a} {b}");
            let (x, y) = (a as i32, b as i32);
            assert_eq!(mul_wide_by_parts(x, y), x as i64 * y as i64, "{x} {y}");
            assert_eq!(square_by_parts(x), (x as i64 * x as i64) as u64, "{x}");
            let wide = ((a as i64) << 29) ^ b as i64;
            assert_eq!(mul_i64_i32_by_parts(wide, y), wide.wrapping_mul(y as i64), "{wide} {y}");
            assert_eq!(mul_i64_i32_by_parts(-wide, y >> 9), (-wide).wrapping_mul((y >> 9) as i64));
            let full = ((a as i64) << 32 | b as i64) ^ (i as i64).wrapping_mul(0x9e37_79b9_7f4a_7c15u64 as i64);
            for (n, k) in [(full, y), (wide, y), (full, i32::MIN), (i64::MIN, y), (i64::MAX, i32::MIN)] {
                assert_eq!(mul_i64_i32_wide_by_parts(n, k), n as i128 * k as i128, "{n} {k}");
            }
        }
    }

    #[test]
    fn crossing_product_by_parts_is_exact() {
        let limit = 1i64 << 60;
        let mut next = crate::test_rng::seeded(0x9e37_79b9_7f4a_7c15);
        let edges = [
            0i64,
            1,
            -1,
            (1 << 24) - 1,
            -(1 << 24),
            (1 << 32) - 1,
            1 << 32,
            -(1 << 32),
            1 << 33,
            -(1 << 33),
            i64::MAX >> 20,
            -(i64::MAX >> 20),
        ];
        for i in 0..200_000 {
            let x = match i % 4 {
                0 => edges[(next() % edges.len() as u64) as usize],
                _ => (next() as i64) >> (next() % 40 + 20),
            };
            let y = (next() >> (next() % 33)) | 1 << 31;
            let plain = ((x as i128 * y as i128) >> 24).clamp(-(limit as i128), limit as i128) as i64;
            assert_eq!(mul_u64_shr24_clamped_by_parts(x, y, limit), plain, "{x} × {y}");
            if (x.unsigned_abs() as u128 * y as u128) < 1 << 84 {
                assert_eq!(mul_u64_shr24_by_parts(x, y), ((x as i128 * y as i128) >> 24) as i64, "{x} × {y}");
            }
        }
    }

    #[test]
    fn wide_products_are_exact() {
        for (i, v) in spread(20_000).enumerate() {
            let (a, b) = (v as u32, (v >> 32) as u32 ^ (i as u32).wrapping_mul(2_654_435_761));
            assert_eq!(mul_u32_wide(a, b), a as u64 * b as u64);
            let (a, b) = (a as i32, b as i32);
            assert_eq!(mul_wide(a, b), a as i64 * b as i64, "{a} {b}");
        }
        assert_eq!(mul_wide(i32::MIN, i32::MIN), 1 << 62);
        assert_eq!(mul_wide(i32::MIN, i32::MAX), i32::MIN as i64 * i32::MAX as i64);
    }
}
