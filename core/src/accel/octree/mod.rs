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

mod dda;
mod named;
mod overlap;
mod shaft;

pub use overlap::{overlaps, Cell};
pub use shaft::ShadowShaft;

use super::{Accelerator, Hit, Mailbox, RayStart};
use crate::capacity::{Arena, CapacityKind, Counts};
use crate::math::Scalar;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Aabb, Ratio, Ray, ShapeKinds};
use named::NamedWalk;

/// Where the ray leaves a leaf: an exact ratio (the thesis's walk) or a
/// Q40.24 parameter (3DDDA).
#[derive(Clone, Copy, Debug)]
enum Exit {
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
fn walk_leaves<C: OctreeCapacities, const FRAMES: usize>(
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

/// How far (Q16.16 raw units) beyond a box an object still counts as in it:
/// more than any fixed-point error of a hit point (about 8 units).
pub const FILING_MARGIN: i64 = 32;
/// Box names are decimal, so they fit a `u64` up to this depth.
pub const MAX_DEPTH: u32 = 18;

/// A box of the octree: a leaf with its objects, or a subdivided box.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OctreeNode<I> {
    /// Leaf: index of the first object reference. Subdivided: index of the
    /// first of the eight children, which are consecutive.
    first: I,
    /// Leaf: number of objects. Subdivided: `I::MAX`; a leaf standing for
    /// every object (no room for lists): `I::MAX − 1`.
    count: I,
}

/// The node fields read and written as `u32`.
impl<I: Index> OctreeNode<I> {
    #[inline]
    fn leaf(first: u32, count: u32) -> Self {
        OctreeNode { first: I::new(first), count: I::new(count) }
    }
    #[inline]
    fn internal(children: u32) -> Self {
        OctreeNode { first: I::new(children), count: I::new(I::MAX) }
    }
    #[inline]
    pub(crate) fn is_internal(&self) -> bool {
        self.count.get() == I::MAX
    }
    #[inline]
    pub(crate) fn first(&self) -> u32 {
        self.first.get()
    }
    #[inline]
    pub(crate) fn count(&self) -> u32 {
        self.count.get()
    }
    /// A leaf's object list in `refs` (not for the leaf that stands for
    /// every object).
    #[inline]
    fn list<'r>(&self, refs: &'r [I]) -> &'r [I] {
        &refs[self.first() as usize..(self.first() + self.count()) as usize]
    }
}

/// The thesis's hash-table structure: a subdivided box's name and where its
/// eight children are, chained by `next` (`I::MAX`: end of the chain).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HashEntry<I> {
    name: u64,
    children: I,
    next: I,
}

/// How to walk the octree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Traversal {
    /// Integer 3DDDA over the leaves (first: an empty octree's bits are
    /// zero).
    Dda,
    /// The thesis's method: Minlen steps and hash-table point location.
    Named,
}

/// The subdivision criterion and the walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OctreeConfig {
    /// A box holding more objects than this is subdivided.
    pub max_objects: usize,
    /// Boxes deeper than this are not subdivided (at most [`MAX_DEPTH`], and
    /// below the octree's `FRAMES`).
    pub max_depth: u32,
    /// How rays walk the tree; every walk gives the same hits.
    pub traversal: Traversal,
    /// Whether to find, for each leaf and light, whether shadow rays from
    /// the leaf to the light can skip the walk (a [`ShadowShaft`], 28
    /// bytes, a box: see [`OctreeCapacities::ShadowShafts`]); the image is
    /// the same.
    pub shadow_shafts: bool,
}

impl OctreeConfig {
    /// At most 4 objects a leaf, 12 levels, the 3DDDA walk, no shadow
    /// shafts (a board's RAM is for the scene; the host profile turns them
    /// on).
    pub const DEFAULT: OctreeConfig =
        OctreeConfig { max_objects: 4, max_depth: 12, traversal: Traversal::Dda, shadow_shafts: false };
}

impl Default for OctreeConfig {
    fn default() -> Self {
        OctreeConfig::DEFAULT
    }
}

