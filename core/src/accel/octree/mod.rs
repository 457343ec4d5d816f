//! The octree of the thesis's chapter 4, and two ways to walk it.
//!
//! *Build.* A cubic root box (a power of two in Q16.16 units) encloses every
//! object. A box is cut into eight equal children while it holds more than
//! `max_objects` and is shallower than `max_depth`. Boxes are named as in the
//! thesis: the root is 1, its children 11 … 18, the children of 15 are
//! 151 … 158 (digit = 1 + x + 2y + 4z, the octant's bits). A hash table keyed
//! by name (name mod table size, chained, as Glassner's) holds, for every
//! subdivided box, where its eight children are. Objects are filed by exact
//! tests against the box widened by [`FILING_MARGIN`].
//!
//! *Walks.* Both visit, in ray order, the leaves the ray passes through,
//! each with the parameter at which the ray leaves it:
//! - [`Traversal::Named`], the thesis's method, its parameters compared
//!   exactly as ratios of integers: from the exit point step by
//!   half of Minlen (the smallest box side) across the faces the ray leaves
//!   through, then find the leaf holding that point from the root, one hash
//!   lookup per level. (A full Minlen step lands exactly on the far face of a
//!   smallest neighbour, which exact arithmetic would then skip.)
//! - [`Traversal::Dda`], octrace's integer 3DDDA: the same steps, from leaf
//!   to leaf across the plane the ray meets first (Amanatides & Woo's step,
//!   one product a plane with the ray's reciprocal, parameters in Q40.24),
//!   with the next leaf found by the bits of integer coordinates (location
//!   codes, Frisken & Perry) from the deepest box holding both leaves: no
//!   hash lookups, no division after the ray's set-up, no stack (see
//!   `dda.rs`).
//!
//! *Shadow shafts* (`shaft.rs`, when the config asks and the profile has
//! room): per leaf and light, whether only the leaf's own objects come near
//! the hull of those objects and the light; a shadow ray from such a leaf
//! tests them and skips the walk, with the walk's answer.
//!
//! *Exactness.* A leaf's hits are final once the nearest is before the leaf's
//! exit (strictly: an equal hit in the next leaf may come earlier in the
//! file). With the filing margin wider than any rounding of a hit point,
//! every mode returns exactly the naive mode's hit.
//!
//! *Capacity.* When an arena runs out while building, the box being split
//! stays a leaf (with more objects): slower, never wrong. The
//! [`BuildReport`] says how often that happened.
//!
//! *Files.* `types.rs` the vocabulary (boxes, config, report, a leaf's
//! shadow shafts, capacities), `build.rs` the build, `hash.rs` the thesis's
//! hash table, `query.rs` the walks' common loop and the [`Accelerator`]
//! queries, `named.rs` and `dda.rs` the two walks, `overlap.rs` the exact
//! filing, `shaft.rs` finding the shadow shafts; this file the [`Octree`]
//! itself.

mod build;
mod dda;
mod hash;
mod named;
mod overlap;
mod query;
mod shaft;
mod types;

pub use overlap::{overlaps, Cell};
use types::LIGHTS;
pub use types::{
    BuildReport, HashEntry, Index, OctreeCapacities, OctreeConfig, OctreeNode, ShadowShaft, Traversal, FILING_MARGIN,
    MAX_DEPTH,
};

use super::{Accelerator, Hit, Mailbox, RayStart};
use crate::capacity::{Arena, CapacityKind};
use crate::math::Scalar;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Aabb, Ratio, Ray};

impl<C: OctreeCapacities, const FRAMES: usize> core::fmt::Debug for Octree<C, FRAMES> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Octree").field("report", self.report()).finish_non_exhaustive()
    }
}

