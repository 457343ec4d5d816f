//! A scene on the host: the core's raytracer holding it, loaded from a file
//! or bytes, and indexed as a render's options say.
//!
//! Invariants: a scene with errors leaves nothing loaded; an index is built
//! anew for each render, each build timed apart.

use crate::exit::ShownPath;
use crate::options::RenderOptions;
use octrace_core::accel::{BuildReport, LightBufferReport};
use octrace_core::parse::{imagefile, ParseError};
use octrace_core::profile::Host;
use octrace_core::scene::SceneView;
use octrace_core::{AccelMode, LoadedScene, Raytracer};
use std::path::Path;
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
    /// The scene's IMAGEFILE, if any, and where its statement stands.
    pub imagefile: Option<(String, octrace_core::parse::Pos)>,
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
    let imagefile = std::str::from_utf8(bytes).ok().and_then(imagefile).map(|(name, pos)| (name.to_owned(), pos));
    Ok(Loaded { imagefile, frames })
}

/// The most host-sim reads of a scene file: five times the fifty megabytes
/// of comment the hostile-input tests parse in a second or two. A device
/// read as a scene (`/dev/zero`) ends there, not when memory does.
pub const MAX_SCENE_FILE_BYTES: usize = 256 << 20;

/// The bytes of the scene file at `path`, refused past
/// [`MAX_SCENE_FILE_BYTES`].
pub fn read_scene_file(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?.take(MAX_SCENE_FILE_BYTES as u64 + 1).read_to_end(&mut bytes)?;
    if bytes.len() > MAX_SCENE_FILE_BYTES {
        return Err(std::io::Error::other(format!(
            "it is larger than {} MiB, the most host-sim reads as a scene",
            MAX_SCENE_FILE_BYTES >> 20
        )));
    }
    Ok(bytes)
}

/// Reads and parses the scene file at `path`.
pub fn load_file(path: &Path, scene: &mut HostScene) -> Result<Loaded, LoadError> {
    let bytes = read_scene_file(path).map_err(LoadError::Io)?;
    load_bytes(&ShownPath(path).to_string(), &bytes, scene)
}
