//! Wide products and square roots, cheap on every target.
//!
//! ARMv6-M (Cortex-M0) has only a 32-bit multiply: a Rust `i64 * i64`
//! becomes a call to a general 64×64 routine. A 32×32→64 product needs only
//! four 16×16 ones, so [`mul_wide`] does that there (and is the plain
//! product elsewhere). Square roots avoid division entirely: Newton's
//! iteration for 1/√x needs only products, from a 192-entry table built at
//! compile time. Every function returns the same bits on every target.

/// `a · b` exactly, for unsigned 32-bit operands.
#[inline(always)]
pub fn mul_u32_wide(a: u32, b: u32) -> u64 {
    #[cfg(all(target_arch = "arm", not(target_feature = "thumb2")))]
    {
        let (al, ah) = (a & 0xffff, a >> 16);
        let (bl, bh) = (b & 0xffff, b >> 16);
        let mid = (al * bh) as u64 + (ah * bl) as u64;
        (((ah * bh) as u64) << 32) + (mid << 16) + (al * bl) as u64
    }
    #[cfg(not(all(target_arch = "arm", not(target_feature = "thumb2"))))]
    {
        a as u64 * b as u64
    }
}

/// `a · b` exactly, for signed 32-bit operands.
#[inline(always)]
pub fn mul_wide(a: i32, b: i32) -> i64 {
    #[cfg(all(target_arch = "arm", not(target_feature = "thumb2")))]
    {
        let m = mul_u32_wide(a.unsigned_abs(), b.unsigned_abs()) as i64;
        if (a ^ b) < 0 {
            -m
        } else {
            m
        }
    }
    #[cfg(not(all(target_arch = "arm", not(target_feature = "thumb2"))))]
    {
        a as i64 * b as i64
    }
}

/// 2^30 / √f at the middle of each of 192 intervals of f = m/256, m from 64
/// to 255: the starting point of Newton's iteration (8 bits right).
static RSQRT_TABLE: [u32; 192] = {
    let mut t = [0u32; 192];
    let mut i = 0;
    while i < 192 {
        // f = (i + 64.5) / 256 = (2i + 129) / 512; 2^30/√f = √(2^60 · 512 / (2i + 129)).
        t[i] = super::isqrt_u128((1u128 << 69) / (2 * i as u128 + 129)) as u32;
        i += 1;
    }
    t
};

/// `1/√x` for `x > 0` as `(g, e)` with `1/√x ≈ g · 2^-e`, `g` in [2^30, 2^31]
/// to about 30 bits.
#[inline]
pub fn rsqrt(x: u64) -> (u32, i32) {
    // x = f · 2^shift with f in [2^30, 2^32) and an even shift, so that
    // 1/√x = (1/√(f / 2^32)) · 2^-(16 + shift/2).
    let bits = 64 - x.leading_zeros() as i32;
    let shift = (bits - 31) & !1;
    let f = if shift >= 0 { (x >> shift) as u32 } else { (x << -shift) as u32 };
    let mut g = RSQRT_TABLE[((f >> 24) - 64) as usize]; // Q2.30
    for _ in 0..2 {
        // g' = g (3 − f g²) / 2; g² in Q3.29 and f·g² in Q2.30 stay in u32.
        let g2 = (mul_u32_wide(g, g) >> 31) as u32;
        let fg2 = (mul_u32_wide(f, g2) >> 31) as u32;
        let t = (3u32 << 30).wrapping_sub(fg2);
        g = (mul_u32_wide(g, t) >> 31) as u32;
    }
    (g, 46 + shift / 2)
}

/// Floor of the square root of a `u64`, without division.
#[inline]
pub fn isqrt(n: u64) -> u64 {
    if n < 2 {
        return n;
    }
    let (g, e) = rsqrt(n);
    isqrt_from(n, g, e)
}

/// ⌊√n⌋ given `1/√n ≈ g · 2^-e` from [`rsqrt`] (`n ≥ 2`).
#[inline]
pub fn isqrt_from(n: u64, g: u32, e: i32) -> u64 {
    // √n = n · (1/√n), from the top 32 bits of n, then corrected to the
    // exact floor (at most a couple of steps).
    let bits = 64 - n.leading_zeros() as i32;
    let drop = (bits - 32).max(0);
    let top = (n >> drop) as u32;
    let mut s = mul_u32_wide(top, g) >> (e - drop).clamp(0, 63);
    // √n < 2^32: anything at or above it squares past every u64.
    let fits = |s: u64| s < 1 << 32 && mul_u32_wide(s as u32, s as u32) <= n;
    while s > 0 && !fits(s) {
        s -= 1;
    }
    while fits(s + 1) {
        s += 1;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift, for repeatable spreads of inputs.
    fn spread(count: usize) -> impl Iterator<Item = u64> {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        (0..count).map(move |_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s >> (s % 64)
        })
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
