//! octrace on the desktop: load a scene file, render it with the same core
//! code a board runs, write a PNG. The binary is a thin wrapper around
//! [`run`], so tests drive exactly what a user runs.

pub mod cli;
pub mod image;

pub use image::RgbImage;

use octrace_core::accel::Naive;
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

/// Renders a loaded scene into a new image (`size` overrides RASTER).
pub fn render(scene: &HostScene, size: Option<(u32, u32)>) -> Result<(RgbImage, Stats), CameraError> {
    render_with_progress(scene, size, |_| {})
}

/// As [`render`], calling `row_done(y)` after each row.
pub fn render_with_progress(
    scene: &HostScene,
    size: Option<(u32, u32)>,
    mut row_done: impl FnMut(u32),
) -> Result<(RgbImage, Stats), CameraError> {
    let view = scene.view();
    let [w, h] = size.map_or(view.settings.raster, |(w, h)| [w, h]);
    let mut renderer = Renderer::with_size(view, &Naive, w, h)?;
    let mut image = RgbImage::new(w, h);
    let mut stats = Stats::default();
    for y in 0..h {
        match renderer.render_rows(y..y + 1, &mut image) {
            Ok(s) => stats.add(&s),
            Err(never) => match never {},
        }
        row_done(y);
    }
    Ok((image, stats))
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
