//! A triangle of a `BSPLINE` patch: flat for the hit test, with the
//! surface's own normals at its corners for shading (the normal at a hit is
//! interpolated across the triangle).
//!
//! Interpolated normals bend light around the flat facets, so near the edge
//! of the shadow a point whose normal faces the light can sit on a facet the
//! neighbouring facets hide: black speckles along the shadow line (the
//! "shadow terminator"). Shadow rays therefore leave from the point lifted
//! onto the smooth surface the normals describe: each corner's tangent plane
//! gives one projection of the hit point, and their barycentric blend is used
//! when it lies on the side the surface is seen from (Hanika, "Hacking the
//! Shadow Terminator", 2021).

use super::triangle::Triangle;
use super::{Aabb, Leaving, Ray, Shape};
use crate::math::{div_saturating, leading_zeros, Dir, Scalar, Vec3};

/// One triangle of a BSPLINE patch, with corner normals to shade smoothly.
// Public only for `profile!` (arenas of it) and the firmware's RAM
// estimate; its geometry is the core's own business.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SmoothTriangle {
    pub triangle: Triangle,
    /// Unit normals at the corners, on the side of the triangle's front
    /// normal.
    pub normals: [Dir; 3],
    /// The object id of its patch's first triangle: the patch is one object
    /// as the scene file wrote it (set when the patch is stored).
    pub patch: u32,
}

impl SmoothTriangle {
    /// `None` when the corners are collinear. A missing corner normal (the
    /// surface had none there) is the face normal; one pointing to the back
    /// is turned to the front, so that blending never cancels out.
    pub fn new(corners: [Vec3; 3], normals: [Option<Dir>; 3], surface: u16) -> Option<SmoothTriangle> {
        let triangle = Triangle::new(corners, surface)?;
        let face = triangle.normal();
        let normals = normals.map(|n| match n {
            Some(n) if !n.dot_is_negative(face) => n,
            Some(n) => -n,
            None => face,
        });
        Some(SmoothTriangle { triangle, normals, patch: 0 })
    }

    /// The flat (geometric) normal.
    pub fn normal(&self) -> Dir {
        self.triangle.normal()
    }

    /// Barycentric weights of `p` (on the plane) in Q2.30, summing to 2^30
    /// within rounding; clamped to the triangle.
    fn weights(&self, p: Vec3) -> [u64; 3] {
        let e = self.triangle.polygon.edge_values(p).map(|v| v.max(0) as u64);
        // Edge i is opposite corner i + 2.
        let corner = [e[1], e[2], e[0]];
        let total = corner[0] + corner[1] + corner[2];
        if total == 0 {
            return [1 << 30, 0, 0];
        }
        // A common shift brings the total below 2^32 for the division.
        let shift = 32u32.saturating_sub(leading_zeros(total));
        let divisor = (total >> shift).max(1) as u32;
        corner.map(|c| div_saturating((c >> shift) << 30, divisor) as u64)
    }

    /// The normal to shade `p` with, on the side of `facing` (the flat
    /// normal as the tracer turned it towards the ray).
    pub fn shading_normal(&self, p: Vec3, facing: Dir) -> Dir {
        let w = self.weights(p);
        let n = [0, 1, 2].map(|a| (0..3).map(|i| w[i] as i64 * self.normals[i].wide()[a]).sum::<i64>());
        let n = Dir::normalize(n).unwrap_or(self.normal());
        if facing.dot_is_negative(self.normal()) {
            -n
        } else {
            n
        }
    }

    /// Where shadow rays from `p` leave: `p` lifted onto the smooth surface
    /// when that moves it towards `facing`, else `p`.
    pub fn shadow_origin(&self, p: Vec3, facing: Dir) -> Vec3 {
        let w = self.weights(p);
        let corners = self.triangle.polygon.corners;
        let mut lifted = [0i64; 3];
        for i in 0..3 {
            // The projection of p onto corner i's tangent plane.
            let n = self.normals[i];
            let on_plane = p - n.scale((p - corners[i]).dot_dir(n));
            for (sum, c) in lifted.iter_mut().zip(on_plane.wide()) {
                *sum += w[i] as i64 * c;
            }
        }
        let lifted = Vec3::from_bits(lifted.map(|c| (c >> 30) as i32));
        if (lifted - p).dot_dir(facing).to_bits() > 0 {
            lifted
        } else {
            p
        }
    }
}

impl Shape for SmoothTriangle {
    const FLAT: bool = true;

    #[inline]
    fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        self.triangle.intersect(ray, t_max, leaving)
    }

    fn normal_at(&self, _: Vec3) -> Dir {
        self.normal()
    }

    fn bounds(&self) -> Aabb {
        self.triangle.bounds()
    }

    fn surface(&self) -> u16 {
        self.triangle.surface
    }

    fn shading(&self, p: Vec3, facing: Dir) -> (Dir, Vec3) {
        (self.shading_normal(p, facing), self.shadow_origin(p, facing))
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::*;
    use super::*;

    /// A triangle in the plane z = −5 whose corner normals lean outwards,
    /// as on a dome.
    fn dome() -> SmoothTriangle {
        let lean = |x: i64, y: i64| Dir::normalize([x, y, 4]);
        SmoothTriangle::new([p(0, 0, -5), p(4, 0, -5), p(0, 4, -5)], [lean(-1, -1), lean(1, 0), lean(0, 1)], 0).unwrap()
    }

    #[test]
    fn normals_interpolate_and_match_at_the_corners() {
        let t = dome();
        assert_eq!(t.normal(), Dir::Z);
        assert_eq!(t.shading_normal(p(4, 0, -5), Dir::Z), t.normals[1]);
        let centre = t.shading_normal(Vec3::from_bits([87381, 87381, -5 << 16]), Dir::Z);
        assert!(centre.dot(Dir::Z).to_bits() > 1 << 29);
        // Seen from the back, the shading normal turns too.
        assert_eq!(t.shading_normal(p(4, 0, -5), -Dir::Z), -t.normals[1]);
    }

    #[test]
    fn missing_and_backward_normals_fall_back_to_the_front() {
        let t = SmoothTriangle::new([p(0, 0, -5), p(4, 0, -5), p(0, 4, -5)], [None, Some(-Dir::Z), None], 0).unwrap();
        assert_eq!(t.normals, [Dir::Z; 3]);
        assert_eq!(t.shading_normal(p(1, 1, -5), Dir::Z), Dir::Z);
        assert!(SmoothTriangle::new([p(0, 0, 0), p(1, 1, 1), p(2, 2, 2)], [None; 3], 0).is_none());
    }

    #[test]
    fn shadow_rays_leave_from_the_smooth_surface() {
        let t = dome();
        let inside = p(1, 1, -5);
        let lifted = t.shadow_origin(inside, Dir::Z);
        assert!(lifted.z > inside.z, "{lifted:?}");
        assert!((lifted.x - inside.x).abs() < Scalar::from_num(0.5));
        // From the back the surface is concave: the point stays.
        assert_eq!(t.shadow_origin(inside, -Dir::Z), inside);
        // Flat normals: no lift.
        let flat = SmoothTriangle::new([p(0, 0, -5), p(4, 0, -5), p(0, 4, -5)], [None; 3], 0).unwrap();
        assert_eq!(flat.shadow_origin(inside, Dir::Z), inside);
    }
}
