//! Capacity profiles: how many of each thing one build holds, named as
//! counts. A profile sizes a [`Scene`](crate::scene::Scene), an
//! [`Octree`](crate::accel::Octree) and a mailbox, all in fixed arenas, so
//! the linker checks the RAM of a board.
//!
//! Define one for your scene with [`profile!`](crate::profile!); what is
//! not named is 0, and `objects` defaults to the sum of the shapes:
//!
//! ```
//! octrace_core::profile! {
//!     /// Two spheres on a checkerboard of 64 rectangles.
//!     pub struct Chessboard {
//!         spheres: 2, rectangles: 64, surfaces: 3, lights: 2,
//!         octree_boxes: 512, octree_references: 1024,
//!     }
//!     octree: { max_objects: 4, max_depth: 6 }
//! }
//! use octrace_core::profile::Profile;
//! assert_eq!(Chessboard::COUNTS.objects, 66);
//! ```
//!
//! [`parse::count`](crate::parse::count) tells what a scene needs; a scene
//! that needs more than its profile holds is a
//! [`CapacityError`](crate::capacity::CapacityError) naming the count.
//!
//! Invariants: a profile's arena types are exactly its [`Profile::COUNTS`];
//! its octree walks at most `OCTREE.max_depth + 1` frames deep.

pub use crate::accel::linked::Linked;
use crate::accel::OctreeConfig;
use crate::capacity::{Arena, Counts};
use crate::render::ScreenBound;
use crate::scene::SceneCapacities;
#[cfg(feature = "alloc")]
use crate::{
    parse::{count, parse, ParseError},
    AccelMode,
};

/// Everything one build holds and links: a scene's arenas, an octree's, a
/// mailbox, and what its tracer links ([`Linked`]: the octree, the screen
/// lists, the light buffer, coherence). Implement it with
/// [`profile!`](crate::profile!). The octree is `Sync` and a renderer's
/// room `Send`, so that the cores of a board can share a scene and each
/// render in room of its own ([`SharedScene`](crate::SharedScene)).
///
/// ```
/// use octrace_core::profile::{Board16K, Board64K, Profile};
///
/// assert_eq!(Board16K::COUNTS.spheres, 200);
/// assert_eq!(Board16K::OCTREE.max_depth, 3);
/// assert!(Board64K::COUNTS.objects > Board16K::COUNTS.objects);
/// ```
pub trait Profile: SceneCapacities + Linked {
    /// What the profile holds.
    const COUNTS: Counts;
    /// How the octree is built (its depth also bounds the walk's stack).
    const OCTREE: OctreeConfig;
    /// One bit per object: an object filed in several octree boxes is then
    /// tested once per ray.
    type MailboxWords: Arena<u32> + Send;
    /// Whether the octree keeps the thesis's hash table, which only the
    /// thesis's walk (`AccelMode::Octree`)
    /// reads. A profile without it (`named_walk: false` in
    /// [`profile!`](crate::profile!)) saves that RAM; its scenes asked for
    /// that walk are walked by 3DDDA (the same image) and say so.
    const NAMED_WALK: bool = true;
    /// Room for the screen lists: a bound for each object when
    /// [`Linked::FIRST_HITS`], else none.
    type ScreenBounds: Arena<ScreenBound> + Send;
    /// And for the lists' positions: [`ScreenBound::positions_for`] the
    /// objects when [`Linked::FIRST_HITS`], else none.
    type ScreenPositions: Arena<u16> + Send;
    /// RAM for the shadow rays' light buffer
    /// ([`LightBuffer`](crate::accel::LightBuffer)), which
    /// [`Raytracer`](crate::Raytracer) builds when a scene loads for the
    /// first `light_buffer_lights` lights: `light_buffer_words` words (none
    /// when 0; with `light_buffer_lights` above 0 a prebuilt buffer may
    /// still serve them, see
    /// [`LoadedScene::use_light_buffer`](crate::LoadedScene::use_light_buffer)).
    type LightBufferWords: Arena<u32> + Send;
}

