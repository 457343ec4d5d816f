//! `SUPERQUADRIC s power xc yc zc xs ys zs`: the rounded box
//! |x/xs|^p + |y/ys|^p + |z/zs|^p = 1 around the centre, 2 ≤ p ≤ 64.
//!
//! Root finding exploits convexity rather than sampling. The ray is clipped to
//! the bounding box and mapped to the unit cube, where the segment is
//! `x(u) = l0 + u·(l1 − l0)`, `u ∈ [0, 1]`, so every quantity is bounded
//! whatever the shape's size. Along it `f(u) = Σ|x_i|^p` is convex, so:
//! - `f(0) > 1` with `f'(0) ≥ 0` is a proven miss;
//! - Newton's method started outside the shape approaches the first root
//!   monotonically from the left (a tangent of a convex function lies below
//!   it) and can neither overshoot nor skip it;
//! - a Newton iterate where `f > 1` and `f' ≥ 0` proves the minimum is above
//!   1: a miss.
//!
//! Sampling root finders fail exactly where the surface touches its bounding
//! box (the face centres, where for large p the surface is nearly flat and a
//! ray meets it right at the box face); here such a ray has `f(0) ≤ 1` and
//! hits at the box face.

use super::axis_aligned_box::slab_span;
use super::{Aabb, Leaving, Ray, Shape};
use crate::math::{pow_q30, Dir, Scalar, Vec3};

const ONE: i64 = 1 << 30;
/// Newton stops when `f` is within this of 1 (Q2.30): 2^-22.
const CONVERGED: i64 = 1 << 8;
const MAX_ITERATIONS: u32 = 48;

/// A SUPERQUADRIC (a superellipsoid).
// Public only for `profile!` (arenas of it) and the firmware's RAM
// estimate; its geometry is the core's own business.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Superquadric {
    pub center: Vec3,
    pub half: Vec3,
    /// The exponent p, in Q16.16.
    pub power: Scalar,
    pub surface: u16,
}

/// The segment of a ray inside the bounding box, in unit-cube coordinates.
struct Segment {
    t0: i64,
    t1: i64,
    l0: [i64; 3],
    delta: [i64; 3],
}

impl Superquadric {
    pub fn new(center: Vec3, half: Vec3, power: Scalar, surface: u16) -> Superquadric {
        Superquadric { center, half, power, surface }
    }

    /// `p` in unit-cube coordinates (Q2.30).
    fn local(&self, p: Vec3) -> [i64; 3] {
        let c = self.center.wide();
        let h = self.half.wide();
        let p = p.wide();
        [0, 1, 2].map(|i| ((p[i] - c[i]) << 30) / h[i].max(1))
    }

    /// `f(u)` and `f'(u) / p` at the point `x` (Q2.30 both). Coordinates are
    /// clamped to ±1.5 and powers to 2: every point evaluated lies on the
    /// bounding box's segment, so only rounding can push it past ±1.
    fn evaluate(&self, x: [i64; 3], delta: [i64; 3]) -> (i64, i64) {
        let pm1 = ((self.power.to_bits() - (1 << 16)) as i64) << 16;
        let mut f = 0;
        let mut g = 0;
        for i in 0..3 {
            let (a, pow) = clamped_power(x[i], pm1);
            f += (pow * a) >> 30;
            let slope = ((pow >> 2) * delta[i]) >> 28;
            g += if x[i] < 0 { -slope } else { slope };
        }
        (f, g)
    }

    fn point(seg: &Segment, u: i64) -> [i64; 3] {
        [0, 1, 2].map(|i| seg.l0[i] + ((u * seg.delta[i]) >> 30))
    }

