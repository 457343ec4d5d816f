//! octrace-core in the browser: the studio page's WebAssembly module. It
//! parses scene text (any frame of an animation), renders any rectangle of
//! the image with the very same core host-sim uses, plays an animation's
//! frames re-tracing only what moved (`player`, the core's coherence), maps finished images through the palette modes and
//! panel colours of `octrace-images`, and reads and writes its image files
//! (host-sim's, as host-sim uses the same crate).
//!
//! Invariants: the module holds one scene at a time; nothing here uses
//! floating point on the render path; the page talks to it only through the
//! plain `extern "C"` functions in [`exports`] and two byte buffers (input
//! and output) in linear memory, so no Rust code dereferences a pointer the
//! page hands it.

#![deny(unsafe_code)]

mod error;
mod exports;
mod player;
mod studio;

pub use error::StudioError;
pub use studio::{accel_from_code, Display, Loaded, Studio};
