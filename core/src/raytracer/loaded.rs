//! A loaded scene: its view, accelerator, light buffer and the room of the
//! core that loaded it; it draws as an image, directly or progressively.

use crate::accel::{AccelMode, BuildReport, LightBuffer, LightBufferError};
use crate::animation::coherence::Halt;
use crate::animation::{Coherence, Motion};
use crate::panel::{Dithered, TracedColor};
use crate::profile::Profile;
use crate::render::{Polling, Progressive, Renderer, Stop};
use crate::scene::{CameraError, Frames, SceneView};
use crate::shade::Stats;
use crate::shade::{Poll, Unpolled};
use core::cell::{Cell, RefCell};
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::Size;
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::Rectangle;

use super::shared::renderer_in;
use super::{light_buffer, DrawError, SceneAccelerator, ScreenLists, SharedScene};

/// A scene ready to trace, borrowed from its [`Raytracer`](super::Raytracer).
pub struct LoadedScene<'r, P: Profile> {
    pub(super) view: SceneView<'r>,
    pub(super) mode: AccelMode,
    pub(super) octree: Option<(&'r P::Octree, BuildReport)>,
    /// The shadow rays' light buffer (none buffered without room for one).
    pub(super) lights: LightBuffer<'r>,
    pub(super) mailbox: RefCell<&'r mut [u32]>,
    /// The camera rays' screen lists (bounds and positions), if they are
    /// used.
    pub(super) screen_lists: RefCell<Option<ScreenLists<'r>>>,
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
            .field("octree", &self.octree.map(|(_, report)| report))
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
        SceneAccelerator { octree: self.octree.as_ref().map(|(octree, _)| *octree), lights: self.lights }
    }

    /// The shadow rays' light buffer: built when the scene loaded if the
    /// profile serves lights with one and has RAM for it
    /// (`light_buffer_lights` and `light_buffer_words`, see
    /// [`Profile::LightBufferWords`]) and the mode is not
    /// [`AccelMode::Naive`] asked for by name, or the one
    /// [`LoadedScene::use_light_buffer`] took; else none
    /// ([`LightBuffer::report`] says how many lights it buffers).
    pub fn light_buffer(&self) -> LightBuffer<'r> {
        self.lights
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
        if !light_buffer::<P>() {
            return Err(LightBufferError::NoRoom);
        }
        self.lights = LightBuffer::verified(&self.view, words)?;
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
    pub fn with_renderer<R>(
        &self,
        size: Size,
        f: impl FnOnce(&mut Renderer<'_, SceneAccelerator<'r, P>>) -> R,
    ) -> Result<R, CameraError> {
        let accelerator = self.accelerator();
        let (mut mailbox, mut screen_lists) = (self.mailbox.try_borrow_mut(), self.screen_lists.try_borrow_mut());
        let (mailbox, lists) = room_of(&mut mailbox, &mut screen_lists);
        let mut renderer = renderer_in(self.view, &accelerator, size, mailbox, lists)?;
        let result = f(&mut renderer);
        let mut total = self.stats.get();
        total.add(&renderer.stats());
        self.stats.set(total);
        Ok(result)
    }

    /// What another core needs to render this scene with a [`Renderer`] of
    /// its own: see [`SharedScene`].
    pub fn share(&self) -> SharedScene<'r, P> {
        SharedScene { view: self.view, accelerator: self.accelerator(), first_hits: self.first_hits }
    }

    /// Whether camera rays find their hits in the screen lists
    /// ([`Profile::FIRST_HITS`]): the same image as the walk's.
    pub fn first_hits(&self) -> bool {
        self.first_hits
    }

    /// What building the octree produced, if the mode uses one.
    pub fn octree_report(&self) -> Option<&BuildReport> {
        self.octree.as_ref().map(|(_, report)| report)
    }

    /// The scene's FRAMES, if it is an animation (loaded at one of its
    /// frames: [`Raytracer::load_frame`](super::Raytracer::load_frame)).
    pub fn frames(&self) -> Option<Frames> {
        self.frames
    }

    /// Draws frame `frame` of an animation, this scene loaded at that
    /// frame, into `target` (of `coherence`'s size), re-tracing only the
    /// tiles [`Coherence::plan`] left to trace (call it first) and drawing
    /// only their runs of pixels: after the frame before it in the loop
    /// (or at the first frame, everything), `target` shows the frame as a
    /// whole draw would. An example is [`Coherence`]'s.
    ///
    /// A panel of few levels (`BinaryColor`, `Gray2`, `Gray4`,
    /// [`BlackWhiteRed`](crate::panel::BlackWhiteRed)) is dithered by
    /// [`Dithering::Bayer`], whose pixels depend on nothing but themselves
    /// (error diffusion would carry a change across the whole image): it
    /// shows the frame as a whole draw with that method would.
    pub fn draw_changes<D>(
        &self,
        motion: &Motion<'_>,
        frame: u32,
        coherence: &Coherence<'_>,
        target: &mut D,
    ) -> Result<Stats, DrawError<D::Error>>
    where
        D: DrawTarget,
        D::Color: TracedColor,
    {
        self.draw_bands(motion, frame, coherence, 0..coherence.bands(), target)
    }

    /// [`LoadedScene::draw_changes`] of the bands `bands` only, with one
    /// renderer in the room of the loading core: on a board whose cores
    /// share the frame, `bands` takes the next band no core has taken yet
    /// (the other cores trace theirs with [`Coherence::trace_band`] and a
    /// renderer of their own, [`SharedScene::renderer`]).
    pub fn draw_bands<D>(
        &self,
        motion: &Motion<'_>,
        frame: u32,
        coherence: &Coherence<'_>,
        bands: impl IntoIterator<Item = u32>,
        target: &mut D,
    ) -> Result<Stats, DrawError<D::Error>>
    where
        D: DrawTarget,
        D::Color: TracedColor,
    {
        self.draw_bands_polled(motion, frame, coherence, bands, target, &mut Unpolled)
    }

    /// [`LoadedScene::draw_bands`], asking `stop` before every ray (as
    /// [`Renderer::pixel_until`] does): [`DrawError::Stopped`] as soon as
    /// it says so, the run being traced drawn up to the pixel it stopped
    /// in, and the tiles not drawn kept to be traced.
    pub fn draw_bands_until<D, S: Stop>(
        &self,
        motion: &Motion<'_>,
        frame: u32,
        coherence: &Coherence<'_>,
        bands: impl IntoIterator<Item = u32>,
        target: &mut D,
        stop: &mut S,
    ) -> Result<Stats, DrawError<D::Error>>
    where
        D: DrawTarget,
        D::Color: TracedColor,
    {
        self.draw_bands_polled(motion, frame, coherence, bands, target, &mut Polling { stop, stopped: false })
    }

    /// [`LoadedScene::draw_bands`], `poll` asked before every ray: into
    /// `target` converted, or through ordered dithering for a panel of few
    /// levels.
    fn draw_bands_polled<D, Q: Poll>(
        &self,
        motion: &Motion<'_>,
        frame: u32,
        coherence: &Coherence<'_>,
        bands: impl IntoIterator<Item = u32>,
        target: &mut D,
        poll: &mut Q,
    ) -> Result<Stats, DrawError<D::Error>>
    where
        D: DrawTarget,
        D::Color: TracedColor,
    {
        match D::Color::PANEL {
            None => self.draw_bands_converted(motion, frame, coherence, bands, target, poll),
            Some(_) => self.draw_bands_converted(motion, frame, coherence, bands, &mut Dithered::ordered(target), poll),
        }
    }

    /// [`LoadedScene::draw_bands_polled`] into a target that takes the
    /// traced colours converted.
    fn draw_bands_converted<D, Q: Poll>(
        &self,
        motion: &Motion<'_>,
        frame: u32,
        coherence: &Coherence<'_>,
        bands: impl IntoIterator<Item = u32>,
        target: &mut D,
        poll: &mut Q,
    ) -> Result<Stats, DrawError<D::Error>>
    where
        D: DrawTarget,
        D::Color: From<Rgb888>,
    {
        let accelerator = self.accelerator();
        // As `with_renderer`, here: the renderer's room is borrowed no
        // longer than `motion` lives.
        let (mut mailbox, mut screen_lists) = (self.mailbox.try_borrow_mut(), self.screen_lists.try_borrow_mut());
        let (mailbox, lists) = room_of(&mut mailbox, &mut screen_lists);
        let mut renderer =
            renderer_in(self.view, &accelerator, coherence.size(), mailbox, lists).map_err(DrawError::Camera)?;
        let mut stats = Stats::default();
        let result = bands.into_iter().try_for_each(|band| {
            let traced = coherence
                .trace_band_polled(&mut renderer, motion, frame, band, poll, &mut |line, pixels| {
                    target.fill_contiguous(line, pixels.map(|p| p.color.into())).map_err(DrawError::Target)
                })
                .map_err(|halt| match halt {
                    Halt::Sink(e) => e,
                    Halt::Stopped(_) => DrawError::Stopped,
                })?;
            stats.add(&traced);
            Ok(())
        });
        let mut total = self.stats.get();
        total.add(&stats);
        self.stats.set(total);
        result.map(|()| stats)
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

    /// Draws the scene as an image of `order`'s size at the origin of
    /// `target`, in the [`Progressive`] order: the whole picture in coarse
    /// blocks first, then finer, until it is exactly the picture
    /// [`LoadedScene::image`] draws. Every pixel is traced once; the
    /// drawing streams (no framebuffer), in a few calls a pass.
    ///
    /// A panel of few levels (`BinaryColor`, `Gray2`, `Gray4`,
    /// [`BlackWhiteRed`](crate::panel::BlackWhiteRed)) is dithered by
    /// [`Dithering::Bayer`] in every pass, the one method that needs no
    /// order: the last pass is then the image with that method.
    ///
    /// ```
    /// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb565, prelude::*};
    /// use octrace_core::{profile::Board16K, render::Progressive, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n")?;
    /// let mut display = MockDisplay::<Rgb565>::new();
    /// display.set_allow_overdraw(true); // later passes draw over the coarse blocks
    /// scene.draw_progressive(&Progressive::new(display.size(), 16), &mut display)?;
    /// assert_eq!(scene.stats().rays, 64 * 64, "every pixel traced once: nothing reflects");
    ///
    /// let mut direct = MockDisplay::<Rgb565>::new();
    /// Image::new(&scene.image_for(&direct), Point::zero()).draw(&mut direct)?;
    /// assert_eq!(display, direct);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn draw_progressive<D>(&self, order: &Progressive, target: &mut D) -> Result<(), DrawError<D::Error>>
    where
        D: DrawTarget,
        D::Color: TracedColor,
    {
        let drawn = match D::Color::PANEL {
            None => self.with_renderer(order.size(), |renderer| order.render_unchecked(renderer, target)),
            Some(_) => {
                let mut ordered = Dithered::ordered(target);
                self.with_renderer(order.size(), |renderer| order.render_unchecked(renderer, &mut ordered))
            }
        };
        drawn.map_err(DrawError::Camera)?.map_err(DrawError::Target)?;
        Ok(())
    }

    /// Renders `area` of an image of `size` into `target`, in the image's
    /// coordinates.
    pub(super) fn render_area<D>(&self, size: Size, area: &Rectangle, target: &mut D) -> Result<(), DrawError<D::Error>>
    where
        D: DrawTarget,
        D::Color: From<Rgb888>,
    {
        let drawn = self.with_renderer(size, |renderer| renderer.render_rect(area, target));
        drawn.map_err(DrawError::Camera)?.map_err(DrawError::Target)?;
        Ok(())
    }
}

/// The loading core's room out of its cells: none of what another draw of
/// the scene holds (only if a display draws from inside a draw: the render
/// goes without, the same image).
fn room_of<'g, 'r>(
    mailbox: &'g mut Result<core::cell::RefMut<'_, &'r mut [u32]>, core::cell::BorrowMutError>,
    screen_lists: &'g mut Result<core::cell::RefMut<'_, Option<ScreenLists<'r>>>, core::cell::BorrowMutError>,
) -> (Option<&'g mut [u32]>, Option<ScreenLists<'g>>) {
    let lists = screen_lists.as_deref_mut().ok().and_then(|lists| lists.as_mut());
    let lists = lists.map(|(bounds, positions)| (&mut **bounds, &mut **positions));
    (mailbox.as_deref_mut().ok().map(|words| &mut **words), lists)
}
