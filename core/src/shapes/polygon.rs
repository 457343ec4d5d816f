//! The plane-and-edges test shared by triangles and rectangles: a convex
//! polygon with `N` corners, counter-clockwise seen from its front.
//!
//! The hit point is found on the plane, then tested against the edges in the
//! 2-D projection that drops the normal's largest axis. Edge functions are
//! exact integer products, so two polygons sharing an edge classify a point on
//! it consistently; each edge is widened by [`EDGE_TOLERANCE`] so that
//! neighbours whose planes round differently still leave no crack.

use super::{Aabb, Leaving, Ray, Shape};
use crate::math::{div_saturating, mul_wide, Dir, Scalar, Vec3};

/// How far (in Q16.16 raw units, normalised space) a hit may lie outside an
/// edge and still count: four units, about 6·10^-5, far below a pixel.
pub const EDGE_TOLERANCE: i64 = 1 << EDGE_TOLERANCE_LOG2;
const EDGE_TOLERANCE_LOG2: u32 = 2;

/// A flat convex polygon of `N` corners: the core of triangles and rectangles.
// Public only for `profile!` (arenas of it) and the firmware's RAM
// estimate; its geometry is the core's own business.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Polygon<const N: usize> {
    pub corners: [Vec3; N],
    /// Front normal.
    pub normal: Dir,
    /// `normal · corners[0]`.
    pub offset: Scalar,
    /// The axis dropped for the 2-D edge test (the normal's largest).
    drop_axis: u8,
    /// Whether the normal is exactly ±1 along `drop_axis` and 0 along the
    /// others (a floor's, a wall's, whatever the corners' shape): the
    /// plane's products are then one term each (see `intersect`).
    axis_normal: bool,
    /// Whether every edge runs along an axis (a chessboard's tiles, a
    /// floor's; never a triangle's): the polygon then lies across
    /// `drop_axis` (so `axis_normal` holds) and fills its bounds in its
    /// plane, so the bounds' test is the edges' test (see `intersect`).
    along_axes: bool,
}

