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
pub mod output;
pub mod parts;
pub mod studio;
mod terminal;
mod threaded;

use threaded::stream_threads;

pub use octrace_images::{RgbImage, NO_OBJECT};

use octrace_core::accel::{BuildReport, Indexing, LightBufferReport, OctreeConfig};
use octrace_core::parse::{imagefile, ParseError};
use octrace_core::profile::{Host, Profile};
use octrace_core::scene::{CameraError, SceneView};
use octrace_core::shade::Stats;
use octrace_core::{LoadedScene, Raytracer};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// A scene loaded on the host: the core's [`Raytracer`] holding it, in the
/// host build (a million objects of any mix, heap-backed), as a board's
/// holds its scene. Each render indexes it as its options say and traces
/// the loaded scene, as a board does.
#[derive(Debug)]
pub struct HostScene {
    raytracer: Box<Raytracer<Host>>,
}

impl HostScene {
    /// The scene's objects, surfaces, lights and settings.
    pub fn view(&self) -> SceneView<'_> {
        self.raytracer.view()
    }

    /// The raytracer holding it: for an animation's frames.
    pub(crate) fn raytracer(&mut self) -> &mut Raytracer<Host> {
        &mut self.raytracer
    }

    /// The scene indexed as `options` say: its octree and light buffer
    /// built anew (each build timed apart), no parse.
    pub(crate) fn index(&mut self, options: &RenderOptions) -> Indexed<'_> {
        let (mut octree, mut lights) = (Duration::ZERO, Duration::ZERO);
        let scene = self.raytracer.reindex(options.indexing(), |beside, here| {
            let started = Instant::now();
            here();
            octree = started.elapsed();
            let started = Instant::now();
            beside();
            lights = started.elapsed();
        });
        let build = scene.octree_report().map(|report| (*report, octree));
        let light_buffer = (scene.light_buffer().report().lights > 0).then(|| (scene.light_buffer().report(), lights));
        Indexed { scene, build, light_buffer }
    }
}

/// A scene indexed for a render, and what building its index took.
pub(crate) struct Indexed<'s> {
    pub scene: LoadedScene<'s, Host>,
    pub build: Option<(BuildReport, Duration)>,
    pub light_buffer: Option<(LightBufferReport, Duration)>,
}

/// A fresh, empty host scene.
pub fn new_scene() -> Box<HostScene> {
    Box::new(HostScene { raytracer: Box::new(Raytracer::new()) })
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
    // Parsed only: each render indexes it as it is asked to.
    let frames = match scene.raytracer.load_frame_with(bytes, frame, AccelMode::Naive, &mut on_error) {
        Ok(loaded) => loaded.frames(),
        Err(_) => return Err(LoadError::Scene(errors)),
    };
    let imagefile = std::str::from_utf8(bytes).ok().and_then(imagefile).map(str::to_owned);
    Ok(Loaded { imagefile, frames })
}

/// Reads and parses the scene file at `path`.
pub fn load_file(path: &Path, scene: &mut HostScene) -> Result<Loaded, LoadError> {
    let bytes = std::fs::read(path).map_err(LoadError::Io)?;
    load_bytes(&path.display().to_string(), &bytes, scene)
}

pub use octrace_core::AccelMode;

/// How the image is cut between threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Partition {
    /// Tiles of 32×32 pixels handed out one at a time from a shared
    /// counter: a thread that finishes early takes the next, so all stay
    /// busy to the end.
    Tiles,
    /// The thesis's parallel mode: four equal rectangles (the image's
    /// quarters), quarter `i` to thread `i mod threads`.
    Equal4,
}

/// The side of a tile in [`Partition::Tiles`]: small enough to balance 2 to
/// 64 threads on a 160×128 image, large enough that handing one out costs
/// nothing next to tracing it.
pub const TILE_SIDE: u32 = 32;

/// How to render.
#[derive(Clone, Copy, Debug)]
pub struct RenderOptions {
    /// Overrides RASTER.
    pub size: Option<(u32, u32)>,
    pub accel: AccelMode,
    /// Subdivision criterion (the traversal follows `accel`).
    pub octree: OctreeConfig,
    /// Threads to render on (at least 1). The image is the same for any
    /// number.
    pub threads: usize,
    pub partition: Partition,
    /// Once set (host-sim's Ctrl-C), a streamed render ([`render_streamed`])
    /// stops before its next ray, inside the pixels it traces, with
    /// [`StreamError::Stopped`]. The renders into memory ([`render`] and
    /// the others) never stop.
    pub stop: Option<&'static AtomicBool>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            size: None,
            accel: AccelMode::Auto,
            octree: OCTREE,
            threads: 1,
            partition: Partition::Tiles,
            stop: None,
        }
    }
}

