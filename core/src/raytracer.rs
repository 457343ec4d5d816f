//! The one way in: a [`Raytracer`] holds a scene, its octree, a mailbox,
//! room for the camera rays' screen lists and for the shadow rays' light
//! buffer in one place (a `static` on a board), [`Raytracer::load`] parses a scene
//! text and indexes it, and the [`LoadedScene`] draws as an embedded-graphics
//! image ([`TracedImage`]) in the colour of any display.
//!
//! Invariants: a [`Raytracer::new`] is all zero bits (a `static` of it lands
//! in `.bss`, initialised in place); a [`LoadedScene`] exists only for a
//! scene that parsed without errors, with its accelerator built.

use crate::accel::{
    self, naive, AccelMode, Accelerator, BuildReport, Hit, LightBuffer, LightBufferError, LightBufferStore, Mailbox,
    OctreeStore, Prepared, RayStart, MAX_CELLS_A_SIDE,
};
use crate::capacity::Arena;
use crate::math::Scalar;
use crate::parse::{parse_bytes, ErrorKind, ParseError, Pos};
use crate::profile::Profile;
use crate::render::{Progressive, Renderer, ScreenBound};
use crate::scene::{CameraError, Scene, SceneView};
use crate::shade::Stats;
use crate::shapes::{Ray, ShapeKinds};
use core::cell::{Cell, RefCell};
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, OriginDimensions, Point, Size};
use embedded_graphics_core::image::ImageDrawable;
use embedded_graphics_core::pixelcolor::{PixelColor, Rgb888};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;

/// Room for one scene of the profile `P`: the scene's arenas, its octree and
/// a mailbox. On a board, keep it in a `static` (it is all zero bits, so it
/// costs no flash) and take it once with the re-exported
/// [`ConstStaticCell`](crate::ConstStaticCell); on a host, box it.
///
/// ```
/// use octrace_core::{profile::Board16K, ConstStaticCell, Raytracer};
///
/// static RAYTRACER: ConstStaticCell<Raytracer<Board16K>> = ConstStaticCell::new(Raytracer::new());
/// let raytracer: &'static mut Raytracer<Board16K> = RAYTRACER.take();
/// let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nSPHERE 1 1 0 0 0\n").unwrap();
/// assert_eq!(scene.view().object_count(), 1);
/// ```
pub struct Raytracer<P: Profile> {
    scene: Scene<P>,
    octree: P::Octree,
    /// The first core's renderer's own room.
    room: RendererRoom<P>,
    light_buffer: LightBufferStore<P::LightBufferWords>,
}

/// Room for one core's [`Renderer`] over a profile's scenes: a mailbox and
/// screen lists, as the profile sizes them. A [`Raytracer`] holds one for
/// the core that loads the scene; give each other core one of its own (all
/// zero bits: a `static`, taken once) and make its renderer with
/// [`SharedScene::renderer`]: they are the only state a render writes.
///
/// ```
/// use octrace_core::{profile::Board16K, ConstStaticCell, RendererRoom};
///
/// static CORE1_ROOM: ConstStaticCell<RendererRoom<Board16K>> = ConstStaticCell::new(RendererRoom::new());
/// let room: &'static mut RendererRoom<Board16K> = CORE1_ROOM.take();
/// # let _ = room;
/// ```
pub struct RendererRoom<P: Profile> {
    mailbox: P::MailboxWords,
    screen_bounds: P::ScreenBounds,
    screen_positions: P::ScreenPositions,
}

impl<P: Profile> RendererRoom<P> {
    /// Empty room: a constant of all-zero bits.
    pub const fn new() -> Self {
        RendererRoom {
            mailbox: P::MailboxWords::EMPTY,
            screen_bounds: P::ScreenBounds::EMPTY,
            screen_positions: P::ScreenPositions::EMPTY,
        }
    }

