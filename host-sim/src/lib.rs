//! octrace on the desktop: load a scene file, render it with the same core
//! code a board runs, write a PNG. The binary is a thin wrapper around
//! [`run`], so tests drive exactly what a user runs.

pub mod cli;
pub mod formats;
pub mod image;
pub mod palette;

pub use image::RgbImage;

use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::RgbColor;
use embedded_graphics_core::primitives::Rectangle;
use octrace_core::accel::{Accelerator, BuildReport, Mailbox, Naive, Octree, OctreeConfig, Traversal};
use octrace_core::parse::{parse_bytes, ParseError};
use octrace_core::profile::Host;
use octrace_core::render::{Renderer, Tiles};
use octrace_core::scene::{CameraError, Scene, SceneView};
use octrace_core::shade::Stats;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
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
}

/// Parses scene `text` (bytes, UTF-8 checked) into `scene`; errors are
/// formatted with `name` in front.
pub fn load_bytes(name: &str, bytes: &[u8], scene: &mut HostScene) -> Result<Loaded, LoadError> {
    let mut errors = Vec::new();
    let mut on_error = |e: ParseError<'_>| errors.push(format!("{name}:{e}"));
    match parse_bytes(bytes, scene, &mut on_error) {
        Ok(parsed) => Ok(Loaded { imagefile: parsed.imagefile.map(str::to_owned) }),
        Err(_) => Err(LoadError::Scene(errors)),
    }
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
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            size: None,
            accel: AccelMode::Auto,
            octree: OctreeConfig::default(),
            threads: 1,
            partition: Partition::Tiles,
        }
    }
}

/// Every core of this machine (1 if that cannot be told).
pub fn all_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// What [`Rendered::objects`] holds for a pixel that shows the background.
pub const NO_OBJECT: u32 = u32::MAX;

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
    /// Wall-clock time of the render (without building the octree).
    pub wall: Duration,
    /// For each thread, the time it spent rendering; `wall − busy` is the
    /// time it stood idle while others worked.
    pub busy: Vec<Duration>,
}

/// The host's octree.
pub type HostOctree = Octree<Host>;

/// Builds the acceleration structure for `mode` (none for naive).
pub fn build_octree(scene: &HostScene, mode: AccelMode, config: &OctreeConfig) -> Option<Box<HostOctree>> {
    let traversal = mode.resolve(scene.view().object_count()).traversal()?;
    let mut octree: Box<HostOctree> = Box::default();
    octree.build(&scene.view(), &OctreeConfig { traversal, ..*config });
    Some(octree)
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
    let accel = options.accel.resolve(scene.view().object_count());
    let started = Instant::now();
    let octree = build_octree(scene, accel, &options.octree);
    let build = octree.as_ref().map(|o| (*o.report(), started.elapsed()));
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
    // Set-up errors are found once, before any thread starts.
    Renderer::with_size(view, &Naive, w, h)?;
    let (accel, job) = match octree {
        None => (AccelMode::Naive, render_threads(view, &Naive, (w, h), options, progress)),
        Some(tree) => {
            let mode = if tree.traversal() == Traversal::Named { AccelMode::Octree } else { AccelMode::Dda };
            (mode, render_threads(view, tree, (w, h), options, progress))
        }
    };
    let (image, objects, stats, wall, busy) = job;
    Ok(Rendered { image, objects, stats, accel, build: None, wall, busy })
}

/// The pieces of the image in the order they are handed out.
fn pieces(size: Size, partition: Partition) -> Vec<Rectangle> {
    match partition {
        Partition::Tiles => Tiles::new(size, TILE_SIDE).iter().collect(),
        Partition::Equal4 => {
            let (w, h) = (size.width, size.height);
            let (left, top) = (w / 2, h / 2);
            [(0, 0, left, top), (left, 0, w - left, top), (0, top, left, h - top), (left, top, w - left, h - top)]
                .into_iter()
                .map(|(x, y, w, h)| Rectangle::new(Point::new(x as i32, y as i32), Size::new(w, h)))
                .collect()
        }
    }
}

