//! The map from world units (as written in the scene, up to ±1e6) to the
//! normalised space the tracer works in.
//!
//! A scene is translated to the centre of everything that matters (objects,
//! eye, lights) and scaled by a power of two so that all of it lies within
//! ±2^13 ([`crate::math::SCENE_RANGE_LOG2`]). The scale is exact (a shift) and
//! is as large as the range allows, so a scene at 1e-3 and the same scene at
//! 1e5 become the same numbers, and Q16.16 always has about 2^29 steps across
//! the scene. Only the light fall-off needs world distances back:
//! [`Normalization::world_distance_q32`].

use crate::math::{leading_zeros, shl_u64, shr_u64, Scalar, Vec3, SCENE_RANGE_LOG2};

/// A world value in Q32.32 (as the parser reads numbers).
pub type WorldValue = i64;
/// A world point in Q32.32.
pub type WorldPoint = [i64; 3];

/// `normalised = (world − center) · 2^shift`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Normalization {
    /// The world point that maps to the origin.
    pub center: WorldPoint,
    /// The power of two world units are scaled by.
    pub shift: i32,
}

/// Scale limits: a scene of a single point still gets a finite scale.
const MAX_SHIFT: i32 = 40;
const MIN_SHIFT: i32 = -24;

/// Shifts `v` right by `s` with rounding half away from zero, so that a scene
/// symmetric about its centre stays symmetric.
#[inline]
fn round_shift(v: i64, s: u32) -> i64 {
    if s == 0 {
        return v;
    }
    let m = v.unsigned_abs();
    let r = ((m >> (s - 1)) + 1) >> 1;
    if v < 0 {
        -(r as i64)
    } else {
        r as i64
    }
}

impl Normalization {
    /// World space as is (centre 0, Q32.32 to Q16.16).
    pub const IDENTITY: Normalization = Normalization { center: [0; 3], shift: 16 };
    /// An empty scene's, before loading: zero bits (see [`super::Scene::new`]).
    pub(crate) const UNLOADED: Normalization = Normalization { center: [0; 3], shift: 0 };

    /// The normalisation that fits the world box `[min, max]`.
    pub fn fit(min: WorldPoint, max: WorldPoint) -> Normalization {
        let center = [0, 1, 2].map(|a| min[a] / 2 + max[a] / 2 + (min[a] % 2 + max[a] % 2) / 2);
        let half = (0..3).map(|a| (max[a] - center[a]).max(center[a] - min[a]).unsigned_abs()).max().unwrap_or(0);
        // Largest shift with half · 2^shift ≤ 2^13 in Q32.32, i.e. ≤ 2^45 raw.
        let shift = if half == 0 {
            MAX_SHIFT
        } else {
            (45 - (64 - (half - 1).leading_zeros() as i32)).clamp(MIN_SHIFT, MAX_SHIFT)
        };
        Normalization { center, shift }
    }

    /// A world length (no translation) in normalised Q16.16 units, as `i64`
    /// (may exceed the Q16.16 range for lengths larger than the scene).
    #[inline]
    pub fn length_wide(&self, w: WorldValue) -> i64 {
        // world Q32 → normalised Q16: multiply by 2^(shift − 16).
        let s = self.shift - 16;
        if s >= 0 {
            w.saturating_mul(1 << s)
        } else {
            round_shift(w, (-s) as u32)
        }
    }

    /// A world length inside the scene's extent, as normalised Q16.16.
    #[inline]
    pub fn length(&self, w: WorldValue) -> Scalar {
        Scalar::from_bits(self.length_wide(w).clamp(i32::MIN as i64, i32::MAX as i64) as i32)
    }

    /// A world point inside the fitted box, in normalised space.
    pub fn point(&self, w: WorldPoint) -> Vec3 {
        Vec3::from_bits([0, 1, 2].map(|a| {
            let v = self.length_wide(w[a] - self.center[a]);
            v.clamp(i32::MIN as i64, i32::MAX as i64) as i32
        }))
    }

    /// A world point displaced by `offset` (normalised Q16.16 units): the
    /// displacement is added after the point is normalised, so that every
    /// point of a moved object moves by the same bits. Within the fitted
    /// box the sum is in range even where the point alone is not.
    pub(crate) fn moved(&self, w: WorldPoint, offset: [i64; 3]) -> Vec3 {
        Vec3::from_bits([0, 1, 2].map(|a| {
            let v = self.length_wide(w[a] - self.center[a]).saturating_add(offset[a]);
            v.clamp(i32::MIN as i64, i32::MAX as i64) as i32
        }))
    }

