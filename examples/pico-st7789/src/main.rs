//! octrace on a Raspberry Pi Pico: a scene embedded in flash is parsed on the
//! board and traced by both cores straight into an ST7789 panel (Waveshare
//! Pico-LCD-1.3, 240×240) through `mipidsi`. No heap, no framebuffer: the
//! panel's own memory holds the picture. An animation (`FRAMES` and `MOVE`)
//! plays in a loop, each frame re-tracing only what its motion can change.
//! The Pico's LED is lit while the board works on a picture or a frame.
//! Pins and wiring are in README.md. Once a still picture is drawn, the
//! Pico is a USB serial port that answers anything it is sent with what it
//! measured: the load's and the render's microseconds by its TIMER and
//! their contested accesses to the SRAM banks (`measure::Report`;
//! `pico-compare` sets them beside the emulated Pico's).
//!
//! Invariants: the scene, its octree and core 0's mailbox live in one static
//! cell, core 1's mailbox and lists in another (all zero bits, so in `.bss`:
//! no flash, no copy on the stack); so do an animation's motion and tiles,
//! sized for this scene by `build.rs` (empty for a still); the image takes
//! the panel's size; any split of the rows or tiles between the cores gives
//! the same bits as one core; USB starts after the picture, so it takes
//! nothing from it.

#![no_std]
#![no_main]

use core::cell::RefCell;
use core::fmt::Write;
use critical_section::Mutex;
use embedded_graphics::pixelcolor::Rgb565;
use embedded_graphics::prelude::*;
use embedded_hal::digital::OutputPin;
use hal::entry;
use hal::multicore::Stack;
use hal::pac::{self, interrupt};
use octrace_core::animation::{AnimationNeeds, AnimationRoom};
use octrace_core::render::Handoff;
#[cfg(progressive_order)]
use octrace_core::render::Progressive;
use octrace_core::{ConstStaticCell, Raytracer, RendererRoom};
use octrace_pico::animation::{self, Player, Runs};
use octrace_pico::board::{self, Board};
use octrace_pico::both_cores;
use octrace_pico_st7789::measure::{Meter, Report};
use octrace_pico_st7789::panel;
use octrace_pico_st7789::usb::{self, SerialDevice};
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
use scene::{SceneProfile, ANIMATED, MOTION, SCENE_NAME, SCENE_TEXT};

/// Room for the scene, its octree and core 0's mailbox and lists.
static RAYTRACER: ConstStaticCell<Raytracer<SceneProfile>> = ConstStaticCell::new(Raytracer::new());

/// Core 1's own mailbox and screen lists.
static CORE1_ROOM: ConstStaticCell<RendererRoom<SceneProfile>> = ConstStaticCell::new(RendererRoom::new());

/// Core 1's stack: 16 KiB (the render needs a few).
static CORE1_STACK: Stack<4096> = Stack::new();

/// The progressive order (`OCTRACE_ORDER=progressive`): the whole panel in
/// blocks of 16 first, then 8, then each row of blocks at full resolution.
#[cfg(progressive_order)]
const PROGRESSIVE: Progressive =
    Progressive::new(Size::new(panel::WIDTH as u32, panel::HEIGHT as u32), 16).with_finest(8);

/// The most pixels core 1 hands over at once: a row, or a unit of the
/// progressive order (30 KiB for four: only the progressive build keeps
/// them, so that the rows' leaves core 0's stack the room).
#[cfg(not(progressive_order))]
const HANDED_PIXELS: usize = panel::WIDTH as usize;
#[cfg(progressive_order)]
const HANDED_PIXELS: usize = PROGRESSIVE.max_unit_pixels();

/// What core 1 traced, on its way to the panel: it may trace four ahead.
static RING: Handoff<HANDED_PIXELS, 4> = Handoff::new();

/// What the scene's animation takes on the panel: a byte a tile, and its
/// motion (`build.rs` counted it); none for a still.
const ANIMATION: AnimationNeeds = AnimationNeeds {
    tiles: if ANIMATED { AnimationNeeds::tiles_for(Size::new(panel::WIDTH as u32, panel::HEIGHT as u32)) } else { 0 },
    ..MOTION
};

/// The animation's room: its tiles and motion.
static ANIMATION_ROOM: ConstStaticCell<AnimationRoom<{ ANIMATION.tiles }, { ANIMATION.tracks }, { ANIMATION.keys }>> =
    ConstStaticCell::new(AnimationRoom::new());

