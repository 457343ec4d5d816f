//! octrace on the desktop: load a scene file, render it with the same core
//! code a board runs, write an image file. The binary is a thin wrapper
//! around [`run`], so tests drive exactly what a user runs.
//!
//! Invariants: any number of threads and any partition give the same bits;
//! a streamed render ([`render_streamed`]) holds a few bands of rows, never
//! the image, and hands every row to its sink once, in order.

pub mod animation;
mod arguments;
pub mod board;
pub mod cli;
pub mod exit;
mod options;
pub mod output;
pub mod parts;
pub mod studio;
mod terminal;
mod threaded;

use threaded::stream_threads;

pub use cli::run;
pub use octrace_images::{RgbImage, NO_OBJECT};

use octrace_core::accel::{
    self, Accelerator, BuildReport, LightBuffer, LightBufferReport, LightBufferStore, LightBuffered, Naive, Octree,
    OctreeConfig, Traversal,
};
use octrace_core::parse::{parse_frame_bytes, ParseError};
use octrace_core::profile::Host;
use octrace_core::profile::Profile;
use octrace_core::scene::{CameraError, Scene};
use octrace_core::shade::Stats;
use std::path::Path;
use std::time::{Duration, Instant};

/// The host build's scene: a million objects of any mix, heap-backed.
pub type HostScene = Scene<Host>;

/// A fresh, empty host scene.
pub fn new_scene() -> Box<HostScene> {
    Box::new(Scene::new())
}

/// Why a scene could not be loaded.
#[derive(Debug)]
pub enum LoadError {
    /// The file could not be read.
    Io(std::io::Error),
    /// The scene has errors, each formatted `file:line:col: message`.
    Scene(Vec<String>),
}

impl std::fmt::Display for LoadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LoadError::Io(e) => write!(f, "{e}"),
            LoadError::Scene(errors) => f.write_str(&errors.join("\n")),
        }
    }
}

/// What loading a scene produced besides the scene itself.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Loaded {
    /// The scene's IMAGEFILE, if any.
    pub imagefile: Option<String>,
    /// Its FRAMES, if it is an animation.
    pub frames: Option<octrace_core::scene::Frames>,
}

/// Parses scene `text` (bytes, UTF-8 checked) into `scene`; errors are
/// formatted with `name` in front.
pub fn load_bytes(name: &str, bytes: &[u8], scene: &mut HostScene) -> Result<Loaded, LoadError> {
    load_frame_bytes(name, bytes, 0, scene)
}

/// [`load_bytes`] of frame `frame` of an animation (a scene with FRAMES).
pub fn load_frame_bytes(name: &str, bytes: &[u8], frame: u32, scene: &mut HostScene) -> Result<Loaded, LoadError> {
    let mut errors = Vec::new();
    let mut on_error = |e: ParseError<'_>| errors.push(format!("{name}:{e}"));
    match parse_frame_bytes(bytes, scene, frame, &mut on_error) {
        Ok(parsed) => Ok(Loaded { imagefile: parsed.imagefile.map(str::to_owned), frames: parsed.frames }),
        Err(_) => Err(LoadError::Scene(errors)),
    }
}

/// Reads and parses the scene file at `path`.
pub fn load_file(path: &Path, scene: &mut HostScene) -> Result<Loaded, LoadError> {
    let bytes = std::fs::read(path).map_err(LoadError::Io)?;
    load_bytes(&path.display().to_string(), &bytes, scene)
}

pub use octrace_core::AccelMode;
pub use options::{Partition, RenderOptions, RowSink, StreamError, LIGHT_BUFFER, OCTREE, TILE_SIDE};

/// A light buffer's words on the host (heap-backed, as large as the
/// buffer).
pub type HostLightBuffer = LightBufferStore<<Host as Profile>::LightBufferWords>;

