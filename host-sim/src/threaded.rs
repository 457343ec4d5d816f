//! The threaded streaming render: worker threads take pieces of the image
//! (tiles of a band of rows, or the thesis's four rectangles) from a shared
//! counter, each drawing the scene's image area by area (`areas`: one
//! renderer a thread, in a room of its own), and a window of bands collects them
//! so that rows reach the sink in order, holding only a bounded number of
//! bands in memory.
//!
//! Invariants: every piece is rendered once; a band is handed to the sink
//! only when all its pieces are in, and bands in order; a panicking worker
//! is counted out so the writer never waits for it; once the render's stop
//! is set (Ctrl-C), every worker stops before its next ray, inside a pixel,
//! and no band after is written.

use crate::options::{Partition, RenderOptions, TILE_SIDE};
use crate::rows::{RowSink, StreamError};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Point, Size};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::profile::Host;
use octrace_core::render::{PixelSample, Tiles};
use octrace_core::shade::Stats;
use octrace_core::{DrawError, RendererRoom, SharedScene};
use octrace_images::{SampleImage, NO_OBJECT};
use std::cell::{Cell, RefCell};
use std::sync::atomic::Ordering;
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// A piece of the image one thread renders at a time, and the band of rows
/// it belongs to.
#[derive(Clone, Copy, Debug)]
struct Piece {
    band: usize,
    area: Rectangle,
}

/// The bands of `rows` (each a range of rows) and their pieces in the order
/// they are handed out: bands of [`TILE_SIDE`] rows cut into tiles, or for
/// [`Partition::Equal4`] one band, the thesis's four rectangles.
fn bands(width: u32, rows: &std::ops::Range<u32>, partition: Partition) -> (Vec<std::ops::Range<u32>>, Vec<Piece>) {
    let rectangle = |x: u32, y: u32, w: u32, h: u32| Rectangle::new(Point::new(x as i32, y as i32), Size::new(w, h));
    match partition {
        Partition::Tiles => {
            // The core's tiles of the rows as an image of their own, in
            // raster order: a band is a row of tiles.
            let bands: Vec<_> =
                rows.clone().step_by(TILE_SIDE as usize).map(|y| y..(y + TILE_SIDE).min(rows.end)).collect();
            let tiles = Tiles::new(Size::new(width, rows.len() as u32), TILE_SIDE);
            let offset = Point::new(0, rows.start as i32);
            let pieces = tiles
                .iter()
                .map(|t| Piece {
                    band: t.top_left.y as usize / TILE_SIDE as usize,
                    area: Rectangle::new(t.top_left + offset, t.size),
                })
                .collect();
            (bands, pieces)
        }
        Partition::Equal4 => {
            let (left, top, height) = (width / 2, rows.start + rows.len() as u32 / 2, rows.len() as u32);
            let top_height = top - rows.start;
            let quarters = [
                (0, rows.start, left, top_height),
                (left, rows.start, width - left, top_height),
                (0, top, left, height - top_height),
                (left, top, width - left, height - top_height),
            ];
            let pieces = quarters.into_iter().map(|(x, y, w, h)| Piece { band: 0, area: rectangle(x, y, w, h) });
            (vec![rows.clone()], pieces.collect())
        }
    }
}

/// A band of rows being filled: colours and objects, row-major.
struct Slot {
    band: usize,
    colors: Vec<u8>,
    objects: Vec<u32>,
    /// Pieces of the band not yet copied in.
    remaining: usize,
}

/// What the threads of a streamed render share.
struct Window {
    /// The next piece to hand out (tiles).
    next: usize,
    /// Bands already given to the sink.
    written: usize,
    slots: Vec<Slot>,
    /// Threads still rendering.
    alive: usize,
    /// The sink failed, or the render's stop was set: stop.
    abort: bool,
}

/// At most this many bytes of bands wait to be written (unless two bands
/// need more): far below the target of 256 MB for a 16384-pixel-wide image.
const WINDOW_BYTES: usize = 64 << 20;

