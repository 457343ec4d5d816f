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
//! crossing computed directly, as the mean would be meaningless. Empty leaves are passed over, and boxes the
//! ray enters after the nearest hit found so far are skipped whole.
//!
//! None of this can change an image: the walked line differs from the true
//! ray by at most two Q16.16 units across the scene and the parameters by far
//! less, both well inside the filing margin, and objects are still tested
//! with the true ray.

use super::Octree;
use super::OctreeCapacities;
use crate::capacity::Arena;
use crate::math::{mul_u64_shr24_clamped, reciprocal_q62};
use crate::shapes::Ray;

/// Parameters are Q40.24.
const FRAC: u32 = 24;
/// Saturation bound: 2^36 in Q40.24.
const LIMIT: i64 = 1 << (36 + FRAC);

/// A box being walked: its planes' crossing parameters and the next child.
#[derive(Clone, Copy, Debug)]
struct Frame {
    t0: [i64; 3],
    tm: [i64; 3],
    t1: [i64; 3],
    /// The box's low corner (mirrored space) and log2 of its side. The
    /// corner is kept up to date only when an axis saturated (the one use of
    /// it); otherwise it stays the root's.
    lo: [i64; 3],
    log2: u32,
    children: u32,
    /// The next child to visit, in mirrored octant order; 8 when done.
    next: u8,
}

pub(super) struct DdaWalk<const FRAMES: usize> {
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
    /// cubic root): boxes left before `near` or entered after `far` hold
    /// nothing this ray can hit.
    near: i64,
    far: i64,
    stack: heapless::Vec<Frame, FRAMES>,
    /// A root that is itself a leaf, still to be returned.
    root_leaf: Option<(u32, i64)>,
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

impl<const FRAMES: usize> DdaWalk<FRAMES> {
    pub const fn new() -> Self {
        DdaWalk {
            mirror: 0,
            saturated: 0,
            origin: [0; 3],
            inverse: [0; 3],
            near: 0,
            far: 0,
            stack: heapless::Vec::new(),
            root_leaf: None,
        }
    }

    /// Starts a walk along `ray` (in place: the walk's stack is not small).
    pub fn start<C: OctreeCapacities>(&mut self, tree: &Octree<C, FRAMES>, ray: &Ray) {
        self.mirror = 0;
        self.saturated = 0;
        self.stack.clear();
        self.root_leaf = None;
        let walk = self;
        let nodes = tree.nodes.as_slice();
        let Some(root) = nodes.first().filter(|r| r.count() != 0) else { return };
        let o = ray.origin.wide();
        let d = ray.dir.wide();
        let half = 1i64 << (tree.root_log2 - 1);
        let mut t0 = [0; 3];
        let mut t1 = [0; 3];
        for a in 0..3 {
            let centre = tree.root_min[a] + half;
            // Mirror a negative axis about the root's centre.
            let oa = if d[a] < 0 {
                walk.mirror |= 1 << a;
                2 * centre - o[a]
            } else {
                o[a]
            };
            walk.origin[a] = oa;
            walk.inverse[a] = reciprocal_q62(d[a].unsigned_abs() as u32);
            t0[a] = walk.crossing(a, tree.root_min[a]);
            t1[a] = walk.crossing(a, tree.root_min[a] + 2 * half);
            if t0[a].abs() == LIMIT || t1[a].abs() == LIMIT {
                walk.saturated |= 1 << a;
            }
        }
        let enter = t0[max_axis(&t0)];
        let exit = t1[min_axis(&t1)];
        if enter >= exit || exit < 0 {
            return;
        }
        // Clip to the objects' own bounds (rounding outwards: a wider span
        // only visits more boxes). Their low corner is the root's, so on
        // each axis one of the two crossings is the root's, known already.
        let (mut near, mut far) = (-LIMIT, LIMIT);
        for a in 0..3 {
            let (lo, hi) = if walk.mirror >> a & 1 == 1 {
                let c2 = 2 * (tree.root_min[a] + half);
                (walk.crossing(a, c2 - tree.bounds_max[a]), t1[a])
            } else {
                (t0[a], walk.crossing(a, tree.bounds_max[a]))
            };
            near = near.max(lo);
            far = far.min(hi);
        }
        (walk.near, walk.far) = (near - 1, far + 1);
        if walk.far < walk.near || walk.far < 0 {
            return;
        }
        if !root.is_internal() {
            walk.root_leaf = Some((0, exit));
        } else {
            walk.push(root.first(), t0, t1, tree.root_min, tree.root_log2);
        }
    }

