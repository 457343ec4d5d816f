//! Integer `log2`, `exp2` and `pow` for the superquadric, the specular term and
//! the gamma table.
//!
//! Both functions interpolate linearly in a 257-entry table that is computed
//! at compile time from integer square roots and squarings, so the results are
//! the same bits on every target and no float ever runs. Absolute error: below
//! 3·10^-6 for `log2` and a relative 2·10^-6 for `exp2`.

use super::{isqrt_u128, mul_wide};

/// log2(1 + i/256) in Q0.32 for i = 0..=256.
static LOG2_TABLE: [u64; 257] = log2_table();
/// 2^(i/256) in Q1.62 for i = 0..=256.
static EXP2_TABLE: [u64; 257] = exp2_table();

/// log2 of `x` in [1, 2) given in Q2.62, as Q0.32, by repeated squaring.
const fn log2_mantissa_q32(mut x: u128) -> u64 {
    let mut result: u64 = 0;
    let mut bit = 0;
    // 34 bits, then round to 32.
    while bit < 34 {
        x = (x * x) >> 62;
        result <<= 1;
        if x >= 2 << 62 {
            x >>= 1;
            result |= 1;
        }
        bit += 1;
    }
    (result + 2) >> 2
}

const fn log2_table() -> [u64; 257] {
    let mut t = [0u64; 257];
    let mut i = 0;
    while i < 256 {
        t[i] = log2_mantissa_q32(((256 + i as u128) << 62) / 256);
        i += 1;
    }
    t[256] = 1 << 32;
    t
}

const fn exp2_table() -> [u64; 257] {
    // 2^(1/256) by eight square roots of 2, in Q2.62 (sqrt of a Q4.124 value).
    let mut root: u128 = 2 << 62;
    let mut k = 0;
    while k < 8 {
        root = isqrt_u128(root << 62);
        k += 1;
    }
    let mut t = [0u64; 257];
    let mut acc: u128 = 1 << 62;
    let mut i = 0;
    while i <= 256 {
        t[i] = acc as u64;
        acc = (acc * root + (1 << 61)) >> 62;
        i += 1;
    }
    // Pin the end points exactly: 2^0 and 2^1.
    t[0] = 1 << 62;
    t[256] = 2 << 62;
    t
}

/// log2 of the positive fixed-point value `raw / 2^frac_bits`, in Q32.32.
/// Returns `i64::MIN` for zero (log of zero is minus infinity).
pub fn log2_q32(raw: u64, frac_bits: u32) -> i64 {
    if raw == 0 {
        return i64::MIN;
    }
    let top = 63 - super::leading_zeros(raw) as i64;
    // Top bit at 63: m / 2^63 in [1, 2). In 32-bit halves: a variable
    // 64-bit shift is a library call on a 32-bit core.
    let up = (63 - top) as u32;
    let m = if up >= 32 { (((raw as u32) << (up - 32)) as u64) << 32 } else { super::shl_u64(raw, up) };
    let index = ((m >> 55) & 0xff) as usize;
    let rest = ((m >> 23) & 0xffff_ffff) as u32; // Q0.32 position inside the interval
    let lo = LOG2_TABLE[index];
    let hi = LOG2_TABLE[index + 1];
    // Neighbouring entries differ by less than 2^25.
    let frac = lo + (super::mul_u32_wide((hi - lo) as u32, rest) >> 32);
    ((top - frac_bits as i64) << 32) + frac as i64
}

/// 2^`y` for `y` in Q32.32, as Q32.32 (`u64`), saturating at `u64::MAX` and
/// flushing to zero below 2^-32.
pub fn exp2_q32(y: i64) -> u64 {
    let int = y >> 32;
    let frac = (y & 0xffff_ffff) as u64;
    let index = (frac >> 24) as usize;
    let rest = frac & 0xff_ffff; // Q0.24
    let lo = EXP2_TABLE[index];
    let hi = EXP2_TABLE[index + 1];
    // Neighbouring entries differ by less than 2^54.
    let mant = lo + super::mul_u32_wide(((hi - lo) >> 24) as u32, rest as u32); // Q2.62 in [1, 2]
                                                                                // result = mant · 2^int in Q32: shift right by 30 − int.
    let shift = 30 - int;
    if shift >= 64 {
        0
    } else if shift > 0 {
        // (mant + 2^(shift−1)) >> shift, which cannot overflow (mant ≤ 2^63),
        // as the halves' shift by one less, plus one, halved: the same bits.
        (super::shr_u64(mant, shift as u32 - 1) + 1) >> 1
    } else if -shift <= mant.leading_zeros() as i64 {
        mant << -shift
    } else {
        u64::MAX
    }
}

