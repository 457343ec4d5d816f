//! A picture at once, the exact one after: a progressive pixel order, in
//! the manner of POV-Ray's mosaic preview. The first pass traces the
//! top-left pixel of every coarse block and fills the block with it, so the
//! whole display shows the scene after one trace in a few hundred; each
//! later pass halves the blocks and traces only the three new corners of
//! each split block, filling its new blocks; the last leaves every pixel
//! its own colour.
//!
//! The order is data ([`Progressive`], a sequence of [`Unit`]s: one row of
//! blocks of one pass each), so that several cores can share it: any core
//! traces a unit's pixels into a colour buffer ([`Unit::trace`]) and the
//! core that owns the display draws it from there ([`Unit::with_colors`],
//! [`TracedUnit::draw`]), in order. One core draws it all through a
//! scene's image
//! ([`TracedImage::progressive`](crate::TracedImage::progressive)),
//! streaming as the direct order does: no framebuffer.
//!
//! Invariants: every pixel of the image is traced once, by exactly one
//! unit; a unit's pixels lie in its own rows ([`Unit::rows`]) and it draws
//! only there, each traced pixel filling its block (clipped to the image),
//! never a pixel of a block traced before (that block's top-left quarter);
//! so after the first pass every pixel is drawn, and after the last every
//! pixel shows its own traced colour, which is the direct order's bit for
//! bit (a pixel's colour depends on nothing but its coordinates).
//!
//! # Drawing, for an SPI panel
//!
//! Each drawing call is a rectangle (a window command and its pixels).
//! Blocks of 8 pixels a side and more are drawn one `fill_solid` each (a
//! driver repeats one pixel at the speed of its bus); smaller new blocks
//! beside old ones one `fill_solid` each too, and a row of wholly new
//! small blocks as one `fill_contiguous`. Units go down the display, so
//! each pass sweeps it from top to bottom. [`Progressive::with_finest`]
//! stops the mosaic at a block size and then finishes each row of blocks
//! at full resolution: fewer rectangles (BENCHMARKS.md, "A picture at
//! once", has what each order sends a 240×240 panel and takes on the
//! emulated Pico).
//!
//! # Two cores
//!
//! Core 1 traces every other unit into a slot of colours (on a board, a
//! ring of slots handed over with atomics, as `interleaved_rows` describes),
//! core 0 traces the others and draws every unit in order:
//!
//! ```
//! use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*};
//! use octrace_core::render::{Progressive, Renderer};
//! use octrace_core::{profile::Board16K, Raytracer};
//!
//! const ORDER: Progressive = Progressive::new(Size::new(24, 20), 8);
//! let mut raytracer = Raytracer::<Board16K>::new();
//! let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n")?;
//! let accelerator = scene.accelerator();
//! let mut display = MockDisplay::<Rgb888>::new();
//! display.set_allow_overdraw(true); // later passes draw over the coarse blocks
//!
//! // Each core has its own renderer and colour buffer, as large as the largest unit.
//! let mut core0 = Renderer::with_size(scene.view(), &accelerator, 24, 20)?;
//! let mut core1 = Renderer::with_size(scene.view(), &accelerator, 24, 20)?;
//! let mut mine = [Rgb888::BLACK; ORDER.max_unit_pixels()];
//! let mut slot = [Rgb888::BLACK; ORDER.max_unit_pixels()];
//! for (index, unit) in ORDER.units().enumerate() {
//!     if index % 2 == 1 {
//!         unit.trace(&mut core1, &mut slot)?; // on core 1
//!         unit.with_colors(&slot)?.draw(&mut display)?; // on core 0, once handed over
//!     } else {
//!         unit.trace(&mut core0, &mut mine)?.draw(&mut display)?;
//!     }
//! }
//! // The direct order's picture, bit for bit.
//! let mut direct = MockDisplay::<Rgb888>::new();
//! Image::new(&scene.image(ORDER.size()), Point::zero()).draw(&mut direct)?;
//! assert_eq!(display, direct);
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```

use super::{Halt, Renderer, Walk};
use crate::accel::Linked;
use crate::scene::MAX_SIDE;
use crate::shade::{Poll, Stats, Unpolled};
use core::convert::Infallible;
use core::fmt;
use core::ops::Range;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::{PixelColor, Rgb888};
use embedded_graphics_core::primitives::Rectangle;

/// Blocks of at least this side are drawn one `fill_solid` each; smaller
/// ones, a run of them side by side as one `fill_contiguous`. A display
/// driver sends a solid block as one pixel repeated, as fast as its bus,
/// but each colour of `fill_contiguous` through a loop a pixel; a block's
/// own window is repaid from this side on (measured on the emulated Pico's
/// ST7789 through mipidsi: BENCHMARKS.md, "A picture at once").
const SOLID_FROM: u32 = 8;

/// Blocks a single core traces before drawing them as one rectangle (runs
/// of blocks wider than a pixel and narrower than [`SOLID_FROM`]): its
/// colour buffer, on the stack.
const CHUNK_BLOCKS: usize = 32;

/// A progressive order over an image of `size`: passes of blocks from
/// `coarsest` pixels a side down to `finest`, then (if `finest` is more
/// than 1) each row of those blocks at full resolution. With `coarsest` 1
/// it is the direct row order.
///
/// ```
/// use embedded_graphics::prelude::*;
/// use octrace_core::render::Progressive;
///
/// let order = Progressive::new(Size::new(240, 240), 16);
/// assert_eq!(order.passes(), 5); // blocks of 16, 8, 4, 2 and 1
/// let first = order.units().take_while(|unit| unit.pass() == 0);
/// assert_eq!(first.map(|unit| unit.pixel_count()).sum::<usize>(), 225); // the coarse panel
/// assert_eq!(order.units().map(|unit| unit.pixel_count()).sum::<usize>(), 240 * 240);
/// assert_eq!(order.max_unit_pixels(), 360); // a row of 120 new pixels, then 240
/// assert_eq!(order.with_finest(4).passes(), 4); // 16, 8, 4, then rows of 4 at full resolution
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progressive {
    size: Size,
    coarsest: u32,
    finest: u32,
}

