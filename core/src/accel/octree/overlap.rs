//! Exact object–box tests for filing objects into octree boxes.
//!
//! A box receives an object when the box meets the object's *surface* (rays
//! only ever hit surfaces): a box deep inside a sphere or a solid box gets
//! nothing, which keeps large objects from filling the tree. Tests are exact
//! in `i128`; the caller widens each box by a margin so that hits reported
//! a few units off the ideal surface (fixed-point rounding) are still filed.

use crate::shapes::{Polygon, ShapeRef};

/// A closed box `[lo, hi]` in Q16.16 raw units.
#[derive(Clone, Copy, Debug)]
pub struct Cell {
    pub lo: [i64; 3],
    pub hi: [i64; 3],
}

/// Whether the surface of `shape` meets the closed box `cell`.
pub fn overlaps(shape: ShapeRef<'_>, cell: &Cell) -> bool {
    let b = shape.bounds();
    let (blo, bhi) = (b.min.wide(), b.max.wide());
    if (0..3).any(|a| bhi[a] < cell.lo[a] || blo[a] > cell.hi[a]) {
        return false;
    }
    match shape {
        ShapeRef::Sphere(s) => {
            let c = s.center.wide();
            let r = s.radius.to_bits() as i128;
            let mut near = 0i128;
            let mut far = 0i128;
            for a in 0..3 {
                let to_lo = (c[a] - cell.lo[a]) as i128;
                let to_hi = (cell.hi[a] - c[a]) as i128;
                let gap = if to_lo < 0 {
                    -to_lo
                } else if to_hi < 0 {
                    -to_hi
                } else {
                    0
                };
                near += gap * gap;
                far += to_lo.abs().max(to_hi.abs()).pow(2);
            }
            // The ball reaches the box, and the box is not wholly inside it.
            near <= r * r && far >= r * r
        }
        ShapeRef::Box(b) => {
            let (lo, hi) = (b.min.wide(), b.max.wide());
            let inside = (0..3).all(|a| lo[a] < cell.lo[a] && cell.hi[a] < hi[a]);
            !inside
        }
        ShapeRef::Triangle(t) => polygon_overlaps(&t.polygon, cell),
        ShapeRef::SmoothTriangle(t) => polygon_overlaps(&t.triangle.polygon, cell),
        ShapeRef::Rectangle(r) => polygon_overlaps(&r.polygon, cell),
        // Conservative for the others (the superquadric, and a new kind
        // until it has its own test): the bounding boxes meet.
        _ => true,
    }
}

fn cross(a: [i128; 3], b: [i128; 3]) -> [i128; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: [i128; 3], b: [i128; 3]) -> i128 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Separating-axis test of a convex polygon against a box: the box's axes
/// (already done by the caller's bounds check), the polygon's normal, and
/// every edge crossed with every box axis. Coordinates are doubled around the
/// box centre so that everything stays integral.
fn polygon_overlaps<const N: usize>(p: &Polygon<N>, cell: &Cell) -> bool {
    // A polygon whose edges each run along an axis (a chessboard's tiles, a
    // floor's) is its own bounds, so the bounds' test already made was
    // exact: the same answer as the separating axes below, without them.
    let along_axes = (0..N).all(|i| {
        let (a, b) = (p.corners[i].wide(), p.corners[(i + 1) % N].wide());
        (0..3).filter(|&k| a[k] != b[k]).count() <= 1
    });
    along_axes || no_separating_axis(p, cell)
}