/// `x^p` for `x` ≥ 0 in Q2.30 (so below 4) and `p` ≥ 0 in Q32.32, as Q2.30
/// in a `u64`, saturating at 2^10. `0^0` is 1.
pub fn pow_q30(x: u32, p: i64) -> u64 {
    if p <= 0 {
        return 1 << 30;
    }
    if x == 0 {
        return 0;
    }
    // log2 x lies in [−30, 2): in Q8.24 it fits an i32, and y = p · log2 x
    // is formed from 32×32 products only (p's whole part, then its
    // fraction's two halves): 64-bit products are library calls on a
    // Cortex-M0.
    let l = (log2_q32(x as u64, 30) >> 8) as i32;
    let y = if p & 0xffff_ffff == 0 {
        // A whole exponent (the usual Phong power): the fraction's two
        // products are zero.
        mul_wide(l, (p >> 32).min(i32::MAX as i64) as i32)
    } else {
        exponent_times_log(p, l)
    }; // Q40.24
    if y < -(40 << 24) {
        return 0;
    }
    if y > 10 << 24 {
        return 1 << 40;
    }
    (exp2_q32(y << 8) + 2) >> 2
}

/// `p · l` in Q40.24 for `p` ≥ 0 in Q32.32 and `l` in Q8.24, from 32×32
/// products: p's whole part, then its fraction's two halves.
#[inline]
fn exponent_times_log(p: i64, l: i32) -> i64 {
    let whole = (p >> 32).min(i32::MAX as i64) as i32;
    let (f_high, f_low) = (((p >> 16) & 0xffff) as i32, (p & 0xffff) as i32);
    mul_wide(l, whole) + (mul_wide(l, f_high) >> 16) + (mul_wide(l, f_low) >> 32)
}

/// `x^p` for `x` in [0, 1] given in Q2.30 (values outside are clamped) and
/// `p` ≥ 0 in Q32.32; result in Q2.30. `0^0` is 1, as the shading model's
/// constant specular term needs.
pub fn pow_unit(x: i32, p: i64) -> i32 {
    pow_q30(x.clamp(0, 1 << 30) as u32, p).min(1 << 30) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_exponents_skip_only_zero_products() {
        for whole in [0i64, 1, 2, 5, 10, 60, 120, 1000, i32::MAX as i64, 1 << 40] {
            let p = whole << 32;
            for l in [0, 1, -1, -(30 << 24), -(1 << 29), (2 << 24) - 1, i32::MIN, i32::MAX] {
                assert_eq!(mul_wide(l, (p >> 32).min(i32::MAX as i64) as i32), exponent_times_log(p, l), "{whole} {l}");
            }
        }
    }

    #[test]
    fn shifts_in_halves_are_the_plain_shifts() {
        let mut x = 0x0bad_5eed_1234_5678u64;
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let raw = (x >> (x % 64)).max(1);
            let top = 63 - raw.leading_zeros();
            let up = 63 - top;
            let m = if up >= 32 { (((raw as u32) << (up - 32)) as u64) << 32 } else { super::super::shl_u64(raw, up) };
            assert_eq!(m, raw << up, "{raw}");
            let mant = x >> 1;
            for shift in 1..64 {
                let rounded = (super::super::shr_u64(mant, shift - 1) + 1) >> 1;
                assert_eq!(rounded, (mant + (1 << (shift - 1))) >> shift, "{mant} {shift}");
            }
        }
    }

    #[test]
    fn table_end_points_are_exact() {
        assert_eq!(LOG2_TABLE[0], 0);
        assert_eq!(LOG2_TABLE[128], 2_512_394_810); // log2(1.5) * 2^32, rounded
        assert_eq!((EXP2_TABLE[128] + (1 << 29)) >> 30, 6_074_001_000); // sqrt(2) * 2^32
    }

    #[test]
    fn log2_of_powers_of_two_is_exact() {
        for k in 0..60u32 {
            assert_eq!(log2_q32(1 << k, 16), ((k as i64) - 16) << 32);
        }
        assert_eq!(log2_q32(0, 0), i64::MIN);
    }

    #[test]
    fn exp2_of_integers_is_exact() {
        for k in -31..31i64 {
            let expect = if k >= -32 { 1u64 << (32 + k) } else { 0 };
            assert_eq!(exp2_q32(k << 32), expect, "2^{k}");
        }
        assert_eq!(exp2_q32(-(40 << 32)), 0);
        assert_eq!(exp2_q32(40 << 32), u64::MAX);
    }

    #[test]
    fn exp2_inverts_log2() {
        for raw in [1u64, 3, 1000, 65_535, 65_536, 99_999, 1 << 40] {
            let back = exp2_q32(log2_q32(raw, 16)) as i128; // Q32
            let want = (raw as i128) << 16;
            assert!((back - want).abs() * 100_000 <= want + 100_000, "{raw}: {back} vs {want}");
        }
    }

    #[test]
    fn pow_unit_special_cases() {
        let one = 1 << 30;
        let sixteen = 16 << 32;
        assert_eq!(pow_unit(one, sixteen), one);
        assert_eq!(pow_unit(0, sixteen), 0);
        assert_eq!(pow_unit(0, 0), one);
        assert_eq!(pow_unit(one / 2, 0), one);
        let quarter = pow_unit(one / 2, 2 << 32);
        assert!((quarter - one / 4).abs() < 64, "{quarter}");
    }
}
