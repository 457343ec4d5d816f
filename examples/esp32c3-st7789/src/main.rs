//! octrace on an ESP32-C3 (one RV32IMC core at 160 MHz): a scene embedded in
//! flash is parsed on the board and traced row by row straight into an
//! ST7789 panel (240×240) through `mipidsi`. No heap, no framebuffer: the
//! panel's own memory holds the picture. Board and wiring are in README.md.
//!
//! Invariants: the scene, its octree and mailbox live in one static cell
//! (all zero bits, so in `.bss`: no flash, no copy on the stack); the image
//! takes the panel's size.

#![no_std]
#![no_main]

use embedded_graphics::image::Image;
use embedded_graphics::pixelcolor::Rgb565;
use embedded_graphics::prelude::*;
use embedded_hal_bus::spi::ExclusiveDevice;
use esp_hal::clock::CpuClock;
use esp_hal::delay::Delay;
use esp_hal::gpio::{Level, Output, OutputConfig};
use esp_hal::spi::master::{Config, Spi};
use esp_hal::spi::Mode;
use esp_hal::time::Rate;
use mipidsi::interface::SpiInterface;
use mipidsi::models::ST7789;
use mipidsi::options::ColorInversion;
use mipidsi::Builder;
use octrace_core::{ConstStaticCell, Raytracer};

// The application descriptor the ESP-IDF second-stage bootloader checks.
esp_bootloader_esp_idf::esp_app_desc!();

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

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    esp_hal::system::software_reset()
}

#[esp_hal::main]
fn main() -> ! {
    let peripherals = esp_hal::init(esp_hal::Config::default().with_cpu_clock(CpuClock::max()));

    // The panel on SPI2 through the GPIO matrix (README.md): clock GPIO6,
    // data GPIO7, chip select GPIO10, data/command GPIO3, reset GPIO4,
    // backlight GPIO5, clear of the strapping (2, 8, 9), flash (12 to 17)
    // and USB (18, 19) pins. 40 MHz: the tracer, not the bus, sets the pace.
    let config = Config::default().with_frequency(Rate::from_mhz(40)).with_mode(Mode::_0);
    let bus = Spi::new(peripherals.SPI2, config).unwrap().with_sck(peripherals.GPIO6).with_mosi(peripherals.GPIO7);
    let chip_select = Output::new(peripherals.GPIO10, Level::High, OutputConfig::default());
    let data_command = Output::new(peripherals.GPIO3, Level::Low, OutputConfig::default());
    let reset = Output::new(peripherals.GPIO4, Level::High, OutputConfig::default());
    let mut backlight = Output::new(peripherals.GPIO5, Level::Low, OutputConfig::default());
    let mut delay = Delay::new();
    let device = ExclusiveDevice::new(bus, chip_select, Delay::new()).unwrap();
    let mut buffer = [0u8; 512];
    let interface = SpiInterface::new(device, data_command, &mut buffer);
    let mut display = Builder::new(ST7789, interface)
        .display_size(PANEL_WIDTH, PANEL_HEIGHT)
        .invert_colors(ColorInversion::Inverted)
        .reset_pin(reset)
        .init(&mut delay)
        .unwrap();
    display.clear(Rgb565::BLACK).unwrap();
    backlight.set_high();

    // octrace: parse and index the scene, then trace it into the panel at
    // the panel's size, scanline by scanline. A scene the board cannot trace
    // (check it with host-sim, whose errors name the line and column) leaves
    // the panel red.
    match RAYTRACER.take().load(SCENE_TEXT) {
        Ok(scene) => Image::new(&scene.image_for(&display), Point::zero()).draw(&mut display).unwrap(),
        Err(_) => display.clear(Rgb565::RED).unwrap(),
    }
    loop {
        core::hint::spin_loop();
    }
}
