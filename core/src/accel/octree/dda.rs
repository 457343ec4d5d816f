//! octrace's walk: an integer 3DDDA over the octree's leaves, in the
//! parametric form of Revelles, Ureña and Lastra (2000) — the octree
//! counterpart of Fujimoto's 3DDDA and of Amanatides and Woo's grid walk.
//!
//! Per axis the walk keeps the parameters at which the ray crosses the
//! current box's near, middle and far planes (Q40.24 integers). Only the
//! root's six are computed (one reciprocal per axis per ray); a child's planes
//! are its parent's, and a middle plane is the mean of two (exact up to one
//! unit of 2^-24 per level), so a step is additions, shifts and comparisons:
//! no division, no multiplication, no float. Negative directions are mirrored
//! about the root's centre so every axis runs forwards; a zero component is
//! nudged to one unit (2^-30). Crossings saturate at ±2^36 (a ray almost
//! parallel to an axis); a middle plane next to a saturated one gets its
//! crossing computed directly, as the mean would be meaningless. Empty
//! leaves are passed over, and boxes the ray enters after the nearest hit
//! found so far are skipped whole.
//!
//! The walk is one loop that calls the caller's visit for each non-empty
//! leaf, so the box being walked stays in registers; a box's ancestors wait
//! on a stack, one frame a level. The boxes' corners, needed only for the
//! middles of saturated axes, are carried only by the walks that have one
//! (a second copy of the loop, chosen once per ray).
//!
//! None of this can change an image: the walked line differs from the true
//! ray by at most two Q16.16 units across the scene and the parameters by far
//! less, both well inside the filing margin, and objects are still tested
//! with the true ray.

use super::Octree;
use super::OctreeCapacities;
use crate::capacity::Arena;
use crate::math::{mul_u64_shr24, mul_u64_shr24_clamped, reciprocal_q62};
use crate::shapes::Ray;

/// Parameters are Q40.24.
const FRAC: u32 = 24;
/// Saturation bound: 2^36 in Q40.24.
const LIMIT: i64 = 1 << (36 + FRAC);
/// Direction components (Q2.30) at least this large cannot saturate a
/// crossing; smaller ones (below 2^-16) take the clamped path.
const STEEP: u64 = 1 << 14;

/// What a ray's walk computes once: its origin and reciprocals in mirrored
/// space and the span where its objects can be.
#[derive(Clone, Copy, Debug)]
struct Setup {
    /// Octant bits of the mirrored axes.
    mirror: u8,
    /// Octant bits of the axes whose root crossings saturated (the ray runs
    /// almost parallel to them); on every other axis all crossings inside
    /// the root are exact and middle planes are plain means.
    saturated: u8,
    /// The ray's origin in mirrored space and 2^62 / |d_a|.
    origin: [i64; 3],
    inverse: [u64; 3],
    /// Where the ray is inside the objects' own bounds (tighter than the
    /// cubic root) and not behind its origin: boxes left before `begin` or
    /// entered after `far` hold nothing this ray can hit.
    begin: i64,
    far: i64,
}

impl Setup {
    /// The parameter (Q40.24, saturated) at which the ray crosses the plane
    /// at `plane` (mirrored space) on axis `a`: (plane − o)·2^38 / |d|
    /// through the reciprocal 2^62 / |d|.
    #[inline]
    fn crossing(&self, a: usize, plane: i64) -> i64 {
        mul_u64_shr24_clamped::<LIMIT>(plane - self.origin[a], self.inverse[a])
    }

    /// [`Setup::crossing`] on an axis with |d_a| ≥ [`STEEP`]: planes and the
    /// mirrored origin (i32 points, mirrored about a centre inside the root)
    /// are well within 2^36 of each other and 2^62 / |d_a| is at most 2^48,
    /// so the crossing stays below 2^60 = `LIMIT` without a clamp.
    #[inline]
    fn steep_crossing(&self, a: usize, plane: i64) -> i64 {
        debug_assert!((plane - self.origin[a]).unsigned_abs() < 1 << 36);
        mul_u64_shr24(plane - self.origin[a], self.inverse[a])
    }
}

/// What a box carries besides its crossings: nothing on rays with no
/// saturated axis, its corner on the others.
trait Corner: Copy {
    /// The corner of child `octant` (mirrored octant bits).
    fn child(self, octant: u8) -> Self;
    /// The crossing of the box's middle plane on axis `a`, given its outer
    /// planes' crossings.
    fn middle(&self, setup: &Setup, a: usize, t0: i64, t1: i64) -> i64;
}

/// No saturated axis: every middle plane's crossing is the mean of the outer
/// ones (exact up to one unit a level).
impl Corner for () {
    #[inline]
    fn child(self, _: u8) -> Self {}
    #[inline]
    fn middle(&self, _: &Setup, _: usize, t0: i64, t1: i64) -> i64 {
        (t0 + t1) >> 1
    }
}

/// A box's low corner (mirrored space) and log2 of its side.
#[derive(Clone, Copy, Debug)]
struct BoxCorner {
    lo: [i64; 3],
    log2: u32,
}

