//! Where a streamed render's rows go: a [`RowSink`], and why a stream
//! stopped; the [`Canvas`] that keeps them all in memory.
//!
//! Invariants: a sink gets every row once, in order from top to bottom.

use octrace_core::scene::CameraError;
use octrace_images::{RgbImage, NO_OBJECT};

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
    /// The render's stop was set ([`RenderOptions::stop`](crate::RenderOptions::stop)): it stopped
    /// inside the pixels it traced.
    Stopped,
}

impl std::fmt::Display for StreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StreamError::Camera(e) => write!(f, "cannot set up the camera: {e}"),
            StreamError::Sink(e) => write!(f, "{e}"),
            StreamError::Stopped => f.write_str("the render was stopped"),
        }
    }
}

impl std::error::Error for StreamError {}

/// The image and the object of every pixel, filled row by row.
pub(crate) struct Canvas {
    pub(crate) image: RgbImage,
    pub(crate) objects: Vec<u32>,
}

impl Canvas {
    /// A black `w` × `h` image, no object seen.
    pub(crate) fn new(w: u32, h: u32) -> Canvas {
        Canvas { image: RgbImage::new(w, h), objects: vec![NO_OBJECT; w as usize * h as usize] }
    }
}

impl RowSink for Canvas {
    fn row(&mut self, y: u32, colors: &[u8], objects: &[u32]) -> std::io::Result<()> {
        let (w, y) = (self.image.width as usize, y as usize);
        self.image.data[3 * y * w..3 * (y + 1) * w].copy_from_slice(colors);
        self.objects[y * w..(y + 1) * w].copy_from_slice(objects);
        Ok(())
    }
}
