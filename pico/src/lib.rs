//! octrace on a Raspberry Pi Pico (RP2040), what every Pico template needs
//! beside its panel: the start-up ([`board`]: clocks, pins, core 1 waiting
//! for jobs), core 1 as a scoped job runner ([`second_core`]), both cores
//! tracing a picture for one core to present ([`both_cores`]), each on a
//! stack in an SRAM bank of its own ([`bank_stack`]), or playing an
//! animation, only its changed runs drawn ([`animation`]), and what
//! runs before `main`: boot2 and the code copied into SRAM ([`boot!`]);
//! and a delay that sleeps through a panel's set-up ([`sleep`]).
//! Its build-script half, `octrace-pico-build`, embeds the scene, sizes its
//! profile and places the code.
//!
//! Invariants: no heap; every static a firmware needs is the firmware's,
//! handed in, so that each sizes its own from its capacity profile; the
//! library takes no pin and no peripheral but those [`board::start`] uses
//! to start the chip.

#![no_std]

pub mod animation;
pub mod bank_stack;
pub mod board;
pub mod boot;
pub mod both_cores;
pub mod second_core;
pub mod sleep;
