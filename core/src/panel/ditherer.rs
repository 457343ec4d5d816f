//! The [`Ditherer`]: one region of an image, its pixels in raster order,
//! each given its panel level at once.
//!
//! Invariants: a level is always below the panel's [`Panel::levels`]; the
//! error rows are `channels × width` `i16`s of the caller's storage, all
//! zero at the region's top; the same pixels in the same order give the
//! same levels on every target.

use super::black_white_red::project;
use super::diffusion::Accumulators;
use super::{BlackWhiteRed, Dithering, ErrorRowTooShort, Panel};
use embedded_graphics_core::geometry::Point;
use embedded_graphics_core::pixelcolor::Rgb888;

/// Dithers a region of an image `width` pixels wide, its pixels given in
/// raster order (rows top to bottom, each left to right), into a panel's
/// levels, each at once: the state a dithered draw keeps. Error diffusion
/// needs a row of accumulators per channel, `i16`s in storage the caller
/// owns ([`Panel::error_words`]); ordered dithering and the nearest level
/// need none.
///
/// What octrace's images and [`Dithered`](super::Dithered) are made of;
/// use it directly to dither pixels of your own, a finished image say.
///
/// ```
/// use embedded_graphics::{pixelcolor::Rgb888, prelude::*};
/// use octrace_core::panel::{Ditherer, Dithering, Panel};
///
/// // A 4×2 region of 25 % gray on a one-bit panel: 2 of the 8 pixels lit.
/// let mut rows = [0i16; Panel::Mono.error_words(4)];
/// let mut ditherer = Ditherer::new(Panel::Mono, Dithering::FsPe, Point::zero(), 4, &mut rows)?;
/// let lit = (0..8).filter(|_| ditherer.next(Rgb888::new(64, 64, 64)) == 1).count();
/// assert_eq!(lit, 2);
/// assert_eq!(ditherer.position(), Point::new(0, 2));
/// # Ok::<(), octrace_core::panel::ErrorRowTooShort>(())
/// ```
#[derive(Debug)]
pub struct Ditherer<'b> {
    panel: Panel,
    dithering: Dithering,
    /// The region's left column and the next pixel.
    left: i32,
    position: Point,
    width: u32,
    /// The next row's accumulators, a row per channel, in Q4.
    rows: &'b mut [i16],
    channels: [Accumulators; 2],
}

impl<'b> Ditherer<'b> {
    /// A ditherer for the region of `width` pixels a row from `top_left`
    /// (in the image's coordinates, which ordered dithering's pattern
    /// follows), its error rows in `rows`: at least
    /// [`Panel::error_words`]`(width)` for error diffusion.
    pub fn new(
        panel: Panel,
        dithering: Dithering,
        top_left: Point,
        width: u32,
        rows: &'b mut [i16],
    ) -> Result<Self, ErrorRowTooShort> {
        let needed = if dithering.diffuses() { panel.error_words(width) } else { 0 };
        let given = rows.len();
        let rows = rows.get_mut(..needed).ok_or(ErrorRowTooShort { needed, given })?;
        Ok(Ditherer::with_rows(panel, dithering, top_left, width, rows))
    }

