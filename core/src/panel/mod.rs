//! Panels with few levels: one bit (`BinaryColor`, an SSD1306 OLED or
//! black-and-white e-paper), 4 and 16 grays (`Gray2`, `Gray4`: SSD1327-like
//! OLEDs, gray e-paper) and black/white/red e-paper ([`BlackWhiteRed`]),
//! shown dithered, streaming in raster order without a framebuffer.
//!
//! A traced image drawn into such a display ([`TracedImage`](crate::TracedImage),
//! through `scene.image_for(&display)`) is dithered by the method its
//! colour type's panel calls for ([`TracedColor`]): nothing to write beyond
//! the draw.
//!
//! ```
//! use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::BinaryColor, prelude::*};
//! use octrace_core::{profile::Board16K, Raytracer};
//!
//! let mut raytracer = Raytracer::<Board16K>::new();
//! // A mid-gray background: a cut at mid-gray would show it all black.
//! let scene = raytracer.load("BACKGROUND 0.45 0.45 0.45\n")?;
//! let mut display = MockDisplay::<BinaryColor>::new();
//! Image::new(&scene.image_for(&display), Point::zero()).draw(&mut display)?;
//! let lit = display.affected_area().points().filter(|&p| display.get_pixel(p) == Some(BinaryColor::On)).count();
//! // 0.45 shows as gray 177 (the default gamma 2.2): 69 % of 64 × 64 lit.
//! assert!((2800..=2950).contains(&lit), "{lit}");
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```
//!
//! # The methods
//!
//! [`Dithering`] names them; each works on the gray (BT.601 luma, as
//! embedded-graphics converts colour to gray) of the display values, in
//! integers:
//!
//! - [`Dithering::FsPe`], the default: Floyd–Steinberg error diffusion plus
//!   a feedback of each pixel's *pure* error (its gray less the level
//!   shown) to the same four neighbours, in raster order. Seen through a
//!   blur of one pixel (an eye at reading distance), it is the closest of
//!   the four to the picture: 30.4, 30.4 and 31.1 dB on one bit for fig5_1,
//!   fig5_3 and fig5_5 at 128×64, 40 dB on four grays (BENCHMARKS.md).
//! - [`Dithering::FloydSteinberg`]: the classic error diffusion, raster
//!   order.
//! - [`Dithering::Bayer`]: ordered dithering with the 4×4 Bayer matrix
//!   ([`BAYER_4X4`]); a pixel's level depends on its colour and position
//!   alone.
//! - [`Dithering::Nearest`]: no dithering, the nearest level, as
//!   embedded-graphics converts a colour (`From<Rgb888>`).
//!
//! Error diffusion keeps a row of `i16` accumulators per channel
//! ([`Panel::error_words`]: 256 bytes for a 128-wide one-bit panel). An
//! image keeps it on the draw's stack, 512 bytes for up to 256 words (a
//! one-bit or gray panel up to 256 pixels wide, black/white/red up to 128),
//! else [`IMAGE_ERROR_WORDS`] (1.6 KiB: rows up to 800 pixels, 400 on
//! black/white/red), or uses storage the caller gives
//! ([`TracedImage::error_rows`](crate::TracedImage::error_rows)).
//!
//! # Sub-images, bands and other orders
//!
//! Error diffusion runs in raster order over the area drawn: a sub-image
//! (`draw_sub_image`) is dithered as an image of its own, its first row
//! with no error carried in. Ordered dithering and the nearest level depend
//! on each pixel alone, so any part of the image is the whole one's pixels.
//! To draw an image's rows in several calls, or from several cores, with
//! the whole image's dither, send its rows in order through one
//! [`Dithered`] target, which carries the error from each band of rows to
//! the next. Drawn in no order at all (a progressive order's passes, an
//! animation's changed tiles), a panel is dithered by Bayer
//! ([`Dithered::ordered`]): a [`TracedImage`](crate::TracedImage) drawn
//! in the progressive order, or a frame's tiles, does so.
//!
//! # One bit
//!
//! `BinaryColor::On` is the bright level (a lit OLED pixel), as
//! embedded-graphics converts colours. An e-paper driver whose `On` is ink
//! shows the picture inverted: map its colours as below.
//!
//! # Three-colour e-paper
//!
//! [`BlackWhiteRed`] is dithered after each colour is brought into what
//! black, white and red can mix (a blue becomes a dark gray). A driver's
//! own colour type takes it through a small adapter, here for
//! `epd-waveshare`'s `TriColor`:
//!
//! ```
//! use embedded_graphics::{pixelcolor::Rgb888, prelude::*, primitives::Rectangle};
//! use octrace_core::panel::BlackWhiteRed;
//! # #[derive(Clone, Copy, PartialEq, Debug)] enum TriColor { Black, White, Chromatic }
//! # impl PixelColor for TriColor { type Raw = (); }
//!
//! /// A `TriColor` display seen as a `BlackWhiteRed` one.
//! struct Tri<'a, D>(&'a mut D);
//!
//! fn tri(color: BlackWhiteRed) -> TriColor {
//!     match color {
//!         BlackWhiteRed::Black => TriColor::Black,
//!         BlackWhiteRed::White => TriColor::White,
//!         BlackWhiteRed::Red => TriColor::Chromatic,
//!     }
//! }
//!
//! impl<D: DrawTarget<Color = TriColor>> DrawTarget for Tri<'_, D> {
//!     type Color = BlackWhiteRed;
//!     type Error = D::Error;
//!     fn draw_iter<I: IntoIterator<Item = Pixel<BlackWhiteRed>>>(&mut self, pixels: I) -> Result<(), D::Error> {
//!         self.0.draw_iter(pixels.into_iter().map(|Pixel(p, c)| Pixel(p, tri(c))))
//!     }
//!     fn fill_contiguous<I: IntoIterator<Item = BlackWhiteRed>>(&mut self, area: &Rectangle, colors: I) -> Result<(), D::Error> {
//!         self.0.fill_contiguous(area, colors.into_iter().map(tri))
//!     }
//! }
//!
//! impl<D: DrawTarget> Dimensions for Tri<'_, D> {
//!     fn bounding_box(&self) -> Rectangle {
//!         self.0.bounding_box()
//!     }
//! }
//! // Then: let mut panel = Tri(&mut epd);
//! //       Image::new(&scene.image_for(&panel), Point::zero()).draw(&mut panel)?;
//! ```
//!
//! Invariants: integers only, so the same colours in the same order give
//! the same levels on every target; a level is below its panel's
//! [`Panel::levels`]; error diffusion's accumulators saturate, never wrap.

