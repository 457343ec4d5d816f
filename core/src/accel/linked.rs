//! What a build links into its tracer, as its profile configures it
//! ([`Linked`]: the shape kinds, the octree, the screen lists, the light
//! buffer, coherence), and the one accelerator a loaded scene traces with
//! over them ([`SceneAccelerator`]: its octree or every object, the light
//! buffer in front of its shadow rays).
//!
//! Invariant: every choice is a constant of the profile, so that a build
//! without an octree, a light buffer, screen lists or coherence links none
//! of their code; a scene's own choice (its mode, whether it has a buffer)
//! is made at load and only narrows these.

use super::light_buffer::{ShadowLinks, ShadowQuery};
use super::{naive, Accelerator, Hit, LightBuffer, LightBuffered, Mailbox, OctreeCapacities, OctreeStore, RayStart};
use crate::math::Scalar;
use crate::scene::SceneView;
use crate::shapes::{Ray, ShapeKinds};
use core::fmt;

/// What a build links: every [`Profile`](crate::profile::Profile) is one
/// (see [`profile!`](crate::profile!)'s options). The tracer dispatches on
/// its shape kinds only ([`OctreeCapacities::KINDS`]), marks a mailbox only
/// when its octree has room for boxes, and links the screen lists, the
/// light buffer and coherence only when it says so.
pub trait Linked: OctreeCapacities + Sized {
    /// The octree, with a walk as deep as the build allows.
    type Octree: OctreeStore + Sync;
    /// Whether camera rays find their hits among the objects seen around
    /// their pixel (see [`Renderer`](crate::render::Renderer)): the same
    /// image, for RAM.
    const FIRST_HITS: bool = false;
    /// Whether, with [`Linked::FIRST_HITS`], the reflections of camera rays
    /// off a mirror along an axis (a floor) find their hits the same way,
    /// among the objects seen around their pixel from the eye's image in
    /// it: the same image, for as much RAM again.
    const MIRROR_HITS: bool = false;
    /// Whether an animation's frames re-trace only what the motion can
    /// change (the tracer watches every ray of a frame against the motion
    /// to come); without it every frame is traced whole, the same pictures.
    const COHERENCE: bool = false;
    /// Whether shadow rays may go through a light buffer.
    const LIGHT_BUFFER: bool = false;
    /// Whether that buffer is a cube, or cones (see
    /// [`LightBuffer::build`](crate::accel::LightBuffer::build)): a
    /// `profile!` links one form, cones when it holds no more objects than
    /// [`AccelMode::AUTO_NAIVE_UP_TO`](crate::AccelMode::AUTO_NAIVE_UP_TO),
    /// else a cube, for every scene, few objects or not (on a desktop's
    /// 64-bit core a cube costs little, and it serves large flat objects
    /// better: fig5_8 at 320×240 took 7 % more instructions with cones,
    /// fig5_1 4.7 % fewer).
    const LIGHT_CUBES: bool = Self::LIGHT_BUFFER;
    /// See [`Linked::LIGHT_CUBES`].
    const LIGHT_CONES: bool = false;
}

/// A build's shadow rays test its own shapes, through the light buffer's
/// form it links.
impl<L: Linked> ShadowLinks for L {
    const KINDS: ShapeKinds = L::KINDS;
    const CUBES: bool = L::LIGHT_CUBES || !L::LIGHT_CONES;
    const CONES: bool = L::LIGHT_CONES;
}

/// Whether builds of `L` mark the mailbox: only an octree's queries do.
pub(crate) const fn uses_mailbox<L: Linked>() -> bool {
    <L::Octree as OctreeStore>::HAS_BOXES
}

/// What a loaded scene traces with ([`LoadedScene::accelerator`](crate::LoadedScene::accelerator)):
/// its octree, or (without one) every object, over only the shape kinds
/// its build links, and the light buffer in front of its shadow rays when
/// the build links one.
pub struct SceneAccelerator<'r, L: Linked> {
    lit: LightBuffered<'r, Indexed<'r, L>>,
}

