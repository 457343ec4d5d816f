//! The naive mode: every object tested for every ray, as the thesis's first
//! version did. It is the reference the other modes must match bit for bit.
//! Each object is tested once by construction, so it needs no mailbox.

use super::{Accelerator, Hit, Mailbox, RayStart};
use crate::math::Scalar;
use crate::profile::Profile;
use crate::scene::{ObjectId, SceneView};
use crate::shapes::{Ray, ShapeKinds};
use core::marker::PhantomData;

/// Tests every object, in file order.
#[derive(Clone, Copy, Debug, Default)]
pub struct Naive;

impl Accelerator for Naive {
    const USES_MAILBOX: bool = false;

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

/// [`Naive`] over a scene of the profile `P`: it dispatches only on the
/// shape kinds `P` has room for, so a board links no other kind's tests.
pub(crate) struct NaiveFor<P>(PhantomData<P>);

impl<P> NaiveFor<P> {
    pub const fn new() -> Self {
        NaiveFor(PhantomData)
    }
}

impl<P: Profile> Accelerator for NaiveFor<P> {
    const KINDS: ShapeKinds = ShapeKinds::with_room(&P::COUNTS);
    const USES_MAILBOX: bool = false;

    /// Only the [`Raytracer`](crate::Raytracer) tests every object this
    /// way: it gives camera rays the screen lists when its profile has
    /// room for them and the naive mode was not asked for by name.
    fn first_hits_by_screen(&self) -> bool {
        true
    }

    fn nearest(&self, scene: &SceneView<'_>, ray: &Ray, start: Option<RayStart>, _: &mut Mailbox<'_>) -> Option<Hit> {
        nearest(Self::KINDS, scene, ray, start)
    }

    fn occluded(
        &self,
        scene: &SceneView<'_>,
        ray: &Ray,
        t_max: Scalar,
        start: Option<RayStart>,
        mailbox: &mut Mailbox<'_>,
    ) -> bool {
        occluded(Self::KINDS, scene, ray, t_max, start, mailbox)
    }
}

/// Every object of `kinds` in file order; the nearest hit wins.
#[inline(always)]
fn nearest(kinds: ShapeKinds, scene: &SceneView<'_>, ray: &Ray, start: Option<RayStart>) -> Option<Hit> {
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
fn occluded(
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
