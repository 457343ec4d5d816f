//! The loaded scene: objects in per-kind arenas, surfaces, lights and the
//! scene parameters, all in normalised space.
//!
//! Invariants (established by [`crate::parse`], relied on by the tracer):
//! - every object, light and the eye lie within the normalised range;
//! - every object's surface index is valid;
//! - objects are numbered in file order ([`ObjectId`]); the tie rule (equal
//!   distance: the earlier object wins) uses that order.
//!
//! [`Scene`] owns the storage (sized by a [`Capacities`] profile); the tracer
//! and the accelerators read it through [`SceneView`], plain slices, so they
//! do not carry the profile's type parameters.

mod camera;
mod normalize;
mod surface;

pub use camera::{Camera, CameraError, View, MAX_SAMPLES, MAX_SIDE};
pub use normalize::{Normalization, WorldPoint, WorldValue};
pub use surface::{Color, Surface, SurfaceEntry};

use crate::capacity::{Arena, Capacities};
use crate::math::{Vec3, Wide};
use crate::shapes::{
    AxisAlignedBox, Rectangle, ShapeHandle, ShapeKind, ShapeRef, SmoothTriangle, Sphere, Superquadric, Triangle,
};

/// An object's position in the scene file (0 for the first object).
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
    pub view: View,
    /// RASTER width and height, 1 to 16384.
    pub raster: [u32; 2],
    pub rdepth: u32,
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

/// A scene exceeded one of its profile's capacities.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CapacityError {
    /// What ran out ("spheres", "objects", …).
    pub what: &'static str,
    pub capacity: usize,
    /// The [`Capacities`] profile.
    pub profile: &'static str,
}

/// Scene storage sized by the profile `C`.
pub struct Scene<C: Capacities> {
    objects: C::Objects,
    spheres: C::Spheres,
    boxes: C::Boxes,
    superquadrics: C::Superquadrics,
    triangles: C::Triangles,
    rectangles: C::Rectangles,
    smooth_triangles: C::SmoothTriangles,
    /// Scratch: the control points of the patch being evaluated.
    control_points: C::ControlPoints,
    surfaces: C::Surfaces,
    lights: C::Lights,
    pub settings: Settings,
    pub normalization: Normalization,
}

impl<C: Capacities> Default for Scene<C> {
    fn default() -> Self {
        Self::new()
    }
}

fn push<T, A: Arena<T>>(
    arena: &mut A,
    item: T,
    what: &'static str,
    profile: &'static str,
) -> Result<usize, CapacityError> {
    let index = arena.as_slice().len();
    arena.push(item).map_err(|_| CapacityError { what, capacity: A::CAPACITY, profile })?;
    Ok(index)
}

impl<C: Capacities> Scene<C> {
    /// An empty scene (a constant expression: it can initialise a `static`).
    pub const fn new() -> Self {
        Scene {
            objects: C::Objects::EMPTY,
            spheres: C::Spheres::EMPTY,
            boxes: C::Boxes::EMPTY,
            superquadrics: C::Superquadrics::EMPTY,
            triangles: C::Triangles::EMPTY,
            rectangles: C::Rectangles::EMPTY,
            smooth_triangles: C::SmoothTriangles::EMPTY,
            control_points: C::ControlPoints::EMPTY,
            surfaces: C::Surfaces::EMPTY,
            lights: C::Lights::EMPTY,
            settings: DEFAULT_SETTINGS,
            normalization: Normalization::IDENTITY,
        }
    }

    /// Empties the scene and resets the parameters to their defaults.
    pub fn clear(&mut self) {
        self.objects.clear();
        self.spheres.clear();
        self.boxes.clear();
        self.superquadrics.clear();
        self.triangles.clear();
        self.rectangles.clear();
        self.smooth_triangles.clear();
        self.control_points.clear();
        self.surfaces.clear();
        self.lights.clear();
        self.settings = Settings::default();
        self.normalization = Normalization::IDENTITY;
    }

