//! Why a picture could not be drawn: the one error of every draw of a
//! loaded scene or a frame ([`TracedImage`](super::TracedImage)).

use crate::panel::ErrorRowTooShort;
use crate::render::Stopped;
use crate::scene::{CameraError, MAX_SIDE};
use core::fmt;

/// Why a [`TracedImage`](super::TracedImage) was not drawn whole.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawError<E> {
    /// The camera cannot be set up for this size (see [`CameraError`]).
    Camera(CameraError),
    /// Error diffusion has no room for the image's rows (an image wider
    /// than [`IMAGE_ERROR_WORDS`](crate::panel::IMAGE_ERROR_WORDS) allows, drawn without
    /// [`TracedImage::error_rows`](super::TracedImage::error_rows)).
    ErrorRow(ErrorRowTooShort),
    /// The display's own error.
    Target(E),
    /// The caller's stop said so ([`TracedImage::try_draw_until`](super::TracedImage::try_draw_until)).
    Stopped,
    /// The image is wider or higher than [`MAX_SIDE`] pixels (a display
    /// of that size, given to `image_for`): nothing is drawn.
    TooLarge {
        /// The image's width, in pixels.
        width: u32,
        /// Its height.
        height: u32,
    },
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
            DrawError::TooLarge { width, height } => {
                write!(f, "an image of {width}×{height} pixels: its sides are at most {MAX_SIDE}")
            }
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for DrawError<E> {}