/// Defines a [`Profile`] from counts: the fields of
/// [`Counts`](crate::capacity::Counts) (what is not named is 0; `objects`
/// defaults to the sum of the shapes), then optionally the octree's
/// [`OctreeConfig`](crate::accel::OctreeConfig) fields (default: 4 objects a
/// leaf, 12 levels, 3DDDA). The arenas are `heapless::Vec`s with 16-bit
/// octree indices (a compile-time check keeps the octree counts within
/// them); the crate re-exports all it needs. A last `named_walk: false`
/// leaves out the hash table only the thesis's walk needs (see
/// [`Profile::NAMED_WALK`]); a last `first_hits: true` gives camera rays
/// the screen lists (see [`Linked::FIRST_HITS`]: the same image, for a
/// [`ScreenBound`] (16 bytes) an object and [`ScreenBound::positions_for`]
/// them (2 bytes each) of RAM, used in every mode but
/// [`AccelMode::Naive`](crate::AccelMode::Naive) asked for by name, which
/// stays the thesis's test of every object); a last `mirror_hits: true`
/// after it gives the reflections of camera rays off a floor the same, for
/// as much RAM again (see [`Linked::MIRROR_HITS`]); a last `coherence: true` lets
/// an animation re-trace only what changes (see [`Linked::COHERENCE`]:
/// without it none of that code is linked, and a board that draws stills
/// pays nothing for it); a last `motion: false` makes a `MOVE` an error
/// (see [`SceneCapacities::MOTION`]:
/// a board built for a still links no interpolation of keys).
///
/// ```
/// octrace_core::profile! {
///     /// Fifty spheres, no octree.
///     pub struct Spheres50 { spheres: 50, surfaces: 4, lights: 2 }
/// }
/// # use octrace_core::profile::Profile;
/// # assert_eq!(Spheres50::COUNTS.objects, 50);
/// ```
#[macro_export]
macro_rules! profile {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident { $($field:ident : $value:expr),* $(,)? }
        $(octree: { $($octree_field:ident : $octree_value:expr),* $(,)? })?
        $(named_walk: $named_walk:literal)?
        $(first_hits: $first_hits:literal)?
        $(mirror_hits: $mirror_hits:literal)?
        $(coherence: $coherence:literal)?
        $(motion: $motion:literal)?
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        $vis struct $name;

        const _: () = {
            use $crate::profile::__private as p;

            impl $crate::profile::Profile for $name {
                #[allow(clippy::needless_update)]
                const COUNTS: p::Counts = p::Counts { $($field: $value,)* ..p::Counts::ZERO }.with_objects();
                const OCTREE: p::OctreeConfig =
                    p::OctreeConfig { $($($octree_field: $octree_value,)*)? ..p::OctreeConfig::DEFAULT };
                type MailboxWords = p::Vec<u32, { <$name as $crate::profile::Profile>::COUNTS.mailbox_words() }>;
                const NAMED_WALK: bool = p::given_or(&[$($named_walk)?], true);
                type ScreenBounds = p::Vec<
                    p::ScreenBound,
                    { p::ScreenBound::if_wanted(<$name as p::Linked>::FIRST_HITS, p::ScreenBound::lists(<$name as p::Linked>::MIRROR_HITS) * <$name as $crate::profile::Profile>::COUNTS.objects) },
                >;
                type ScreenPositions = p::Vec<
                    u16,
                    { p::ScreenBound::if_wanted(<$name as p::Linked>::FIRST_HITS, p::ScreenBound::lists(<$name as p::Linked>::MIRROR_HITS) * p::ScreenBound::positions_for(<$name as $crate::profile::Profile>::COUNTS.objects)) },
                >;
                type LightBufferWords = p::Vec<u32, { <$name as $crate::profile::Profile>::COUNTS.light_buffer_words }>;
            }

            impl p::Linked for $name {
                type Octree = p::Octree<$name, { <$name as $crate::profile::Profile>::OCTREE.max_depth as usize + 1 }>;
                const FIRST_HITS: bool = p::given_or(&[$($first_hits)?], false);
                const MIRROR_HITS: bool = p::given_or(&[$($mirror_hits)?], false);
                const COHERENCE: bool = p::given_or(&[$($coherence)?], false);
                const LIGHT_BUFFER: bool = <$name as $crate::profile::Profile>::COUNTS.light_buffer_lights > 0;
                const LIGHT_CUBES: bool = <$name as p::Linked>::LIGHT_BUFFER
                    && <$name as $crate::profile::Profile>::COUNTS.objects > $crate::AccelMode::AUTO_NAIVE_UP_TO;
                const LIGHT_CONES: bool = <$name as p::Linked>::LIGHT_BUFFER && !<$name as p::Linked>::LIGHT_CUBES;
            }

            const _: () = assert!(
                <$name as $crate::profile::Profile>::COUNTS.octree_fits_its_index(),
                "profile!: octree_boxes and octree_references must be below 65534 (Counts::OCTREE_INDEX_LIMIT)"
            );
            $crate::__shape_kinds!($crate::__scene_capacities! { $name, p::Vec, motion: p::given_or(&[$($motion)?], true) });

            impl p::OctreeCapacities for $name {
                const KINDS: p::ShapeKinds = p::ShapeKinds::with_room(&<$name as $crate::profile::Profile>::COUNTS);
                type Index = u16;
                type Nodes = p::Vec<p::OctreeNode<u16>, { <$name as $crate::profile::Profile>::COUNTS.octree_boxes }>;
                type References = p::Vec<u16, { <$name as $crate::profile::Profile>::COUNTS.octree_references }>;
                type HashEntries = p::Vec<
                    p::HashEntry<u16>,
                    { <$name as $crate::profile::Profile>::COUNTS.octree_hash_entries_if(<$name as $crate::profile::Profile>::NAMED_WALK) },
                >;
                type HashBuckets = p::Vec<
                    u16,
                    { <$name as $crate::profile::Profile>::COUNTS.octree_hash_buckets_if(<$name as $crate::profile::Profile>::NAMED_WALK) },
                >;
                type ShadowShafts = p::Vec<
                    p::ShadowShaft,
                    { <$name as $crate::profile::Profile>::COUNTS.octree_shadow_shafts_if(<$name as $crate::profile::Profile>::OCTREE.shadow_shafts) },
                >;
            }
        };
    };
}