    /// The room cleared for a scene of `objects` objects: its mailbox, and
    /// its screen lists when the scene's camera rays use them.
    fn prepare(&mut self, objects: usize, first_hits: bool) -> (&mut [u32], Option<ScreenLists<'_>>) {
        fill(&mut self.mailbox, Mailbox::words_for(objects), 0);
        let listed = if first_hits { objects } else { 0 };
        fill(&mut self.screen_bounds, listed, ScreenBound::EMPTY);
        fill(&mut self.screen_positions, ScreenBound::positions_for(listed), 0);
        let lists = (self.screen_bounds.as_mut_slice(), self.screen_positions.as_mut_slice());
        (self.mailbox.as_mut_slice(), first_hits.then_some(lists))
    }
}

impl<P: Profile> Default for RendererRoom<P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<P: Profile> fmt::Debug for RendererRoom<P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RendererRoom").field("profile", &P::NAME).finish_non_exhaustive()
    }
}

/// A renderer's screen lists: a bound for each object, and their positions.
type ScreenLists<'a> = (&'a mut [ScreenBound], &'a mut [u16]);

impl<P: Profile> fmt::Debug for Raytracer<P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Raytracer")
            .field("profile", &P::NAME)
            .field("objects", &self.scene.view().object_count())
            .finish_non_exhaustive()
    }
}

impl<P: Profile> Default for Raytracer<P> {
    fn default() -> Self {
        Self::new()
    }
}

/// A scene that did not load: how many errors it has and the first one.
/// [`Raytracer::load_with`] hands every error to a callback.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadError<'t> {
    /// The first error, with its line and column.
    pub first: ParseError<'t>,
    /// How many errors the scene has (at least 1).
    pub count: usize,
}

impl fmt::Display for LoadError<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.first)?;
        match self.count {
            1 => Ok(()),
            n => write!(f, " (and {} more error{})", n - 1, if n == 2 { "" } else { "s" }),
        }
    }
}

impl core::error::Error for LoadError<'_> {}

impl<P: Profile> Raytracer<P> {
    /// Empty room for a scene: a constant of all-zero bits.
    pub const fn new() -> Self {
        Raytracer {
            scene: Scene::new(),
            octree: P::Octree::EMPTY,
            room: RendererRoom::new(),
            light_buffer: LightBufferStore::new(),
        }
    }