/// Renders `rows` of `scene` on `options.threads` threads, each with its
/// own renderer in a room of its own (mailbox, screen lists), as a board's
/// other cores do: threads take pieces of the bands in order, at most a
/// window of bands ahead of the oldest one not yet written, while this
/// thread hands finished bands to `sink` in order. `options.stop`, once
/// set, stops every thread inside the pixel it traces.
pub(crate) fn stream_threads(
    scene: SharedScene<'_, Host>,
    (w, h): (u32, u32),
    rows: std::ops::Range<u32>,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
    sink: &mut dyn RowSink,
) -> Result<(Stats, Duration, Vec<Duration>), StreamError> {
    let threads = options.threads.max(1);
    let (bands, pieces) = bands(w, &rows, options.partition);
    let mut pieces_in_band = vec![0usize; bands.len()];
    pieces.iter().for_each(|p| pieces_in_band[p.band] += 1);
    let band_bytes = bands.first().map_or(0, |b| b.len()) * w as usize * 7;
    let window = (2 * threads).max(4).min((WINDOW_BYTES / band_bytes.max(1)).max(2));
    let slot = |band: usize, mut colors: Vec<u8>, mut objects: Vec<u32>| {
        let pixels = bands[band].len() * w as usize;
        colors.resize(3 * pixels, 0);
        objects.resize(pixels, NO_OBJECT);
        Slot { band, colors, objects, remaining: pieces_in_band[band] }
    };
    let slots = (0..window.min(bands.len())).map(|band| slot(band, Vec::new(), Vec::new())).collect();
    let shared = Mutex::new(Window { next: 0, written: 0, slots, alive: threads, abort: false });
    let changed = Condvar::new();
    let lock = || shared.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let started = Instant::now();
    let worker = |thread: usize| {
        // Counts this thread out even if it panics, so the writer stops waiting.
        struct Leaving<'a, F: Fn() -> std::sync::MutexGuard<'a, Window>>(&'a F, &'a Condvar);
        impl<'a, F: Fn() -> std::sync::MutexGuard<'a, Window>> Drop for Leaving<'a, F> {
            fn drop(&mut self) {
                (self.0)().alive -= 1;
                self.1.notify_all();
            }
        }
        let _leaving = Leaving(&lock, &changed);
        let room = RendererRoom::<Host>::new();
        // The piece being drawn, filled by the draw; handed to its band
        // when the draw asks for the next (it asks only once a piece is
        // whole), so that an empty piece is handed too.
        let tile: RefCell<Option<Tile>> = RefCell::new(None);
        let waited = Cell::new(Duration::ZERO);
        // Equal4 hands the thesis's rectangles out statically.
        let own_next = Cell::new(thread);
        let next = || -> Option<Rectangle> {
            let began = Instant::now();
            let mut state = lock();
            if let Some(done) = tile.borrow_mut().take() {
                let slot = &mut state.slots[done.band % window];
                done.copy_into(slot, bands[done.band].start, w);
                slot.remaining -= 1;
                if slot.remaining == 0 {
                    changed.notify_all();
                }
                drop(state);
                progress(done.area.size.width as u64 * done.area.size.height as u64);
                state = lock();
            }
            let piece = loop {
                let index = match options.partition {
                    Partition::Tiles => state.next,
                    Partition::Equal4 => own_next.get(),
                };
                let piece = match pieces.get(index) {
                    Some(p) if !state.abort => *p,
                    _ => break None,
                };
                if piece.band < state.written + window {
                    match options.partition {
                        Partition::Tiles => state.next += 1,
                        Partition::Equal4 => own_next.set(own_next.get() + threads),
                    }
                    break Some(piece);
                }
                state = changed.wait(state).unwrap_or_else(|poisoned| poisoned.into_inner());
            };
            drop(state);
            *tile.borrow_mut() = piece.map(Tile::new);
            waited.set(waited.get() + began.elapsed());
            piece.map(|p| p.area)
        };
        let mut target = TileTarget { tile: &tile, size: Size::new(w, h) };
        let image = scene.image::<PixelSample>(&room, Size::new(w, h)).areas(&next);
        let started = Instant::now();
        let drawn = match options.stop {
            None => image.try_draw(&mut target),
            Some(stop) => image.try_draw_until(&mut target, &mut || stop.load(Ordering::Relaxed)),
        };
        let busy = started.elapsed().saturating_sub(waited.get());
        match drawn {
            Ok(stats) => (stats, busy),
            // Stopped inside a piece: the others stop at their next ask.
            Err(DrawError::Stopped) => {
                lock().abort = true;
                changed.notify_all();
                (Stats::default(), busy)
            }
            // A camera that cannot be set up: the scene's load refused it.
            Err(_) => (Stats::default(), busy),
        }
    };
    let stopped = || options.stop.is_some_and(|stop| stop.load(Ordering::Relaxed));
    let mut writer = || -> Result<(), StreamError> {
        for (band, ys) in bands.iter().enumerate() {
            let mut state = lock();
            let index = band % window;
            while state.slots[index].band != band || state.slots[index].remaining > 0 {
                if state.abort && stopped() {
                    return Err(StreamError::Stopped);
                }
                if state.alive == 0 {
                    // A thread died (its panic is raised when the scope ends).
                    let stopped = std::io::Error::other("the render stopped before the image was complete");
                    return Err(StreamError::Sink(stopped));
                }
                state = changed.wait(state).unwrap_or_else(|poisoned| poisoned.into_inner());
            }
            let colors = std::mem::take(&mut state.slots[index].colors);
            let objects = std::mem::take(&mut state.slots[index].objects);
            drop(state);
            let width = w as usize;
            let result = ys.clone().enumerate().try_for_each(|(i, y)| {
                sink.row(y, &colors[3 * i * width..3 * (i + 1) * width], &objects[i * width..(i + 1) * width])
            });
            let mut state = lock();
            if let Err(e) = result {
                state.abort = true;
                changed.notify_all();
                return Err(StreamError::Sink(e));
            }
            state.slots[index] = if band + window < bands.len() {
                slot(band + window, colors, objects)
            } else {
                Slot { band: usize::MAX, colors: Vec::new(), objects: Vec::new(), remaining: 0 }
            };
            state.written = band + 1;
            changed.notify_all();
        }
        Ok(())
    };
    let (written, results) = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads).map(|t| scope.spawn(move || worker(t))).collect();
        let written = writer();
        let results: Vec<(Stats, Duration)> =
            handles.into_iter().map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))).collect();
        (written, results)
    });
    written?;
    let wall = started.elapsed();
    let mut stats = Stats::default();
    for (s, _) in &results {
        stats.add(s);
    }
    Ok((stats, wall, results.into_iter().map(|(_, busy)| busy).collect()))
}

