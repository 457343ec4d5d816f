//! An in-memory RGB image that is an embedded-graphics `DrawTarget` (its
//! files: [`crate::formats`]).
//!
//! Invariant: `data` holds `width × height` RGB triples, row-major; pixels
//! drawn outside the image are dropped, as a display drops them.

use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use std::convert::Infallible;

/// 8-bit RGB pixels, row-major.
///
/// ```
/// use embedded_graphics_core::{draw_target::DrawTarget, pixelcolor::Rgb888, prelude::*};
/// use octrace_images::RgbImage;
///
/// let mut image = RgbImage::new(2, 2);
/// image.draw_iter([Pixel(Point::new(1, 0), Rgb888::new(9, 8, 7))]).unwrap();
/// assert_eq!(image.pixel(1, 0), [9, 8, 7]);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    pub data: Vec<u8>,
}

impl RgbImage {
    pub fn new(width: u32, height: u32) -> RgbImage {
        RgbImage { width, height, data: vec![0; width as usize * height as usize * 3] }
    }

    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = (y as usize * self.width as usize + x as usize) * 3;
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }

    fn put(&mut self, x: i32, y: i32, c: Rgb888) {
        if x >= 0 && y >= 0 && (x as u32) < self.width && (y as u32) < self.height {
            let i = (y as usize * self.width as usize + x as usize) * 3;
            self.data[i..i + 3].copy_from_slice(&[c.r(), c.g(), c.b()]);
        }
    }
}

impl OriginDimensions for RgbImage {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl DrawTarget for RgbImage {
    type Color = Rgb888;
    type Error = Infallible;

    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Infallible>
    where
        I: IntoIterator<Item = Pixel<Rgb888>>,
    {
        for Pixel(p, c) in pixels {
            self.put(p.x, p.y, c);
        }
        Ok(())
    }

    fn fill_contiguous<I>(&mut self, area: &Rectangle, colors: I) -> Result<(), Infallible>
    where
        I: IntoIterator<Item = Rgb888>,
    {
        let mut colors = colors.into_iter();
        for y in 0..area.size.height as i32 {
            for x in 0..area.size.width as i32 {
                match colors.next() {
                    Some(c) => self.put(area.top_left.x + x, area.top_left.y + y, c),
                    None => return Ok(()),
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_graphics_core::geometry::Point;

    #[test]
    fn rows_land_where_they_are_drawn() {
        let mut img = RgbImage::new(3, 2);
        img.fill_contiguous(
            &Rectangle::new(Point::new(0, 1), Size::new(3, 1)),
            [Rgb888::new(1, 2, 3), Rgb888::new(4, 5, 6), Rgb888::new(255, 0, 7)],
        )
        .unwrap();
        assert_eq!(img.pixel(2, 1), [255, 0, 7]);
        assert_eq!(img.pixel(2, 0), [0, 0, 0]);
    }
}