    /// Parses `text` (replacing any scene loaded before) and indexes it for
    /// tracing, choosing the accelerator with [`AccelMode::Auto`].
    pub fn load<'t>(&mut self, text: &'t str) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        self.load_with(text.as_bytes(), AccelMode::Auto, &mut |_| {})
    }

    /// [`Raytracer::load`] from bytes (invalid UTF-8 is an error at its
    /// place), with the accelerator `mode`, handing every error to
    /// `on_error` as it is found. A profile with no room for octree boxes
    /// always uses [`AccelMode::Naive`] (same image; no octree code is
    /// linked); [`LoadedScene::mode`] says which mode is in use.
    pub fn load_with<'t>(
        &mut self,
        text: &'t [u8],
        mode: AccelMode,
        on_error: &mut dyn FnMut(ParseError<'t>),
    ) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        self.load_in(text, mode, on_error, &mut |beside, here| {
            here();
            beside();
        })
    }

    /// [`Raytracer::load`] on two cores: the light buffer is built on the
    /// other core while this one builds the octree (on a Pico that spares
    /// fig5_3 4 M cycles of its 28 M). `both(beside, here)` must run
    /// `beside` on the other core and `here` on this one, and return once
    /// both have returned, as `std::thread::scope` or the Pico template's
    /// `SecondCore::scope` do. The same scene as [`Raytracer::load`]'s.
    ///
    /// ```
    /// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb565, prelude::*};
    /// use octrace_core::{profile::Board64K, Raytracer};
    ///
    /// let text = "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n";
    /// let mut raytracer = Box::new(Raytracer::<Board64K>::new());
    /// let scene = raytracer.load_on_two_cores(text, |beside, here| {
    ///     std::thread::scope(|scope| {
    ///         scope.spawn(|| beside());
    ///         here();
    ///     })
    /// })?;
    /// let mut two = MockDisplay::<Rgb565>::new();
    /// Image::new(&scene.image_for(&two), Point::zero()).draw(&mut two)?;
    ///
    /// let mut one = MockDisplay::<Rgb565>::new();
    /// let mut raytracer = Box::new(Raytracer::<Board64K>::new());
    /// let scene = raytracer.load(text)?;
    /// Image::new(&scene.image_for(&one), Point::zero()).draw(&mut one)?;
    /// assert_eq!(one, two);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn load_on_two_cores<'t>(
        &mut self,
        text: &'t str,
        both: impl FnOnce(&mut (dyn FnMut() + Send), &mut dyn FnMut()),
    ) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        let mut both = Some(both);
        self.load_in(text.as_bytes(), AccelMode::Auto, &mut |_| {}, &mut |beside, here| {
            if let Some(both) = both.take() {
                both(beside, here);
            }
        })
    }

    /// Parses `text` and indexes it; `both(beside, here)` runs the two
    /// jobs of the indexing that are apart (the light buffer, the octree)
    /// and returns once both are done.
    fn load_in<'t>(
        &mut self,
        text: &'t [u8],
        mode: AccelMode,
        on_error: &mut dyn FnMut(ParseError<'t>),
        both: &mut RunBoth<'_>,
    ) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        let mut first = None;
        let parsed = parse_bytes(text, &mut self.scene, &mut |e| {
            first.get_or_insert(e);
            on_error(e);
        });
        match (parsed, first) {
            (Ok(_), _) => {}
            (Err(count), Some(first)) => return Err(LoadError { first, count }),
            // Never taken: `parse_bytes` hands every error it counts to the
            // callback. Answered at the file's start rather than by a panic.
            (Err(count), None) => {
                let first = ParseError::new(Pos { line: 1, column: 1 }, ErrorKind::InvalidUtf8);
                return Err(LoadError { first, count });
            }
        }
        let view = self.scene.view();
        let requested = mode;
        // The naive mode asked for by name stays the thesis's test of
        // every object, camera rays too; likewise the shadow rays' light
        // buffer.
        let buffered =
            <P::LightBufferWords as Arena<u32>>::CAPACITY > 0 && light_buffer::<P>() && requested != AccelMode::Naive;
        let (octree_store, light_buffer) = (&mut self.octree, &mut self.light_buffer);
        let (mut prepared, mut built) = (None, false);
        both(
            &mut || {
                if buffered {
                    light_buffer.build_for(&view, MAX_CELLS_A_SIDE, P::COUNTS.light_buffer_lights);
                    built = true;
                }
            },
            &mut || prepared = Some(accel::prepare(mode, &view, octree_store, &P::OCTREE)),
        );
        // `both` ran both jobs, unless a caller's broke its promise: then
        // the octree is built now, and the shadow rays go without a buffer
        // (the store may hold an earlier scene's).
        let Prepared { mode, report } =
            prepared.unwrap_or_else(|| accel::prepare(mode, &view, &mut self.octree, &P::OCTREE));
        let octree = report.map(|report| (&self.octree, report));
        let lights = if built { self.light_buffer.buffer() } else { LightBuffer::NONE };
        let first_hits = P::FIRST_HITS && requested != AccelMode::Naive;
        let (mailbox, screen_lists) = self.room.prepare(view.object_count(), first_hits);
        Ok(LoadedScene {
            view,
            mode,
            octree,
            lights,
            mailbox: RefCell::new(mailbox),
            screen_lists: RefCell::new(screen_lists),
            first_hits,
            stats: Cell::new(Stats::default()),
        })
    }
}

/// Runs its first job on another core (or after) and its second here.
type RunBoth<'a> = dyn FnMut(&mut (dyn FnMut() + Send), &mut dyn FnMut()) + 'a;

/// Whether profile `P` serves lights with a light buffer (else none of its
/// code is linked).
const fn light_buffer<P: Profile>() -> bool {
    P::COUNTS.light_buffer_lights > 0
}