/// What a build produced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildReport {
    /// Boxes in the tree, leaves included.
    pub nodes: usize,
    /// Boxes holding objects with no children.
    pub leaves: usize,
    /// Object references filed in the leaves.
    pub references: usize,
    /// Object references the build needed at its peak: an arena of exactly
    /// this many builds the same tree.
    pub peak_references: usize,
    /// Entries of the hash table that finds a box's children.
    pub hash_entries: usize,
    /// The deepest level reached (the root is level 0).
    pub depth: u32,
    /// Boxes left unsplit because an arena was full (0 when all went well).
    pub unsplit: usize,
    /// The capacity that ran out first, if any.
    pub exhausted: Option<CapacityKind>,
    /// Pairs of a leaf and a light whose shadow rays skip the walk: nothing
    /// but the leaf's own objects is near their shaft (0 in a profile
    /// without room for them, see [`OctreeCapacities::ShadowShafts`]).
    pub clear_shafts: usize,
    /// Bytes of the structure (nodes, references, hash table, shafts).
    pub bytes: usize,
}

/// The integer type of the octree's indices: `u32` on hosts, `u16` on small
/// boards (half the RAM for the octree). Its largest two values are
/// reserved as markers.
pub trait Index: Copy + Eq + core::fmt::Debug + 'static {
    /// The largest value.
    const MAX: u32;
    /// `v` as an index; `v` must not exceed [`Index::MAX`].
    fn new(v: u32) -> Self;
    /// The index as a `u32`.
    fn get(self) -> u32;
}

impl Index for u16 {
    const MAX: u32 = u16::MAX as u32;
    #[inline]
    fn new(v: u32) -> u16 {
        v as u16
    }
    #[inline]
    fn get(self) -> u32 {
        self as u32
    }
}

impl Index for u32 {
    const MAX: u32 = u32::MAX;
    #[inline]
    fn new(v: u32) -> u32 {
        v
    }
    #[inline]
    fn get(self) -> u32 {
        self
    }
}

/// The arenas an [`Octree`] is stored in. Every profile implements it;
/// define one with [`crate::profile!`], which names counts, not these types.
pub trait OctreeCapacities {
    /// The shape kinds the profile's scenes can hold: the queries dispatch
    /// on these only (see [`Accelerator::KINDS`]).
    const KINDS: ShapeKinds = ShapeKinds::ALL;
    /// The index type (bounds the arenas and the objects it files).
    type Index: Index;
    /// Boxes (8 per subdivision, plus the root).
    type Nodes: Arena<OctreeNode<Self::Index>>;
    /// Object references of the leaves (an object in several leaves counts
    /// once per leaf), and working room while building.
    type References: Arena<Self::Index>;
    /// Hash-table entries: one per subdivided box (the thesis's structure
    /// holding the addresses of a box's eight children).
    type HashEntries: Arena<HashEntry<Self::Index>>;
    /// Hash-table buckets; the table size is this arena's capacity.
    type HashBuckets: Arena<Self::Index>;
    /// One [`ShadowShaft`] per box: the lights that shadow rays from the
    /// leaf reach testing only its own objects. Found when the config asks
    /// and the arena holds one for every box; a capacity of 0 leaves the
    /// shafts out (and their code).
    type ShadowShafts: Arena<ShadowShaft>;
}

impl<C: OctreeCapacities, const FRAMES: usize> core::fmt::Debug for Octree<C, FRAMES> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Octree").field("report", self.report()).finish_non_exhaustive()
    }
}

impl BuildReport {
    /// The octree counts of a profile that builds this very tree (see
    /// [`crate::parse::count`] for the scene's).
    pub fn counts(&self) -> Counts {
        Counts { octree_boxes: self.nodes, octree_references: self.peak_references, ..Counts::ZERO }
    }
}