mod black_white_red;
mod diffusion;
mod dithered;
mod ditherer;
mod divisor;

pub use black_white_red::BlackWhiteRed;
pub use dithered::Dithered;
pub use ditherer::Ditherer;

use crate::scene::ObjectId;
use divisor::Divisor;

use core::fmt;
use embedded_graphics_core::geometry::Point;
use embedded_graphics_core::pixelcolor::{
    Bgr555, Bgr565, Bgr666, Bgr888, BinaryColor, Gray2, Gray4, Gray8, GrayColor, PixelColor, Rgb555, Rgb565, Rgb666,
    Rgb888,
};

/// A display with few levels, which octrace dithers onto.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Panel {
    /// One bit: off and on, black and white (`BinaryColor`).
    Mono,
    /// Four grays: 0, 85, 170, 255 (`Gray2`).
    Gray2,
    /// Sixteen grays, 17 apart (`Gray4`).
    Gray4,
    /// Black, white and red e-paper ([`BlackWhiteRed`]).
    BlackWhiteRed,
}

impl Panel {
    /// Every panel.
    pub const ALL: [Panel; 4] = [Panel::Mono, Panel::Gray2, Panel::Gray4, Panel::BlackWhiteRed];

    /// How many levels it shows: its level numbers are below this.
    pub const fn levels(self) -> u8 {
        match self {
            Panel::Mono => 2,
            Panel::Gray2 => 4,
            Panel::Gray4 => 16,
            Panel::BlackWhiteRed => 3,
        }
    }