pub fn all_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// A finished render.
pub struct Rendered {
    pub image: RgbImage,
    /// The object seen through each pixel (its centre sample), row-major;
    /// [`NO_OBJECT`] for background.
    pub objects: Vec<u32>,
    pub stats: Stats,
    /// The mode actually used (never `Auto`).
    pub accel: AccelMode,
    /// The octree's build report and time, when one was built.
    pub build: Option<(BuildReport, std::time::Duration)>,
    /// The light buffer's report and build time, when one was built.
    pub light_buffer: Option<(LightBufferReport, Duration)>,
    /// Wall-clock time of the render (without building the octree).
    pub wall: Duration,
    /// For each thread, the time it spent rendering; `wall − busy` is the
    /// time it stood idle while others worked.
    pub busy: Vec<Duration>,
}

/// The host's octree.
pub type HostOctree = Octree<Host>;

/// Builds the octree `mode` walks (none for the naive mode), as the core
/// chooses it ([`octrace_core::accel::prepare`]).
pub fn build_octree(scene: &HostScene, mode: AccelMode, config: &OctreeConfig) -> Option<Box<HostOctree>> {
    let mut octree: Box<HostOctree> = Box::default();
    accel::prepare(mode, &scene.view(), &mut *octree, config).report.map(|_| octree)
}

/// The octree `options` ask for, with its build report and the time the
/// build took.
fn timed_octree(
    scene: &HostScene,
    options: &RenderOptions,
) -> (Option<Box<HostOctree>>, Option<(BuildReport, Duration)>) {
    let started = Instant::now();
    let octree = build_octree(scene, options.accel, &options.octree);
    let build = octree.as_ref().map(|o| (*o.report(), started.elapsed()));
    (octree, build)
}

/// Renders a loaded scene into a new image.
pub fn render(scene: &HostScene, options: &RenderOptions) -> Result<Rendered, CameraError> {
    render_with_progress(scene, options, &|_| {})
}

/// As [`render`], calling `progress(pixels)` (from any thread) each time a
/// piece of the image is done.
pub fn render_with_progress(
    scene: &HostScene,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    let (octree, build) = timed_octree(scene, options);
    let mut rendered = render_prebuilt(scene, options, octree.as_deref(), progress)?;
    rendered.build = build;
    Ok(rendered)
}

/// Renders with an octree built beforehand (`None`: the naive mode);
/// `options.accel` and `options.octree` are not used.
pub fn render_prebuilt(
    scene: &HostScene,
    options: &RenderOptions,
    octree: Option<&HostOctree>,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    let view = scene.view();
    let (w, h) = options.size.unwrap_or((view.settings.raster[0], view.settings.raster[1]));
    let mut canvas = Canvas::new(w, h);
    // Never stopped (see `RenderOptions::stop`).
    let options = RenderOptions { stop: None, ..*options };
    let streamed = match stream_prebuilt(scene, &options, octree, 0..h, progress, &mut canvas) {
        Ok(s) => s,
        Err(StreamError::Camera(e)) => return Err(e),
        // The canvas takes every row, and nothing stops the render.
        Err(e @ (StreamError::Sink(_) | StreamError::Stopped)) => unreachable!("a render into memory failed: {e}"),
    };
    let Streamed { stats, accel, build, light_buffer, wall, busy } = streamed;
    Ok(Rendered { image: canvas.image, objects: canvas.objects, stats, accel, build, light_buffer, wall, busy })
}

/// What a streamed render reports; its rows went to a [`RowSink`].
#[derive(Clone, Debug)]
pub struct Streamed {
    pub stats: Stats,
    /// The mode actually used (never `Auto`).
    pub accel: AccelMode,
    /// The octree's build report and time, when one was built.
    pub build: Option<(BuildReport, Duration)>,
    /// The light buffer's report and build time, when one was built.
    pub light_buffer: Option<(LightBufferReport, Duration)>,
    /// Wall-clock time of the render (without building the octree).
    pub wall: Duration,
    /// For each thread, the time it spent tracing.
    pub busy: Vec<Duration>,
}

impl Streamed {
    /// The time spent tracing: building the octree and the light buffer
    /// plus every thread's time rendering pixels, without the encoder's
    /// time or idle waits. With one thread this is what POV-Ray calls its
    /// trace time.
    pub fn tracing(&self) -> Duration {
        self.build.map_or(Duration::ZERO, |(_, built)| built)
            + self.light_buffer.map_or(Duration::ZERO, |(_, built)| built)
            + self.busy.iter().sum::<Duration>()
    }
}