impl<const N: usize> Polygon<N> {
    /// A polygon with the given front normal; `None` if the normal is zero.
    pub fn with_normal(corners: [Vec3; N], normal: [i64; 3]) -> Option<Self> {
        let normal = Dir::normalize(normal)?;
        let nb = normal.bits().map(|c| c.unsigned_abs());
        let drop_axis = if nb[0] >= nb[1] && nb[0] >= nb[2] {
            0
        } else if nb[1] >= nb[2] {
            1
        } else {
            2
        };
        let axis_normal = (0..3).all(|k| {
            let component = normal.axis(k).to_bits().unsigned_abs();
            component == if k == drop_axis as usize { 1 << 30 } else { 0 }
        });
        let along_axes = N == 4
            && (0..N).all(|i| {
                let (a, b) = (corners[i].bits(), corners[(i + 1) % N].bits());
                (0..3).filter(|&k| a[k] != b[k]).count() <= 1
            })
            && axis_normal
            // Its other two corners within the box of the first and the
            // third (which a rectangle along the axes has: the intersection
            // test takes that box for the bounds).
            && [1, 3].into_iter().all(|i| {
                let (a, b, c) = (corners[0].bits(), corners[2 % N].bits(), corners[i % N].bits());
                (0..3).all(|k| a[k].min(b[k]) <= c[k] && c[k] <= a[k].max(b[k]))
            });
        Some(Polygon { corners, normal, offset: corners[0].dot_dir(normal), drop_axis, axis_normal, along_axes })
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        // A flat shape cannot be met again by a ray leaving it.
        if leaving != Leaving::No {
            return None;
        }
        let along_axes = N == 4 && self.along_axes;
        let (den, num) = if self.axis_normal {
            // The normal is ±2^30 on one axis and 0 on the others: n·d and
            // n·o have one term, exactly what the sums below would give.
            let a = self.drop_axis as usize;
            let positive = self.normal.axis(a).to_bits() > 0;
            let (d, o) = (ray.dir.axis(a).to_bits() as i64, ray.origin.axis(a).to_bits() as i64);
            let (den, o) = if positive { (d, o) } else { (-d, -o) };
            (den, (self.offset.to_bits() as i64 - o) << 30)
        } else {
            // Most rays that miss the plane meet it behind them (or leave
            // it behind): on a Cortex-M0 short products say so before the
            // exact ones, which would reject it as well.
            if ray.dir.plane_surely_behind(ray.origin, self.normal, self.offset) {
                return None;
            }
            // n·d in Q2.30 and (offset − n·o) in Q18.46; t = num / den is
            // then Q16.16.
            let den = self.normal.dot(ray.dir).to_bits() as i64;
            (den, ((self.offset.to_bits() as i64) << 30) - ray.origin.dot_dir_q46(self.normal))
        };
        if den == 0 {
            return None;
        }
        let (num, den) = if den < 0 { (-num, -den) } else { (num, den) };
        // Filter on the rounded parameter (⌊num / den⌋ ≤ t_max), as returned:
        // before dividing when t_max < MAX (den ≤ 2^30, so no overflow)...
        let limit = match t_max.to_bits().checked_add(1) {
            Some(t) => mul_wide(t, den as i32),
            None => i64::MAX,
        };
        if num <= 0 || num >= limit {
            return None;
        }
        // ...and after, for t_max = MAX: a plane met beyond the Q16.16 range
        // is no hit (it once came back as a negative parameter).
        let t = div_saturating(num as u64, den as u32) as i64;
        if t <= 0 || t > t_max.to_bits() as i64 {
            return None;
        }
        // The plane may be met far outside the scene range; only a point
        // inside the polygon's bounds is representable and worth testing.
        let o = ray.origin.wide();
        let d = ray.dir.bits();
        // Across an axis normal's plane, through the first corner's
        // coordinate `c` on that axis, the point is within [c − 2, c + 1]
        // (t is the floor of the exact parameter, |d| ≤ 2^30, and the product
        // is floored once more), so inside the bounds' slack there: that
        // axis needs neither the product nor the test (the edges' test
        // drops it too).
        let across = if self.axis_normal { self.drop_axis as usize } else { 3 };
        let p = [0, 1, 2].map(|a| if a == across { o[a] } else { o[a] + (mul_wide(d[a], t as i32) >> 30) });
        // Along the axes, the first and third corners span the bounds (see
        // `with_normal`): two corners' box instead of the fold over four.
        let b = if along_axes { Aabb::spanned(self.corners[0], self.corners[2 % N]) } else { self.bounds() };
        let (lo, hi) = (b.min.wide(), b.max.wide());
        let slack = EDGE_TOLERANCE;
        if (0..3).any(|a| a != across && (p[a] < lo[a] - slack || p[a] > hi[a] + slack)) {
            return None;
        }
        // Within the bounds, so each coordinate fits an i32: this is
        // `ray.at(t)`, already computed (but across an axis normal, where it
        // holds the origin's, which the edges' test drops). A polygon along
        // the axes fills its bounds: each edge's test (within its tolerance
        // of the edge) is the bounds' test just made on that side.
        let t = Scalar::from_bits(t as i32);
        (along_axes || self.contains(Vec3::from_bits(p.map(|c| c as i32)))).then_some(t)
    }

    /// Whether `p` (on the plane) lies inside the polygon, edges included.
    #[inline]
    pub fn contains(&self, p: Vec3) -> bool {
        let (u, v) = self.project(p);
        let flip = self.normal.axis(self.drop_axis as usize).to_bits() < 0;
        let mut prev = self.project(self.corners[N - 1]);
        for corner in &self.corners {
            let cur = self.project(*corner);
            // Points within ±2^29 units, so differences fit an i32.
            let (du, dv) = (cur.0 - prev.0, cur.1 - prev.1);
            let (across, along) = (v - prev.1, u - prev.0);
            // `−edge < −tolerance` when flipped, without the negation (which
            // the compiler once made a 64-bit multiply by ±1).
            let outside = match coarse_edge_outside(du, across, dv, along, flip) {
                Some(outside) => outside,
                None => {
                    let edge = mul_wide(du, across) - mul_wide(dv, along);
                    let tolerance = (du.unsigned_abs().max(dv.unsigned_abs()) as i64) << EDGE_TOLERANCE_LOG2;
                    if flip {
                        edge > tolerance
                    } else {
                        edge < -tolerance
                    }
                }
            };
            if outside {
                return false;
            }
            prev = cur;
        }
        true
    }

    /// Edge function values of `p` against each edge (`i` from corner `i` to
    /// `i + 1`), positive inside; used for barycentric weights.
    pub fn edge_values(&self, p: Vec3) -> [i64; N] {
        let (u, v) = self.project(p);
        let sign = self.normal.axis(self.drop_axis as usize).to_bits().signum() as i64;
        core::array::from_fn(|i| {
            let a = self.project(self.corners[i]);
            let b = self.project(self.corners[(i + 1) % N]);
            (mul_wide(b.0 - a.0, v - a.1) - mul_wide(b.1 - a.1, u - a.0)) * sign
        })
    }

