//! The octree's vocabulary: its boxes, hash entries, walks, build
//! criterion and report, index types, a leaf's shadow shafts and the
//! capacities a profile gives it.

use crate::capacity::{Arena, CapacityKind, Counts};
use crate::shapes::ShapeKinds;

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
    pub(super) fn leaf(first: u32, count: u32) -> Self {
        OctreeNode { first: I::new(first), count: I::new(count) }
    }
    #[inline]
    pub(super) fn internal(children: u32) -> Self {
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
    pub(super) fn list<'r>(&self, refs: &'r [I]) -> &'r [I] {
        &refs[self.first() as usize..(self.first() + self.count()) as usize]
    }
}

/// The thesis's hash-table structure: a subdivided box's name and where its
/// eight children are, chained by `next` (`I::MAX`: end of the chain).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HashEntry<I> {
    pub(super) name: u64,
    pub(super) children: I,
    pub(super) next: I,
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

/// The arenas an [`Octree`](super::Octree) is stored in. Every profile implements it;
/// define one with [`crate::profile!`], which names counts, not these types.
pub trait OctreeCapacities {
    /// The shape kinds the profile's scenes can hold: the queries and the
    /// tracer dispatch on these only, so a build links no other kind's
    /// code.
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

impl BuildReport {
    /// The octree counts of a profile that builds this very tree (see
    /// [`crate::parse::count`] for the scene's).
    pub fn counts(&self) -> Counts {
        Counts { octree_boxes: self.nodes, octree_references: self.peak_references, ..Counts::ZERO }
    }
}

/// Lights with a bit: one per bit of a leaf's word.
pub(super) const LIGHTS: usize = 32;

/// A leaf's shadow shafts: the lights (a bit each, the first 32) that shadow
/// rays starting in its source reach past its own objects with nothing else
/// near (see [`crate::accel::OctreeCapacities::ShadowShafts`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadowShaft {
    pub(super) lights: u32,
    /// The source: where the leaf's objects are inside its box (Q16.16).
    pub(super) low: [i32; 3],
    pub(super) high: [i32; 3],
}

// What the README and `OctreeConfig::shadow_shafts` say a box costs.
const _: () = assert!(core::mem::size_of::<ShadowShaft>() == 28);

impl ShadowShaft {
    /// No shaft: every shadow ray walks.
    pub(super) const NONE: ShadowShaft = ShadowShaft { lights: 0, low: [0; 3], high: [0; 3] };

    /// Whether a shadow ray from `origin` to light `light` may skip the walk.
    #[inline]
    pub(super) fn clear(&self, origin: [i32; 3], light: usize) -> bool {
        self.lights >> light & 1 == 1 && (0..3).all(|a| self.low[a] <= origin[a] && origin[a] <= self.high[a])
    }
}
