//! `BSPLINE s order rows cols su sv` and its control points: a tensor-product
//! B-spline surface with clamped uniform knots, evaluated on an su × sv grid
//! and cut into [`SmoothTriangle`]s carrying the surface's normals.
//!
//! Knots are counted in *knot units*: with n control points of order k there
//! are m = n − k + 1 spans, knot j is clamp(j − (k − 1), 0, m), and the
//! parameter runs from 0 to m. Parameters and basis weights are Q30 (i64),
//! so the whole evaluation is integer arithmetic: the same bits on every
//! target. It runs once, when the scene is loaded; 128-bit intermediates keep
//! it exact enough there.
//!
//! Normals come from the partial derivatives, ∂S/∂u × ∂S/∂v, the
//! derivatives being B-splines of one order less over the control points'
//! differences. Where they vanish or are parallel (a collapsed edge, repeated
//! control points) the normal is taken a little way into the patch instead;
//! failing that, the triangles use their face normal there.

use super::smooth_triangle::SmoothTriangle;
use crate::math::{Dir, Vec3};

/// The highest order (degree + 1).
pub const MAX_ORDER: u32 = 8;
/// The most control points along either side.
pub const MAX_CONTROL_SIDE: u32 = 1024;
/// The most generated points along either side.
pub const MAX_SAMPLE_SIDE: u32 = 1024;

const ONE: i64 = 1 << 30;

/// A patch over normalised control points, row by row (`rows` along u,
/// `cols` along v).
#[derive(Clone, Copy, Debug)]
pub struct Bspline<'p> {
    order: usize,
    rows: usize,
    cols: usize,
    points: &'p [Vec3],
}

/// The non-zero basis functions at `u` (Q30 knot units): the index of the
/// first and the weights in Q30, for `n` control points of order `k`.
fn basis(n: usize, k: usize, u: i64) -> (usize, [i64; MAX_ORDER as usize]) {
    let m = (n - k + 1) as i64;
    let knot = |j: usize| (j as i64 - (k as i64 - 1)).clamp(0, m) << 30;
    // Interior knots are whole numbers: the span is the integer part (the
    // last span also takes u = m).
    let span = (k - 1 + (u.clamp(0, m << 30) >> 30) as usize).min(n - 1);
    let mut w = [0i64; MAX_ORDER as usize];
    let mut left = [0i64; MAX_ORDER as usize];
    let mut right = [0i64; MAX_ORDER as usize];
    w[0] = ONE;
    // Cox–de Boor, one degree at a time (The NURBS Book, A2.2).
    for j in 1..k {
        left[j] = u - knot(span + 1 - j);
        right[j] = knot(span + j) - u;
        let mut saved = 0i64;
        for r in 0..j {
            // Never zero: the span's own interval is at least one knot unit.
            let den = (right[r + 1] + left[j - r]).max(1) as i128;
            let temp = (((w[r] as i128) << 30) + den / 2) / den;
            w[r] = saved + ((right[r + 1] as i128 * temp + (1 << 29)) >> 30) as i64;
            saved = ((left[j - r] as i128 * temp + (1 << 29)) >> 30) as i64;
        }
        w[j] = saved;
    }
    (span + 1 - k, w)
}

/// `v` scaled by a power of two so that its largest component is below 2^30.
fn shrink(v: [i128; 3]) -> [i64; 3] {
    let largest = v.iter().map(|c| c.unsigned_abs()).max().unwrap_or(0);
    let shift = (128 - largest.leading_zeros()).saturating_sub(30);
    v.map(|c| (c >> shift) as i64)
}

