//! The loaded scene: objects in per-kind arenas, surfaces, lights and the
//! scene parameters, all in normalised space.
//!
//! Invariants (established by [`crate::parse`], relied on by the tracer):
//! - every object, light and the eye lie within the normalised range;
//! - every object's surface index is valid;
//! - objects are numbered in file order ([`ObjectId`]); the tie rule (equal
//!   distance: the earlier object wins) uses that order.
//!
//! [`Scene`] owns the storage, arenas sized by [`SceneCapacities`] (which
//! every [`crate::profile`](mod@crate::profile) implements); the tracer and the accelerators read
//! it through [`SceneView`], plain slices, so they do not carry the
//! profile's type parameters. An empty [`Scene`] is all zero bits, so one in
//! a `static` costs no flash.

mod camera;
mod mirror;
pub(crate) mod motion;
mod normalize;
mod surface;

pub use camera::{Camera, CameraError, View, MAX_SAMPLES, MAX_SIDE};
pub(crate) use camera::{CameraRay, Projection, RayCursor, Stride};
pub(crate) use mirror::MirrorPlane;
pub use motion::{displacement_at, Frames};
pub use normalize::{Normalization, WorldPoint, WorldValue};
pub use surface::{Color, Surface, SurfaceEntry};

use crate::capacity::{Arena, CapacityError, CapacityKind};
use crate::math::{Scalar, Vec3, Wide};
use crate::shapes::{Leaving, Ray, Shape, ShapeHandle, ShapeKind, ShapeKinds, ShapeRef, SmoothTriangle};

/// An object's position in the scene file (0 for the first object).
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ObjectId(pub u32);

/// A white point light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Light {
    /// Normalised position.
    pub position: Vec3,
    /// Brightness B ≥ 0.
    pub brightness: Wide,
}

/// The scene parameters of section 2 of the format (world units where they
/// are lengths).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    /// VIEWPOINT, ORIGIN, UPVECTOR and VIEWPORT.
    pub view: View,
    /// RASTER width and height, 1 to 16384.
    pub raster: [u32; 2],
    /// RDEPTH: how many reflections and refractions a ray may spawn in a row.
    pub rdepth: u32,
    /// BACKGROUND: the colour of rays that hit nothing.
    pub background: Color,
    /// GAMMA, > 0.
    pub gamma: Wide,
    /// ATTENUATION d0, > 0, world units.
    pub attenuation: Wide,
    /// SAMPLES n (n×n rays per pixel), 1 to 16.
    pub samples: u32,
}

impl Default for Settings {
    fn default() -> Settings {
        DEFAULT_SETTINGS
    }
}

