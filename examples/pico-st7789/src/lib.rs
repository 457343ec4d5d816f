//! The board behind octrace's ST7789 firmwares: a Raspberry Pi Pico with a
//! Waveshare Pico-LCD-1.3 panel ([`panel`]), started, core 1 waiting for
//! jobs and both cores tracing (each on a stack in an SRAM bank of its own)
//! by `octrace-pico`, which every Pico template shares; what each firmware
//! measures of a scene ([`measure`]) and its USB serial port ([`usb`]).
//! `src/main.rs` draws a scene embedded at build time, `src/bin/live.rs`
//! the scenes a host sends over USB.
//!
//! Invariants: no heap; every static the firmwares need is theirs, handed
//! in, so that each sizes its own from its capacity profile.

#![no_std]

pub mod measure;
pub mod panel;
pub mod usb;
