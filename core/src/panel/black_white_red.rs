//! Three-colour e-paper: the [`BlackWhiteRed`] colour type, and the colours
//! such a panel can mix, onto which a colour is projected before it is
//! dithered.
//!
//! Mixing black, white and red gives the colours `(r, m, m)` with
//! `0 ≤ m ≤ r ≤ 255`: a triangle in the plane green = blue. Error
//! diffusion must not chase a colour outside it (a blue it can never
//! reach would pile up error), so each colour is first replaced by its
//! nearest point of the triangle in RGB ([`project`]), and the dither runs
//! on the two values `r` and `m`.

use super::divisor::Divisor;
use embedded_graphics_core::pixelcolor::{PixelColor, Rgb888, RgbColor};

/// A pixel of a black/white/red e-paper panel. embedded-graphics has no
/// such colour type; e-paper drivers each have their own (`epd-waveshare`'s
/// `TriColor`, with `Chromatic` for the red), to which a small adapter
/// maps it (see the [module docs](super#three-colour-e-paper)).
///
/// It converts from `Rgb888` to the nearest of the three (a plain cut, as
/// embedded-graphics' own conversions are); octrace dithers onto it.
///
/// ```
/// use embedded_graphics::pixelcolor::Rgb888;
/// use octrace_core::panel::BlackWhiteRed;
///
/// assert_eq!(BlackWhiteRed::from(Rgb888::new(200, 40, 30)), BlackWhiteRed::Red);
/// assert_eq!(Rgb888::from(BlackWhiteRed::White), Rgb888::new(255, 255, 255));
/// ```
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BlackWhiteRed {
    /// Black ink.
    #[default]
    Black,
    /// The paper.
    White,
    /// Red ink.
    Red,
}

impl BlackWhiteRed {
    /// The three, in the order of their level numbers (0, 1, 2).
    pub const ALL: [BlackWhiteRed; 3] = [BlackWhiteRed::Black, BlackWhiteRed::White, BlackWhiteRed::Red];

    /// The colour's `(r, m)`: its red, and its green and blue.
    pub(super) const fn red_and_rest(self) -> [i32; 2] {
        match self {
            BlackWhiteRed::Black => [0, 0],
            BlackWhiteRed::White => [255, 255],
            BlackWhiteRed::Red => [255, 0],
        }
    }

    /// The colour nearest to `(r, m)` in `dr² + 2 dm²` (the RGB distance in
    /// the plane green = blue), the first of black, white, red on a tie.
    /// `step` is 255 in the unit of `r` and `m`. The distances' differences
    /// are linear, so no square is taken (nor can one overflow).
    #[inline]
    pub(super) fn nearest_mixed(r: i32, m: i32, step: i32) -> BlackWhiteRed {
        // Each distance less black's, over step: white's is 3 step − 2 r −
        // 4 m, red's step − 2 r.
        let white = 3 * step - 2 * r - 4 * m;
        let red = step - 2 * r;
        let mut best = (BlackWhiteRed::Black, 0);
        if white < best.1 {
            best = (BlackWhiteRed::White, white);
        }
        if red < best.1 {
            best = (BlackWhiteRed::Red, red);
        }
        best.0
    }
}

impl PixelColor for BlackWhiteRed {
    // Drivers pack it in planes of their own.
    type Raw = ();
}

impl From<Rgb888> for BlackWhiteRed {
    /// The nearest of the three in RGB; on a tie the first of black, white,
    /// red.
    fn from(color: Rgb888) -> Self {
        let distance = |c: Rgb888| {
            let d = |a: u8, b: u8| (a as i32 - b as i32).pow(2);
            d(color.r(), c.r()) + d(color.g(), c.g()) + d(color.b(), c.b())
        };
        let mut best = BlackWhiteRed::Black;
        for candidate in BlackWhiteRed::ALL {
            if distance(candidate.into()) < distance(best.into()) {
                best = candidate;
            }
        }
        best
    }
}

impl From<BlackWhiteRed> for Rgb888 {
    fn from(color: BlackWhiteRed) -> Self {
        let [r, m] = color.red_and_rest();
        Rgb888::new(r as u8, m as u8, m as u8)
    }
}

