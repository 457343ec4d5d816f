//! Frame-to-frame coherence: the image cut into square tiles, each with a
//! byte saying how many of the loop's next transitions surely leave all its
//! pixels as they are. A frame re-traces only the tiles whose count ran
//! out, and records their new counts as it traces them.
//!
//! Invariants: a tile's count is the smallest of its pixels' clean counts
//! ([`super::lookout`]) at the frame it was last traced, less the frames
//! since; [`TRACE`] marks a tile to trace in the frame being drawn (every
//! tile, at first); counts are atomics written by whichever core traced the
//! tile (loads and stores only, which a Cortex-M0 has), so cores share one
//! store without a lock.

use crate::accel::Accelerator;
use crate::motion::{Dependence, Lookout, Motion, NEVER};
use crate::render::{PixelSample, Polling, Renderer, Stop, Stopped};
use crate::shade::Stats;
use crate::shade::{Poll, Unpolled};
use core::fmt;
use core::ops::Range;
use core::sync::atomic::{AtomicU8, Ordering};
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::primitives::Rectangle;

/// Why a band's trace ended early: its sink's error, or its poll said stop.
pub(crate) enum Halt<E, S> {
    Sink(E),
    Stopped(S),
}

/// A tile to trace in the frame being drawn.
const TRACE: u8 = 254;
/// A tile nothing that moves can change.
const FOREVER: u8 = 255;
/// The largest count kept (a longer one is cut to it: traced early).
const MOST: u8 = 253;
/// Tiles of a band traced as one run at most (their counts wait on the
/// stack).
const RUN_TILES: usize = 32;

/// What receives a traced run's row of pixels: the row (a rectangle one
/// pixel high) and its pixels as they are traced
/// ([`Coherence::trace_band`]).
pub type RunSink<'f, E> = dyn FnMut(&Rectangle, &mut dyn Iterator<Item = PixelSample>) -> Result<(), E> + 'f;

/// Why [`Coherence::new`] refused its storage.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoherenceError {
    /// Fewer counts than tiles: how many the image needs
    /// ([`Coherence::tiles_for`]).
    NoRoom {
        /// Tiles in the image.
        needed: usize,
    },
}

impl fmt::Display for CoherenceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoherenceError::NoRoom { needed } => write!(f, "no room for coherence: the image has {needed} tiles"),
        }
    }
}

impl core::error::Error for CoherenceError {}

/// The tiles of an animation's image and what each still holds, over one
/// byte a tile of the caller's storage ([`Coherence::tiles_for`] of them, a
/// `const fn`). Each frame: [`Coherence::plan`], then trace the bands
/// ([`LoadedScene::draw_bands`](crate::LoadedScene::draw_bands) into a
/// display, or [`Coherence::trace_band`]),
/// on one core or several, each with a renderer of its own over the
/// frame's scene: only the tiles that can have changed are traced, and
/// only their runs of pixels drawn. The scene's profile says
/// `coherence: true` ([`Profile::COHERENCE`](crate::profile::Profile::COHERENCE));
/// under one that does not, every tile is traced each frame (the same
/// pictures, none of the watching code linked).
///
/// ```
/// use core::sync::atomic::AtomicU8;
/// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*};
/// use octrace_core::animation::{Coherence, Key, Motion, Track};
/// use octrace_core::Raytracer;
///
/// octrace_core::profile! {
///     /// Two spheres, one moving; frames re-trace only what changes.
///     struct Moving { spheres: 2, surfaces: 1, lights: 1 }
///     coherence: true
/// }
/// let text = "FRAMES 4\nRASTER 16 16\nBACKGROUND 0 0 1\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n\
///             LIGHT 10 5 5 5\nSPHERE 1 2 0 0 -4\nSPHERE 1 0.5 -3 2 0 MOVE 0 0 0 0  3 1.5 0 0\n";
/// const TILES: usize = Coherence::tiles_for(16, 16, 4);
/// static COUNTS: [AtomicU8; TILES] = [const { AtomicU8::new(0) }; TILES];
/// let coherence = Coherence::new(&COUNTS, Size::new(16, 16), 4)?;
/// let (mut tracks, mut keys, mut displacements) = ([Track::EMPTY; 1], [Key::default(); 2], [[0; 3]; 4]);
///
/// let mut raytracer = Raytracer::<Moving>::new();
/// let mut panel = MockDisplay::<Rgb888>::new();
/// panel.set_allow_overdraw(true);
/// let first = raytracer.load_frame(text, 0)?;
/// let frames = first.frames().unwrap();
/// let motion = Motion::read(text, frames, &first.view(), 0, &mut tracks, &mut keys, &mut displacements)?;
/// for frame in frames.all() {
///     let scene = raytracer.load_frame(text, frame)?;
///     let tiles = coherence.plan();
///     scene.draw_changes(&motion, frame, &coherence, &mut panel)?;
///     // The panel shows frame `frame`, as if drawn whole.
///     let mut whole = MockDisplay::<Rgb888>::new();
///     Image::new(&scene.image(Size::new(16, 16)), Point::zero()).draw(&mut whole)?;
///     assert_eq!(panel, whole);
///     assert!(frame == 0 && tiles == 16 || frame > 0 && tiles < 16, "frame {frame}: {tiles} tiles");
/// }
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Coherence<'s> {
    counts: &'s [AtomicU8],
    size: Size,
    side: u32,
    across: u32,
    ignored: u8,
}

