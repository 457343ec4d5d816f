//! octrace's core: a ray tracer in fixed-point arithmetic for small
//! microcontrollers, `no_std` and allocation-free. A scene is parsed from
//! text ([`parse`]) into fixed-capacity arenas ([`scene`], sized by a
//! [`capacity`] profile), optionally indexed by an octree ([`accel`]), and
//! rendered pixel by pixel ([`render`]) into any embedded-graphics
//! `DrawTarget`, in truecolour or through a 256-colour [`palette`].
//!
//! # No-panic contract
//!
//! For any input text, however malformed or hostile, and any scene the
//! parser accepted:
//!
//! - [`parse::parse`] and [`parse::parse_bytes`] return; they never panic,
//!   never loop, and take time linear in the text's length (plus the
//!   evaluation of `BSPLINE` patches, linear in their generated points). A
//!   scene with errors is left empty.
//! - Building an octree ([`accel::Octree::build`]) returns for any scene; an
//!   arena that runs out leaves boxes unsplit (slower, same image), never a
//!   panic.
//! - Rendering ([`render::Renderer`]) never panics, divides by zero or
//!   overflows silently: fixed-point products are exact in 64 bits, or
//!   saturate where a value can grow (colours, attenuation). The only errors
//!   it returns are the `DrawTarget`'s own.
//! - The API panics only when handed values it did not make: an
//!   [`scene::ObjectId`] from another scene, say.
//!
//! The test suite runs with overflow checks on, so a silent wrap fails it,
//! and the parser and renderer are fuzzed (`fuzz/`).
//!
//! # Worst-case time per pixel
//!
//! Each of the `SAMPLES²` primary rays spawns a ray tree bounded by
//! [`shade::MAX_RAYS_PER_SAMPLE`] rays (4096), however large RDEPTH is; each
//! ray that hits sends one shadow ray per light. So a pixel costs at most
//! `SAMPLES² × 4096 × (1 + lights)` ray queries, and a query at most one
//! intersection test per object (the naive mode; the octree's walk, given a
//! mailbox, tests each object at most once per ray too) plus, with an
//! octree, one step per box crossed. With
//! RDEPTH d and no transparency the tree is a chain: `SAMPLES² × (d + 1) ×
//! (1 + lights)` queries.

#![no_std]
#![forbid(unsafe_code)]
// Per-axis loops index several arrays at once; iterators would obscure them.
#![allow(clippy::needless_range_loop)]

#[cfg(feature = "alloc")]
extern crate alloc;

pub mod accel;
pub mod capacity;
pub mod math;
pub mod palette;
pub mod parse;
pub mod profile;
mod raytracer;
pub mod render;
pub mod scene;
pub mod shade;
pub mod shapes;

pub use accel::AccelMode;
pub use raytracer::{DrawError, LoadError, LoadedScene, Raytracer, TracedImage};
#[cfg(feature = "static-cell")]
pub use static_cell::ConstStaticCell;