/// `value`, at most [`MAX_SIDE`].
const fn at_most_side(value: u32) -> u32 {
    if value > MAX_SIDE {
        MAX_SIDE
    } else {
        value
    }
}

/// The power of two at most `value`, within 1 ..= [`MAX_SIDE`].
const fn power_of_two_at_most(value: u32) -> u32 {
    // `| 1`: 0 counts as 1; a power of two is unchanged.
    1 << (31 - (at_most_side(value) | 1).leading_zeros())
}

/// How many blocks of `block` pixels (a power of two) `length` pixels
/// start: a shift, where a division is a long call on a core without one.
const fn blocks_across(length: u32, block: u32) -> u32 {
    (length + block - 1) >> block.trailing_zeros()
}

impl Progressive {
    /// The order for an image of `size` (each side at most [`MAX_SIDE`])
    /// whose first pass fills blocks of `coarsest` pixels a side (rounded
    /// down to a power of two, at least 1), refined down to single pixels.
    pub const fn new(size: Size, coarsest: u32) -> Progressive {
        let size = Size::new(at_most_side(size.width), at_most_side(size.height));
        Progressive { size, coarsest: power_of_two_at_most(coarsest), finest: 1 }
    }

    /// The same order with its mosaic stopped at blocks of `finest` pixels
    /// (a power of two, rounded down, at most the coarsest): after that
    /// pass each row of those blocks is finished at full resolution, top to
    /// bottom, in fewer drawing calls. The same final picture.
    pub const fn with_finest(self, finest: u32) -> Progressive {
        let finest = power_of_two_at_most(finest);
        Progressive { finest: if finest > self.coarsest { self.coarsest } else { finest }, ..self }
    }

    /// The image's size.
    pub const fn size(&self) -> Size {
        self.size
    }

    /// The first pass's block side.
    pub const fn coarsest(&self) -> u32 {
        self.coarsest
    }

    /// The last mosaic pass's block side.
    pub const fn finest(&self) -> u32 {
        self.finest
    }

    /// How many passes there are: one for each block size from the
    /// coarsest down to the finest, and the finishing one if the finest is
    /// more than a pixel.
    pub const fn passes(&self) -> u32 {
        let halvings = self.coarsest.trailing_zeros() - self.finest.trailing_zeros();
        1 + halvings + (self.finest > 1) as u32
    }

    /// Pass `pass` (below [`Progressive::passes`]).
    const fn level(&self, pass: u32) -> Level {
        let halvings = self.coarsest.trailing_zeros() - self.finest.trailing_zeros();
        if pass == 0 {
            Level { block: self.coarsest, parent: None }
        } else if pass <= halvings {
            let block = self.coarsest >> pass;
            Level { block, parent: Some(2 * block) }
        } else {
            Level { block: 1, parent: Some(self.finest) }
        }
    }

    /// How many units there are in all passes.
    pub const fn unit_count(&self) -> u32 {
        let mut count = 0;
        let mut pass = 0;
        while pass < self.passes() {
            count += self.size.height.div_ceil(self.level(pass).span());
            pass += 1;
        }
        count
    }

    /// The units, in the order they are drawn.
    pub fn units(&self) -> impl Iterator<Item = Unit> {
        let order = *self;
        (0..order.passes()).flat_map(move |pass| {
            let level = order.level(pass);
            (0..order.size.height).step_by(level.span() as usize).map(move |y| Unit {
                level,
                pass,
                y,
                size: order.size,
            })
        })
    }

    /// The most pixels a unit traces: how many colours a buffer for
    /// [`Unit::trace`] must hold. A `const fn`, so that a board can size
    /// its buffers in a `static`.
    pub const fn max_unit_pixels(&self) -> usize {
        let mut most = 0;
        let mut pass = 0;
        while pass < self.passes() {
            // The first unit of a pass has all its rows.
            let unit = Unit { level: self.level(pass), pass, y: 0, size: self.size };
            let pixels = unit.pixel_count();
            most = if pixels > most { pixels } else { most };
            pass += 1;
        }
        most
    }

