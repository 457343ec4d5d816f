//! `SPHERE s radius x y z`.
//!
//! The discriminant is formed as r² − |q|², q the closest approach of the ray
//! to the centre, rather than b² − c: both terms are exact Q32.32 products, so
//! far and small spheres keep their precision (no cancellation of two large,
//! nearly equal numbers).

use super::{Aabb, Leaving, Ray};
use crate::math::{isqrt, mul_wide, Dir, Scalar, Vec3};

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

    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        if leaving == Leaving::Outward {
            return None;
        }
        let oc = ray.origin - self.center;
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

    /// Outward unit normal at `p`.
    pub fn normal_at(&self, p: Vec3) -> Dir {
        (p - self.center).direction().unwrap_or(Dir::Y)
    }

    pub fn bounds(&self) -> Aabb {
        let r = Vec3 { x: self.radius, y: self.radius, z: self.radius };
        Aabb { min: self.center - r, max: self.center + r }
    }
}

#[cfg(test)]
mod tests {
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
}
