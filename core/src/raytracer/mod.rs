//! The one way in: a [`Raytracer`] holds a scene, its octree, a mailbox,
//! room for the camera rays' screen lists and for the shadow rays' light
//! buffer in one place (a `static` on a board), [`Raytracer::load`] parses a scene
//! text and indexes it, and the [`LoadedScene`] draws as an embedded-graphics
//! image ([`TracedImage`]) in the colour of any display.
//!
//! Invariants: a [`Raytracer::new`] is all zero bits (a `static` of it lands
//! in `.bss`, initialised in place); a [`LoadedScene`] exists only for a
//! scene that parsed without errors, with its accelerator built.

use crate::accel::MAX_CELLS_A_SIDE;
use crate::accel::{
    self, AccelMode, Indexing, LightBuffer, LightBufferStore, Mailbox, OctreeStore, Prepared, SceneAccelerator,
};
use crate::capacity::Arena;
use crate::parse::{parse_recording, ErrorKind, MotionSink, ParseError, Pos};
use crate::profile::Profile;
use crate::render::{ScreenBound, ScreenRoom};
use crate::scene::{Frames, Scene, SceneView};
use crate::shade::Stats;
use core::cell::{Cell, RefCell};
use core::fmt;

mod animated;
mod draw;
mod draw_error;
mod image;
mod loaded;
pub mod picture;
mod shared;

pub use animated::{AnimationError, Frame};
pub use draw_error::DrawError;
pub use image::TracedImage;
pub use loaded::LoadedScene;
pub use shared::SharedScene;

/// Room for one scene of the profile `P`: the scene's arenas, its octree and
/// a mailbox. On a board, keep it in a `static` (it is all zero bits, so it
/// costs no flash) and take it once with the re-exported
/// [`ConstStaticCell`](https://docs.rs/static_cell/2/static_cell/struct.ConstStaticCell.html)
/// (feature `static-cell`); on a host, box it.
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
    /// The scene's FRAMES, count and rate (0 frames: none).
    frames: [u32; 2],
    /// How the scene was last indexed: its mode (`Auto`: not indexed since
    /// it loaded), whether its light buffer was built, and whether its
    /// camera rays use the screen lists.
    indexed: (AccelMode, bool, bool),
}

/// Room for one core's [`Renderer`](crate::render::Renderer) over a profile's scenes: a mailbox and
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
    /// Borrowed by one renderer at a time: a draw's, for its length.
    room: RefCell<Room<P>>,
}

/// What a [`RendererRoom`] holds.
struct Room<P: Profile> {
    mailbox: P::MailboxWords,
    screen_bounds: P::ScreenBounds,
    screen_positions: P::ScreenPositions,
}

impl<P: Profile> RendererRoom<P> {
    /// Empty room: a constant of all-zero bits.
    pub const fn new() -> Self {
        let room = Room {
            mailbox: P::MailboxWords::EMPTY,
            screen_bounds: P::ScreenBounds::EMPTY,
            screen_positions: P::ScreenPositions::EMPTY,
        };
        RendererRoom { room: RefCell::new(room) }
    }
}