/// A scene's octree, or every object, over a build's kinds.
pub(crate) struct Indexed<'r, L: Linked> {
    octree: Option<&'r L::Octree>,
}

impl<L: Linked> Clone for Indexed<'_, L> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<L: Linked> Copy for Indexed<'_, L> {}

impl<L: Linked> Clone for SceneAccelerator<'_, L> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<L: Linked> Copy for SceneAccelerator<'_, L> {}

impl<L: Linked> fmt::Debug for SceneAccelerator<'_, L> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SceneAccelerator")
            .field("octree", &self.lit.accel().octree.is_some())
            .field("light_buffer", &self.lit.buffer())
            .finish()
    }
}

impl<'r, L: Linked> SceneAccelerator<'r, L> {
    /// Over `octree` (none: every object), `lights` in front of the shadow
    /// rays.
    pub(crate) fn new(octree: Option<&'r L::Octree>, lights: LightBuffer<'r>) -> Self {
        SceneAccelerator { lit: LightBuffered::new(Indexed { octree }, lights) }
    }

    /// The shadow rays' light buffer.
    pub(crate) fn light_buffer(&self) -> LightBuffer<'r> {
        self.lit.buffer()
    }

    /// The same octree, `lights` in front of the shadow rays.
    pub(crate) fn with_light_buffer(self, lights: LightBuffer<'r>) -> Self {
        SceneAccelerator::new(self.lit.accel().octree, lights)
    }

    /// Whether camera rays may find their hits in a renderer's screen lists:
    /// when the build links them, and its octree (if any) walks by 3DDDA
    /// (the thesis's walk stays the thesis's for every ray).
    #[inline]
    pub(crate) fn first_hits_by_screen(&self) -> bool {
        L::FIRST_HITS && self.lit.accel().octree().is_none_or(|octree| octree.walked_by_dda())
    }

    /// Whether reflections off a mirror may find their hits in screen lists
    /// too: when the build links them and camera rays use theirs, and
    /// reflected rays would walk an octree. Without one a reflection tests
    /// a few objects (the naive mode's), which cost what the lists would.
    #[inline]
    pub(crate) fn mirror_hits_by_screen(&self) -> bool {
        L::MIRROR_HITS && self.first_hits_by_screen() && self.lit.accel().octree().is_some()
    }
}

impl<L: Linked> Indexed<'_, L> {
    /// The octree, if the build has room for one and the scene uses it.
    #[inline(always)]
    fn octree(&self) -> Option<&L::Octree> {
        self.octree.filter(|_| <L::Octree as OctreeStore>::HAS_BOXES)
    }
}

impl<L: Linked> Accelerator for Indexed<'_, L> {
    #[inline]
    fn nearest(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> Option<Hit> {
        match self.octree() {
            Some(octree) => octree.nearest(scene, ray, start, mailbox),
            None => naive::nearest(L::KINDS, scene, ray, start),
        }
    }

    #[inline]
    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        match self.octree() {
            Some(octree) => octree.occluded(scene, ray, t_max, start, mailbox),
            None => naive::occluded(L::KINDS, scene, ray, t_max, start, mailbox),
        }
    }

    #[inline]
    fn occluded_toward(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        light: usize,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        match self.octree() {
            Some(octree) => octree.occluded_toward(scene, ray, t_max, light, start, mailbox),
            None => self.occluded(scene, ray, t_max, start, mailbox),
        }
    }
}

impl<L: Linked> Accelerator for SceneAccelerator<'_, L> {
    #[inline]
    fn nearest(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> Option<Hit> {
        self.lit.accel().nearest(scene, ray, start, mailbox)
    }

    #[inline]
    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        self.lit.accel().occluded(scene, ray, t_max, start, mailbox)
    }

    #[inline]
    fn occluded_toward(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        light: usize,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        match L::LIGHT_BUFFER {
            true => {
                let query = ShadowQuery { scene, ray, t_max, light, start };
                self.lit.occluded_toward_among::<L>(&query, mailbox)
            }
            false => self.lit.accel().occluded_toward(scene, ray, t_max, light, start, mailbox),
        }
    }
}
