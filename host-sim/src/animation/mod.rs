//! Animations on the desktop: every frame of a scene with `FRAMES` loaded
//! and traced in turn, each after the first re-tracing only the tiles the
//! motion can change (the core's [`Coherence`]) on every thread, then
//! written as an animated GIF (`gif.rs`, its colours from `quantize/`), an
//! APNG (`apng.rs`), both storing only what each frame changed
//! (`changes.rs`), or one image file a frame (`writers.rs`).
//!
//! Invariants: a frame's image is the frame traced whole, bit for bit
//! (the core's coherence is exact; `--no-coherence` traces every pixel);
//! any number of threads gives the same bits; the frames reach the writer
//! in order, each once.

mod apng;
mod changes;
mod command;
mod gif;
mod quantize;
mod writers;

pub use apng::ApngWriter;
pub use changes::Area;
pub use command::{animate, is_frame_file, merge_frames, Request};
pub use gif::{gif_delay, GifWriter};
pub use writers::{FrameInfo, FramePattern, Output};

use crate::{build_octree, HostLightBuffer, HostScene, RenderOptions, RgbImage, NO_OBJECT};
use embedded_graphics_core::geometry::Size;
use embedded_graphics_core::pixelcolor::RgbColor;
use octrace_core::accel::{Accelerator, LightBuffer, LightBuffered, Mailbox, Naive};
use octrace_core::animation::{Coherence, Key, Motion, RunSink, Track};
use octrace_core::parse::{parse_frame_bytes, ParseError};
use octrace_core::render::{PixelSample, Renderer, ScreenBound};
use octrace_core::scene::{Frames, SceneView};
use octrace_core::shade::Stats;
use octrace_core::AccelMode;
use std::sync::atomic::{AtomicU32, AtomicU8, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The side of the tiles whose pixels are re-traced together: chosen by
/// measurement (BENCHMARKS.md, "Animation").
pub const COHERENCE_TILE: u32 = 4;

/// One frame's image: its colours and the object seen through each pixel.
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
    /// The scene has errors at this frame, each `line:col: message`.
    Scene { frame: u32, errors: Vec<String> },
    /// The camera cannot be set up for the size asked, or the motion not
    /// read: the message says why.
    Setup(String),
    /// The frames' writer failed.
    Write(std::io::Error),
}

/// How to render an animation's frames.
#[derive(Clone, Copy, Debug)]
pub struct AnimationOptions {
    pub render: RenderOptions,
    /// Re-trace only what can change (false: every frame whole).
    pub coherence: bool,
}

/// Renders frames `frames` of the animation `bytes` (a scene with FRAMES:
/// `count` of them), handing each to `each` in order; `progress(pixels)`
/// after each band traced.
pub fn render_frames(
    bytes: &[u8],
    count: Frames,
    frames: std::ops::Range<u32>,
    options: &AnimationOptions,
    progress: &(dyn Fn(u64) + Sync),
    each: &mut dyn FnMut(u32, &FrameImage) -> std::io::Result<()>,
) -> Result<AnimationReport, AnimationError> {
    let mut report = AnimationReport::default();
    let mut scene = crate::new_scene();
    let mut current: Option<FrameImage> = None;
    // The size, the tiles' counts and the motion (its storage), from the
    // first frame.
    load(bytes, frames.start, &mut scene)?;
    let raster = scene.view().settings.raster;
    let (w, h) = options.render.size.unwrap_or((raster[0], raster[1]));
    let counts: Vec<AtomicU8> = (0..Coherence::tiles_for(w, h, COHERENCE_TILE)).map(|_| AtomicU8::new(0)).collect();
    let coherence =
        Coherence::new(&counts, Size::new(w, h), COHERENCE_TILE).map_err(|e| AnimationError::Setup(e.to_string()))?;
    let text = std::str::from_utf8(bytes).unwrap_or_default();
    let needs = Motion::needs(text);
    let (mut tracks, mut keys, mut table) =
        (vec![Track::EMPTY; needs.tracks], vec![Key::default(); needs.keys], vec![[0; 3]; needs.displacements]);
    let motion = match options.coherence {
        true => Some(
            Motion::read(text, count, &scene.view(), frames.start, &mut tracks, &mut keys, &mut table)
                .map_err(|e| AnimationError::Setup(e.to_string()))?,
        ),
        false => None,
    };
    for frame in frames {
        let started = Instant::now();
        load(bytes, frame, &mut scene)?;
        let view = scene.view();
        view.check_camera(w, h).map_err(|e| AnimationError::Setup(e.to_string()))?;
        let image = current.get_or_insert_with(|| FrameImage {
            image: RgbImage::new(w, h),
            objects: vec![NO_OBJECT; w as usize * h as usize],
            retraced: None,
        });
        let octree = build_octree(&scene, options.render.accel, &options.render.octree);
        let mut lights = HostLightBuffer::new();
        let cells = if options.render.accel == AccelMode::Naive { 0 } else { options.render.light_buffer };
        let lights = if cells > 0 { lights.build(&view, cells) } else { LightBuffer::NONE };
        report.loading += started.elapsed();
        let traced = Instant::now();
        let watched = motion.as_ref();
        if watched.is_some() {
            coherence.plan();
        } else {
            coherence.restart();
        }
        image.retraced = (watched.is_some() && report.frames > 0).then(|| retraced(&coherence));
        report.traced += coherence.traced_pixels();
        let job = Job { view, coherence: &coherence, motion: watched, frame, threads: options.render.threads };
        let stats = match &octree {
            Some(tree) => job.run(&LightBuffered::new(&**tree, lights), image, progress),
            None => job.run(&LightBuffered::new(&Naive, lights), image, progress),
        };
        report.stats.add(&stats);
        if report.frames == 0 {
            report.first_tracing = traced.elapsed();
        }
        report.tracing += traced.elapsed();
        report.frames += 1;
        report.pixels += u64::from(w) * u64::from(h);
        each(frame, image).map_err(AnimationError::Write)?;
    }
    Ok(report)
}