    /// The parameter (Q40.24, saturated) at which the ray crosses the plane
    /// at `plane` (mirrored space) on axis `a`: (plane − o)·2^38 / |d|
    /// through the reciprocal 2^62 / |d|.
    #[inline]
    fn crossing(&self, a: usize, plane: i64) -> i64 {
        mul_u64_shr24_clamped::<LIMIT>(plane - self.origin[a], self.inverse[a])
    }

    /// Enters a subdivided box: the first child the ray meets lies beyond
    /// every middle plane crossed before the entry plane. A ray that starts
    /// inside the box (or whose objects' bounds begin inside it) starts at
    /// the child holding that point instead: the children before it end
    /// before the walk begins, and the walk would pass over them one by one.
    #[inline]
    fn push(&mut self, children: u32, t0: [i64; 3], t1: [i64; 3], lo: [i64; 3], log2: u32) {
        let tm = if self.saturated == 0 {
            [0, 1, 2].map(|a| (t0[a] + t1[a]) >> 1)
        } else {
            [0, 1, 2].map(|a| self.middle(a, t0[a], t1[a], lo[a], log2))
        };
        let entry_axis = max_axis(&t0);
        let entry = t0[entry_axis];
        let begin = entry.max(self.near).max(0);
        let mut first = 0u8;
        for a in 0..3 {
            if tm[a] < begin && (a != entry_axis || begin > entry) {
                first |= 1 << a;
            }
        }
        let _ = self.stack.push(Frame { t0, tm, t1, lo, log2, children, next: first });
    }

    /// The crossing of a box's middle plane on axis `a`: the mean of the
    /// outer planes' crossings (exact: the mean plane's crossing), unless one
    /// of them saturated (a ray almost parallel to the axis), where the mean
    /// would be meaningless; then it is computed directly.
    #[inline]
    fn middle(&self, a: usize, t0: i64, t1: i64, lo: i64, log2: u32) -> i64 {
        if self.saturated >> a & 1 == 1 && (t0.abs() == LIMIT || t1.abs() == LIMIT) {
            self.crossing(a, lo + (1i64 << (log2 - 1)))
        } else {
            (t0 + t1) >> 1
        }
    }

    /// The next non-empty leaf along the ray that the ray enters no later
    /// than `stop` (Q40.24), and the parameter at which the ray leaves it.
    /// Boxes entered after `stop` are skipped whole, with every box behind
    /// them in the same parent (children are visited in ray order).
    #[inline]
    pub fn next_leaf<C: OctreeCapacities>(&mut self, tree: &Octree<C, FRAMES>, stop: i64) -> Option<(u32, i64)> {
        if let Some(leaf) = self.root_leaf.take() {
            return Some(leaf);
        }
        let nodes = tree.nodes.as_slice();
        loop {
            let top = self.stack.last_mut()?;
            let c = top.next;
            if c == 8 {
                self.stack.pop();
                continue;
            }
            let (mut t0, mut t1) = (top.t0, top.t1);
            for a in 0..3 {
                if c >> a & 1 == 1 {
                    t0[a] = top.tm[a];
                } else {
                    t1[a] = top.tm[a];
                }
            }
            if t0[max_axis(&t0)] > stop.min(self.far) {
                top.next = 8;
                continue;
            }
            // The sibling the ray enters next: across the child's nearest far
            // plane, unless that plane is the parent's own.
            let axis = min_axis(&t1);
            let bit = 1u8 << axis;
            top.next = if c & bit != 0 { 8 } else { c | bit };
            let node = top.children + (c ^ self.mirror) as u32;
            let exit = t1[axis];
            if exit < 0 || exit < self.near {
                continue; // wholly behind the origin, or before the objects
            }
            let n = nodes[node as usize];
            if n.is_internal() {
                // Corners are needed only for the middles of saturated axes.
                let lo = if self.saturated == 0 {
                    top.lo
                } else {
                    let half = 1i64 << (top.log2 - 1);
                    [0, 1, 2].map(|a| top.lo[a] + if c >> a & 1 == 1 { half } else { 0 })
                };
                let log2 = top.log2 - 1;
                self.push(n.first(), t0, t1, lo, log2);
            } else if n.count() != 0 {
                return Some((node, exit));
            }
        }
    }
}
