//! Exact division without a divide instruction: a reciprocal from a table
//! and one Newton step, then a remainder fix-up. The same bits as the
//! native division on every target; and the reciprocal alone, for the
//! 3DDDA.

use super::super::ARMV6M;
use super::bits::{leading_zeros_u32, shl_u64};
use super::product::mul_u32_wide;

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

/// About 2^63 / (d · 2^shift) and the `shift` that puts `d · 2^shift` in
/// [2^31, 2^32), for `d > 0` (0 is taken as 1): a reciprocal to 31 bits from
/// the table and one Newton step, without a division, the same bits on
/// every target (the 3DDDA's, which only needs it within a bound). It lies
/// within (−1.07, 1] of the exact quotient: checked once for every one of
/// the 2^31 normalised divisors; the test below samples them.
#[inline]
pub(crate) fn reciprocal_estimate(d: u32) -> (u32, u32) {
    let reciprocal = Reciprocal::of(d.max(1));
    (reciprocal.r, reciprocal.shift)
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

/// About 2^63 / `dn` for `dn` in [2^31, 2^32), to some 17 bits: the table,
/// interpolated (1/x is within 2^-18 of its chord over an interval). Its
/// terms stay in a u32: neighbours differ by less than 2^24.
#[inline(always)]
pub(crate) fn reciprocal_start(dn: u32) -> u32 {
    let i = ((dn >> 23) & 0xff) as usize;
    let (lo, hi) = (RECIPROCAL_TABLE[i], RECIPROCAL_TABLE[i + 1]);
    lo - ((((lo - hi) >> 9) * ((dn >> 7) & 0xffff)) >> 7)
}

/// `⌊n / d⌋` for `0 < d` and `n < d · 2^32`, from a reciprocal.
#[inline]
fn div_by_reciprocal(n: u64, d: u32) -> u32 {
    Reciprocal::of(d).quotient(n)
}

/// A divisor made ready for exact division by products: normalised, with
/// its reciprocal from the table and one Newton step.
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
        // r ≈ 2^63 / dn: about 17 bits from the table, then about 31 after
        // one Newton step r' = r + r·(2^63 − dn·r)/2^63.
        let r = reciprocal_start(dn);
        let error = ((1u64 << 63).wrapping_sub(mul_u32_wide(dn, r)) as i64 >> 31) as i32;
        let step = (mul_u32_wide(r, error.unsigned_abs()) >> 32) as u32;
        let r = if error >= 0 { r.saturating_add(step) } else { r - step };
        Reciprocal { divisor: d, shift, r }
    }

    /// `⌊n / divisor⌋` for `n < divisor · 2^32`: the estimate from the
    /// reciprocal is a few off at most, then stepped on the remainder.
    #[inline(always)]
    fn quotient(&self, n: u64) -> u32 {
        let (r, d) = (self.r, self.divisor);
        let numerator = shl_u64(n, self.shift); // below dn · 2^32
        let (high, low) = ((numerator >> 32) as u32, numerator as u32);
        let estimate = (mul_u32_wide(high, r) + (mul_u32_wide(low, r) >> 32)) >> 31;
        let mut q = estimate.min(u32::MAX as u64) as u32;
        let mut remainder = n.wrapping_sub(mul_u32_wide(q, d)) as i64;
        while remainder < 0 {
            q -= 1;
            remainder += d as i64;
        }
        while remainder >= d as i64 {
            q += 1;
            remainder -= d as i64;
        }
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::wide::tests::spread;

    #[test]
    fn reciprocal_estimates_are_within_their_bound() {
        // r − 2^63/dn in (−1.07, 1], told exactly: r·dn − 2^63 in
        // (−1.07·dn, dn].
        let check = |d: u32| {
            let (r, shift) = reciprocal_estimate(d);
            let dn = (d.max(1) as u64) << shift;
            assert!((1 << 31..1 << 32).contains(&dn), "{d}");
            let off = r as i128 * dn as i128 - (1i128 << 63);
            assert!(off * 100 > -107 * dn as i128 && off <= dn as i128, "{d}: {off}");
        };
        let mut next = crate::test_rng::seeded(0x7ec1_9a0c);
        for d in [0, 1, 2, 3, 1 << 14, (1 << 30) - 1, 1 << 30, (1 << 30) + 1, u32::MAX] {
            check(d);
        }
        for _ in 0..1_000_000 {
            check((next() as u32) >> (next() % 32));
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
}