    pub fn view(&self) -> SceneView<'_> {
        SceneView {
            objects: self.objects.as_slice(),
            spheres: self.spheres.as_slice(),
            boxes: self.boxes.as_slice(),
            superquadrics: self.superquadrics.as_slice(),
            triangles: self.triangles.as_slice(),
            rectangles: self.rectangles.as_slice(),
            smooth_triangles: self.smooth_triangles.as_slice(),
            surfaces: self.surfaces.as_slice(),
            lights: self.lights.as_slice(),
            settings: &self.settings,
            normalization: self.normalization,
        }
    }

    /// How many objects of `kind` the profile holds.
    pub fn capacity_of(kind: ShapeKind) -> usize {
        match kind {
            ShapeKind::Sphere => C::Spheres::CAPACITY,
            ShapeKind::Box => C::Boxes::CAPACITY,
            ShapeKind::Superquadric => C::Superquadrics::CAPACITY,
            ShapeKind::Triangle => C::Triangles::CAPACITY,
            ShapeKind::Rectangle => C::Rectangles::CAPACITY,
            ShapeKind::SmoothTriangle => C::SmoothTriangles::CAPACITY,
        }
    }

    pub fn object_capacity() -> usize {
        C::Objects::CAPACITY.min(ShapeHandle::MAX_INDEX)
    }

    pub fn surface_capacity() -> usize {
        C::Surfaces::CAPACITY.min(u16::MAX as usize)
    }

    pub fn light_capacity() -> usize {
        C::Lights::CAPACITY
    }

    fn register(&mut self, kind: ShapeKind, index: usize) -> Result<(), CapacityError> {
        if self.objects.as_slice().len() >= Self::object_capacity() {
            return Err(CapacityError { what: "objects", capacity: Self::object_capacity(), profile: C::NAME });
        }
        push(&mut self.objects, ShapeHandle::new(kind, index), "objects", C::NAME).map(|_| ())
    }

    /// Checks that one more object of `kind` fits, before it is built.
    pub fn check_room(&self, kind: ShapeKind) -> Result<(), CapacityError> {
        let (what, len) = match kind {
            ShapeKind::Sphere => ("spheres", self.spheres.as_slice().len()),
            ShapeKind::Box => ("boxes", self.boxes.as_slice().len()),
            ShapeKind::Superquadric => ("superquadrics", self.superquadrics.as_slice().len()),
            ShapeKind::Triangle => ("triangles", self.triangles.as_slice().len()),
            ShapeKind::Rectangle => ("rectangles", self.rectangles.as_slice().len()),
            ShapeKind::SmoothTriangle => ("B-spline triangles", self.smooth_triangles.as_slice().len()),
        };
        let capacity = Self::capacity_of(kind).min(ShapeHandle::MAX_INDEX);
        if len >= capacity {
            return Err(CapacityError { what, capacity, profile: C::NAME });
        }
        if self.objects.as_slice().len() >= Self::object_capacity() {
            return Err(CapacityError { what: "objects", capacity: Self::object_capacity(), profile: C::NAME });
        }
        Ok(())
    }

    pub fn push_sphere(&mut self, s: Sphere) -> Result<(), CapacityError> {
        self.check_room(ShapeKind::Sphere)?;
        let i = push(&mut self.spheres, s, "spheres", C::NAME)?;
        self.register(ShapeKind::Sphere, i)
    }

    pub fn push_box(&mut self, s: AxisAlignedBox) -> Result<(), CapacityError> {
        self.check_room(ShapeKind::Box)?;
        let i = push(&mut self.boxes, s, "boxes", C::NAME)?;
        self.register(ShapeKind::Box, i)
    }

    pub fn push_superquadric(&mut self, s: Superquadric) -> Result<(), CapacityError> {
        self.check_room(ShapeKind::Superquadric)?;
        let i = push(&mut self.superquadrics, s, "superquadrics", C::NAME)?;
        self.register(ShapeKind::Superquadric, i)
    }

    pub fn push_triangle(&mut self, s: Triangle) -> Result<(), CapacityError> {
        self.check_room(ShapeKind::Triangle)?;
        let i = push(&mut self.triangles, s, "triangles", C::NAME)?;
        self.register(ShapeKind::Triangle, i)
    }

    pub fn push_rectangle(&mut self, s: Rectangle) -> Result<(), CapacityError> {
        self.check_room(ShapeKind::Rectangle)?;
        let i = push(&mut self.rectangles, s, "rectangles", C::NAME)?;
        self.register(ShapeKind::Rectangle, i)
    }

    pub fn push_smooth_triangle(&mut self, s: SmoothTriangle) -> Result<(), CapacityError> {
        self.check_room(ShapeKind::SmoothTriangle)?;
        let i = push(&mut self.smooth_triangles, s, "B-spline triangles", C::NAME)?;
        self.register(ShapeKind::SmoothTriangle, i)
    }

    /// Checks that `count` more objects of `kind` fit, before any is built
    /// (a B-spline patch's triangles are checked as a whole).
    pub fn check_room_for(&self, kind: ShapeKind, count: usize) -> Result<(), CapacityError> {
        if count == 0 {
            return Ok(());
        }
        let (what, len) = match kind {
            ShapeKind::SmoothTriangle => ("B-spline triangles", self.smooth_triangles.as_slice().len()),
            _ => return self.check_room(kind),
        };
        let capacity = Self::capacity_of(kind).min(ShapeHandle::MAX_INDEX);
        if len.saturating_add(count) > capacity {
            return Err(CapacityError { what, capacity, profile: C::NAME });
        }
        if self.objects.as_slice().len().saturating_add(count) > Self::object_capacity() {
            return Err(CapacityError { what: "objects", capacity: Self::object_capacity(), profile: C::NAME });
        }
        Ok(())
    }

    /// Replaces the control-point scratch with `points`; `false` (and
    /// nothing kept) if they do not fit.
    pub fn set_control_points(&mut self, points: impl Iterator<Item = Vec3>) -> bool {
        self.control_points.clear();
        for p in points {
            if self.control_points.push(p).is_err() {
                self.control_points.clear();
                return false;
            }
        }
        true
    }

    /// How many control points one patch may have.
    pub fn control_point_capacity() -> usize {
        C::ControlPoints::CAPACITY
    }

    /// Evaluates the patch whose control points were set, pushing its
    /// triangles (room checked beforehand with [`Scene::check_room_for`]);
    /// returns how many were made.
    pub fn push_bspline(&mut self, order: u32, rows: u32, cols: u32, samples: [u32; 2], surface: u16) -> usize {
        let points = core::mem::replace(&mut self.control_points, C::ControlPoints::EMPTY);
        let mut made = 0;
        let first = self.objects.as_slice().len() as u32;
        if let Some(patch) = crate::shapes::Bspline::new(order, rows, cols, points.as_slice()) {
            patch.triangles(samples[0], samples[1], surface, |t| {
                if self.push_smooth_triangle(SmoothTriangle { patch: first, ..t }).is_ok() {
                    made += 1;
                }
            });
        }
        self.control_points = points;
        self.control_points.clear();
        made
    }

    pub fn push_light(&mut self, l: Light) -> Result<(), CapacityError> {
        push(&mut self.lights, l, "lights", C::NAME).map(|_| ())
    }

    pub fn push_surface(&mut self, s: SurfaceEntry) -> Result<(), CapacityError> {
        if self.surfaces.as_slice().len() >= Self::surface_capacity() {
            return Err(CapacityError { what: "surfaces", capacity: Self::surface_capacity(), profile: C::NAME });
        }
        push(&mut self.surfaces, s, "surfaces", C::NAME).map(|_| ())
    }

    /// Sorts the surfaces by number (first definition first), so that
    /// [`SceneView::surface_index`] can binary-search them.
    pub fn sort_surfaces(&mut self) {
        self.surfaces.as_mut_slice().sort_unstable_by_key(|s| (s.number, s.line, s.column));
    }

    /// Drops the objects and lights but keeps the surfaces (the parser's
    /// second pass rebuilds them in normalised space).
    pub fn clear_geometry(&mut self) {
        self.objects.clear();
        self.spheres.clear();
        self.boxes.clear();
        self.superquadrics.clear();
        self.triangles.clear();
        self.rectangles.clear();
        self.smooth_triangles.clear();
        self.control_points.clear();
        self.lights.clear();
    }
}