/// Implements `SceneCapacities` for the profile `$name` with arenas of the
/// type `$arena` sized by its `COUNTS`, one per shape kind from the list
/// (`__shape_kinds!`); not a public API ([`profile!`](crate::profile!) and
/// the `Host` profile expand it).
#[doc(hidden)]
#[macro_export]
macro_rules! __scene_capacities {
    (
        shapes [$($(#[$doc:meta])* $kind:ident($type:ident) in $field:ident: $capacity:ident, $what:literal;)*]
        $name:ident, $($arena:ident)::+ $(, motion: $motion:expr)? $(, desktop: $desktop:expr)?
    ) => {
        const _: () = {
            type ArenaOf<T, const N: usize> = $($arena)::+<T, N>;

            impl $crate::scene::SceneCapacities for $name {
                const NAME: &'static str = stringify!($name);
                type Objects = ArenaOf<$crate::shapes::ShapeHandle, { <$name as $crate::profile::Profile>::COUNTS.objects }>;
                $(type $capacity = ArenaOf<$crate::shapes::$type, { <$name as $crate::profile::Profile>::COUNTS.$field }>;)*
                type ControlPoints = ArenaOf<$crate::math::Vec3, { <$name as $crate::profile::Profile>::COUNTS.control_points }>;
                type Surfaces = ArenaOf<$crate::scene::SurfaceEntry, { <$name as $crate::profile::Profile>::COUNTS.surfaces }>;
                type Lights = ArenaOf<$crate::scene::Light, { <$name as $crate::profile::Profile>::COUNTS.lights }>;
                $(const MOTION: bool = $motion;)?
                $(const DESKTOP: bool = $desktop;)?
            }
        };
    };
}

/// What `text` needs of each capacity when its accelerator is built the way
/// `mode` and `octree` say: its statements' counts (as
/// [`parse::count`](crate::parse::count)) and, when `mode` resolves to an
/// octree walk, the octree's ([`BuildReport::counts`](crate::accel::BuildReport::counts)),
/// built here with the same code a board runs, so a profile of exactly these
/// counts builds exactly the same tree. A build script sizes a board's
/// profile with it (write the profile with
/// [`Counts::profile_fields`](crate::capacity::Counts::profile_fields)).
/// A scene with errors hands each to `on_error` and gives how many there are.
///
/// ```
/// use octrace_core::{accel::OctreeConfig, profile::needed_by, AccelMode};
///
/// let text = "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\n";
/// let needs = needed_by(text, AccelMode::Dda, &OctreeConfig::DEFAULT, &mut |_| {}).unwrap();
/// assert_eq!((needs.spheres, needs.surfaces), (2, 1));
/// assert!(needs.octree_boxes >= 1);
/// assert_eq!(needed_by("SPHERE 1 1 0 0", AccelMode::Auto, &OctreeConfig::DEFAULT, &mut |_| {}), Err(1));
/// ```
#[cfg(feature = "alloc")]
pub fn needed_by<'t>(
    text: &'t str,
    mode: AccelMode,
    octree: &OctreeConfig,
    on_error: &mut dyn FnMut(ParseError<'t>),
) -> Result<Counts, usize> {
    needed_with_light_buffer(text, mode, octree, 0, on_error)
}

/// [`needed_by`], and the words of a light buffer with at most
/// `cells_a_side` cells a face side (see
/// [`LightBuffer::build`](crate::accel::LightBuffer::build); 0: no light
/// buffer): a profile of these counts builds this very buffer when the
/// scene loads, so its shadow rays test only the objects their cells list.
///
/// ```
/// use octrace_core::{accel::OctreeConfig, profile::needed_with_light_buffer, AccelMode};
///
/// let text = "LIGHT 1 0 9 0\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\n";
/// let needs = needed_with_light_buffer(text, AccelMode::Auto, &OctreeConfig::DEFAULT, 8, &mut |_| {}).unwrap();
/// assert!(needs.light_buffer_words > 0);
/// ```
#[cfg(feature = "alloc")]
pub fn needed_with_light_buffer<'t>(
    text: &'t str,
    mode: AccelMode,
    octree: &OctreeConfig,
    cells_a_side: u32,
    on_error: &mut dyn FnMut(ParseError<'t>),
) -> Result<Counts, usize> {
    use crate::accel::Octree;
    use alloc::boxed::Box;

    let scene = host_scene(text, on_error)?;
    let mut counts = count(text);
    let view = scene.view();
    if let Some(traversal) = mode.resolve(view.object_count()).traversal() {
        let mut tree: Box<Octree<Host>> = Box::default();
        let report = tree.build(&view, &OctreeConfig { traversal, ..*octree });
        counts = counts.max(&report.counts());
    }
    if cells_a_side > 0 {
        let mut words = crate::accel::LightBufferStore::<<Host as Profile>::LightBufferWords>::new();
        let report = words.build(&view, cells_a_side).report();
        (counts.light_buffer_lights, counts.light_buffer_words) = (report.lights, report.words);
    }
    Ok(counts)
}

/// The words of the light buffer of `text`'s scene with at most
/// `cells_a_side` cells a face side, built here as a board builds it: a
/// build script writes them into a `static`, and the board, having loaded
/// the same text, takes them with
/// [`LoadedScene::use_light_buffer`](crate::LoadedScene::use_light_buffer)
/// (which checks them against its scene): the buffer is then in flash, no
/// RAM spent on it. The profile serves the lights (`light_buffer_lights`)
/// without RAM for the words (`light_buffer_words: 0`).
///
/// ```
/// use octrace_core::{profile::light_buffer_words, Raytracer};
///
/// octrace_core::profile! {
///     /// Two spheres; a light buffer from elsewhere for their light.
///     struct Spheres { spheres: 2, surfaces: 1, lights: 1, light_buffer_lights: 1 }
/// }
/// let text = "LIGHT 1 0 9 0\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\n";
/// let words = light_buffer_words(text, 16, &mut |_| {}).unwrap();
/// let mut raytracer = Raytracer::<Spheres>::new();
/// let mut scene = raytracer.load(text)?;
/// scene.use_light_buffer(&words)?;
/// // Two spheres: a cone each for the light (a scene of more objects gets a cube).
/// assert_eq!((scene.light_buffer().report().lights, scene.light_buffer().report().entries), (1, 2));
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
#[cfg(feature = "alloc")]
pub fn light_buffer_words<'t>(
    text: &'t str,
    cells_a_side: u32,
    on_error: &mut dyn FnMut(ParseError<'t>),
) -> Result<alloc::vec::Vec<u32>, usize> {
    let mut words = crate::accel::LightBufferStore::<<Host as Profile>::LightBufferWords>::new();
    Ok(words.build(&host_scene(text, on_error)?.view(), cells_a_side).words().to_vec())
}

/// `text`'s scene in the host profile.
#[cfg(feature = "alloc")]
fn host_scene<'t>(
    text: &'t str,
    on_error: &mut dyn FnMut(ParseError<'t>),
) -> Result<alloc::boxed::Box<crate::scene::Scene<Host>>, usize> {
    let mut scene = alloc::boxed::Box::new(crate::scene::Scene::<Host>::new());
    parse(text, &mut scene, on_error)?;
    Ok(scene)
}

/// A [`profile!`](crate::profile!) invocation as text, for a build script
/// that sizes a board's profile for its scene: it writes this into
/// `OUT_DIR` and the firmware `include!`s it (octrace's firmware and board
/// templates do). The counts from `needed_by` (feature `alloc`) or
/// [`parse::count`](crate::parse::count), the octree's criterion when it
/// is not the default one, and the four options.
///
/// ```
/// use octrace_core::{accel::OctreeConfig, parse::count, profile::ProfileText};
///
/// let counts = count("SPHERE 1 1 0 0 0\n");
/// let octree = OctreeConfig { max_depth: 4, ..OctreeConfig::DEFAULT };
/// let text = ProfileText { name: "Scene", doc: "One sphere.", counts: &counts, octree: Some(&octree), named_walk: false, first_hits: true, mirror_hits: true, coherence: false, motion: false };
/// assert_eq!(
///     text.to_string(),
///     "octrace_core::profile! {\n    /// One sphere.\n    pub struct Scene { objects: 1, spheres: 1 }\n    \
///      octree: { max_objects: 4, max_depth: 4, shadow_shafts: false }\n    named_walk: false\n    first_hits: true\n    \
///      mirror_hits: true\n    coherence: false\n    motion: false\n}\n",
/// );
/// ```
#[derive(Clone, Copy, Debug)]
pub struct ProfileText<'a> {
    /// The profile type's name.
    pub name: &'a str,
    /// Its doc comment (one line).
    pub doc: &'a str,
    /// What the profile holds.
    pub counts: &'a Counts,
    /// The octree's criterion, if not [`OctreeConfig::DEFAULT`]'s.
    pub octree: Option<&'a OctreeConfig>,
    /// [`Profile::NAMED_WALK`].
    pub named_walk: bool,
    /// [`Linked::FIRST_HITS`].
    pub first_hits: bool,
    /// [`Linked::MIRROR_HITS`].
    pub mirror_hits: bool,
    /// [`Linked::COHERENCE`]: what a firmware that plays animations needs.
    pub coherence: bool,
    /// [`SceneCapacities::MOTION`]:
    /// whether its scene may have a `MOVE`.
    pub motion: bool,
}

impl ProfileText<'_> {
    /// About how many bytes of RAM the profile's arenas take on a board: its
    /// counts times their items' sizes (the core's types hold no pointer or
    /// `usize`, so a build script running on the host gets the board's
    /// sizes), with the hash table, the mailbox and the techniques' room. A
    /// build script weighs a scene against a board's RAM with it.
    ///
    /// ```
    /// use octrace_core::{parse::count, profile::ProfileText};
    ///
    /// let one = count("SPHERE 1 1 0 0 0\n");
    /// let two = count("SPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\n");
    /// let text = |counts| ProfileText { name: "Scene", doc: "", counts, octree: None, named_walk: false, first_hits: false, mirror_hits: false, coherence: false, motion: false };
    /// assert!(text(&two).arena_bytes() > text(&one).arena_bytes());
    /// ```
    pub fn arena_bytes(&self) -> usize {
        use crate::accel::{HashEntry, OctreeNode, ShadowShaft};
        use crate::math::Vec3;
        use crate::scene::{Light, SurfaceEntry};
        use crate::shapes::{ShapeHandle, ShapeKind};
        use core::mem::size_of;

        let counts = self.counts;
        let shadow_shafts = self.octree.is_some_and(|octree| octree.shadow_shafts);
        let mut shapes = 0;
        for kind in ShapeKind::ALL {
            shapes += counts.get(kind.capacity()) * kind.item_bytes();
        }
        shapes
            + counts.objects * size_of::<ShapeHandle>()
            + counts.control_points * size_of::<Vec3>()
            + counts.surfaces * size_of::<SurfaceEntry>()
            + counts.lights * size_of::<Light>()
            + counts.octree_boxes * size_of::<OctreeNode<u16>>()
            + counts.octree_references * size_of::<u16>()
            + counts.octree_hash_entries_if(self.named_walk) * size_of::<HashEntry<u16>>()
            + (counts.octree_hash_buckets_if(self.named_walk) + 1) * size_of::<u16>()
            + counts.mailbox_words() * size_of::<u32>()
            + ScreenBound::if_wanted(self.first_hits, ScreenBound::lists(self.mirror_hits) * counts.objects)
                * size_of::<ScreenBound>()
            + ScreenBound::if_wanted(
                self.first_hits,
                ScreenBound::lists(self.mirror_hits) * ScreenBound::positions_for(counts.objects),
            ) * size_of::<u16>()
            + counts.octree_shadow_shafts_if(shadow_shafts) * size_of::<ShadowShaft>()
            + counts.light_buffer_words * size_of::<u32>()
    }
}

impl core::fmt::Display for ProfileText<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        writeln!(f, "octrace_core::profile! {{")?;
        writeln!(f, "    /// {}", self.doc)?;
        writeln!(f, "    pub struct {} {{ {} }}", self.name, self.counts.profile_fields())?;
        if let Some(octree) = self.octree {
            let OctreeConfig { max_objects, max_depth, shadow_shafts, .. } = octree;
            writeln!(
                f,
                "    octree: {{ max_objects: {max_objects}, max_depth: {max_depth}, shadow_shafts: {shadow_shafts} }}"
            )?;
        }
        writeln!(f, "    named_walk: {}", self.named_walk)?;
        writeln!(f, "    first_hits: {}", self.first_hits)?;
        writeln!(f, "    mirror_hits: {}", self.mirror_hits)?;
        writeln!(f, "    coherence: {}", self.coherence)?;
        writeln!(f, "    motion: {}", self.motion)?;
        writeln!(f, "}}")
    }
}