/// The nearest colour the panel can mix to `color`, as `(r, m)`: its red,
/// and the green and blue they share. Inside the triangle the green and
/// blue are averaged; outside, the nearest of the three edges' nearest
/// points is taken, compared in integers (distances doubled, so no half is
/// lost).
pub(super) fn project(color: Rgb888) -> [i32; 2] {
    let r = color.r() as i32;
    // Twice the shared value: the plane green = blue meets (g, b) there.
    let m2 = color.g() as i32 + color.b() as i32;
    if m2 <= 2 * r {
        return [r, (m2 + 1) >> 1];
    }
    // Outside (more green and blue than red): the edges black–red (m = 0),
    // red–white (r = 255) and black–white (r = m).
    let t = (Divisor::BY_3.quotient((r + m2 + 1) as u32) as i32).clamp(0, 255);
    let edges = [[r, 0], [255, ((m2 + 1) >> 1).min(255)], [t, t]];
    let distance = |[er, em]: [i32; 2]| 2 * (er - r).pow(2) + (2 * em - m2).pow(2);
    let mut best = edges[0];
    for edge in edges {
        if distance(edge) < distance(best) {
            best = edge;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mixable_colours_are_kept() {
        for (r, m) in [(0, 0), (255, 255), (255, 0), (200, 100), (10, 10), (128, 3)] {
            assert_eq!(project(Rgb888::new(r, m, m)), [r as i32, m as i32]);
        }
        // Green and blue averaged, rounded up.
        assert_eq!(project(Rgb888::new(200, 100, 51)), [200, 76]);
    }

    #[test]
    fn a_colour_outside_goes_to_its_nearest_edge_point() {
        // Pure blue and pure green: nearest the black–white edge at a third.
        assert_eq!(project(Rgb888::new(0, 0, 255)), [85, 85]);
        assert_eq!(project(Rgb888::new(0, 255, 0)), [85, 85]);
        // Cyan: on the black–white edge, two thirds up.
        assert_eq!(project(Rgb888::new(0, 255, 255)), [170, 170]);
        // Every projection is mixable, and no other mixable colour is nearer.
        for (r, g, b) in [(0, 255, 255), (30, 200, 90), (100, 255, 255), (254, 255, 255), (0, 1, 0)] {
            let [pr, pm] = project(Rgb888::new(r, g, b));
            assert!(0 <= pm && pm <= pr && pr <= 255, "({r}, {g}, {b}) -> ({pr}, {pm})");
            let d = |cr: i32, cm: i32| (cr - r as i32).pow(2) + (cm - g as i32).pow(2) + (cm - b as i32).pow(2);
            let nearest = (0..=255).flat_map(|cr| (0..=cr).map(move |cm| (cr, cm))).map(|(cr, cm)| d(cr, cm)).min();
            // Within rounding of the best (the projection is rounded to whole values).
            assert!(d(pr, pm) <= nearest.unwrap() + 3 * 255, "({r}, {g}, {b})");
        }
    }

    #[test]
    fn the_nearest_mixed_colour_is_the_nearest_in_distance() {
        for r in (-300..600).step_by(7) {
            for m in (-300..600).step_by(11) {
                let d = |c: BlackWhiteRed| {
                    let [cr, cm] = c.red_and_rest();
                    (r - cr).pow(2) + 2 * (m - cm).pow(2)
                };
                let nearest = BlackWhiteRed::nearest_mixed(r, m, 255);
                // The first of the three with the least distance.
                let expected = BlackWhiteRed::ALL.into_iter().min_by_key(|&c| d(c)).unwrap();
                assert_eq!(nearest, expected, "({r}, {m})");
            }
        }
    }

    #[test]
    fn rgb_converts_to_the_nearest_of_the_three() {
        assert_eq!(BlackWhiteRed::from(Rgb888::new(100, 100, 100)), BlackWhiteRed::Black);
        assert_eq!(BlackWhiteRed::from(Rgb888::new(160, 160, 160)), BlackWhiteRed::White);
        assert_eq!(BlackWhiteRed::from(Rgb888::new(255, 0, 0)), BlackWhiteRed::Red);
        for color in BlackWhiteRed::ALL {
            assert_eq!(BlackWhiteRed::from(Rgb888::from(color)), color);
        }
    }
}
