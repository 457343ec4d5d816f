//! What every table shares: timings, the scenes measured, and the error
//! that stops the tables.
//!
//! Invariants: a timing is the best of its runs (the least disturbed by the
//! machine's neighbours); nothing here prints.

use host_sim::{load_file, new_scene, HostScene, LoadError};
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The best of `runs` timings of `f`.
pub(crate) fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut best = Duration::MAX;
    let mut last = None;
    for _ in 0..runs {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed());
        last = Some(r);
    }
    (best, last.expect("at least one run"))
}

/// A duration in milliseconds, as the tables print it.
pub(crate) fn ms(d: Duration) -> String {
    format!("{:.1} ms", d.as_secs_f64() * 1e3)
}

/// The still scenes in `dir`, by name.
pub(crate) fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> =
        std::fs::read_dir(dir).map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect()).unwrap_or_default();
    // The stills: the animations (`anim_*`) have a table of their own.
    v.retain(|p| {
        p.extension().is_some_and(|x| x == "txt")
            && !p.file_stem().is_some_and(|s| s.to_string_lossy().starts_with("anim_"))
    });
    v.sort();
    v
}

/// Why octrace-bench stopped before its tables were done.
#[derive(Debug)]
pub(crate) enum BenchError {
    /// A table it does not know was asked for, and the names it knows.
    UnknownTable { name: String, known: Vec<&'static str> },
    /// A scene it measures did not load.
    Scene { path: PathBuf, error: LoadError },
    /// A tool it runs, or a file it writes, failed: what and why.
    Tool(String),
}

impl BenchError {
    /// The process's exit code: 1 for a file that cannot be read, 2 for the
    /// rest (as host-sim's).
    pub(crate) fn exit_code(&self) -> i32 {
        match self {
            BenchError::Scene { error: LoadError::Io(_), .. } => host_sim::exit::EXIT_IO,
            _ => host_sim::exit::EXIT_SCENE,
        }
    }
}

impl fmt::Display for BenchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BenchError::UnknownTable { name, known } => {
                write!(
                    f,
                    "octrace-bench: unknown table `{name}` (known: {}; --help says what each measures)",
                    known.join(", ")
                )
            }
            BenchError::Scene { path, error: LoadError::Io(e) } => {
                write!(f, "octrace-bench: cannot read {}: {e}", path.display())
            }
            BenchError::Scene { path, error } => write!(f, "{error}\noctrace-bench: {} does not load", path.display()),
            BenchError::Tool(message) => write!(f, "octrace-bench: {message}"),
        }
    }
}

impl std::error::Error for BenchError {}

/// The scene at `path`, loaded.
pub(crate) fn load(path: &Path) -> Result<Box<HostScene>, BenchError> {
    let mut scene = new_scene();
    load_file(path, &mut scene).map_err(|error| BenchError::Scene { path: path.to_owned(), error })?;
    Ok(scene)
}
