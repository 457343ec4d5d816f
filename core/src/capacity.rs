//! Fixed-capacity storage and the vocabulary of capacities: the leaf every
//! sized type builds on (it imports nothing else from the crate; the shape
//! kinds' capacities come from the list in `shape_kinds`).
//!
//! Invariants: an [`Arena`] never holds more than its `CAPACITY` items and
//! hands an item back instead of growing; an empty arena is a constant whose
//! bits are all zero for `heapless::Vec`, so arenas in a `static` land in
//! `.bss` and cost no flash. Each capacity is named once, by
//! [`CapacityKind`]; [`Counts`] holds one number per kind (what a profile
//! holds, or what a scene needs).

use core::fmt;

/// A fixed-capacity, append-only store: `heapless::Vec` on boards.
pub trait Arena<T>: Sized {
    /// An empty arena (a constant, so a scene can be built in a `static`).
    const EMPTY: Self;
    /// The most items it holds.
    const CAPACITY: usize;
    /// Appends `item`, or gives it back when the arena is full.
    fn push(&mut self, item: T) -> Result<(), T>;
    /// The items, in the order they were pushed.
    fn as_slice(&self) -> &[T];
    /// The items, mutably.
    fn as_mut_slice(&mut self) -> &mut [T];
    /// Drops every item.
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
#[derive(Debug)]
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

/// Declares [`CapacityKind`] and [`Counts`] from one list, so the enum, the
/// struct's fields, their names in messages and in [`crate::profile!`] can
/// never drift apart.
macro_rules! capacities {
    // The shapes' capacities come from the list of shape kinds, after
    // `Objects` and before the others.
    (
        shapes [$($(#[$shape_doc:meta])* $shape:ident($type:ident) in $shape_field:ident: $shape_kind:ident, $shape_what:literal;)*]
        $($rest:tt)*
    ) => {
        capacities! {
            /// All objects (by default the sum of the shapes).
            Objects = 1 => objects, "objects";
            $(#[doc = concat!("The scene's ", $shape_what, ".")] $shape_kind => $shape_field, $shape_what;)*
            $($rest)*
        }

        impl Counts {
            /// The shapes' sum (saturating): the objects a profile needs room for.
            pub const fn shapes(&self) -> usize {
                0usize $(.saturating_add(self.$shape_field))*
            }

            /// These counts with `count` of every shape kind.
            ///
            /// ```
            /// use octrace_core::{capacity::Counts, shapes::ShapeKind};
            ///
            /// let counts = Counts { lights: 1, ..Counts::ZERO }.with_every_shape(3);
            /// assert!(ShapeKind::ALL.iter().all(|kind| counts.get(kind.capacity()) == 3));
            /// assert_eq!((counts.shapes(), counts.lights), (3 * ShapeKind::ALL.len(), 1));
            /// ```
            pub const fn with_every_shape(mut self, count: usize) -> Counts {
                $(self.$shape_field = count;)*
                self
            }
        }
    };
    ($($(#[$doc:meta])* $variant:ident $(= $value:literal)? => $field:ident, $what:literal;)*) => {
        /// One capacity of a profile: something a scene can run out of.
        // Numbered from 1, so that `None` of an `Option<CapacityKind>` is
        // zero bits (an empty octree's report sits in `.bss`).
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum CapacityKind {
            $($(#[$doc])* $variant $(= $value)?,)*
        }

        impl CapacityKind {
            /// Every kind, in the order of [`Counts`]' fields.
            pub const ALL: [CapacityKind; [$(CapacityKind::$variant),*].len()] = [$(CapacityKind::$variant),*];

            /// What runs out, in plain words ("spheres").
            pub const fn what(self) -> &'static str {
                match self {
                    $(CapacityKind::$variant => $what,)*
                }
            }

            /// Its field in [`Counts`] and in [`crate::profile!`].
            pub const fn field(self) -> &'static str {
                match self {
                    $(CapacityKind::$variant => stringify!($field),)*
                }
            }
        }

        /// A number for each [`CapacityKind`]: what a profile holds, or what
        /// a scene needs ([`crate::parse::count`]).
        ///
        /// A profile for several scenes holds the largest need of each:
        ///
        /// ```
        /// use octrace_core::{capacity::{CapacityKind, Counts}, parse::count, profile::{Board16K, Profile}};
        ///
        /// let a = count("SPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\n");
        /// let b = count("SPHERE 1 1 0 0 0\nTRIANGLE 1 0 0 0 1 0 0 0 1 0\n");
        /// let both: Counts = a.max(&b);
        /// assert_eq!((both.spheres, both.triangles), (2, 1));
        /// assert!(CapacityKind::ALL.into_iter().all(|k| both.get(k) <= Board16K::COUNTS.get(k)));
        /// ```
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct Counts {
            $($(#[$doc])* pub $field: usize,)*
        }

        impl Counts {
            /// Nothing at all.
            pub const ZERO: Counts = Counts { $($field: 0,)* };

            /// The count of `kind`.
            pub const fn get(&self, kind: CapacityKind) -> usize {
                match kind {
                    $(CapacityKind::$variant => self.$field,)*
                }
            }

            /// The count of `kind`, mutably.
            pub fn get_mut(&mut self, kind: CapacityKind) -> &mut usize {
                match kind {
                    $(CapacityKind::$variant => &mut self.$field,)*
                }
            }
        }
    };
}

crate::__shape_kinds!(capacities! {
    /// Control points of the largest B-spline patch (room to evaluate one).
    ControlPoints => control_points, "B-spline control points";
    /// Surface definitions (at most 65,535).
    Surfaces => surfaces, "surfaces";
    /// Point lights.
    Lights => lights, "lights";
    /// Octree boxes (8 per subdivision, plus the root).
    OctreeBoxes => octree_boxes, "octree boxes";
    /// Object references in the octree's leaves, and working room while
    /// building (an object in several leaves counts once per leaf).
    OctreeReferences => octree_references, "octree references";
    /// Lights whose shadow rays the light buffer (`accel::LightBuffer`)
    /// serves, the first ones: 0 links none of its code.
    LightBufferLights => light_buffer_lights, "light buffer lights";
    /// Words of RAM for the light buffer, built when a scene loads (0: none
    /// built; a prebuilt one, e.g. in flash, may still serve the lights): a
    /// few for each light and each cell of its cube that lists objects, one
    /// for each object listed in a cell.
    LightBufferWords => light_buffer_words, "light buffer words";
});

impl Counts {
    /// Hash-table entries the octree needs: one per subdivided box.
    pub const fn octree_hash_entries(&self) -> usize {
        self.octree_boxes.saturating_sub(1) / 8
    }

    /// The octree's hash-table size: an odd number near half the entries
    /// (chains of about two), at least 1.
    pub const fn octree_hash_buckets(&self) -> usize {
        (self.octree_hash_entries() / 2) | 1
    }

    /// [`Counts::octree_hash_entries`] for a profile with the thesis's walk,
    /// 0 for one without (see `Profile::NAMED_WALK`).
    pub const fn octree_hash_entries_if(&self, named_walk: bool) -> usize {
        if named_walk {
            self.octree_hash_entries()
        } else {
            0
        }
    }

    /// [`Counts::octree_hash_buckets`] for a profile with the thesis's walk,
    /// 0 for one without.
    pub const fn octree_hash_buckets_if(&self, named_walk: bool) -> usize {
        if named_walk {
            self.octree_hash_buckets()
        } else {
            0
        }
    }

    /// Shadow shafts the octree keeps, one per box, when its config
    /// asks for them (`OctreeConfig::shadow_shafts`); 0 otherwise.
    pub const fn octree_shadow_shafts_if(&self, shadow_shafts: bool) -> usize {
        if shadow_shafts {
            self.octree_boxes
        } else {
            0
        }
    }

    /// These counts with `objects` set to the shapes' sum when it is 0
    /// (what [`crate::profile!`] does when `objects` is not given).
    pub const fn with_objects(mut self) -> Counts {
        if self.objects == 0 {
            self.objects = self.shapes();
        }
        self
    }

    /// Mailbox words for every object (one bit each).
    pub const fn mailbox_words(&self) -> usize {
        self.objects.div_ceil(32)
    }

    /// The counts as the fields of a [`crate::profile!`], those that are not
    /// 0 (`spheres: 4, surfaces: 2, lights: 1`): a build script writes a
    /// profile sized for its scene with it.
    ///
    /// ```
    /// use octrace_core::{capacity::Counts, parse::count};
    ///
    /// let needs = count("SPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\nLIGHT 1 0 9 0\n");
    /// assert_eq!(needs.profile_fields().to_string(), "objects: 2, spheres: 2, lights: 1");
    /// ```
    pub fn profile_fields(&self) -> impl fmt::Display + '_ {
        Listed { counts: self, form: Listing::Fields }
    }

    /// The counts in words, those that are not 0 (`2 objects, 2 spheres, 1 lights`):
    /// what a build script says a scene needs when a board cannot hold it.
    ///
    /// ```
    /// use octrace_core::parse::count;
    ///
    /// let needs = count("SPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\nLIGHT 1 0 9 0\n");
    /// assert_eq!(needs.described().to_string(), "2 objects, 2 spheres, 1 lights");
    /// ```
    pub fn described(&self) -> impl fmt::Display + '_ {
        Listed { counts: self, form: Listing::Words }
    }

    /// The octree's boxes and references a profile holds are below this:
    /// they are numbered in 16 bits, whose top two values are markers.
    pub const OCTREE_INDEX_LIMIT: usize = 0xFFFE;

    /// Whether a profile of these counts can number its octree's boxes and
    /// references ([`Counts::OCTREE_INDEX_LIMIT`]); [`crate::profile!`]
    /// refuses one that cannot when it is compiled.
    pub const fn octree_fits_its_index(&self) -> bool {
        self.octree_boxes < Counts::OCTREE_INDEX_LIMIT && self.octree_references < Counts::OCTREE_INDEX_LIMIT
    }

    /// [`Counts::octree_fits_its_index`] with the reason when it does not:
    /// what a build script reports for a scene too large for any profile.
    ///
    /// ```
    /// use octrace_core::capacity::Counts;
    ///
    /// let counts = Counts { octree_boxes: 70_000, octree_references: 9, ..Counts::ZERO };
    /// let error = counts.check_octree_index().unwrap_err();
    /// assert_eq!(
    ///     error.to_string(),
    ///     "its octree needs 70000 boxes and 9 references, and 16-bit indices number at most 65533 of each"
    /// );
    /// assert!(Counts::ZERO.check_octree_index().is_ok());
    /// ```
    pub fn check_octree_index(&self) -> Result<(), OctreeIndexError> {
        match self.octree_fits_its_index() {
            true => Ok(()),
            false => Err(OctreeIndexError { boxes: self.octree_boxes, references: self.octree_references }),
        }
    }

    /// Each count the larger of `self`'s and `other`'s.
    pub fn max(mut self, other: &Counts) -> Counts {
        for kind in CapacityKind::ALL {
            let c = self.get_mut(kind);
            *c = (*c).max(other.get(kind));
        }
        self
    }
}

/// The counts that are not 0, comma-separated, each in `form`.
struct Listed<'a> {
    counts: &'a Counts,
    form: Listing,
}

/// How [`Listed`] writes a count.
enum Listing {
    /// As a profile's field: `spheres: 2`.
    Fields,
    /// In words: `2 spheres`.
    Words,
}

impl fmt::Display for Listed<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let given = CapacityKind::ALL.into_iter().filter(|&kind| self.counts.get(kind) > 0);
        for (i, kind) in given.enumerate() {
            let (separator, count) = (if i == 0 { "" } else { ", " }, self.counts.get(kind));
            match self.form {
                Listing::Fields => write!(f, "{separator}{}: {count}", kind.field())?,
                Listing::Words => write!(f, "{separator}{count} {}", kind.what())?,
            }
        }
        Ok(())
    }
}

/// A scene needs more of something than its profile holds.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CapacityError {
    /// What ran out.
    pub kind: CapacityKind,
    /// How many the profile holds.
    pub capacity: usize,
    /// How many the scene needs, when known (the parser counts them all
    /// before storing any).
    pub needed: Option<usize>,
    /// The profile's name.
    pub profile: &'static str,
    /// Whether the profile is the desktop's (its
    /// [`SceneCapacities::DESKTOP`](crate::scene::SceneCapacities::DESKTOP)):
    /// then no profile to define holds more.
    pub desktop: bool,
}

impl fmt::Display for CapacityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "too many {}: the capacity profile {} holds {}", self.kind.what(), self.profile, self.capacity)?;
        if let Some(needed) = self.needed {
            write!(f, " and the scene needs {needed}")?;
        }
        if self.desktop {
            // host-sim's, the studio's: a user of those cannot define a
            // profile, and no profile holds more.
            return write!(f, ", the most octrace's desktop build holds: split the scene or simplify it");
        }
        write!(
            f,
            "; define a profile that holds them with octrace_core::profile! ({}: {}, …)",
            self.kind.field(),
            self.needed.unwrap_or(self.capacity.saturating_add(1))
        )
    }
}