/// Declares the scene's arenas, one per shape kind from the list of shape
/// kinds (`crate::shape_kinds`), and what reads and fills them by kind.
macro_rules! scene_arenas {
    (shapes [$($(#[$doc:meta])* $kind:ident($type:ident) in $field:ident: $capacity:ident, $what:literal;)*]) => {
        /// The arenas a [`Scene`] is stored in, each a fixed-capacity [`Arena`].
        /// Every profile implements it; define one with [`crate::profile!`], which
        /// names counts, not these types.
        pub trait SceneCapacities {
            /// The profile's name, shown in capacity errors.
            const NAME: &'static str;
            /// Whether it is the desktop's profile
            /// ([`Host`](crate::profile::Host), feature `alloc`), whose
            /// capacities are octrace's most: its capacity errors suggest no
            /// profile to define. Told by the type, not by a name a board's
            /// `profile!` may share.
            const DESKTOP: bool = false;
            /// All objects, in file order.
            type Objects: Arena<ShapeHandle>;
            $(#[doc = concat!("The ", $what, ".")] type $capacity: Arena<crate::shapes::$type>;)*
            /// Room for one patch's control points while it is evaluated.
            type ControlPoints: Arena<Vec3>;
            /// Surface definitions; at most 65,535 (objects refer to them by `u16`).
            type Surfaces: Arena<SurfaceEntry>;
            /// Point lights.
            type Lights: Arena<Light>;
            /// Whether its scenes may move: a profile without motion
            /// (`motion: false` in [`profile!`](crate::profile!), what a
            /// board built for a still needs) finds a `MOVE` an error, and
            /// its build links none of the interpolation of the keys.
            const MOTION: bool = true;
        }

        /// Scene storage sized by the profile `C`.
        ///
        /// An empty scene is all zero bits; [`crate::parse::parse`] fills it, and
        /// [`Scene::view`] is what the renderer and the accelerators read:
        ///
        /// ```
        /// use octrace_core::{parse::parse, profile::Board16K, scene::Scene};
        ///
        /// let mut scene = Scene::<Board16K>::new();
        /// let text = "RASTER 32 24\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\nLIGHT 10 5 5 5\n";
        /// parse(text, &mut scene, &mut |e| panic!("{e}")).unwrap();
        /// assert_eq!(scene.settings.raster, [32, 24]);
        /// let view = scene.view();
        /// assert_eq!((view.object_count(), view.lights.len(), view.surfaces.len()), (1, 1, 1));
        /// ```
        pub struct Scene<C: SceneCapacities> {
            objects: C::Objects,
            $($field: C::$capacity,)*
            /// Scratch: the control points of the patch being evaluated.
            control_points: C::ControlPoints,
            surfaces: C::Surfaces,
            lights: C::Lights,
            /// The scene parameters (zero until a scene is loaded).
            pub settings: Settings,
            /// How world coordinates map to the normalised space the tracer works in.
            pub normalization: Normalization,
        }

        impl<C: SceneCapacities> Scene<C> {
            /// An empty scene, not loaded yet ([`crate::parse::parse`] fills it; its
            /// settings are all zero until then). A constant of all-zero bits: in a
            /// `static` it lands in `.bss`, costing no flash and no copy.
            pub const fn new() -> Self {
                Scene {
                    objects: C::Objects::EMPTY,
                    $($field: C::$capacity::EMPTY,)*
                    control_points: C::ControlPoints::EMPTY,
                    surfaces: C::Surfaces::EMPTY,
                    lights: C::Lights::EMPTY,
                    settings: UNLOADED_SETTINGS,
                    normalization: Normalization::UNLOADED,
                }
            }

            /// Empties the scene and resets the parameters to their defaults.
            pub fn clear(&mut self) {
                self.objects.clear();
                $(self.$field.clear();)*
                self.control_points.clear();
                self.surfaces.clear();
                self.lights.clear();
                self.settings = Settings::default();
                self.normalization = Normalization::IDENTITY;
            }

            /// The loaded scene, read-only, as the tracer and accelerators see it.
            pub fn view(&self) -> SceneView<'_> {
                SceneView {
                    objects: self.objects.as_slice(),
                    $($field: self.$field.as_slice(),)*
                    surfaces: self.surfaces.as_slice(),
                    lights: self.lights.as_slice(),
                    settings: &self.settings,
                    normalization: self.normalization,
                }
            }

            /// How many objects of `kind` the profile holds (at most what a
            /// [`ShapeHandle`] addresses).
            pub(crate) fn capacity_of(kind: ShapeKind) -> usize {
                let capacity = match kind {
                    $(ShapeKind::$kind => C::$capacity::CAPACITY,)*
                };
                capacity.min(ShapeHandle::MAX_INDEX)
            }

            fn len_of(&self, kind: ShapeKind) -> usize {
                match kind {
                    $(ShapeKind::$kind => self.$field.as_slice().len(),)*
                }
            }
        }

        $(
            impl Stored for crate::shapes::$type {
                const KIND: ShapeKind = ShapeKind::$kind;

                fn push_into<C: SceneCapacities>(self, scene: &mut Scene<C>) -> Result<usize, CapacityError> {
                    Scene::<C>::append(&mut scene.$field, self, CapacityKind::$capacity)
                }
            }
        )*

        /// A read-only view of a scene: what the tracer and the accelerators use.
        #[derive(Clone, Copy, Debug)]
        pub struct SceneView<'a> {
            /// Every object, in the order the scene wrote them: an [`ObjectId`] indexes it.
            pub objects: &'a [ShapeHandle],
            $(#[doc = concat!("The ", $what, ".")] pub $field: &'a [crate::shapes::$type],)*
            /// The surfaces, sorted by number.
            pub surfaces: &'a [SurfaceEntry],
            /// The point lights.
            pub lights: &'a [Light],
            /// The scene parameters.
            pub settings: &'a Settings,
            /// How world coordinates map to normalised space.
            pub normalization: Normalization,
        }

        impl<'a> SceneView<'a> {
            /// The primitive behind a handle.
            #[inline]
            pub fn shape_of(&self, h: ShapeHandle) -> ShapeRef<'a> {
                let i = h.index();
                match h.kind() {
                    $(ShapeKind::$kind => ShapeRef::$kind(&self.$field[i]),)*
                }
            }

            /// [`ShapeRef::intersect_among`] of the primitive behind a handle,
            /// straight from the handle's kind (the object loops' step).
            #[inline(always)]
            pub(crate) fn intersect_handle(
                &self,
                kinds: ShapeKinds,
                h: ShapeHandle,
                ray: &Ray,
                t_max: Scalar,
                leaving: Leaving,
            ) -> Option<Scalar> {
                let i = h.index();
                match h.kind() {
                    $(ShapeKind::$kind if kinds.contains(ShapeKind::$kind) => self.$field.get(i)?.intersect(ray, t_max, leaving),)*
                    _ => None,
                }
            }
        }
    };
}

crate::__shape_kinds!(scene_arenas! {});

/// A primitive the scene stores: which arena it goes in.
pub(crate) trait Stored: Sized {
    /// Its kind.
    const KIND: ShapeKind;

    /// Appends it to its arena, or names the capacity; returns its index there.
    fn push_into<C: SceneCapacities>(self, scene: &mut Scene<C>) -> Result<usize, CapacityError>;
}

impl<C: SceneCapacities> core::fmt::Debug for Scene<C> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Scene")
            .field("profile", &C::NAME)
            .field("objects", &self.view().object_count())
            .field("settings", &self.settings)
            .finish_non_exhaustive()
    }
}

