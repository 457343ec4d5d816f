//! Proves that a board crate can depend on octrace-core beside the current
//! display drivers: the four resolve together (one `embedded-graphics-core`,
//! one `az`) and an octrace image draws into a driver's colour type.

#![no_std]

use embedded_graphics::image::Image;
use embedded_graphics::pixelcolor::{BinaryColor, Rgb565};
use embedded_graphics::prelude::*;
use octrace_core::{profile::Board16K, Raytracer};

/// The ST7789 model `mipidsi` drives, and the SSD1306's 128×64 size.
pub type Panel = mipidsi::models::ST7789;
/// The monochrome OLED's size type from `ssd1306`.
pub type Oled = ssd1306::size::DisplaySize128x64;

/// Draws `text` into any RGB565 display (what `mipidsi` gives) and any
/// on/off display (what `ssd1306` gives), with octrace's image.
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
