//! What other cores render a loaded scene with: the scene shared, and the
//! accelerator over only the shape kinds and structures its profile holds.

use crate::accel::{naive, Accelerator, Hit, LightBuffer, Mailbox, OctreeStore, RayStart};
use crate::math::Scalar;
use crate::profile::Profile;
use crate::render::Renderer;
use crate::scene::{CameraError, SceneView};
use crate::shapes::{Ray, ShapeKinds};
use core::fmt;
use embedded_graphics_core::geometry::Size;

use super::{light_buffer, RendererRoom, ScreenLists};

/// What another core needs to render a [`LoadedScene`](super::LoadedScene)
/// ([`LoadedScene::share`](super::LoadedScene::share)): its objects, its accelerator and whether its
/// camera rays use the screen lists. `Copy`, read-only and `Send`: hand it
/// to the other core when you start it.
///
/// ```
/// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*};
/// use octrace_core::RendererRoom;
/// use octrace_core::{profile::Board16K, render::interleaved_rows, Raytracer};
///
/// let mut raytracer = Raytracer::<Board16K>::new();
/// let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n")?;
/// let mut whole = MockDisplay::<Rgb888>::new();
/// Image::new(&scene.image(Size::new(8, 8)), Point::zero()).draw(&mut whole)?;
///
/// // Core 1 (here, a thread) renders every other row with room of its own.
/// let shared = scene.share();
/// let rows = std::thread::scope(|s| {
///     s.spawn(move || {
///         let mut room = RendererRoom::<Board16K>::new();
///         let mut renderer = shared.renderer(&mut room, Size::new(8, 8)).unwrap();
///         let row = |y| renderer.row(y, 0..8).map(|p| p.color).collect::<Vec<_>>();
///         interleaved_rows(8, 1, 2).map(row).collect::<Vec<_>>()
///     })
///     .join()
///     .unwrap()
/// });
/// for (y, row) in interleaved_rows(8, 1, 2).zip(rows) {
///     for (x, color) in row.into_iter().enumerate() {
///         assert_eq!(whole.get_pixel(Point::new(x as i32, y as i32)), Some(color));
///     }
/// }
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
pub struct SharedScene<'r, P: Profile> {
    pub(super) view: SceneView<'r>,
    pub(super) accelerator: SceneAccelerator<'r, P>,
    pub(super) first_hits: bool,
}

impl<P: Profile> Clone for SharedScene<'_, P> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile> Copy for SharedScene<'_, P> {}

impl<P: Profile> fmt::Debug for SharedScene<'_, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SharedScene")
            .field("objects", &self.view.object_count())
            .field("accelerator", &self.accelerator)
            .field("first_hits", &self.first_hits)
            .finish()
    }
}

impl<'r, P: Profile> SharedScene<'r, P> {
    /// The scene's objects, surfaces, lights and settings.
    pub fn view(&self) -> SceneView<'r> {
        self.view
    }

    /// A renderer of an image of `size` pixels over this scene that writes
    /// only `room`: each core renders with one of its own, and any split of
    /// the image between them gives the same bits as one core.
    pub fn renderer<'a>(
        &'a self,
        room: &'a mut RendererRoom<P>,
        size: Size,
    ) -> Result<Renderer<'a, SceneAccelerator<'r, P>>, CameraError> {
        let (mailbox, lists) = room.prepare(self.view.object_count(), self.first_hits);
        renderer_in(self.view, &self.accelerator, size, Some(mailbox), lists)
    }
}

/// What a [`LoadedScene`](super::LoadedScene) renders with ([`LoadedScene::accelerator`](super::LoadedScene::accelerator)):
/// its octree, or (without one) every object, over only the shape kinds
/// its profile has room for, and with the screen lists only if the profile
/// has room for them. Both are decided on the profile's constants, so that
/// a build without an octree or without the lists links none of their code.
pub struct SceneAccelerator<'r, P: Profile> {
    pub(super) octree: Option<&'r P::Octree>,
    pub(super) lights: LightBuffer<'r>,
}

impl<P: Profile> Clone for SceneAccelerator<'_, P> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile> Copy for SceneAccelerator<'_, P> {}

impl<P: Profile> fmt::Debug for SceneAccelerator<'_, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SceneAccelerator")
            .field("octree", &self.octree.is_some())
            .field("light_buffer", &self.lights)
            .finish()
    }
}

impl<P: Profile> SceneAccelerator<'_, P> {
    /// The octree, if the profile has room for one and the scene uses it.
    #[inline(always)]
    fn octree(&self) -> Option<&P::Octree> {
        self.octree.filter(|_| <P::Octree as OctreeStore>::HAS_BOXES)
    }
}

impl<P: Profile> Accelerator for SceneAccelerator<'_, P> {
    const KINDS: ShapeKinds = ShapeKinds::with_room(&P::COUNTS);
    // The octree's mailbox, only if the profile can have an octree.
    const USES_MAILBOX: bool = <P::Octree as OctreeStore>::HAS_BOXES && <P::Octree as Accelerator>::USES_MAILBOX;
    const FOLLOWS_MOTION: bool = P::COHERENCE;

    fn first_hits_by_screen(&self) -> bool {
        P::FIRST_HITS && self.octree().is_none_or(|octree| octree.first_hits_by_screen())
    }

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
            None => naive::nearest(Self::KINDS, scene, ray, start),
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
            None => naive::occluded(Self::KINDS, scene, ray, t_max, start, mailbox),
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
        if light_buffer::<P>() {
            if let Some(blocked) = self.lights.occluded(scene, Self::KINDS, ray, t_max, light, start, mailbox) {
                return blocked;
            }
        }
        match self.octree() {
            Some(octree) => octree.occluded_toward(scene, ray, t_max, light, start, mailbox),
            None => self.occluded(scene, ray, t_max, start, mailbox),
        }
    }
}

/// A renderer over `view` for an image of `size`, with a mailbox and screen
/// lists where given. Inlined: a board's renderer is made in place.
#[inline(always)]
pub(super) fn renderer_in<'a, A: Accelerator>(
    view: SceneView<'a>,
    accel: &'a A,
    size: Size,
    mailbox: Option<&'a mut [u32]>,
    lists: Option<ScreenLists<'a>>,
) -> Result<Renderer<'a, A>, CameraError> {
    let mut renderer = Renderer::with_size(view, accel, size.width, size.height)?;
    if let Some(words) = mailbox {
        renderer.set_mailbox(words);
    }
    if let Some((bounds, positions)) = lists {
        renderer.set_first_hits(bounds, positions);
    }
    Ok(renderer)
}