    /// The `i16`s error diffusion keeps for a region `width` pixels wide:
    /// a row for each channel (gray; or red and the rest, for
    /// black/white/red).
    ///
    /// ```
    /// use octrace_core::panel::Panel;
    ///
    /// assert_eq!(Panel::Mono.error_words(128), 128);
    /// assert_eq!(Panel::BlackWhiteRed.error_words(296), 592);
    /// ```
    pub const fn error_words(self, width: u32) -> usize {
        let channels = match self {
            Panel::BlackWhiteRed => 2,
            _ => 1,
        };
        channels * width as usize
    }

    /// The colour level `level` shows (black for a level it does not
    /// have).
    ///
    /// ```
    /// use embedded_graphics::pixelcolor::Rgb888;
    /// use octrace_core::panel::Panel;
    ///
    /// assert_eq!(Panel::Gray2.color(1), Rgb888::new(85, 85, 85));
    /// assert_eq!(Panel::BlackWhiteRed.color(2), Rgb888::new(255, 0, 0));
    /// ```
    pub fn color(self, level: u8) -> Rgb888 {
        match self {
            Panel::BlackWhiteRed => BlackWhiteRed::ALL.get(level as usize).copied().unwrap_or_default().into(),
            gray => {
                let v = if level < gray.levels() { gray.gray_value(level) as u8 } else { 0 };
                Rgb888::new(v, v, v)
            }
        }
    }

    /// The level of the pixel at `position` showing `color`, by a method
    /// that needs nothing but the pixel: [`Dithering::Bayer`] or
    /// [`Dithering::Nearest`] (the diffusing methods give the nearest
    /// level here).
    pub fn level_at(self, dithering: Dithering, position: Point, color: Rgb888) -> u8 {
        match dithering {
            Dithering::Bayer => {
                // Two's complement keeps the pattern across negative positions.
                let threshold = BAYER_4X4[(position.y & 3) as usize][(position.x & 3) as usize] as u32;
                self.ordered(color, threshold)
            }
            _ => self.nearest(color),
        }
    }

    /// The nearest level: embedded-graphics' conversion (`From<Rgb888>`).
    fn nearest(self, color: Rgb888) -> u8 {
        match self {
            Panel::BlackWhiteRed => BlackWhiteRed::from(color) as u8,
            gray => Divisor::BY_255.quotient(luma(color) as u32 * (gray.levels() as u32 - 1) + 127) as u8,
        }
    }

    /// Ordered dithering with `threshold` of 0 to 15: the level below the
    /// value, or the one above where the value's fraction of the step
    /// beats `(threshold + ½) / 16`.
    fn ordered(self, color: Rgb888, threshold: u32) -> u8 {
        // 32 × fraction / 255 against 2 threshold + 1.
        let bar = (2 * threshold + 1) * 255;
        match self {
            Panel::BlackWhiteRed => {
                // Of the mixable colour (r, m), a share m / 255 is white, (r − m) / 255
                // red and the rest black: white below m, red below r.
                let [r, m] = black_white_red::project(color);
                let shown = if m as u32 * 32 > bar {
                    BlackWhiteRed::White
                } else if r as u32 * 32 > bar {
                    BlackWhiteRed::Red
                } else {
                    BlackWhiteRed::Black
                };
                shown as u8
            }
            gray => {
                let scaled = luma(color) as u32 * (gray.levels() as u32 - 1);
                let level = Divisor::BY_255.quotient(scaled);
                let fraction = scaled - 255 * level;
                (level + (fraction * 32 > bar) as u32) as u8
            }
        }
    }