impl<'p> Bspline<'p> {
    /// `None` unless 2 ≤ order ≤ rows, cols and there are rows·cols points.
    pub fn new(order: u32, rows: u32, cols: u32, points: &'p [Vec3]) -> Option<Bspline<'p>> {
        let (k, r, c) = (order as usize, rows as usize, cols as usize);
        let valid = (2..=MAX_ORDER as usize).contains(&k) && k <= r && k <= c && points.len() == r * c;
        valid.then_some(Bspline { order: k, rows: r, cols: c, points })
    }

    fn point_at(&self, i: usize, j: usize) -> [i64; 3] {
        self.points[i * self.cols + j].wide()
    }

    /// The parameter of sample `l` of `samples` along a side of `n` points,
    /// in Q30 knot units.
    fn parameter(&self, n: usize, l: u32, samples: u32) -> i64 {
        let m = (n - self.order + 1) as i64;
        ((l as i64 * m) << 30) / (samples.max(2) as i64 - 1)
    }

    /// The surface point at (u, v), Q30 knot units.
    pub fn point(&self, u: i64, v: i64) -> Vec3 {
        let (i0, nu) = basis(self.rows, self.order, u);
        let (j0, nv) = basis(self.cols, self.order, v);
        let mut sum = [0i128; 3];
        for a in 0..self.order {
            for b in 0..self.order {
                let w = nu[a] as i128 * nv[b] as i128; // Q60
                let p = self.point_at(i0 + a, j0 + b);
                for (s, c) in sum.iter_mut().zip(p) {
                    *s += w * c as i128;
                }
            }
        }
        Vec3::from_bits(sum.map(|s| ((s + (1 << 59)) >> 60) as i32))
    }

    /// ∂S/∂u and ∂S/∂v at (u, v), each scaled by some positive power of two.
    fn derivatives(&self, u: i64, v: i64) -> ([i128; 3], [i128; 3]) {
        let k = self.order;
        let along = |rows: bool| -> [i128; 3] {
            // The derivative along one side: order k − 1 over the differences
            // (k − 1)(P[i+1] − P[i]) / (knot[i + k] − knot[i + 1]).
            let (n, t, s) = if rows { (self.rows, u, v) } else { (self.cols, v, u) };
            let (other_n, m) = (if rows { self.cols } else { self.rows }, (n - k + 1) as i64);
            let (i0, dn) = basis(n - 1, k - 1, t);
            let (j0, on) = basis(other_n, k, s);
            let mut sum = [0i128; 3];
            for a in 0..k - 1 {
                let i = i0 + a;
                let span = ((i + 1) as i64).clamp(0, m) - ((i + 2) as i64 - k as i64).clamp(0, m);
                for (b, &weight) in on.iter().enumerate().take(k) {
                    let j = j0 + b;
                    let (p, q) = if rows {
                        (self.point_at(i, j), self.point_at(i + 1, j))
                    } else {
                        (self.point_at(j, i), self.point_at(j, i + 1))
                    };
                    let w = dn[a] as i128 * weight as i128 * (k as i128 - 1) / span.max(1) as i128;
                    for c in 0..3 {
                        sum[c] += w * (q[c] - p[c]) as i128;
                    }
                }
            }
            sum
        };
        (along(true), along(false))
    }

    /// The unit normal ∂S/∂u × ∂S/∂v at (u, v), `None` where the
    /// derivatives vanish or are parallel (to 2^-20).
    fn normal_exact(&self, u: i64, v: i64) -> Option<Dir> {
        let (su, sv) = self.derivatives(u, v);
        let (a, b) = (shrink(su), shrink(sv));
        let cross = [
            a[1] as i128 * b[2] as i128 - a[2] as i128 * b[1] as i128,
            a[2] as i128 * b[0] as i128 - a[0] as i128 * b[2] as i128,
            a[0] as i128 * b[1] as i128 - a[1] as i128 * b[0] as i128,
        ];
        let square = |v: [i128; 3]| v.iter().map(|c| c * c).sum::<i128>();
        let (aa, bb) = (square(a.map(|c| c as i128)), square(b.map(|c| c as i128)));
        // Components below 2^30 keep every square and product in an i128.
        if aa == 0 || bb == 0 || square(cross) < (aa * bb) >> 40 {
            return None;
        }
        Dir::normalize(shrink(cross))
    }

    /// The normal at (u, v), or a little way into the patch where the
    /// surface has none.
    fn normal(&self, u: i64, v: i64) -> Option<Dir> {
        let (mu, mv) = (((self.rows - self.order + 1) as i64) << 30, ((self.cols - self.order + 1) as i64) << 30);
        let inward = |t: i64, m: i64, step: i64| if t < m / 2 { t + step } else { t - step };
        self.normal_exact(u, v).or_else(|| {
            [mu.min(mv) >> 10, mu.min(mv) >> 6]
                .into_iter()
                .find_map(|step| self.normal_exact(inward(u, mu, step), inward(v, mv, step)))
        })
    }

    /// Sample (l, k) of an su × sv grid: the point and its normal.
    pub fn sample(&self, l: u32, su: u32, k: u32, sv: u32) -> (Vec3, Option<Dir>) {
        let (u, v) = (self.parameter(self.rows, l, su), self.parameter(self.cols, k, sv));
        (self.point(u, v), self.normal(u, v))
    }

    /// The triangles of the su × sv grid in order: quad (l, k) is cut into
    /// (l, k), (l+1, k), (l, k+1) and (l+1, k), (l+1, k+1), (l, k+1), whose
    /// front is the side ∂S/∂u × ∂S/∂v points to. Triangles with collinear
    /// corners (where the surface collapses) are left out. Returns how many
    /// were made.
    pub fn triangles(&self, su: u32, sv: u32, surface: u16, mut each: impl FnMut(SmoothTriangle)) -> usize {
        let mut made = 0;
        for l in 0..su.saturating_sub(1) {
            for k in 0..sv.saturating_sub(1) {
                let corner = |dl: u32, dk: u32| self.sample(l + dl, su, k + dk, sv);
                let (a, b, c, d) = (corner(0, 0), corner(1, 0), corner(0, 1), corner(1, 1));
                for [p, q, r] in [[a, b, c], [b, d, c]] {
                    if let Some(t) = SmoothTriangle::new([p.0, q.0, r.0], [p.1, q.1, r.1], surface) {
                        each(t);
                        made += 1;
                    }
                }
            }
        }
        made
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::super::test_util::*;
    use super::*;
    use std::vec::Vec;

    #[test]
    fn basis_weights_sum_to_one_and_clamp_the_ends() {
        for (n, k) in [(2, 2), (4, 3), (7, 4), (9, 8), (5, 2)] {
            let m = (n - k + 1) as i64;
            for step in 0..=64 {
                let u = (m << 30) * step / 64;
                let (first, w) = basis(n, k, u);
                assert!(first + k <= n);
                let sum: i64 = w[..k].iter().sum();
                assert!((sum - ONE).abs() <= 2 * k as i64, "n {n} k {k} u {u}: {sum}");
                assert!(w[..k].iter().all(|&x| x >= 0));
            }
            // Clamped: the first and last control points get all the weight.
            assert_eq!(
                basis(n, k, 0),
                (0, {
                    let mut w = [0; 8];
                    w[0] = ONE;
                    w
                })
            );
            let (first, w) = basis(n, k, m << 30);
            assert_eq!((first + k - 1, w[k - 1]), (n - 1, ONE));
        }
    }

    fn grid(rows: usize, cols: usize, f: impl Fn(usize, usize) -> Vec3) -> Vec<Vec3> {
        (0..rows * cols).map(|i| f(i / cols, i % cols)).collect()
    }

    #[test]
    fn order_two_is_the_bilinear_patch() {
        let pts = [p(0, 0, 0), p(0, 4, 2), p(4, 0, 1), p(4, 4, 8)];
        let s = Bspline::new(2, 2, 2, &pts).unwrap();
        for (l, k) in [(0, 0), (1, 1), (2, 2), (1, 3), (4, 0)] {
            let (u, v) = (l as i64 * ONE / 4, k as i64 * ONE / 4);
            let expect = [0, 1, 2].map(|a| {
                let c = |p: Vec3| p.wide()[a];
                let (u, v) = (u as i128, v as i128);
                let one = ONE as i128;
                ((one - u) * (one - v) * c(pts[0]) as i128
                    + (one - u) * v * c(pts[1]) as i128
                    + u * (one - v) * c(pts[2]) as i128
                    + u * v * c(pts[3]) as i128)
                    >> 60
            });
            assert_eq!(s.point(u, v).wide().map(|c| c as i128), expect, "({l}, {k})");
        }
    }

    #[test]
    fn corner_control_points_lie_on_the_surface() {
        let pts = grid(5, 4, |i, j| p(i as i32 * 2, j as i32 * 3, ((i * j) % 3) as i32));
        for order in [2, 3, 4] {
            let s = Bspline::new(order, 5, 4, &pts).unwrap();
            for (l, k, want) in [(0, 0, pts[0]), (6, 0, pts[16]), (0, 6, pts[3]), (6, 6, pts[19])] {
                assert_eq!(s.sample(l, 7, k, 7).0, want, "order {order}");
            }
        }
    }

    #[test]
    fn a_flat_patch_has_the_plane_normal_everywhere() {
        let pts = grid(4, 4, |i, j| p(i as i32, j as i32, 0));
        let s = Bspline::new(3, 4, 4, &pts).unwrap();
        for l in 0..5 {
            for k in 0..5 {
                assert_eq!(s.sample(l, 5, k, 5).1, Some(Dir::Z), "({l}, {k})");
            }
        }
        let mut count = 0;
        s.triangles(5, 5, 0, |t| {
            assert_eq!(t.normal(), Dir::Z);
            count += 1;
        });
        assert_eq!(count, 32);
    }

    #[test]
    fn a_collapsed_edge_still_has_normals() {
        // The first row of control points is one point (a cone's apex).
        let pts = grid(4, 4, |i, j| if i == 0 { p(0, 0, 4) } else { p(i as i32 * 2, j as i32 * 2 - 3, 0) });
        let s = Bspline::new(3, 4, 4, &pts).unwrap();
        for k in 0..5 {
            let n = s.sample(0, 5, k, 5).1.expect("a normal at the apex");
            assert!(n.dot(Dir::Z).to_bits().abs() > 1 << 20, "{n:?}");
        }
        let mut count = 0;
        s.triangles(5, 5, 0, |_| count += 1);
        assert!(count >= 24, "{count}");
    }

    #[test]
    fn invalid_shapes_are_refused() {
        let pts = grid(3, 3, |i, j| p(i as i32, j as i32, 0));
        assert!(Bspline::new(4, 3, 3, &pts).is_none());
        assert!(Bspline::new(1, 3, 3, &pts).is_none());
        assert!(Bspline::new(2, 3, 2, &pts).is_none());
        assert!(Bspline::new(3, 3, 3, &pts).is_some());
    }
}