/// The separating axis test of a convex polygon against a cell whose bounds
/// it overlaps: the polygon's normal and each edge crossed with each axis.
fn no_separating_axis<const N: usize>(p: &Polygon<N>, cell: &Cell) -> bool {
    let centre2 = [0, 1, 2].map(|a| cell.lo[a] as i128 + cell.hi[a] as i128);
    let half2 = [0, 1, 2].map(|a| cell.hi[a] as i128 - cell.lo[a] as i128);
    let v: [[i128; 3]; N] = core::array::from_fn(|i| {
        let w = p.corners[i].wide();
        [0, 1, 2].map(|a| 2 * w[a] as i128 - centre2[a])
    });
    let separated = |axis: [i128; 3]| {
        let radius: i128 = (0..3).map(|a| axis[a].abs() * half2[a]).sum();
        let proj = v.map(|c| dot(c, axis));
        let lo = proj.iter().copied().min().unwrap_or(0);
        let hi = proj.iter().copied().max().unwrap_or(0);
        lo > radius || hi < -radius
    };
    let e1 = [0, 1, 2].map(|a| v[1][a] - v[0][a]);
    let e2 = [0, 1, 2].map(|a| v[N - 1][a] - v[0][a]);
    // Doubled coordinates (≤ 2^33) give cross products within 2^67, and
    // projections within 2^101: well inside i128.
    if separated(cross(e1, e2)) {
        return false;
    }
    for i in 0..N {
        let e = [0, 1, 2].map(|a| v[(i + 1) % N][a] - v[i][a]);
        for unit in [[1, 0, 0], [0, 1, 0], [0, 0, 1]] {
            let axis = cross(e, unit);
            if axis != [0; 3] && separated(axis) {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Scalar, Vec3};
    use crate::shapes::{AxisAlignedBox, Shape, Sphere, Triangle};

    const U: i64 = 1 << 16;

    fn p(x: i64, y: i64, z: i64) -> Vec3 {
        Vec3::from_bits([(x * U) as i32, (y * U) as i32, (z * U) as i32])
    }

    fn cell(lo: [i64; 3], hi: [i64; 3]) -> Cell {
        Cell { lo: lo.map(|v| v * U), hi: hi.map(|v| v * U) }
    }

    #[test]
    fn sphere_surface_only() {
        let s = Sphere::new(p(0, 0, 0), Scalar::from_num(10), 0);
        let r = ShapeRef::Sphere(&s);
        assert!(overlaps(r, &cell([9, -1, -1], [11, 1, 1])), "straddles the surface");
        assert!(!overlaps(r, &cell([-1, -1, -1], [1, 1, 1])), "deep inside");
        assert!(!overlaps(r, &cell([8, 8, 8], [9, 9, 9])), "outside, within the bounds");
        assert!(overlaps(r, &cell([10, 0, 0], [12, 1, 1])), "touching counts");
    }

    #[test]
    fn box_surface_only() {
        let b = AxisAlignedBox::new(p(0, 0, 0), p(4, 4, 4), 0);
        let r = ShapeRef::Box(&b);
        assert!(overlaps(r, &cell([3, 3, 3], [5, 5, 5])));
        assert!(!overlaps(r, &cell([-1, -1, -1], [1, 1, 1])));
        assert!(!overlaps(r, &cell([5, 5, 5], [6, 6, 6])));
    }

    #[test]
    fn a_rectangle_along_the_axes_is_its_own_bounds() {
        use crate::shapes::Rectangle;
        // Tiles of a floor at y = 0 and of a wall at x = 2, against cells
        // around and across their edges and corners: the bounds' answer is
        // the separating axes' answer.
        let floor = Rectangle::new([p(0, 0, 0), p(2, 0, 0), p(2, 0, 3), p(0, 0, 3)], 0).unwrap();
        let wall = Rectangle::new([p(2, -1, 0), p(2, 1, 0), p(2, 1, 3), p(2, -1, 3)], 0).unwrap();
        for shape in [&floor, &wall] {
            let r = ShapeRef::Rectangle(shape);
            let mut checked = 0;
            for (x, y, z) in (0..125).map(|i| (i % 5 - 1, i / 5 % 5 - 2, i / 25 - 1)) {
                let c = cell([x, y, z], [x + 1, y + 1, z + 1]);
                let (b, corner) = (shape.bounds(), Cell { lo: c.lo.map(|v| v + U / 2), hi: c.hi });
                for c in [c, corner] {
                    let (lo, hi) = (b.min.wide(), b.max.wide());
                    if (0..3).all(|a| hi[a] >= c.lo[a] && lo[a] <= c.hi[a]) {
                        assert_eq!(overlaps(r, &c), no_separating_axis(&shape.polygon, &c), "{c:?}");
                        checked += 1;
                    }
                }
            }
            assert!(checked > 10, "{checked} cells met the bounds");
        }
    }

    #[test]
    fn triangle_separating_axes() {
        let t = Triangle::new([p(0, 0, 0), p(10, 0, 0), p(0, 10, 0)], 0).unwrap();
        let r = ShapeRef::Triangle(&t);
        assert!(overlaps(r, &cell([1, 1, -1], [2, 2, 1])), "inside, plane crosses");
        assert!(!overlaps(r, &cell([1, 1, 1], [2, 2, 2])), "above the plane");
        assert!(!overlaps(r, &cell([6, 6, -1], [8, 8, 1])), "beyond the hypotenuse");
        assert!(overlaps(r, &cell([4, 4, -1], [6, 6, 1])), "on the hypotenuse");
    }
}