    /// Traces the whole image with `renderer` into `target`, unit by unit:
    /// the order for one core. Blocks drawn alone and single pixels stream
    /// as they are traced; a row of small blocks is traced up to 32 blocks
    /// at a time into a buffer on the stack, then drawn. Returns the
    /// counters of this call. (Scenes draw it through a `TracedImage`.)
    #[cfg(test)]
    pub(crate) fn render<L, D>(
        &self,
        renderer: &mut Renderer<'_, L>,
        target: &mut D,
    ) -> Result<Stats, ProgressiveError<D::Error>>
    where
        L: Linked,
        D: DrawTarget,
        D::Color: From<Rgb888>,
    {
        check_size(renderer.size(), self.size)?;
        match self.render_polled(renderer, target, &mut Unpolled) {
            Ok(stats) => Ok(stats),
            Err(Halt::Sink(e)) => Err(ProgressiveError::Target(e)),
            Err(Halt::Stopped(never)) => match never {},
        }
    }

    /// [`Progressive::render`] with a renderer of the order's size, `poll`
    /// asked before every ray.
    pub(crate) fn render_polled<L, D, Q>(
        &self,
        renderer: &mut Renderer<'_, L>,
        target: &mut D,
        poll: &mut Q,
    ) -> Result<Stats, Halt<D::Error, Q::Stopped>>
    where
        L: Linked,
        D: DrawTarget,
        D::Color: From<Rgb888>,
        Q: Poll,
    {
        let before = renderer.stats();
        let mut chunk = [Rgb888::new(0, 0, 0); CHUNK_BLOCKS];
        for unit in self.units() {
            let mut walk = Walk::NEW;
            for run in unit.runs() {
                let y = run.y;
                let mut pixel = |x| renderer.pixel_on(&mut walk, x, y, poll).map(|p| p.color).map_err(Halt::Stopped);
                // Blocks drawn alone, and single pixels, stream as traced.
                if run.solid() {
                    for (block, x) in (0..).zip(run.columns()) {
                        let color = pixel(x)?;
                        target.fill_solid(&run.block_area(block), color.into()).map_err(Halt::Sink)?;
                    }
                } else if run.block == 1 {
                    // Every pixel traced, even for a display that stops
                    // short (one smaller than the image); one stopped cuts
                    // the run there.
                    let mut halted = None;
                    let mut colors = run.columns().map_while(|x| match pixel(x) {
                        Ok(color) => Some(color),
                        Err(stopped) => {
                            halted = Some(stopped);
                            None
                        }
                    });
                    target.fill_contiguous(&run.area, colors.by_ref().map(Into::into)).map_err(Halt::Sink)?;
                    colors.for_each(drop);
                    if let Some(stopped) = halted {
                        return Err(stopped);
                    }
                } else {
                    for part in run.parts(CHUNK_BLOCKS as u32) {
                        let colors = &mut chunk[..(part.blocks as usize).min(CHUNK_BLOCKS)];
                        for (slot, x) in colors.iter_mut().zip(part.columns()) {
                            *slot = pixel(x)?;
                        }
                        part.draw(colors, target).map_err(Halt::Sink)?;
                    }
                }
            }
        }
        Ok(renderer.stats().since(&before))
    }
}

/// One pass: blocks of `block` pixels a side, each filled with its traced
/// top-left pixel. Every pass but the first splits blocks of `parent`
/// pixels, whose top-left pixels are on the display already.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Level {
    block: u32,
    parent: Option<u32>,
}

impl Level {
    /// The rows a unit of this pass covers.
    const fn span(&self) -> u32 {
        match self.parent {
            Some(parent) => parent,
            None => self.block,
        }
    }
}

/// A unit of work: one row of blocks of one pass. Its pixels
/// ([`Unit::pixels`]) are traced in order into a colour buffer, by any core
/// ([`Unit::trace`]); the core that owns the display then draws it
/// ([`TracedUnit::draw`]). Units must be drawn in the order
/// [`Progressive::units`] gives them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unit {
    level: Level,
    pass: u32,
    /// The unit's first row.
    y: u32,
    size: Size,
}

impl Unit {
    /// Which pass the unit belongs to: 0 for the first, coarse one.
    pub const fn pass(&self) -> u32 {
        self.pass
    }

    /// The side of the blocks its traced pixels fill.
    pub const fn block(&self) -> u32 {
        self.level.block
    }

    /// The rows the unit traces and draws in.
    pub const fn rows(&self) -> Range<u32> {
        let end = self.y + self.level.span();
        self.y..if end < self.size.height { end } else { self.size.height }
    }