    /// Newton's method from `u` towards the root on the side `dir` (+1: the
    /// first root, searching forwards from a point left of it; −1: the last
    /// root, searching backwards). Returns `u` of the root in [0, 1].
    fn newton(&self, seg: &Segment, mut u: i64, dir: i64) -> Option<i64> {
        let p = self.power.to_bits() as i64;
        for _ in 0..MAX_ITERATIONS {
            let (f, g) = self.evaluate(Self::point(seg, u), seg.delta);
            let excess = f - ONE;
            if excess <= CONVERGED {
                return Some(u);
            }
            // f' in the search direction must be negative, else the minimum
            // along the rest of the segment is above 1.
            let slope = ((g * p) >> 16) * dir; // Q2.30
            if slope >= 0 {
                return None;
            }
            // A shorter step than Newton's stays left of the root, so capping
            // the excess keeps the iteration monotone and the shift in range.
            let step = (excess.min(4 * ONE) << 30) / -slope;
            if step == 0 {
                // Converging below the fixed-point resolution: f is within
                // rounding of 1 at a grazing touch.
                return (excess <= CONVERGED << 6).then_some(u);
            }
            u += step * dir;
            if !(0..=ONE).contains(&u) {
                return None;
            }
        }
        None
    }
}

impl Shape for Superquadric {
    const FLAT: bool = false;

    #[inline]
    fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        if leaving == Leaving::Outward {
            return None;
        }
        let span = slab_span(ray, self.center - self.half, self.center + self.half)?;
        let exit = span.exit?;
        if exit.num <= 0 {
            return None;
        }
        let t0 = match span.enter {
            Some(e) if e.num > 0 => {
                if !e.le_scalar(t_max) {
                    return None;
                }
                e.to_scalar()
            }
            _ => Scalar::ZERO,
        };
        let t1 = exit.to_scalar();
        let l0 = self.local(ray.at(t0));
        let l1 = self.local(ray.at(t1));
        let seg =
            Segment { t0: t0.to_bits() as i64, t1: t1.to_bits() as i64, l0, delta: [0, 1, 2].map(|i| l1[i] - l0[i]) };
        let (f0, _) = self.evaluate(seg.l0, seg.delta);
        let starts_inside = f0 <= ONE;
        let u = if leaving == Leaving::No && !starts_inside {
            self.newton(&seg, 0, 1)?
        } else if leaving == Leaving::No && seg.t0 > 0 {
            // Entered the box right where the shape touches it.
            0
        } else {
            self.newton(&seg, ONE, -1)?
        };
        let t = seg.t0 + (((seg.t1 - seg.t0) * u) >> 30);
        // A ray leaving the surface inwards at a grazing angle finds its own
        // starting point as the "far" root: that is not a new hit.
        let min_t = if leaving == Leaving::Inward { 16 } else { 0 };
        (t > min_t && t <= t_max.to_bits() as i64).then(|| Scalar::from_bits(t as i32))
    }

    /// Outward normal: the gradient (sgn(x)|x|^(p−1) / half-size) per axis.
    fn normal_at(&self, p: Vec3) -> Dir {
        let x = self.local(p);
        let h = self.half.wide();
        let h_min = h[0].min(h[1]).min(h[2]).max(1);
        let pm1 = ((self.power.to_bits() - (1 << 16)) as i64) << 16;
        let g = [0, 1, 2].map(|i| {
            let (_, pow) = clamped_power(x[i], pm1);
            // Scaled by h_min / h_i ≤ 1 so that no component overflows.
            let w = (pow * ((h_min << 30) / h[i].max(1))) >> 30;
            if x[i] < 0 {
                -w
            } else {
                w
            }
        });
        Dir::normalize(g).unwrap_or(Dir::Y)
    }

    fn bounds(&self) -> Aabb {
        Aabb { min: self.center - self.half, max: self.center + self.half }
    }

    fn surface(&self) -> u16 {
        self.surface
    }
}

/// `|x|` clamped to 1.5 and `|x|^e` clamped to 2, both Q2.30.
#[inline]
fn clamped_power(x: i64, e: i64) -> (i64, i64) {
    let a = x.unsigned_abs().min(3 << 29);
    (a as i64, pow_q30(a as u32, e).min(2 << 30) as i64)
}

#[cfg(test)]
mod tests {
    use super::super::test_util::*;
    use super::*;
    use crate::shapes::Sphere;

    fn sq(power: Scalar) -> Superquadric {
        Superquadric::new(p(0, 0, -10), p(2, 2, 2), power, 0)
    }