/// An animation's runs from core 1 on their way to the panel: a row of 32
/// tiles each, core 1 tracing up to eight ahead.
static RUNS: Runs<{ 32 * octrace_core::animation::TILE as usize }, 8> = Runs::new();

/// The panel's bus buffer.
static PANEL_BUFFER: ConstStaticCell<[u8; 512]> = ConstStaticCell::new([0; 512]);

/// The line the USB port answers with, and how much of its current answer
/// the port has taken: owned by the USB interrupt.
struct Answering {
    device: SerialDevice,
    line: heapless::String<192>,
    sent: usize,
}

static ANSWERING: Mutex<RefCell<Option<Answering>>> = Mutex::new(RefCell::new(None));

#[entry]
fn main() -> ! {
    let Board { mut core1, pins, clocks, timer, mut resets, peripherals, .. } =
        board::start(CORE1_STACK.take().unwrap());
    let (mut display, mut led) = panel::init(peripherals.spi1, pins, &mut resets, &clocks, timer, PANEL_BUFFER.take());
    let raytracer = RAYTRACER.take();
    if ANIMATED {
        // Frame after frame for ever: it returns only when a frame cannot
        // be drawn.
        if let Ok(animation) = ANIMATION_ROOM.take().animation(display.size()) {
            let player = Player { core1: &mut core1, raytracer, animation, room: CORE1_ROOM.take(), runs: &RUNS };
            let _: animation::Stopped = player.play(SCENE_TEXT, &mut display, |_| Ok(()), &mut led, &timer);
        }
        display.clear(Rgb565::RED).unwrap();
        loop {
            cortex_m::asm::wfi();
        }
    }
    let mut meter = Meter::new(timer, peripherals.busctrl);
    meter.start();
    let Ok(()) = led.set_high();

    // octrace: parse and index the scene, then trace it into the panel at
    // the panel's size with both cores. A scene the board cannot trace
    // (check it with host-sim, whose errors name the line and column)
    // leaves the panel red.
    // The light buffer is built on core 1 while core 0 builds the octree.
    let loaded = raytracer.load_on_two_cores(SCENE_TEXT, |beside, here| core1.scope(beside, here));
    let load = meter.split();
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
    let render = meter.split();
    let Ok(()) = led.set_low();
    if !drawn {
        display.clear(Rgb565::RED).unwrap();
    }

    // What was measured, answered on USB to anything the host sends.
    let mut line = heapless::String::new();
    let firmware = concat!(env!("CARGO_BIN_NAME"), " ", env!("CARGO_PKG_VERSION"));
    let report = Report { firmware, scene: SCENE_NAME, load, render };
    // 192 bytes hold the longest report (ten-digit counts and times).
    let _ = write!(line, "{report}\r\n");
    let device = usb::serial_device(
        peripherals.usbctrl_regs,
        peripherals.usbctrl_dpram,
        clocks.usb_clock,
        &mut resets,
        "octrace report",
    );
    // Nothing to send until the host asks.
    let sent = line.len();
    critical_section::with(|cs| ANSWERING.borrow_ref_mut(cs).replace(Answering { device, line, sent }));
    // SAFETY: the handler only touches what the critical section guards.
    unsafe { pac::NVIC::unmask(pac::Interrupt::USBCTRL_IRQ) };
    loop {
        cortex_m::asm::wfi();
    }
}

/// Serves the USB device; a byte from the host starts the answer (again,
/// once the last one is out), which goes out as the port takes it.
#[interrupt]
fn USBCTRL_IRQ() {
    critical_section::with(|cs| {
        let mut answering = ANSWERING.borrow_ref_mut(cs);
        let Some(Answering { device: (device, serial), line, sent }) = answering.as_mut() else { return };
        device.poll(&mut [serial]);
        let mut asked = [0u8; 64];
        // Asked again once the last answer is out: an answer is never cut by a restart.
        if matches!(serial.read(&mut asked), Ok(read) if read > 0) && *sent == line.len() {
            *sent = 0;
        }
        if let Some(rest) = line.as_bytes().get(*sent..).filter(|rest| !rest.is_empty()) {
            if let Ok(written) = serial.write(rest) {
                *sent += written;
            }
        }
    });
}