    /// The step between levels, in gray (or red, or green and blue).
    const fn step(self) -> i32 {
        match self {
            Panel::Mono | Panel::BlackWhiteRed => 255,
            Panel::Gray2 => 85,
            Panel::Gray4 => 17,
        }
    }

    /// Division by the step in 1/16 gray, each panel's made when the crate
    /// compiles: a panel known only when the program runs must not bring
    /// the division back.
    const fn step_divisor(self) -> Divisor {
        match self {
            Panel::Mono | Panel::BlackWhiteRed => const { Divisor::new(16 * 255) },
            Panel::Gray2 => const { Divisor::new(16 * 85) },
            Panel::Gray4 => const { Divisor::new(16 * 17) },
        }
    }

    /// A gray panel's value of `level`, 0 to 255.
    fn gray_value(self, level: u8) -> i32 {
        level as i32 * self.step()
    }

    /// A gray panel's level for `v`, a value with its error in 1/16 gray:
    /// one bit lights from 128, more levels take the nearest (ties up).
    #[inline]
    fn gray_level_of_q4(self, v: i32) -> u8 {
        match self {
            Panel::Mono => (v >= 128 << 4) as u8,
            gray => {
                let (step, top) = (gray.step() << 4, gray.levels() as i32 - 1);
                match v + step / 2 {
                    x if x <= 0 => 0,
                    x if x >= top * step => top as u8,
                    x => gray.step_divisor().quotient(x as u32) as u8,
                }
            }
        }
    }
}

/// How a panel's levels show a picture. The default is [`Dithering::FsPe`].
///
/// ```
/// use octrace_core::panel::Dithering;
///
/// assert_eq!(Dithering::default(), Dithering::FsPe);
/// assert_eq!(Dithering::from_name("Bayer"), Some(Dithering::Bayer));
/// assert_eq!(Dithering::FloydSteinberg.name(), "fs");
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Dithering {
    /// Floyd–Steinberg with pure-error feedback (module docs): the closest
    /// to the picture.
    #[default]
    FsPe,
    /// Floyd–Steinberg error diffusion, raster order.
    FloydSteinberg,
    /// Ordered, with the 4×4 Bayer matrix.
    Bayer,
    /// None: each pixel the nearest level.
    Nearest,
}

impl Dithering {
    /// Every method, the default first.
    pub const ALL: [Dithering; 4] = [Dithering::FsPe, Dithering::FloydSteinberg, Dithering::Bayer, Dithering::Nearest];

    /// The method's name: `fs-pe`, `fs`, `bayer`, `nearest`.
    pub const fn name(self) -> &'static str {
        match self {
            Dithering::FsPe => "fs-pe",
            Dithering::FloydSteinberg => "fs",
            Dithering::Bayer => "bayer",
            Dithering::Nearest => "nearest",
        }
    }

    /// The method its name stands for (case-insensitive).
    pub fn from_name(name: &str) -> Option<Dithering> {
        Dithering::ALL.into_iter().find(|d| d.name().eq_ignore_ascii_case(name))
    }

    /// Whether it diffuses error (so needs the pixels in raster order and
    /// a row of storage).
    pub const fn diffuses(self) -> bool {
        matches!(self, Dithering::FsPe | Dithering::FloydSteinberg)
    }
}

impl fmt::Display for Dithering {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The longest error row a [`TracedImage`](crate::TracedImage) keeps on
/// the stack of its draw for error diffusion, in `i16`s: rows up to 800
/// pixels wide (400 on black/white/red; a row of up to 256 words takes
/// only 512 bytes). A wider image needs
/// [`TracedImage::error_rows`](crate::TracedImage::error_rows).
pub const IMAGE_ERROR_WORDS: usize = 800;

/// The 4×4 Bayer matrix: thresholds 0 to 15, each once, spread so that
/// every 2×2 block holds an even spread (`[y % 4][x % 4]`).
pub const BAYER_4X4: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];

