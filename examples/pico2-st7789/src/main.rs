//! octrace on a Raspberry Pi Pico 2 (RP2350, Cortex-M33): a scene embedded in
//! flash is parsed on the board and traced row by row straight into an ST7789
//! panel (Waveshare
//! Pico-LCD-1.3, 240×240) through `mipidsi`. No heap, no framebuffer: the
//! panel's own memory holds the picture. Pins and wiring are in README.md.
//!
//! Invariants: the scene, its octree and mailbox live in one static cell
//! (all zero bits, so in `.bss`: no flash, no copy on the stack); the image
//! takes the panel's size.

#![no_std]
#![no_main]

use embedded_graphics::image::Image;
use embedded_graphics::pixelcolor::Rgb565;
use embedded_graphics::prelude::*;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::MODE_0;
use embedded_hal_bus::spi::ExclusiveDevice;
use hal::fugit::RateExtU32;
use hal::gpio::{FunctionSpi, Pins};
use hal::{entry, pac, Clock, Sio, Spi, Timer, Watchdog};
use mipidsi::interface::SpiInterface;
use mipidsi::models::ST7789;
use mipidsi::options::ColorInversion;
use mipidsi::Builder;
use octrace_core::{ConstStaticCell, Raytracer};
use panic_halt as _;
use rp235x_hal as hal;

/// What the boot ROM looks for in the first 4 KiB of flash before it runs
/// the program: a Secure executable for the Arm cores (see memory.x).
#[link_section = ".start_block"]
#[used]
static IMAGE_DEF: hal::block::ImageDef = hal::block::ImageDef::secure_exe();

/// The Pico 2's crystal.
const CRYSTAL_HZ: u32 = 12_000_000;

/// The scene (`SCENE_TEXT`, in flash) and a capacity profile that holds
/// exactly what it needs (`SceneProfile`), from `build.rs`: set
/// `OCTRACE_SCENE` to your scene's file when you build.
mod scene {
    include!(concat!(env!("OUT_DIR"), "/scene.rs"));
}
use scene::{SceneProfile, SCENE_TEXT};

/// The panel: a 240×240 IPS ST7789, which shows true colours only with the
/// controller's inversion on.
const PANEL_WIDTH: u16 = 240;
const PANEL_HEIGHT: u16 = 240;

/// Room for the scene, its octree and mailbox.
static RAYTRACER: ConstStaticCell<Raytracer<SceneProfile>> = ConstStaticCell::new(Raytracer::new());

#[entry]
fn main() -> ! {
    let mut peripherals = pac::Peripherals::take().unwrap();
    let mut watchdog = Watchdog::new(peripherals.WATCHDOG);
    let clocks = hal::clocks::init_clocks_and_plls(
        CRYSTAL_HZ,
        peripherals.XOSC,
        peripherals.CLOCKS,
        peripherals.PLL_SYS,
        peripherals.PLL_USB,
        &mut peripherals.RESETS,
        &mut watchdog,
    )
    .unwrap();
    let mut timer = Timer::new_timer0(peripherals.TIMER0, &mut peripherals.RESETS, &clocks);
    let sio = Sio::new(peripherals.SIO);
    let pins = Pins::new(peripherals.IO_BANK0, peripherals.PADS_BANK0, sio.gpio_bank0, &mut peripherals.RESETS);

    // The Pico-LCD-1.3's pins, the same on the Pico 2's headers: SPI1 on
    // GP10 (clock) and GP11 (data), chip select GP9, data/command GP8,
    // reset GP12, backlight GP13. The bus runs at 30 MHz (the 150 MHz
    // peripheral clock over five), which jumper wires to a loose panel
    // carry too: the tracer, not the bus, sets the pace.
    let clock = pins.gpio10.into_function::<FunctionSpi>();
    let data = pins.gpio11.into_function::<FunctionSpi>();
    let bus = Spi::<_, _, _, 8>::new(peripherals.SPI1, (data, clock)).init(
        &mut peripherals.RESETS,
        clocks.peripheral_clock.freq(),
        30_000_000u32.Hz(),
        MODE_0,
    );
    let chip_select = pins.gpio9.into_push_pull_output();
    let data_command = pins.gpio8.into_push_pull_output();
    let reset = pins.gpio12.into_push_pull_output();
    let mut backlight = pins.gpio13.into_push_pull_output();
    let device = ExclusiveDevice::new(bus, chip_select, timer).unwrap();
    let mut buffer = [0u8; 512];
    let interface = SpiInterface::new(device, data_command, &mut buffer);
    let mut display = Builder::new(ST7789, interface)
        .display_size(PANEL_WIDTH, PANEL_HEIGHT)
        .invert_colors(ColorInversion::Inverted)
        .reset_pin(reset)
        .init(&mut timer)
        .unwrap();
    display.clear(Rgb565::BLACK).unwrap();
    backlight.set_high().unwrap();

    // octrace: parse and index the scene, then trace it into the panel at
    // the panel's size, scanline by scanline. A scene the board cannot trace
    // (check it with host-sim, whose errors name the line and column) leaves
    // the panel red.
    match RAYTRACER.take().load(SCENE_TEXT) {
        Ok(scene) => Image::new(&scene.image_for(&display), Point::zero()).draw(&mut display).unwrap(),
        Err(_) => display.clear(Rgb565::RED).unwrap(),
    }
    loop {
        cortex_m::asm::wfi();
    }
}