/// `arena` emptied, then `len` copies of `item`, as many as it holds.
fn fill<T: Copy>(arena: &mut impl Arena<T>, len: usize, item: T) {
    arena.clear();
    while arena.as_slice().len() < len && arena.push(item).is_ok() {}
}

/// A scene ready to trace, borrowed from its [`Raytracer`].
pub struct LoadedScene<'r, P: Profile> {
    view: SceneView<'r>,
    mode: AccelMode,
    octree: Option<(&'r P::Octree, BuildReport)>,
    /// The shadow rays' light buffer (none buffered without room for one).
    lights: LightBuffer<'r>,
    mailbox: RefCell<&'r mut [u32]>,
    /// The camera rays' screen lists (bounds and positions), if they are
    /// used.
    screen_lists: RefCell<Option<ScreenLists<'r>>>,
    first_hits: bool,
    stats: Cell<Stats>,
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
    /// the room its [`Raytracer`] holds: the loading core's renderer on a
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
        // Another draw of this scene holds the mailbox or the lists (only if
        // a display draws from inside a draw): render without, same image.
        let mut mailbox = self.mailbox.try_borrow_mut();
        let mut screen_lists = self.screen_lists.try_borrow_mut();
        let lists = screen_lists.as_deref_mut().ok().and_then(|lists| lists.as_mut());
        let lists = lists.map(|(bounds, positions)| (&mut **bounds, &mut **positions));
        let mailbox = mailbox.as_deref_mut().ok().map(|words| &mut **words);
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

    /// The counters of every draw so far.
    pub fn stats(&self) -> Stats {
        self.stats.get()
    }

    /// The scene's RASTER size.
    pub fn raster(&self) -> Size {
        let [w, h] = self.view.settings.raster;
        Size::new(w, h)
    }

    /// The scene as an image of `size` pixels in the colour `C`.
    pub fn image<C>(&self, size: Size) -> TracedImage<'_, 'r, P, C> {
        TracedImage { scene: self, size, color: core::marker::PhantomData }
    }

    /// The scene as an image as large as `target`, in its colour: what
    /// `Image::new(&scene.image_for(&display), Point::zero())` draws.
    pub fn image_for<D: DrawTarget>(&self, target: &D) -> TracedImage<'_, 'r, P, D::Color> {
        self.image(target.bounding_box().size)
    }

    /// Draws the scene as an image of `order`'s size at the origin of
    /// `target`, in the [`Progressive`] order: the whole picture in coarse
    /// blocks first, then finer, until it is exactly the picture
    /// [`LoadedScene::image`] draws. Every pixel is traced once; the
    /// drawing streams (no framebuffer), in a few calls a pass.
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
        D::Color: From<Rgb888>,
    {
        let drawn = self.with_renderer(order.size(), |renderer| order.render_unchecked(renderer, target));
        drawn.map_err(DrawError::Camera)?.map_err(DrawError::Target)?;
        Ok(())
    }

    /// Renders `area` of an image of `size` into `target`, with the pixel at
    /// `area`'s top-left corner going to `at`.
    fn draw_area<D>(&self, size: Size, area: &Rectangle, at: Point, target: &mut D) -> Result<(), DrawError<D::Error>>
    where
        D: DrawTarget,
        D::Color: From<Rgb888>,
    {
        let mut shifted = Shifted { target, offset: at - area.top_left };
        let drawn = self.with_renderer(size, |renderer| renderer.render_rect(area, &mut shifted));
        drawn.map_err(DrawError::Camera)?.map_err(DrawError::Target)?;
        Ok(())
    }
}

/// A renderer over `view` for an image of `size`, with a mailbox and screen
/// lists where given. Inlined: a board's renderer is made in place.
#[inline(always)]
fn renderer_in<'a, A: Accelerator>(
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

/// What another core needs to render a [`LoadedScene`]
/// ([`LoadedScene::share`]): its objects, its accelerator and whether its
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
    view: SceneView<'r>,
    accelerator: SceneAccelerator<'r, P>,
    first_hits: bool,
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

