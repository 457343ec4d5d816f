//! Rays through the octree: the leaves along a ray in order (by either
//! walk), the nearest hit and the shadow test.
//!
//! Invariant: a leaf's hit is final only once it comes before the leaf's
//! exit, so every mode returns exactly the naive mode's hit.

use super::named::NamedWalk;
use super::*;

/// Where the ray leaves a leaf: an exact ratio (the thesis's walk) or a
/// Q40.24 parameter (3DDDA).
#[derive(Clone, Copy, Debug)]
pub(super) enum Exit {
    Ratio(Ratio),
    Q24(i64),
}

impl Exit {
    /// Whether `t` comes strictly before the exit.
    #[inline]
    fn after(self, t: Scalar) -> bool {
        match self {
            Exit::Ratio(r) => !r.le_scalar(t),
            Exit::Q24(e) => to_q24(t) < e,
        }
    }
}

#[inline]
fn to_q24(t: Scalar) -> i64 {
    (t.to_bits() as i64) << 8
}

/// Visits the leaves along `ray` with `visit(leaf, exit)`, which
/// returns the parameter beyond which nothing matters any more (the nearest
/// hit so far, or the shadow ray's end), or `None` to stop.
#[inline]
pub(super) fn walk_leaves<C: OctreeCapacities, const FRAMES: usize>(
    tree: &Octree<C, FRAMES>,
    ray: &Ray,
    mailbox: &mut Mailbox<'_>,
    stop: Scalar,
    mut visit: impl FnMut(u32, Exit, &mut Mailbox<'_>) -> Option<Scalar>,
) {
    match tree.walked_by() {
        Traversal::Dda => dda::walk(tree, ray, to_q24(stop), |leaf, exit| {
            mailbox.cells += 1;
            visit(leaf, Exit::Q24(exit), mailbox).map(to_q24)
        }),
        Traversal::Named => {
            // The thesis's walk visits every leaf until a hit is final.
            let mut walk = NamedWalk::new(tree, ray);
            while let Some((leaf, exit)) = walk.next_leaf(tree) {
                mailbox.cells += 1;
                if visit(leaf, Exit::Ratio(exit), mailbox).is_none() {
                    return;
                }
            }
        }
    }
}

impl<C: OctreeCapacities, const FRAMES: usize> Octree<C, FRAMES> {
    /// The leaf holding `point` (by the bits of its coordinates relative to
    /// the root), when the point is inside the root.
    #[inline]
    fn leaf_at(&self, point: [i64; 3]) -> Option<u32> {
        let side = self.root_max[0] - self.root_min[0];
        let relative = [0, 1, 2].map(|a| point[a] - self.root_min[a]);
        if relative.iter().any(|&v| v < 0 || v >= side) {
            return None;
        }
        let relative = relative.map(|v| v as u32);
        let nodes = self.nodes.as_slice();
        let (mut node, mut bit) = (0u32, self.root_log2);
        while nodes[node as usize].is_internal() {
            bit -= 1;
            let octant = (relative[0] >> bit & 1) | (relative[1] >> bit & 1) << 1 | (relative[2] >> bit & 1) << 2;
            node = nodes[node as usize].first() + octant;
        }
        Some(node)
    }

    /// Whether object `id` blocks a shadow ray (first tested in this query),
    /// leaving it in the mailbox's `blocker` when so.
    // Always inlined: a call per object tested costs more than the test's
    // set-up (spheres600's shadow rays: 5 % of the time).
    #[inline(always)]
    pub(super) fn blocks(
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
        id: u32,
    ) -> bool {
        let hit = mailbox.first_visit(id) && {
            let object = ObjectId(id);
            let leaving = RayStart::leaving(start, object);
            scene.intersect_handle(C::KINDS, scene.objects[id as usize], ray, t_max, leaving).is_some()
        };
        if hit {
            mailbox.blocker = id;
        }
        hit
    }

    /// The object ids filed in leaf `node` (`None` for the all-objects leaf).
    pub(super) fn leaf_objects(&self, node: u32) -> Option<&[C::Index]> {
        let n = self.nodes.as_slice()[node as usize];
        if n.count() == C::Index::MAX - 1 {
            return None;
        }
        Some(n.list(self.refs.as_slice()))
    }
}

/// Whether `leaf(node, lo, log2)` holds for a leaf of the subtree at
/// `node` (box `[lo, lo + 2^log2]`), visiting only the boxes that
/// `enter(box, lo, log2)` admits, nearest `toward` first (its own octant,
/// then those differing in one axis, …), and stopping at the first.
pub(super) fn any_leaf<I: Index>(
    nodes: &[OctreeNode<I>],
    (node, lo, log2): (u32, [i64; 3], u32),
    toward: [i64; 3],
    enter: &impl Fn(OctreeNode<I>, [i64; 3], u32) -> bool,
    leaf: &mut impl FnMut(u32, [i64; 3], u32) -> bool,
) -> bool {
    let n = nodes[node as usize];
    if !enter(n, lo, log2) {
        return false;
    }
    if !n.is_internal() {
        return leaf(node, lo, log2);
    }
    let half = 1i64 << (log2 - 1);
    let nearest = (0..3).map(|a| ((toward[a] >= lo[a] + half) as u32) << a).sum::<u32>();
    [0, 1, 2, 4, 3, 5, 6, 7].into_iter().any(|k: u32| {
        let octant = k ^ nearest;
        let corner = [0, 1, 2].map(|a| lo[a] + if octant >> a & 1 == 1 { half } else { 0 });
        any_leaf(nodes, (n.first() + octant, corner, log2 - 1), toward, enter, leaf)
    })
}

/// Calls `f(leaf, lo, log2)` for every leaf of the subtree at `node`.
pub(super) fn for_each_leaf<I: Index>(
    nodes: &[OctreeNode<I>],
    root: (u32, [i64; 3], u32),
    f: &mut impl FnMut(u32, [i64; 3], u32),
) {
    any_leaf(nodes, root, root.1, &|_, _, _| true, &mut |node, lo, log2| {
        f(node, lo, log2);
        false
    });
}

// The queries are not inlined: each walk then lives in its own stack frame
// for the query's duration only, instead of two of them sitting in every
// caller's frame — it matters on a 16 KiB board.
impl<C: OctreeCapacities, const FRAMES: usize> Accelerator for Octree<C, FRAMES> {
    #[inline(never)]
    fn nearest(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> Option<Hit> {
        let mut best = Hit::NONE;
        walk_leaves(self, ray, mailbox, Scalar::MAX, |leaf, exit, mailbox| {
            let mut test = |id: u32| {
                if !mailbox.first_visit(id) {
                    return;
                }
                let object = ObjectId(id);
                let leaving = RayStart::leaving(start, object);
                if let Some(t) = scene.intersect_handle(C::KINDS, scene.objects[id as usize], ray, best.t, leaving) {
                    let hit = Hit { t, object };
                    if hit.beats(&best) {
                        best = hit;
                    }
                }
            };
            match self.leaf_objects(leaf) {
                Some(ids) => ids.iter().for_each(|&id| test(id.get())),
                None => (0..scene.object_count() as u32).for_each(test),
            }
            // Final once strictly before the exit: an equal hit in the next
            // leaf might belong to an earlier object.
            if best.found().is_some() && exit.after(best.t) {
                None
            } else {
                Some(best.t)
            }
        });
        best.found()
    }

    #[inline(never)]
    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        let mut blocked = false;
        walk_leaves(self, ray, mailbox, t_max, |leaf, exit, mailbox| {
            let mut test = |id: u32| Self::blocks(scene, ray, t_max, start, mailbox, id);
            blocked = match self.leaf_objects(leaf) {
                Some(ids) => ids.iter().any(|&id| test(id.get())),
                None => (0..scene.object_count() as u32).any(test),
            };
            (!blocked && !exit.after(t_max)).then_some(t_max)
        });
        blocked
    }

    /// From a leaf whose shaft to the light is clear, only the leaf's own
    /// objects are tested; otherwise the walk of [`Accelerator::occluded`].
    #[inline(never)]
    fn occluded_toward(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        light: usize,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        if Self::SHAFTS && light < LIGHTS {
            if let Some(leaf) = self.leaf_at(ray.origin.wide()) {
                if self.shafts.as_slice().get(leaf as usize).is_some_and(|s| s.clear(ray.origin.bits(), light)) {
                    mailbox.cells += 1;
                    // A leaf with bits has its own list (not the one that
                    // stands for every object).
                    let ids = self.leaf_objects(leaf).unwrap_or_default();
                    return ids.iter().any(|&id| Self::blocks(scene, ray, t_max, start, mailbox, id.get()));
                }
            }
        }
        self.occluded(scene, ray, t_max, start, mailbox)
    }
}
