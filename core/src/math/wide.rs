//! Wide products and square roots, cheap on every target.
//!
//! ARMv6-M (Cortex-M0) has only a 32-bit multiply: a Rust `i64 * i64`
//! becomes a call to a general 64×64 routine. A 32×32→64 product needs only
//! four 16×16 ones, so [`mul_wide`] does that there (and is the plain
//! product elsewhere). Square roots avoid division entirely: Newton's
//! iteration for 1/√x needs only products, from a 192-entry table built at
//! compile time. Every function returns the same bits on every target.

// On ARMv6-M the `*_by_parts` forms below are used, elsewhere the native
// operations.
use super::ARMV6M;

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

/// `a · b` exactly, in 128 bits. Not inlined: 128-bit products are long
/// code on a 32-bit core, and their callers (a camera's and an object's
/// set-up) run once per render, not per ray.
#[inline(never)]
pub fn mul_i64_wide(a: i64, b: i64) -> i128 {
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

/// The number of leading zero bits of `x` (64 for zero).
#[inline(always)]
pub fn leading_zeros(x: u64) -> u32 {
    if ARMV6M {
        leading_zeros_by_search(x)
    } else {
        x.leading_zeros()
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

/// The number of leading zero bits of a 32-bit `x` (32 for zero).
#[inline(always)]
pub fn leading_zeros_u32(x: u32) -> u32 {
    if ARMV6M {
        leading_zeros_of_word(x, 0)
    } else {
        x.leading_zeros()
    }
}

/// Leading zeros of each byte value (8 for zero).
static BYTE_LEADING_ZEROS: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        t[i] = (i as u8).leading_zeros() as u8;
        i += 1;
    }
    t
};

/// Two halvings of one 32-bit word, then a table of the top byte: about ten
/// instructions (the library routine costs about 35 on a Cortex-M0, a
/// five-step binary search about 25).
#[inline(always)]
fn leading_zeros_by_search(x: u64) -> u32 {
    let (high, low) = ((x >> 32) as u32, x as u32);
    if high != 0 {
        leading_zeros_of_word(high, 0)
    } else {
        leading_zeros_of_word(low, 32)
    }
}

/// `base` plus the leading zeros of `w` (8 more than the table's for zero).
#[inline(always)]
fn leading_zeros_of_word(mut w: u32, base: u32) -> u32 {
    let mut n = base;
    if w >> 16 == 0 {
        n += 16;
        w <<= 16;
    }
    if w >> 24 == 0 {
        n += 8;
        w <<= 8;
    }
    n + BYTE_LEADING_ZEROS[(w >> 24) as usize] as u32
}

/// `x >> shift` for a shift in 0 ..= 63 whose result fits 32 bits: on a
/// 32-bit core, a 64-bit shift by a variable amount is a library call.
#[inline(always)]
pub fn shr_to_u32(x: u64, shift: u32) -> u32 {
    let (high, low) = ((x >> 32) as u32, x as u32);
    if shift >= 32 {
        high >> (shift - 32)
    } else if shift == 0 {
        low
    } else {
        (low >> shift) | (high << (32 - shift))
    }
}

/// `min(x >> shift, u32::MAX)` for a shift in 1 ..= 63, in 32-bit steps
/// (a 64-bit shift by a variable amount is a library call on a 32-bit core).
#[inline(always)]
pub(crate) fn shr_saturating_u32(x: u64, shift: u32) -> u32 {
    let (high, low) = ((x >> 32) as u32, x as u32);
    if shift >= 32 {
        high >> (shift - 32)
    } else if high >> shift != 0 {
        u32::MAX
    } else {
        (low >> shift) | (high << (32 - shift))
    }
}

/// `⌊n / d⌋`, saturating at `u32::MAX` (also for `d = 0`). Exact on every
/// target; on ARMv6-M without a division (the library's 64-bit division
/// costs some 450 instructions there).
#[inline]
pub fn div_saturating(n: u64, d: u32) -> u32 {
    if d == 0 || n >> 32 >= d as u64 {
        return u32::MAX;
    }
    if ARMV6M {
        div_by_reciprocal(n, d)
    } else {
        (n / d as u64) as u32
    }
}

/// `⌊2^62 / d⌋` for `d > 0` (the 3DDDA's reciprocals). On ARMv6-M, two
/// divisions with 32-bit quotients by reciprocal instead of the library's
/// 64-bit division: the same bits.
#[inline]
pub(crate) fn reciprocal_q62(d: u32) -> u64 {
    let d = d.max(1);
    if ARMV6M {
        // Both quotients by the same reciprocal: 2^30 < d·2^32, and the
        // remainder is below d.
        let reciprocal = Reciprocal::of(d);
        let (high, remainder) = reciprocal.quotient_of_2_30();
        ((high as u64) << 32) | reciprocal.quotient::<2>((remainder as u64) << 32) as u64
    } else {
        (1u64 << 62) / d as u64
    }
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

/// 2^63 / (m · 2^-8) for m = 256 … 512 (divisors normalised to [1, 2]; the
/// first, 2^32, is one below), the ends of the intervals that the start of
/// Newton's iteration for the reciprocal is interpolated in.
static RECIPROCAL_TABLE: [u32; 257] = {
    let mut t = [0u32; 257];
    let mut i = 0;
    while i < 257 {
        let r = (1u64 << 40) / (256 + i as u64);
        t[i] = if r > u32::MAX as u64 { u32::MAX } else { r as u32 };
        i += 1;
    }
    t
};

/// `x >> shift` for a shift in 0 ..= 63, in 32-bit halves (a variable
/// 64-bit shift is a library call on a 32-bit core).
#[inline(always)]
pub(crate) fn shr_u64(x: u64, shift: u32) -> u64 {
    let (high, low) = ((x >> 32) as u32, x as u32);
    if shift >= 32 {
        (high >> (shift - 32)) as u64
    } else if shift == 0 {
        x
    } else {
        (((high >> shift) as u64) << 32) | ((low >> shift) | (high << (32 - shift))) as u64
    }
}

/// `x << shift` for a shift in 0 ..= 31 whose result fits 64 bits, in
/// 32-bit halves (a variable 64-bit shift is a library call on a 32-bit
/// core).
#[inline(always)]
pub(crate) fn shl_u64(x: u64, shift: u32) -> u64 {
    if shift == 0 {
        return x;
    }
    let (high, low) = ((x >> 32) as u32, x as u32);
    ((((high << shift) | (low >> (32 - shift))) as u64) << 32) | (low << shift) as u64
}

/// `⌊n / d⌋` for `0 < d` and `n < d · 2^32`, from a reciprocal.
#[inline]
fn div_by_reciprocal(n: u64, d: u32) -> u32 {
    Reciprocal::of(d).quotient::<0>(n)
}

/// A divisor made ready for exact divisions by products: several quotients
/// by the same divisor share the normalisation and the Newton step.
#[derive(Clone, Copy)]
struct Reciprocal {
    divisor: u32,
    /// `divisor · 2^shift` is in [2^31, 2^32).
    shift: u32,
    /// About 2^63 / (divisor · 2^shift), to some 31 bits.
    r: u32,
}

impl Reciprocal {
    /// For `d > 0`.
    #[inline(always)]
    fn of(d: u32) -> Reciprocal {
        // Normalise: dn in [2^31, 2^32); the quotients are unchanged.
        let shift = leading_zeros_u32(d);
        let dn = d << shift;
        // r ≈ 2^63 / dn: about 17 bits from the table, interpolated (1/x is
        // within 2^-18 of its chord over an interval), then about 31 after
        // one Newton step r' = r + r·(2^63 − dn·r)/2^63. The interpolation's
        // terms stay in a u32: neighbours differ by less than 2^24.
        let i = ((dn >> 23) & 0xff) as usize;
        let (lo, hi) = (RECIPROCAL_TABLE[i], RECIPROCAL_TABLE[i + 1]);
        let r = lo - ((((lo - hi) >> 9) * ((dn >> 7) & 0xffff)) >> 7);
        let error = ((1u64 << 63).wrapping_sub(mul_u32_wide(dn, r)) as i64 >> 31) as i32;
        let step = (mul_u32_wide(r, error.unsigned_abs()) >> 32) as u32;
        let r = if error >= 0 { r.saturating_add(step) } else { r - step };
        Reciprocal { divisor: d, shift, r }
    }

    /// `⌊n / divisor⌋` for `n < divisor · 2^32`.
    #[inline(always)]
    fn quotient<const STEPS: usize>(&self, n: u64) -> u32 {
        let r = self.r;
        let numerator = shl_u64(n, self.shift); // below dn · 2^32
        let (high, low) = ((numerator >> 32) as u32, numerator as u32);
        let estimate = (mul_u32_wide(high, r) + (mul_u32_wide(low, r) >> 32)) >> 31;
        self.corrected::<STEPS>(n, estimate.min(u32::MAX as u64) as u32).0
    }

    /// `⌊2^30 / divisor⌋` and the remainder: the numerator, normalised, is a
    /// power of two, so the estimate above is a shift of the reciprocal (the
    /// same value).
    #[inline(always)]
    fn quotient_of_2_30(&self) -> (u32, u32) {
        // (2^(30 + shift) · r) / 2^63, shift ≥ 1 for a divisor below 2^31.
        let estimate = if self.shift == 0 { 0 } else { self.r >> (33 - self.shift).min(31) };
        self.corrected::<0>(1 << 30, estimate)
    }

    /// The exact floor of `n / divisor` from an estimate a few off at most,
    /// stepped on the remainder, and the remainder. `STEPS` steps are
    /// written out first where the compiler would otherwise turn the
    /// stepping loop into a 64-bit division (see below).
    #[inline(always)]
    fn corrected<const STEPS: usize>(&self, n: u64, estimate: u32) -> (u32, u32) {
        let d = self.divisor;
        let mut q = estimate;
        let mut remainder = n.wrapping_sub(mul_u32_wide(q, d)) as i64;
        // Steps written out first: in the 3DDDA's reciprocals the compiler
        // turned the bare stepping loop into a 64-bit division (a library
        // call of some 450 instructions on a Cortex-M0), which only a far
        // estimate needs.
        for _ in 0..STEPS {
            if remainder < 0 {
                q = q.wrapping_sub(1);
                remainder += d as i64;
            } else if remainder >= d as i64 {
                q = q.wrapping_add(1);
                remainder -= d as i64;
            }
        }
        while remainder < 0 {
            q -= 1;
            remainder += d as i64;
        }
        while remainder >= d as i64 {
            q += 1;
            remainder -= d as i64;
        }
        (q, remainder as u32)
    }
}

/// 2^30 / √f at f = m/256 for m from 64 to 256: the end points of 192
/// intervals, interpolated linearly for the start of Newton's iteration.
static RSQRT_TABLE: [u32; 193] = {
    let mut t = [0u32; 193];
    let mut i = 0;
    while i < 193 {
        // 2^30/√(m/256) = √(2^60 · 256 / m), rounded down.
        t[i] = super::isqrt_u128((1u128 << 68) / (i as u128 + 64)) as u32;
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
    let f = if shift >= 0 { shr_to_u32(x, shift as u32) } else { (x as u32) << -shift };
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
#[inline]
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
    let shift = if n >> 62 != 0 || n >> 58 == 0 {
        return sqrt_and_rsqrt(n);
    } else if n >> 60 != 0 {
        30
    } else {
        28
    };
    // What `rsqrt_argument` gives: f = n / 2^shift in [2^30, 2^32).
    let f = if shift == 30 { (n >> 30) as u32 } else { (n >> 28) as u32 };
    let g = rsqrt_normalised(f);
    (isqrt_from(n, g, f, shift), g, 46 + shift / 2)
}

/// ⌊√n⌋ for `n ≥ 2` given [`rsqrt_argument`]'s `f · 2^shift = n` and
/// `g ≈ 2^30/√(f / 2^32)`.
#[inline]
fn isqrt_from(n: u64, g: u32, f: u32, shift: i32) -> u64 {
    // √n = f · (1/√f) · 2^(shift/2) = f·g · 2^(shift/2 − 46), then
    // corrected to the exact floor (at most a couple of steps). The shift
    // is 30 to 61 for every n ≥ 2.
    // √n < 2^32, so the estimate is capped below it; s² then fits a u64,
    // and the steps keep it as `square` (one product in all).
    let mut s = shr_saturating_u32(mul_u32_wide(f, g), (46 - shift / 2) as u32) as u64;
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

    /// Repeatable inputs of every magnitude.
    fn spread(count: usize) -> impl Iterator<Item = u64> {
        let mut next = crate::test_rng::seeded(0x9e37_79b9_7f4a_7c15);
        (0..count).map(move |_| {
            let s = next();
            s >> (s % 64)
        })
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
    fn reciprocal_by_two_short_divisions_is_exact() {
        // The ARMv6-M form: both quotients by one reciprocal.
        let by_parts = |d: u32| {
            let reciprocal = Reciprocal::of(d);
            let (high, rest) = reciprocal.quotient_of_2_30();
            assert_eq!(high, reciprocal.quotient::<0>(1 << 30), "{d}");
            let remainder = (1u64 << 30) - mul_u32_wide(high, d);
            assert_eq!(rest as u64, remainder, "{d}");
            ((high as u64) << 32) | reciprocal.quotient::<2>(remainder << 32) as u64
        };
        let mut d = 1u32;
        while d < (1 << 30) + 7 {
            for e in [d, d + 1, d.saturating_mul(3) / 2] {
                assert_eq!(by_parts(e), (1u64 << 62) / e as u64, "{e}");
                assert_eq!(reciprocal_q62(e), (1u64 << 62) / e as u64, "{e}");
            }
            d = (d as u64 * 5 / 4 + 1) as u32;
        }
        assert_eq!(reciprocal_q62(0), 1 << 62);
    }

    #[test]
    fn part_wise_forms_match_the_native_operations() {
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
        }
        for v in spread(20_000).chain([0, 1, u64::MAX, 1 << 32, (1 << 32) - 1, 1 << 63]) {
            assert_eq!(leading_zeros_by_search(v), v.leading_zeros(), "{v}");
            assert_eq!(leading_zeros_of_word(v as u32, 0), (v as u32).leading_zeros(), "{v}");
        }
        for v in spread(5_000).chain([u64::MAX, 1 << 63, (1 << 32) - 1, 1]) {
            for shift in 0..64 {
                assert_eq!(shr_u64(v, shift), v >> shift, "{v} >> {shift}");
            }
            for shift in 0..32 {
                if v.leading_zeros() >= shift {
                    assert_eq!(shl_u64(v, shift), v << shift, "{v} << {shift}");
                }
            }
        }
        for v in spread(5_000).chain([u64::MAX, 1 << 63, (1 << 32) - 1]) {
            for shift in 1..64 {
                assert_eq!(shr_saturating_u32(v, shift), (v >> shift).min(u32::MAX as u64) as u32, "{v} >> {shift}");
            }
        }
        for v in spread(5_000) {
            for shift in 0..64 {
                if v >> shift <= u32::MAX as u64 {
                    assert_eq!(shr_to_u32(v, shift), (v >> shift) as u32, "{v} >> {shift}");
                }
            }
        }
    }

    #[test]
    fn division_by_reciprocal_is_exact() {
        let mut cases = 0;
        for (i, v) in spread(40_000).enumerate() {
            let d = ((v >> 17) as u32 ^ (i as u32).wrapping_mul(2_654_435_761)) >> (i % 32);
            if d == 0 {
                continue;
            }
            let n = v % ((d as u64) << 32);
            assert_eq!(div_by_reciprocal(n, d) as u64, n / d as u64, "{n} / {d}");
            cases += 1;
        }
        assert!(cases > 30_000);
        for d in [1u32, 2, 3, 7, 255, 256, 65_535, 1 << 31, (1 << 31) + 1, u32::MAX - 1, u32::MAX] {
            let top = ((d as u64) << 32) - 1;
            for n in [0, 1, d as u64 - 1, d as u64, top, top - d as u64, top / 2, top / 3] {
                assert_eq!(div_by_reciprocal(n, d) as u64, n / d as u64, "{n} / {d}");
            }
        }
        assert_eq!(div_saturating(1 << 40, 0), u32::MAX);
        assert_eq!(div_saturating(1 << 40, 255), u32::MAX);
        assert_eq!(div_saturating(1 << 40, 257), ((1u64 << 40) / 257) as u32);
    }

    #[test]
    fn sqrt_and_rsqrt_agree_with_the_separate_ones() {
        for n in spread(20_000).filter(|&n| n >= 2) {
            assert_eq!(sqrt_and_rsqrt(n), (n.isqrt(), rsqrt(n).0, rsqrt(n).1), "{n}");
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

    #[test]
    fn the_two_scale_square_root_is_the_general_one() {
        let ends = [1 << 58, (1 << 58) - 1, 1 << 60, (1 << 60) - 1, (1 << 62) - 1, 1 << 62, 3 << 60];
        for n in spread(50_000).map(|v| v | 1 << 58 >> (v % 3)).chain(ends) {
            assert_eq!(sqrt_and_rsqrt_58_62(n), sqrt_and_rsqrt(n), "{n}");
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