/// Renders the rows `rows` of the whole image (`options.size`, else RASTER)
/// on `options.threads` threads and hands them to `sink` in order, holding
/// only a few bands of rows at a time: memory follows the width, not the
/// height. Builds the octree `options.accel` asks for first.
pub fn render_streamed(
    scene: &HostScene,
    options: &RenderOptions,
    rows: std::ops::Range<u32>,
    progress: &(dyn Fn(u64) + Sync),
    sink: &mut dyn RowSink,
) -> Result<Streamed, StreamError> {
    let (octree, build) = timed_octree(scene, options);
    let mut streamed = stream_prebuilt(scene, options, octree.as_deref(), rows, progress, sink)?;
    streamed.build = build;
    Ok(streamed)
}

fn stream_prebuilt(
    scene: &HostScene,
    options: &RenderOptions,
    octree: Option<&HostOctree>,
    rows: std::ops::Range<u32>,
    progress: &(dyn Fn(u64) + Sync),
    sink: &mut dyn RowSink,
) -> Result<Streamed, StreamError> {
    let view = scene.view();
    let (w, h) = options.size.unwrap_or((view.settings.raster[0], view.settings.raster[1]));
    // Set-up errors are found once, before any thread starts.
    view.check_camera(w, h).map_err(StreamError::Camera)?;
    let rows = rows.start.min(h)..rows.end.min(h);
    // The light buffer, unless the naive mode is asked for by name.
    let started = Instant::now();
    let mut store = HostLightBuffer::new();
    let cells = if options.accel == AccelMode::Naive { 0 } else { options.light_buffer };
    let lights = (cells > 0).then(|| store.build(&view, cells));
    let light_buffer = lights.map(|lights| (lights.report(), started.elapsed()));
    let (accel, job) = match octree {
        None => (AccelMode::Naive, stream_lit(view, &Naive, lights, (w, h), rows, options, progress, sink)),
        Some(tree) => {
            let mode = if tree.walked_by() == Traversal::Named { AccelMode::Octree } else { AccelMode::Dda };
            (mode, stream_lit(view, tree, lights, (w, h), rows, options, progress, sink))
        }
    };
    let (stats, wall, busy) = job?;
    Ok(Streamed { stats, accel, build: None, light_buffer, wall, busy })
}

/// [`stream_threads`] with `accel`, and `lights` in front of its shadow
/// rays if there is one (an empty buffer otherwise, so that the tracer is
/// compiled once per accelerator: twice, it no longer inlines the naive
/// mode's loop, 3 % more instructions on fig5_1).
#[allow(clippy::too_many_arguments)]
fn stream_lit<A: Accelerator + Sync>(
    view: octrace_core::scene::SceneView<'_>,
    accel: &A,
    lights: Option<LightBuffer<'_>>,
    size: (u32, u32),
    rows: std::ops::Range<u32>,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
    sink: &mut dyn RowSink,
) -> Result<(Stats, Duration, Vec<Duration>), StreamError> {
    let lit = LightBuffered::new(accel, lights.unwrap_or(LightBuffer::NONE));
    stream_threads(view, &lit, size, rows, options, progress, sink)
}

/// The image and the object of every pixel, filled row by row.
pub(crate) struct Canvas {
    pub(crate) image: RgbImage,
    objects: Vec<u32>,
}

impl Canvas {
    /// A black `w` × `h` image, no object seen.
    pub(crate) fn new(w: u32, h: u32) -> Canvas {
        Canvas { image: RgbImage::new(w, h), objects: vec![NO_OBJECT; w as usize * h as usize] }
    }
}

impl RowSink for Canvas {
    fn row(&mut self, y: u32, colors: &[u8], objects: &[u32]) -> std::io::Result<()> {
        let (w, y) = (self.image.width as usize, y as usize);
        self.image.data[3 * y * w..3 * (y + 1) * w].copy_from_slice(colors);
        self.objects[y * w..(y + 1) * w].copy_from_slice(objects);
        Ok(())
    }
}