impl<C: SceneCapacities> Default for Scene<C> {
    fn default() -> Self {
        Self::new()
    }
}

impl<C: SceneCapacities> Scene<C> {
    /// Appends `item` to `arena`, one of the scene's, or names the capacity
    /// that ran out.
    fn append<T, A: Arena<T>>(arena: &mut A, item: T, kind: CapacityKind) -> Result<usize, CapacityError> {
        let index = arena.as_slice().len();
        arena.push(item).map_err(|_| Self::full(kind, A::CAPACITY))?;
        Ok(index)
    }

    pub(crate) fn full(kind: CapacityKind, capacity: usize) -> CapacityError {
        CapacityError { kind, capacity, needed: None, profile: C::NAME, desktop: C::DESKTOP }
    }

    /// The error for one surface too many.
    pub(crate) fn surfaces_full() -> CapacityError {
        Self::full(CapacityKind::Surfaces, C::Surfaces::CAPACITY.min(u16::MAX as usize))
    }

    /// Checks that `count` more objects of `kind` fit, before any is built
    /// (a B-spline patch's triangles are checked as a whole).
    pub(crate) fn check_room(&self, kind: ShapeKind, count: usize) -> Result<(), CapacityError> {
        let capacity = Self::capacity_of(kind);
        if self.len_of(kind).saturating_add(count) > capacity {
            return Err(Self::full(kind.capacity(), capacity));
        }
        let objects = C::Objects::CAPACITY.min(ShapeHandle::MAX_INDEX);
        if self.objects.as_slice().len().saturating_add(count) > objects {
            return Err(Self::full(CapacityKind::Objects, objects));
        }
        Ok(())
    }

    /// Stores one object, after checking the room for it and its handle.
    pub(crate) fn push_shape<S: Stored>(&mut self, shape: S) -> Result<(), CapacityError> {
        self.check_room(S::KIND, 1)?;
        let index = shape.push_into(self)?;
        Self::append(&mut self.objects, ShapeHandle::new(S::KIND, index), CapacityKind::Objects).map(|_| ())
    }

    /// Replaces the control-point scratch with `points`, or names the
    /// capacity (nothing kept) if they do not fit.
    pub(crate) fn set_control_points(&mut self, points: impl Iterator<Item = Vec3>) -> Result<(), CapacityError> {
        self.control_points.clear();
        for p in points {
            if self.control_points.push(p).is_err() {
                self.control_points.clear();
                return Err(Self::full(CapacityKind::ControlPoints, C::ControlPoints::CAPACITY));
            }
        }
        Ok(())
    }