impl<P: Profile> Room<P> {
    /// The room cleared for a scene of `objects` objects: its mailbox, and
    /// its screen lists when the scene's camera rays use them (and as much
    /// again for a mirror's, when the profile has room for both).
    fn prepare(&mut self, objects: usize, first_hits: bool) -> (&mut [u32], Option<ScreenLists<'_>>) {
        fill(&mut self.mailbox, Mailbox::words_for(objects), 0);
        let listed = if first_hits { objects } else { 0 };
        let copies = ScreenBound::lists(P::MIRROR_HITS);
        fill(&mut self.screen_bounds, copies * listed, ScreenBound::EMPTY);
        fill(&mut self.screen_positions, copies * ScreenBound::positions_for(listed), 0);
        let (bounds, positions) = (self.screen_bounds.as_mut_slice(), self.screen_positions.as_mut_slice());
        let lists = match P::MIRROR_HITS {
            // A constant: a profile without the mirror's room links no split.
            false => ((bounds, positions), None),
            true => {
                let (bounds, mirror_bounds) = bounds.split_at_mut(listed.min(bounds.len()));
                let (positions, mirror_positions) =
                    positions.split_at_mut(ScreenBound::positions_for(listed).min(positions.len()));
                ((bounds, positions), Some((mirror_bounds, mirror_positions)))
            }
        };
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

/// A renderer's room for screen lists: its camera's, and a mirror's.
pub(super) type ScreenLists<'a> = (ScreenRoom<'a>, Option<ScreenRoom<'a>>);

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
            frames: [0; 2],
            indexed: (AccelMode::Auto, false, false),
        }
    }

    /// Parses `text` (replacing any scene loaded before) and indexes it for
    /// tracing, choosing the accelerator with [`AccelMode::Auto`].
    pub fn load<'t>(&mut self, text: &'t str) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        self.load_with(text.as_bytes(), AccelMode::Auto, &mut |_| {})
    }

    /// [`Raytracer::load`] of frame `frame` of an animation (a scene with
    /// `FRAMES`; see [`parse_frame`](crate::parse::parse_frame)): its
    /// moving statements stand where their `MOVE` keys put them at that
    /// frame. [`LoadedScene::frames`] says how many frames it has;
    /// [`crate::animation`] draws one frame after another re-tracing only
    /// what moved.
    ///
    /// ```
    /// use embedded_graphics::prelude::*;
    /// use octrace_core::{profile::Board16K, Raytracer};
    ///
    /// let text = "FRAMES 2\nRASTER 8 8\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n\
    ///             LIGHT 10 5 5 5 MOVE 0 0 0 0  1 -10 0 0\nSPHERE 1 3 0 0 0\n";
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let first = raytracer.load_frame(text, 0)?.with_renderer(Size::new(8, 8), |r| r.pixel(4, 4).color)?;
    /// let second = raytracer.load_frame(text, 1)?.with_renderer(Size::new(8, 8), |r| r.pixel(4, 4).color)?;
    /// assert_ne!(first, second, "the light moved");
    /// assert_eq!(raytracer.load_frame(text, 1)?.frames().map(|f| f.count), Some(2));
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn load_frame<'t>(&mut self, text: &'t str, frame: u32) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        self.load_in(text.as_bytes(), frame, &Indexing::default(), &mut |_| {}, &mut one_core, None)
    }

    /// [`Raytracer::load`] from bytes (invalid UTF-8 is an error at its
    /// place), indexed as `indexing` says (an [`AccelMode`], or with an
    /// octree criterion of its own: [`Indexing`]), handing every error to
    /// `on_error` as it is found. A profile with no room for octree boxes
    /// always uses [`AccelMode::Naive`] (same image; no octree code is
    /// linked); [`LoadedScene::mode`] says which mode is in use.
    pub fn load_with<'t>(
        &mut self,
        text: &'t [u8],
        indexing: impl Into<Indexing>,
        on_error: &mut dyn FnMut(ParseError<'t>),
    ) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        self.load_frame_with(text, 0, indexing, on_error)
    }

    /// [`Raytracer::load_with`] of frame `frame` of an animation
    /// ([`Raytracer::load_frame`]).
    pub fn load_frame_with<'t>(
        &mut self,
        text: &'t [u8],
        frame: u32,
        indexing: impl Into<Indexing>,
        on_error: &mut dyn FnMut(ParseError<'t>),
    ) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        self.load_in(text, frame, &indexing.into(), on_error, &mut one_core, None)
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
        self.load_frame_on_two_cores(text, 0, both)
    }

    /// [`Raytracer::load_frame`] on two cores, as
    /// [`Raytracer::load_on_two_cores`]: a board playing an animation
    /// loads each frame so.
    ///
    /// ```
    /// use octrace_core::{profile::Board16K, Raytracer};
    ///
    /// let text = "FRAMES 2\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5 MOVE 0 0 0 0  1 -10 0 0\nSPHERE 1 3 0 0 0\n";
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load_frame_on_two_cores(text, 1, |beside, here| {
    ///     std::thread::scope(|scope| {
    ///         scope.spawn(|| beside());
    ///         here();
    ///     })
    /// })?;
    /// let moved = scene.view().lights[0].position;
    /// let mut alone = Raytracer::<Board16K>::new();
    /// assert_eq!(moved, alone.load_frame(text, 1)?.view().lights[0].position);
    /// assert_ne!(moved, alone.load_frame(text, 0)?.view().lights[0].position);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn load_frame_on_two_cores<'t>(
        &mut self,
        text: &'t str,
        frame: u32,
        both: impl FnOnce(&mut (dyn FnMut() + Send), &mut dyn FnMut()),
    ) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        self.load_in(text.as_bytes(), frame, &Indexing::default(), &mut |_| {}, &mut once(both), None)
    }

    /// Parses frame `frame` of `text` and indexes it; `both(beside,
    /// here)` runs the two jobs of the indexing that are apart (the light
    /// buffer, the octree) and returns once both are done. With `motion`,
    /// each moving statement is handed to it once placed, and the camera of
    /// every frame is checked (an animation loaded to play).
    pub(super) fn load_in<'t>(
        &mut self,
        text: &'t [u8],
        frame: u32,
        indexing: &Indexing,
        on_error: &mut dyn FnMut(ParseError<'t>),
        both: &mut RunBoth<'_>,
        motion: Option<&mut dyn MotionSink>,
    ) -> Result<LoadedScene<'_, P>, LoadError<'t>> {
        let mut first = None;
        let mut report = |e: ParseError<'t>| {
            first.get_or_insert(e);
            on_error(e);
        };
        let parsed = parse_recording(text, &mut self.scene, frame, &mut report, motion);
        (self.frames, self.indexed) = ([0; 2], (AccelMode::Auto, false, false));
        match (parsed, first) {
            (Ok(parsed), _) => self.frames = parsed.frames.map_or([0; 2], |f| [f.count, f.rate]),
            (Err(count), Some(first)) => return Err(LoadError { first, count }),
            // Never taken: `parse_bytes` hands every error it counts to the
            // callback. Answered at the file's start rather than by a panic.
            (Err(count), None) => {
                let first = ParseError::new(Pos { line: 1, column: 1 }, ErrorKind::InvalidUtf8);
                return Err(LoadError { first, count });
            }
        };
        Ok(self.index(indexing, both))
    }

    /// The scene last loaded (empty if none did), indexed again as
    /// `indexing` says, with no parse: what a desktop that renders one
    /// scene in several ways (modes, octree criteria) does. `both` runs the
    /// two jobs of the indexing, as [`Raytracer::load_on_two_cores`]'s
    /// does: on two threads, or in turn (and timed apart).
    ///
    /// ```
    /// use octrace_core::{profile::Board64K, AccelMode, Raytracer};
    ///
    /// let text = "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\nSPHERE 1 1 3 0 0\n";
    /// let mut raytracer = Raytracer::<Board64K>::new();
    /// assert_eq!(raytracer.load(text)?.mode(), AccelMode::Naive);
    /// let scene = raytracer.reindex(AccelMode::Dda, |beside, here| {
    ///     here();
    ///     beside();
    /// });
    /// assert_eq!((scene.mode(), scene.view().object_count()), (AccelMode::Dda, 2));
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn reindex(
        &mut self,
        indexing: impl Into<Indexing>,
        both: impl FnOnce(&mut (dyn FnMut() + Send), &mut dyn FnMut()),
    ) -> LoadedScene<'_, P> {
        self.index(&indexing.into(), &mut once(both))
    }

    /// The scene last loaded, indexed as `indexing` says; `both` runs the
    /// two jobs that are apart (the light buffer, the octree).
    fn index(&mut self, indexing: &Indexing, both: &mut RunBoth<'_>) -> LoadedScene<'_, P> {
        let view = self.scene.view();
        let (mode, config) = (indexing.mode, indexing.octree.unwrap_or(P::OCTREE));
        let requested = mode;
        // The naive mode asked for by name stays the thesis's test of
        // every object, camera rays too; likewise the shadow rays' light
        // buffer.
        let buffered =
            <P::LightBufferWords as Arena<u32>>::CAPACITY > 0 && P::LIGHT_BUFFER && requested != AccelMode::Naive;
        let (octree_store, light_buffer) = (&mut self.octree, &mut self.light_buffer);
        let (mut prepared, mut built) = (None, false);
        both(
            &mut || {
                if buffered {
                    light_buffer.build_for::<P>(&view, MAX_CELLS_A_SIDE, P::COUNTS.light_buffer_lights);
                    built = true;
                }
            },
            &mut || prepared = Some(accel::prepare(mode, &view, octree_store, &config)),
        );
        // `both` ran both jobs, unless a caller's broke its promise: then
        // the octree is built now, and the shadow rays go without a buffer
        // (the store may hold an earlier scene's).
        let Prepared { mode, .. } = prepared.unwrap_or_else(|| accel::prepare(mode, &view, &mut self.octree, &config));
        let first_hits = P::FIRST_HITS && requested != AccelMode::Naive;
        self.indexed = (mode, built, first_hits);
        self.scene_indexed()
    }

    /// The scene last loaded, as it was last indexed (by a load, or
    /// [`Raytracer::reindex`]), if it was: another look at it with nothing
    /// built again, for a desktop that draws it in pieces.
    ///
    /// ```
    /// use octrace_core::{profile::Board16K, AccelMode, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// assert!(raytracer.indexed().is_none());
    /// raytracer.load_with(b"SPHERE 1 1 0 0 0\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n", AccelMode::Dda, &mut |_| {})?;
    /// assert_eq!(raytracer.indexed().map(|scene| scene.mode()), Some(AccelMode::Dda));
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn indexed(&self) -> Option<LoadedScene<'_, P>> {
        (self.indexed.0 != AccelMode::Auto).then(|| self.scene_indexed())
    }

    /// The scene as `indexed` says it was indexed.
    fn scene_indexed(&self) -> LoadedScene<'_, P> {
        let (mode, built, first_hits) = self.indexed;
        let octree = mode.traversal().map(|_| &self.octree);
        let lights = if built { self.light_buffer.buffer_for::<P>() } else { LightBuffer::NONE };
        let frames = match self.frames {
            [0, _] => None,
            [count, rate] => Some(Frames { count, rate }),
        };
        LoadedScene {
            view: self.scene.view(),
            mode,
            report: octree.map(|octree| *octree.report()),
            accelerator: SceneAccelerator::new(octree, lights),
            room: &self.room,
            first_hits,
            stats: Cell::new(Stats::default()),
            frames,
        }
    }

    /// The scene last loaded (empty if none did, or the last load failed):
    /// its objects, surfaces, lights and settings.
    pub fn view(&self) -> SceneView<'_> {
        self.scene.view()
    }
}

