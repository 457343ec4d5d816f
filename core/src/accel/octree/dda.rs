//! octrace's walk: an integer 3DDDA over the octree's leaves with location
//! codes, the integer form of the thesis's point-location walk.
//!
//! Negative directions are mirrored about the root's centre, so every axis
//! runs forwards, and positions are integers relative to the root's low
//! corner: a box at depth `k` holds the points whose coordinates agree with
//! its own in their top `k` bits (of `root_log2`), and those bits, one per
//! axis and level, are the octants on the way down from the root (Frisken
//! and Perry 2002). The walk stands in one leaf at a time. Per axis it takes
//! the parameter (Q40.24) at which the ray crosses the leaf's far plane, one
//! product with the ray's reciprocal of |d_a| (31 bits scaled by a power of
//! two: no division, and one 32×32→64 product on a Cortex-M0), and leaves
//! across the plane met first (Amanatides and Woo's step). The next point is
//! that plane exactly on its axis and the ray's position there on the
//! others, held inside the leaf left and never behind the point before it;
//! the deepest box holding both points is named by the highest bit in which
//! their coordinates differ, and the next leaf is found from there down. So
//! a step costs a few products and the levels between the two leaves, with
//! no stack: the walk keeps one node index a level.
//!
//! Every step moves one coordinate forward to a plane and none back, so the
//! walk ends (after at most 3·2^depth steps). Empty leaves are passed over,
//! and the walk ends at the first leaf entered after the nearest hit found
//! so far.
//!
//! None of this can change an image: a position differs from the true
//! ray's by at most seven units (Q16.16) on each axis, inside the filing
//! margin (32), and objects are still tested with the true ray. Two are the
//! roundings; the reciprocal, within 2^-30.9 of 2^62 / |d_a| relatively,
//! moves a crossing by that share of its distance from the origin along the
//! axis (below 2^33 units: at most 4.3; a normalised scene's below 2^31: 1.1).

use super::Octree;
use super::OctreeCapacities;
use crate::capacity::Arena;
use crate::math::{
    leading_zeros_u32, mul_u32_wide, mul_u64_shr24, mul_u64_shr24_clamped, reciprocal_estimate, shl_u64, ARMV6M,
};
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
    /// The ray's origin in mirrored space, relative to the root's low
    /// corner, and its |d_a| (Q2.30).
    origin: [i64; 3],
    direction: [u64; 3],
    /// 2^62 / |d_a| ≈ `reciprocal · 2^(shift − 1)` ([`reciprocal_estimate`]).
    reciprocal: [u32; 3],
    shift: [u32; 3],
    /// Where the ray is inside the objects' own bounds (tighter than the
    /// cubic root) and not behind its origin: boxes left before `begin` or
    /// entered after `far` hold nothing this ray can hit.
    begin: i64,
    far: i64,
}

impl Setup {
    /// The parameter (Q40.24, saturated) at which the ray crosses the plane
    /// at `plane` (mirrored space, relative to the root) on axis `a`:
    /// (plane − o)·2^38 / |d| through the reciprocal, rounded down.
    // Out of line on ARMv6-M (the `cfg` of `math::ARMV6M`), its wide form
    // apart: the one product's path then keeps its registers (fig5_3 on the
    // Pico −0.9 %); inlined into the walk it ran out of them (+0.5 %).
    // Elsewhere the compiler's choice (forced out of line, the
    // MPS2-AN385's fig5_3 +3.6 %).
    #[cfg_attr(all(target_arch = "arm", not(target_has_atomic = "32")), inline(never))]
    #[cfg_attr(not(all(target_arch = "arm", not(target_has_atomic = "32"))), inline)]
    fn crossing(&self, a: usize, plane: i64) -> i64 {
        let gap = plane - self.origin[a];
        if ARMV6M && self.direction[a] >= STEEP {
            if let Some(t) = crossing_by_one_product(gap, self.reciprocal[a], self.shift[a]) {
                return t;
            }
        }
        self.crossing_wide(a, gap)
    }

    /// [`Setup::crossing`] of a gap `plane − o`, from 64-bit products (on
    /// ARMv6-M, for what the one product cannot take: rare).
    #[cfg_attr(all(target_arch = "arm", not(target_has_atomic = "32")), cold, inline(never))]
    #[cfg_attr(not(all(target_arch = "arm", not(target_has_atomic = "32"))), inline)]
    fn crossing_wide(&self, a: usize, gap: i64) -> i64 {
        let (reciprocal, shift) = (self.reciprocal[a], self.shift[a]);
        if self.direction[a] >= STEEP {
            // Planes and the origin (i32 points, mirrored about a centre
            // inside the root) are well within 2^36 of each other and the
            // reciprocal at most 2^48 (`shift` ≤ 17), so the crossing stays
            // below 2^60 = `LIMIT` without a clamp.
            debug_assert!(gap.unsigned_abs() < 1 << 36 && shift <= 17);
            mul_u64_shr24(gap, shl_u64(reciprocal as u64, shift - 1))
        } else {
            mul_u64_shr24_clamped::<LIMIT>(gap, shl_u64(reciprocal as u64, shift - 1))
        }
    }