    /// Evaluates the patch whose control points were set, pushing its
    /// triangles moved by `shift` (room checked beforehand with
    /// [`Scene::check_room`]); returns how many were made, or the capacity
    /// that ran out (the first triangle that did not fit ends the patch:
    /// none is dropped silently).
    pub(crate) fn push_bspline(
        &mut self,
        order: u32,
        rows: u32,
        cols: u32,
        samples: [u32; 2],
        surface: u16,
        shift: Vec3,
    ) -> Result<usize, CapacityError> {
        let points = core::mem::replace(&mut self.control_points, C::ControlPoints::EMPTY);
        let mut made = Ok(0);
        let first = self.objects.as_slice().len() as u32;
        if let Some(patch) = crate::shapes::Bspline::new(order, rows, cols, points.as_slice()) {
            patch.triangles(samples[0], samples[1], surface, |t| {
                // Moved corners keep their edges, so the same normal: a
                // triangle that was made is made again once moved.
                let corners = t.triangle.polygon.corners.map(|c| c + shift);
                let moved = match shift == Vec3::ZERO {
                    true => Some(t.triangle),
                    false => crate::shapes::Triangle::new(corners, surface),
                };
                let Some(triangle) = moved else { return };
                if let Ok(count) = &mut made {
                    match self.push_shape(SmoothTriangle { triangle, patch: first, ..t }) {
                        Ok(()) => *count += 1,
                        Err(e) => made = Err(e),
                    }
                }
            });
        }
        self.control_points = points;
        self.control_points.clear();
        made
    }

    pub(crate) fn push_light(&mut self, l: Light) -> Result<(), CapacityError> {
        Self::append(&mut self.lights, l, CapacityKind::Lights).map(|_| ())
    }

    /// Stores a surface; at most 65,535 whatever the profile (objects refer
    /// to them by `u16`).
    pub(crate) fn push_surface(&mut self, s: SurfaceEntry) -> Result<(), CapacityError> {
        if self.surfaces.as_slice().len() >= C::Surfaces::CAPACITY.min(u16::MAX as usize) {
            return Err(Self::surfaces_full());
        }
        Self::append(&mut self.surfaces, s, CapacityKind::Surfaces).map(|_| ())
    }

    /// Sorts the surfaces by number (first definition first), so that
    /// [`SceneView::surface_index`] can binary-search them.
    pub(crate) fn sort_surfaces(&mut self) {
        crate::sort::sort_by_key(self.surfaces.as_mut_slice(), |s| (s.number, s.line, s.column));
    }
}

/// What [`Scene::new`] holds until a scene is loaded: zero bits, so that
/// an empty scene in a `static` needs no initial data in flash.
const UNLOADED_SETTINGS: Settings = Settings {
    view: View { eye: [0; 3], look_at: [0; 3], up: [0; 3], viewport: None },
    raster: [0; 2],
    rdepth: 0,
    background: Color::BLACK,
    gamma: Wide::ZERO,
    attenuation: Wide::ZERO,
    samples: 0,
};

const DEFAULT_SETTINGS: Settings = Settings {
    view: View { eye: [0, 0, 10 << 32], look_at: [0; 3], up: [0, 1 << 32, 0], viewport: None },
    raster: [320, 240],
    rdepth: 3,
    background: Color::BLACK,
    gamma: Wide::from_bits(9_448_928_051), // 2.2 in Q32.32, rounded
    attenuation: Wide::ONE,
    samples: 1,
};

