//! Every capacity octrace has, in one place: the arenas a scene is stored in
//! and the profiles that size them.
//!
//! A profile is a type implementing [`Capacities`]; each associated type is an
//! arena of fixed capacity. On a board the arenas are `heapless::Vec`s that
//! live in a `static` (no heap, the linker checks the RAM); on a host they may
//! be `HeapArena`s (feature `alloc`): the same fixed limits, but memory is
//! taken only as the scene fills them. Exceeding a capacity is a scene error
//! that names it ([`crate::parse::ErrorKind::Capacity`]).
//!
//! To raise a limit, define your own profile (copy one below and change the
//! numbers); nothing else changes.

use crate::accel::{HashEntry, OctreeNode};
use crate::math::Vec3;
use crate::scene::{Light, SurfaceEntry};
use crate::shapes::{AxisAlignedBox, Rectangle, ShapeHandle, SmoothTriangle, Sphere, Superquadric, Triangle};

/// A fixed-capacity, append-only store: `heapless::Vec` on boards.
pub trait Arena<T>: Sized {
    /// An empty arena (a constant, so a scene can be built in a `static`).
    const EMPTY: Self;
    /// The most items it holds.
    const CAPACITY: usize;
    /// Appends `item`, or gives it back when the arena is full.
    fn push(&mut self, item: T) -> Result<(), T>;
    fn as_slice(&self) -> &[T];
    fn as_mut_slice(&mut self) -> &mut [T];
    fn clear(&mut self);
    /// Drops the items from `len` on.
    fn truncate(&mut self, len: usize);
}

impl<T, const N: usize> Arena<T> for heapless::Vec<T, N> {
    const EMPTY: Self = heapless::Vec::new();
    const CAPACITY: usize = N;

    fn push(&mut self, item: T) -> Result<(), T> {
        heapless::Vec::push(self, item)
    }

    fn as_slice(&self) -> &[T] {
        self
    }

    fn as_mut_slice(&mut self) -> &mut [T] {
        self
    }

    fn clear(&mut self) {
        heapless::Vec::clear(self)
    }

    fn truncate(&mut self, len: usize) {
        heapless::Vec::truncate(self, len)
    }
}

/// A heap-backed arena with the fixed capacity `N` (feature `alloc`): for
/// hosts, where a million-object limit should not cost memory up front.
#[cfg(feature = "alloc")]
pub struct HeapArena<T, const N: usize>(alloc::vec::Vec<T>);

#[cfg(feature = "alloc")]
impl<T, const N: usize> Arena<T> for HeapArena<T, N> {
    const EMPTY: Self = HeapArena(alloc::vec::Vec::new());
    const CAPACITY: usize = N;

    fn push(&mut self, item: T) -> Result<(), T> {
        if self.0.len() >= N {
            return Err(item);
        }
        self.0.push(item);
        Ok(())
    }

    fn as_slice(&self) -> &[T] {
        &self.0
    }

    fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.0
    }

    fn clear(&mut self) {
        self.0.clear()
    }

    fn truncate(&mut self, len: usize) {
        self.0.truncate(len)
    }
}

/// The integer type of the octree's indices: `u32` on hosts, `u16` on small
/// boards (half the RAM for the octree). Its largest two values are
/// reserved as markers.
pub trait Index: Copy + Eq + core::fmt::Debug + 'static {
    /// The largest value.
    const MAX: u32;
    /// `v` as an index; `v` must not exceed [`Index::MAX`].
    fn new(v: u32) -> Self;
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

/// The capacities of one build: how many of each thing a scene may hold.
pub trait Capacities {
    /// The profile's name, shown in capacity errors.
    const NAME: &'static str;
    /// All objects, in file order.
    type Objects: Arena<ShapeHandle>;
    type Spheres: Arena<Sphere>;
    type Boxes: Arena<AxisAlignedBox>;
    type Superquadrics: Arena<Superquadric>;
    type Triangles: Arena<Triangle>;
    type Rectangles: Arena<Rectangle>;
    /// The triangles of B-spline patches.
    type SmoothTriangles: Arena<SmoothTriangle>;
    /// Room for one patch's control points while it is evaluated.
    type ControlPoints: Arena<Vec3>;
    /// Surface definitions; at most 65,535 (objects refer to them by `u16`).
    type Surfaces: Arena<SurfaceEntry>;
    type Lights: Arena<Light>;
    /// The octree's index type (bounds its arenas and the objects it files).
    type Index: Index;
    /// Octree boxes (8 per subdivision, plus the root).
    type OctreeNodes: Arena<OctreeNode<Self::Index>>;
    /// Object references of the octree's leaves (an object in several
    /// leaves counts once per leaf), and working room while building.
    type OctreeRefs: Arena<Self::Index>;
    /// Hash-table entries: one per subdivided box (the thesis's structure
    /// holding the addresses of a box's eight children).
    type OctreeEntries: Arena<HashEntry<Self::Index>>;
    /// Hash-table buckets; the table size is this arena's capacity.
    type OctreeBuckets: Arena<Self::Index>;
}