    /// How many pixels the unit traces.
    pub const fn pixel_count(&self) -> usize {
        let (width, block) = (self.size.width, self.level.block);
        let lines = blocks_across(self.rows().end.saturating_sub(self.y), block);
        if lines == 0 {
            return 0;
        }
        let across = blocks_across(width, block) as usize;
        // The first line skips the parents' pixels, traced before.
        let first = match self.level.parent {
            Some(parent) => across - blocks_across(width, parent) as usize,
            None => across,
        };
        first + (lines as usize - 1) * across
    }

    /// The pixels the unit traces, in order: its colours come in this
    /// order.
    pub fn pixels(&self) -> impl Iterator<Item = Point> {
        self.runs().flat_map(|run| run.columns().map(move |x| Point::new(x as i32, run.y as i32)))
    }

    /// The unit's runs of blocks, line by line and left to right.
    fn runs(&self) -> Runs {
        let x = if self.level.parent.is_some() { self.level.block } else { 0 };
        Runs { unit: *self, row: self.y, x }
    }

    /// Traces the unit's pixels with `renderer` into `colors`, in the
    /// order of [`Unit::pixels`]: the unit ready to draw. `renderer` traces
    /// the order's size; `colors` holds the unit's pixels (a buffer of
    /// [`Progressive::max_unit_pixels`] holds any unit's).
    pub fn trace<'c, L: Linked, C: From<Rgb888>>(
        &self,
        renderer: &mut Renderer<'_, L>,
        colors: &'c mut [C],
    ) -> Result<TracedUnit<'c, C>, ProgressiveError> {
        check_size(renderer.size(), self.size)?;
        let room = colors.len();
        let colors = colors
            .get_mut(..self.pixel_count())
            .ok_or(ProgressiveError::Buffer { pixels: self.pixel_count(), room })?;
        let (mut slots, mut walk) = (colors.iter_mut(), Walk::NEW);
        for run in self.runs() {
            // The columns first: when they end, no slot is taken.
            for (x, slot) in run.columns().zip(slots.by_ref()) {
                let Ok(pixel) = renderer.pixel_on(&mut walk, x, run.y, &mut Unpolled);
                *slot = pixel.color.into();
            }
        }
        Ok(TracedUnit { unit: *self, colors })
    }

    /// The unit with the colours of its pixels (traced by another core,
    /// with [`Unit::trace`]), ready to draw; an error when `colors` holds
    /// fewer than its pixels (more are ignored).
    pub fn with_colors<'c, C>(&self, colors: &'c [C]) -> Result<TracedUnit<'c, C>, ProgressiveError> {
        let pixels = self.pixel_count();
        let colors = colors.get(..pixels).ok_or(ProgressiveError::Buffer { pixels, room: colors.len() })?;
        Ok(TracedUnit { unit: *self, colors })
    }
}

/// A unit's runs, line by line, left to right: plain arithmetic, no
/// division (a mosaic's lines of new blocks beside old ones have a run a
/// pixel traced).
#[derive(Clone, Copy, Debug)]
struct Runs {
    unit: Unit,
    /// The line, and where its next run starts.
    row: u32,
    x: u32,
}

impl Iterator for Runs {
    type Item = Run;

    fn next(&mut self) -> Option<Run> {
        let Unit { level, y, size, .. } = self.unit;
        let block = level.block;
        let end = self.unit.rows().end;
        while self.row < end {
            // The first line of a split has runs between the parents'
            // pixels, `parent` apart; any other line, one run across.
            let (period, most) = match level.parent {
                Some(parent) if self.row == y => (parent, blocks_across(parent, block) - 1),
                _ => (size.width, blocks_across(size.width, block)),
            };
            if self.x < size.width {
                let x = self.x;
                self.x += period;
                let blocks = most.min(blocks_across(size.width - x, block));
                return Some(Run::new(Point::new(x as i32, self.row as i32), block, blocks, size));
            }
            self.row += block;
            self.x = 0;
        }
        None
    }
}

/// A [`Unit`] with the colours of its pixels, ready to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TracedUnit<'c, C> {
    unit: Unit,
    colors: &'c [C],
}

impl<C: PixelColor> TracedUnit<'_, C> {
    /// The unit.
    pub fn unit(&self) -> Unit {
        self.unit
    }

    /// Its pixels' colours, in the order of [`Unit::pixels`].
    pub fn colors(&self) -> &[C] {
        self.colors
    }

    /// Draws the unit: each traced pixel fills its block (module docs,
    /// "Drawing").
    pub fn draw<D>(&self, target: &mut D) -> Result<(), D::Error>
    where
        D: DrawTarget,
        D::Color: From<C>,
    {
        let mut rest = self.colors;
        for run in self.unit.runs() {
            let (colors, after) = rest.split_at(rest.len().min(run.blocks as usize));
            run.draw(colors, target)?;
            rest = after;
        }
        Ok(())
    }
}

/// Blocks side by side in one row of blocks, drawn together ([`Run::draw`]):
/// their traced pixels are `(x + i · block, y)` for `i` below `blocks`.
#[derive(Clone, Copy, Debug)]
struct Run {
    x: u32,
    y: u32,
    block: u32,
    blocks: u32,
    /// The blocks, clipped to the image.
    area: Rectangle,
}

