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
pub mod render;
pub mod scene;
pub mod shade;
pub mod shapes;