/// The octree over one scene, in arenas sized by the profile `C`. `FRAMES`
/// bounds the depth of a walk (the tree is at most `FRAMES − 1` deep); the
/// 3DDDA keeps one node index per level on the stack.
///
/// Built over a parsed scene, it is an [`Accelerator`] for a
/// [`Renderer`](crate::render::Renderer); the image is the same as without it:
///
/// ```
/// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::Rgb888};
/// use octrace_core::{accel::{Naive, Octree}, parse::parse, profile::{Board16K, Profile}};
/// use octrace_core::{render::Renderer, scene::Scene};
///
/// let mut scene = Scene::<Board16K>::new();
/// parse("RASTER 8 8\nVIEWPOINT 0 0 5\nORIGIN 0 0 0\nUPVECTOR 0 1 0\nBACKGROUND 0 0 1\nLIGHT 10 5 5 5\nSPHERE 1 1.5 0 0 0\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n", &mut scene, &mut |e| panic!("{e}")).unwrap();
/// let mut octree = Octree::<Board16K>::new();
/// let report = octree.build(&scene.view(), &Board16K::OCTREE);
/// assert_eq!(report.unsplit, 0, "the arenas were large enough");
///
/// let mut with_octree = MockDisplay::<Rgb888>::new();
/// Renderer::new(scene.view(), &octree)?.render(&mut with_octree)?;
/// let mut without = MockDisplay::<Rgb888>::new();
/// Renderer::new(scene.view(), &Naive)?.render(&mut without)?;
/// assert_eq!(with_octree, without);
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
        // (the build is depth first), so the fix-up is exact.
        let end = self.refs.as_slice().len();
        self.refs.as_mut_slice().copy_within(parent_end..end, s.refs_start);
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
        let (mut clear, mut blockers) = (0, [u32::MAX; shaft::LIGHTS]);
        for_each_leaf(nodes, root, &mut |leaf, lo, log2| {
            let own = nodes[leaf as usize].list(refs);
            let found = shaft::of_leaf::<C>(nodes, refs, scene, root, (lo, log2), own, &mut blockers);
            clear += found.lights.count_ones() as usize;
            shafts[leaf as usize] = found;
        });
        self.report.clear_shafts = clear;
    }

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
    fn blocks(
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

    fn insert_entry(&mut self, name: u64, children: u32) {
        let none = C::Index::new(C::Index::MAX);
        let index = C::Index::new(self.entries.as_slice().len() as u32);
        let _ = self.entries.push(HashEntry { name, children: C::Index::new(children), next: none });
        let bucket = (name % self.buckets.as_slice().len() as u64) as usize;
        // Append at the end of the bucket's chain, as the thesis does.
        let mut at = self.buckets.as_slice()[bucket];
        if at == none {
            self.buckets.as_mut_slice()[bucket] = index;
            return;
        }
        loop {
            let next = self.entries.as_slice()[at.get() as usize].next;
            if next == none {
                self.entries.as_mut_slice()[at.get() as usize].next = index;
                return;
            }
            at = next;
        }
    }

    fn finish(&mut self, max_depth: u32) {
        let nodes = self.nodes.as_slice();
        self.report.nodes = nodes.len();
        self.report.leaves = nodes.iter().filter(|n| !n.is_internal()).count();
        self.report.references = self.refs.as_slice().len();
        self.report.hash_entries = self.entries.as_slice().len();
        self.report.depth = self.root_log2.saturating_sub(self.min_log2).min(max_depth);
        self.report.bytes = core::mem::size_of_val(nodes)
            + core::mem::size_of_val(self.refs.as_slice())
            + core::mem::size_of_val(self.shafts.as_slice())
            + core::mem::size_of_val(self.entries.as_slice())
            + core::mem::size_of_val(self.buckets.as_slice());
    }

    /// The children of the box called `name`, looked up in the hash table.
    fn lookup(&self, name: u64) -> Option<u32> {
        let buckets = self.buckets.as_slice();
        let mut at = buckets.get((name % buckets.len().max(1) as u64) as usize)?.get();
        while at != C::Index::MAX {
            let e = self.entries.as_slice().get(at as usize)?;
            if e.name == name {
                return Some(e.children.get());
            }
            at = e.next.get();
        }
        None
    }

    /// The object ids filed in leaf `node` (`None` for the all-objects leaf).
    fn leaf_objects(&self, node: u32) -> Option<&[C::Index]> {
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

/// An [`Octree`] whatever its walk depth: what a profile's octree is.
pub trait OctreeStore: Accelerator {
    /// An empty octree.
    const EMPTY: Self;
    /// Builds the octree over `scene`'s objects (see [`Octree::build`]).
    fn build(&mut self, scene: &SceneView<'_>, config: &OctreeConfig) -> BuildReport;
}

impl<C: OctreeCapacities, const FRAMES: usize> OctreeStore for Octree<C, FRAMES> {
    const EMPTY: Self = Octree::new();

    fn build(&mut self, scene: &SceneView<'_>, config: &OctreeConfig) -> BuildReport {
        Octree::build(self, scene, config)
    }
}

// The queries are not inlined: each walk then lives in its own stack frame
// for the query's duration only, instead of two of them sitting in every
// caller's frame — it matters on a 16 KiB board.
impl<C: OctreeCapacities, const FRAMES: usize> Accelerator for Octree<C, FRAMES> {
    const KINDS: ShapeKinds = C::KINDS;

    /// Only for 3DDDA: the thesis's walk stays the thesis's for every ray.
    fn first_hits_by_screen(&self) -> bool {
        self.walked_by() == Traversal::Dda
    }

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
        if Self::SHAFTS && light < shaft::LIGHTS {
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

#[cfg(test)]
mod tests {
    extern crate std;
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
