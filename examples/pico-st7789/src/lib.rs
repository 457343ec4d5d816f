//! The board behind octrace's Pico firmwares: a Raspberry Pi Pico with a
//! Waveshare Pico-LCD-1.3 panel ([`panel`]), started the same way for each
//! ([`board`]), octrace's picture traced by both of its cores
//! ([`both_cores`]), what each firmware measures of a scene ([`measure`])
//! and its USB serial port ([`usb`]). `src/main.rs` draws a scene embedded
//! at build time, `src/bin/live.rs` the scenes a host sends over USB.
//!
//! Invariants: no heap; every static the firmwares need is theirs, handed
//! in, so that each sizes its own from its capacity profile.

#![no_std]

pub mod bank_stack;
pub mod board;
pub mod both_cores;
pub mod measure;
pub mod panel;
pub mod sram_code;
pub mod usb;