/// The host build: a million objects of any mix (heap-backed arenas).
#[cfg(feature = "alloc")]
pub struct Host;

#[cfg(feature = "alloc")]
impl Capacities for Host {
    const NAME: &'static str = "Host";
    type Objects = HeapArena<ShapeHandle, 1_000_000>;
    type Spheres = HeapArena<Sphere, 1_000_000>;
    type Boxes = HeapArena<AxisAlignedBox, 1_000_000>;
    type Superquadrics = HeapArena<Superquadric, 1_000_000>;
    type Triangles = HeapArena<Triangle, 1_000_000>;
    type Rectangles = HeapArena<Rectangle, 1_000_000>;
    type SmoothTriangles = HeapArena<SmoothTriangle, 1_000_000>;
    type ControlPoints = HeapArena<Vec3, 1_048_576>;
    type Surfaces = HeapArena<SurfaceEntry, 65_535>;
    type Lights = HeapArena<Light, 4_096>;
    type Index = u32;
    type OctreeNodes = HeapArena<OctreeNode<u32>, 16_000_000>;
    type OctreeRefs = HeapArena<u32, 64_000_000>;
    type OctreeEntries = HeapArena<HashEntry<u32>, 2_000_000>;
    type OctreeBuckets = HeapArena<u32, 65_521>;
}

/// A board with 16 KiB of RAM (BBC micro:bit v1): scenes of up to 200
/// spheres and a few other shapes in about 6 KiB, and an octree of up to 128
/// boxes in about 2 KiB (16-bit indices), leaving 6 KiB of stack.
pub struct Board16K;

impl Capacities for Board16K {
    const NAME: &'static str = "Board16K";
    type Objects = heapless::Vec<ShapeHandle, 208>;
    type Spheres = heapless::Vec<Sphere, 200>;
    type Boxes = heapless::Vec<AxisAlignedBox, 2>;
    type Superquadrics = heapless::Vec<Superquadric, 2>;
    type Triangles = heapless::Vec<Triangle, 2>;
    type Rectangles = heapless::Vec<Rectangle, 2>;
    type SmoothTriangles = heapless::Vec<SmoothTriangle, 0>;
    type ControlPoints = heapless::Vec<Vec3, 0>;
    type Surfaces = heapless::Vec<SurfaceEntry, 12>;
    type Lights = heapless::Vec<Light, 4>;
    type Index = u16;
    type OctreeNodes = heapless::Vec<OctreeNode<u16>, 128>;
    type OctreeRefs = heapless::Vec<u16, 640>;
    type OctreeEntries = heapless::Vec<HashEntry<u16>, 16>;
    type OctreeBuckets = heapless::Vec<u16, 13>;
}

/// A board with 64 KiB of RAM or more (Cortex-M3/M4 class).
pub struct Board64K;

impl Capacities for Board64K {
    const NAME: &'static str = "Board64K";
    type Objects = heapless::Vec<ShapeHandle, 512>;
    type Spheres = heapless::Vec<Sphere, 320>;
    type Boxes = heapless::Vec<AxisAlignedBox, 32>;
    type Superquadrics = heapless::Vec<Superquadric, 32>;
    type Triangles = heapless::Vec<Triangle, 96>;
    type Rectangles = heapless::Vec<Rectangle, 96>;
    type SmoothTriangles = heapless::Vec<SmoothTriangle, 32>;
    type ControlPoints = heapless::Vec<Vec3, 16>;
    type Surfaces = heapless::Vec<SurfaceEntry, 64>;
    type Lights = heapless::Vec<Light, 8>;
    type Index = u16;
    type OctreeNodes = heapless::Vec<OctreeNode<u16>, 2048>;
    type OctreeRefs = heapless::Vec<u16, 6144>;
    type OctreeEntries = heapless::Vec<HashEntry<u16>, 256>;
    type OctreeBuckets = heapless::Vec<u16, 127>;
}
