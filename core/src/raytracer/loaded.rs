//! A loaded scene: its view, accelerator, light buffer and the room of the
//! core that loaded it; it draws as an image ([`TracedImage`]).

use crate::accel::{AccelMode, BuildReport, LightBuffer, LightBufferError, SceneAccelerator};
use crate::profile::Profile;
use crate::render::Renderer;
use crate::scene::{CameraError, Frames, SceneView};
use crate::shade::Stats;
use core::cell::Cell;
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::Size;

use super::draw::{Picture, Source};
use super::{RendererRoom, SharedScene, TracedImage};

/// A scene ready to trace, borrowed from its [`Raytracer`](super::Raytracer).
pub struct LoadedScene<'r, P: Profile> {
    pub(super) view: SceneView<'r>,
    pub(super) mode: AccelMode,
    /// What its octree's build reported, if it has one.
    pub(super) report: Option<BuildReport>,
    /// Its octree, if any, and the shadow rays' light buffer (none buffered
    /// without room for one): what every draw's renderer queries.
    pub(super) accelerator: SceneAccelerator<'r, P>,
    /// The loading core's renderers' room.
    pub(super) room: &'r RendererRoom<P>,
    pub(super) first_hits: bool,
    pub(super) stats: Cell<Stats>,
    /// FRAMES, for an animation.
    pub(super) frames: Option<Frames>,
}

impl<P: Profile> fmt::Debug for LoadedScene<'_, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LoadedScene")
            .field("objects", &self.view.object_count())
            .field("mode", &self.mode)
            .field("octree", &self.report)
            .finish_non_exhaustive()
    }
}