/// What [`profile!`](crate::profile!) expands to; not a public API.
#[doc(hidden)]
pub mod __private {
    pub use crate::accel::linked::Linked;
    pub use crate::accel::{HashEntry, Octree, OctreeCapacities, OctreeConfig, OctreeNode, ShadowShaft};
    pub use crate::capacity::Counts;
    pub use crate::render::ScreenBound;
    pub use crate::shapes::ShapeKinds;
    pub use heapless::Vec;

    /// The value given, if one was, else `default`.
    pub const fn given_or(given: &[bool], default: bool) -> bool {
        match given {
            [value] => *value,
            _ => default,
        }
    }
}

crate::profile! {
    /// A board with 16 KiB of RAM (BBC micro:bit v1): up to 200 spheres and
    /// a few other shapes in about 6 KiB, and an octree of up to 128 boxes in
    /// about 2 KiB, 3 levels deep (the walk's stack stays small).
    pub struct Board16K {
        spheres: 200, boxes: 2, superquadrics: 2, triangles: 2, rectangles: 2,
        surfaces: 12, lights: 4, octree_boxes: 128, octree_references: 640,
    }
    octree: { max_objects: 8, max_depth: 3 }
}

crate::profile! {
    /// A board with 64 KiB of RAM or more (Cortex-M3/M4 class).
    pub struct Board64K {
        spheres: 320, boxes: 32, superquadrics: 32, triangles: 96, rectangles: 96,
        bspline_triangles: 32, control_points: 16, surfaces: 64, lights: 8,
        objects: 512, octree_boxes: 2048, octree_references: 6144,
    }
}