/// What a [`LoadedScene`] renders with ([`LoadedScene::accelerator`]):
/// its octree, or (without one) every object, over only the shape kinds
/// its profile has room for, and with the screen lists only if the profile
/// has room for them. Both are decided on the profile's constants, so that
/// a build without an octree or without the lists links none of their code.
pub struct SceneAccelerator<'r, P: Profile> {
    octree: Option<&'r P::Octree>,
    lights: LightBuffer<'r>,
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

/// Why a [`TracedImage`] could not be drawn with
/// [`TracedImage::try_draw`].
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawError<E> {
    /// The camera cannot be set up for this size (see [`CameraError`]).
    Camera(CameraError),
    /// The display's own error.
    Target(E),
}

impl<E: fmt::Display> fmt::Display for DrawError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DrawError::Camera(e) => write!(f, "{e}"),
            DrawError::Target(e) => write!(f, "the display failed: {e}"),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for DrawError<E> {}

/// A traced scene as an embedded-graphics image, `size` pixels in the colour
/// `C` (any colour that converts from `Rgb888`: `Rgb565`, `Gray4`, …), like
/// `tinybmp::Bmp<C>`. Each draw traces the pixels as the display takes
/// them, one scanline at a time: no framebuffer.
///
/// ```
/// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb565, prelude::*};
/// use octrace_core::{profile::Board16K, Raytracer};
///
/// let mut raytracer = Raytracer::<Board16K>::new();
/// let scene = raytracer.load("BACKGROUND 0 0 1\n").unwrap();
/// let mut display = MockDisplay::<Rgb565>::new();
/// Image::new(&scene.image::<Rgb565>(Size::new(4, 2)), Point::zero()).draw(&mut display).unwrap();
/// display.assert_pattern(&["BBBB", "BBBB"]);
/// ```
pub struct TracedImage<'s, 'r, P: Profile, C> {
    scene: &'s LoadedScene<'r, P>,
    size: Size,
    color: core::marker::PhantomData<C>,
}

impl<P: Profile, C> fmt::Debug for TracedImage<'_, '_, P, C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TracedImage").field("size", &self.size).field("scene", self.scene).finish()
    }
}

impl<P: Profile, C> Clone for TracedImage<'_, '_, P, C> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile, C> Copy for TracedImage<'_, '_, P, C> {}

impl<P: Profile, C: PixelColor + From<Rgb888>> TracedImage<'_, '_, P, C> {
    /// Draws the image at the origin of `target`, telling a camera that
    /// cannot be set up (a zero size) apart from the display's errors;
    /// [`ImageDrawable::draw`] draws nothing then.
    pub fn try_draw<D: DrawTarget<Color = C>>(&self, target: &mut D) -> Result<(), DrawError<D::Error>> {
        self.scene.draw_area(self.size, &Rectangle::new(Point::zero(), self.size), Point::zero(), target)
    }
}

impl<P: Profile, C> OriginDimensions for TracedImage<'_, '_, P, C> {
    fn size(&self) -> Size {
        self.size
    }
}

impl<P: Profile, C: PixelColor + From<Rgb888>> ImageDrawable for TracedImage<'_, '_, P, C> {
    type Color = C;

    fn draw<D: DrawTarget<Color = C>>(&self, target: &mut D) -> Result<(), D::Error> {
        self.draw_sub_image(target, &self.bounding_box())
    }

    fn draw_sub_image<D: DrawTarget<Color = C>>(&self, target: &mut D, area: &Rectangle) -> Result<(), D::Error> {
        match self.scene.draw_area(self.size, area, Point::zero(), target) {
            Ok(()) | Err(DrawError::Camera(_)) => Ok(()),
            Err(DrawError::Target(e)) => Err(e),
        }
    }
}

/// A target seen shifted by `offset`: a sub-image's pixels land at the
/// target's origin.
struct Shifted<'t, D> {
    target: &'t mut D,
    offset: Point,
}

