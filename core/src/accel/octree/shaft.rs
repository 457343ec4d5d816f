//! Shadow shafts: for each leaf and light, whether nothing but the leaf's
//! own objects can block a shadow ray from the leaf to the light (Haines and
//! Wallace's shaft culling), so that such a ray tests those objects and
//! skips the walk.
//!
//! A shadow ray leaves from a point on an object, and that object is filed
//! in the leaf holding the point; so a leaf's rays start in its *source*:
//! the leaf's box cut to its objects' bounds, widened by the filing margin
//! (a ray starting elsewhere, as from a smooth triangle's lifted point,
//! takes the walk). The shaft to a light is the convex hull of the source
//! and the light's point: the boxes `(1 − s)·source + s·light` for `s` in
//! `[0, 1]`. A box meets the hull exactly when one `s` satisfies the six
//! linear inequalities of overlapping one of those boxes, solved as
//! fractions (i128 products, exact). A leaf's bit for a light is set only
//! when no object outside its list has bounds meeting its shaft once
//! widened by the filing margin, more than a shadow ray strays from the
//! exact segment (a unit or two) plus a hit point from its surface (about
//! 8); the octree's boxes, widened as much, prune the search. So a set bit
//! gives a shadow ray from the source the walk's own answer.
//!
//! Invariants: shafts are found at build time and never change a query's
//! answer, only its cost; lights past the 32nd (the bits of a `u32`), empty
//! leaves and the leaf that stands for every object get none.

use super::query::any_leaf;
use super::{Index, OctreeCapacities, OctreeNode, ShadowShaft, FILING_MARGIN, LIGHTS};
use crate::scene::{ObjectId, SceneView};

/// A leaf's shaft towards a light: its source and the light.
#[derive(Clone, Copy, Debug)]
struct Shaft {
    low: [i64; 3],
    high: [i64; 3],
    light: [i64; 3],
}

impl Shaft {
    /// Whether the box `[lo, hi]` meets the shaft (exactly).
    fn meets(&self, lo: [i64; 3], hi: [i64; 3]) -> bool {
        // Most boxes miss the hull's own bounding box: a cheap test first.
        if (0..3).any(|a| hi[a] < self.low[a].min(self.light[a]) || lo[a] > self.high[a].max(self.light[a])) {
            return false;
        }
        // The s for which the shaft's cross-section overlaps the box on
        // every axis, kept as the fractions low ≤ s ≤ high (numerator,
        // positive denominator; products of two i64s in i128), starting
        // from [0, 1]. Each overlap condition is s·d ≤ k: the section's low
        // side below the box's high side, and its high side above the box's
        // low side.
        let product = |a: i64, b: i64| a as i128 * b as i128;
        let (mut low, mut high) = ((0i64, 1i64), (1i64, 1i64));
        for a in 0..3 {
            let conditions = [
                (self.light[a] - self.low[a], hi[a] - self.low[a]),
                (self.high[a] - self.light[a], self.high[a] - lo[a]),
            ];
            for (d, k) in conditions {
                if d > 0 {
                    if product(k, high.1) < product(high.0, d) {
                        high = (k, d);
                    }
                } else if d < 0 {
                    if product(-k, low.1) > product(low.0, -d) {
                        low = (-k, -d);
                    }
                } else if k < 0 {
                    return false;
                }
            }
            if product(low.0, high.1) > product(high.0, low.1) {
                return false;
            }
        }
        true
    }
}

