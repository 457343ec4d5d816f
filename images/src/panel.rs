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
use embedded_graphics_core::pixelcolor::{Gray8, GrayColor, Rgb565, Rgb888, RgbColor};
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

/// How close `shown`, what `panel` shows of `render`, looks to it for an
/// eye that cannot tell pixels apart (at reading distance): the PSNR (peak
/// 255, in dB) between the two, each blurred by a Gaussian of σ = 1 pixel
/// (5 taps, borders reflected half a sample out), in display values. A
/// gray panel is compared with the render's gray (BT.601 luma, what the
/// core dithers); black/white/red with the render's RGB, each channel
/// apart (capped by the blues and greens it cannot show). This is issue
/// 42's measure: it gives its table's 11.4, 15.9 and 11.1 dB for a cut at
/// mid-gray of fig5_1, fig5_3 and fig5_5 at 128×64.
///
/// ```
/// use octrace_core::panel::{Dithering, Panel};
/// use octrace_images::{panel, RgbImage};
///
/// // A flat 25 % gray: one lit pixel in four looks almost like it.
/// let render = RgbImage { width: 32, height: 32, data: vec![64; 32 * 32 * 3] };
/// let dithered = panel::dithered(&render, Panel::Mono, Dithering::FsPe).to_rgb();
/// let cut = panel::dithered(&render, Panel::Mono, Dithering::Nearest).to_rgb();
/// assert!(panel::seen_psnr(&render, &dithered, Panel::Mono) > 30.0);
/// assert!(panel::seen_psnr(&render, &cut, Panel::Mono) < 13.0);
/// ```
pub fn seen_psnr(render: &RgbImage, shown: &RgbImage, panel: Panel) -> f64 {
    match panel {
        Panel::BlackWhiteRed => blurred_psnr(render, shown),
        _ => {
            let difference: Vec<f64> =
                pixels(shown).zip(pixels(render)).map(|(s, r)| s.r() as f64 - Gray8::from(r).luma() as f64).collect();
            blurred_difference_psnr(difference, render.width as usize, render.height as usize, 1)
        }
    }
}

/// How close `shown` looks to `render` for an eye that cannot tell pixels
/// apart: the PSNR (peak 255, in dB) over every RGB channel between the
/// two, each blurred by a Gaussian of σ = 1 pixel as [`seen_psnr`] blurs
/// them.
///
/// ```
/// use octrace_images::{panel, RgbImage};
///
/// // Alternate pixels 2 levels above and below a flat colour: 48 dB
/// // plain, nearly the colour itself once blurred.
/// let flat = RgbImage { width: 16, height: 16, data: vec![100; 16 * 16 * 3] };
/// let data = (0..16 * 16 * 3).map(|i| if (i / 3 + i / 48) % 2 == 0 { 98 } else { 102 }).collect();
/// let checked = RgbImage { width: 16, height: 16, data };
/// assert!(octrace_images::palette::psnr(&flat, &checked) < 43.0);
/// assert!(panel::blurred_psnr(&flat, &checked) > 55.0);
/// ```
pub fn blurred_psnr(render: &RgbImage, shown: &RgbImage) -> f64 {
    let difference = shown.data.iter().zip(&render.data).map(|(&s, &r)| s as f64 - r as f64).collect();
    blurred_difference_psnr(difference, render.width as usize, render.height as usize, 3)
}

/// The PSNR of a difference of `w` × `h` pixels of `channels` each,
/// blurred first (the blur is linear: blurring the difference is
/// differencing the blurred images).
fn blurred_difference_psnr(mut difference: Vec<f64>, w: usize, h: usize, channels: usize) -> f64 {
    blur(&mut difference, w, h, channels);
    let squared: f64 = difference.iter().map(|d| d * d).sum();
    match squared {
        0.0 => f64::INFINITY,
        _ => 10.0 * (255.0f64 * 255.0 / (squared / difference.len().max(1) as f64)).log10(),
    }
}

/// Blurs `values` (`w` × `h` pixels of `channels` each) in place by a
/// Gaussian of σ = 1 pixel, 5 taps, across then down.
fn blur(values: &mut [f64], w: usize, h: usize, channels: usize) {
    let taps = [-2i64, -1, 0, 1, 2].map(|k| (-(k * k) as f64 / 2.0).exp());
    let sum: f64 = taps.iter().sum();
    let taps = taps.map(|t| t / sum);
    let mut pass = |stride: usize, step: usize, lines: usize, length: usize| {
        let mut line = vec![0.0; length];
        for first in (0..lines).map(|l| l * stride) {
            for c in 0..channels {
                for (i, v) in line.iter_mut().enumerate() {
                    *v = values[first + i * step + c];
                }
                for i in 0..length {
                    let at = |k: i64| line[reflect(i as i64 + k, length)];
                    values[first + i * step + c] = (-2..=2).zip(taps).map(|(k, t)| t * at(k)).sum();
                }
            }
        }
    };
    pass(w * channels, channels, h, w);
    pass(channels, w * channels, w, h);
}

/// Index `i` of a line of `n` values, reflected half a sample beyond each
/// end (`… c b a | a b c …`), as often as it takes.
fn reflect(mut i: i64, n: usize) -> usize {
    let n = n as i64;
    while i < 0 || i >= n {
        i = if i < 0 { -i - 1 } else { 2 * n - i - 1 };
    }
    i as usize
}

fn pixels(image: &RgbImage) -> impl Iterator<Item = Rgb888> + '_ {
    image.data.chunks_exact(3).map(|p| Rgb888::new(p[0], p[1], p[2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_graphics_core::pixelcolor::Gray4;

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

    #[test]
    fn the_blur_keeps_a_flat_picture_and_reflects_at_the_borders() {
        let mut flat = vec![3.0; 5 * 4 * 3];
        blur(&mut flat, 5, 4, 3);
        assert!(flat.iter().all(|v| (v - 3.0).abs() < 1e-12));
        // A single bright pixel at a corner sees itself reflected once on
        // each axis, (0.40262 + 0.24420)², and keeps its whole light.
        let mut corner = vec![0.0; 8 * 8];
        corner[0] = 1.0;
        blur(&mut corner, 8, 8, 1);
        assert!((corner[0] - 0.64682f64.powi(2)).abs() < 1e-4, "{}", corner[0]);
        assert!((corner.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert_eq!([reflect(-1, 4), reflect(-2, 4), reflect(4, 4), reflect(5, 4), reflect(-2, 1)], [0, 1, 3, 2, 0]);
    }
}