/// The host build: a million objects of any kind, heap-backed arenas that
/// take memory only as the scene fills them (feature `alloc`).
#[cfg(feature = "alloc")]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Host;

#[cfg(feature = "alloc")]
mod host {
    use super::{Host, Profile};
    use crate::accel::{HashEntry, Linked, Octree, OctreeCapacities, OctreeConfig, OctreeNode, ShadowShaft, MAX_DEPTH};
    use crate::capacity::{Counts, HeapArena};
    use crate::render::ScreenBound;

    const MILLION: usize = 1_000_000;

    impl Profile for Host {
        const COUNTS: Counts = Counts {
            objects: MILLION,
            control_points: 1_048_576,
            surfaces: 65_535,
            lights: 4_096,
            octree_boxes: 16_000_000,
            octree_references: 64_000_000,
            light_buffer_lights: 4_096,
            light_buffer_words: 64_000_000,
            ..Counts::ZERO
        }
        .with_every_shape(MILLION);
        // RAM is plenty: shadow shafts on.
        const OCTREE: OctreeConfig = OctreeConfig { shadow_shafts: true, ..OctreeConfig::DEFAULT };
        type MailboxWords = HeapArena<u32, { Host::COUNTS.mailbox_words() }>;
        type ScreenBounds = HeapArena<ScreenBound, { ScreenBound::lists(Host::MIRROR_HITS) * Host::COUNTS.objects }>;
        type ScreenPositions = HeapArena<
            u16,
            { ScreenBound::lists(Host::MIRROR_HITS) * ScreenBound::positions_for(Host::COUNTS.objects) },
        >;
        type LightBufferWords = HeapArena<u32, { Host::COUNTS.light_buffer_words }>;
    }

