//! octrace on the desktop: load a scene file, render it with the same core
//! code a board runs, write an image file. The binary is a thin wrapper
//! around [`run`], so tests drive exactly what a user runs.
//!
//! Invariants: any number of threads and any partition give the same bits;
//! a streamed render ([`render_streamed`]) holds a few bands of rows, never
//! the image, and hands every row to its sink once, in order.

pub mod cli;
pub mod exit;
pub mod formats;
pub mod image;
pub mod output;
pub mod palette;
pub mod parts;
pub mod studio;

pub use image::RgbImage;

use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::RgbColor;
use embedded_graphics_core::primitives::Rectangle;
use octrace_core::accel::{Accelerator, BuildReport, Mailbox, Naive, Octree, OctreeConfig, Traversal};
use octrace_core::parse::{parse_bytes, ParseError};
use octrace_core::profile::Host;
use octrace_core::render::{Renderer, ScreenBound, Tiles};
use octrace_core::scene::{CameraError, Scene, SceneView};
use octrace_core::shade::Stats;
use std::path::Path;
use std::sync::{Condvar, Mutex};
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
        RenderOptions { size: None, accel: AccelMode::Auto, octree: OCTREE, threads: 1, partition: Partition::Tiles }
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

/// How host-sim builds octrees unless told otherwise: the host profile's
/// config (shadow shafts on).
pub const OCTREE: OctreeConfig = <Host as octrace_core::profile::Profile>::OCTREE;

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
    let mut canvas = Canvas { image: RgbImage::new(w, h), objects: vec![NO_OBJECT; w as usize * h as usize] };
    let streamed = match stream_prebuilt(scene, options, octree, 0..h, progress, &mut canvas) {
        Ok(s) => s,
        Err(StreamError::Camera(e)) => return Err(e),
        // The canvas takes every row.
        Err(StreamError::Sink(e)) => unreachable!("a canvas refused a row: {e}"),
    };
    let Streamed { stats, accel, build, wall, busy } = streamed;
    Ok(Rendered { image: canvas.image, objects: canvas.objects, stats, accel, build, wall, busy })
}

/// What a streamed render reports; its rows went to a [`RowSink`].
#[derive(Clone, Debug)]
pub struct Streamed {
    pub stats: Stats,
    /// The mode actually used (never `Auto`).
    pub accel: AccelMode,
    /// The octree's build report and time, when one was built.
    pub build: Option<(BuildReport, Duration)>,
    /// Wall-clock time of the render (without building the octree).
    pub wall: Duration,
    /// For each thread, the time it spent tracing.
    pub busy: Vec<Duration>,
}

impl Streamed {
    /// The time spent tracing: building the octree plus every thread's
    /// time rendering pixels, without the encoder's time or idle waits.
    /// With one thread this is what POV-Ray calls its trace time.
    pub fn tracing(&self) -> Duration {
        self.build.map_or(Duration::ZERO, |(_, built)| built) + self.busy.iter().sum::<Duration>()
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
}

impl std::fmt::Display for StreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StreamError::Camera(e) => write!(f, "cannot set up the camera: {e}"),
            StreamError::Sink(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for StreamError {}

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
    let accel = options.accel.resolve(scene.view().object_count());
    let started = Instant::now();
    let octree = build_octree(scene, accel, &options.octree);
    let build = octree.as_ref().map(|o| (*o.report(), started.elapsed()));
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
    Renderer::with_size(view, &Naive, w, h).map_err(StreamError::Camera)?;
    let rows = rows.start.min(h)..rows.end.min(h);
    let (accel, job) = match octree {
        None => (AccelMode::Naive, stream_threads(view, &Naive, (w, h), rows, options, progress, sink)),
        Some(tree) => {
            let mode = if tree.walked_by() == Traversal::Named { AccelMode::Octree } else { AccelMode::Dda };
            (mode, stream_threads(view, tree, (w, h), rows, options, progress, sink))
        }
    };
    let (stats, wall, busy) = job.map_err(StreamError::Sink)?;
    Ok(Streamed { stats, accel, build: None, wall, busy })
}

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
    /// The sink failed: stop.
    abort: bool,
}

