//! 256-colour images on the host: the core's four palette modes applied to
//! a finished render, in raster order, exactly as a board streams them.
//!
//! `scan` runs in two passes here (the whole image learnt first, then
//! mapped); `dither`, `coarse` and `gray` need one. [`apply`] maps an image
//! held whole; host-sim's command line streams rows through the same
//! quantizers and writes the same files.

use crate::formats::Image;
use crate::{RgbImage, NO_OBJECT};
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};
use octrace_core::palette::{Coarse, Dither, Gray, Quantizer, Scan};
use octrace_core::scene::ObjectId;

/// How to map the image onto a colour table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PaletteMode {
    /// Truecolour: no colour table.
    None,
    /// The thesis's hash-scan colour table, built from the image.
    Scan,
    /// Ordered dithering onto the 6×6×6 colour cube.
    Dither,
    /// Dithering with outlines around objects.
    Coarse,
    /// 256 gray levels by luma.
    Gray,
}

impl PaletteMode {
    /// Every mode, in the order the studio's page numbers them.
    pub const ALL: [PaletteMode; 5] =
        [PaletteMode::None, PaletteMode::Scan, PaletteMode::Dither, PaletteMode::Coarse, PaletteMode::Gray];

    /// The mode's name on host-sim's command line (`--palette`).
    pub fn name(self) -> &'static str {
        match self {
            PaletteMode::None => "none",
            PaletteMode::Scan => "scan",
            PaletteMode::Dither => "dither",
            PaletteMode::Coarse => "coarse",
            PaletteMode::Gray => "gray",
        }
    }
}

/// The image in `mode`: indexed, with the colour table up to its last
/// entry in use, or the truecolour image itself for `None`. `objects` is
/// the object under each pixel, or [`NO_OBJECT`].
///
/// ```
/// use octrace_images::palette::{apply, PaletteMode};
/// use octrace_images::{formats::Image, RgbImage, NO_OBJECT};
///
/// let image = RgbImage { width: 2, height: 1, data: vec![0, 0, 0, 255, 255, 255] };
/// let Image::Indexed { palette, indices, .. } = apply(&image, &[NO_OBJECT; 2], PaletteMode::Gray) else {
///     unreachable!("a palette mode gives an indexed image")
/// };
/// assert_eq!((palette[indices[0] as usize], palette[indices[1] as usize]), ([0; 3], [255; 3]));
/// ```
pub fn apply(image: &RgbImage, objects: &[u32], mode: PaletteMode) -> Image {
    match mode {
        PaletteMode::None => Image::Rgb(image.clone()),
        PaletteMode::Gray => indexed(image, objects, &mut Gray),
        PaletteMode::Dither => indexed(image, objects, &mut Dither),
        PaletteMode::Coarse => {
            let mut above = vec![0u32; image.width as usize];
            indexed(image, objects, &mut Coarse::new(&mut above))
        }
        PaletteMode::Scan => {
            let mut scan = learn(image, Scan::new());
            scan.freeze();
            indexed(image, objects, &mut scan)
        }
    }
}

/// The first pass of `scan`: learns every pixel, again with a closeness
/// limit half as large again while the table overflows.
fn learn(image: &RgbImage, mut scan: Scan) -> Scan {
    loop {
        for p in image.data.chunks(3) {
            scan.learn(Rgb888::new(p[0], p[1], p[2]));
        }
        // Past 3·255², every colour is close to every entry.
        if !scan.overflowed() || scan.closeness() > 3 * 255 * 255 {
            return scan;
        }
        scan = Scan::with_closeness(scan.closeness() * 3 / 2);
    }
}