impl<D: DrawTarget> Dimensions for Shifted<'_, D> {
    fn bounding_box(&self) -> Rectangle {
        let b = self.target.bounding_box();
        Rectangle::new(b.top_left - self.offset, b.size)
    }
}

impl<D: DrawTarget> DrawTarget for Shifted<'_, D> {
    type Color = D::Color;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<D::Color>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        let offset = self.offset;
        self.target.draw_iter(pixels.into_iter().map(|Pixel(p, c)| Pixel(p + offset, c)))
    }

    fn fill_contiguous<I: IntoIterator<Item = D::Color>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), D::Error> {
        self.target.fill_contiguous(&Rectangle::new(area.top_left + self.offset, area.size), colors)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::Board16K;
    use embedded_graphics_core::pixelcolor::{Gray4, Rgb565};

    const SCENE: &str = "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n";

    /// Collects what a draw writes.
    struct Grid<C, const W: usize, const H: usize>([[Option<C>; W]; H]);

    impl<C: PixelColor, const W: usize, const H: usize> OriginDimensions for Grid<C, W, H> {
        fn size(&self) -> Size {
            Size::new(W as u32, H as u32)
        }
    }

    impl<C: PixelColor, const W: usize, const H: usize> DrawTarget for Grid<C, W, H> {
        type Color = C;
        type Error = core::convert::Infallible;

        fn draw_iter<I: IntoIterator<Item = Pixel<C>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
            for Pixel(p, c) in pixels {
                assert!(p.x >= 0 && p.y >= 0 && (p.x as usize) < W && (p.y as usize) < H, "{p:?} outside");
                assert!(self.0[p.y as usize][p.x as usize].replace(c).is_none(), "{p:?} drawn twice");
            }
            Ok(())
        }
    }

    #[test]
    fn an_image_sized_from_its_target_draws_every_pixel_once() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let mut grid = Grid::<Gray4, 12, 8>([[None; 12]; 8]);
        let image = scene.image_for(&grid);
        assert_eq!(image.size(), Size::new(12, 8));
        image.draw(&mut grid).unwrap();
        assert!(grid.0.iter().flatten().all(|c| c.is_some()));
        assert_eq!(scene.stats().rays, 96);
    }

    #[test]
    fn a_sub_image_is_the_same_pixels_at_the_origin() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let mut whole = Grid::<Rgb565, 12, 8>([[None; 12]; 8]);
        scene.image_for(&whole).draw(&mut whole).unwrap();
        let mut part = Grid::<Rgb565, 5, 3>([[None; 5]; 3]);
        let image = scene.image::<Rgb565>(Size::new(12, 8));
        image.draw_sub_image(&mut part, &Rectangle::new(Point::new(4, 2), Size::new(5, 3))).unwrap();
        for y in 0..3 {
            assert_eq!(part.0[y], whole.0[y + 2][4..9], "row {y}");
        }
    }

    #[test]
    fn every_mode_gives_the_same_pixels() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let mut first = None;
        for mode in AccelMode::ALL {
            let scene = raytracer.load_with(SCENE.as_bytes(), mode, &mut |e| panic!("{e:?}")).unwrap();
            assert_ne!(scene.mode(), AccelMode::Auto);
            assert_eq!(scene.octree_report().is_some(), scene.mode().traversal().is_some());
            let mut grid = Grid::<Rgb565, 8, 6>([[None; 8]; 6]);
            scene.image_for(&grid).draw(&mut grid).unwrap();
            assert_eq!(*first.get_or_insert(grid.0), grid.0, "{mode}");
        }
    }

    crate::profile! {
        /// No octree: one sphere and its light.
        struct NoOctree { spheres: 1, surfaces: 1, lights: 1 }
    }

    #[test]
    fn a_profile_without_octree_room_traces_every_object() {
        let mut raytracer = Raytracer::<NoOctree>::new();
        let scene = raytracer.load_with(SCENE.as_bytes(), AccelMode::Dda, &mut |e| panic!("{e:?}")).unwrap();
        assert_eq!(scene.mode(), AccelMode::Naive);
        assert!(scene.octree_report().is_none());
        let mut grid = Grid::<Rgb565, 8, 6>([[None; 8]; 6]);
        scene.image_for(&grid).draw(&mut grid).unwrap();
        let mut roomy = Raytracer::<Board16K>::new();
        let dda = roomy.load_with(SCENE.as_bytes(), AccelMode::Dda, &mut |e| panic!("{e:?}")).unwrap();
        let mut expected = Grid::<Rgb565, 8, 6>([[None; 8]; 6]);
        dda.image_for(&expected).draw(&mut expected).unwrap();
        assert_eq!(grid.0, expected.0);
    }

    crate::profile! {
        /// A row of twelve spheres in an octree without the thesis's hash
        /// table.
        struct Hashless { spheres: 12, surfaces: 1, lights: 1, octree_boxes: 200, octree_references: 400 }
        octree: { max_objects: 1, max_depth: 4 }
        named_walk: false
    }

    crate::profile! {
        /// The same row, no octree.
        struct Row { spheres: 12, surfaces: 1, lights: 1 }
    }

    #[test]
    fn a_profile_without_the_hash_table_walks_the_thesis_mode_by_3ddda() {
        extern crate std;
        let spheres: std::string::String = (0..12).map(|i| std::format!("SPHERE 1 0.4 {} 0 0\n", i - 6)).collect();
        let text = std::format!(
            "RASTER 8 6\nVIEWPOINT 0 2 9\nLIGHT 10 5 5 5\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n{spheres}"
        );
        const _: () = assert!(!<Hashless as Profile>::NAMED_WALK && <Row as Profile>::NAMED_WALK);
        let mut raytracer = Raytracer::<Hashless>::new();
        let scene = raytracer.load_with(text.as_bytes(), AccelMode::Octree, &mut |e| panic!("{e:?}")).unwrap();
        assert_eq!(scene.mode(), AccelMode::Dda, "says which walk it took");
        let report = scene.octree_report().unwrap();
        assert!(report.nodes > 9 && report.hash_entries == 0 && report.unsplit == 0, "{report:?}");
        let mut grid = Grid::<Rgb565, 8, 6>([[None; 8]; 6]);
        scene.image_for(&grid).draw(&mut grid).unwrap();
        let mut naive = Raytracer::<Row>::new();
        let naive = naive.load(&text).unwrap();
        let mut expected = Grid::<Rgb565, 8, 6>([[None; 8]; 6]);
        naive.image_for(&expected).draw(&mut expected).unwrap();
        assert_eq!(grid.0, expected.0);
    }

    crate::profile! {
        /// An octree for 20 spheres (more than the naive mode is chosen
        /// for), and a light buffer for its light.
        struct Buffered {
            spheres: 20, surfaces: 1, lights: 1, octree_boxes: 400, octree_references: 800,
            light_buffer_lights: 1, light_buffer_words: 8_000
        }
        octree: { max_objects: 1, max_depth: 4 }
    }

    crate::profile! {
        /// [`Buffered`] without the light buffer.
        struct Unbuffered { spheres: 20, surfaces: 1, lights: 1, octree_boxes: 400, octree_references: 800 }
        octree: { max_objects: 1, max_depth: 4 }
    }

    #[test]
    fn loading_on_two_cores_builds_what_one_core_does() {
        extern crate std;
        use std::boxed::Box;
        let spheres: std::string::String =
            (0..20).map(|i| std::format!("SPHERE 1 0.3 {} {} 0\n", i % 5 - 2, i / 5 - 2)).collect();
        let text = std::format!("VIEWPOINT 0 2 9\nLIGHT 10 5 5 5\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n{spheres}");
        fn draw<P: Profile>(scene: &LoadedScene<'_, P>) -> ([[Option<Rgb565>; 32]; 24], Stats) {
            let mut grid = Grid::<Rgb565, 32, 24>([[None; 32]; 24]);
            scene.image_for(&grid).draw(&mut grid).unwrap();
            (grid.0, scene.stats())
        }
        let mut one = Box::new(Raytracer::<Buffered>::new());
        let (pixels, stats) = draw(&one.load(&text).unwrap());
        let mut two = Box::new(Raytracer::<Buffered>::new());
        let both = |beside: &mut (dyn FnMut() + Send), here: &mut dyn FnMut()| {
            std::thread::scope(|scope| {
                scope.spawn(beside);
                here();
            })
        };
        assert_eq!(draw(&two.load_on_two_cores(&text, both).unwrap()), (pixels, stats));
        // The buffer is in use: without it, shadow rays walk the octree.
        let mut unbuffered = Box::new(Raytracer::<Unbuffered>::new());
        let (walked_pixels, walked) = draw(&unbuffered.load(&text).unwrap());
        assert_eq!(walked_pixels, pixels);
        assert!(walked.cells > stats.cells, "{} cells walked against {}", walked.cells, stats.cells);
        // A `both` that skips the other core's job: no buffer, not the
        // last scene's.
        assert_eq!(draw(&two.load_on_two_cores(&text, |_, here| here()).unwrap()), (walked_pixels, walked));
        // A scene loaded with no buffer after one with: none, not the old one.
        let naive = |raytracer: &mut Raytracer<Buffered>| {
            draw(&raytracer.load_with(text.as_bytes(), AccelMode::Naive, &mut |e| panic!("{e:?}")).unwrap())
        };
        assert_eq!(naive(&mut two), naive(&mut Box::new(Raytracer::new())));
    }

    crate::profile! {
        /// [`Hashless`] with room for the camera rays' screen lists.
        struct Listed { spheres: 12, surfaces: 1, lights: 1, octree_boxes: 200, octree_references: 400 }
        octree: { max_objects: 1, max_depth: 4 }
        named_walk: false
        first_hits: true
    }

    #[test]
    fn a_profile_with_first_hits_draws_the_same_pixels_without_walking_camera_rays() {
        extern crate std;
        let spheres: std::string::String = (0..12).map(|i| std::format!("SPHERE 1 0.4 {} 0 0\n", i - 6)).collect();
        let text = std::format!("VIEWPOINT 0 2 9\nLIGHT 10 5 5 5\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n{spheres}");
        fn draw<P: Profile>(scene: &LoadedScene<'_, P>) -> [[Option<Rgb565>; 32]; 24] {
            let mut grid = Grid::<Rgb565, 32, 24>([[None; 32]; 24]);
            scene.image_for(&grid).draw(&mut grid).unwrap();
            grid.0
        }
        let mut walked = Raytracer::<Hashless>::new();
        let walked = walked.load_with(text.as_bytes(), AccelMode::Dda, &mut |e| panic!("{e:?}")).unwrap();
        let mut listed = Raytracer::<Listed>::new();
        let listed = listed.load_with(text.as_bytes(), AccelMode::Dda, &mut |e| panic!("{e:?}")).unwrap();
        assert!(listed.first_hits() && !walked.first_hits());
        assert_eq!(draw(&listed), draw(&walked));
        let (cells, walked_cells) = (listed.stats().cells, walked.stats().cells);
        assert!(cells < walked_cells, "camera rays skip the walk: {cells} cells against {walked_cells}");
        let mut by_name = Raytracer::<Listed>::new();
        let naive = by_name.load_with(text.as_bytes(), AccelMode::Naive, &mut |e| panic!("{e:?}")).unwrap();
        assert!(!naive.first_hits(), "the naive mode named tests every object");
    }

    #[test]
    fn a_bad_scene_gives_its_first_error_and_the_count() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let e = raytracer.load("SPHERE 1 1 0 0 0\nFOO\n").unwrap_err();
        assert_eq!(e.count, 2);
        assert_eq!((e.first.pos.line, e.first.pos.column), (1, 1));
    }
}