    #[inline]
    fn project(&self, p: Vec3) -> (i32, i32) {
        let b = p.bits();
        match self.drop_axis {
            0 => (b[1], b[2]),
            1 => (b[2], b[0]),
            _ => (b[0], b[1]),
        }
    }

    pub fn bounds(&self) -> Aabb {
        let first = Aabb { min: self.corners[0], max: self.corners[0] };
        self.corners.iter().fold(first, |b, &c| b.union(Aabb { min: c, max: c }))
    }
}

/// Whether a point is outside an edge (`edge = du·across − dv·along`
/// beyond the edge's tolerance, on the side `flip` says) when 32-bit
/// products of the operands' top bits decide it, else `None`: most points
/// are far from every edge, and a Cortex-M0 makes each exact product in
/// parts.
///
/// Why: each operand is a difference of points within ±2^29, so within
/// ±2^30; with `x = h·2^16 + l` (`|h| ≤ 2^14`, `0 ≤ l < 2^16`) a product
/// `x·y` is within `2^14·2^16·2^16·2 + 2^32 < 2^48` of `h_x·h_y·2^32`, and
/// the edge within 2^49 of `H·2^32` (`H` the short products' difference,
/// below 2^29 in magnitude). The tolerance is at most 2^30 << 2 = 2^32. So
/// `H ≥ 2^17` makes `edge ≥ 0` (inside on the unflipped side), `H ≤
/// −2^17 − 2` makes `edge < −2^32` (outside); the flipped side mirrors it.
#[inline(always)]
fn coarse_edge_outside(du: i32, across: i32, dv: i32, along: i32, flip: bool) -> Option<bool> {
    const SURE: i32 = 1 << 17;
    let h = (du >> 16) * (across >> 16) - (dv >> 16) * (along >> 16);
    let h = if flip { -h } else { h };
    if h >= SURE {
        Some(false)
    } else if h <= -SURE - 2 {
        Some(true)
    } else {
        None
    }
}

/// `(b − a) × (c − a)` exactly, in Q32.32, for points within the scene range.
pub fn cross_of_edges(a: Vec3, b: Vec3, c: Vec3) -> [i64; 3] {
    let e1 = (b - a).wide();
    let e2 = (c - a).wide();
    [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
}

/// A flat shape: a convex polygon and its surface. A TRIANGLE is a
/// `Flat<3>` ([`Triangle`](super::Triangle)), a RECTANGLE a `Flat<4>`
/// ([`Rectangle`](super::Rectangle)); each builds its polygon its own way.
// Public only for `profile!` (arenas of it) and the firmware's RAM
// estimate; its geometry is the core's own business.
#[doc(hidden)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Flat<const N: usize> {
    pub polygon: Polygon<N>,
    pub surface: u16,
}

impl<const N: usize> Flat<N> {
    pub fn normal(&self) -> Dir {
        self.polygon.normal
    }
}

impl<const N: usize> Shape for Flat<N> {
    const FLAT: bool = true;

    #[inline]
    fn intersect(&self, ray: &Ray, t_max: Scalar, leaving: Leaving) -> Option<Scalar> {
        self.polygon.intersect(ray, t_max, leaving)
    }

    fn normal_at(&self, _: Vec3) -> Dir {
        self.normal()
    }

    fn bounds(&self) -> Aabb {
        self.polygon.bounds()
    }

