//! B-spline patches evaluated by Cox–de Boor in f64, and cut into triangles carrying the surface normals.

use crate::vector::V3;
use crate::Shape;

/// A tensor-product B-spline with clamped uniform knots, control points row
/// by row (`rows` along u, `cols` along v).
pub struct Patch {
    pub order: usize,
    pub rows: usize,
    pub cols: usize,
    pub points: Vec<V3>,
}

/// The clamped uniform knot vector for `n` control points of order `k`, in
/// knot units (spans of length 1, from 0 to n − k + 1).
fn knots(n: usize, k: usize) -> Vec<f64> {
    let m = (n - k + 1) as f64;
    (0..n + k).map(|j| (j as f64 - (k as f64 - 1.0)).clamp(0.0, m)).collect()
}

/// N_{i,k}(u) by the Cox–de Boor recursion, with the last span closed at
/// its right end so that u = end belongs to it.
fn basis_function(t: &[f64], i: usize, k: usize, u: f64) -> f64 {
    if k == 1 {
        let end = *t.last().unwrap_or(&0.0);
        let last_span = t[i + 1] == end && t[i] < end;
        return if (t[i] <= u && u < t[i + 1]) || (last_span && u == end) { 1.0 } else { 0.0 };
    }
    let mut value = 0.0;
    let left = t[i + k - 1] - t[i];
    if left > 0.0 {
        value += (u - t[i]) / left * basis_function(t, i, k - 1, u);
    }
    let right = t[i + k] - t[i + 1];
    if right > 0.0 {
        value += (t[i + k] - u) / right * basis_function(t, i + 1, k - 1, u);
    }
    value
}

/// dN_{i,k}/du.
fn basis_derivative(t: &[f64], i: usize, k: usize, u: f64) -> f64 {
    let mut value = 0.0;
    let left = t[i + k - 1] - t[i];
    if left > 0.0 {
        value += (k as f64 - 1.0) / left * basis_function(t, i, k - 1, u);
    }
    let right = t[i + k] - t[i + 1];
    if right > 0.0 {
        value -= (k as f64 - 1.0) / right * basis_function(t, i + 1, k - 1, u);
    }
    value
}

impl Patch {
    fn span(&self, n: usize) -> f64 {
        (n - self.order + 1) as f64
    }

    /// S(u, v), ∂S/∂u and ∂S/∂v at knot-unit parameters.
    pub fn evaluate(&self, u: f64, v: f64) -> (V3, V3, V3) {
        let (tu, tv) = (knots(self.rows, self.order), knots(self.cols, self.order));
        let zero = V3::new(0.0, 0.0, 0.0);
        let (mut s, mut su, mut sv) = (zero, zero, zero);
        for i in 0..self.rows {
            let (nu, du) = (basis_function(&tu, i, self.order, u), basis_derivative(&tu, i, self.order, u));
            for j in 0..self.cols {
                let (nv, dv) = (basis_function(&tv, j, self.order, v), basis_derivative(&tv, j, self.order, v));
                let p = self.points[i * self.cols + j];
                s = s + p * (nu * nv);
                su = su + p * (du * nv);
                sv = sv + p * (nu * dv);
            }
        }
        (s, su, sv)
    }

    /// The unit normal ∂S/∂u × ∂S/∂v, `None` where the derivatives vanish or
    /// are parallel (to 2^-20).
    fn exact_normal(&self, u: f64, v: f64) -> Option<V3> {
        let (_, su, sv) = self.evaluate(u, v);
        let n = su.cross(sv);
        (n.length() > su.length() * sv.length() * 2f64.powi(-20) && n.length() > 0.0).then(|| n.normalised())
    }

    /// Sample (l, k) of an su × sv grid: the point and its normal, the
    /// normal taken a little way into the patch (1/1024, then 1/64 of the
    /// shorter parameter range) where the surface has none.
    pub fn sample(&self, l: usize, su: usize, k: usize, sv: usize) -> (V3, Option<V3>) {
        let (mu, mv) = (self.span(self.rows), self.span(self.cols));
        let (u, v) = (l as f64 * mu / (su - 1) as f64, k as f64 * mv / (sv - 1) as f64);
        let inward = |t: f64, m: f64, step: f64| if t < m / 2.0 { t + step } else { t - step };
        let normal = self.exact_normal(u, v).or_else(|| {
            [1.0 / 1024.0, 1.0 / 64.0].iter().find_map(|f| {
                let step = mu.min(mv) * f;
                self.exact_normal(inward(u, mu, step), inward(v, mv, step))
            })
        });
        (self.evaluate(u, v).0, normal)
    }

    /// The triangles of the su × sv grid, quad by quad: (l,k), (l+1,k),
    /// (l,k+1) and (l+1,k), (l+1,k+1), (l,k+1); degenerate ones left out.
    pub fn triangles(&self, su: usize, sv: usize) -> Vec<Shape> {
        let mut out = Vec::new();
        for l in 0..su - 1 {
            for k in 0..sv - 1 {
                let c = |dl, dk| self.sample(l + dl, su, k + dk, sv);
                let (a, b, cc, d) = (c(0, 0), c(1, 0), c(0, 1), c(1, 1));
                for corners in [[a, b, cc], [b, d, cc]] {
                    let p = corners.map(|c| c.0);
                    let face = (p[1] - p[0]).cross(p[2] - p[0]);
                    if face.length() == 0.0 {
                        continue;
                    }
                    let face = face.normalised();
                    let normals = corners.map(|c| match c.1 {
                        Some(n) if n.dot(face) >= 0.0 => n,
                        Some(n) => -n,
                        None => face,
                    });
                    out.push(Shape::SmoothTriangle { p, normal: face, normals });
                }
            }
        }
        out
    }
}

/// Barycentric weights of `x` (on the plane of `p`), clamped to the triangle.
pub(crate) fn barycentric(p: &[V3; 3], x: V3) -> [f64; 3] {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let area = |a: V3, b: V3| (b - a).cross(x - a).dot(n).max(0.0);
    let w = [area(p[1], p[2]), area(p[2], p[0]), area(p[0], p[1])];
    let total = w[0] + w[1] + w[2];
    if total > 0.0 {
        w.map(|v| v / total)
    } else {
        [1.0, 0.0, 0.0]
    }
}
