//! octrace's images on the host and in the browser: an RGB image that is an
//! embedded-graphics `DrawTarget`, the thesis's image files (PNG, Targa, Sun
//! raster), its 256-colour displays and the colours a panel shows.
//!
//! host-sim and the studio's WebAssembly module both build on this crate,
//! so a file written by one reads in the other and a palette maps the same
//! pixels to the same indices in both.
//!
//! Invariants: reading a file never panics, whatever its bytes (a malformed
//! file is a [`formats::FormatError`]); nothing here depends on a command
//! line or a page.
//!
//! ```
//! use octrace_images::formats::{self, Format, Image};
//! use octrace_images::RgbImage;
//!
//! let image = Image::Rgb(RgbImage { width: 2, height: 1, data: vec![255, 0, 0, 0, 0, 255] });
//! let mut bytes = Vec::new();
//! formats::write(&image, Format::Tga, &mut bytes)?;
//! assert_eq!(formats::read(&bytes)?, image);
//! # Ok::<(), formats::FormatError>(())
//! ```

#![forbid(unsafe_code)]

pub mod formats;
pub mod palette;
pub mod panel;
mod rgb_image;
mod sample_image;

pub use rgb_image::RgbImage;
pub use sample_image::SampleImage;

/// What an object buffer holds for a pixel that shows the background: the
/// object buffers beside a render hold each pixel's `ObjectId`, or this.
pub const NO_OBJECT: u32 = u32::MAX;
