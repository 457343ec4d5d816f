//! Exact object–box tests for filing objects into octree boxes.
//!
//! A box receives an object when the box meets the object's *surface* (rays
//! only ever hit surfaces): a box deep inside a sphere or a solid box gets
//! nothing, which keeps large objects from filling the tree. Tests are
//! exact (in 64 bits where the values allow, else in `i128`); the caller
//! widens each box by a margin so that hits reported a few units off the
//! ideal surface (fixed-point rounding) are still filed.

use crate::math::{mul_i64_i32_wide, mul_wide, square_u32_wide};
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
        ShapeRef::Sphere(s) => sphere_overlaps(s.center.wide(), s.radius.to_bits(), cell),
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
/// Coordinates are doubled around the cell's centre so that everything
/// stays integral. Where they and the cell are below 2^30 (any scene of
/// ordinary size: a unit is 2^16), the edges' axes are tested in 64 bits,
/// from 32-bit products, and the normal in 128; otherwise all in 128. The
/// same answer either way: every sum is exact.
fn no_separating_axis<const N: usize>(p: &Polygon<N>, cell: &Cell) -> bool {
    let centre2 = [0, 1, 2].map(|a| cell.lo[a] + cell.hi[a]);
    let half2 = [0, 1, 2].map(|a| cell.hi[a] - cell.lo[a]);
    let v: [[i64; 3]; N] = core::array::from_fn(|i| {
        let w = p.corners[i].wide();
        [0, 1, 2].map(|a| 2 * w[a] - centre2[a])
    });
    const SMALL: i64 = 1 << 30;
    let small = |x: &i64| x.abs() < SMALL;
    if v.iter().flatten().all(small) && half2.iter().all(small) {
        let v = v.map(|c| c.map(|x| x as i32));
        no_separating_axis_small(&v, half2.map(|h| h as i32))
    } else {
        no_separating_axis_wide(&v.map(|c| c.map(i128::from)), half2.map(i128::from))
    }
}

/// [`no_separating_axis`] for coordinates and a cell below 2^30: the
/// edges' axes first (an edge below 2^31, so each projection is two
/// products below 2^61), the normal last, in 128 bits. On slices, not
/// arrays: one copy of the code for every polygon.
#[inline(never)]
fn no_separating_axis_small(v: &[[i32; 3]], half2: [i32; 3]) -> bool {
    let n = v.len();
    for i in 0..n {
        let e: [i32; 3] = [0, 1, 2].map(|a| v[(i + 1) % n][a] - v[i][a]);
        // The edge crossed with axis `a` has no component along `a`, `e[c]`
        // along `b` and `-e[b]` along `c`.
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            if e[b] == 0 && e[c] == 0 {
                continue;
            }
            let radius = mul_wide(e[c].abs(), half2[b]) + mul_wide(e[b].abs(), half2[c]);
            let (mut lo, mut hi) = (i64::MAX, i64::MIN);
            for corner in v {
                let projection = mul_wide(corner[b], e[c]) - mul_wide(corner[c], e[b]);
                (lo, hi) = (lo.min(projection), hi.max(projection));
            }
            if lo > radius || hi < -radius {
                return false;
            }
        }
    }
    let wide = |c: [i32; 3]| c.map(i64::from);
    let e1 = wide([0, 1, 2].map(|a| v[1][a] - v[0][a]));
    let e2 = wide([0, 1, 2].map(|a| v[n - 1][a] - v[0][a]));
    // Each product below 2^62: the normal's components fit 64 bits (their
    // magnitudes too).
    let normal = [0, 1, 2].map(|a| {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        e1[b] * e2[c] - e1[c] * e2[b]
    });
    let radius: i128 = (0..3).map(|a| mul_i64_i32_wide(normal[a].abs(), half2[a])).sum();
    // The normal is square to the edges from corner 0 to corners 1 and N-1,
    // exactly: those three project alike, and the rest are worked out.
    let projection = |c: [i32; 3]| (0..3).map(|a| mul_i64_i32_wide(normal[a], c[a])).sum::<i128>();
    let first = projection(v[0]);
    let (mut lo, mut hi) = (first, first);
    for &corner in &v[2..n - 1] {
        let p = projection(corner);
        (lo, hi) = (lo.min(p), hi.max(p));
    }
    !(lo > radius || hi < -radius)
}