impl core::error::Error for CapacityError {}

/// An octree of more boxes or references than its 16-bit indices number
/// ([`Counts::OCTREE_INDEX_LIMIT`]): no profile can hold it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OctreeIndexError {
    /// The octree's boxes.
    pub boxes: usize,
    /// Its references to objects.
    pub references: usize,
}

impl fmt::Display for OctreeIndexError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "its octree needs {} boxes and {} references, and 16-bit indices number at most {} of each",
            self.boxes,
            self.references,
            Counts::OCTREE_INDEX_LIMIT - 1
        )
    }
}

impl core::error::Error for OctreeIndexError {}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::string::ToString;

    #[test]
    fn kinds_and_fields_agree() {
        let mut c = Counts::ZERO;
        for (i, kind) in CapacityKind::ALL.into_iter().enumerate() {
            *c.get_mut(kind) = i + 1;
        }
        for (i, kind) in CapacityKind::ALL.into_iter().enumerate() {
            assert_eq!(c.get(kind), i + 1, "{kind:?}");
        }
        assert_eq!(CapacityKind::BsplineTriangles.field(), "bspline_triangles");
        assert_eq!(CapacityKind::BsplineTriangles.what(), "B-spline triangles");
    }

    #[test]
    fn derived_counts() {
        let c = Counts { spheres: 200, rectangles: 64, octree_boxes: 129, ..Counts::ZERO }.with_objects();
        assert_eq!(c.objects, 264);
        assert_eq!(c.with_objects().objects, 264);
        assert_eq!(c.mailbox_words(), 9);
        assert_eq!(c.octree_hash_entries(), 16);
        assert_eq!(c.octree_hash_buckets(), 9);
        assert_eq!(Counts::ZERO.octree_hash_buckets(), 1);
    }

    #[test]
    fn the_message_says_what_how_many_and_how_to_fix_it() {
        let e = CapacityError {
            kind: CapacityKind::Rectangles,
            capacity: 2,
            needed: Some(64),
            profile: "Board16K",
            desktop: false,
        };
        assert_eq!(
            e.to_string(),
            "too many rectangles: the capacity profile Board16K holds 2 and the scene needs 64; \
             define a profile that holds them with octrace_core::profile! (rectangles: 64, …)"
        );
        // The desktop's profile: nothing to define.
        let e = CapacityError {
            kind: CapacityKind::Lights,
            capacity: 4096,
            needed: Some(4100),
            profile: "Host",
            desktop: true,
        };
        assert_eq!(
            e.to_string(),
            "too many lights: the capacity profile Host holds 4096 and the scene needs 4100, \
             the most octrace's desktop build holds: split the scene or simplify it"
        );
    }
}
