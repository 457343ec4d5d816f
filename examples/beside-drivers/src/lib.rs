//! Proves that a board crate can depend on octrace-core beside the current
//! display drivers: they resolve together (one `embedded-graphics-core`,
//! one `az`), and an octrace image draws into the drivers' own display
//! types, which only type-checks when their `DrawTarget` is the one
//! octrace's images draw through.

#![no_std]

use embedded_graphics::image::Image;
use embedded_graphics::pixelcolor::{BinaryColor, Rgb565};
use embedded_graphics::prelude::*;
use embedded_hal::digital::OutputPin;
use embedded_hal::i2c::I2c;
use embedded_hal::spi::SpiDevice;
use mipidsi::interface::SpiInterface;
use mipidsi::models::ST7789;
use octrace_core::{profile::Board16K, Raytracer};
use ssd1306::mode::BufferedGraphicsMode;
use ssd1306::prelude::I2CInterface;
use ssd1306::size::DisplaySize128x64;
use ssd1306::Ssd1306;

/// An ST7789 panel on SPI as `mipidsi` drives it.
pub type Panel<'b, Spi, Dc, Reset> = mipidsi::Display<SpiInterface<'b, Spi, Dc>, ST7789, Reset>;
/// A 128×64 SSD1306 on I2C, buffered, as `ssd1306` drives it.
pub type Oled<Bus> = Ssd1306<I2CInterface<Bus>, DisplaySize128x64, BufferedGraphicsMode<DisplaySize128x64>>;

/// Draws the scene `text` into both drivers' displays: the call that
/// fails to compile should a driver move to another `embedded-graphics`.
pub fn draw_on_the_drivers<Spi, Dc, Reset, Bus>(
    raytracer: &mut Raytracer<Board16K>,
    text: &str,
    panel: &mut Panel<'_, Spi, Dc, Reset>,
    oled: &mut Oled<Bus>,
) -> bool
where
    Spi: SpiDevice,
    Dc: OutputPin,
    Reset: OutputPin,
    Bus: I2c,
{
    draw_both(raytracer, text, panel, oled)
}

/// Draws `text` into any RGB565 display and any on/off display, with
/// octrace's image.
pub fn draw_both<D, M>(raytracer: &mut Raytracer<Board16K>, text: &str, color: &mut D, mono: &mut M) -> bool
where
    D: DrawTarget<Color = Rgb565>,
    M: DrawTarget<Color = BinaryColor>,
{
    let Ok(scene) = raytracer.load(text) else { return false };
    let color_ok = Image::new(&scene.image_for(color), Point::zero()).draw(color).is_ok();
    let mono_ok = Image::new(&scene.image_for(mono), Point::zero()).draw(mono).is_ok();
    color_ok && mono_ok
}