/// The octree over one scene, in arenas sized by the profile `C`. `FRAMES`
/// bounds the depth of a walk (the tree is at most `FRAMES − 1` deep); the
/// 3DDDA keeps one node index per level on the stack.
///
/// Built over a parsed scene, it is an [`Accelerator`]; a loaded scene
/// traced with it gives the same image as without it (every
/// [`AccelMode`](crate::AccelMode) does):
///
/// ```
/// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*};
/// use octrace_core::{accel::Octree, parse::parse, profile::{Board16K, Profile}};
/// use octrace_core::{scene::Scene, AccelMode, Raytracer};
///
/// const TEXT: &str = "RASTER 8 8\nVIEWPOINT 0 0 5\nORIGIN 0 0 0\nUPVECTOR 0 1 0\nBACKGROUND 0 0 1\nLIGHT 10 5 5 5\nSPHERE 1 1.5 0 0 0\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n";
/// let mut scene = Scene::<Board16K>::new();
/// parse(TEXT, &mut scene, &mut |e| panic!("{e}")).unwrap();
/// let mut octree = Octree::<Board16K>::new();
/// let report = octree.build(&scene.view(), &Board16K::OCTREE);
/// assert_eq!(report.unsplit, 0, "the arenas were large enough");
///
/// let mut raytracer = Raytracer::<Board16K>::new();
/// let mut draw = |mode| {
///     let scene = raytracer.load_with(TEXT.as_bytes(), mode, &mut |e| panic!("{e}")).unwrap();
///     let mut display = MockDisplay::<Rgb888>::new();
///     Image::new(&scene.image_for(&display), Point::zero()).draw(&mut display).unwrap();
///     display
/// };
/// assert_eq!(draw(AccelMode::Dda), draw(AccelMode::Naive));
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
pub struct Octree<C: OctreeCapacities, const FRAMES: usize = { MAX_DEPTH as usize + 1 }> {
    nodes: C::Nodes,
    refs: C::References,
    entries: C::HashEntries,
    buckets: C::HashBuckets,
    /// Per box, the lights its shadow rays reach without a walk.
    shafts: C::ShadowShafts,
    /// The root box: `[root_min, root_max]`, `root_max = root_min +
    /// 2^root_log2` per axis (kept: a 64-bit shift by a variable is a
    /// library call on a small core, and every ray's set-up needs it).
    root_min: [i64; 3],
    root_max: [i64; 3],
    /// The objects' own upper bounds, widened by the filing margin (their
    /// lower bounds are `root_min`).
    bounds_max: [i64; 3],
    root_log2: u32,
    /// log2 of Minlen, the smallest box side.
    min_log2: u32,
    traversal: Traversal,
    report: BuildReport,
}

impl<C: OctreeCapacities, const FRAMES: usize> Default for Octree<C, FRAMES> {
    fn default() -> Self {
        Self::new()
    }
}

impl<C: OctreeCapacities, const FRAMES: usize> Octree<C, FRAMES> {
    /// Whether the tree keeps the thesis's hash table: not when its arena
    /// has no room at all (a profile without the thesis's walk, which alone
    /// reads it); [`Traversal::Named`] is then walked by 3DDDA.
    const HASHED: bool = C::HashEntries::CAPACITY > 0;

    /// Whether the tree may keep shadow shafts.
    const SHAFTS: bool = C::ShadowShafts::CAPACITY > 0;

    /// An empty octree (a constant: it can live in a `static`).
    pub const fn new() -> Self {
        Octree {
            nodes: C::Nodes::EMPTY,
            refs: C::References::EMPTY,
            entries: C::HashEntries::EMPTY,
            buckets: C::HashBuckets::EMPTY,
            shafts: C::ShadowShafts::EMPTY,
            root_min: [0; 3],
            root_max: [0; 3],
            bounds_max: [0; 3],
            root_log2: 0,
            min_log2: 0,
            traversal: Traversal::Dda,
            // Zero bits, field by field: an empty octree in a `static`
            // lands in `.bss`.
            report: BuildReport {
                nodes: 0,
                leaves: 0,
                references: 0,
                peak_references: 0,
                hash_entries: 0,
                depth: 0,
                unsplit: 0,
                exhausted: None,
                clear_shafts: 0,
                bytes: 0,
            },
        }
    }

    /// What the last build produced.
    pub fn report(&self) -> &BuildReport {
        &self.report
    }

    /// How rays walk the tree.
    pub fn traversal(&self) -> Traversal {
        self.traversal
    }

    /// Switches the walk without rebuilding.
    pub fn set_traversal(&mut self, t: Traversal) {
        self.traversal = t;
    }

    /// The walk rays take: the one set, but 3DDDA on a tree without the
    /// hash table the thesis's walk needs.
    pub fn walked_by(&self) -> Traversal {
        if Self::HASHED {
            self.traversal
        } else {
            Traversal::Dda
        }
    }
}

/// An [`Octree`] whatever its walk depth: what a profile's octree is.
pub trait OctreeStore: Accelerator {
    /// An empty octree.
    const EMPTY: Self;
    /// Whether it has room for any box (else every mode is the naive one).
    const HAS_BOXES: bool;
    /// Whether it has room for the thesis's hash table, which its walk
    /// ([`Traversal::Named`]) needs.
    const NAMED_WALK: bool;
    /// Builds the octree over `scene`'s objects (see [`Octree::build`]).
    fn build(&mut self, scene: &SceneView<'_>, config: &OctreeConfig) -> BuildReport;

    /// Whether it is walked by 3DDDA (the thesis's walk stays the thesis's
    /// for every ray, camera rays included).
    fn walked_by_dda(&self) -> bool;

    /// What its last build produced.
    fn report(&self) -> &BuildReport;
}

impl<C: OctreeCapacities, const FRAMES: usize> OctreeStore for Octree<C, FRAMES> {
    const EMPTY: Self = Octree::new();
    const HAS_BOXES: bool = C::Nodes::CAPACITY > 0;
    const NAMED_WALK: bool = C::HashBuckets::CAPACITY > 0;