/// Runs its first job on another core (or after) and its second here.
pub(super) type RunBoth<'a> = dyn FnMut(&mut (dyn FnMut() + Send), &mut dyn FnMut()) + 'a;

/// Both jobs on this core, the second first.
pub(super) fn one_core(beside: &mut (dyn FnMut() + Send), here: &mut dyn FnMut()) {
    here();
    beside();
}

/// A caller's `both` (see [`Raytracer::load_on_two_cores`]) as a
/// [`RunBoth`], run once.
pub(super) fn once(
    both: impl FnOnce(&mut (dyn FnMut() + Send), &mut dyn FnMut()),
) -> impl FnMut(&mut (dyn FnMut() + Send), &mut dyn FnMut()) {
    let mut both = Some(both);
    move |beside, here| {
        if let Some(both) = both.take() {
            both(beside, here);
        }
    }
}

/// `arena` emptied, then `len` copies of `item`, as many as it holds.
fn fill<T: Copy>(arena: &mut impl Arena<T>, len: usize, item: T) {
    arena.clear();
    while arena.as_slice().len() < len && arena.push(item).is_ok() {}
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::Board16K;
    use embedded_graphics_core::draw_target::DrawTarget;
    use embedded_graphics_core::geometry::{OriginDimensions, Size};
    use embedded_graphics_core::image::ImageDrawable;
    use embedded_graphics_core::pixelcolor::PixelColor;
    use embedded_graphics_core::pixelcolor::Rgb565;
    use embedded_graphics_core::Pixel;

    pub(super) const SCENE: &str = "SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n";

    /// Collects what a draw writes.
    pub(super) struct Grid<C, const W: usize, const H: usize>(pub(super) [[Option<C>; W]; H]);

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
