#![no_std]
#![forbid(unsafe_code)]

#[cfg(feature = "alloc")]
extern crate alloc;

pub mod capacity;
pub mod math;
pub mod scene;
pub mod shapes;
