//! An animation's frames rendered in turn, on threads: each after the first
//! re-tracing only the tiles the motion can change (the core's
//! [`Animation`](octrace_core::animation::Animation)), or every frame whole.
//!
//! Invariants: a frame's image is the frame traced whole, bit for bit;
//! any number of threads gives the same bits; the frames reach the caller
//! in order, each once.

use super::changes::Area;
use crate::options::RenderOptions;
use crate::rows::{RowSink, StreamError};
use crate::scene::{load_frame_bytes, new_scene, LoadError};
use crate::threaded::stream_threads;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Point, Size};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::animation::{Animation, AnimationNeeds, HostAnimationRoom};
use octrace_core::profile::Host;
use octrace_core::render::PixelSample;
use octrace_core::shade::Stats;
use octrace_core::{AnimationError as Refused, DrawError, Frame, Raytracer, RendererRoom};
use octrace_images::{RgbImage, SampleImage, NO_OBJECT};
use std::cell::Cell;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The side of the tiles whose pixels are re-traced together: the core's
/// (chosen by measurement, BENCHMARKS.md, "Animation").
pub const COHERENCE_TILE: u32 = octrace_core::animation::TILE;

/// One frame's image: its colours and the object seen through each pixel,
/// and the rectangles traced for it (the tiles the motion can have changed
/// since the frame before; every pixel for the first frame, or without
/// coherence): outside them the frame is the frame before, bit for bit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameImage {
    pub image: RgbImage,
    /// [`NO_OBJECT`] for background.
    pub objects: Vec<u32>,
    /// The areas traced for this frame, where it can differ from the frame
    /// before (the tiles the coherence re-traced); `None`: anywhere (the
    /// first frame, or every frame traced whole).
    pub retraced: Option<Vec<Area>>,
}

/// What rendering the frames did.
#[derive(Clone, Debug, Default)]
pub struct AnimationReport {
    /// Counters of every trace.
    pub stats: Stats,
    /// Frames rendered.
    pub frames: u32,
    /// Pixels traced, and in all the frames.
    pub traced: u64,
    pub pixels: u64,
    /// Time spent loading frames (parsing and indexing) and tracing them.
    pub loading: Duration,
    pub tracing: Duration,
    /// The first frame's tracing (traced whole).
    pub first_tracing: Duration,
}

/// Why frames could not be rendered.
#[derive(Debug)]
pub enum AnimationError {
    /// The scene has errors at this frame (`None`: found by the check of
    /// every frame's camera, each message naming its frame), each
    /// `line:col: message`.
    Scene { frame: Option<u32>, errors: Vec<String> },
    /// The camera cannot be set up for the size asked, or the animation's
    /// room not made: the message says why.
    Setup(String),
    /// The frames' writer failed.
    Write(std::io::Error),
    /// The render's stop was set (Ctrl-C): nothing more was traced.
    Stopped,
}

/// How to render an animation's frames.
#[derive(Clone, Copy, Debug)]
pub struct AnimationOptions {
    pub render: RenderOptions,
    /// Re-trace only what can change (false: every frame whole).
    pub coherence: bool,
}

/// Whether the animation `bytes` loads at every frame, its camera
/// included: the check [`render_frames`] makes as it loads the first, for
/// a frame asked for alone (a scene is valid or not whichever frame is
/// drawn).
pub fn check_every_frame(bytes: &[u8]) -> Result<(), AnimationError> {
    let mut errors = Vec::new();
    new_scene()
        .raytracer()
        .check_every_frame(bytes, &mut |e| errors.push(e.to_string()))
        .map_err(|e| refused(e, errors))
}

/// Frame 0 of the animation `bytes` loaded into `animation` anew: its
/// motion recorded, which checks every frame's camera (an error there
/// names its frame, so the scene's error has none).
fn load_anew<'a, 'r>(
    animation: &'a mut Animation<'_>,
    raytracer: &'r mut Raytracer<Host>,
    bytes: &[u8],
) -> Result<Frame<'a, 'r, Host>, AnimationError> {
    let mut errors = Vec::new();
    animation.load_with(raytracer, bytes, &mut |e| errors.push(e.to_string())).map_err(|e| refused(e, errors))
}

/// Why frame 0 of an animation was refused, with the scene's `errors`
/// (each at its line and column; those of a camera name their frame).
fn refused(e: Refused<'_>, errors: Vec<String>) -> AnimationError {
    match e {
        Refused::Scene(_) => AnimationError::Scene { frame: None, errors },
        Refused::NoRoom(e) => AnimationError::Setup(e.to_string()),
    }
}