/// Every pixel through `quantizer`, in raster order.
fn indexed(image: &RgbImage, objects: &[u32], quantizer: &mut impl Quantizer) -> Image {
    let width = image.width.max(1);
    let indices: Vec<u8> = image
        .data
        .chunks(3)
        .enumerate()
        .map(|(i, p)| {
            let object = objects.get(i).copied().filter(|&o| o != NO_OBJECT).map(ObjectId);
            quantizer.quantize(i as u32 % width, i as u32 / width, Rgb888::new(p[0], p[1], p[2]), object)
        })
        .collect();
    let entries = indices.iter().max().map_or(1, |&m| m as usize + 1);
    let palette = quantizer.table()[..entries].iter().map(|c| [c.r(), c.g(), c.b()]).collect();
    Image::Indexed { width: image.width, height: image.height, palette, indices }
}

/// Distinct colours an image shows.
pub fn colors_used(image: &Image) -> usize {
    let rgb = image.to_rgb();
    let mut seen: Vec<[u8; 3]> = rgb.data.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
    seen.sort_unstable();
    seen.dedup();
    seen.len()
}

/// Peak signal-to-noise ratio of `b` against `a` in dB over all channels
/// (infinite for identical images).
pub fn psnr(a: &RgbImage, b: &RgbImage) -> f64 {
    let n = a.data.len().max(1) as f64;
    let squared: f64 = a.data.iter().zip(&b.data).map(|(&x, &y)| (x as f64 - y as f64).powi(2)).sum();
    if squared == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / (squared / n)).log10()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> RgbImage {
        let mut img = RgbImage::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let i = 3 * (y * w + x) as usize;
                img.data[i..i + 3].copy_from_slice(&f(x, y));
            }
        }
        img
    }

    #[test]
    fn one_colour_images() {
        for (w, h) in [(1, 1), (5, 3)] {
            let img = image(w, h, |_, _| [90, 30, 200]);
            let objects = vec![NO_OBJECT; (w * h) as usize];
            for mode in PaletteMode::ALL {
                let out = apply(&img, &objects, mode);
                assert_eq!((out.width(), out.height()), (w, h));
                if mode == PaletteMode::Scan {
                    // One colour, one entry, shown exactly.
                    assert_eq!(out.to_rgb(), img);
                    assert_eq!(colors_used(&out), 1);
                }
            }
        }
    }

    #[test]
    fn scan_with_more_than_256_colours_uses_the_whole_table() {
        let img = image(64, 64, |x, y| [(x * 4) as u8, (y * 4) as u8, ((x + y) * 2) as u8]);
        let out = apply(&img, &vec![NO_OBJECT; 64 * 64], PaletteMode::Scan);
        let Image::Indexed { palette, .. } = &out else { panic!("indexed") };
        assert!(palette.len() <= 256);
        let (used, quality) = (colors_used(&out), psnr(&img, &out.to_rgb()));
        assert!(used > 128 && quality > 25.0, "{used} colours, {quality:.1} dB");
        // The thesis's single pass fills the table with the first rows'
        // colours: two passes do much better on such an image.
        let mut one_pass = Scan::new();
        let streamed = indexed(&img, &vec![NO_OBJECT; 64 * 64], &mut one_pass);
        let single = psnr(&img, &streamed.to_rgb());
        println!("gradient: one pass {single:.1} dB, two passes {quality:.1} dB");
        assert!(single + 5.0 < quality, "one pass {single:.1} dB, two {quality:.1} dB");
    }

    #[test]
    fn gray_is_luma_and_coarse_draws_outlines() {
        let img = image(4, 2, |_, _| [255, 255, 255]);
        let gray = apply(&img, &[NO_OBJECT; 8], PaletteMode::Gray);
        assert!(gray.to_rgb().data.iter().all(|&v| v == 255));
        let objects = [0, 0, 1, 1, 0, 0, 1, 1];
        let coarse = apply(&img, &objects, PaletteMode::Coarse);
        let Image::Indexed { indices, .. } = coarse else { panic!("indexed") };
        assert_eq!(indices, [215, 215, 0, 215, 215, 215, 0, 215]);
    }
}