/// A piece of the image as it is drawn: colours and objects, row-major.
struct Tile {
    band: usize,
    area: Rectangle,
    colors: Vec<u8>,
    objects: Vec<u32>,
}

impl Tile {
    /// Room for `piece`'s pixels.
    fn new(piece: Piece) -> Tile {
        let count = piece.area.size.width as usize * piece.area.size.height as usize;
        Tile { band: piece.band, area: piece.area, colors: vec![0; 3 * count], objects: vec![NO_OBJECT; count] }
    }

    /// Copies the tile into the band starting at row `top` of an image
    /// `width` pixels wide.
    fn copy_into(&self, slot: &mut Slot, top: u32, width: u32) {
        let (x0, y0) = (self.area.top_left.x as usize, self.area.top_left.y as usize - top as usize);
        let (w, image_w) = (self.area.size.width as usize, width as usize);
        for y in 0..self.area.size.height as usize {
            let at = (y0 + y) * image_w + x0;
            slot.colors[3 * at..3 * (at + w)].copy_from_slice(&self.colors[3 * y * w..3 * (y + 1) * w]);
            slot.objects[at..at + w].copy_from_slice(&self.objects[y * w..(y + 1) * w]);
        }
    }
}

/// A thread's draw target: each pixel into the tile being drawn, at its
/// place there (the draw hands it only the pixels of that tile's area).
struct TileTarget<'t> {
    tile: &'t RefCell<Option<Tile>>,
    size: Size,
}

impl OriginDimensions for TileTarget<'_> {
    fn size(&self) -> Size {
        self.size
    }
}

impl TileTarget<'_> {
    /// Runs `draw` on the tile being drawn, as an image of its own, with
    /// where its top-left pixel lies in the picture (nothing without one).
    fn in_tile(&self, draw: impl FnOnce(&mut SampleImage<'_>, Point)) {
        if let Some(tile) = self.tile.borrow_mut().as_mut() {
            let at = tile.area.top_left;
            draw(&mut SampleImage { colours: &mut tile.colors, objects: &mut tile.objects, size: tile.area.size }, at);
        }
    }
}

impl DrawTarget for TileTarget<'_> {
    type Color = PixelSample;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<PixelSample>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        self.in_tile(|image, at| {
            let Ok(()) = image.draw_iter(pixels.into_iter().map(|Pixel(p, sample)| Pixel(p - at, sample)));
        });
        Ok(())
    }

    fn fill_contiguous<I: IntoIterator<Item = PixelSample>>(
        &mut self,
        area: &Rectangle,
        samples: I,
    ) -> Result<(), Self::Error> {
        self.in_tile(|image, at| {
            let Ok(()) = image.fill_contiguous(&Rectangle::new(area.top_left - at, area.size), samples);
        });
        Ok(())
    }
}