/// Renders frames `frames` of the animation `bytes` (a scene with FRAMES),
/// handing each to `each` in order; `progress(pixels)`
/// after each band traced. Every frame's camera is checked before the
/// first is rendered.
pub fn render_frames(
    bytes: &[u8],
    frames: std::ops::Range<u32>,
    options: &AnimationOptions,
    progress: &(dyn Fn(u64) + Sync),
    each: &mut dyn FnMut(u32, &FrameImage) -> std::io::Result<()>,
) -> Result<AnimationReport, AnimationError> {
    let mut report = AnimationReport::default();
    let mut scene = new_scene();
    let text = std::str::from_utf8(bytes).map_err(|e| AnimationError::Setup(e.to_string()))?;
    // The size from the scene's RASTER, then the motion and the tiles: the
    // animation loaded whole once, every frame checked.
    let raster = match load_frame_bytes("", bytes, frames.start, &mut scene) {
        Ok(_) => scene.view().settings.raster,
        Err(LoadError::Scene(errors)) => return Err(AnimationError::Scene { frame: Some(frames.start), errors }),
        Err(LoadError::Io(e)) => return Err(AnimationError::Setup(e.to_string())),
    };
    let (w, h) = options.render.size.unwrap_or((raster[0], raster[1]));
    let size = Size::new(w, h);
    let mut room = HostAnimationRoom::new(AnimationNeeds::of(text, size));
    let animation = room.animation(size).map_err(|e| AnimationError::Setup(e.to_string()))?;
    let mut animation = animation.indexed(options.render.indexing());
    let first = load_anew(&mut animation, scene.raytracer(), bytes)?;
    first.scene().view().check_camera(w, h).map_err(|e| AnimationError::Setup(e.to_string()))?;
    let mut current: Option<FrameImage> = None;
    for frame in frames {
        if options.render.stop.is_some_and(|stop| stop.load(Ordering::Relaxed)) {
            return Err(AnimationError::Stopped);
        }
        let started = Instant::now();
        let image = current.get_or_insert_with(|| FrameImage {
            image: RgbImage::new(w, h),
            objects: vec![NO_OBJECT; w as usize * h as usize],
            retraced: None,
        });
        let stats = match options.coherence {
            true => {
                let loaded = animation.load(scene.raytracer(), text, frame).map_err(|e| match e {
                    Refused::Scene(e) => AnimationError::Scene { frame: Some(frame), errors: vec![e.to_string()] },
                    Refused::NoRoom(e) => AnimationError::Setup(e.to_string()),
                })?;
                report.loading += started.elapsed();
                let traced = Instant::now();
                // The first frame can differ anywhere.
                image.retraced = (report.frames > 0).then(|| loaded.tiles().traced_areas().map(area).collect());
                report.traced += loaded.tiles().traced_pixels();
                let stats = draw_frame(&loaded, image, &options.render, progress).ok_or(AnimationError::Stopped)?;
                report.tracing += traced.elapsed();
                if report.frames == 0 {
                    report.first_tracing = traced.elapsed();
                }
                stats
            }
            // Every frame whole, as a still: no watching of the motion.
            false => {
                load_frame_bytes("", bytes, frame, &mut scene).map_err(|e| match e {
                    LoadError::Scene(errors) => AnimationError::Scene { frame: Some(frame), errors },
                    LoadError::Io(e) => AnimationError::Setup(e.to_string()),
                })?;
                let indexed = scene.index(&options.render);
                report.loading += started.elapsed();
                let traced = Instant::now();
                image.retraced = None;
                report.traced += u64::from(w) * u64::from(h);
                let rows = 0..h;
                let mut sink = Whole(image);
                let streamed =
                    stream_threads(indexed.scene.share(), (w, h), rows, &options.render, progress, &mut sink);
                report.tracing += traced.elapsed();
                if report.frames == 0 {
                    report.first_tracing = traced.elapsed();
                }
                match streamed {
                    Ok((stats, _, _)) => stats,
                    Err(StreamError::Camera(e)) => return Err(AnimationError::Setup(e.to_string())),
                    Err(StreamError::Sink(e)) => return Err(AnimationError::Write(e)),
                    Err(StreamError::Stopped) => return Err(AnimationError::Stopped),
                }
            }
        };
        report.stats.add(&stats);
        report.frames += 1;
        report.pixels += u64::from(w) * u64::from(h);
        each(frame, image).map_err(AnimationError::Write)?;
    }
    Ok(report)
}

