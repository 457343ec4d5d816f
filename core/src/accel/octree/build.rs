//! Building the octree: the root box around every object, boxes cut into
//! eight while they hold too many objects, objects filed by exact tests,
//! and (when asked) the shadow shafts marked.
//!
//! Invariant: an arena that runs out leaves the box being split a leaf, and
//! the report says so.

use super::query::for_each_leaf;
use super::*;

/// Where to put a box's objects and children while building.
struct Split {
    node: usize,
    depth: u32,
    name: u64,
    lo: [i64; 3],
    log2: u32,
    refs_start: usize,
    /// How many boxes in a row, ending with this one, hold every object of
    /// their parent.
    stale: u32,
}

/// Boxes in a row that may hold every object of their parent before the last
/// stays a leaf. A split that only carves off empty space still helps a
/// ray, so one or two are allowed; but objects that no split can part —
/// coincident ones, or surfaces meeting at a point such as the four tiles
/// and the base at a chessboard's corner — then stop here instead of being
/// filed down to the maximum depth around that point.
const MAX_STALE_SPLITS: u32 = 2;

impl<C: OctreeCapacities, const FRAMES: usize> Octree<C, FRAMES> {
    /// Builds the octree over `scene`'s objects.
    pub fn build(&mut self, scene: &SceneView<'_>, config: &OctreeConfig) -> BuildReport {
        self.nodes.clear();
        self.refs.clear();
        self.entries.clear();
        self.buckets.clear();
        self.shafts.clear();
        self.report = BuildReport::default();
        self.traversal = config.traversal;
        while self.buckets.push(C::Index::new(C::Index::MAX)).is_ok() {}

        let Some(bounds) = scene.object_ids().map(|id| scene.shape(id).bounds()).reduce(Aabb::union) else {
            // No objects: a single empty leaf.
            (self.root_min, self.root_max, self.root_log2, self.min_log2) = ([0; 3], [2; 3], 1, 1);
            self.bounds_max = [0; 3];
            let _ = self.nodes.push(OctreeNode::leaf(0, 0));
            self.finish(0);
            return self.report;
        };
        let (lo, hi) = (bounds.min.wide(), bounds.max.wide());
        let extent = (0..3).map(|a| hi[a] - lo[a]).max().unwrap_or(0) + 2 * FILING_MARGIN;
        self.root_log2 = 64 - (extent.max(2) as u64 - 1).leading_zeros();
        self.root_min = lo.map(|v| v - FILING_MARGIN);
        self.root_max = self.root_min.map(|v| v + (1i64 << self.root_log2));
        self.bounds_max = hi.map(|v| v + FILING_MARGIN);
        self.min_log2 = self.root_log2;

        let count = scene.object_count();
        let all_fit = (count as u64) < C::Index::MAX as u64 - 1
            && self.nodes.push(OctreeNode::leaf(0, 0)).is_ok()
            && (0..count).all(|i| self.refs.push(C::Index::new(i as u32)).is_ok());
        if !all_fit {
            // Not even the root's list fits: one leaf that stands for every
            // object (the walk then tests them all, as the naive mode does).
            self.nodes.clear();
            self.refs.clear();
            let _ = self.nodes.push(OctreeNode::leaf(0, C::Index::MAX - 1));
            self.report.unsplit = 1;
            self.report.exhausted = Some(if self.nodes.as_slice().is_empty() {
                CapacityKind::OctreeBoxes
            } else {
                CapacityKind::OctreeReferences
            });
            self.finish(0);
            return self.report;
        }
        // The 3DDDA's coordinates inside the root are u32s: a root wider
        // than 2^31 units (beyond the normalised range of every parsed
        // scene) stays one leaf.
        let max_depth =
            if self.root_log2 <= 31 { config.max_depth.min(MAX_DEPTH).min(FRAMES.saturating_sub(1) as u32) } else { 0 };
        let root =
            Split { node: 0, depth: 0, name: 1, lo: self.root_min, log2: self.root_log2, refs_start: 0, stale: 0 };
        self.split(scene, root, config.max_objects.max(1), max_depth, 0);
        if config.shadow_shafts {
            self.mark_clear_shafts(scene);
        }
        self.finish(max_depth);
        self.report
    }