    impl Linked for Host {
        type Octree = Octree<Host, { MAX_DEPTH as usize + 1 }>;
        const FIRST_HITS: bool = true;
        const MIRROR_HITS: bool = true;
        const COHERENCE: bool = true;
        const LIGHT_BUFFER: bool = true;
    }

    crate::__shape_kinds!(crate::__scene_capacities! { Host, HeapArena, desktop: true });

    impl OctreeCapacities for Host {
        type Index = u32;
        type Nodes = HeapArena<OctreeNode<u32>, { Host::COUNTS.octree_boxes }>;
        type References = HeapArena<u32, { Host::COUNTS.octree_references }>;
        type HashEntries = HeapArena<HashEntry<u32>, { Host::COUNTS.octree_hash_entries() }>;
        // A prime: the table's size since the first host profile.
        type HashBuckets = HeapArena<u32, 65_521>;
        type ShadowShafts = HeapArena<ShadowShaft, { Host::COUNTS.octree_boxes }>;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::capacity::CapacityKind;
    use crate::scene::Scene;
    use std::string::ToString;

    crate::profile! {
        struct Tiny { spheres: 3, lights: 1, surfaces: 1 }
    }

    /// A board's profile that shares the desktop's name.
    mod board {
        crate::profile! {
            pub struct Host { spheres: 1, lights: 1, surfaces: 1 }
        }
    }