impl<'a> SceneView<'a> {
    /// The object `id`. Panics only for an id not taken from this scene.
    #[inline]
    pub fn shape(&self, id: ObjectId) -> ShapeRef<'a> {
        self.shape_of(self.objects[id.0 as usize])
    }

    /// The object `id` belongs to as the scene file wrote it: itself, or for
    /// a triangle of a B-spline patch the patch's first triangle (what the
    /// renderer reports per pixel, so that outlines go round a patch, not
    /// round each of its triangles).
    pub fn written_object(&self, id: ObjectId) -> ObjectId {
        // The handle's kind first: this runs for every primary ray.
        let h = self.objects[id.0 as usize];
        match h.kind() {
            ShapeKind::SmoothTriangle => ObjectId(self.bspline_triangles[h.index()].patch),
            _ => id,
        }
    }

    /// Whether the scene's camera can be set up for an image of
    /// `width`×`height` pixels: the check every renderer makes first, for a
    /// caller that wants the answer before it builds or starts anything.
    pub fn check_camera(&self, width: u32, height: u32) -> Result<(), CameraError> {
        let settings = &self.settings;
        Camera::new(&settings.view, &self.normalization, width, height, settings.samples).map(|_| ())
    }

    /// How many objects the scene holds (B-spline triangles count one each).
    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Ids of all objects, in file order.
    pub fn object_ids(&self) -> impl Iterator<Item = ObjectId> + '_ {
        (0..self.objects.len() as u32).map(ObjectId)
    }

    /// The surface at `index` in [`SceneView::surfaces`] (objects store that index).
    pub fn surface(&self, index: u16) -> &'a Surface {
        &self.surfaces[index as usize].surface
    }

    /// The index of the first surface numbered `number` (surfaces sorted).
    pub fn surface_index(&self, number: u32) -> Option<u16> {
        let i = self.surfaces.partition_point(|s| s.number < number);
        (self.surfaces.get(i)?.number == number).then_some(i as u16)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Scalar;
    use crate::profile::Board16K;
    use crate::shapes::{AxisAlignedBox, Sphere};

    #[test]
    fn an_empty_scene_is_zero_until_cleared() {
        let mut scene: Scene<Board16K> = Scene::new();
        assert_eq!(scene.settings.raster, [0, 0]);
        scene.clear();
        assert_eq!(scene.settings, Settings::default());
        assert_eq!(scene.normalization, Normalization::IDENTITY);
    }

    #[test]
    fn default_settings_match_the_format() {
        let s = Settings::default();
        assert_eq!(s.raster, [320, 240]);
        assert_eq!(s.gamma.to_bits(), (22i64 << 32) / 10);
        assert_eq!(s.view.eye, [0, 0, 10 << 32]);
    }

    #[test]
    fn capacity_errors_name_the_limit() {
        let mut scene: Scene<Board16K> = Scene::new();
        let b = AxisAlignedBox::new(Vec3::ZERO, Vec3::from_bits([1 << 16; 3]), 0);
        for _ in 0..2 {
            scene.push_shape(b).unwrap();
        }
        let e = scene.push_shape(b).unwrap_err();
        assert_eq!((e.kind, e.capacity, e.profile), (CapacityKind::Boxes, 2, "Board16K"));
        assert_eq!(scene.view().object_count(), 2);
        let s = Sphere::new(Vec3::ZERO, Scalar::ONE, 0);
        scene.push_shape(s).unwrap();
        assert_eq!(scene.view().objects[2].kind(), ShapeKind::Sphere);
    }

    crate::profile! {
        /// Room for a 5 × 5 patch's 32 triangles but one.
        struct Patch31 { bspline_triangles: 31, control_points: 9, surfaces: 1 }
    }
    crate::profile! {
        /// Room for 32 patch triangles, but 31 objects.
        struct Objects31 { bspline_triangles: 32, objects: 31, control_points: 9, surfaces: 1 }
    }

    /// A 3 × 3 grid of control points in the plane z = 0.
    fn grid() -> impl Iterator<Item = Vec3> {
        (0..9).map(|i| Vec3::from_bits([(i % 3) << 14, (i / 3) << 14, 0]))
    }

    #[test]
    fn room_is_checked_to_the_last_object() {
        let scene: Scene<Patch31> = Scene::new();
        assert_eq!(scene.check_room(ShapeKind::SmoothTriangle, 31), Ok(()));
        let e = scene.check_room(ShapeKind::SmoothTriangle, 32).unwrap_err();
        assert_eq!((e.kind, e.capacity), (CapacityKind::BsplineTriangles, 31));
        let scene: Scene<Objects31> = Scene::new();
        assert_eq!(scene.check_room(ShapeKind::SmoothTriangle, 31), Ok(()));
        let e = scene.check_room(ShapeKind::SmoothTriangle, 32).unwrap_err();
        assert_eq!((e.kind, e.capacity), (CapacityKind::Objects, 31));
    }

    #[test]
    fn a_patch_that_runs_out_of_room_names_the_capacity() {
        // 2 · 4 · 4 = 32 triangles, pushed without the check beforehand:
        // the one that does not fit is an error, not a triangle dropped.
        let mut scene: Scene<Patch31> = Scene::new();
        scene.set_control_points(grid()).unwrap();
        let e = scene.push_bspline(3, 3, 3, [5, 5], 0, Vec3::ZERO).unwrap_err();
        assert_eq!((e.kind, e.capacity), (CapacityKind::BsplineTriangles, 31));
        let mut scene: Scene<Objects31> = Scene::new();
        scene.set_control_points(grid()).unwrap();
        let e = scene.push_bspline(3, 3, 3, [5, 5], 0, Vec3::ZERO).unwrap_err();
        assert_eq!((e.kind, e.capacity), (CapacityKind::Objects, 31));
        // 2 · 4 · 3 = 24 fit.
        let mut scene: Scene<Patch31> = Scene::new();
        scene.set_control_points(grid()).unwrap();
        assert_eq!(scene.push_bspline(3, 3, 3, [5, 4], 0, Vec3::ZERO), Ok(24));
    }
}