    /// A normalised distance (Q16.16 raw, ≥ 0) back in world units, Q32.32.
    #[inline]
    pub fn world_distance_q32(&self, d: i64) -> i64 {
        let s = 16 - self.shift;
        // Shifts, not multiplies, and in 32-bit halves for a distance (not
        // negative): 64-bit products and variable 64-bit shifts are library
        // calls on a Cortex-M0.
        if s >= 0 {
            let s = s.min(62) as u32;
            if d < 0 {
                d << s
            } else if leading_zeros(d as u64) <= s {
                // d · 2^s would pass i64::MAX.
                i64::MAX
            } else if s >= 32 {
                ((((d as u32) << (s - 32)) as u64) << 32) as i64
            } else {
                shl_u64(d as u64, s) as i64
            }
        } else if d >= 0 {
            shr_u64(d as u64, (-s).min(63) as u32) as i64
        } else {
            d >> (-s).min(63)
        }
    }

    /// Whether a normalised point lies within the range the tracer supports.
    pub fn in_range(p: Vec3) -> bool {
        let limit = ((1i64 << SCENE_RANGE_LOG2) + 1) << 16;
        p.wide().iter().all(|c| c.abs() <= limit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn world_distances_shift_as_the_plain_forms_do() {
        let plain = |shift: i32, d: i64| {
            let s = 16 - shift;
            if s >= 0 {
                let s = s.min(62);
                if d > i64::MAX >> s {
                    i64::MAX
                } else {
                    d << s
                }
            } else {
                d >> (-s).min(63)
            }
        };
        let mut x = 0x1234_5678_9abc_def1u64;
        for shift in -80..80 {
            let norm = Normalization { center: [0; 3], shift };
            for i in 0..400 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let d = match i % 4 {
                    0 => (x >> (x % 64)) as i64,
                    1 => (x as i64) >> (x % 64),
                    2 => [0, 1, i64::MAX, i64::MIN, 1 << 31, (1 << 32) - 1][i / 4 % 6],
                    _ => (x >> 33) as i64,
                };
                assert_eq!(norm.world_distance_q32(d), plain(shift, d), "shift {shift}, d {d}");
            }
        }
    }

    const ONE: i64 = 1 << 32;

    #[test]
    fn fits_the_box_within_the_range() {
        for half in [ONE / 1000, ONE, 37 * ONE, 1_000_000 * ONE] {
            let n = Normalization::fit([-half, 0, 5 * ONE], [half, half, 5 * ONE]);
            for p in [[-half, 0, 5 * ONE], [half, half, 5 * ONE]] {
                let q = n.point(p);
                assert!(Normalization::in_range(q), "{half}: {q:?}");
            }
            // As large as the range allows: more than half of it is used.
            let q = n.point([half, 0, 5 * ONE]);
            assert!(q.x.to_bits() as i64 > (1 << 28), "{half}: {q:?}");
        }
    }

    #[test]
    fn scaled_scenes_normalise_to_the_same_numbers() {
        // The same scene at unit scale and at 1024 times: identical.
        let a = Normalization::fit([-3 * ONE, -ONE, 0], [5 * ONE, ONE, 2 * ONE]);
        let b = Normalization::fit([-3 * ONE * 1024, -ONE * 1024, 0], [5 * ONE * 1024, ONE * 1024, 2 * ONE * 1024]);
        assert_eq!(a.shift, b.shift + 10);
        assert_eq!(a.point([ONE, ONE / 2, ONE]), b.point([ONE * 1024, ONE * 512, ONE * 1024]));
        assert_eq!(a.length(3 * ONE), b.length(3 * ONE * 1024));
    }

    #[test]
    fn world_distance_round_trips() {
        let n = Normalization::fit([-10 * ONE; 3], [10 * ONE; 3]);
        let d = n.length(7 * ONE);
        let back = n.world_distance_q32(d.to_bits() as i64);
        assert!((back - 7 * ONE).abs() < ONE >> 20, "{back}");
    }

    #[test]
    fn symmetric_rounding() {
        let n = Normalization::fit([-ONE; 3], [ONE; 3]);
        let p = n.point([ONE / 3, -ONE / 3, 0]);
        assert_eq!(p.x, -p.y);
    }

    #[test]
    fn a_single_point_scene_is_finite() {
        let n = Normalization::fit([ONE; 3], [ONE; 3]);
        assert_eq!(n.point([ONE; 3]), Vec3::ZERO);
    }
}
