//! Ray against each shape: the nearest root with t > 0, or the far side only for a ray leaving a closed shape inward.

use crate::vector::V3;
use crate::{Object, Shape};

/// Which roots of a closed shape a ray may report.
#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Roots {
    /// The nearest root with t > 0.
    Nearest,
    /// Only the far side: the ray starts on this shape and goes inward.
    FarOnly,
}

/// The parameter interval [t0, t1] where `o + t·d` is inside the box
/// |x_i − c_i| ≤ h_i, or `None` if the line misses it.
fn slab(o: V3, d: V3, c: V3, h: V3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..3 {
        let (oi, di) = (o.get(i) - c.get(i), d.get(i));
        let hi = h.get(i);
        if di == 0.0 {
            if oi.abs() > hi {
                return None;
            }
        } else {
            let (a, b) = ((-hi - oi) / di, (hi - oi) / di);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Bisect [lo, hi] while `is_lo_side(mid)` tells which half to keep, down to
/// adjacent floating-point numbers. Returns the final (lo, hi).
fn bisect(mut lo: f64, mut hi: f64, is_lo_side: impl Fn(f64) -> bool) -> (f64, f64) {
    for _ in 0..300 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if is_lo_side(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (lo, hi)
}

fn sphere_hit(centre: V3, radius: f64, o: V3, d: V3, roots: Roots) -> Option<f64> {
    let oc = o - centre;
    let b = oc.dot(d);
    // Squared distance from the centre to the line, computed directly for accuracy.
    let perp = oc - d * b;
    let disc = radius * radius - perp.dot(perp);
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let (near, far) = (-b - sq, -b + sq);
    if roots == Roots::Nearest && near > 0.0 {
        Some(near)
    } else {
        (far > 0.0).then_some(far)
    }
}

fn box_hit(centre: V3, half: V3, o: V3, d: V3, roots: Roots) -> Option<f64> {
    let (t0, t1) = slab(o, d, centre, half)?;
    if roots == Roots::Nearest && t0 > 0.0 {
        Some(t0)
    } else {
        (t1 > 0.0).then_some(t1)
    }
}

fn superquadric_hit(power: f64, centre: V3, half: V3, o: V3, d: V3, roots: Roots) -> Option<f64> {
    // Work in local coordinates where the bounding box is [-1, 1]^3.
    let lo = V3::from_fn(|i| (o.get(i) - centre.get(i)) / half.get(i));
    let ld = V3::from_fn(|i| d.get(i) / half.get(i));
    let (t0, t1) = slab(lo, ld, V3::new(0.0, 0.0, 0.0), V3::new(1.0, 1.0, 1.0))?;
    if t1 <= 0.0 {
        return None;
    }
    let at = |t: f64| lo + ld * t;
    // f(t) = Σ|x_i|^p − 1 is convex along the line; f' is non-decreasing.
    let f = |t: f64| {
        let x = at(t);
        (0..3).map(|i| x.get(i).abs().powf(power)).sum::<f64>() - 1.0
    };
    let df = |t: f64| {
        let x = at(t);
        (0..3).map(|i| x.get(i).signum() * x.get(i).abs().powf(power - 1.0) * ld.get(i)).sum::<f64>()
    };
    let start = t0.max(0.0);
    // The minimum of f on [start, t1]: bisect on the sign of f'.
    let tmin = if df(start) >= 0.0 {
        start
    } else if df(t1) <= 0.0 {
        t1
    } else {
        let (a, b) = bisect(start, t1, |t| df(t) < 0.0);
        if f(a) <= f(b) {
            a
        } else {
            b
        }
    };
    if f(tmin) > 0.0 {
        return None; // the line never gets inside the surface within the box
    }
    if roots == Roots::Nearest {
        if f(start) > 0.0 {
            // Outside at the start: the entry root lies in [start, tmin].
            let (_, b) = bisect(start, tmin, |t| f(t) > 0.0);
            return Some(b);
        }
        if t0 > 0.0 {
            // Inside the surface right at the box entry (large p touches the
            // box faces at their centres): hit at the entry point.
            return Some(t0);
        }
        // Otherwise the ray starts inside the surface: report the exit.
    }
    let exit = if f(t1) <= 0.0 { t1 } else { bisect(tmin, t1, |t| f(t) <= 0.0).0 };
    (exit > 0.0).then_some(exit)
}

fn triangle_hit(p: &[V3; 3], o: V3, d: V3) -> Option<f64> {
    // Möller–Trumbore.
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - p[0];
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t > 0.0).then_some(t)
}

fn rectangle_hit(p: &[V3; 4], normal: V3, o: V3, d: V3) -> Option<f64> {
    let denom = normal.dot(d);
    if denom == 0.0 {
        return None;
    }
    let centre = (p[0] + p[1] + p[2] + p[3]) * 0.25;
    let t = normal.dot(centre - o) / denom;
    if t <= 0.0 {
        return None;
    }
    let hit = o + d * t;
    for k in 0..4 {
        let (a, b) = (p[k], p[(k + 1) % 4]);
        if (b - a).cross(hit - a).dot(normal) < 0.0 {
            return None;
        }
    }
    Some(t)
}

impl Object {
    pub(crate) fn hit(&self, o: V3, d: V3, roots: Roots) -> Option<f64> {
        match self.shape {
            Shape::Sphere { centre, radius } => sphere_hit(centre, radius, o, d, roots),
            Shape::Box { centre, half } => box_hit(centre, half, o, d, roots),
            Shape::Superquadric { power, centre, half } => superquadric_hit(power, centre, half, o, d, roots),
            Shape::Triangle { ref p, .. } | Shape::SmoothTriangle { ref p, .. } => triangle_hit(p, o, d),
            Shape::Rectangle { ref p, normal } => rectangle_hit(p, normal, o, d),
        }
    }

    /// The geometric unit normal at a point on the object (outward for closed
    /// shapes, the front normal for flat ones).
    pub(crate) fn normal(&self, at: V3) -> V3 {
        match self.shape {
            Shape::Sphere { centre, .. } => (at - centre).normalised(),
            Shape::Box { centre, half } => {
                let rel = |i: usize| (at.get(i) - centre.get(i)) / half.get(i);
                let mut axis = 0;
                for i in 1..3 {
                    if rel(i).abs() > rel(axis).abs() {
                        axis = i;
                    }
                }
                let sign = if rel(axis) < 0.0 { -1.0 } else { 1.0 };
                V3::from_fn(|i| if i == axis { sign } else { 0.0 })
            }
            Shape::Superquadric { power, centre, half } => {
                let g = V3::from_fn(|i| {
                    let x = (at.get(i) - centre.get(i)) / half.get(i);
                    x.signum() * x.abs().powf(power - 1.0) / half.get(i)
                });
                g.normalised()
            }
            Shape::Triangle { normal, .. } | Shape::Rectangle { normal, .. } | Shape::SmoothTriangle { normal, .. } => {
                normal
            }
        }
    }
}