/// A colour a traced image draws in: how each traced (`Rgb888`) pixel
/// becomes one. Implemented for every embedded-graphics colour type and
/// [`BlackWhiteRed`]: truecolour ones convert each pixel (`From<Rgb888>`);
/// `BinaryColor`, `Gray2`, `Gray4` and [`BlackWhiteRed`] are [`Panel`]s,
/// dithered.
///
/// A colour type of your own that converts from `Rgb888` draws by that
/// conversion once it says so, in one line; one that is a panel names it.
///
/// ```
/// use embedded_graphics::pixelcolor::{raw::RawU8, PixelColor, Rgb888, RgbColor};
/// use octrace_core::panel::TracedColor;
///
/// #[derive(Clone, Copy, PartialEq, Debug)]
/// struct Sepia(u8);
/// impl PixelColor for Sepia {
///     type Raw = RawU8;
/// }
/// impl From<Rgb888> for Sepia {
///     fn from(c: Rgb888) -> Self {
///         Sepia(c.r() / 3 + c.g() / 3 + c.b() / 3)
///     }
/// }
/// impl TracedColor for Sepia {}
/// ```
pub trait TracedColor: PixelColor + From<Rgb888> {
    /// The panel a display of this colour is, dithered; `None` (the
    /// default): each pixel converted.
    const PANEL: Option<Panel> = None;

    /// The colour of level `level` of [`TracedColor::PANEL`].
    fn from_level(level: u8) -> Self {
        Self::from(Self::PANEL.map_or(Rgb888::new(0, 0, 0), |panel| panel.color(level)))
    }

    /// A traced pixel's colour (`color`, the object it sees `object`) in
    /// this colour: converted, by default.
    #[inline(always)]
    fn traced(color: Rgb888, object: Option<ObjectId>) -> Self {
        let _ = object;
        Self::from(color)
    }
}

impl TracedColor for Rgb555 {}
impl TracedColor for Bgr555 {}
impl TracedColor for Rgb565 {}
impl TracedColor for Bgr565 {}
impl TracedColor for Rgb666 {}
impl TracedColor for Bgr666 {}
impl TracedColor for Rgb888 {}
impl TracedColor for Bgr888 {}
impl TracedColor for Gray8 {}

impl TracedColor for BinaryColor {
    const PANEL: Option<Panel> = Some(Panel::Mono);

    fn from_level(level: u8) -> Self {
        if level == 0 {
            BinaryColor::Off
        } else {
            BinaryColor::On
        }
    }
}

impl TracedColor for Gray2 {
    const PANEL: Option<Panel> = Some(Panel::Gray2);

    fn from_level(level: u8) -> Self {
        Gray2::new(level)
    }
}

impl TracedColor for Gray4 {
    const PANEL: Option<Panel> = Some(Panel::Gray4);

    fn from_level(level: u8) -> Self {
        Gray4::new(level)
    }
}

impl TracedColor for BlackWhiteRed {
    const PANEL: Option<Panel> = Some(Panel::BlackWhiteRed);

    fn from_level(level: u8) -> Self {
        BlackWhiteRed::ALL.get(level as usize).copied().unwrap_or_default()
    }
}

/// Error diffusion was given fewer `i16`s than its region needs
/// ([`Panel::error_words`]).
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ErrorRowTooShort {
    /// What the region needs.
    pub needed: usize,
    /// What was given.
    pub given: usize,
}

impl fmt::Display for ErrorRowTooShort {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "error diffusion needs a row of {} accumulators here, but was given room for {}",
            self.needed, self.given
        )
    }
}

impl core::error::Error for ErrorRowTooShort {}