/// The shadow shafts of the leaf with the box `[lo, lo + 2^log2]` and the
/// objects `own`, searching the tree from `root`. `blockers` holds, per
/// light, the object that blocked the last leaf's shaft (`u32::MAX`: none):
/// neighbouring leaves are mostly blocked by the same one, tried first.
pub(super) fn of_leaf<C: OctreeCapacities>(
    nodes: &[OctreeNode<C::Index>],
    refs: &[C::Index],
    scene: &SceneView<'_>,
    root: (u32, [i64; 3], u32),
    (lo, log2): ([i64; 3], u32),
    own: &[C::Index],
    blockers: &mut [u32; LIGHTS],
) -> ShadowShaft {
    let bounds = |id: C::Index| scene.shape(ObjectId(id.get())).bounds();
    let Some(objects) = own.iter().map(|&id| bounds(id)).reduce(crate::shapes::Aabb::union) else {
        return ShadowShaft::NONE;
    };
    let (min, max) = (objects.min.wide(), objects.max.wide());
    let low = [0, 1, 2].map(|a| (min[a] - FILING_MARGIN).max(lo[a]));
    let high = [0, 1, 2].map(|a| (max[a] + FILING_MARGIN).min(lo[a] + (1 << log2)));
    let widened = |lo: [i64; 3], hi: [i64; 3]| [lo.map(|v| v - FILING_MARGIN), hi.map(|v| v + FILING_MARGIN)];
    let mut lights = 0;
    for ((index, light), blocker) in scene.lights.iter().take(LIGHTS).enumerate().zip(blockers) {
        let shaft = Shaft { low, high, light: light.position.wide() };
        let blocks = |id: C::Index| {
            !own.contains(&id) && {
                let b = bounds(id);
                let [lo, hi] = widened(b.min.wide(), b.max.wide());
                shaft.meets(lo, hi)
            }
        };
        if *blocker != u32::MAX && blocks(C::Index::new(*blocker)) {
            continue;
        }
        // Empty leaves need no test.
        let near = |node: OctreeNode<C::Index>, lo: [i64; 3], log2: u32| {
            let [lo, hi] = widened(lo, lo.map(|v| v + (1 << log2)));
            (node.is_internal() || node.count() != 0) && shaft.meets(lo, hi)
        };
        let blocked = any_leaf(nodes, root, low, &near, &mut |leaf, _, _| {
            let found = nodes[leaf as usize].list(refs).iter().find(|&&id| blocks(id));
            found.map(|id| *blocker = id.get()).is_some()
        });
        if !blocked {
            lights |= 1 << index;
        }
    }
    let clamp = |v: [i64; 3]| v.map(|c| c.clamp(i32::MIN as i64, i32::MAX as i64) as i32);
    ShadowShaft { lights, low: clamp(low), high: clamp(high) }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    /// Against f64 sampling of the hull's cross-sections: a box that one
    /// sampled section overlaps meets the shaft, and a box said to meet it
    /// is overlapped by a section at a nearby s once widened by a unit (a
    /// section moves less than that between samples).
    #[test]
    fn a_box_meets_the_shaft_when_a_cross_section_overlaps_it() {
        // The test's own reference is plain f64 sampling; the shafts
        // themselves are integers only.
        let seed = 0x5_4af7;
        let mut next = crate::test_rng::seeded(seed);
        let mut coordinate = move |span: u64| (next() % span) as i64 - (span / 2) as i64;
        let mut met = 0;
        for _ in 0..20_000 {
            let low = [0, 1, 2].map(|_| coordinate(64));
            let high = low.map(|v| v + coordinate(64).abs());
            let shaft = Shaft { low, high, light: [0, 1, 2].map(|_| coordinate(256)) };
            let lo = [0, 1, 2].map(|_| coordinate(128));
            let hi = [0, 1, 2].map(|a| lo[a] + coordinate(64).abs());
            let overlapped = |steps: u32, widen: i64| {
                (0..=steps).any(|i| {
                    let s = i as f64 / steps as f64;
                    (0..3).all(|a| {
                        let section = |side: i64| (1.0 - s) * side as f64 + s * shaft.light[a] as f64;
                        section(shaft.low[a]) <= (hi[a] + widen) as f64
                            && section(shaft.high[a]) >= (lo[a] - widen) as f64
                    })
                })
            };
            let exact = shaft.meets(lo, hi);
            assert!(!overlapped(256, 0) || exact, "seed {seed:#x}: {shaft:?} misses [{lo:?}, {hi:?}]");
            assert!(!exact || overlapped(4096, 1), "seed {seed:#x}: {shaft:?} said to meet [{lo:?}, {hi:?}]");
            met += exact as usize;
        }
        assert!(met > 1000 && met < 19_000, "seed {seed:#x}: both answers exercised ({met})");
    }
}
