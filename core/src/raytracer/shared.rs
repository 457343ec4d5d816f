//! What other cores render a loaded scene with: the scene shared (its
//! accelerator, and a frame's tiles), drawn in a room of their own.

use crate::accel::SceneAccelerator;
use crate::animation::Playing;
use crate::profile::Profile;
use crate::render::Renderer;
use crate::scene::{CameraError, SceneView};
use core::fmt;
use embedded_graphics_core::geometry::Size;

use super::draw::{renderer_in, Picture, Source};
use super::picture::{self, Bands, Still};
use super::{RendererRoom, TracedImage};

/// What another core needs to render a [`LoadedScene`](super::LoadedScene)
/// ([`LoadedScene::share`](super::LoadedScene::share)) or a
/// [`Frame`](super::Frame) ([`Frame::share`](super::Frame::share)): its
/// objects, its accelerator, whether its camera rays use the screen lists,
/// and a frame's tiles. `Copy`, read-only and `Send`: hand it to the other
/// core when you start it; there, draw it with [`SharedScene::image`] in a
/// [`RendererRoom`] of that core's, or trace pixels with a
/// [`SharedScene::renderer`].
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
pub struct SharedScene<'r, P: Profile, K: picture::Picture = Still> {
    pub(super) view: SceneView<'r>,
    pub(super) accelerator: SceneAccelerator<'r, P>,
    pub(super) first_hits: bool,
    /// A frame's motion and planned tiles (`K` is then [`Bands`]).
    pub(super) playing: Option<Playing<'r>>,
    pub(super) picture: core::marker::PhantomData<K>,
}

impl<P: Profile, K: picture::Picture> Clone for SharedScene<'_, P, K> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile, K: picture::Picture> Copy for SharedScene<'_, P, K> {}

impl<P: Profile, K: picture::Picture> fmt::Debug for SharedScene<'_, P, K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SharedScene")
            .field("objects", &self.view.object_count())
            .field("accelerator", &self.accelerator)
            .field("first_hits", &self.first_hits)
            .finish()
    }
}

impl<'r, P: Profile> SharedScene<'r, P> {
    /// The share of a frame of this scene, `playing`.
    pub(super) fn frame(self, playing: Playing<'r>) -> SharedScene<'r, P, Bands> {
        let SharedScene { view, accelerator, first_hits, .. } = self;
        SharedScene { view, accelerator, first_hits, playing: Some(playing), picture: core::marker::PhantomData }
    }
}

impl<'r, P: Profile, K: picture::Picture> SharedScene<'r, P, K> {
    /// The scene's objects, surfaces, lights and settings.
    pub fn view(&self) -> SceneView<'r> {
        self.view
    }

    /// A renderer of an image of `size` pixels over this scene that writes
    /// only `room`: each core renders with one of its own, and any split of
    /// the image between them gives the same bits as one core.
    pub fn renderer<'a>(&'a self, room: &'a mut RendererRoom<P>, size: Size) -> Result<Renderer<'a, P>, CameraError> {
        let (mailbox, lists) = room.room.get_mut().prepare(self.view.object_count(), self.first_hits);
        renderer_in(self.view, &self.accelerator, size, Some(mailbox), lists)
    }

    /// The scene (a frame's tiles, if shared from a [`Frame`](super::Frame))
    /// as an image of `size` pixels in the colour `C`, drawn in `room`:
    /// another core's draw, as [`LoadedScene::image`](super::LoadedScene::image) is the loading
    /// core's.
    pub fn image<'s, C>(&'s self, room: &'s RendererRoom<P>, size: Size) -> TracedImage<'s, 'r, P, C, K> {
        let source =
            Source { view: &self.view, accelerator: &self.accelerator, first_hits: self.first_hits, room, stats: None };
        TracedImage::new(source, size, Picture::whole(size, self.playing))
    }
}
