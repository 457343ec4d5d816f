//! Wide arithmetic, cheap on every target, one file per operation:
//! [`product`]s, [`bits`] (leading zeros and shifts), [`division`] and
//! square [`root`]s.
//!
//! Invariant: every function returns the same bits on every target. On
//! ARMv6-M (Cortex-M0: a 32×32→32 multiply only, no count of leading zeros,
//! no divide) each takes a part-wise form instead of the library's 64-bit
//! routines; the tests check each part-wise form against the native
//! operation on the host.

mod bits;
mod division;
mod product;
mod root;

pub use bits::{leading_zeros, leading_zeros_u32};
pub(crate) use bits::{shl_u64, shr_saturating_u32, shr_signed_to_u32, shr_u64};
pub use division::div_saturating;
pub(crate) use division::{reciprocal_estimate, reciprocal_start};
pub use product::{mul_i64_i32, mul_i64_i32_wide, mul_i64_wide, mul_u32_wide, mul_wide, square_u32_wide, square_wide};
pub(crate) use product::{mul_u64_shr24, mul_u64_shr24_clamped};
pub use root::{isqrt, isqrt_u128};
pub(crate) use root::{sqrt_and_rsqrt_58_62, sqrt_and_rsqrt_estimates_58_62};

#[cfg(test)]
pub(crate) mod tests {
    /// Repeatable inputs of every magnitude.
    pub(crate) fn spread(count: usize) -> impl Iterator<Item = u64> {
        let mut next = crate::test_rng::seeded(0x9e37_79b9_7f4a_7c15);
        (0..count).map(move |_| {
            let s = next();
            s >> (s % 64)
        })
    }
}