    fn build(&mut self, scene: &SceneView<'_>, config: &OctreeConfig) -> BuildReport {
        Octree::build(self, scene, config)
    }

    fn walked_by_dda(&self) -> bool {
        self.walked_by() == Traversal::Dda
    }

    fn report(&self) -> &BuildReport {
        Octree::report(self)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::query::for_each_leaf;
    use super::query::walk_leaves;
    use super::*;
    use crate::math::Dir;
    use crate::parse::parse;
    use crate::profile::Board64K;
    use crate::scene::Scene;
    use std::boxed::Box;
    use std::format;
    use std::string::String;
    use std::vec::Vec;

    const SURF: &str = "SURFACE 1 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 0 0 0\n";

    fn scene(objects: &str) -> Box<Scene<Board64K>> {
        let mut s: Box<Scene<Board64K>> = Box::default();
        parse(&format!("{SURF}{objects}"), &mut s, &mut |e| panic!("{e}")).unwrap();
        s
    }

    /// A row of spheres along x.
    fn row(n: usize) -> String {
        (0..n).map(|i| format!("SPHERE 1 0.4 {} 0 0\n", i as i32 - n as i32 / 2)).collect()
    }

    crate::profile! {
        /// Exactly what the chessboard below needs, as its report says.
        struct Exact { spheres: 1, rectangles: 64, surfaces: 1, octree_boxes: 865, octree_references: 1288 }
    }

    #[test]
    fn a_profile_sized_from_the_report_builds_the_same_tree() {
        let squares: String = (0..64)
            .map(|i| {
                let (x, z) = (i % 8 - 4, i / 8 - 4);
                format!("RECTANGLE 1 {x} 0 {z} {} 0 {z} {} 0 {} {x} 0 {}\n", x + 1, x + 1, z + 1, z + 1)
            })
            .collect();
        let text = format!("{SURF}{squares}SPHERE 1 1 0 1 0\n");
        let config = OctreeConfig::DEFAULT;
        let roomy = scene(&text[SURF.len()..]);
        let mut tree: Box<Octree<Board64K>> = Box::default();
        let report = tree.build(&roomy.view(), &config);
        assert_eq!(report.unsplit, 0);
        let exact_counts = <Exact as crate::profile::Profile>::COUNTS;
        let octree = (exact_counts.octree_boxes, exact_counts.octree_references);
        assert_eq!((report.counts().octree_boxes, report.counts().octree_references), octree, "update Exact");
        let mut exact: Box<Scene<Exact>> = Box::default();
        parse(&text, &mut exact, &mut |e| panic!("{e}")).unwrap();
        let mut small: Box<Octree<Exact>> = Box::default();
        // The same tree; only the hash table's size (bytes) differs.
        assert_eq!(BuildReport { bytes: 0, ..small.build(&exact.view(), &config) }, BuildReport { bytes: 0, ..report });
        assert_eq!(small.nodes.as_slice(), tree.nodes.as_slice());
    }

    #[test]
    fn boxes_are_named_as_in_the_thesis_and_found_by_hash() {
        let s = scene(&row(12));
        let mut tree: Box<Octree<Board64K>> = Box::default();
        let report = tree.build(
            &s.view(),
            &OctreeConfig { max_objects: 2, max_depth: 6, traversal: Traversal::Named, ..OctreeConfig::DEFAULT },
        );
        assert!(report.depth >= 2 && report.unsplit == 0, "{report:?}");
        // The root is 1 and its children are found under that name.
        assert_eq!(tree.lookup(1), Some(tree.nodes.as_slice()[0].first()));
        // Every subdivided box is in the table under its decimal name: walk
        // the tree by names and compare with the child indices.
        let mut stack = Vec::from([(0u32, 1u64)]);
        let mut subdivided = 0;
        while let Some((node, name)) = stack.pop() {
            let n = tree.nodes.as_slice()[node as usize];
            if !n.is_internal() {
                continue;
            }
            subdivided += 1;
            assert_eq!(tree.lookup(name), Some(n.first()), "box {name}");
            for k in 0..8u32 {
                stack.push((n.first() + k, name * 10 + 1 + k as u64));
            }
        }
        assert_eq!(subdivided, report.hash_entries);
        assert_eq!(tree.lookup(19), None, "no digit 9");
    }

    #[test]
    fn every_leaf_holds_exactly_the_objects_that_touch_it() {
        let s = scene(&row(9));
        let view = s.view();
        let mut tree: Box<Octree<Board64K>> = Box::default();
        tree.build(
            &view,
            &OctreeConfig { max_objects: 1, max_depth: 5, traversal: Traversal::Dda, ..OctreeConfig::DEFAULT },
        );
        let mut references = 0;
        for_each_leaf(tree.nodes.as_slice(), (0, tree.root_min, tree.root_log2), &mut |node, lo, log2| {
            let objects = tree.leaf_objects(node).unwrap();
            references += objects.len();
            let cell = Cell { lo: lo.map(|v| v - FILING_MARGIN), hi: lo.map(|v| v + (1 << log2) + FILING_MARGIN) };
            for id in view.object_ids() {
                let filed = objects.iter().any(|o| o.get() == id.0);
                assert_eq!(filed, overlaps(view.shape(id), &cell), "leaf {node}, object {id:?}");
            }
        });
        assert_eq!(references, tree.report().references, "compaction kept every list");
    }

    /// Calls `f(node, low corner, log2 of the side)` for every leaf below
    /// `node`, a box with that corner and side.
    #[test]
    fn objects_meeting_at_a_point_stop_the_split_there() {
        // Four squares meeting at the origin, on a base: every box around
        // the corner holds all five, however small. Each such box may be
        // split twice more, not down to the maximum depth (depth 12 before).
        let squares: String = [(-1, -1), (0, -1), (0, 0), (-1, 0)]
            .iter()
            .map(|&(x, z)| format!("RECTANGLE 1 {x} 0 {z} {} 0 {z} {} 0 {} {x} 0 {}\n", x + 1, x + 1, z + 1, z + 1))
            .collect();
        let s = scene(&format!("{squares}BOX 1 0 -0.25 0 1 0.25 1\n"));
        let mut tree: Box<Octree<Board64K>> = Box::default();
        let report = tree.build(
            &s.view(),
            &OctreeConfig { max_objects: 4, max_depth: 12, traversal: Traversal::Dda, ..OctreeConfig::DEFAULT },
        );
        assert!(report.depth <= 4, "{report:?}");
    }

    #[test]
    fn running_out_of_room_leaves_boxes_unsplit() {
        use crate::profile::Board16K;
        let mut s: Box<Scene<Board16K>> = Box::default();
        let text = format!("{SURF}{}", row(60));
        parse(&text, &mut s, &mut |e| panic!("{e}")).unwrap();
        let mut tree: Box<Octree<Board16K>> = Box::default();
        let report = tree.build(
            &s.view(),
            &OctreeConfig { max_objects: 1, max_depth: 12, traversal: Traversal::Dda, ..OctreeConfig::DEFAULT },
        );
        assert!(report.unsplit > 0 && report.exhausted.is_some(), "{report:?}");
        assert!(report.nodes <= 400);
    }

    /// 3DDDA skips what lies outside the objects' own bounds; otherwise both
    /// walks meet the same non-empty leaves in the same order.
    #[test]
    fn both_walks_visit_the_same_leaves_in_ray_order() {
        let s = scene(&row(16));
        let view = s.view();
        let mut tree: Box<Octree<Board64K>> = Box::default();
        tree.build(
            &view,
            &OctreeConfig { max_objects: 1, max_depth: 6, traversal: Traversal::Dda, ..OctreeConfig::DEFAULT },
        );
        let eye = view.normalization.point([-20 << 32, 1 << 29, 1 << 28]);
        for d in [[1i64, 0, 0], [3, -1, 0], [1, 1, 1], [5, 0, -1], [1, 0, 1 << 20]] {
            let ray = Ray { origin: eye, dir: Dir::normalize(d).unwrap() };
            let mut visits = [Vec::new(), Vec::new()];
            for (i, t) in [Traversal::Dda, Traversal::Named].into_iter().enumerate() {
                tree.set_traversal(t);
                let mut m = Mailbox::none();
                walk_leaves(&tree, &ray, &mut m, Scalar::MAX, |leaf, exit, _| {
                    if tree.leaf_objects(leaf).is_some_and(|o| !o.is_empty()) {
                        visits[i].push(leaf);
                    }
                    let _ = exit;
                    Some(Scalar::MAX)
                });
            }
            let mut named = visits[1].iter();
            assert!(visits[0].iter().all(|leaf| named.any(|n| n == leaf)), "{d:?}: {visits:?}");
            if d[1] == 0 && d[2] == 0 {
                assert_eq!(visits[0], visits[1], "along the row");
                assert!(visits[0].len() > 8);
            }
        }
    }
}