impl<'s> Coherence<'s> {
    /// How many tiles (bytes of storage) an image of `width` × `height`
    /// pixels has in tiles of `side` × `side` (`side` at least 1).
    pub const fn tiles_for(width: u32, height: u32, side: u32) -> usize {
        let side = if side == 0 { 1 } else { side };
        width.div_ceil(side) as usize * height.div_ceil(side) as usize
    }

    /// Coherence for an image of `size` in tiles of `side` × `side` pixels
    /// over `counts`, every tile to be traced at the first frame.
    pub fn new(counts: &'s [AtomicU8], size: Size, side: u32) -> Result<Coherence<'s>, CoherenceError> {
        let side = side.max(1);
        let needed = Coherence::tiles_for(size.width, size.height, side);
        let Some(counts) = counts.get(..needed) else { return Err(CoherenceError::NoRoom { needed }) };
        let coherence = Coherence { counts, size, side, across: size.width.div_ceil(side), ignored: 0 };
        coherence.restart();
        Ok(coherence)
    }

    /// Drops the dependence `dependence` from the tracking: for a test
    /// that checks its check of exactness fails without it.
    #[doc(hidden)]
    pub fn ignoring(mut self, dependence: Dependence) -> Self {
        self.ignored |= 1 << dependence as u8;
        self
    }

    /// The image's size.
    pub fn size(&self) -> Size {
        self.size
    }

    /// The tiles' side, in pixels.
    pub fn side(&self) -> u32 {
        self.side
    }

    /// The most pixels of a row a run of tiles hands over at once
    /// ([`Coherence::trace_band`]): what a buffer for one must hold.
    ///
    /// ```
    /// use core::sync::atomic::AtomicU8;
    /// use embedded_graphics::prelude::Size;
    /// use octrace_core::animation::Coherence;
    ///
    /// const TILES: usize = Coherence::tiles_for(240, 240, 4);
    /// static COUNTS: [AtomicU8; TILES] = [const { AtomicU8::new(0) }; TILES];
    /// // Runs of up to 32 tiles of 4 pixels: 128 pixels of a 240-pixel row.
    /// assert_eq!(Coherence::new(&COUNTS, Size::new(240, 240), 4)?.longest_row(), 128);
    /// # Ok::<(), octrace_core::animation::CoherenceError>(())
    /// ```
    pub fn longest_row(&self) -> u32 {
        (RUN_TILES as u32 * self.side).min(self.size.width)
    }

    /// Rows of tiles (bands), each [`Coherence::side`] rows of pixels
    /// high (the last may be lower): the units cores share.
    pub fn bands(&self) -> u32 {
        self.size.height.div_ceil(self.side)
    }

    /// Every tile is traced in the next frame (the scene or its frame
    /// changed otherwise than by the loop's next step).
    pub fn restart(&self) {
        self.counts.iter().for_each(|c| c.store(TRACE, Ordering::Relaxed));
    }

    /// Steps to the next frame of the loop: a tile whose count ran out is
    /// marked to be traced, the others count one transition less. Returns
    /// how many tiles the frame traces. Call it once a frame, on one core,
    /// before any traces.
    pub fn plan(&self) -> usize {
        let mut traced = 0;
        for count in self.counts {
            let next = match count.load(Ordering::Relaxed) {
                0 | TRACE => TRACE,
                FOREVER => FOREVER,
                n => n - 1,
            };
            count.store(next, Ordering::Relaxed);
            traced += usize::from(next == TRACE);
        }
        traced
    }

    /// How many pixels the planned frame traces.
    pub fn traced_pixels(&self) -> u64 {
        (0..self.bands()).map(|band| self.band_pixels(band)).sum()
    }

    /// How many pixels the planned frame traces in band `band`.
    pub fn band_pixels(&self, band: u32) -> u64 {
        self.runs(band).map(|tiles| self.pixels_of(band, tiles)).sum()
    }

    /// The pixels of the tiles `tiles` of band `band`.
    fn area(&self, band: u32, tiles: &Range<u32>) -> Rectangle {
        let (x0, y0) = (tiles.start * self.side, band * self.side);
        let x1 = (tiles.end * self.side).min(self.size.width);
        let y1 = (y0 + self.side).min(self.size.height);
        Rectangle::new(Point::new(x0 as i32, y0 as i32), Size::new(x1 - x0, y1 - y0))
    }

    fn pixels_of(&self, band: u32, tiles: Range<u32>) -> u64 {
        let area = self.area(band, &tiles);
        u64::from(area.size.width) * u64::from(area.size.height)
    }

    /// The runs of tiles of band `band` to trace in the planned frame, as
    /// ranges of tile columns.
    pub fn runs(&self, band: u32) -> impl Iterator<Item = Range<u32>> + '_ {
        let row = self.counts.get((band * self.across) as usize..((band + 1) * self.across) as usize).unwrap_or(&[]);
        let traced = move |x: u32| row.get(x as usize).is_some_and(|c| c.load(Ordering::Relaxed) == TRACE);
        let mut x = 0;
        core::iter::from_fn(move || {
            while x < self.across && !traced(x) {
                x += 1;
            }
            let start = x;
            while x < self.across && traced(x) && x - start < RUN_TILES as u32 {
                x += 1;
            }
            (x > start).then_some(start..x)
        })
    }

