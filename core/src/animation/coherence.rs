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

use crate::accel::Linked;
use crate::motion::NEVER;
use crate::render::{Halt, PixelSample, Renderer};
use crate::shade::{Poll, Stats};
use core::ops::Range;
use core::sync::atomic::{AtomicU8, Ordering};
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::primitives::Rectangle;

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
/// pixel high) and its pixels as they are traced.
pub(crate) type RunSink<'f, E> = dyn FnMut(&Rectangle, &mut dyn Iterator<Item = PixelSample>) -> Result<(), E> + 'f;

/// The tiles of an animation's image and what each still holds: one byte
/// a tile, in an [`Animation`](super::Animation)'s room. Each frame
/// loaded plans which tiles it traces (those whose count ran out); the
/// frame's draw traces them and records their new counts. Under a profile
/// without `coherence: true`
/// ([`Profile::COHERENCE`](crate::profile::Linked::COHERENCE)) every tile
/// is traced each frame (the same pictures, none of the watching code
/// linked).
///
/// ```
/// use embedded_graphics::prelude::*;
/// use octrace_core::animation::{AnimationNeeds, AnimationRoom};
///
/// let size = Size::new(240, 240);
/// let mut room = AnimationRoom::<{ AnimationNeeds::tiles_for(Size::new(240, 240)) }, 0, 0>::new();
/// let animation = room.animation(size)?;
/// let tiles = animation.tiles();
/// // Runs of up to 32 tiles of 4 pixels: 128 pixels of a 240-pixel row.
/// assert_eq!((tiles.bands(), tiles.longest_row()), (60, 128));
/// // Nothing loaded yet: every tile is to be traced.
/// assert_eq!(tiles.traced_pixels(), 240 * 240);
/// # Ok::<(), octrace_core::animation::NoRoom>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Coherence<'s> {
    counts: &'s [AtomicU8],
    size: Size,
    side: u32,
    across: u32,
}

impl<'s> Coherence<'s> {
    /// How many tiles (bytes of storage) an image of `width` × `height`
    /// pixels has in tiles of `side` × `side` (`side` at least 1).
    pub const fn tiles_for(width: u32, height: u32, side: u32) -> usize {
        let side = if side == 0 { 1 } else { side };
        width.div_ceil(side) as usize * height.div_ceil(side) as usize
    }

    /// Coherence for an image of `size` in tiles of `side` × `side` pixels
    /// over `counts` (every tile to be traced at the next frame if
    /// `restart`, else the counts as they are); or how many counts it
    /// needs.
    pub(crate) fn new(counts: &'s [AtomicU8], size: Size, side: u32, restart: bool) -> Result<Coherence<'s>, usize> {
        let side = side.max(1);
        let needed = Coherence::tiles_for(size.width, size.height, side);
        let counts = counts.get(..needed).ok_or(needed)?;
        let coherence = Coherence { counts, size, side, across: size.width.div_ceil(side) };
        if restart {
            coherence.restart();
        }
        Ok(coherence)
    }

    /// The image's size.
    pub fn size(&self) -> Size {
        self.size
    }

    /// The tiles' side, in pixels.
    pub fn side(&self) -> u32 {
        self.side
    }

    /// The most pixels of a row a frame's draw hands a target at once
    /// (a row of a run of tiles): what a buffer for one must hold.
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
    pub(crate) fn restart(&self) {
        self.counts.iter().for_each(|c| c.store(TRACE, Ordering::Relaxed));
    }

    /// Steps to the next frame of the loop: a tile whose count ran out is
    /// marked to be traced, the others count one transition less. Returns
    /// how many tiles the frame traces. Once a frame, on one core, before
    /// any traces.
    pub(crate) fn plan(&self) -> usize {
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

    /// The rectangles of pixels the planned frame traces: each run of
    /// tiles of each band (what a writer that stores only a frame's
    /// changes stores).
    pub fn traced_areas(&self) -> impl Iterator<Item = Rectangle> + '_ {
        (0..self.bands()).flat_map(move |band| self.runs(band).map(move |tiles| self.area(band, &tiles)))
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

    /// Traces the tiles of band `band` that the planned frame traces with
    /// `renderer` (over the frame's scene, watching the motion to come
    /// when it has a lookout), `poll` asked before every ray: each run of tiles row by row, handing `each` the run's
    /// row (a rectangle one pixel high) and its pixels as they are traced;
    /// records the tiles' new counts. Returns the counters of the traces,
    /// or why it ended early: `each`'s error, or the poll's stop (the
    /// pixels of the row handed to `each` then end before the stopped
    /// pixel, and the run's tiles keep their mark to be traced).
    #[inline(always)]
    pub(crate) fn trace_band<L: Linked, Q: Poll, E>(
        &self,
        renderer: &mut Renderer<'_, L>,
        band: u32,
        poll: &mut Q,
        each: &mut RunSink<'_, E>,
    ) -> Result<Stats, Halt<E, Q::Stopped>> {
        let before = renderer.stats();
        let watching = renderer.is_watching();
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
        result.map(|()| renderer.stats().since(&before))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use crate::animation::AnimationRoom;
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
    fn play<P: Profile>() -> std::vec::Vec<u64> {
        let size = Size::new(16, 16);
        let mut room = AnimationRoom::<16, 1, 2>::new();
        let mut animation = room.animation(size).unwrap();
        let mut raytracer = std::boxed::Box::new(Raytracer::<P>::new());
        let mut panel = MockDisplay::<Rgb888>::new();
        panel.set_allow_overdraw(true);
        let mut traced = std::vec::Vec::new();
        for frame in 0..4 {
            let loaded = animation.load(&mut raytracer, TEXT, frame).unwrap();
            traced.push(loaded.tiles().traced_pixels() / 16);
            loaded.image().try_draw(&mut panel).unwrap();
            let mut whole = MockDisplay::<Rgb888>::new();
            Image::new(&loaded.scene().image(size), Point::zero()).draw(&mut whole).unwrap();
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
