//! A scene's mirror: a reflective triangle or rectangle across an axis (a
//! floor), whose reflections of camera rays are the rays of the eye's
//! mirror image, so a renderer may list their hits as it lists the camera
//! rays' (`render/first_hit.rs`, `shade/mirror.rs`).
//!
//! Invariant: a reflection counts as the mirror's ([`MirrorPlane::mirrors`])
//! only when its direction is the camera ray's mirror image exactly (as
//! `Dir::reflect_about` makes it for a shading normal exactly ±1 on the
//! plane's axis) and it leaves from within [`MirrorPlane::NEAR`] of the
//! plane, so that it runs parallel to a ray of the mirrored camera at most
//! [`MirrorPlane::OFFSET`] from it.

use super::SceneView;
use crate::math::{Dir, Vec3, UNIT_ONE};
use crate::shapes::{Ray, ShapeRef};

/// A plane across `axis` at `coordinate` (Q16.16 bits, normalised space):
/// the one mirror whose reflections of camera rays a renderer lists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct MirrorPlane {
    pub axis: usize,
    pub coordinate: i32,
}

impl MirrorPlane {
    /// How far from the plane (in Q16.16 units along its axis) a reflected
    /// ray may leave and still be listed: the hit point's rounding keeps it
    /// within a unit or two of a flat polygon's plane.
    pub const NEAR: i32 = 16;

    /// How far a listed ray may run from the mirrored camera's ray of the
    /// same offsets: `2·NEAR` for the point's distance from the plane, and
    /// `3·√3` for its rounding (each coordinate below one unit off the
    /// camera ray's exact point, counted on both sides of the mirror), with
    /// room to spare. The lists widen every bound by it.
    pub const OFFSET: i64 = 64;

    /// Whether `reflection`, the reflected ray of camera ray `camera_ray`
    /// (from its hit point), is listed: its direction the camera ray's
    /// mirrored exactly, its origin near the plane (the module's invariant).
    #[inline]
    pub fn mirrors(&self, camera_ray: &Ray, reflection: &Ray) -> bool {
        let (d, r) = (camera_ray.dir.bits(), reflection.dir.bits());
        (0..3).all(|a| r[a] == if a == self.axis { d[a].wrapping_neg() } else { d[a] })
            && reflection.origin.bits()[self.axis].abs_diff(self.coordinate) <= Self::NEAR as u32
    }

    /// Whether the flat shape of normal `normal` through `corner` lies in a
    /// plane across an axis (its normal exactly ±1 on it): that plane.
    pub fn of_flat(normal: Dir, corner: Vec3) -> Option<MirrorPlane> {
        let n = normal.bits();
        let axis = (0..3).find(|&a| n[a].unsigned_abs() as i64 == UNIT_ONE)?;
        (0..3).all(|a| a == axis || n[a] == 0).then(|| MirrorPlane { axis, coordinate: corner.bits()[axis] })
    }
}

impl SceneView<'_> {
    /// The scene's mirror, if any: the plane of its first reflective
    /// triangle or rectangle (in file order) that lies across an axis.
    pub(crate) fn mirror(&self) -> Option<MirrorPlane> {
        self.object_ids().find_map(|id| {
            let shape = self.shape(id);
            let (normal, corner) = match shape {
                ShapeRef::Triangle(flat) => (flat.normal(), flat.polygon.corners[0]),
                ShapeRef::Rectangle(flat) => (flat.normal(), flat.polygon.corners[0]),
                _ => return None,
            };
            let reflective = self.surface(shape.surface()).reflectivity.to_bits() > 0;
            MirrorPlane::of_flat(normal, corner).filter(|_| reflective)
        })
    }

    /// Whether the scene has a mirror whose reflections of camera rays a
    /// renderer may list (see [`Linked::MIRROR_HITS`](crate::profile::Linked::MIRROR_HITS)):
    /// a reflective triangle or rectangle across an axis, such as a floor.
    /// A build script gives its profile `mirror_hits` when it has.
    ///
    /// ```
    /// use octrace_core::{profile::Board16K, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let floor = "SURFACE 1 .1 .1 .1 .5 .5 .5 0 0 0 1 0.5 0\nRECTANGLE 1 -5 0 5 5 0 5 5 0 -5 -5 0 -5\n";
    /// assert!(raytracer.load(floor)?.view().has_mirror());
    /// let matte = "SURFACE 1 .1 .1 .1 .5 .5 .5 0 0 0 1 0 0\nRECTANGLE 1 -5 0 5 5 0 5 5 0 -5 -5 0 -5\n";
    /// assert!(!raytracer.load(matte)?.view().has_mirror());
    /// # Ok::<(), octrace_core::LoadError>(())
    /// ```
    pub fn has_mirror(&self) -> bool {
        self.mirror().is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_mirrored_direction_near_the_plane_is_listed() {
        let floor = MirrorPlane { axis: 1, coordinate: -(1 << 16) };
        let eye = Vec3::from_bits([0, 3 << 16, 10 << 16]);
        let camera_ray = Ray { origin: eye, dir: Dir::normalize([1, -3, -5]).unwrap() };
        let point = Vec3::from_bits([5 << 16, -(1 << 16) + 3, 7]);
        let reflected = |normal: Dir, origin: Vec3| Ray { origin, dir: (-camera_ray.dir).reflect_about(normal) };
        assert!(floor.mirrors(&camera_ray, &reflected(Dir::Y, point)));
        assert!(floor.mirrors(&camera_ray, &reflected(-Dir::Y, point)));
        let tilted = Dir::normalize([1, 1 << 12, 0]).unwrap();
        assert!(!floor.mirrors(&camera_ray, &reflected(tilted, point)), "not exactly along the axis");
        assert!(!floor.mirrors(&camera_ray, &reflected(Dir::X, point)), "another axis");
        let above = Vec3::from_bits([5 << 16, -(1 << 16) + MirrorPlane::NEAR + 1, 7]);
        assert!(!floor.mirrors(&camera_ray, &reflected(Dir::Y, above)), "too far from the plane");
    }

    #[test]
    fn a_flat_shape_across_an_axis_is_a_plane() {
        let corner = Vec3::from_bits([1, 2 << 16, 3]);
        assert_eq!(MirrorPlane::of_flat(-Dir::Y, corner), Some(MirrorPlane { axis: 1, coordinate: 2 << 16 }));
        assert_eq!(MirrorPlane::of_flat(Dir::normalize([1, 1, 0]).unwrap(), corner), None);
    }
}
