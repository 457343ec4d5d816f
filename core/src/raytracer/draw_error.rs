//! Why a picture could not be drawn: one error for every way a loaded
//! scene is drawn ([`TracedImage`](super::TracedImage) and the loaded
//! scene's own draws).

use crate::panel::ErrorRowTooShort;
use crate::render::Stopped;
use crate::scene::CameraError;
use core::fmt;

/// Why a [`TracedImage`] could not be drawn with
/// [`TracedImage::try_draw`].
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawError<E> {
    /// The camera cannot be set up for this size (see [`CameraError`]).
    Camera(CameraError),
    /// Error diffusion has no room for the image's rows (an image wider
    /// than [`IMAGE_ERROR_WORDS`](crate::panel::IMAGE_ERROR_WORDS) allows, drawn without storage of its
    /// own).
    ErrorRow(ErrorRowTooShort),
    /// The display's own error.
    Target(E),
    /// The caller's stop said so
    /// ([`LoadedScene::draw_bands_until`](crate::LoadedScene::draw_bands_until)).
    Stopped,
}

impl<E> From<Stopped> for DrawError<E> {
    fn from(_: Stopped) -> Self {
        DrawError::Stopped
    }
}

impl<E: fmt::Display> fmt::Display for DrawError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DrawError::Camera(e) => write!(f, "{e}"),
            DrawError::ErrorRow(e) => write!(f, "{e}"),
            DrawError::Target(e) => write!(f, "the display failed: {e}"),
            DrawError::Stopped => write!(f, "stopped before the picture's end"),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for DrawError<E> {}