impl Run {
    /// The run of `blocks` blocks from `at` in an image of `size`.
    fn new(at: Point, block: u32, blocks: u32, size: Size) -> Run {
        let (x, y) = (at.x as u32, at.y as u32);
        let area = Size::new((blocks * block).min(size.width - x), block.min(size.height - y));
        Run { x, y, block, blocks, area: Rectangle::new(at, area) }
    }

    /// The columns of its traced pixels, left to right.
    fn columns(&self) -> impl Iterator<Item = u32> {
        let (x, block) = (self.x, self.block);
        (0..self.blocks).map(move |i| x + i * block)
    }

    /// The run cut into runs of at most `most` blocks.
    fn parts(&self, most: u32) -> impl Iterator<Item = Run> {
        let run = *self;
        let size = Size::new(run.x + run.area.size.width, run.y + run.area.size.height);
        (0..run.blocks).step_by(most.max(1) as usize).map(move |first| {
            let at = Point::new((run.x + first * run.block) as i32, run.y as i32);
            Run::new(at, run.block, most.min(run.blocks - first), size)
        })
    }

    /// Whether its blocks are drawn one `fill_solid` each: a single block,
    /// or blocks of [`SOLID_FROM`] and more.
    fn solid(&self) -> bool {
        self.blocks == 1 || self.block >= SOLID_FROM
    }

    /// Block `index`'s area, clipped to the image.
    fn block_area(&self, index: u32) -> Rectangle {
        let x = self.x + index * self.block;
        let width = self.block.min((self.x + self.area.size.width).saturating_sub(x));
        Rectangle::new(Point::new(x as i32, self.y as i32), Size::new(width, self.area.size.height))
    }

    /// Draws the run with its blocks' `colors`: a `fill_solid` a block
    /// ([`Run::solid`]), else one `fill_contiguous`, each colour repeated
    /// across and down its block.
    fn draw<C: PixelColor, D>(&self, colors: &[C], target: &mut D) -> Result<(), D::Error>
    where
        D: DrawTarget,
        D::Color: From<C>,
    {
        if self.solid() {
            for (block, &color) in (0..).zip(colors) {
                target.fill_solid(&self.block_area(block), color.into())?;
            }
            return Ok(());
        }
        let (width, block) = (self.area.size.width as usize, self.block as usize);
        let row = move || colors.iter().flat_map(move |&c| core::iter::repeat_n(D::Color::from(c), block)).take(width);
        target.fill_contiguous(&self.area, (0..self.area.size.height).flat_map(move |_| row()))
    }
}

/// Why a progressive order cannot trace or draw a unit.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProgressiveError<E = Infallible> {
    /// The renderer traces an image of another size than the order's
    /// (width and height of each).
    Size {
        /// The renderer's image.
        renderer: [u32; 2],
        /// The order's image.
        order: [u32; 2],
    },
    /// A unit has more pixels than its colour buffer holds.
    Buffer {
        /// The unit's pixels.
        pixels: usize,
        /// The colours the buffer holds.
        room: usize,
    },
    /// The display's own error.
    Target(E),
}

/// An error unless `renderer` traces images of `order`'s size.
fn check_size<E>(renderer: Size, order: Size) -> Result<(), ProgressiveError<E>> {
    if renderer == order {
        return Ok(());
    }
    Err(ProgressiveError::Size { renderer: [renderer.width, renderer.height], order: [order.width, order.height] })
}

