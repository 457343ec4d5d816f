//! octrace on a Raspberry Pi Pico: a scene embedded in flash is parsed on the
//! board and traced by both cores straight into an ST7789 panel (Waveshare
//! Pico-LCD-1.3, 240×240) through `mipidsi`. No heap, no framebuffer: the
//! panel's own memory holds the picture. An animation (`FRAMES` and `MOVE`)
//! plays in a loop, each frame re-tracing only what its motion can change.
//! The Pico's LED is lit while the board works on a picture or a frame.
//! Pins and wiring are in README.md.
//!
//! Invariants: the scene, its octree and core 0's mailbox live in one static
//! cell, core 1's mailbox and lists in another (all zero bits, so in `.bss`:
//! no flash, no copy on the stack); so do an animation's motion and tiles,
//! sized for this scene by `build.rs` (empty for a still); the image takes
//! the panel's size; any split of the rows or tiles between the cores gives
//! the same bits as one core.

#![no_std]
#![no_main]

use core::sync::atomic::AtomicU8;
use embedded_graphics::pixelcolor::Rgb565;
use embedded_graphics::prelude::*;
use embedded_hal::digital::OutputPin;
use hal::entry;
use hal::multicore::Stack;
use octrace_core::animation::{Coherence, Key, Track};
use octrace_core::render::{Handoff, Progressive};
use octrace_core::{ConstStaticCell, Raytracer, RendererRoom};
use octrace_pico::animation::{self, MotionRoom, Runs, TILE};
use octrace_pico::board::{self, Board};
use octrace_pico::both_cores;
use octrace_pico_st7789::panel;
use panic_halt as _;
use rp2040_hal as hal;

// boot2, and what build.rs places in SRAM (OCTRACE_CODE_IN) copied there at boot.
octrace_pico::boot!();

/// The scene (`SCENE_TEXT`, in flash) and a capacity profile that holds
/// exactly what it needs (`SceneProfile`), from `build.rs`: set
/// `OCTRACE_SCENE` to your scene's file when you build.
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

/// The progressive order (`OCTRACE_ORDER=progressive`): the whole panel in
/// blocks of 16 first, then 8, then each row of blocks at full resolution.
const PROGRESSIVE: Progressive =
    Progressive::new(Size::new(panel::WIDTH as u32, panel::HEIGHT as u32), 16).with_finest(8);

/// What core 1 traced, on its way to the panel (a row, or a unit of the
/// progressive order): it may trace four ahead.
static RING: Handoff<{ PROGRESSIVE.max_unit_pixels() }, 4> = Handoff::new();

/// An animation's motion: its tracks, keys and displacements.
static TRACKS: ConstStaticCell<[Track; MOTION.tracks]> = ConstStaticCell::new([Track::EMPTY; MOTION.tracks]);
static KEYS: ConstStaticCell<[Key; MOTION.keys]> = ConstStaticCell::new([Key::EMPTY; MOTION.keys]);
static DISPLACEMENTS: ConstStaticCell<[[i32; 3]; MOTION.displacements]> =
    ConstStaticCell::new([[0; 3]; MOTION.displacements]);

/// An animation's tiles, a byte each (none for a still).
const TILES: usize = if ANIMATED { Coherence::tiles_for(panel::WIDTH as u32, panel::HEIGHT as u32, TILE) } else { 0 };
static COUNTS: [AtomicU8; TILES] = [const { AtomicU8::new(0) }; TILES];

/// An animation's runs from core 1 on their way to the panel: a row of 32
/// tiles each, core 1 tracing up to eight ahead.
static RUNS: Runs<{ 32 * TILE as usize }, 8> = Runs::new();

/// The panel's bus buffer.
static PANEL_BUFFER: ConstStaticCell<[u8; 512]> = ConstStaticCell::new([0; 512]);

#[entry]
fn main() -> ! {
    let Board { mut core1, pins, clocks, timer, mut resets, peripherals, .. } =
        board::start(CORE1_STACK.take().unwrap());
    let (mut display, mut led) = panel::init(peripherals.spi1, pins, &mut resets, &clocks, timer, PANEL_BUFFER.take());
    let raytracer = RAYTRACER.take();

    // octrace: parse and index the scene, then trace it into the panel at
    // the panel's size with both cores; an animation, frame after frame
    // for ever. A scene the board cannot trace (check it with host-sim,
    // whose errors name the line and column) leaves the panel red.
    let drawn = if ANIMATED {
        let motion = MotionRoom { tracks: TRACKS.take(), keys: KEYS.take(), displacements: DISPLACEMENTS.take() };
        // For ever: it returns only when a frame cannot be drawn.
        let _: animation::Stopped = animation::play(
            &mut core1,
            raytracer,
            SCENE_TEXT,
            motion,
            &COUNTS,
            CORE1_ROOM.take(),
            &RUNS,
            &mut display,
            &mut led,
            &timer,
        );
        false
    } else {
        let Ok(()) = led.set_high();
        // The light buffer is built on core 1 while core 0 builds the octree.
        let loaded = raytracer.load_on_two_cores(SCENE_TEXT, |beside, here| core1.scope(beside, here));
        let drawn = match loaded {
            #[cfg(not(progressive_order))]
            Ok(scene) => {
                let each_row = |_, _: &_| core::ops::ControlFlow::Continue(());
                both_cores::draw(&mut core1, &scene, CORE1_ROOM.take(), &RING, &mut display, each_row).is_ok()
            }
            #[cfg(progressive_order)]
            Ok(scene) => {
                both_cores::draw_progressive(&mut core1, &scene, CORE1_ROOM.take(), &RING, &mut display, &PROGRESSIVE)
                    .is_ok()
            }
            Err(_) => false,
        };
        let Ok(()) = led.set_low();
        drawn
    };
    if !drawn {
        display.clear(Rgb565::RED).unwrap();
    }
    loop {
        cortex_m::asm::wfi();
    }
}
