//! Where the tracer finds the hit of a camera ray's reflection off the
//! scene's mirror (`scene/mirror.rs`): a renderer's screen lists.
//!
//! Invariant: only the reflection [`MirrorPlane::mirrors`] admits is asked
//! for, and the answer is the accelerator's, bit for bit.

use super::Poll;
use crate::accel::{Hit, RayStart};
use crate::math::Scalar;
use crate::scene::{MirrorPlane, SceneView};
use crate::shapes::Ray;

/// Where the tracer finds the hit of a camera ray's reflection off the
/// renderer's mirror, if anywhere: the render module's screen lists are
/// behind it.
pub(crate) trait Mirror {
    /// Whether it can list anything: false, the checks are compiled away.
    const LISTS: bool = true;

    /// The plane whose reflections it lists.
    fn plane(&self) -> Option<MirrorPlane>;

    /// The nearest hit of `ray`, the reflection (leaving as `start` says) of
    /// the sample's camera ray, which hit the plane at `primary_t`: what
    /// the accelerator's `nearest` gives, or `None` when the lists cannot
    /// tell (the caller then walks). Lists still to be made are made first,
    /// `poll` asked before each object.
    fn nearest<Q: Poll>(
        &mut self,
        scene: &SceneView<'_>,
        ray: &Ray,
        start: Option<RayStart>,
        primary_t: Scalar,
        poll: &mut Q,
    ) -> Option<Option<Hit>>;
}

/// No mirror: every reflected ray walks the accelerator.
#[cfg(test)]
pub(crate) struct NoMirror;

#[cfg(test)]
impl Mirror for NoMirror {
    const LISTS: bool = false;

    #[inline(always)]
    fn plane(&self) -> Option<MirrorPlane> {
        None
    }

    #[inline(always)]
    fn nearest<Q: Poll>(
        &mut self,
        _: &SceneView<'_>,
        _: &Ray,
        _: Option<RayStart>,
        _: Scalar,
        _: &mut Q,
    ) -> Option<Option<Hit>> {
        None
    }
}
