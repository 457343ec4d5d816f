//! octrace-core in the browser: the studio page's WebAssembly module. It
//! parses scene text, renders any rectangle of the image with the very same
//! core host-sim uses, maps finished images through host-sim's palette modes
//! and panel colours, and reads and writes host-sim's image files.
//!
//! Invariants: the module holds one scene at a time; nothing here uses
//! floating point on the render path; the page talks to it only through the
//! plain `extern "C"` functions in [`exports`] and two byte buffers (input
//! and output) in linear memory, so no Rust code dereferences a pointer the
//! page hands it.

#![deny(unsafe_code)]

#[path = "../../host-sim/src/formats.rs"]
pub mod formats;
#[path = "../../host-sim/src/image.rs"]
pub mod image;
#[path = "../../host-sim/src/palette.rs"]
pub mod palette;

mod exports;
mod studio;

pub use image::RgbImage;
pub use studio::{accel_from_code, Display, Studio, StudioError};

/// What an object buffer holds for a pixel that shows the background (as
/// host-sim's `NO_OBJECT`).
pub const NO_OBJECT: u32 = u32::MAX;
