//! `SPHERE s radius x y z`.
//!
//! The discriminant is formed as r² − |q|², q the closest approach of the ray
//! to the centre, rather than b² − c: both terms are exact Q32.32 products, so
//! far and small spheres keep their precision (no cancellation of two large,
//! nearly equal numbers).

use super::{Aabb, Leaving, Ray, Shape};
use crate::math::{isqrt, mul_wide, Dir, Scalar, Vec3};

/// How far the estimate of `b = oc·dir` in [`surely_missed`] may be from the
/// exact one, in Q16.16 raw units (8 units of the ±8192 scene): within
/// 4·Σ(|oc_i/2^17| + |dir_i/2^15| + 1) + 1 for the products dropped.
const DOT_ERROR: i64 = 1 << 19;
/// How far its estimate of the closest approach `q = oc − b·dir` may be off
/// per axis: `DOT_ERROR` plus what the second set of short products drops.
const OFFSET_ERROR: i64 = 1 << 20;

/// A SPHERE: centre and radius in normalised space.
// Public only for `profile!` (arenas of it) and the firmware's RAM
// estimate; its geometry is the core's own business.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sphere {
    pub center: Vec3,
    pub radius: Scalar,
    /// Index of the surface in the scene's surface table.
    pub surface: u16,
}

impl Sphere {
    pub fn new(center: Vec3, radius: Scalar, surface: u16) -> Sphere {
        Sphere { center, radius, surface }
    }

    /// The exact test, given `oc = origin − center`. Not inlined: most
    /// tests end in [`surely_missed`], and the exact one's frame (a
    /// Cortex-M0 spills its 64-bit products) then costs only the rays that
    /// come near.
    #[inline(never)]
    fn intersect_exactly(&self, oc: Vec3, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        let b = oc.dot_dir(ray.dir); // the centre lies at parameter −b
        let r = self.radius.to_bits() as i64;
        // Entirely beyond t_max (or behind): the nearest point of the sphere
        // along the ray is at −b − r.
        let center_t = -(b.to_bits() as i64);
        if center_t - r > t_max.to_bits() as i64 || center_t + r <= 0 {
            return None;
        }
        let q = oc - ray.dir.scale(b);
        // Most rays pass wide of a sphere: one coordinate of q beyond the
        // radius settles it without the squares.
        if q.bits().iter().any(|c| c.unsigned_abs() as i64 > r) {
            return None;
        }
        let disc = mul_wide(r as i32, r as i32) - q.length_squared_q32();
        if disc < 0 {
            return None;
        }
        let h = isqrt(disc as u64) as i64;
        let near = center_t - h;
        let far = center_t + h;
        let t = if leaving == Leaving::No && near > 0 { near } else { far };
        (t > 0 && t <= t_max.to_bits() as i64).then(|| Scalar::from_bits(t as i32))
    }
}

impl Shape for Sphere {
    const FLAT: bool = false;

    // Not inlined: in the object loops' frames its registers would spill
    // (measured on a Cortex-M0); its own frame is small, the exact test's
    // kept apart.
    #[inline(never)]
    fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        if leaving == Leaving::Outward {
            return None;
        }
        let oc = ray.origin - self.center;
        if surely_missed(oc.bits(), ray.dir.bits(), t_max.to_bits(), self.radius.to_bits()) {
            return None;
        }
        self.intersect_exactly(oc, ray, t_max, leaving)
    }

    /// Outward unit normal at `p`.
    fn normal_at(&self, p: Vec3) -> Dir {
        (p - self.center).direction().unwrap_or(Dir::Y)
    }

    fn bounds(&self) -> Aabb {
        let r = Vec3 { x: self.radius, y: self.radius, z: self.radius };
        Aabb { min: self.center - r, max: self.center + r }
    }

    fn surface(&self) -> u16 {
        self.surface
    }
}