const DEFAULT_SETTINGS: Settings = Settings {
    view: View { eye: [0, 0, 10 << 32], look_at: [0; 3], up: [0, 1 << 32, 0], viewport: None },
    raster: [320, 240],
    rdepth: 3,
    background: Color::BLACK,
    gamma: Wide::from_bits(9_448_928_051), // 2.2 in Q32.32, rounded
    attenuation: Wide::ONE,
    samples: 1,
};

/// A read-only view of a scene: what the tracer and the accelerators use.
#[derive(Clone, Copy, Debug)]
pub struct SceneView<'a> {
    pub objects: &'a [ShapeHandle],
    pub spheres: &'a [Sphere],
    pub boxes: &'a [AxisAlignedBox],
    pub superquadrics: &'a [Superquadric],
    pub triangles: &'a [Triangle],
    pub rectangles: &'a [Rectangle],
    pub smooth_triangles: &'a [SmoothTriangle],
    pub surfaces: &'a [SurfaceEntry],
    pub lights: &'a [Light],
    pub settings: &'a Settings,
    pub normalization: Normalization,
}

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
            ShapeKind::SmoothTriangle => ObjectId(self.smooth_triangles[h.index()].patch),
            _ => id,
        }
    }

    #[inline]
    pub fn shape_of(&self, h: ShapeHandle) -> ShapeRef<'a> {
        let i = h.index();
        match h.kind() {
            ShapeKind::Sphere => ShapeRef::Sphere(&self.spheres[i]),
            ShapeKind::Box => ShapeRef::Box(&self.boxes[i]),
            ShapeKind::Superquadric => ShapeRef::Superquadric(&self.superquadrics[i]),
            ShapeKind::Triangle => ShapeRef::Triangle(&self.triangles[i]),
            ShapeKind::Rectangle => ShapeRef::Rectangle(&self.rectangles[i]),
            ShapeKind::SmoothTriangle => ShapeRef::SmoothTriangle(&self.smooth_triangles[i]),
        }
    }

    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Ids of all objects, in file order.
    pub fn object_ids(&self) -> impl Iterator<Item = ObjectId> + '_ {
        (0..self.objects.len() as u32).map(ObjectId)
    }

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
    use crate::capacity::Board16K;
    use crate::math::Scalar;

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
            scene.push_box(b).unwrap();
        }
        let e = scene.push_box(b).unwrap_err();
        assert_eq!((e.what, e.capacity, e.profile), ("boxes", 2, "Board16K"));
        assert_eq!(scene.view().object_count(), 2);
        let s = Sphere::new(Vec3::ZERO, Scalar::ONE, 0);
        scene.push_sphere(s).unwrap();
        assert_eq!(scene.view().objects[2].kind(), ShapeKind::Sphere);
    }
}
