//! An image the studio's draws fill: each pixel's colour and the object it
//! sees, row-major, as the page takes them.

use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::RgbColor;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::render::PixelSample;
use octrace_images::NO_OBJECT;

/// `size` pixels: RGB colours, and the object under each ([`NO_OBJECT`]
/// for the background), as a draw hands them over run by run.
pub(crate) struct Pixels<'i> {
    pub colours: &'i mut [u8],
    pub objects: &'i mut [u32],
    pub size: Size,
}

impl OriginDimensions for Pixels<'_> {
    fn size(&self) -> Size {
        self.size
    }
}

impl DrawTarget for Pixels<'_> {
    type Color = PixelSample;
    type Error = std::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<PixelSample>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
        for Pixel(at, sample) in pixels {
            self.fill_contiguous(&Rectangle::new(at, Size::new(1, 1)), [sample])?;
        }
        Ok(())
    }

    fn fill_contiguous<I: IntoIterator<Item = PixelSample>>(
        &mut self,
        area: &Rectangle,
        samples: I,
    ) -> Result<(), Self::Error> {
        let (w, h) = (self.size.width as i32, self.size.height as i32);
        let (x0, y) = (area.top_left.x, area.top_left.y);
        for (x, p) in (x0..x0 + area.size.width as i32).zip(samples) {
            // A draw stays within the image; what would not is dropped.
            if (0..w).contains(&x) && (0..h).contains(&y) {
                let at = (y * w + x) as usize;
                self.colours[3 * at..3 * at + 3].copy_from_slice(&[p.color.r(), p.color.g(), p.color.b()]);
                self.objects[at] = p.object.map_or(NO_OBJECT, |o| o.0);
            }
        }
        Ok(())
    }
}
