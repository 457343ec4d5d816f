#![no_std]
#![forbid(unsafe_code)]

pub mod math;
pub mod shapes;