/// The areas of the tiles the planned frame traces: a rectangle a run.
fn retraced(coherence: &Coherence<'_>) -> Vec<Area> {
    let side = coherence.side();
    (0..coherence.bands())
        .flat_map(|band| coherence.runs(band).map(move |tiles| (band, tiles)))
        .map(|(band, tiles)| Area {
            x: tiles.start * side,
            y: band * side,
            width: (tiles.end - tiles.start) * side,
            height: side,
        })
        .collect()
}

/// Parses frame `frame` of `bytes` into `scene`.
fn load(bytes: &[u8], frame: u32, scene: &mut HostScene) -> Result<(), AnimationError> {
    let mut errors = Vec::new();
    let mut on_error = |e: ParseError<'_>| errors.push(e.to_string());
    match parse_frame_bytes(bytes, scene, frame, &mut on_error) {
        Ok(_) => Ok(()),
        Err(_) => Err(AnimationError::Scene { frame, errors }),
    }
}

/// One frame's tracing, shared by the threads.
struct Job<'a> {
    view: SceneView<'a>,
    coherence: &'a Coherence<'a>,
    /// The motion, when tracing with coherence (else every tile whole).
    motion: Option<&'a Motion<'a>>,
    frame: u32,
    threads: usize,
}

impl Job<'_> {
    /// Traces the planned tiles into `image` on the threads, each taking
    /// the next band not yet taken.
    fn run<A: Accelerator + Sync>(&self, accel: &A, image: &mut FrameImage, progress: &(dyn Fn(u64) + Sync)) -> Stats {
        let (w, side) = (image.image.width as usize, self.coherence.side() as usize);
        // Each band's rows, to be written by the thread that traces it.
        let bands: Vec<Mutex<(&mut [u8], &mut [u32])>> =
            image.image.data.chunks_mut(3 * w * side).zip(image.objects.chunks_mut(w * side)).map(Mutex::new).collect();
        let next = AtomicU32::new(0);
        let worker = || {
            let objects = self.view.object_count();
            let mut words = vec![0u32; Mailbox::words_for(objects)];
            let mut bounds = vec![ScreenBound::EMPTY; objects];
            let mut positions = vec![0; ScreenBound::positions_for(objects)];
            let size = self.coherence.size();
            let Ok(renderer) = Renderer::with_size(self.view, accel, size.width, size.height) else {
                return Stats::default();
            };
            let mut renderer = renderer.with_mailbox(&mut words).with_first_hits(&mut bounds, &mut positions);
            loop {
                let band = next.fetch_add(1, Ordering::Relaxed);
                let Some(rows) = bands.get(band as usize) else { break };
                let pixels = self.coherence.band_pixels(band);
                let mut rows = rows.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
                let (colors, objects) = &mut *rows;
                let top = band as usize * side;
                let mut write = |line: &embedded_graphics_core::primitives::Rectangle,
                                 pixels: &mut dyn Iterator<Item = PixelSample>|
                 -> Result<(), std::convert::Infallible> {
                    let (x0, y) = (line.top_left.x as usize, line.top_left.y as usize - top);
                    for (i, p) in pixels.enumerate() {
                        let at = y * w + x0 + i;
                        colors[3 * at..3 * at + 3].copy_from_slice(&[p.color.r(), p.color.g(), p.color.b()]);
                        objects[at] = p.object.map_or(NO_OBJECT, |o| o.0);
                    }
                    Ok(())
                };
                let traced = match self.motion {
                    Some(motion) => self.coherence.trace_band(&mut renderer, motion, self.frame, band, &mut write),
                    None => whole_band(&mut renderer, self.coherence, band, &mut write).map(|()| Stats::default()),
                };
                let Ok(_) = traced;
                progress(pixels);
            }
            renderer.stats()
        };
        let mut stats = Stats::default();
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..self.threads.max(1)).map(|_| scope.spawn(worker)).collect();
            for handle in handles {
                let s = handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
                stats.add(&s);
            }
        });
        stats
    }
}

/// Band `band` traced whole, without the lookout's cost: a frame of
/// `--no-coherence`.
fn whole_band<A: Accelerator>(
    renderer: &mut Renderer<'_, A>,
    coherence: &Coherence<'_>,
    band: u32,
    each: &mut RunSink<'_, std::convert::Infallible>,
) -> Result<(), std::convert::Infallible> {
    use embedded_graphics_core::geometry::{Point, Size};
    let (side, size) = (coherence.side(), coherence.size());
    for y in band * side..((band + 1) * side).min(size.height) {
        let line =
            embedded_graphics_core::primitives::Rectangle::new(Point::new(0, y as i32), Size::new(size.width, 1));
        each(&line, &mut renderer.row(y, 0..size.width))?;
    }
    Ok(())
}