/// A rectangle the coherence re-traced, as the writers take it.
fn area(traced: Rectangle) -> Area {
    let (x, y) = (traced.top_left.x as u32, traced.top_left.y as u32);
    Area { x, y, width: traced.size.width, height: traced.size.height }
}

/// A frame whole, row by row, into its image.
struct Whole<'i>(&'i mut FrameImage);

impl RowSink for Whole<'_> {
    fn row(&mut self, y: u32, colors: &[u8], objects: &[u32]) -> std::io::Result<()> {
        let (w, y) = (self.0.image.width as usize, y as usize);
        self.0.image.data[3 * y * w..3 * (y + 1) * w].copy_from_slice(colors);
        self.0.objects[y * w..(y + 1) * w].copy_from_slice(objects);
        Ok(())
    }
}

/// Draws `frame`'s planned tiles into `image` on `options.threads`
/// threads, each drawing the next band of tiles not yet taken with a
/// renderer of its own (as a board's cores do); `progress(pixels)` after
/// each band. `None` once `options.stop` is set: each thread stops before
/// its next ray.
fn draw_frame(
    frame: &Frame<'_, '_, Host>,
    image: &mut FrameImage,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Option<Stats> {
    let (shared, tiles) = (frame.share(), frame.tiles());
    let (width, side) = (image.image.width as usize, tiles.side() as usize);
    // Each band's rows, written by the thread that draws it.
    let bands: Vec<Mutex<(&mut [u8], &mut [u32])>> = image
        .image
        .data
        .chunks_mut(3 * width * side)
        .zip(image.objects.chunks_mut(width * side))
        .map(Mutex::new)
        .collect();
    let next = AtomicU32::new(0);
    let worker = || {
        let room = RendererRoom::<Host>::new();
        // The band taken last, reported done as the next is taken.
        let last = Cell::new(None);
        let take = || {
            if let Some(band) = last.take() {
                progress(tiles.band_pixels(band));
            }
            let band = next.fetch_add(1, Ordering::Relaxed);
            let band = (band < tiles.bands()).then_some(band);
            last.set(band);
            band
        };
        let mut target = Bands { bands: &bands, width, side, size: tiles.size() };
        let image = shared.image::<PixelSample>(&room, tiles.size()).bands(&take);
        match options.stop {
            Some(stop) => image.try_draw_until(&mut target, &mut || stop.load(Ordering::Relaxed)),
            None => image.try_draw(&mut target),
        }
    };
    let mut stats = Some(Stats::default());
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..options.threads.max(1)).map(|_| scope.spawn(worker)).collect();
        for handle in handles {
            match handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)) {
                Ok(drawn) => stats.iter_mut().for_each(|s| s.add(&drawn)),
                Err(DrawError::Stopped) => stats = None,
                // The camera was checked before the first frame, and the
                // bands' target never fails.
                Err(_) => {}
            }
        }
    });
    stats
}

/// A frame's image as its bands of tiles, each behind a lock: each run of
/// pixels drawn goes to its band's rows.
struct Bands<'b, 'i> {
    bands: &'b [Mutex<(&'i mut [u8], &'i mut [u32])>],
    width: usize,
    side: usize,
    size: Size,
}

impl OriginDimensions for Bands<'_, '_> {
    fn size(&self) -> Size {
        self.size
    }
}

impl DrawTarget for Bands<'_, '_> {
    type Color = PixelSample;
    type Error = std::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<PixelSample>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(at, sample) in pixels {
            let area = Rectangle::new(at, Size::new(1, 1));
            self.fill_contiguous(&area, [sample])?;
        }
        Ok(())
    }

    fn fill_contiguous<I: IntoIterator<Item = PixelSample>>(
        &mut self,
        area: &Rectangle,
        samples: I,
    ) -> Result<(), Self::Error> {
        // A run of one row, in that row's band.
        let y = area.top_left.y.max(0) as usize;
        let Some(band) = self.bands.get(y / self.side) else { return Ok(()) };
        let mut rows = band.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let (colours, objects) = &mut *rows;
        let size = Size::new(self.width as u32, self.side as u32);
        let run = Rectangle::new(Point::new(area.top_left.x, (y % self.side) as i32), area.size);
        SampleImage { colours, objects, size }.fill_contiguous(&run, samples)
    }
}