    fn surface(&self) -> u16 {
        self.surface
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    /// Rectangles along the axes, and triangles across an axis, in every
    /// axis plane and facing either way, hit exactly as the general
    /// plane-and-edges test hits them: rays from anywhere, from their plane
    /// and a unit off it, towards their edges and corners within a few
    /// units.
    #[test]
    fn along_the_axes_the_short_test_is_the_general_one() {
        let mut next = crate::test_rng::seeded(0xa1_0a9e5);
        let mut coordinate = move |range: u64| (next() % (2 * range + 1)) as i64 - range as i64;
        let (mut along, mut hits, mut triangle_hits) = (0, 0, 0);
        for _ in 0..20_000 {
            let a = (coordinate(1) + 1) as usize;
            let [u, v] = [(a + 1) % 3, (a + 2) % 3];
            let plane = coordinate(1 << 22);
            let (u0, v0) = (coordinate(1 << 22), coordinate(1 << 22));
            let (u1, v1) = (u0 + 1 + coordinate(1 << 20).abs(), v0 + 1 + coordinate(1 << 20).abs());
            let corner = |cu: i64, cv: i64| {
                let mut p = [0i64; 3];
                (p[a], p[u], p[v]) = (plane, cu, cv);
                Vec3::from_bits(p.map(|c| c as i32))
            };
            let mut corners = [corner(u0, v0), corner(u1, v0), corner(u1, v1), corner(u0, v1)];
            if coordinate(1) > 0 {
                corners.reverse();
            }
            let d1 = (corners[2] - corners[0]).wide();
            let d2 = (corners[3] - corners[1]).wide();
            let normal = [d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2], d1[0] * d2[1] - d1[1] * d2[0]];
            let fast = Polygon::with_normal(corners, normal).unwrap();
            assert!(fast.along_axes);
            assert_eq!(Aabb::spanned(fast.corners[0], fast.corners[2]), fast.bounds());
            along += 1;
            let general = Polygon { axis_normal: false, along_axes: false, ..fast };
            // A triangle across the same axis takes the one-term plane too.
            let fast_triangle = Polygon::with_normal([corners[0], corners[1], corners[2]], normal).unwrap();
            assert!(fast_triangle.axis_normal && !fast_triangle.along_axes);
            let general_triangle = Polygon { axis_normal: false, ..fast_triangle };
            let target = [0, 1, 2].map(|k| match k {
                k if k == a => plane,
                k if k == u => [u0, u1][coordinate(1).unsigned_abs() as usize % 2] + coordinate(6),
                _ => v0 + coordinate((v1 - v0 + 12) as u64).abs() - 6,
            });
            let origin = [0, 1, 2].map(|k| match (k == a, coordinate(3)) {
                (true, 0) => plane,
                (true, 1) => plane + coordinate(1),
                _ => target[k] + coordinate(1 << 23),
            });
            let Some(dir) = Dir::normalize([0, 1, 2].map(|k| target[k] - origin[k])) else { continue };
            let ray = Ray { origin: Vec3::from_bits(origin.map(|c| c as i32)), dir };
            for t_max in [Scalar::MAX, Scalar::from_bits(coordinate(1 << 25).abs() as i32)] {
                let hit = fast.intersect(&ray, t_max, Leaving::No);
                assert_eq!(hit, general.intersect(&ray, t_max, Leaving::No), "{ray:?} {fast:?}");
                hits += hit.is_some() as u32;
                let hit = fast_triangle.intersect(&ray, t_max, Leaving::No);
                assert_eq!(hit, general_triangle.intersect(&ray, t_max, Leaving::No), "{ray:?} {fast_triangle:?}");
                triangle_hits += hit.is_some() as u32;
            }
        }
        assert!(along > 15_000 && hits > 5_000, "{along} along the axes, {hits} hits");
        assert!(triangle_hits > 2_500, "{triangle_hits} hits of triangles");
        // A tilted one is not along the axes.
        let tilted =
            [[0, 0, 0], [1 << 16, 0, 0], [1 << 16, 1 << 16, 1 << 16], [0, 1 << 16, 1 << 16]].map(Vec3::from_bits);
        let tilted = Polygon::with_normal(tilted, [0, -1, 1]).unwrap();
        assert!(!tilted.along_axes && !tilted.axis_normal);
    }

    /// The short products' decision agrees with the exact edge test for
    /// differences of points within ±2^29, on either side, and leaves few
    /// points to the exact test.
    #[test]
    fn the_coarse_edge_test_decides_as_the_exact_one() {
        let mut next = crate::test_rng::seeded(0xed9e_c0a5);
        let (mut decided, mut undecided) = (0, 0);
        for i in 0..500_000 {
            let mut point = || -> [i32; 2] {
                let r = next();
                // Mostly large polygons (the coarse test's case), some small.
                let cut = [0, 0, 1, 2, 3, 6, 12, 20][(r >> 61) as usize];
                [((r as i32) >> 2) >> cut, ((r >> 32) as i32 >> 2) >> cut]
            };
            let (a, b, p) = (point(), point(), point());
            let (du, dv) = (b[0] - a[0], b[1] - a[1]);
            let (across, along) = (p[1] - a[1], p[0] - a[0]);
            let edge = du as i64 * across as i64 - dv as i64 * along as i64;
            let tolerance = (du.unsigned_abs().max(dv.unsigned_abs()) as i64) << EDGE_TOLERANCE_LOG2;
            for flip in [false, true] {
                let exact = if flip { edge > tolerance } else { edge < -tolerance };
                match coarse_edge_outside(du, across, dv, along, flip) {
                    Some(outside) => {
                        assert_eq!(outside, exact, "case {i}: {a:?} {b:?} {p:?} flip {flip}");
                        decided += 1;
                    }
                    None => undecided += 1,
                }
            }
        }
        assert!(decided > 500_000 && undecided > 1_000, "{decided} {undecided}");
    }
}