    /// Files the box's objects (in `refs[refs_start..]`) into children, or
    /// makes it a leaf. `reserved` references are promised to boxes still
    /// waiting up the tree (siblings not yet filed), so this box's subtree
    /// never takes their room: when an arena runs short, a box stays a leaf
    /// instead, and nothing already filed is ever undone.
    fn split(&mut self, scene: &SceneView<'_>, s: Split, max_objects: usize, max_depth: u32, reserved: usize) {
        let count = self.refs.as_slice().len() - s.refs_start;
        self.report.peak_references = self.report.peak_references.max(self.refs.as_slice().len());
        let leaf = OctreeNode::leaf(s.refs_start as u32, count as u32);
        if count <= max_objects || s.depth >= max_depth || s.log2 <= 1 || s.stale >= MAX_STALE_SPLITS {
            self.nodes.as_mut_slice()[s.node] = leaf;
            self.min_log2 = self.min_log2.min(s.log2);
            return;
        }
        let half = 1i64 << (s.log2 - 1);
        let parent_end = s.refs_start + count;
        let cell = |octant: usize| {
            let lo = [0, 1, 2].map(|a| s.lo[a] + if octant >> a & 1 == 1 { half } else { 0 });
            (lo, Cell { lo: lo.map(|v| v - FILING_MARGIN), hi: lo.map(|v| v + half + FILING_MARGIN) })
        };
        // Count first, so that the room asked for is exact.
        let counts: [usize; 8] = core::array::from_fn(|octant| {
            let (_, c) = cell(octant);
            self.refs.as_slice()[s.refs_start..parent_end]
                .iter()
                .filter(|&&id| overlaps(scene.shape(ObjectId(id.get())), &c))
                .count()
        });
        let need: usize = counts.iter().sum();
        // The index type bounds every arena too (its top two values mark).
        let limit = |cap: usize| cap.min(C::Index::MAX as usize - 2);
        let room = |len: usize, cap: usize, need: usize| len + need <= limit(cap);
        // Hash entries are sized from the boxes (one per eight), so they run
        // out as the boxes do; a tree without a hash table (a profile
        // without the thesis's walk) needs none.
        let exhausted = if !room(self.nodes.as_slice().len(), C::Nodes::CAPACITY, 8)
            || (Self::HASHED && !room(self.entries.as_slice().len(), C::HashEntries::CAPACITY, 1))
        {
            Some(CapacityKind::OctreeBoxes)
        } else if !room(self.refs.as_slice().len() + reserved, C::References::CAPACITY, need) {
            Some(CapacityKind::OctreeReferences)
        } else {
            None
        };
        if let Some(what) = exhausted {
            self.nodes.as_mut_slice()[s.node] = leaf;
            self.min_log2 = self.min_log2.min(s.log2);
            self.report.unsplit += 1;
            self.report.exhausted.get_or_insert(what);
            return;
        }
        // The room this split asked for: an arena of the peak passes every
        // check a larger one passes, so it builds the very same tree.
        let asked = self.refs.as_slice().len() + reserved + need;
        self.report.peak_references = self.report.peak_references.max(asked);
        let children = self.nodes.as_slice().len();
        for _ in 0..8 {
            let _ = self.nodes.push(leaf);
        }
        if Self::HASHED {
            self.insert_entry(s.name, children as u32);
        }
        self.nodes.as_mut_slice()[s.node] = OctreeNode::internal(children as u32);
        let mut pending = need;
        for (octant, &n) in counts.iter().enumerate() {
            let (lo, c) = cell(octant);
            let start = self.refs.as_slice().len();
            for i in s.refs_start..parent_end {
                let id = self.refs.as_slice()[i];
                if overlaps(scene.shape(ObjectId(id.get())), &c) {
                    let _ = self.refs.push(id);
                }
            }
            pending -= n;
            let child = Split {
                node: children + octant,
                depth: s.depth + 1,
                name: s.name * 10 + 1 + octant as u64,
                lo,
                log2: s.log2 - 1,
                refs_start: start,
                stale: if n == count { s.stale + 1 } else { 0 },
            };
            self.split(scene, child, max_objects, max_depth, reserved + pending);
        }
        // This box's own list is no longer needed: slide its subtree's lists
        // down over it. The subtree is every node made after its children
        // (the build is depth first), so the fix-up is exact. Front to back,
        // as the lists only move down: `copy_within` would link `memmove`
        // (1.3 KiB of a board's flash) for it.
        let end = self.refs.as_slice().len();
        let refs = self.refs.as_mut_slice();
        for from in parent_end..end {
            refs[from - count] = refs[from];
        }
        self.refs.truncate(end - count);
        for node in &mut self.nodes.as_mut_slice()[children..] {
            if !node.is_internal() {
                *node = OctreeNode::leaf(node.first().saturating_sub(count as u32), node.count());
            }
        }
    }

    /// Finds every non-empty leaf's shadow shafts, when the arena holds one
    /// for every box.
    fn mark_clear_shafts(&mut self, scene: &SceneView<'_>) {
        let boxes = self.nodes.as_slice().len();
        if !Self::SHAFTS || scene.lights.is_empty() || (0..boxes).any(|_| self.shafts.push(ShadowShaft::NONE).is_err())
        {
            self.shafts.clear();
            return;
        }
        let (nodes, refs, shafts) = (self.nodes.as_slice(), self.refs.as_slice(), self.shafts.as_mut_slice());
        let root = (0, self.root_min, self.root_log2);
        let (mut clear, mut blockers) = (0, [u32::MAX; LIGHTS]);
        for_each_leaf(nodes, root, &mut |leaf, lo, log2| {
            let own = nodes[leaf as usize].list(refs);
            let found = shaft::of_leaf::<C>(nodes, refs, scene, root, (lo, log2), own, &mut blockers);
            clear += found.lights.count_ones() as usize;
            shafts[leaf as usize] = found;
        });
        self.report.clear_shafts = clear;
    }
}
