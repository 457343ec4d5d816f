//! What a small panel shows of a render: each pixel converted to the
//! panel's colour depth by embedded-graphics, as the firmware's renderer
//! converts it, and widened back to 8 bits by embedded-graphics to be seen
//! or saved.
//!
//! Invariant: a preview has the render's size, and a pixel's preview
//! depends on that pixel alone.

use crate::formats::Image;
use crate::RgbImage;
use embedded_graphics_core::pixelcolor::{Gray4, Gray8, GrayColor, Rgb565, Rgb888, RgbColor};

/// `image` as an RGB565 panel shows it (5, 6 and 5 bits widened back).
///
/// ```
/// use octrace_images::{panel, RgbImage};
///
/// let image = RgbImage { width: 1, height: 1, data: vec![255, 131, 9] };
/// assert_eq!(panel::rgb565(&image).pixel(0, 0), [255, 130, 8]);
/// ```
pub fn rgb565(image: &RgbImage) -> RgbImage {
    let data = pixels(image).map(|c| Rgb888::from(Rgb565::from(c))).flat_map(|c| [c.r(), c.g(), c.b()]).collect();
    RgbImage { width: image.width, height: image.height, data }
}

/// `image` as a 16-level gray panel shows it: indices are the levels, the
/// colour table their 8-bit grays (level × 17).
///
/// ```
/// use octrace_images::{formats::Image, panel, RgbImage};
///
/// let image = RgbImage { width: 2, height: 1, data: vec![0, 0, 0, 255, 255, 255] };
/// let Image::Indexed { palette, indices, .. } = panel::gray4(&image) else { unreachable!() };
/// assert_eq!((indices, palette[15]), (vec![0, 15], [255; 3]));
/// ```
pub fn gray4(image: &RgbImage) -> Image {
    let indices = pixels(image).map(|c| Gray4::from(c).luma()).collect();
    let palette = (0..16).map(|level| [Gray8::from(Gray4::new(level)).luma(); 3]).collect();
    Image::Indexed { width: image.width, height: image.height, palette, indices }
}

fn pixels(image: &RgbImage) -> impl Iterator<Item = Rgb888> + '_ {
    image.data.chunks_exact(3).map(|p| Rgb888::new(p[0], p[1], p[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gray_levels_widen_as_embedded_graphics_widens_them_to_rgb() {
        let data = (0..=255u8).flat_map(|v| [v, v / 2, 255 - v]).collect();
        let image = RgbImage { width: 256, height: 1, data };
        let widened: Vec<u8> =
            pixels(&image).map(|c| Rgb888::from(Gray4::from(c))).flat_map(|c| [c.r(), c.g(), c.b()]).collect();
        assert_eq!(gray4(&image).to_rgb().data, widened);
    }
}
