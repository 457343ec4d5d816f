//! Fixed-point numbers and vectors: the only arithmetic the tracer does per ray.
//!
//! Invariants:
//! - A loaded scene lives in *normalised* space (see [`crate::scene::Normalization`]):
//!   every point the tracer meets has coordinates within ±2^13 = ±8192, so a
//!   difference of two points is within ±2^14 per axis and any distance along
//!   a ray is below 2^15. [`Scalar`] (Q16.16) holds all of them.
//! - Directions are unit vectors in Q2.30 ([`Dir`]); a product of a Q16.16
//!   component and a Q2.30 component fits an `i64` with room for a sum of three.
//! - Products are computed exactly in `i64` and rounded by an arithmetic shift,
//!   so every result is the same bits on every target.
//! - No function here panics on any input except through an overflow that the
//!   invariants above rule out; debug builds (and the test suite) check that.

mod exp_log;
mod vector;
mod wide;

pub(crate) use exp_log::{pow_q30, pow_unit};
pub use vector::{Dir, Vec3};
pub(crate) use wide::{
    div_saturating, isqrt, isqrt_u128, leading_zeros, leading_zeros_u32, mul_i64_i32, mul_i64_i32_wide, mul_i64_wide,
    mul_u32_wide, mul_wide, sqrt_and_rsqrt_58_62, sqrt_and_rsqrt_estimates_58_62, square_u32_wide, square_wide,
};

/// Whether this build is for ARMv6-M (Cortex-M0 and M0+), which has only a
/// 32×32→32 multiply and no count of leading zeros: there the core takes
/// part-wise forms of its products where they are cheaper; every form gives
/// the same bits, and the tests check the part-wise ones on the host.
///
/// Told apart by its atomics: of Rust's Arm targets, ARMv6-M's alone has
/// no 32-bit compare-and-swap (no LDREX/STREX), where the Cortex-M3, M4 and
/// M33 (ARMv7-M, ARMv8-M Mainline, with `umull` and `clz`) have it. (Stable
/// Rust reports no Arm target feature to `cfg`: `target_feature =
/// "thumb2"` was never set, so every Arm build took the ARMv6-M forms.)
/// ARMv8-M Baseline (Cortex-M23) lacks the long multiply too but has the
/// atomics: it takes the general forms.
pub(crate) const ARMV6M: bool = cfg!(all(target_arch = "arm", not(target_has_atomic = "32")));

/// On ARMv6-M, `part_wise()` when it decides the result; else, and on other
/// targets, `exact()`: the one shape of every "cheaper form when it can"
/// choice above.
#[inline(always)]
pub(crate) fn part_wise_or<T>(part_wise: impl FnOnce() -> Option<T>, exact: impl FnOnce() -> T) -> T {
    match ARMV6M.then(part_wise).flatten() {
        Some(value) => value,
        None => exact(),
    }
}

pub(crate) use wide::{
    mul_u64_shr24, mul_u64_shr24_clamped, reciprocal_estimate, reciprocal_start, shl_u64, shr_saturating_u32,
    shr_signed_to_u32, shr_u64,
};

pub use fixed::types::{I16F16, I2F30, I32F32};

/// Positions, lengths, ray parameters and colours: Q16.16.
pub type Scalar = I16F16;
/// Components of unit vectors and cosines: Q2.30.
pub type Unit = I2F30;
/// Wide values (world coordinates as parsed, products of two [`Scalar`]s): Q32.32.
pub type Wide = I32F32;

/// Normalised scene coordinates lie within ±2^`SCENE_RANGE_LOG2`.
pub const SCENE_RANGE_LOG2: u32 = 13;

/// One in Q2.30.
pub const UNIT_ONE: i64 = 1 << 30;