    /// A ditherer by [`Dithering::Bayer`], which keeps no rows.
    pub(super) fn ordered(panel: Panel, top_left: Point, width: u32) -> Ditherer<'static> {
        Ditherer::with_rows(panel, Dithering::Bayer, top_left, width, &mut [])
    }

    /// A ditherer over `rows`, as many as it needs.
    fn with_rows(panel: Panel, dithering: Dithering, top_left: Point, width: u32, rows: &'b mut [i16]) -> Self {
        let mut ditherer = Ditherer {
            panel,
            dithering,
            left: top_left.x,
            position: top_left,
            width,
            rows,
            channels: [Accumulators::default(); 2],
        };
        ditherer.restart(top_left.y);
        ditherer
    }

    /// The panel it dithers for.
    pub fn panel(&self) -> Panel {
        self.panel
    }

    /// The method.
    pub fn dithering(&self) -> Dithering {
        self.dithering
    }

    /// The region's width.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// The region's left column.
    pub(super) fn left(&self) -> i32 {
        self.left
    }

    /// Where the next pixel is.
    pub fn position(&self) -> Point {
        self.position
    }

    /// Starts the region again at row `top`, with no error carried.
    pub fn restart(&mut self, top: i32) {
        self.rows.fill(0);
        self.channels = [Accumulators::default(); 2];
        self.position = Point::new(self.left, top);
    }

    /// The level of the next pixel, which shows `color`.
    #[inline]
    pub fn next(&mut self, color: Rgb888) -> u8 {
        let column = self.position.x.abs_diff(self.left);
        let level = match self.dithering {
            // (A region of no columns has no pixels: whatever comes is cut.)
            _ if column >= self.width => self.panel.level_at(Dithering::Nearest, self.position, color),
            Dithering::FsPe => self.diffuse(column as usize, color, true),
            Dithering::FloydSteinberg => self.diffuse(column as usize, color, false),
            Dithering::Bayer | Dithering::Nearest => self.panel.level_at(self.dithering, self.position, color),
        };
        self.position.x = self.position.x.saturating_add(1);
        if column + 1 == self.width {
            if self.dithering.diffuses() {
                self.end_row();
            }
            self.position = Point::new(self.left, self.position.y + 1);
        }
        level
    }

    /// The level of the pixel at column `x` of the region by error
    /// diffusion, its errors spread; `pure`: FS-PE's pure error too.
    #[inline]
    fn diffuse(&mut self, x: usize, color: Rgb888, pure: bool) -> u8 {
        let pure = pure as i32;
        match self.panel {
            Panel::BlackWhiteRed => {
                let [red, rest] = project(color);
                let (red_row, rest_row) = self.rows.split_at_mut(self.width as usize);
                let [red_channel, rest_channel] = &mut self.channels;
                let v = [red_channel.value(red_row, x, red), rest_channel.value(rest_row, x, rest)];
                let shown = BlackWhiteRed::nearest_mixed(v[0], v[1], 255 << 4);
                let [o_red, o_rest] = shown.red_and_rest();
                red_channel.push(red_row, x, v[0] - (o_red << 4), pure * (red - o_red));
                rest_channel.push(rest_row, x, v[1] - (o_rest << 4), pure * (rest - o_rest));
                shown as u8
            }
            gray => {
                let value = super::luma(color) as i32;
                let channel = &mut self.channels[0];
                let v = channel.value(self.rows, x, value);
                let level = gray.gray_level_of_q4(v);
                let shown = gray.gray_value(level);
                channel.push(self.rows, x, v - (shown << 4), pure * (value - shown));
                level
            }
        }
    }

    /// Closes the row of every channel in use.
    fn end_row(&mut self) {
        let width = self.width as usize;
        for (channel, row) in self.channels.iter_mut().zip(self.rows.chunks_exact_mut(width)) {
            channel.end_row(row, width - 1);
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// Every level of a `width`-wide picture of `colors`, dithered.
    fn dither(panel: Panel, dithering: Dithering, width: u32, colors: &[Rgb888]) -> Vec<u8> {
        let mut rows = std::vec![0i16; panel.error_words(width)];
        let mut ditherer = Ditherer::new(panel, dithering, Point::zero(), width, &mut rows).unwrap();
        colors.iter().map(|&c| ditherer.next(c)).collect()
    }

    fn gray(v: u8) -> Rgb888 {
        Rgb888::new(v, v, v)
    }

    #[test]
    fn too_little_storage_is_an_error_naming_what_is_needed() {
        let mut rows = [0i16; 9];
        let e = Ditherer::new(Panel::BlackWhiteRed, Dithering::FsPe, Point::zero(), 5, &mut rows).unwrap_err();
        assert_eq!(e, ErrorRowTooShort { needed: 10, given: 9 });
        // Ordered dithering needs none.
        assert!(Ditherer::new(Panel::BlackWhiteRed, Dithering::Bayer, Point::zero(), 5, &mut []).is_ok());
    }

    #[test]
    fn a_flat_tone_keeps_its_mean_on_every_panel() {
        // 40×40 of one gray: the mean level shown is the gray's, within
        // what leaves at the edges.
        for panel in [Panel::Mono, Panel::Gray2, Panel::Gray4] {
            for dithering in Dithering::ALL {
                for v in [3u8, 16, 54, 75, 128, 182, 250] {
                    let levels = dither(panel, dithering, 40, &[gray(v); 1600]);
                    let mean: f64 =
                        levels.iter().map(|&l| panel.gray_value(l) as f64).sum::<f64>() / levels.len() as f64;
                    // The nearest level is off by half a step at most; a 4×4
                    // pattern has 17 tones, a 32nd of a step from any value.
                    let allowed = match dithering {
                        Dithering::Nearest => panel.step() as f64 / 2.0,
                        Dithering::Bayer => panel.step() as f64 / 32.0,
                        _ => 2.5,
                    };
                    assert!((mean - v as f64).abs() <= allowed, "{panel:?} {dithering:?} {v}: {mean}");
                }
            }
        }
    }

    #[test]
    fn diffusion_has_no_dead_zone_near_a_level() {
        // Gray 3 on one bit: a few lit pixels, not all black (model-based
        // diffusion without the FS loop shows 1 to 16 as black).
        let lit = dither(Panel::Mono, Dithering::FsPe, 64, &[gray(3); 64 * 64]).iter().filter(|&&l| l == 1).count();
        assert!((40..=56).contains(&lit), "{lit} of 4096 lit, for 48 expected");
    }

    #[test]
    fn the_levels_are_the_panels() {
        let ramp: Vec<Rgb888> = (0..=255u8).flat_map(|v| [gray(v), Rgb888::new(v, 255 - v, v / 2)]).collect();
        for panel in Panel::ALL {
            for dithering in Dithering::ALL {
                assert!(dither(panel, dithering, 32, &ramp).iter().all(|&l| l < panel.levels()), "{panel:?}");
            }
        }
    }

    #[test]
    fn black_white_red_mixes_a_pink_from_all_three() {
        // (255, 128, 128): half red, half white, no black.
        let pink = Rgb888::new(255, 128, 128);
        for dithering in [Dithering::FsPe, Dithering::FloydSteinberg, Dithering::Bayer] {
            let levels = dither(Panel::BlackWhiteRed, dithering, 32, &[pink; 32 * 32]);
            let count = |c: BlackWhiteRed| levels.iter().filter(|&&l| l == c as u8).count();
            let (white, red) = (count(BlackWhiteRed::White), count(BlackWhiteRed::Red));
            assert!((500..=530).contains(&white) && (494..=524).contains(&red), "{dithering:?}: {white} {red}");
        }
        // A blue it cannot show becomes a dark gray (its projection), not red.
        let levels = dither(Panel::BlackWhiteRed, Dithering::FsPe, 32, &[Rgb888::new(0, 0, 255); 32 * 32]);
        assert!(levels.iter().all(|&l| l != BlackWhiteRed::Red as u8));
    }

    /// A 24×10 picture of many colours, written out the same way where the
    /// expected levels below were made.
    fn sample(x: u32, y: u32) -> Rgb888 {
        Rgb888::new(
            ((x * 37 + y * 11) % 256) as u8,
            ((x * x + 3 * y * y) % 256) as u8,
            ((255 + 512 - x * 13 - y * 7) % 256) as u8,
        )
    }

    #[test]
    fn diffusion_gives_the_independent_references_levels() {
        // Levels (hexadecimal) from the research's integer reference,
        // `intref.py`'s `FsPe` and `FsPeTri` in Python (Floyd–Steinberg:
        // its pure-error weights set to 0), written independently of this
        // code: fixed bits, the same on every target.
        let expected: [(Dithering, Panel, [&str; 10]); 8] = [
            (
                Dithering::FsPe,
                Panel::Mono,
                [
                    "000010100101010100101010",
                    "010100001001011010010110",
                    "000001100010110100101101",
                    "010100010101101010010110",
                    "000101100101011000111001",
                    "101010010111100011010100",
                    "010101101010110001110101",
                    "101010101110000110101001",
                    "011111010001010101100110",
                    "110100010101001110101010",
                ],
            ),
            (
                Dithering::FsPe,
                Panel::Gray2,
                [
                    "010111111112131201112221",
                    "011011201112221210213121",
                    "101111111121222201122221",
                    "011112201121312211122221",
                    "111121112122221101221211",
                    "111212111222221022232111",
                    "121212122223301111312112",
                    "212231212221010222321112",
                    "222222230211111223101222",
                    "232320010112112221212121",
                ],
            ),
            (
                Dithering::FsPe,
                Panel::Gray4,
                [
                    "2234466345689a882367a9a3",
                    "2243566346689b7a2457b8b4",
                    "334466744678ab89346ab9a4",
                    "335557846689a79b256a8ac5",
                    "455678456799c89346ab8a36",
                    "5567885688abc92358aca356",
                    "68889b688abce2357ab9a468",
                    "889aa789abc513569bdb367a",
                    "9abbd99b34664568be54579b",
                    "ccdd61335678669bd68579b5",
                ],
            ),
            (
                Dithering::FsPe,
                Panel::BlackWhiteRed,
                [
                    "010101201010121002021010",
                    "010012100010100101012110",
                    "001201201012212102221101",
                    "101012101010101000210110",
                    "010101020101210021011010",
                    "101012101012100102111001",
                    "010121010101210021101010",
                    "101121010112000210110101",
                    "101010101020101011101011",
                    "111110002012000110101010",
                ],
            ),
            (
                Dithering::FloydSteinberg,
                Panel::Mono,
                [
                    "000001000101010100011010",
                    "001010100010110100101010",
                    "000001001010110100101110",
                    "010101010101010101010110",
                    "001010001011101000110100",
                    "100101010101100011011001",
                    "010110101011101001101010",
                    "101010110110000110110011",
                    "111111010001001011001010",
                    "101100001010101110101010",
                ],
            ),
            (
                Dithering::FloydSteinberg,
                Panel::Gray2,
                [
                    "010111111112221201112221",
                    "011111111111222201122221",
                    "101111201122222201122221",
                    "110111211112212211122221",
                    "111121111222222011222211",
                    "111122111222220112222011",
                    "112222122222301112222112",
                    "222221212231011122321112",
                    "222222221111111223111122",
                    "223310111112112231111221",
                ],
            ),
            (
                Dithering::FloydSteinberg,
                Panel::Gray4,
                [
                    "2234466345689a792357b8a4",
                    "2334557345789b892467b8b3",
                    "234456745678ab8a2469c9b4",
                    "344567845689a79a357a79c5",
                    "44567845679ab8a2469b9a45",
                    "56678856799bc92358ac9357",
                    "67889a788abce2356ac9b468",
                    "889ab789abc52356abda357a",
                    "aabcc99b34663568bd63679b",
                    "bcdd52335679578cd68579b5",
                ],
            ),
            (
                Dithering::FloydSteinberg,
                Panel::BlackWhiteRed,
                [
                    "010101200101210102021101",
                    "001021210010120002221010",
                    "100101201012210102011110",
                    "010122100101010102110101",
                    "010101010101201020110101",
                    "101212010101100021110101",
                    "010101010121202010101010",
                    "101112101012001011110101",
                    "110110100122000111201011",
                    "011120010221010110101010",
                ],
            ),
        ];
        for (dithering, panel, rows) in expected {
            let colors: Vec<Rgb888> = (0..10).flat_map(|y| (0..24).map(move |x| sample(x, y))).collect();
            let levels = dither(panel, dithering, 24, &colors);
            let shown: Vec<std::string::String> =
                levels.chunks(24).map(|row| row.iter().map(|l| std::format!("{l:x}")).collect()).collect();
            assert_eq!(shown, rows, "{dithering:?} on {panel:?}");
        }
    }

    #[test]
    fn the_accumulators_stay_far_from_saturating_on_hostile_pictures() {
        // Noise, noise at the extremes, saturated colours, one-pixel
        // stripes and checkers, ramps: the largest accumulator stays under
        // half of what an i16 holds, so saturation never changes a level.
        let mut next = crate::test_rng::seeded(0xd17_4e55);
        let width = 96u32;
        let pictures: [&dyn Fn(u32, u32, u64) -> Rgb888; 6] = [
            &|_, _, r| Rgb888::new(r as u8, (r >> 8) as u8, (r >> 16) as u8),
            &|_, _, r| gray(if r & 1 == 0 { 0 } else { 255 }),
            &|_, _, r| [Rgb888::new(0, 0, 255), Rgb888::new(0, 255, 0), Rgb888::new(255, 0, 255)][(r % 3) as usize],
            &|x, _, _| gray(if x % 2 == 0 { 0 } else { 255 }),
            &|x, y, _| if (x + y) % 2 == 0 { Rgb888::new(0, 255, 255) } else { Rgb888::new(255, 0, 0) },
            &|x, y, _| Rgb888::new((x * 255 / 95) as u8, (y * 4) as u8, 128),
        ];
        let mut largest = 0;
        for picture in pictures {
            for panel in Panel::ALL {
                for dithering in [Dithering::FsPe, Dithering::FloydSteinberg] {
                    let mut rows = std::vec![0i16; panel.error_words(width)];
                    let mut ditherer = Ditherer::new(panel, dithering, Point::zero(), width, &mut rows).unwrap();
                    for y in 0..64 {
                        for x in 0..width {
                            assert!(ditherer.next(picture(x, y, next())) < panel.levels());
                        }
                        let row_largest = ditherer.rows.iter().map(|v| v.unsigned_abs()).max().unwrap_or(0);
                        largest = largest.max(row_largest);
                    }
                }
            }
        }
        std::println!("largest accumulator: {largest}");
        assert!(largest < 1 << 14, "an accumulator reached {largest}");
    }

    #[test]
    fn restart_forgets_the_error() {
        let colors = [gray(100); 24];
        let mut rows = [0i16; 6];
        let mut ditherer = Ditherer::new(Panel::Mono, Dithering::FsPe, Point::new(2, 5), 6, &mut rows).unwrap();
        let first: Vec<u8> = colors.iter().map(|&c| ditherer.next(c)).collect();
        assert_eq!(ditherer.position(), Point::new(2, 9));
        ditherer.restart(5);
        let again: Vec<u8> = colors.iter().map(|&c| ditherer.next(c)).collect();
        assert_eq!(first, again);
    }
}
