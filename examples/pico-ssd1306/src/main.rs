//! octrace on a Raspberry Pi Pico with a 128×64 SSD1306 OLED: a scene
//! embedded in flash is parsed on the board and traced by both cores into
//! the `ssd1306` crate's buffer in the panel's one-bit look (octrace's
//! dither for a `BinaryColor` display), then sent to the panel over I2C.
//! An animation (`FRAMES` and `MOVE`) plays in a loop, each frame
//! re-tracing only what its motion can change, in ordered dithering (a
//! pixel's dots depend on it alone), the buffer sent after each frame.
//! The Pico's LED is lit while it traces (for an animation, until the
//! frame is on the panel). Pins and wiring are in README.md.
//!
//! Invariants: the scene, its octree and core 0's mailbox live in one
//! static cell, core 1's mailbox and lists in another (all zero bits, so in
//! `.bss`: no flash, no copy on the stack); so do an animation's motion and
//! tiles, sized for this scene by `build.rs` (empty for a still); the image
//! takes the panel's size and colour, and so its look; any split of the
//! rows or tiles between the cores gives the same bits as one core.

#![no_std]
#![no_main]

use core::ops::ControlFlow;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_graphics::prelude::*;
use embedded_hal::digital::OutputPin;
use hal::entry;
use hal::multicore::Stack;
use octrace_core::animation::{AnimationNeeds, AnimationRoom};
use octrace_core::render::Handoff;
use octrace_core::{ConstStaticCell, Raytracer, RendererRoom};
use octrace_pico::animation::{self, Player, Runs};
use octrace_pico::board::{self, Board};
use octrace_pico::both_cores;
use panic_halt as _;
use rp2040_hal as hal;

mod panel;

// boot2, and what build.rs places in SRAM (OCTRACE_CODE_IN) copied there at boot.
octrace_pico::boot!();

/// The scene (`SCENE_TEXT`, in flash) and a capacity profile that holds
/// exactly what it needs (`SceneProfile`), from `build.rs`: set
/// `OCTRACE_SCENE` to your scene's file when you build; for an animation,
/// `ANIMATED` and what its motion needs (`MOTION`).
#[allow(dead_code)]
mod scene {
    include!(concat!(env!("OUT_DIR"), "/scene.rs"));
}
use scene::{SceneProfile, ANIMATED, MOTION, SCENE_TEXT};

/// Room for the scene, its octree and core 0's mailbox and lists.
static RAYTRACER: ConstStaticCell<Raytracer<SceneProfile>> = ConstStaticCell::new(Raytracer::new());

/// Core 1's own mailbox and screen lists.
static CORE1_ROOM: ConstStaticCell<RendererRoom<SceneProfile>> = ConstStaticCell::new(RendererRoom::new());

/// Core 1's stack: 16 KiB (the render needs a few).
static CORE1_STACK: Stack<4096> = Stack::new();

/// Core 1's rows on their way to the panel's buffer: it may trace four ahead.
static RING: Handoff<{ panel::WIDTH }, 4> = Handoff::new();

/// What the scene's animation takes on the panel: a byte a tile (512),
/// and its motion (`build.rs` counted it); none for a still.
const ANIMATION: AnimationNeeds = AnimationNeeds {
    tiles: if ANIMATED { AnimationNeeds::tiles_for(Size::new(panel::WIDTH as u32, panel::HEIGHT as u32)) } else { 0 },
    ..MOTION
};

/// The animation's room: its tiles and motion.
static ANIMATION_ROOM: ConstStaticCell<AnimationRoom<{ ANIMATION.tiles }, { ANIMATION.tracks }, { ANIMATION.keys }>> =
    ConstStaticCell::new(AnimationRoom::new());

/// An animation's runs from core 1 on their way to the panel's buffer: a
/// row of up to 32 tiles each, core 1 tracing up to eight ahead.
static RUNS: Runs<{ panel::WIDTH }, 8> = Runs::new();

#[entry]
fn main() -> ! {
    let Board { mut core1, pins, clocks, timer, mut resets, peripherals, .. } =
        board::start(CORE1_STACK.take().unwrap());
    let mut display = panel::init(peripherals.i2c0, pins.gpio4, pins.gpio5, &mut resets, &clocks);
    let mut led = pins.gpio25.into_push_pull_output();

    if ANIMATED {
        // Frame after frame for ever, each sent to the panel once drawn: it
        // returns only when a frame cannot be drawn.
        if let Ok(animation) = ANIMATION_ROOM.take().animation(display.size()) {
            let (raytracer, room) = (RAYTRACER.take(), CORE1_ROOM.take());
            let player = Player { core1: &mut core1, raytracer, animation, room, runs: &RUNS };
            let _: animation::Stopped =
                player.play(SCENE_TEXT, &mut display, |display| display.flush(), &mut led, &timer);
        }
        let _ = display.clear(BinaryColor::On);
        let _ = display.flush();
        loop {
            cortex_m::asm::wfi();
        }
    }

    // octrace: parse and index the scene (the light buffer on core 1 while
    // core 0 builds the octree), then trace it at the panel's size with
    // both cores, core 0 putting each row into the panel's buffer in its
    // colour. A scene the board cannot trace (check it with host-sim, whose
    // errors name the line and column) lights the whole panel.
    let loaded = RAYTRACER.take().load_on_two_cores(SCENE_TEXT, |beside, here| core1.scope(beside, here));
    let drawn = match loaded {
        Ok(scene) => {
            let Ok(()) = led.set_high();
            let each_row = |_, _: &_| ControlFlow::Continue(());
            let drawn = both_cores::draw(&mut core1, &scene, CORE1_ROOM.take(), &RING, &mut display, each_row);
            let Ok(()) = led.set_low();
            drawn.is_ok()
        }
        Err(_) => false,
    };
    if !drawn {
        // Fills the buffer only: it cannot fail.
        let _ = display.clear(BinaryColor::On);
    }
    // The picture, from the buffer to the panel.
    if display.flush().is_err() {
        panic!("the panel did not take the picture");
    }
    loop {
        cortex_m::asm::wfi();
    }
}
