//! The naive mode: every object tested for every ray, as the thesis's first
//! version did. It is the reference the other modes must match bit for bit.
//! Each object is tested once by construction, so it needs no mailbox.

use super::{Accelerator, Hit, Mailbox, RayStart};
use crate::math::Scalar;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Ray, ShapeKinds};

/// Tests every object, in file order.
#[derive(Clone, Copy, Debug, Default)]
pub struct Naive;

impl Accelerator for Naive {
    fn nearest(&self, scene: &SceneView<'_>, ray: &Ray, start: Option<RayStart>, _: &mut Mailbox<'_>) -> Option<Hit> {
        nearest(ShapeKinds::ALL, scene, ray, start)
    }

    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        occluded(ShapeKinds::ALL, scene, ray, t_max, start, mailbox)
    }
}

/// Every object of `kinds` in file order; the nearest hit wins. Also the
/// [`Raytracer`](crate::Raytracer)'s naive walk, over the kinds its
/// profile has room for.
#[inline(always)]
pub(crate) fn nearest(kinds: ShapeKinds, scene: &SceneView<'_>, ray: &Ray, start: Option<RayStart>) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    let mut t_max = Scalar::MAX;
    for (i, &handle) in scene.objects.iter().enumerate() {
        let object = ObjectId(i as u32);
        let leaving = RayStart::leaving(start, object);
        if let Some(t) = scene.intersect_handle(kinds, handle, ray, t_max, leaving) {
            // File order: a later object wins only when strictly nearer.
            if best.is_none_or(|b| t < b.t) {
                best = Some(Hit { t, object });
                t_max = t;
            }
        }
    }
    best
}

/// Whether any object of `kinds` blocks the ray; the first that does is
/// left in the mailbox.
#[inline(always)]
pub(crate) fn occluded(
    kinds: ShapeKinds,
    scene: &SceneView<'_>,
    ray: &Ray,
    t_max: Scalar,
    start: Option<RayStart>,
    mailbox: &mut Mailbox<'_>,
) -> bool {
    let blocker = scene.objects.iter().enumerate().position(|(i, &handle)| {
        let leaving = RayStart::leaving(start, ObjectId(i as u32));
        scene.intersect_handle(kinds, handle, ray, t_max, leaving).is_some()
    });
    if let Some(i) = blocker {
        mailbox.blocker = i as u32;
    }
    blocker.is_some()
}
