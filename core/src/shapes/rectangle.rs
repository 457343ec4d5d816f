//! `RECTANGLE s p1 p2 p3 p4`: a planar convex quadrilateral, corners
//! counter-clockwise seen from the front. Planarity and convexity are checked
//! when the scene is parsed, in world units.

use super::polygon::{Flat, Polygon};
use crate::math::Vec3;

/// A RECTANGLE: a planar convex quadrilateral.
pub type Rectangle = Flat<4>;

impl Rectangle {
    /// `None` when the corners span no area at this precision.
    pub fn new(corners: [Vec3; 4], surface: u16) -> Option<Rectangle> {
        // The cross product of the diagonals: the front normal of a convex
        // counter-clockwise quadrilateral, using all four corners.
        let d1 = (corners[2] - corners[0]).wide();
        let d2 = (corners[3] - corners[1]).wide();
        let normal = [d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2], d1[0] * d2[1] - d1[1] * d2[0]];
        Some(Rectangle { polygon: Polygon::with_normal(corners, normal)?, surface })
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::*;
    use super::super::{Leaving, Shape};
    use super::*;
    use crate::math::{Dir, Scalar};

    fn floor() -> Rectangle {
        // y = −1, seen from above: counter-clockwise from +y.
        Rectangle::new([p(-2, -1, 2), p(2, -1, 2), p(2, -1, -2), p(-2, -1, -2)], 0).unwrap()
    }

    #[test]
    fn front_normal_and_hits() {
        let f = floor();
        assert_eq!(f.normal(), Dir::Y);
        assert_eq!(f.intersect(&ray(p(0, 3, 0), [0, -1, 0]), far(), Leaving::No), Some(s(4)));
        assert_eq!(f.intersect(&ray(p(1, -5, 1), [0, 1, 0]), far(), Leaving::No), Some(s(4)));
        assert_eq!(f.intersect(&ray(p(2, 3, -2), [0, -1, 0]), far(), Leaving::No), Some(s(4)));
    }

    #[test]
    fn misses_outside_the_corners() {
        let f = floor();
        assert_eq!(f.intersect(&ray(p(3, 3, 0), [0, -1, 0]), far(), Leaving::No), None);
        assert_eq!(f.intersect(&ray(p(0, 3, 3), [0, -1, 0]), far(), Leaving::No), None);
    }

    #[test]
    fn oblique_hit_lands_on_the_plane() {
        let f = floor();
        let r = ray(p(0, 3, 0), [1, -2, 0]);
        let t = f.intersect(&r, far(), Leaving::No).unwrap();
        assert!(close(r.at(t), p(2, -1, 0), 2), "{:?}", r.at(t));
    }

    #[test]
    fn shared_edge_leaves_no_crack() {
        // Two tiles sharing the edge x = 0: every ray down the seam hits one.
        let a = Rectangle::new([p(-2, 0, 2), p(0, 0, 2), p(0, 0, -2), p(-2, 0, -2)], 0).unwrap();
        let b = Rectangle::new([p(0, 0, 2), p(2, 0, 2), p(2, 0, -2), p(0, 0, -2)], 0).unwrap();
        for k in -50..50 {
            let origin = Vec3 { x: Scalar::from_bits(k), ..p(0, 5, 0) };
            let r = ray(origin, [1, -1000, 3]);
            let hit = a.intersect(&r, far(), Leaving::No).or(b.intersect(&r, far(), Leaving::No));
            assert!(hit.is_some(), "crack at k = {k}");
        }
    }
}