impl<'r, P: Profile> LoadedScene<'r, P> {
    /// The scene's objects, surfaces, lights and settings.
    pub fn view(&self) -> SceneView<'r> {
        self.view
    }

    /// The accelerator in use (never [`AccelMode::Auto`]).
    pub fn mode(&self) -> AccelMode {
        self.mode
    }

    /// What this scene's images render with: its octree, or every object
    /// (over only the shape kinds the profile has room for). For a board
    /// that renders with [`Renderer`]s of its own, one per core (each with
    /// its own mailbox and screen lists) over this one scene: see
    /// [`interleaved_rows`](crate::render::interleaved_rows).
    ///
    /// ```
    /// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::Rgb888};
    /// use embedded_graphics::{image::Image, prelude::*};
    /// use octrace_core::{profile::Board16K, render::{interleaved_rows, Renderer}, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n")?;
    /// let accelerator = scene.accelerator();
    /// let mut whole = MockDisplay::<Rgb888>::new();
    /// Image::new(&scene.image(Size::new(8, 8)), Point::zero()).draw(&mut whole)?;
    /// // Two "cores", each with its own renderer, rows dealt out in turn.
    /// for core in 0..2 {
    ///     let mut renderer = Renderer::with_size(scene.view(), &accelerator, 8, 8)?;
    ///     for y in interleaved_rows(8, core, 2) {
    ///         for (x, pixel) in renderer.row(y, 0..8).enumerate() {
    ///             assert_eq!(whole.get_pixel(Point::new(x as i32, y as i32)), Some(pixel.color));
    ///         }
    ///     }
    /// }
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn accelerator(&self) -> SceneAccelerator<'r, P> {
        self.accelerator
    }

    /// The shadow rays' light buffer: built when the scene loaded if the
    /// profile serves lights with one and has RAM for it
    /// (`light_buffer_lights` and `light_buffer_words`, see
    /// [`Profile::LightBufferWords`]) and the mode is not
    /// [`AccelMode::Naive`] asked for by name, or the one
    /// [`LoadedScene::use_light_buffer`] took; else none
    /// ([`LightBuffer::report`] says how many lights it buffers).
    pub fn light_buffer(&self) -> LightBuffer<'r> {
        self.accelerator.light_buffer()
    }

    /// Uses `words`, a light buffer built beforehand for this scene (its
    /// [`LightBuffer::words`], kept in flash by a build script), once
    /// checked to hold every object wherever a buffer built here would
    /// ([`LightBuffer::verified`]); a buffer that is not is refused, and
    /// the scene keeps the one it had. The profile must serve lights with a
    /// light buffer (`light_buffer_lights`), not necessarily hold one in
    /// RAM (`light_buffer_words`).
    ///
    /// ```
    /// use octrace_core::{accel::{LightBuffer, LightBufferError}, parse::parse, profile::{Board16K, Board64K}};
    /// use octrace_core::{scene::Scene, Raytracer};
    ///
    /// octrace_core::profile! {
    ///     /// Two spheres; a light buffer from flash for their light.
    ///     struct Spheres { spheres: 2, surfaces: 1, lights: 1, light_buffer_lights: 1 }
    /// }
    /// let text = "LIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\nSPHERE 1 0.5 1 1 1\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n";
    /// // Where the scene is known beforehand (a build script): the words.
    /// let mut built = Scene::<Board64K>::new();
    /// parse(text, &mut built, &mut |e| panic!("{e}")).unwrap();
    /// let mut words = heapless::Vec::<u32, 400>::new();
    /// let prebuilt = LightBuffer::build(&built.view(), &mut words, 8).words();
    /// // On the board: the scene, and the words from flash.
    /// let mut raytracer = Raytracer::<Spheres>::new();
    /// let mut scene = raytracer.load(text)?;
    /// assert_eq!(scene.light_buffer().report().lights, 0, "no RAM for one");
    /// scene.use_light_buffer(prebuilt)?;
    /// assert_eq!(scene.light_buffer().report().lights, 1);
    ///
    /// // A profile without light buffers refuses it.
    /// let mut small = Raytracer::<Board16K>::new();
    /// assert_eq!(small.load(text)?.use_light_buffer(prebuilt), Err(LightBufferError::NoRoom));
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn use_light_buffer(&mut self, words: &'r [u32]) -> Result<(), LightBufferError> {
        if !P::LIGHT_BUFFER {
            return Err(LightBufferError::NoRoom);
        }
        self.accelerator = self.accelerator.with_light_buffer(LightBuffer::verified(&self.view, words)?);
        Ok(())
    }

    /// Runs `f` with a renderer of an image of `size` over this scene, in
    /// the room its [`Raytracer`](super::Raytracer) holds: the loading core's renderer on a
    /// board whose other cores render with [`SharedScene::renderer`]. Its
    /// counters are added to [`LoadedScene::stats`].
    ///
    /// ```
    /// use embedded_graphics::prelude::*;
    /// use octrace_core::{profile::Board16K, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("BACKGROUND 0 0 1\n")?;
    /// let pixels = scene.with_renderer(Size::new(4, 2), |renderer| renderer.row(1, 0..4).count())?;
    /// assert_eq!(pixels, 4);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn with_renderer<R>(&self, size: Size, f: impl FnOnce(&mut Renderer<'_, P>) -> R) -> Result<R, CameraError> {
        self.source().with_renderer(size, None, f)
    }

    /// Where this scene's draws get their renderer: the loading core's
    /// room, the counters added to [`LoadedScene::stats`].
    pub(super) fn source(&self) -> Source<'_, 'r, P> {
        Source {
            view: &self.view,
            accelerator: &self.accelerator,
            first_hits: self.first_hits,
            room: self.room,
            stats: Some(&self.stats),
        }
    }

    /// What another core needs to render this scene with a [`Renderer`] of
    /// its own: see [`SharedScene`].
    pub fn share(&self) -> SharedScene<'r, P> {
        SharedScene {
            view: self.view,
            accelerator: self.accelerator(),
            first_hits: self.first_hits,
            playing: None,
            picture: core::marker::PhantomData,
        }
    }

    /// Whether camera rays find their hits in the screen lists
    /// ([`Linked::FIRST_HITS`](crate::profile::Linked::FIRST_HITS)): the same image as the walk's.
    pub fn first_hits(&self) -> bool {
        self.first_hits
    }

    /// What building the octree produced, if the mode uses one.
    pub fn octree_report(&self) -> Option<&BuildReport> {
        self.report.as_ref()
    }

    /// The scene's FRAMES, if it is an animation (loaded at one of its
    /// frames: [`Raytracer::load_frame`](super::Raytracer::load_frame)).
    pub fn frames(&self) -> Option<Frames> {
        self.frames
    }

    /// The counters of every draw so far.
    pub fn stats(&self) -> Stats {
        self.stats.get()
    }

    /// The scene's RASTER size.
    pub fn raster(&self) -> Size {
        let [w, h] = self.view.settings.raster;
        Size::new(w, h)
    }

    /// The scene as an image of `size` pixels in the colour `C`: what to
    /// draw of it, and how ([`TracedImage`]).
    pub fn image<C>(&self, size: Size) -> TracedImage<'_, 'r, P, C> {
        TracedImage::new(self.source(), size, Picture::whole(size, None))
    }

    /// The scene as an image as large as `target`, in its colour: what
    /// `Image::new(&scene.image_for(&display), Point::zero())` draws.
    pub fn image_for<D: DrawTarget>(&self, target: &D) -> TracedImage<'_, 'r, P, D::Color> {
        self.image(target.bounding_box().size)
    }
}
