//! The build-script half of `octrace-pico`: what a Pico template's
//! `build.rs` does, in three calls. [`embed_scene`] reads the scene
//! `OCTRACE_SCENE` names (else [`DEFAULT_SCENE`]), checks it with the parser the board runs and
//! writes it into `OUT_DIR/scene.rs` with a capacity profile holding
//! exactly what it needs, and says whether it is a still or an animation
//! ([`SceneKind`]); [`link`] puts the RP2040's memory map where the
//! linker finds it and writes each firmware's code placement
//! ([`CodePlacement`], `OCTRACE_CODE_IN`). A board's firmware that draws
//! one still and links by its own memory map (the ESP32-C3's, the Pico
//! 2's) needs [`embed_still_scene`] alone.
//!
//! ```no_run
//! // build.rs of a Pico template
//! use octrace_pico_build::{embed_scene, link, CodePlacement};
//!
//! fn main() {
//!     let placement = CodePlacement::from_env().unwrap_or_else(|e| fail(e));
//!     let scene = embed_scene().unwrap_or_else(|e| fail(e));
//!     link(&[("my-firmware", placement, scene)]).unwrap_or_else(|e| fail(e));
//! }
//!
//! fn fail(error: octrace_pico_build::BuildError) -> ! {
//!     eprintln!("my-firmware: {error}");
//!     std::process::exit(1)
//! }
//! ```
//!
//! Invariants: every file it reads is announced to cargo
//! (`rerun-if-changed`), every variable it reads too (`rerun-if-env-changed`);
//! nothing is written for a scene with errors.

mod placement;
mod scene;

pub use placement::{link, CodePlacement};
pub use scene::{embed_scene, embed_still_scene, SceneKind, DEFAULT_SCENE};

use std::fmt;

/// Why a Pico firmware cannot be built.
#[derive(Debug)]
pub enum BuildError {
    /// A variable's value is not one it takes.
    Variable { name: &'static str, value: String, expected: &'static str },
    /// The scene has errors (each printed with its line and column as it
    /// was found).
    Scene { scene: String, errors: usize },
    /// The scene needs more than the board can hold, refused before
    /// anything is compiled: `needs`, its counts in words; `limit`, which
    /// of the board's bounds it passes, and by how much.
    TooLarge { scene: String, needs: String, limit: String },
    /// A file could not be read or written.
    File { path: String, error: std::io::Error },
    /// A variable cargo sets for a build script is missing.
    NotInBuildScript(&'static str),
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BuildError::Variable { name, value, expected } => write!(f, "{name}={value}: expected {expected}"),
            BuildError::Scene { scene, errors } => {
                write!(f, "{scene}: {errors} error(s); nothing is built from a scene with errors")
            }
            BuildError::TooLarge { scene, needs, limit } => write!(
                f,
                "{scene} is too large for this board: it needs {needs}; {limit}. host-sim renders it, \
                 and a scene of fewer objects fits"
            ),
            BuildError::File { path, error } => write!(f, "{path}: {error}"),
            BuildError::NotInBuildScript(name) => write!(f, "{name} is not set: call this from a build script"),
        }
    }
}

impl std::error::Error for BuildError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            BuildError::File { error, .. } => Some(error),
            _ => None,
        }
    }
}

/// `OUT_DIR`, where the build script's files go.
fn out_dir() -> Result<std::path::PathBuf, BuildError> {
    std::env::var_os("OUT_DIR").map(Into::into).ok_or(BuildError::NotInBuildScript("OUT_DIR"))
}

/// Writes `text` to `path`.
fn write(path: &std::path::Path, text: &str) -> Result<(), BuildError> {
    std::fs::write(path, text).map_err(|error| BuildError::File { path: path.display().to_string(), error })
}