/// A saturated axis: where an outer crossing saturated the mean would be
/// meaningless, so the middle plane's crossing is computed directly.
impl Corner for BoxCorner {
    #[inline]
    fn child(self, octant: u8) -> Self {
        let half = 1i64 << (self.log2 - 1);
        let lo = [0, 1, 2].map(|a| self.lo[a] + if octant >> a & 1 == 1 { half } else { 0 });
        BoxCorner { lo, log2: self.log2 - 1 }
    }
    #[inline]
    fn middle(&self, setup: &Setup, a: usize, t0: i64, t1: i64) -> i64 {
        if setup.saturated >> a & 1 == 1 && (t0.abs() == LIMIT || t1.abs() == LIMIT) {
            setup.crossing(a, self.lo[a] + (1i64 << (self.log2 - 1)))
        } else {
            (t0 + t1) >> 1
        }
    }
}

/// A subdivided box being walked: its planes' crossing parameters and the
/// next child to visit.
#[derive(Clone, Copy, Debug)]
struct Frame<K> {
    t0: [i64; 3],
    tm: [i64; 3],
    t1: [i64; 3],
    corner: K,
    children: u32,
    /// The next child to visit, in mirrored octant order; 8 when done.
    next: u8,
}

impl<K: Corner> Frame<K> {
    /// Enters a subdivided box that the ray enters at `entry`: the first
    /// child the ray meets lies beyond every middle plane crossed before
    /// the entry. A ray that starts inside the box (or whose objects'
    /// bounds begin inside it) starts at the child holding that point
    /// instead: the children before it end before the walk begins.
    #[inline]
    fn enter(setup: &Setup, t0: [i64; 3], t1: [i64; 3], entry: i64, corner: K, children: u32) -> Self {
        let tm = [0, 1, 2].map(|a| corner.middle(setup, a, t0[a], t1[a]));
        let begin = entry.max(setup.begin);
        let next = (tm[0] < begin) as u8 | ((tm[1] < begin) as u8) << 1 | ((tm[2] < begin) as u8) << 2;
        Frame { t0, tm, t1, corner, children, next }
    }
}

#[inline]
fn max_axis(t: &[i64; 3]) -> usize {
    if t[0] >= t[1] {
        if t[0] >= t[2] {
            0
        } else {
            2
        }
    } else if t[1] >= t[2] {
        1
    } else {
        2
    }
}

#[inline]
fn min_axis(t: &[i64; 3]) -> usize {
    if t[0] <= t[1] {
        if t[0] <= t[2] {
            0
        } else {
            2
        }
    } else if t[1] <= t[2] {
        1
    } else {
        2
    }
}

/// Visits, in ray order, the non-empty leaves along `ray` that it enters no
/// later than the current stop (Q40.24; `stop` at first), calling
/// `visit(leaf, exit)` with the parameter at which the ray leaves the leaf.
/// `visit` returns the new stop (the nearest hit so far) or `None` to end
/// the walk. Boxes entered after the stop are skipped whole, with every box
/// behind them in the same parent (children are visited in ray order).
#[inline]
pub(super) fn walk<C: OctreeCapacities, const FRAMES: usize>(
    tree: &Octree<C, FRAMES>,
    ray: &Ray,
    stop: i64,
    mut visit: impl FnMut(u32, i64) -> Option<i64>,
) {
    let Some(root) = tree.nodes.as_slice().first().filter(|r| r.count() != 0) else { return };
    let Some((setup, t0, t1)) = set_up(tree, ray) else { return };
    let entry = t0[max_axis(&t0)];
    if !root.is_internal() {
        let _ = visit(0, t1[min_axis(&t1)]);
    } else if setup.saturated == 0 {
        let frame = Frame::enter(&setup, t0, t1, entry, (), root.first());
        descend(tree, &setup, frame, stop, &mut visit);
    } else {
        let corner = BoxCorner { lo: tree.root_min, log2: tree.root_log2 };
        let frame = Frame::enter(&setup, t0, t1, entry, corner, root.first());
        descend(tree, &setup, frame, stop, &mut visit);
    }
}