    /// Traces the tiles of band `band` that the planned frame traces, frame
    /// `frame` of `motion` loaded in `renderer`'s scene: each run of tiles
    /// row by row, handing `each` the run's row (a rectangle one pixel
    /// high) and its pixels as they are traced; records the tiles' new
    /// counts. Returns the counters of the traces, or `each`'s error.
    pub fn trace_band<'a, A: Accelerator, E>(
        &self,
        renderer: &mut Renderer<'a, A>,
        motion: &'a Motion<'a>,
        frame: u32,
        band: u32,
        each: &mut RunSink<'_, E>,
    ) -> Result<Stats, E> {
        match self.trace_band_polled(renderer, motion, frame, band, &mut Unpolled, each) {
            Ok(stats) => Ok(stats),
            Err(Halt::Sink(e)) => Err(e),
            Err(Halt::Stopped(never)) => match never {},
        }
    }

    /// [`Coherence::trace_band`], asking `stop` before every ray (as
    /// [`Renderer::pixel_until`] does): [`Stopped`] as soon as it says so.
    /// The pixels of the run's row handed to `each` end before the stopped
    /// pixel (`each` is still called; the error that follows says the row
    /// is cut), and the tiles of that run keep their mark to be traced.
    pub fn trace_band_until<'a, A: Accelerator, S: Stop, E: From<Stopped>>(
        &self,
        renderer: &mut Renderer<'a, A>,
        motion: &'a Motion<'a>,
        frame: u32,
        band: u32,
        stop: &mut S,
        each: &mut RunSink<'_, E>,
    ) -> Result<Stats, E> {
        let mut polling = Polling { stop, stopped: false };
        match self.trace_band_polled(renderer, motion, frame, band, &mut polling, each) {
            Ok(stats) => Ok(stats),
            Err(Halt::Sink(e)) => Err(e),
            Err(Halt::Stopped(stopped)) => Err(stopped.into()),
        }
    }

    /// [`Coherence::trace_band`] with `poll` asked before every ray.
    #[inline(always)]
    pub(crate) fn trace_band_polled<'a, A: Accelerator, Q: Poll, E>(
        &self,
        renderer: &mut Renderer<'a, A>,
        motion: &'a Motion<'a>,
        frame: u32,
        band: u32,
        poll: &mut Q,
        each: &mut RunSink<'_, E>,
    ) -> Result<Stats, Halt<E, Q::Stopped>> {
        let before = renderer.stats();
        let lookout = Lookout::new(motion, frame, self.ignored);
        // A camera that moves before the next frame makes every count 0:
        // the pixels are traced as a still's, at a still's cost.
        let watching = !lookout.is_idle();
        renderer.set_lookout(watching.then_some(lookout));
        let result = self.runs(band).try_for_each(|tiles| {
            let area = self.area(band, &tiles);
            let (x0, side) = (area.top_left.x as u32, self.side);
            let mut clean = [NEVER; RUN_TILES];
            for y in area.rows() {
                let line = Rectangle::new(Point::new(x0 as i32, y), Size::new(area.size.width, 1));
                let mut halted = None;
                let mut pixels = (x0..x0 + area.size.width).map_while(|x| {
                    let tile = ((x - x0) / side) as usize;
                    let traced = match watching {
                        true => renderer.watched_pixel(x, y as u32, clean[tile], poll),
                        false => renderer.pixel_polled(x, y as u32, poll).map(|pixel| (pixel, 0)),
                    };
                    match traced {
                        Ok((pixel, count)) => {
                            clean[tile] = count;
                            Some(pixel)
                        }
                        Err(stopped) => {
                            halted = Some(stopped);
                            None
                        }
                    }
                });
                each(&line, &mut pixels).map_err(Halt::Sink)?;
                if let Some(stopped) = halted {
                    return Err(Halt::Stopped(stopped));
                }
            }
            for (tile, &count) in tiles.zip(&clean) {
                let stored = if count == NEVER { FOREVER } else { count.min(u32::from(MOST)) as u8 };
                if let Some(c) = self.counts.get((band * self.across + tile) as usize) {
                    c.store(stored, Ordering::Relaxed);
                }
            }
            Ok(())
        });
        renderer.set_lookout(None);
        result.map(|()| renderer.stats().since(&before))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::animation::{Key, Track};
    use crate::profile::{Board16K, Profile};
    use crate::Raytracer;
    use embedded_graphics::image::Image;
    use embedded_graphics::mock_display::MockDisplay;
    use embedded_graphics::pixelcolor::Rgb888;
    use embedded_graphics::prelude::*;

    const TEXT: &str = "FRAMES 4\nRASTER 16 16\nBACKGROUND 0 0 1\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n\
                        LIGHT 10 5 5 5\nSPHERE 1 2 0 0 -4\nSPHERE 1 0.5 -3 2 0 MOVE 0 0 0 0  3 1.5 0 0\n";

    /// Plays `TEXT` under profile `P`: each frame's tiles traced, and
    /// each panel checked against the frame drawn whole.
    fn play<P: Profile>() -> std::vec::Vec<usize> {
        let counts = [const { AtomicU8::new(0) }; 16];
        let coherence = Coherence::new(&counts, Size::new(16, 16), 4).unwrap();
        let (mut tracks, mut keys, mut displacements) = ([Track::EMPTY; 1], [Key::default(); 2], [[0; 3]; 4]);
        let mut raytracer = std::boxed::Box::new(Raytracer::<P>::new());
        let first = raytracer.load_frame(TEXT, 0).unwrap();
        let frames = first.frames().unwrap();
        let view = first.view();
        let motion = Motion::read(TEXT, frames, &view, 0, &mut tracks, &mut keys, &mut displacements).unwrap();
        let mut panel = MockDisplay::<Rgb888>::new();
        panel.set_allow_overdraw(true);
        let mut traced = std::vec::Vec::new();
        for frame in frames.all() {
            let scene = raytracer.load_frame(TEXT, frame).unwrap();
            traced.push(coherence.plan());
            scene.draw_changes(&motion, frame, &coherence, &mut panel).unwrap();
            let mut whole = MockDisplay::<Rgb888>::new();
            Image::new(&scene.image(Size::new(16, 16)), Point::zero()).draw(&mut whole).unwrap();
            assert_eq!(panel, whole, "frame {frame}");
        }
        traced
    }

    crate::profile! {
        /// Board16K's two spheres, with coherence.
        struct Moving { spheres: 2, surfaces: 1, lights: 1 }
        coherence: true
    }

    #[test]
    fn a_profile_without_coherence_traces_every_tile_of_every_frame() {
        assert_eq!(play::<Board16K>(), [16; 4]);
        let with = play::<Moving>();
        assert!(with[0] == 16 && with[1..].iter().all(|&t| t < 16), "{with:?}");
    }
}