impl RenderOptions {
    /// How the scene is indexed: the mode, and the octree's criterion.
    pub fn indexing(&self) -> Indexing {
        Indexing { mode: self.accel, octree: Some(self.octree) }
    }
}

/// Every core of this machine (1 if that cannot be told).
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

/// How host-sim builds octrees unless told otherwise: the host profile's
/// config (shadow shafts on).
pub const OCTREE: OctreeConfig = <Host as Profile>::OCTREE;

/// Indexes `scene` as a render in `mode` with the octree `config` does:
/// the octree's build report and the time the build took, when the mode
/// walks one.
pub fn build_octree(scene: &mut HostScene, mode: AccelMode, config: &OctreeConfig) -> Option<(BuildReport, Duration)> {
    let options = RenderOptions { accel: mode, octree: *config, ..RenderOptions::default() };
    scene.index(&options).build
}

/// Renders a loaded scene into a new image, indexed as `options` say.
pub fn render(scene: &mut HostScene, options: &RenderOptions) -> Result<Rendered, CameraError> {
    render_with_progress(scene, options, &|_| {})
}

/// As [`render`], calling `progress(pixels)` (from any thread) each time a
/// piece of the image is done.
pub fn render_with_progress(
    scene: &mut HostScene,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    let (w, h) = options.size.unwrap_or((scene.view().settings.raster[0], scene.view().settings.raster[1]));
    let mut canvas = Canvas::new(w, h);
    // Never stopped (see `RenderOptions::stop`).
    let options = RenderOptions { stop: None, ..*options };
    let streamed = match render_streamed(scene, &options, 0..h, progress, &mut canvas) {
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

/// Receives a streamed render's rows, each once, in order from top to bottom.
pub trait RowSink {
    /// Row `y` (counted in the whole image): RGB triples, and the object
    /// seen through each pixel ([`NO_OBJECT`] for background).
    fn row(&mut self, y: u32, colors: &[u8], objects: &[u32]) -> std::io::Result<()>;
}

/// Why a streamed render stopped.
#[derive(Debug)]
pub enum StreamError {
    /// The camera cannot be set up for the size asked (nothing rendered).
    Camera(CameraError),
    /// The sink refused a row; the render stopped there.
    Sink(std::io::Error),
    /// The render's stop was set ([`RenderOptions::stop`]): it stopped
    /// inside the pixels it traced.
    Stopped,
}

impl std::fmt::Display for StreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StreamError::Camera(e) => write!(f, "cannot set up the camera: {e}"),
            StreamError::Sink(e) => write!(f, "{e}"),
            StreamError::Stopped => f.write_str("the render was stopped"),
        }
    }
}

impl std::error::Error for StreamError {}

/// Renders the rows `rows` of the whole image (`options.size`, else RASTER)
/// on `options.threads` threads and hands them to `sink` in order, holding
/// only a few bands of rows at a time: memory follows the width, not the
/// height. Indexes the scene as `options.accel` and `options.octree` ask
/// first (timed apart from the render).
pub fn render_streamed(
    scene: &mut HostScene,
    options: &RenderOptions,
    rows: std::ops::Range<u32>,
    progress: &(dyn Fn(u64) + Sync),
    sink: &mut dyn RowSink,
) -> Result<Streamed, StreamError> {
    let view = scene.view();
    let (w, h) = options.size.unwrap_or((view.settings.raster[0], view.settings.raster[1]));
    // Set-up errors are found once, before anything is built or started.
    view.check_camera(w, h).map_err(StreamError::Camera)?;
    let rows = rows.start.min(h)..rows.end.min(h);
    let Indexed { scene, build, light_buffer } = scene.index(options);
    let (stats, wall, busy) = stream_threads(scene.share(), (w, h), rows, options, progress, sink)?;
    Ok(Streamed { stats, accel: scene.mode(), build, light_buffer, wall, busy })
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

/// Runs the command line `args` (including the program name); help goes to
/// `stdout`, diagnostics to `stderr`. Returns the process exit code.
pub fn run<I, T>(args: I, stdout: &mut dyn std::io::Write, stderr: &mut dyn std::io::Write) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    cli::run(args, stdout, stderr)
}