impl<E: fmt::Display> fmt::Display for ProgressiveError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProgressiveError::Size { renderer: [rw, rh], order: [ow, oh] } => {
                write!(f, "the renderer traces {rw}×{rh} pixels, the progressive order is for {ow}×{oh}")
            }
            ProgressiveError::Buffer { pixels, room } => write!(
                f,
                "a unit of {pixels} pixels does not fit a colour buffer of {room} (Progressive::max_unit_pixels sizes it)"
            ),
            ProgressiveError::Target(e) => write!(f, "the display failed: {e}"),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for ProgressiveError<E> {}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::parse::parse;
    use crate::profile::{Board64K, Profile};
    use crate::scene::Scene;
    use embedded_graphics_core::geometry::OriginDimensions;
    use embedded_graphics_core::primitives::PointsIter;
    use embedded_graphics_core::Pixel;
    use std::{boxed::Box, vec, vec::Vec};

    /// A display that keeps its pixels and counts its rectangles and the
    /// pixels sent, as an SPI panel would receive them.
    struct Panel {
        size: Size,
        pixels: Vec<Option<Rgb888>>,
        rectangles: usize,
        sent: usize,
    }

    impl Panel {
        fn new(size: Size) -> Panel {
            Panel { size, pixels: vec![None; (size.width * size.height) as usize], rectangles: 0, sent: 0 }
        }

        fn get(&self, x: u32, y: u32) -> Option<Rgb888> {
            self.pixels[(y * self.size.width + x) as usize]
        }
    }

    impl OriginDimensions for Panel {
        fn size(&self) -> Size {
            self.size
        }
    }

    impl DrawTarget for Panel {
        type Color = Rgb888;
        type Error = Infallible;

        fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), Infallible> {
            for Pixel(p, c) in pixels {
                let (x, y) = (p.x as u32, p.y as u32);
                assert!(p.x >= 0 && p.y >= 0 && x < self.size.width && y < self.size.height, "{p:?} outside");
                self.pixels[(y * self.size.width + x) as usize] = Some(c);
                self.sent += 1;
            }
            Ok(())
        }

        fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(
            &mut self,
            area: &Rectangle,
            colors: I,
        ) -> Result<(), Infallible> {
            self.rectangles += 1;
            let before = self.sent;
            self.draw_iter(area.points().zip(colors).map(|(p, c)| Pixel(p, c)))?;
            assert_eq!(self.sent - before, area.size.width as usize * area.size.height as usize, "{area:?} filled");
            Ok(())
        }

        fn fill_solid(&mut self, area: &Rectangle, color: Rgb888) -> Result<(), Infallible> {
            self.fill_contiguous(area, core::iter::repeat(color))
        }
    }

    /// Image sizes (odd, thin, a power of two, tiny) and orders.
    fn orders() -> impl Iterator<Item = Progressive> {
        let sizes = [(1, 1), (1, 7), (9, 1), (13, 9), (33, 17), (40, 24), (32, 32), (47, 5)];
        sizes.into_iter().flat_map(|(w, h)| {
            [1, 2, 4, 8, 16, 64].into_iter().flat_map(move |coarsest| {
                [1, 2, 4, 16]
                    .into_iter()
                    .filter(move |&f| f <= coarsest)
                    .map(move |finest| Progressive::new(Size::new(w, h), coarsest).with_finest(finest))
            })
        })
    }

    #[test]
    fn every_pixel_is_traced_once_by_a_unit_over_its_rows() {
        for order in orders() {
            let Size { width, height } = order.size();
            let mut traced = vec![0u32; (width * height) as usize];
            let (mut units, mut most) = (0, 0);
            for unit in order.units() {
                let pixels: Vec<Point> = unit.pixels().collect();
                assert_eq!(pixels.len(), unit.pixel_count(), "{order:?} {unit:?}");
                for p in pixels {
                    assert!(unit.rows().contains(&(p.y as u32)) && (p.x as u32) < width, "{order:?} {unit:?}: {p}");
                    traced[(p.y as u32 * width + p.x as u32) as usize] += 1;
                }
                units += 1;
                most = most.max(unit.pixel_count());
            }
            assert!(traced.iter().all(|&n| n == 1), "{order:?}: {traced:?}");
            assert_eq!((units, most), (order.unit_count(), order.max_unit_pixels()), "{order:?}");
        }
    }

    /// A colour of its own for each pixel, as if traced.
    fn own(x: u32, y: u32) -> Rgb888 {
        Rgb888::new(x as u8, y as u8, (x >> 8 | y >> 8 << 4) as u8 ^ 0x5a)
    }

    #[test]
    fn the_first_pass_covers_the_panel_and_the_last_leaves_each_pixel_its_own() {
        for order in orders() {
            let Size { width, height } = order.size();
            let mut panel = Panel::new(order.size());
            let mut first_pass_done = false;
            for unit in order.units() {
                if unit.pass() == 1 && !first_pass_done {
                    assert!(panel.pixels.iter().all(Option::is_some), "{order:?}: the first pass leaves holes");
                    first_pass_done = true;
                }
                let before = panel.pixels.clone();
                let colors: Vec<Rgb888> = unit.pixels().map(|p| own(p.x as u32, p.y as u32)).collect();
                unit.with_colors(&colors).unwrap().draw(&mut panel).unwrap();
                for (i, (was, now)) in before.iter().zip(&panel.pixels).enumerate() {
                    let (x, y) = (i as u32 % width, i as u32 / width);
                    // A pixel that shows its own colour keeps it, and a unit
                    // draws in its own rows only.
                    if *was == Some(own(x, y)) || !unit.rows().contains(&y) {
                        assert_eq!(was, now, "{order:?} {unit:?} at ({x}, {y})");
                    }
                }
            }
            for (x, y) in (0..height).flat_map(|y| (0..width).map(move |x| (x, y))) {
                assert_eq!(panel.get(x, y), Some(own(x, y)), "{order:?} at ({x}, {y})");
            }
        }
    }

    #[test]
    fn a_coarse_pass_fills_each_block_with_its_top_left_pixel() {
        let order = Progressive::new(Size::new(21, 11), 8);
        let mut panel = Panel::new(order.size());
        for unit in order.units().take_while(|unit| unit.pass() < 2) {
            let colors: Vec<Rgb888> = unit.pixels().map(|p| own(p.x as u32, p.y as u32)).collect();
            unit.with_colors(&colors).unwrap().draw(&mut panel).unwrap();
        }
        // After the passes of 8 and 4: blocks of 4.
        for (x, y) in (0..11).flat_map(|y| (0..21).map(move |x| (x, y))) {
            assert_eq!(panel.get(x, y), Some(own(x & !3, y & !3)), "({x}, {y})");
        }
    }

    /// Rectangles and pixels sent for `order`, pass by pass, drawn from
    /// colours handed over (as two cores do).
    fn sent_by_pass(order: &Progressive) -> Vec<(usize, usize)> {
        let mut panel = Panel::new(order.size());
        let mut by_pass = vec![(0, 0); order.passes() as usize];
        let colors = vec![Rgb888::new(0, 0, 0); order.max_unit_pixels()];
        for unit in order.units() {
            let before = (panel.rectangles, panel.sent);
            unit.with_colors(&colors).unwrap().draw(&mut panel).unwrap();
            let pass = &mut by_pass[unit.pass() as usize];
            pass.0 += panel.rectangles - before.0;
            pass.1 += panel.sent - before.1;
        }
        by_pass
    }

    #[test]
    fn a_240_panel_takes_a_rectangle_a_block_of_8_and_more_and_one_a_row_of_smaller() {
        let order = Progressive::new(Size::new(240, 240), 16);
        let p = 240 * 240;
        // The first pass: a rectangle a block, every pixel once. Then, for
        // blocks of b, a rectangle for each new block beside an old one,
        // and for each block of 8 and more below them, or one for each row
        // of smaller ones: 3/4 of the pixels.
        let expected =
            [(225, p), (15 * 45, p * 3 / 4), (30 * 31, p * 3 / 4), (60 * 61, p * 3 / 4), (120 * 121, p * 3 / 4)];
        assert_eq!(sent_by_pass(&order), expected);
        // Finished from blocks of 4 at full resolution: a rectangle for each
        // three new pixels beside an old one, one for each row below.
        let finished = sent_by_pass(&order.with_finest(4));
        assert_eq!(finished[..3], expected[..3]);
        assert_eq!(finished[3], (60 * 63, p * 15 / 16));
    }

    const SCENE: &str = "RASTER 8 8\nVIEWPOINT 1 2 6\nLIGHT 10 5 5 5\nLIGHT 8 -4 3 6\nBACKGROUND .2 .3 .5\n\
        SURFACE 1 .1 .1 .1 .7 .2 .2 .3 .3 .3 8 .4 0\nSURFACE 2 .1 .1 .1 .2 .6 .3 0 0 0 1 0 0\n\
        SPHERE 1 1 0 0 0\nSPHERE 2 .5 1.2 .8 .5\nSPHERE 1 .4 -1.3 -.5 1\nBOX 2 -3 -1.5 -3 6 .2 6\n";

    fn scene() -> Box<Scene<Board64K>> {
        let mut scene: Box<Scene<Board64K>> = Box::default();
        parse(SCENE, &mut scene, &mut |e| panic!("{e}")).unwrap();
        scene
    }

    /// The direct order's panel and its counters (but the cells, which a
    /// remembered shadow blocker makes depend on the order).
    fn direct<L: Linked>(renderer: &mut Renderer<'_, L>) -> (Vec<Option<Rgb888>>, [u64; 3]) {
        let mut panel = Panel::new(renderer.size());
        let stats = renderer.render(&mut panel).unwrap();
        (panel.pixels, [stats.rays, stats.shadow_rays, stats.truncated])
    }

    crate::profile! {
        /// Board64K's room, camera rays finding their hits in screen lists.
        struct Listed {
            spheres: 320, boxes: 32, superquadrics: 32, triangles: 96, rectangles: 96,
            bspline_triangles: 32, control_points: 16, surfaces: 64, lights: 8,
            objects: 512, octree_boxes: 2048, octree_references: 6144,
        }
        first_hits: true
    }

    #[test]
    fn one_core_and_two_cores_draw_the_direct_picture() {
        use crate::accel::{LightBuffer, Linked, OctreeStore, SceneAccelerator};
        let scene = scene();
        let view = scene.view();
        let mut octree = Box::new(<Listed as Linked>::Octree::EMPTY);
        octree.build(&view, &Listed::OCTREE);
        let (octree, naive) = (
            SceneAccelerator::<Listed>::new(Some(&*octree), LightBuffer::NONE),
            SceneAccelerator::<Listed>::new(None, LightBuffer::NONE),
        );
        // 150 wide: runs of more blocks than a single core traces at once.
        for (w, h) in [(29, 19), (16, 16), (3, 11), (40, 7), (150, 6)] {
            let mut bounds = vec![crate::render::ScreenBound::EMPTY; view.object_count()];
            let mut positions = vec![0; crate::render::ScreenBound::positions_for(view.object_count())];
            let mut listed = Renderer::with_size(view, &octree, w, h).unwrap();
            listed.set_first_hits((&mut bounds, &mut positions), None);
            let mut naive = Renderer::with_size(view, &naive, w, h).unwrap();
            let expected = direct(&mut naive);
            assert_eq!(direct(&mut listed), expected);
            for coarsest in [1, 2, 4, 16] {
                for finest in [1, 2, 4] {
                    let order = Progressive::new(Size::new(w, h), coarsest).with_finest(finest);
                    // One core, both accelerators.
                    let mut panel = Panel::new(order.size());
                    let stats = order.render(&mut naive, &mut panel).unwrap();
                    assert_eq!((panel.pixels, [stats.rays, stats.shadow_rays, stats.truncated]), expected, "{order:?}");
                    // The same rectangles as from handed-over colours, but
                    // where a run of blocks is cut for the stack buffer.
                    let handed_over: usize = sent_by_pass(&order).iter().map(|pass| pass.0).sum();
                    assert!(panel.rectangles == handed_over || w > 2 * CHUNK_BLOCKS as u32, "{order:?}");
                    assert!(panel.rectangles >= handed_over, "{order:?}");
                    let mut panel = Panel::new(order.size());
                    order.render(&mut listed, &mut panel).unwrap();
                    assert_eq!(panel.pixels, expected.0, "{order:?} with first hits");
                    // Two cores: units dealt out in turn, one core drawing.
                    let mut panel = Panel::new(order.size());
                    let mut slots = [
                        vec![Rgb888::new(0, 0, 0); order.max_unit_pixels()],
                        vec![Rgb888::new(0, 0, 0); order.max_unit_pixels()],
                    ];
                    let before = [naive.stats(), listed.stats()];
                    for (index, unit) in order.units().enumerate() {
                        let traced = match index % 2 {
                            0 => unit.trace(&mut naive, &mut slots[0]).unwrap().colors().len(),
                            _ => unit.trace(&mut listed, &mut slots[1]).unwrap().colors().len(),
                        };
                        assert_eq!(traced, unit.pixel_count());
                        unit.with_colors(&slots[index % 2]).unwrap().draw(&mut panel).unwrap();
                    }
                    assert_eq!(panel.pixels, expected.0, "{order:?} on two cores");
                    let rays = naive.stats().since(&before[0]).rays + listed.stats().since(&before[1]).rays;
                    assert_eq!(rays, expected.1[0], "{order:?} on two cores: every pixel traced once");
                }
            }
        }
    }

    #[test]
    fn a_short_buffer_or_another_size_is_an_error() {
        let scene = scene();
        let order = Progressive::new(Size::new(12, 10), 4);
        let naive = crate::accel::SceneAccelerator::<Board64K>::new(None, crate::accel::LightBuffer::NONE);
        let mut renderer = Renderer::with_size(scene.view(), &naive, 12, 10).unwrap();
        let unit = order.units().last().unwrap();
        assert_eq!(unit.pixel_count(), 6 + 12);
        let mut short = [Rgb888::new(0, 0, 0); 17];
        let error = unit.trace(&mut renderer, &mut short).unwrap_err();
        assert_eq!(error, ProgressiveError::Buffer { pixels: 18, room: 17 });
        assert_eq!(unit.with_colors(&short).unwrap_err(), error);
        assert_eq!(
            std::format!("{error}"),
            "a unit of 18 pixels does not fit a colour buffer of 17 (Progressive::max_unit_pixels sizes it)"
        );
        assert_eq!(renderer.stats().rays, 0, "nothing traced");
        let mut other = Renderer::with_size(scene.view(), &naive, 12, 11).unwrap();
        let error = order.render(&mut other, &mut Panel::new(Size::new(12, 11))).unwrap_err();
        assert_eq!(error, ProgressiveError::Size { renderer: [12, 11], order: [12, 10] });
        assert_eq!(std::format!("{error}"), "the renderer traces 12×11 pixels, the progressive order is for 12×10");
        assert_eq!(
            unit.trace(&mut other, &mut [Rgb888::new(0, 0, 0); 18]).unwrap_err(),
            ProgressiveError::Size { renderer: [12, 11], order: [12, 10] }
        );
    }

    #[test]
    fn block_sides_are_powers_of_two_within_the_image_limits() {
        let size = Size::new(20, 20);
        assert_eq!(Progressive::new(size, 12).coarsest(), 8);
        assert_eq!(Progressive::new(size, 0).coarsest(), 1);
        assert_eq!(Progressive::new(size, u32::MAX).coarsest(), MAX_SIDE);
        assert_eq!(Progressive::new(size, 8).with_finest(3).finest(), 2);
        assert_eq!(Progressive::new(size, 8).with_finest(64).finest(), 8);
        assert_eq!(Progressive::new(Size::new(u32::MAX, 3), 8).size(), Size::new(MAX_SIDE, 3));
        // Coarsest 1: the direct order, a row a unit.
        let direct = Progressive::new(size, 1);
        assert_eq!((direct.passes(), direct.unit_count()), (1, 20));
        assert!(direct.units().all(|unit| unit.rows().len() == 1 && unit.pixel_count() == 20));
        assert_eq!(Progressive::new(Size::zero(), 16).units().count(), 0);
    }
}