    #[test]
    fn power_two_is_a_sphere() {
        let q = sq(s(2));
        let sphere = Sphere::new(p(0, 0, -10), s(2), 0);
        for k in -20..=20 {
            let r = ray(p(0, 0, 0), [k, 3 * k / 2, -100]);
            let a = q.intersect(&r, far(), Leaving::No);
            let b = sphere.intersect(&r, far(), Leaving::No);
            match (a, b) {
                (Some(a), Some(b)) => assert!((a - b).abs().to_bits() < 64, "k={k}: {a} vs {b}"),
                (None, None) => {}
                _ => panic!("k={k}: {a:?} vs {b:?}"),
            }
        }
    }

    #[test]
    fn face_centre_hit_for_every_power() {
        // The ray down the axis meets the surface exactly at the box face.
        for power in [2, 3, 8, 20, 64] {
            let q = sq(s(power));
            let r = ray(p(0, 0, 0), [0, 0, -1]);
            assert_eq!(q.intersect(&r, far(), Leaving::No), Some(s(8)), "p = {power}");
            assert_eq!(q.intersect(&r, far(), Leaving::Inward), Some(s(12)));
            assert_eq!(q.normal_at(p(0, 0, -8)), Dir::Z);
        }
    }

    #[test]
    fn near_face_centre_with_large_power() {
        // Slightly off the axis and oblique: still hits just behind the face.
        let q = sq(s(64));
        for k in 1..50 {
            let r = ray(p(k, 0, 0), [-(k as i64), 1, -8]);
            let t = q.intersect(&r, far(), Leaving::No).expect("hit");
            let z = r.at(t).z;
            assert!(z <= s(-8) && z > Scalar::from_num(-8.05), "k={k} z={z}");
        }
    }

    #[test]
    fn corner_is_rounded() {
        // Along the diagonal a p = 2 superquadric ends at radius 2, a p = 64
        // one near the box corner.
        let r = ray(p(10, 10, 0), [-1, -1, -1]);
        let d = Scalar::from_num(10.0 * 1.7320508);
        let t2 = sq(s(2)).intersect(&ray(p(10, 10, 0), [-1, -1, -1]), far(), Leaving::No).unwrap();
        assert!((t2 - (d - s(2))).abs() < Scalar::from_num(0.01), "{t2}");
        let t64 = sq(s(64)).intersect(&r, far(), Leaving::No).unwrap();
        let corner = d - Scalar::from_num(2.0 * 1.7320508);
        assert!(t64 > corner && t64 < corner + Scalar::from_num(0.1), "{t64}");
    }

    #[test]
    fn misses_past_the_rounded_corner() {
        // Inside the bounding box's corner region but outside the shape.
        let r = ray(p(0, 0, 0), [19, 19, -100]);
        // Aim just inside the box corner at the near face.
        assert_eq!(sq(s(2)).intersect(&r, far(), Leaving::No), None);
        assert!(sq(s(64)).intersect(&r, far(), Leaving::No).is_some());
    }

    #[test]
    fn non_integer_power_between_neighbours() {
        let r = ray(p(10, 10, 0), [-1, -1, -1]);
        let t3 = sq(s(3)).intersect(&r, far(), Leaving::No).unwrap();
        let t35 = sq(Scalar::from_num(3.5)).intersect(&r, far(), Leaving::No).unwrap();
        let t4 = sq(s(4)).intersect(&r, far(), Leaving::No).unwrap();
        assert!(t3 > t35 && t35 > t4, "{t3} {t35} {t4}");
    }

    #[test]
    fn from_inside_hits_the_wall() {
        let r = ray(p(0, 0, -10), [1, 0, 0]);
        for power in [2, 5, 64] {
            let t = sq(s(power)).intersect(&r, far(), Leaving::No).unwrap();
            assert!((t - s(2)).abs().to_bits() < 32, "{t}");
        }
    }

    #[test]
    fn normals_are_outward() {
        let q = sq(Scalar::from_num(4.5));
        let r = ray(p(10, 10, 0), [-1, -1, -1]);
        let t = q.intersect(&r, far(), Leaving::No).unwrap();
        let n = q.normal_at(r.at(t));
        let b = n.bits();
        assert!(b[0] > 0 && b[1] > 0 && b[2] > 0 && (b[0] - b[1]).abs() < 1 << 12, "{n:?}");
    }
}