    /// The ray's coordinate on axis `a` at parameter `t` (mirrored space,
    /// relative to the root; rounded down, and one unit lower at most where
    /// `t` is rounded to Q16.16 first).
    #[inline]
    fn position(&self, a: usize, t: i64) -> i64 {
        // t·|d| / 2^38 from one 32-bit product: t (Q40.24, ≥ 0) is here at
        // most the span of the objects' bounds from the origin, below 2^16
        // scene units (2^32 in Q16.16), and |d| at most 2^30.
        let t = (t >> 8).clamp(0, u32::MAX as i64) as u32;
        self.origin[a] + (mul_u32_wide(t, self.direction[a] as u32) >> 30) as i64
    }
}

/// `⌊gap · reciprocal · 2^(shift − 1) / 2^24⌋` for `shift` in 1 ..= 17 from
/// one 32×32→64 product, when `|gap|` is below 2^32 (any normalised
/// scene's); `None` otherwise.
#[inline(always)]
fn crossing_by_one_product(gap: i64, reciprocal: u32, shift: u32) -> Option<i64> {
    let magnitude = u32::try_from(gap.unsigned_abs()).ok()?;
    let product = mul_u32_wide(magnitude, reciprocal);
    // A negative gap rounds towards −∞: its magnitude rounds up (the sum
    // stays below 2^64, as the product is below (2^32 − 1)^2).
    let down = 25 - shift;
    let product = if gap >= 0 { product } else { product + ((1u32 << down) - 1) as u64 };
    // Shifted right by 8 to 24 in 32-bit halves (a variable 64-bit shift
    // is a library call on a 32-bit core).
    let (high, low) = ((product >> 32) as u32, product as u32);
    let shifted = (((high >> down) as u64) << 32) | ((high << (32 - down)) | (low >> down)) as u64;
    Some(if gap >= 0 { shifted as i64 } else { -(shifted as i64) })
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
/// the walk.
#[inline]
pub(super) fn walk<C: OctreeCapacities, const FRAMES: usize>(
    tree: &Octree<C, FRAMES>,
    ray: &Ray,
    stop: i64,
    mut visit: impl FnMut(u32, i64) -> Option<i64>,
) {
    let nodes = tree.nodes.as_slice();
    if nodes.first().is_none_or(|root| root.count() == 0) {
        return;
    }
    let Some(setup) = set_up(tree, ray) else { return };
    // Coordinates relative to the root fit a u32: its side is at most 2^31
    // (the build keeps a wider root whole).
    let log2 = tree.root_log2;
    let last = (tree.root_max[0] - tree.root_min[0] - 1) as u32;
    let mut limit = stop.min(setup.far);
    // Where the walk stands: a point of the current leaf, entered at
    // `entry`, and the node of every box holding it down to the leaf at
    // `level` (the tree is at most FRAMES − 1 deep). The point's bits are
    // the ray's down to depth `known` on the axes in `stale`, and all of
    // them on the others; a descent below `known` computes the rest.
    let mut entry = setup.begin;
    let mut point = [0, 1, 2].map(|a| setup.position(a, entry).clamp(0, last as i64) as u32);
    let (mut stale, mut known) = (0u8, 0u32);
    let mut path = [0u32; FRAMES];
    let mut level = 0;
    // The current leaf's far planes and where the ray crosses them.
    let mut far_plane = [0; 3];
    let mut exit_at = [0; 3];
    loop {
        let mut node = path[level];
        let mut box_ = nodes[node as usize];
        while box_.is_internal() {
            level += 1;
            let depth = level as u32;
            if depth > known && stale != 0 {
                // On those axes the ray at `entry` is in the slab of depth
                // `known` that holds the point, and not behind it.
                let side = log2 - known;
                for a in 0..3 {
                    if stale >> a & 1 == 1 {
                        let end = ((point[a] >> side) + 1) << side;
                        point[a] = setup.position(a, entry).clamp(point[a] as i64, end as i64 - 1) as u32;
                    }
                }
                stale = 0;
            }
            let bit = log2 - depth;
            let octant = (point[0] >> bit & 1) | (point[1] >> bit & 1) << 1 | (point[2] >> bit & 1) << 2;
            node = box_.first() + (octant ^ setup.mirror as u32);
            path[level] = node;
            box_ = nodes[node as usize];
        }
        // The leaf's far planes, and the one the ray crosses first.
        let side = log2 - level as u32;
        for a in 0..3 {
            let plane = ((point[a] >> side) + 1) << side;
            // A crossing is a product: without a multiplier for it (ARMv6-M)
            // one of a plane the last leaf shared is kept.
            if !ARMV6M || plane != far_plane[a] {
                far_plane[a] = plane;
                exit_at[a] = setup.crossing(a, plane as i64);
            }
        }
        let axis = min_axis(&exit_at);
        let exit = exit_at[axis];
        if box_.count() != 0 {
            match visit(node, exit) {
                Some(s) => limit = s.min(setup.far),
                None => return,
            }
        }
        if exit > limit || far_plane[axis] > last {
            return;
        }
        // Across that plane; on the other axes the ray stays in the leaf's
        // slab, so their bits hold down to the leaf's depth.
        let before = point[axis];
        point[axis] = far_plane[axis];
        (stale, known) = (0b111 ^ 1 << axis, level as u32);
        entry = exit;
        // The deepest box holding both points: its children differ in the
        // highest bit in which the points do.
        level = (log2 + leading_zeros_u32(before ^ point[axis]) - 32) as usize;
    }
}

/// The ray's set-up, or `None` when the ray misses the objects' bounds.
// Always inlined: returned by value, its bytes were copied with memcpy (and
// zeroed first) on the Cortex-M0.
#[inline(always)]
fn set_up<C: OctreeCapacities, const FRAMES: usize>(tree: &Octree<C, FRAMES>, ray: &Ray) -> Option<Setup> {
    let o = ray.origin.wide();
    let d = ray.dir.wide();
    let mut setup =
        Setup { mirror: 0, origin: [0; 3], direction: [0; 3], reciprocal: [0; 3], shift: [0; 3], begin: 0, far: 0 };
    // Clip to the objects' own bounds (rounding outwards: a wider span only
    // visits more boxes). Their low corner is the root's; mirrored, their
    // high corner is.
    let (mut near, mut far) = (-LIMIT, LIMIT);
    for a in 0..3 {
        let bound = tree.bounds_max[a] - tree.root_min[a];
        let root = tree.root_max[a] - tree.root_min[a];
        let (lo, hi) = if d[a] < 0 {
            setup.mirror |= 1 << a;
            setup.origin[a] = tree.root_max[a] - o[a];
            (root - bound, root)
        } else {
            setup.origin[a] = o[a] - tree.root_min[a];
            (0, bound)
        };
        setup.direction[a] = d[a].unsigned_abs();
        (setup.reciprocal[a], setup.shift[a]) = reciprocal_estimate(d[a].unsigned_abs() as u32);
        // An origin past the low plane crosses it at a parameter ≤ 0, which
        // cannot move the walk's start (it is clamped to 0) nor reject a
        // ray that `far` does not.
        if setup.origin[a] < lo {
            near = near.max(setup.crossing(a, lo));
        }
        far = far.min(setup.crossing(a, hi));
    }
    let (near, far) = (near - 1, far + 1);
    if far < near || far < 0 {
        return None;
    }
    (setup.begin, setup.far) = (near.max(0), far);
    Some(setup)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    /// Unclamped crossings on steep axes are the clamped ones, and never
    /// reach the clamp; the Cortex-M0's one product gives them for every
    /// gap below 2^32: at the bounds and at random points between.
    #[test]
    fn steep_crossings_need_no_clamp() {
        let mut next = crate::test_rng::seeded(0x5eed_0c7a);
        let extremes = [(1i64 << 36) - 1, -(1 << 36) + 1, 0, 1, -1, (1 << 32) - 1, -(1 << 32) + 1, 1 << 32];
        for i in 0..200_000 {
            let d = if i < extremes.len() { STEEP } else { STEEP + next() % ((1 << 30) - STEEP + 1) };
            let x = match extremes.get(i) {
                Some(&x) => x,
                None if i % 2 == 0 => (next() % (1 << 37)) as i64 - (1 << 36),
                None => (next() % (1 << 33)) as i64 - (1 << 32),
            };
            let (reciprocal, shift) = reciprocal_estimate(d as u32);
            let inverse = shl_u64(reciprocal as u64, shift - 1);
            let exact = mul_u64_shr24_clamped::<LIMIT>(x, inverse);
            assert_eq!(mul_u64_shr24(x, inverse), exact, "x {x}, d {d}");
            assert!(exact.abs() < LIMIT, "x {x}, d {d}");
            if let Some(t) = crossing_by_one_product(x, reciprocal, shift) {
                assert_eq!(t, exact, "x {x}, d {d}");
            } else {
                assert!(x.unsigned_abs() >= 1 << 32, "x {x}");
            }
        }
    }

    /// On random trees and rays (from outside and inside, along the axes
    /// and nearly so), the walk visits every non-empty leaf that the ray
    /// crosses inside the objects' bounds for more than a few units
    /// (positions round by one), in ray order.
    #[test]
    fn the_walk_visits_every_leaf_the_ray_crosses_in_order() {
        use super::super::query::for_each_leaf;
        use super::super::{OctreeConfig, Traversal};
        use crate::math::{Dir, Vec3};
        use crate::parse::parse;
        use crate::profile::Board64K;
        use crate::scene::Scene;
        use std::{boxed::Box, format, string::String, vec::Vec};
        // The test's own reference is plain f64 geometry.
        const SHRINK: f64 = 4.0;
        let mut next = crate::test_rng::seeded(0x1ea5_c0de);
        for _ in 0..100 {
            let mut text = String::from("SURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 0 0 0\n");
            for _ in 0..1 + next() % 24 {
                let radius = ["0.25", "0.5", "1", "2"][(next() % 4) as usize];
                let c = [0, 1, 2].map(|_| next() % 21).map(|v| v as i64 - 10);
                text += &format!("SPHERE 1 {radius} {} {} {}\n", c[0], c[1], c[2]);
            }
            let mut scene: Box<Scene<Board64K>> = Box::default();
            parse(&text, &mut scene, &mut |e| panic!("{e}")).unwrap();
            let view = scene.view();
            let mut tree: Box<Octree<Board64K>> = Box::default();
            let config = OctreeConfig {
                max_objects: 1 + (next() % 3) as usize,
                max_depth: 2 + (next() % 6) as u32,
                traversal: Traversal::Dda,
                ..OctreeConfig::DEFAULT
            };
            tree.build(&view, &config);
            // Every non-empty leaf's box.
            let mut leaves = Vec::new();
            for_each_leaf(tree.nodes.as_slice(), (0, tree.root_min, tree.root_log2), &mut |node, lo, log2| {
                if tree.nodes.as_slice()[node as usize].count() != 0 {
                    leaves.push((node, lo, lo.map(|v| v + (1 << log2))));
                }
            });
            let side = tree.root_max[0] - tree.root_min[0];
            for _ in 0..200 {
                let origin = [0, 1, 2].map(|a| {
                    let v = tree.root_min[a] - side + (next() % (3 * side as u64)) as i64;
                    v.clamp(i32::MIN as i64, i32::MAX as i64) as i32
                });
                // Mostly aimed at a point of some non-empty leaf; some
                // components zeroed or made tiny: rays along the planes.
                let (_, lo, hi) = leaves[(next() % leaves.len() as u64) as usize];
                let d = [0, 1, 2].map(|a| {
                    let target = lo[a] + (next() % (hi[a] - lo[a]) as u64) as i64;
                    match next() % 8 {
                        0 => 0,
                        1 => (next() % 16) as i64 - 8,
                        _ => target - origin[a] as i64,
                    }
                });
                let Some(dir) = Dir::normalize(d) else { continue };
                let ray = Ray { origin: Vec3::from_bits(origin), dir };
                let mut visited = Vec::new();
                walk(&tree, &ray, i64::MAX, |leaf, exit| {
                    visited.push((leaf, exit));
                    Some(i64::MAX)
                });
                assert!(visited.windows(2).all(|w| w[0].1 <= w[1].1), "exits out of order: {visited:?}");
                let o = ray.origin.wide().map(|v| v as f64);
                let d = ray.dir.wide().map(|v| v as f64 / (1u64 << 30) as f64);
                for &(node, lo, hi) in &leaves {
                    // Where the ray is inside the leaf and the objects'
                    // bounds, both shrunk, and ahead of its origin.
                    let (mut enter, mut leave) = (SHRINK, f64::INFINITY);
                    for a in 0..3 {
                        let low = lo[a].max(tree.root_min[a]) as f64 + SHRINK;
                        let high = hi[a].min(tree.bounds_max[a]) as f64 - SHRINK;
                        if d[a] == 0.0 {
                            if o[a] <= low || o[a] >= high {
                                leave = f64::NEG_INFINITY;
                            }
                            continue;
                        }
                        let (t0, t1) = ((low - o[a]) / d[a], (high - o[a]) / d[a]);
                        enter = enter.max(t0.min(t1));
                        leave = leave.min(t0.max(t1));
                    }
                    if enter < leave {
                        assert!(
                            visited.iter().any(|&(leaf, _)| leaf == node),
                            "ray {origin:?} {d:?} crosses leaf {node} over [{enter}, {leave}] unvisited"
                        );
                    }
                }
            }
        }
    }
}