/// The gray of `color`, 0 to 255: BT.601 luma as embedded-graphics computes
/// it (and [`palette::Gray`](crate::palette::Gray)).
#[inline]
fn luma(color: Rgb888) -> u8 {
    Gray8::from(color).luma()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gray(v: u8) -> Rgb888 {
        Rgb888::new(v, v, v)
    }

    #[test]
    fn nearest_is_embedded_graphics_conversion() {
        for v in 0..=255u8 {
            for color in [gray(v), Rgb888::new(v, 255 - v, v / 3), Rgb888::new(v / 2, v, 200)] {
                let at = |panel: Panel| panel.level_at(Dithering::Nearest, Point::zero(), color);
                assert_eq!(BinaryColor::from_level(at(Panel::Mono)), BinaryColor::from(color), "{color:?}");
                assert_eq!(Gray2::from_level(at(Panel::Gray2)), Gray2::from(color), "{color:?}");
                assert_eq!(Gray4::from_level(at(Panel::Gray4)), Gray4::from(color), "{color:?}");
                assert_eq!(BlackWhiteRed::from_level(at(Panel::BlackWhiteRed)), BlackWhiteRed::from(color));
            }
        }
    }

    #[test]
    fn every_level_converts_to_itself() {
        // A level's own colour, converted as any colour is, is that level.
        fn check<C: TracedColor + fmt::Debug>(panel: Panel) {
            assert_eq!(C::PANEL, Some(panel));
            for level in 0..panel.levels() {
                assert_eq!(C::from(panel.color(level)), C::from_level(level), "{panel:?} {level}");
            }
        }
        check::<BinaryColor>(Panel::Mono);
        check::<Gray2>(Panel::Gray2);
        check::<Gray4>(Panel::Gray4);
        check::<BlackWhiteRed>(Panel::BlackWhiteRed);
        assert_eq!(Rgb565::PANEL, None);
        assert_eq!(Gray8::PANEL, None);
    }

    #[test]
    fn bayer_is_the_issues_threshold_and_keeps_a_tone() {
        // One bit: white where g > (B + ½) · 255 / 16.
        for v in 0..=255u8 {
            for (y, row) in BAYER_4X4.iter().enumerate() {
                for (x, &b) in row.iter().enumerate() {
                    let level = Panel::Mono.level_at(Dithering::Bayer, Point::new(x as i32, y as i32), gray(v));
                    let expected = (v as f64) > (b as f64 + 0.5) * 255.0 / 16.0;
                    assert_eq!(level == 1, expected, "{v} at ({x}, {y})");
                }
            }
        }
        // Four grays: 100 is 1 and 15/85 of a step, so 3 of 16 pixels go up.
        let ups = (0..16)
            .filter(|i| Panel::Gray2.level_at(Dithering::Bayer, Point::new(i % 4 - 4, i / 4 + 8), gray(100)) == 2);
        assert_eq!(ups.count(), 3);
    }

    #[test]
    fn bayer_holds_each_threshold_once() {
        let mut seen = [false; 16];
        for &b in BAYER_4X4.iter().flatten() {
            seen[b as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn every_name_reads_back() {
        for dithering in Dithering::ALL {
            assert_eq!(Dithering::from_name(dithering.name()), Some(dithering));
        }
        assert_eq!(Dithering::from_name("floyd"), None);
    }

    #[test]
    fn the_levels_of_a_q4_value_are_nearest_ties_up() {
        assert_eq!(Panel::Mono.gray_level_of_q4(2047), 0);
        assert_eq!(Panel::Mono.gray_level_of_q4(2048), 1);
        // Four grays: halfway between 85 and 170 is 127.5, i.e. 2040 in Q4.
        assert_eq!(Panel::Gray2.gray_level_of_q4(2039), 1);
        assert_eq!(Panel::Gray2.gray_level_of_q4(2040), 2);
        assert_eq!(Panel::Gray2.gray_level_of_q4(-10_000), 0);
        assert_eq!(Panel::Gray4.gray_level_of_q4(30_000), 15);
        assert_eq!(Panel::Gray2.color(7), Rgb888::new(0, 0, 0));
    }
}
