//! `TRIANGLE s x1 y1 z1 x2 y2 z2 x3 y3 z3`: corners counter-clockwise seen
//! from the front, front normal (p2 − p1) × (p3 − p1).

use super::polygon::{cross_of_edges, Flat, Polygon};
use crate::math::Vec3;

/// A TRIANGLE.
pub type Triangle = Flat<3>;

impl Triangle {
    /// `None` when the corners are collinear at this precision.
    pub fn new(corners: [Vec3; 3], surface: u16) -> Option<Triangle> {
        let normal = cross_of_edges(corners[0], corners[1], corners[2]);
        Some(Triangle { polygon: Polygon::with_normal(corners, normal)?, surface })
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::*;
    use super::super::{Leaving, Ray, Shape};
    use super::*;
    use crate::math::{Dir, Scalar};

    fn tri() -> Triangle {
        Triangle::new([p(0, 0, -5), p(4, 0, -5), p(0, 4, -5)], 0).unwrap()
    }

    #[test]
    fn hits_inside_from_both_sides() {
        let t = tri();
        assert_eq!(t.normal(), Dir::Z);
        assert_eq!(t.intersect(&ray(p(1, 1, 0), [0, 0, -1]), far(), Leaving::No), Some(s(5)));
        assert_eq!(t.intersect(&ray(p(1, 1, -10), [0, 0, 1]), far(), Leaving::No), Some(s(5)));
    }

    #[test]
    fn misses_outside_parallel_and_behind() {
        let t = tri();
        assert_eq!(t.intersect(&ray(p(3, 3, 0), [0, 0, -1]), far(), Leaving::No), None);
        assert_eq!(t.intersect(&ray(p(1, 1, 0), [1, 0, 0]), far(), Leaving::No), None);
        assert_eq!(t.intersect(&ray(p(1, 1, 0), [0, 0, 1]), far(), Leaving::No), None);
        assert_eq!(t.intersect(&ray(p(1, 1, 0), [0, 0, -1]), s(4), Leaving::No), None);
    }

    #[test]
    fn edges_count_as_inside_and_leaving_never_rehits() {
        let t = tri();
        assert_eq!(t.intersect(&ray(p(2, 2, 0), [0, 0, -1]), far(), Leaving::No), Some(s(5)));
        assert_eq!(t.intersect(&ray(p(0, 0, 0), [0, 0, -1]), far(), Leaving::No), Some(s(5)));
        assert_eq!(t.intersect(&ray(p(1, 1, 0), [0, 0, -1]), far(), Leaving::Inward), None);
    }

    #[test]
    fn a_plane_beyond_the_representable_range_is_no_hit() {
        // Four raw units above the plane, almost parallel to it: the plane is
        // met at t = 2^32 raw units, beyond Q16.16. That is no hit — it once
        // came back as t = −1 unit (found by the render fuzzer: the naive
        // mode, passing Scalar::MAX, saw a hit the octree did not).
        let t = Triangle::new([p(-4000, -4000, 0), p(4000, -4000, 0), p(0, 4000, 0)], 0).unwrap();
        let origin = Vec3 { x: s(0), y: s(0), z: Scalar::from_bits(4) };
        let r = Ray { origin, dir: Dir::from_bits([(1 << 30) - 1, 0, -1]) };
        assert_eq!(t.intersect(&r, Scalar::MAX, Leaving::No), None);
    }

    #[test]
    fn collinear_corners_are_rejected() {
        assert!(Triangle::new([p(0, 0, 0), p(1, 1, 1), p(2, 2, 2)], 0).is_none());
    }

    #[test]
    fn clockwise_corners_face_the_other_way() {
        let t = Triangle::new([p(0, 0, -5), p(0, 4, -5), p(4, 0, -5)], 0).unwrap();
        assert_eq!(t.normal(), -Dir::Z);
        assert_eq!(t.intersect(&ray(p(1, 1, 0), [0, 0, -1]), far(), Leaving::No), Some(s(5)));
    }
}
