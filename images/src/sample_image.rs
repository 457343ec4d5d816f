//! An image a draw of [`PixelSample`]s fills: each pixel's RGB colour and
//! the object it sees, row-major, as host-sim's frames and the studio's
//! page take them.
//!
//! Invariant: a pixel outside the image is dropped, never written.

use crate::NO_OBJECT;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::RgbColor;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::render::PixelSample;

/// `size` pixels: three bytes of colour each in `colours`, and in
/// `objects` the object each sees ([`NO_OBJECT`] for the background).
///
/// ```
/// use embedded_graphics_core::{geometry::{Point, Size}, primitives::Rectangle, draw_target::DrawTarget};
/// use embedded_graphics_core::pixelcolor::Rgb888;
/// use octrace_core::{render::PixelSample, scene::ObjectId};
/// use octrace_images::{SampleImage, NO_OBJECT};
///
/// let (mut colours, mut objects) = ([0; 3 * 4], [0; 4]);
/// let mut image = SampleImage { colours: &mut colours, objects: &mut objects, size: Size::new(2, 2) };
/// let red = PixelSample { color: Rgb888::new(255, 0, 0), object: Some(ObjectId(7)) };
/// let sky = PixelSample { color: Rgb888::new(0, 0, 255), object: None };
/// image.fill_contiguous(&Rectangle::new(Point::new(0, 1), Size::new(2, 1)), [red, sky]).unwrap();
/// assert_eq!(colours[6..], [255, 0, 0, 0, 0, 255]);
/// assert_eq!(objects, [0, 0, 7, NO_OBJECT]);
/// ```
#[derive(Debug)]
pub struct SampleImage<'i> {
    pub colours: &'i mut [u8],
    pub objects: &'i mut [u32],
    pub size: Size,
}

impl OriginDimensions for SampleImage<'_> {
    fn size(&self) -> Size {
        self.size
    }
}

impl DrawTarget for SampleImage<'_> {
    type Color = PixelSample;
    type Error = core::convert::Infallible;

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
        let (w, h) = (self.size.width as i64, self.size.height as i64);
        let (x0, width) = (i64::from(area.top_left.x), i64::from(area.size.width));
        let mut samples = samples.into_iter();
        for y in (area.top_left.y..).take(area.size.height as usize).map(i64::from) {
            for (x, p) in (x0..x0 + width).zip(samples.by_ref()) {
                if (0..w).contains(&x) && (0..h).contains(&y) {
                    let at = (y * w + x) as usize;
                    self.colours[3 * at..3 * at + 3].copy_from_slice(&[p.color.r(), p.color.g(), p.color.b()]);
                    self.objects[at] = p.object.map_or(NO_OBJECT, |o| o.0);
                }
            }
        }
        Ok(())
    }
}