/// At most this many bytes of bands wait to be written (unless two bands
/// need more): far below the target of 256 MB for a 16384-pixel-wide image.
const WINDOW_BYTES: usize = 64 << 20;

/// Renders `rows` on `options.threads` threads, each with its own renderer
/// (and mailbox): threads take pieces of the bands in order, at most a
/// window of bands ahead of the oldest one not yet written, while this
/// thread hands finished bands to `sink` in order.
fn stream_threads<A: Accelerator + Sync>(
    view: SceneView<'_>,
    accel: &A,
    (w, h): (u32, u32),
    rows: std::ops::Range<u32>,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
    sink: &mut dyn RowSink,
) -> std::io::Result<(Stats, Duration, Vec<Duration>)> {
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
        let mut busy = Duration::ZERO;
        let mut words = vec![0u32; Mailbox::words_for(view.object_count())];
        let Ok(renderer) = Renderer::with_size(view, accel, w, h) else { return (Stats::default(), busy) };
        let mut bounds = vec![ScreenBound::EMPTY; view.object_count()];
        let mut positions = vec![0; ScreenBound::positions_for(view.object_count())];
        let mut renderer = renderer.with_mailbox(&mut words).with_first_hits(&mut bounds, &mut positions);
        // Equal4 hands the thesis's rectangles out statically.
        let mut own_next = thread;
        loop {
            let mut state = lock();
            let piece = loop {
                let index = match options.partition {
                    Partition::Tiles => state.next,
                    Partition::Equal4 => own_next,
                };
                let piece = match pieces.get(index) {
                    Some(p) if !state.abort => *p,
                    _ => return (renderer.stats(), busy),
                };
                if piece.band < state.written + window {
                    match options.partition {
                        Partition::Tiles => state.next += 1,
                        Partition::Equal4 => own_next += threads,
                    }
                    break piece;
                }
                state = changed.wait(state).unwrap_or_else(|poisoned| poisoned.into_inner());
            };
            drop(state);
            let began = Instant::now();
            let tile = Tile::render(&mut renderer, &piece.area);
            busy += began.elapsed();
            let mut state = lock();
            let slot = &mut state.slots[piece.band % window];
            tile.copy_into(slot, bands[piece.band].start, w);
            slot.remaining -= 1;
            if slot.remaining == 0 {
                changed.notify_all();
            }
            drop(state);
            progress(piece.area.size.width as u64 * piece.area.size.height as u64);
        }
    };
    let mut writer = || -> std::io::Result<()> {
        for (band, ys) in bands.iter().enumerate() {
            let mut state = lock();
            let index = band % window;
            while state.slots[index].band != band || state.slots[index].remaining > 0 {
                if state.alive == 0 {
                    // A thread died (its panic is raised when the scope ends).
                    return Err(std::io::Error::other("the render stopped before the image was complete"));
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
            if result.is_err() {
                state.abort = true;
                changed.notify_all();
                return result;
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

/// The image and the object of every pixel, filled row by row.
struct Canvas {
    image: RgbImage,
    objects: Vec<u32>,
}

impl RowSink for Canvas {
    fn row(&mut self, y: u32, colors: &[u8], objects: &[u32]) -> std::io::Result<()> {
        let (w, y) = (self.image.width as usize, y as usize);
        self.image.data[3 * y * w..3 * (y + 1) * w].copy_from_slice(colors);
        self.objects[y * w..(y + 1) * w].copy_from_slice(objects);
        Ok(())
    }
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

/// Runs the command line `args` (including the program name); help goes to
/// `stdout`, diagnostics to `stderr`. Returns the process exit code.
pub fn run<I, T>(args: I, stdout: &mut dyn std::io::Write, stderr: &mut dyn std::io::Write) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    cli::run(args, stdout, stderr)
}