/// The ray's set-up and the root's crossings, or `None` when the ray misses
/// the root or the objects' bounds.
// Always inlined: returned by value, its 100-odd bytes were copied twice
// with memcpy (and zeroed first) on the Cortex-M0.
#[inline(always)]
fn set_up<C: OctreeCapacities, const FRAMES: usize>(
    tree: &Octree<C, FRAMES>,
    ray: &Ray,
) -> Option<(Setup, [i64; 3], [i64; 3])> {
    let o = ray.origin.wide();
    let d = ray.dir.wide();
    let mut setup = Setup { mirror: 0, saturated: 0, origin: [0; 3], inverse: [0; 3], begin: 0, far: 0 };
    let mut t0 = [0; 3];
    let mut t1 = [0; 3];
    for a in 0..3 {
        // Mirror a negative axis about the root's centre.
        setup.origin[a] = if d[a] < 0 {
            setup.mirror |= 1 << a;
            tree.root_min[a] + tree.root_max[a] - o[a]
        } else {
            o[a]
        };
        setup.inverse[a] = reciprocal_q62(d[a].unsigned_abs() as u32);
        if d[a].unsigned_abs() >= STEEP {
            t0[a] = setup.steep_crossing(a, tree.root_min[a]);
            t1[a] = setup.steep_crossing(a, tree.root_max[a]);
        } else {
            t0[a] = setup.crossing(a, tree.root_min[a]);
            t1[a] = setup.crossing(a, tree.root_max[a]);
            if t0[a].abs() == LIMIT || t1[a].abs() == LIMIT {
                setup.saturated |= 1 << a;
            }
        }
    }
    let enter = t0[max_axis(&t0)];
    let exit = t1[min_axis(&t1)];
    if enter >= exit || exit < 0 {
        return None;
    }
    // Clip to the objects' own bounds (rounding outwards: a wider span only
    // visits more boxes). Their low corner is the root's, so on each axis
    // one of the two crossings is the root's, known already.
    let (mut near, mut far) = (-LIMIT, LIMIT);
    for a in 0..3 {
        let bound = |plane| match d[a].unsigned_abs() >= STEEP {
            true => setup.steep_crossing(a, plane),
            false => setup.crossing(a, plane),
        };
        let (lo, hi) = if setup.mirror >> a & 1 == 1 {
            (bound(tree.root_min[a] + tree.root_max[a] - tree.bounds_max[a]), t1[a])
        } else {
            (t0[a], bound(tree.bounds_max[a]))
        };
        near = near.max(lo);
        far = far.min(hi);
    }
    let (near, far) = (near - 1, far + 1);
    if far < near || far < 0 {
        return None;
    }
    (setup.begin, setup.far) = (near.max(0), far);
    Some((setup, t0, t1))
}

/// The walk below a subdivided root; see [`walk`].
#[inline]
fn descend<K: Corner, C: OctreeCapacities, const FRAMES: usize>(
    tree: &Octree<C, FRAMES>,
    setup: &Setup,
    root: Frame<K>,
    stop: i64,
    visit: &mut impl FnMut(u32, i64) -> Option<i64>,
) {
    let nodes = tree.nodes.as_slice();
    // The box being walked is `current`; its ancestors wait here (the tree
    // is at most FRAMES − 1 deep, so a push cannot fail).
    let mut ancestors = heapless::Vec::<Frame<K>, FRAMES>::new();
    let mut current = root;
    let mut limit = stop.min(setup.far);
    loop {
        let c = current.next;
        if c == 8 {
            match ancestors.pop() {
                Some(parent) => current = parent,
                None => return,
            }
            continue;
        }
        // The child's crossings: its parent's low and middle planes' on the
        // axes where it is the low half, the middle and high ones elsewhere.
        let high = |a: usize| c >> a & 1 == 1;
        let t0 = [0, 1, 2].map(|a| if high(a) { current.tm[a] } else { current.t0[a] });
        let entry = t0[0].max(t0[1]).max(t0[2]);
        if entry > limit {
            current.next = 8;
            continue;
        }
        let t1 = [0, 1, 2].map(|a| if high(a) { current.t1[a] } else { current.tm[a] });
        // The sibling the ray enters next: across the child's nearest far
        // plane, unless that plane is the parent's own.
        let axis = min_axis(&t1);
        let bit = 1u8 << axis;
        current.next = if c & bit != 0 { 8 } else { c | bit };
        let exit = t1[axis];
        if exit < setup.begin {
            continue; // wholly behind the origin, or before the objects
        }
        let node = current.children + (c ^ setup.mirror) as u32;
        let n = nodes[node as usize];
        if n.is_internal() {
            let child = Frame::enter(setup, t0, t1, entry, current.corner.child(c), n.first());
            // A box with no child left to visit need not wait for this one.
            if current.next != 8 {
                let _ = ancestors.push(current);
            }
            current = child;
        } else if n.count() != 0 {
            match visit(node, exit) {
                Some(s) => limit = s.min(setup.far),
                None => return,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    /// Unclamped crossings on steep axes are the clamped ones, and never
    /// reach the clamp: at the bounds and at random points between.
    #[test]
    fn steep_crossings_need_no_clamp() {
        let mut next = crate::test_rng::seeded(0x5eed_0c7a);
        let extremes = [(1i64 << 36) - 1, -(1 << 36) + 1, 0, 1, -1];
        for i in 0..100_000 {
            let d = if i < 5 { STEEP } else { STEEP + next() % ((1 << 30) - STEEP + 1) };
            let x = if i < 5 { extremes[i] } else { (next() % (1 << 37)) as i64 - (1 << 36) };
            let inverse = reciprocal_q62(d as u32);
            let exact = mul_u64_shr24_clamped::<LIMIT>(x, inverse);
            assert_eq!(mul_u64_shr24(x, inverse), exact, "x {x}, d {d}");
            assert!(exact.abs() < LIMIT, "x {x}, d {d}");
        }
    }
}