/// The image and the object of every pixel, filled in pieces.
struct Canvas {
    image: RgbImage,
    objects: Vec<u32>,
}

/// Renders on `options.threads` threads, each with its own renderer (and
/// mailbox), into one image.
fn render_threads<A: Accelerator + Sync>(
    view: SceneView<'_>,
    accel: &A,
    (w, h): (u32, u32),
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> (RgbImage, Vec<u32>, Stats, Duration, Vec<Duration>) {
    let threads = options.threads.max(1);
    let pieces = pieces(Size::new(w, h), options.partition);
    let next = AtomicUsize::new(0);
    let canvas = Mutex::new(Canvas { image: RgbImage::new(w, h), objects: vec![NO_OBJECT; w as usize * h as usize] });
    let started = Instant::now();
    let worker = |thread: usize| {
        let began = Instant::now();
        let mut words = vec![0u32; Mailbox::words_for(view.object_count())];
        let Ok(renderer) = Renderer::with_size(view, accel, w, h) else { return (Stats::default(), Duration::ZERO) };
        let mut renderer = renderer.with_mailbox(&mut words);
        let mut piece_index = thread;
        loop {
            let index = match options.partition {
                Partition::Tiles => next.fetch_add(1, Ordering::Relaxed),
                Partition::Equal4 => {
                    piece_index += threads;
                    piece_index - threads
                }
            };
            let Some(piece) = pieces.get(index) else { break };
            let tile = Tile::render(&mut renderer, piece);
            tile.copy_into(&mut canvas.lock().unwrap_or_else(|poisoned| poisoned.into_inner()));
            progress(piece.size.width as u64 * piece.size.height as u64);
        }
        (renderer.stats(), began.elapsed())
    };
    let results: Vec<(Stats, Duration)> = if threads == 1 {
        vec![worker(0)]
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads).map(|t| scope.spawn(move || worker(t))).collect();
            handles.into_iter().map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))).collect()
        })
    };
    let wall = started.elapsed();
    let mut stats = Stats::default();
    for (s, _) in &results {
        stats.add(s);
    }
    let canvas = canvas.into_inner().unwrap_or_else(|poisoned| poisoned.into_inner());
    (canvas.image, canvas.objects, stats, wall, results.into_iter().map(|(_, busy)| busy).collect())
}

/// A rendered piece of the image: colours and objects, row-major.
struct Tile {
    area: Rectangle,
    colors: Vec<u8>,
    objects: Vec<u32>,
}

impl Tile {
    fn render<A: Accelerator>(renderer: &mut Renderer<'_, A>, area: &Rectangle) -> Tile {
        let (x0, y0) = (area.top_left.x as u32, area.top_left.y as u32);
        let count = area.size.width as usize * area.size.height as usize;
        let mut tile = Tile { area: *area, colors: Vec::with_capacity(3 * count), objects: Vec::with_capacity(count) };
        for y in y0..y0 + area.size.height {
            for p in renderer.row(y, x0..x0 + area.size.width) {
                tile.colors.extend([p.color.r(), p.color.g(), p.color.b()]);
                tile.objects.push(p.object.map_or(NO_OBJECT, |o| o.0));
            }
        }
        tile
    }

    fn copy_into(&self, canvas: &mut Canvas) {
        let (x0, y0) = (self.area.top_left.x as usize, self.area.top_left.y as usize);
        let (w, image_w) = (self.area.size.width as usize, canvas.image.width as usize);
        for y in 0..self.area.size.height as usize {
            let at = (y0 + y) * image_w + x0;
            canvas.image.data[3 * at..3 * (at + w)].copy_from_slice(&self.colors[3 * y * w..3 * (y + 1) * w]);
            canvas.objects[at..at + w].copy_from_slice(&self.objects[y * w..(y + 1) * w]);
        }
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