    /// Capacity errors tell the desktop's users that no profile holds more,
    /// and a board's, whatever its name, which profile to define.
    #[test]
    fn only_the_desktops_profile_has_no_larger_one_to_suggest() {
        let text = "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nLIGHT 10 -5 5 5\nSPHERE 1 1 0 0 0\n";
        let mut scene = Scene::<board::Host>::new();
        let mut first = None;
        let _ = crate::parse::parse(text, &mut scene, &mut |e| {
            first.get_or_insert(e.to_string());
        });
        let board = "3:1: too many lights: the capacity profile Host holds 1 and the scene needs 2; \
                     define a profile that holds them with octrace_core::profile! (lights: 2, …)";
        assert_eq!(first.as_deref(), Some(board));
        #[cfg(feature = "alloc")]
        {
            let desktop = Scene::<Host>::full(CapacityKind::Lights, 4096).to_string();
            let no_larger = "the capacity profile Host holds 4096, the most octrace's desktop build holds: split";
            assert!(desktop.contains(no_larger), "{desktop}");
        }
    }

    #[test]
    fn a_profile_holds_exactly_its_counts() {
        assert_eq!(<Tiny as SceneCapacities>::Spheres::CAPACITY, 3);
        assert_eq!(<Tiny as SceneCapacities>::Objects::CAPACITY, 3);
        assert_eq!(<Tiny as SceneCapacities>::Boxes::CAPACITY, 0);
        assert_eq!(<Tiny as Profile>::MailboxWords::CAPACITY, 1);
        assert_eq!(Board16K::COUNTS.objects, 208, "the shapes' sum");
        assert_eq!(Board16K::COUNTS.get(CapacityKind::Rectangles), 2);
        assert_eq!(Board16K::OCTREE.max_depth, 3);
        assert_eq!(Board64K::COUNTS.objects, 512, "given, not summed");
    }
}
