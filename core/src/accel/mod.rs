//! The seam between the tracer and the acceleration structures: a nearest-hit
//! query and an any-hit query for shadow rays.
//!
//! Contract every accelerator keeps, so that all modes give the same bits:
//! - [`Accelerator::nearest`] returns the hit with the smallest `t`, and among
//!   equal `t` the smallest [`ObjectId`] (the format's tie rule);
//! - [`Accelerator::occluded`] answers whether any object is hit with
//!   `0 < t ≤ t_max`, and may stop at the first one;
//! - the object a ray starts on is treated as [`RayStart`] says.

mod naive;

pub use naive::Naive;

use crate::math::Scalar;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Leaving, Ray};

/// The nearest intersection: the cheap part of a hit (pbrt's split); the
/// surface data is computed only for the hit that wins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hit {
    pub t: Scalar,
    pub object: ObjectId,
}

/// The object a secondary ray leaves, and how it leaves it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayStart {
    pub object: ObjectId,
    pub leaving: Leaving,
}

impl RayStart {
    /// How the ray relates to `object`.
    #[inline]
    pub fn leaving(start: Option<RayStart>, object: ObjectId) -> Leaving {
        match start {
            Some(s) if s.object == object => s.leaving,
            _ => Leaving::No,
        }
    }
}

/// An intersection strategy over a scene.
pub trait Accelerator {
    /// The nearest hit along `ray` (`t > 0`), ties to the earlier object.
    fn nearest(&self, scene: &SceneView<'_>, ray: &Ray, start: Option<RayStart>) -> Option<Hit>;

    /// Whether anything is hit with `0 < t ≤ t_max`.
    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
    ) -> bool;
}
