//! octrace on the desktop: load a scene file, render it with the same core
//! code a board runs, write a PNG. The binary is a thin wrapper around
//! [`run`], so tests drive exactly what a user runs.

pub mod cli;
pub mod image;

pub use image::RgbImage;

use octrace_core::accel::{BuildReport, Mailbox, Naive, Octree, OctreeConfig, Traversal};
use octrace_core::capacity::Host;
use octrace_core::parse::{parse_bytes, ParseError};
use octrace_core::render::Renderer;
use octrace_core::scene::{CameraError, Scene};
use octrace_core::shade::Stats;
use std::path::Path;

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

/// Which intersection strategy to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AccelMode {
    /// The fastest for the scene: naive for a handful of objects, else dda.
    Auto,
    /// Every object tested for every ray (the thesis's first version).
    Naive,
    /// The thesis's octree walk: Minlen steps and hash-table lookups.
    Octree,
    /// The octree walked with integer 3DDDA.
    Dda,
}

/// Scenes with at most this many objects render fastest without an octree
/// (measured: see BENCHMARKS.md).
pub const NAIVE_UP_TO: usize = 16;

impl AccelMode {
    /// The concrete mode `Auto` stands for on a scene with `objects` objects.
    pub fn resolve(self, objects: usize) -> AccelMode {
        match self {
            AccelMode::Auto if objects <= NAIVE_UP_TO => AccelMode::Naive,
            AccelMode::Auto => AccelMode::Dda,
            m => m,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            AccelMode::Auto => "auto",
            AccelMode::Naive => "naive",
            AccelMode::Octree => "octree",
            AccelMode::Dda => "dda",
        }
    }
}

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Overrides RASTER.
    pub size: Option<(u32, u32)>,
    pub accel: AccelMode,
    /// Subdivision criterion (the traversal follows `accel`).
    pub octree: OctreeConfig,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions { size: None, accel: AccelMode::Auto, octree: OctreeConfig::default() }
    }
}

/// A finished render.
pub struct Rendered {
    pub image: RgbImage,
    pub stats: Stats,
    /// The mode actually used (never `Auto`).
    pub accel: AccelMode,
    /// The octree's build report and time, when one was built.
    pub build: Option<(BuildReport, std::time::Duration)>,
}

/// The host's octree.
pub type HostOctree = Octree<Host>;

/// Builds the acceleration structure for `mode` (none for naive).
pub fn build_octree(scene: &HostScene, mode: AccelMode, config: &OctreeConfig) -> Option<Box<HostOctree>> {
    let traversal = match mode.resolve(scene.view().object_count()) {
        AccelMode::Naive | AccelMode::Auto => return None,
        AccelMode::Octree => Traversal::Named,
        AccelMode::Dda => Traversal::Dda,
    };
    let mut octree: Box<HostOctree> = Box::default();
    octree.build(&scene.view(), &OctreeConfig { traversal, ..*config });
    Some(octree)
}

/// Renders a loaded scene into a new image.
pub fn render(scene: &HostScene, options: &RenderOptions) -> Result<Rendered, CameraError> {
    render_with_progress(scene, options, |_| {})
}

/// As [`render`], calling `row_done(y)` after each row.
pub fn render_with_progress(
    scene: &HostScene,
    options: &RenderOptions,
    row_done: impl FnMut(u32),
) -> Result<Rendered, CameraError> {
    let accel = options.accel.resolve(scene.view().object_count());
    let started = std::time::Instant::now();
    let octree = build_octree(scene, accel, &options.octree);
    let build = octree.as_ref().map(|o| (*o.report(), started.elapsed()));
    let mut rendered = render_prebuilt(scene, options.size, octree.as_deref(), row_done)?;
    rendered.build = build;
    Ok(rendered)
}

/// Renders with an octree built beforehand (`None`: the naive mode).
pub fn render_prebuilt(
    scene: &HostScene,
    size: Option<(u32, u32)>,
    octree: Option<&HostOctree>,
    mut row_done: impl FnMut(u32),
) -> Result<Rendered, CameraError> {
    let view = scene.view();
    let [w, h] = size.map_or(view.settings.raster, |(w, h)| [w, h]);
    let accel = match octree.map(|o| o.traversal()) {
        None => AccelMode::Naive,
        Some(Traversal::Named) => AccelMode::Octree,
        Some(Traversal::Dda) => AccelMode::Dda,
    };
    let mut image = RgbImage::new(w, h);
    let mut stats = Stats::default();
    let mut words = vec![0u32; Mailbox::words_for(view.object_count())];
    let mut rows = |renderer: &mut dyn FnMut(u32, &mut RgbImage) -> Stats| {
        for y in 0..h {
            stats.add(&renderer(y, &mut image));
            row_done(y);
        }
    };
    match octree {
        None => {
            let mut r = Renderer::with_size(view, &Naive, w, h)?;
            rows(&mut |y, img| r.render_rows(y..y + 1, img).unwrap_or_else(|never| match never {}));
        }
        Some(tree) => {
            let mut r = Renderer::with_size(view, tree, w, h)?.with_mailbox(&mut words);
            rows(&mut |y, img| r.render_rows(y..y + 1, img).unwrap_or_else(|never| match never {}));
        }
    }
    Ok(Rendered { image, stats, accel, build: None })
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
