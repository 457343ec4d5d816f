//! Why a studio operation could not be done: the one error every export
//! reports to the page.

use octrace_images::formats;
use std::fmt;

/// Why an operation could not be done.
#[derive(Debug)]
pub enum StudioError {
    /// The scene text has errors, each `line:col: message`.
    Scene(Vec<String>),
    /// No scene is loaded.
    NoScene,
    /// The camera cannot be set up or the size is out of range.
    Camera(String),
    /// A buffer does not hold what the call needs.
    BadInput(&'static str),
    /// An image file could not be read or written.
    Image(formats::FormatError),
    /// An animation's frames cannot be traced one from another: why.
    Motion(String),
}

impl fmt::Display for StudioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StudioError::Scene(errors) => f.write_str(&errors.join("\n")),
            StudioError::NoScene => f.write_str("no scene is loaded"),
            StudioError::Camera(why) => write!(f, "cannot set up the camera: {why}"),
            StudioError::BadInput(what) => write!(f, "bad input: {what}"),
            StudioError::Image(e) => write!(f, "{e}"),
            StudioError::Motion(why) => write!(f, "cannot play the animation: {why}"),
        }
    }
}

impl std::error::Error for StudioError {}