/// True only when the exact test surely finds no hit: the same two rejections
/// (centre's parameter out of reach, closest approach off by more than the
/// radius on one axis), from 32-bit products of the operands' top bits with
/// their error bounds added. Most rays pass wide of a sphere: on a Cortex-M0,
/// which lacks a 32×32→64 multiply, this costs a fraction of the exact path
/// to the same answer; a near ray goes on to the exact test.
///
/// The bounds hold for the normalised space's points (|oc_i| ≤ 2^30) and
/// unit directions (|dir_i| ≤ 2^30 + 2^15), whatever `t_max` and the radius.
/// Every step is a 32-bit one (the estimate of `b` is `4s`, and each
/// comparison of it is divided by four exactly), with the answer of the
/// same comparisons made in 64 bits for any inputs.
#[inline(always)]
fn surely_missed(oc: [i32; 3], dir: [i32; 3], t_max: i32, radius: i32) -> bool {
    // oc_i·dir_i = (oc_i >> 17)(dir_i >> 15)·2^32 + what the low bits add;
    // each short product is below 2^28 in magnitude, their sum `s` below
    // 2^30, and `b` within DOT_ERROR of `4s` (Q16.16).
    let short = |a: usize| (oc[a] >> 17).wrapping_mul(dir[a] >> 15);
    let s = short(0).wrapping_add(short(1)).wrapping_add(short(2));
    // The centre lies at parameter −b: out of reach when −4s − DOT_ERROR −
    // radius > t_max, that is −s > ⌊(t_max + DOT_ERROR + radius)/4⌋; behind
    // when −4s + DOT_ERROR + radius ≤ 0, that is s ≥ ⌈(DOT_ERROR + radius)/4⌉
    // (DOT_ERROR a multiple of four; the floors of the sums from their
    // parts' floors and remainders, in 32 bits).
    let quarter = DOT_ERROR as i32 >> 2;
    let beyond = (t_max >> 2) + (radius >> 2) + quarter + (((t_max & 3) + (radius & 3)) >> 2);
    let behind = (radius >> 2) + quarter + (((radius & 3) + 3) >> 2);
    if s < -beyond || s >= behind {
        return true;
    }
    // Here |4s| < 2^32 + 2^20, so `b_high` (= ⌊4s / 2^16⌋) is within
    // ±(2^16 + 17), (dir_i >> 16)·b_high within ±(2^30 + 2^18) and q_i's
    // quarter estimate below 2^31: 32-bit steps. q_i = 4·quarter + (oc_i & 3)
    // ± OFFSET_ERROR; `reach` is ⌊(radius + OFFSET_ERROR + 3)/4⌋.
    let b_high = s >> 14;
    let reach = ((radius >> 2) + (((radius & 3) + OFFSET_ERROR as i32 + 3) >> 2)) as u32;
    let quarter = [0, 1, 2].map(|a| ((oc[a] >> 2).wrapping_sub((dir[a] >> 16).wrapping_mul(b_high))).unsigned_abs());
    if quarter.iter().any(|&q| q > reach) {
        return true;
    }
    // Within the radius on every axis, but maybe not within the sphere:
    // |q_i| ≥ 4·|quarter_i| − 3 − OFFSET_ERROR ≥ 4·v_i, v_i = |quarter_i| −
    // 2^18 − 1 (when positive), so |q|² ≥ 2^32·Σ c_i² with c_i = ⌊v_i/2^14⌋;
    // that is above r² once Σ c_i² ≥ (⌊r/2^16⌋ + 1)², and the exact test's
    // r² − |q|² is then negative (its sums exact for a radius below 2^30).
    // Each c_i is below 2^15 here (v_i ≤ reach), the sums fit a u32.
    if !(0..1 << 30).contains(&radius) {
        return false;
    }
    let c = quarter.map(|q| q.saturating_sub((OFFSET_ERROR as u32 >> 2) + 1) >> 14);
    let r = (radius >> 16) as u32 + 1;
    c[0] * c[0] + c[1] * c[1] + c[2] * c[2] >= r * r
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::super::test_util::*;
    use super::*;

    fn unit_sphere_at(z: i32) -> Sphere {
        Sphere::new(p(0, 0, z), s(1), 0)
    }

    #[test]
    fn hits_front_and_back() {
        let sph = unit_sphere_at(-5);
        let r = ray(p(0, 0, 0), [0, 0, -1]);
        assert_eq!(sph.intersect(&r, far(), Leaving::No), Some(s(4)));
        assert_eq!(sph.intersect(&r, far(), Leaving::Inward), Some(s(6)));
        assert_eq!(sph.intersect(&r, far(), Leaving::Outward), None);
        // t_max cuts it off.
        assert_eq!(sph.intersect(&r, s(3), Leaving::No), None);
        assert_eq!(sph.intersect(&r, s(4), Leaving::No), Some(s(4)));
    }

    #[test]
    fn misses_beside_and_behind() {
        let sph = unit_sphere_at(-5);
        assert_eq!(sph.intersect(&ray(p(2, 0, 0), [0, 0, -1]), far(), Leaving::No), None);
        assert_eq!(sph.intersect(&ray(p(0, 0, 0), [0, 0, 1]), far(), Leaving::No), None);
        assert_eq!(sph.intersect(&ray(p(0, 0, 0), [0, 1, 0]), far(), Leaving::No), None);
    }

    #[test]
    fn from_inside_hits_the_far_side() {
        let sph = Sphere::new(p(0, 0, 0), s(2), 0);
        let r = ray(p(0, 0, 0), [1, 0, 0]);
        assert_eq!(sph.intersect(&r, far(), Leaving::No), Some(s(2)));
    }

    #[test]
    fn grazing_ray_touches() {
        let sph = unit_sphere_at(-5);
        let r = ray(p(1, 0, 0), [0, 0, -1]);
        assert_eq!(sph.intersect(&r, far(), Leaving::No), Some(s(5)));
    }

    #[test]
    fn normal_points_outward() {
        let sph = unit_sphere_at(-5);
        assert_eq!(sph.normal_at(p(0, 0, -4)), Dir::Z);
        assert_eq!(sph.normal_at(p(-1, 0, -5)), -Dir::X);
    }

    #[test]
    fn leaving_inward_from_surface_finds_the_exit() {
        // A ray leaving the near pole into the sphere meets the far pole, not
        // its own starting point, however the start rounds.
        let sph = unit_sphere_at(-5);
        let start = p(0, 0, -4);
        let r = ray(start, [0, 0, -1]);
        assert_eq!(sph.intersect(&r, far(), Leaving::Inward), Some(s(2)));
    }

    #[test]
    fn tiny_and_huge_spheres() {
        let tiny = Sphere::new(p(0, 0, -100), Scalar::from_bits(64), 0);
        let t = tiny.intersect(&ray(p(0, 0, 0), [0, 0, -1]), far(), Leaving::No).unwrap();
        assert_eq!(t.to_bits(), (100 << 16) - 64);
        let huge = Sphere::new(p(0, 0, -8000), s(4000), 0);
        let t = huge.intersect(&ray(p(0, 0, 8000), [0, 0, -1]), far(), Leaving::No).unwrap();
        assert_eq!(t, s(12000));
    }
    #[test]
    fn the_quick_rejection_never_changes_an_answer() {
        // Rays aimed at, beside and far from spheres of every size, at every
        // distance: the answer with the 32-bit pre-test is the exact one.
        let mut next = crate::test_rng::seeded(0x5eed_0f5f_e4e5_u64);
        let coordinate = |next: &mut dyn FnMut() -> u64| ((next() as i32) >> 2) >> (next() % 20);
        let (mut hits, mut near) = (0, 0);
        for i in 0..400_000u32 {
            let center = Vec3::from_bits([0; 3].map(|_| coordinate(&mut next)));
            let radius = Scalar::from_bits(((next() >> 34) as i32 >> (next() % 28)).max(1));
            let sphere = Sphere::new(center, radius, 0);
            let origin = Vec3::from_bits([0; 3].map(|_| coordinate(&mut next)));
            // Aimed within a few radii of the centre, or anywhere.
            let target = if i % 4 == 0 {
                [0; 3].map(|_| next() as i32 as i64 >> 2)
            } else {
                let spread = (radius.to_bits() as i64) << (next() % 4);
                let c = center.wide();
                [0, 1, 2].map(|a| c[a] + ((next() as i64 % (spread + 1)) - spread / 2))
            };
            let o = origin.wide();
            let Some(dir) = Dir::normalize([0, 1, 2].map(|a| target[a] - o[a])) else { continue };
            let ray = Ray { origin, dir };
            let t_max = match next() % 3 {
                0 => Scalar::MAX,
                _ => Scalar::from_bits((next() >> 33) as i32),
            };
            let leaving = if next() % 3 == 0 { Leaving::Inward } else { Leaving::No };
            let exact = sphere.intersect_exactly(origin - center, &ray, t_max, leaving);
            assert_eq!(sphere.intersect(&ray, t_max, leaving), exact, "case {i}: {sphere:?} {ray:?} {t_max:?}");
            hits += exact.is_some() as u32;
            near += (!surely_missed((origin - center).bits(), dir.bits(), t_max.to_bits(), radius.to_bits())) as u32;
        }
        // The cases must include hits and near misses, or the test proves nothing.
        assert!(hits > 20_000 && near > hits, "{hits} hits, {near} near");
    }

    /// The pre-test in 64-bit steps, as it was first written (with the
    /// squared closest approach since): the 32-bit one must answer as it
    /// does for any inputs.
    fn surely_missed_in_64_bits(oc: [i32; 3], dir: [i32; 3], t_max: i64, radius: i64) -> bool {
        let short = |a: usize| (oc[a] >> 17).wrapping_mul(dir[a] >> 15);
        let estimate = 4 * short(0).wrapping_add(short(1)).wrapping_add(short(2)) as i64;
        if -estimate - DOT_ERROR - radius > t_max || -estimate + DOT_ERROR + radius <= 0 {
            return true;
        }
        let b_high = (estimate >> 16) as i32;
        let reach = ((radius + OFFSET_ERROR + 3) >> 2) as u32;
        let quarter =
            [0, 1, 2].map(|a| ((oc[a] >> 2).wrapping_sub((dir[a] >> 16).wrapping_mul(b_high))).unsigned_abs() as i64);
        if quarter.iter().any(|&q| q > reach as i64) {
            return true;
        }
        if !(0..1 << 30).contains(&radius) {
            return false;
        }
        let c = quarter.map(|q| (q - (OFFSET_ERROR >> 2) - 1).max(0) >> 14);
        c.iter().map(|c| c * c).sum::<i64>() >= ((radius >> 16) + 1).pow(2)
    }

    #[test]
    fn the_pre_test_in_32_bits_answers_as_in_64() {
        let mut next = crate::test_rng::seeded(0x32_64_5f);
        let edges = [0, 1, 2, 3, -1, -4, i32::MAX, i32::MIN, i32::MAX - 3, 1 << 30, -(1 << 30), 1 << 29];
        let word = |next: &mut dyn FnMut() -> u64| match next() % 5 {
            0 => edges[(next() % edges.len() as u64) as usize],
            _ => (next() as i32) >> (next() % 32),
        };
        let (mut missed, mut kept) = (0, 0);
        for i in 0..1_000_000 {
            let oc = [0; 3].map(|_| word(&mut next));
            let dir = [0; 3].map(|_| word(&mut next));
            let (t_max, radius) = (word(&mut next), word(&mut next));
            let wide = surely_missed_in_64_bits(oc, dir, t_max as i64, radius as i64);
            assert_eq!(surely_missed(oc, dir, t_max, radius), wide, "case {i}: {oc:?} {dir:?} {t_max} {radius}");
            if wide {
                missed += 1;
            } else {
                kept += 1;
            }
        }
        assert!(missed > 100_000 && kept > 10_000, "{missed} {kept}");
    }
}