/// [`no_separating_axis`] for any coordinates, in 128 bits.
#[inline(never)]
fn no_separating_axis_wide(v: &[[i128; 3]], half2: [i128; 3]) -> bool {
    let n = v.len();
    let separated = |axis: [i128; 3]| {
        let radius: i128 = (0..3).map(|a| axis[a].abs() * half2[a]).sum();
        let proj = v.iter().map(|&c| dot(c, axis));
        let (lo, hi) = proj.fold((i128::MAX, i128::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
        lo > radius || hi < -radius
    };
    let e1 = [0, 1, 2].map(|a| v[1][a] - v[0][a]);
    let e2 = [0, 1, 2].map(|a| v[n - 1][a] - v[0][a]);
    // Doubled coordinates (≤ 2^33) give cross products within 2^67, and
    // projections within 2^101: well inside i128.
    if separated(cross(e1, e2)) {
        return false;
    }
    for i in 0..n {
        let e = [0, 1, 2].map(|a| v[(i + 1) % n][a] - v[i][a]);
        for unit in [[1, 0, 0], [0, 1, 0], [0, 0, 1]] {
            let axis = cross(e, unit);
            if axis != [0; 3] && separated(axis) {
                return false;
            }
        }
    }
    true
}

/// Whether a sphere's surface meets the cell: the ball reaches the box,
/// and the box is not wholly inside it. Sums of squared distances, in
/// 64 bits from 32-bit squares when every distance is below 2^31 (the
/// usual case: a cell near the sphere), else in 128 bits; the same answer.
fn sphere_overlaps(c: [i64; 3], r: i32, cell: &Cell) -> bool {
    // The gap to the box and the distance to its far corner, per axis.
    let spans = [0, 1, 2].map(|a| {
        let (to_lo, to_hi) = (c[a] - cell.lo[a], cell.hi[a] - c[a]);
        let gap = if to_lo < 0 {
            -to_lo
        } else if to_hi < 0 {
            -to_hi
        } else {
            0
        };
        (gap, to_lo.abs().max(to_hi.abs()))
    });
    let r = r.unsigned_abs();
    if spans.iter().all(|&(_, far)| far < 1 << 31) {
        // Three squares below 2^62 each: their sum fits 64 bits.
        let square = |d: i64| square_u32_wide(d as u32);
        let near: u64 = spans.iter().map(|&(gap, _)| square(gap)).sum();
        let far: u64 = spans.iter().map(|&(_, far)| square(far)).sum();
        let r2 = square_u32_wide(r);
        return near <= r2 && far >= r2;
    }
    let square = |d: i64| (d as i128) * (d as i128);
    let near: i128 = spans.iter().map(|&(gap, _)| square(gap)).sum();
    let far: i128 = spans.iter().map(|&(_, far)| square(far)).sum();
    let r2 = (r as i128) * (r as i128);
    near <= r2 && far >= r2
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
    fn a_spheres_test_in_64_bits_is_its_test_in_128() {
        // Cells near and far, small and across the whole range, against the
        // test in 128 bits alone.
        let mut next = crate::test_rng::seeded(0x5fe7_e064);
        let mut below = |bits: u64| (next() % (1 << bits)) as i64 - (1 << (bits - 1));
        let mut meets = 0;
        for round in 0..100_000 {
            // Sphere, radius and cell of one scale, so that all answers come.
            let bits = [20, 30, 32, 34][round % 4];
            let c = [below(36), below(36), below(36)];
            let r = below(bits.min(32)).unsigned_abs().min(i32::MAX as u64) as i32;
            let lo = [0, 1, 2].map(|i| c[i] + below(bits));
            let cell = Cell { lo, hi: [0, 1, 2].map(|i| lo[i] + below(bits).abs()) };
            let (mut near, mut far) = (0i128, 0i128);
            for i in 0..3 {
                let (to_lo, to_hi) = ((c[i] - cell.lo[i]) as i128, (cell.hi[i] - c[i]) as i128);
                let gap = if to_lo < 0 { -to_lo } else { (-to_hi).max(0) };
                near += gap * gap;
                far += to_lo.abs().max(to_hi.abs()).pow(2);
            }
            let r2 = (r as i128) * (r as i128);
            let expected = near <= r2 && far >= r2;
            assert_eq!(sphere_overlaps(c, r, &cell), expected, "{c:?} {r} {cell:?}");
            meets += expected as u32;
        }
        assert!((10_000..90_000).contains(&meets), "{meets} cells of 100,000 meet their sphere");
    }

    #[test]
    fn a_polygons_test_in_64_bits_is_its_test_in_128() {
        extern crate std;
        use std::vec::Vec;
        // Triangles and quadrilaterals (planar or not: the test takes the
        // corners as given) against cells of every scale, near and across
        // them, below 2^30 doubled.
        let mut next = crate::test_rng::seeded(0x0a11_5e9a);
        let mut below = |bits: u64| (next() % (1 << bits)) as i64 - (1 << (bits - 1));
        let (mut meets, mut tests) = (0, 0);
        for round in 0..20_000 {
            let bits = [12, 20, 26, 28][round % 4];
            let corner = |below: &mut dyn FnMut(u64) -> i64| [below(bits), below(bits), below(bits)];
            let triangle: [[i64; 3]; 3] = core::array::from_fn(|_| corner(&mut below));
            let quad: [[i64; 3]; 4] = core::array::from_fn(|_| corner(&mut below));
            let lo = corner(&mut below);
            let half2 = [0, 1, 2].map(|_| below(bits).abs());
            // Doubled around the cell's centre, as the caller makes them.
            let around = |c: [i64; 3]| [0, 1, 2].map(|a| 2 * c[a] - (2 * lo[a] + half2[a]));
            let small = |x: i64| i32::try_from(x).ok().filter(|x| x.abs() < 1 << 30);
            for corners in [&triangle.map(around)[..], &quad.map(around)[..]] {
                if !corners.iter().flatten().chain(&half2).all(|&x| small(x).is_some()) {
                    continue;
                }
                let wide: Vec<[i128; 3]> = corners.iter().map(|c| c.map(i128::from)).collect();
                let narrow: Vec<[i32; 3]> = corners.iter().map(|c| c.map(|x| x as i32)).collect();
                let expected = no_separating_axis_wide(&wide, half2.map(i128::from));
                let got = no_separating_axis_small(&narrow, half2.map(|h| h as i32));
                assert_eq!(got, expected, "{corners:?} {half2:?}");
                (meets, tests) = (meets + expected as u32, tests + 1);
            }
        }
        assert!(tests > 30_000 && meets > tests / 20 && meets < tests * 19 / 20, "{meets} of {tests} met");
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
