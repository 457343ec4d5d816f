//! What a small panel shows of a render: each pixel converted to the
//! panel's colour depth by embedded-graphics, as the firmware's renderer
//! converts it, or dithered onto a panel of few levels by the core's
//! [`Ditherer`], as a board's image is; widened back to 8 bits to be seen
//! or saved.
//!
//! Invariant: a preview has the render's size, and is the pixels a board
//! draws of the same render: a converted pixel depends on that pixel alone,
//! a dithered one on the pixels before it in raster order, exactly as on
//! the board.

use crate::formats::Image;
use crate::RgbImage;
use embedded_graphics_core::geometry::Point;
use embedded_graphics_core::pixelcolor::{Rgb565, Rgb888, RgbColor};
use octrace_core::panel::{Ditherer, Dithering, Panel};

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

/// `image` as `panel` shows it, dithered by `dithering` over the whole
/// image in raster order: indices are the panel's levels, the colour table
/// their colours ([`Panel::color`]: grays for the gray panels, level ×
/// 255 / (levels − 1)).
///
/// ```
/// use octrace_core::panel::{Dithering, Panel};
/// use octrace_images::{formats::Image, panel, RgbImage};
///
/// let image = RgbImage { width: 2, height: 1, data: vec![0, 0, 0, 255, 255, 255] };
/// let Image::Indexed { palette, indices, .. } = panel::dithered(&image, Panel::Gray4, Dithering::FsPe) else {
///     unreachable!()
/// };
/// assert_eq!((indices, palette[15]), (vec![0, 15], [255; 3]));
/// ```
pub fn dithered(image: &RgbImage, panel: Panel, dithering: Dithering) -> Image {
    let mut rows = vec![0; panel.error_words(image.width)];
    let indices = match Ditherer::new(panel, dithering, Point::zero(), image.width, &mut rows) {
        Ok(mut ditherer) => pixels(image).map(|c| ditherer.next(c)).collect(),
        Err(e) => unreachable!("the rows were sized for the image: {e}"),
    };
    let palette = (0..panel.levels()).map(|level| panel.color(level)).map(|c| [c.r(), c.g(), c.b()]).collect();
    Image::Indexed { width: image.width, height: image.height, palette, indices }
}

fn pixels(image: &RgbImage) -> impl Iterator<Item = Rgb888> + '_ {
    image.data.chunks_exact(3).map(|p| Rgb888::new(p[0], p[1], p[2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_graphics_core::pixelcolor::{Gray4, GrayColor};

    #[test]
    fn gray_levels_widen_as_embedded_graphics_widens_them_to_rgb() {
        let data = (0..=255u8).flat_map(|v| [v, v / 2, 255 - v]).collect();
        let image = RgbImage { width: 256, height: 1, data };
        let preview = dithered(&image, Panel::Gray4, Dithering::Nearest);
        let widened: Vec<u8> =
            pixels(&image).map(|c| Rgb888::from(Gray4::from(c))).flat_map(|c| [c.r(), c.g(), c.b()]).collect();
        assert_eq!(preview.to_rgb().data, widened);
        let Image::Indexed { indices, .. } = preview else { unreachable!() };
        assert!(pixels(&image).zip(indices).all(|(c, level)| Gray4::from(c).luma() == level));
    }
}
