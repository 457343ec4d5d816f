//! [`Dithered`]: a truecolour `DrawTarget` in front of a panel, dithering
//! what is drawn into it.
//!
//! Invariants: rows drawn in order, each across the region, are dithered
//! as one picture; anything else drawn is given each pixel's level from
//! that pixel alone; nothing is drawn outside what the display is given.

use super::{Ditherer, Dithering, ErrorRowTooShort, TracedColor};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, Point};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::{PointsIter, Rectangle};
use embedded_graphics_core::Pixel;

/// A truecolour (`Rgb888`) `DrawTarget` in front of `display`, which shows
/// what is drawn into it in its own colour: dithered onto its
/// [`Panel`](super::Panel)'s levels, or converted for a truecolour one
/// ([`TracedColor`]).
///
/// Rows drawn in order, each across the display (one `fill_contiguous` a
/// row or a band, as a [`Renderer`](crate::render::Renderer) and a
/// [`Handoff`](crate::render::Handoff)'s rows draw them), are dithered as
/// one picture, the error carried from each call to the next: a board
/// whose cores trace alternate rows draws them all through one `Dithered`.
/// A row that does not follow the last starts the picture again, with no
/// error carried. Any other drawing (a shape, text, a part of a row) gets
/// each pixel's level from that pixel alone: ordered with
/// [`Dithering::Bayer`], else the nearest level.
///
/// ```
/// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::{Gray2, Rgb888}, prelude::*, primitives::Rectangle};
/// use octrace_core::panel::{Dithered, Dithering, Panel};
///
/// let mut display = MockDisplay::<Gray2>::new();
/// let mut rows = [0i16; Panel::Gray2.error_words(64)];
/// let mut dithered = Dithered::new(&mut display, Dithering::FsPe, &mut rows)?;
/// // Two bands of rows, one picture: gray 100 on 0, 85, 170, 255.
/// for band in [0, 32] {
///     let area = Rectangle::new(Point::new(0, band), Size::new(64, 32));
///     dithered.fill_contiguous(&area, core::iter::repeat(Rgb888::new(100, 100, 100)))?;
/// }
/// let levels: u32 = display.affected_area().points().map(|p| display.get_pixel(p).unwrap().luma() as u32).sum();
/// assert_eq!(display.affected_area().size, Size::new(64, 64));
/// assert!((4800..=4840).contains(&levels), "{levels}: 100 / 85 × 4096 is 4819");
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct Dithered<'t, 'b, D> {
    display: &'t mut D,
    /// `None` for a truecolour display.
    ditherer: Option<Ditherer<'b>>,
    /// The row a band must start at to carry on the picture.
    next_row: Option<i32>,
}

impl<'t, 'b, D> Dithered<'t, 'b, D>
where
    D: DrawTarget,
    D::Color: TracedColor,
{
    /// `display`, dithered with `dithering` across its width, error
    /// diffusion's rows in `rows` (at least
    /// [`Panel::error_words`](super::Panel::error_words) of its width; none
    /// for the other methods, or a truecolour display).
    pub fn new(display: &'t mut D, dithering: Dithering, rows: &'b mut [i16]) -> Result<Self, ErrorRowTooShort> {
        let area = display.bounding_box();
        Dithered::across(display, dithering, area.top_left.x, area.size.width, rows)
    }

    /// `display`, each pixel dithered on its own by [`Dithering::Bayer`]:
    /// for drawing in any order (a progressive order's passes, an
    /// animation's changed tiles), with no rows kept.
    ///
    /// ```
    /// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::{BinaryColor, Rgb888}, prelude::*};
    /// use octrace_core::panel::Dithered;
    ///
    /// let mut display = MockDisplay::<BinaryColor>::new();
    /// let mut ordered = Dithered::ordered(&mut display);
    /// // Half gray, a pixel at a time in any order: lit where the 4×4
    /// // Bayer threshold is below half (0 at (0, 0)), not where above (8 at (1, 0)).
    /// ordered.draw_iter([Pixel(Point::new(1, 0), Rgb888::new(128, 128, 128))])?;
    /// ordered.draw_iter([Pixel(Point::new(0, 0), Rgb888::new(128, 128, 128))])?;
    /// assert_eq!(display.get_pixel(Point::new(0, 0)), Some(BinaryColor::On));
    /// assert_eq!(display.get_pixel(Point::new(1, 0)), Some(BinaryColor::Off));
    /// # Ok::<(), core::convert::Infallible>(())
    /// ```
    pub fn ordered(display: &'t mut D) -> Dithered<'t, 'static, D> {
        let area = display.bounding_box();
        let ditherer = D::Color::PANEL.map(|panel| Ditherer::ordered(panel, area.top_left, area.size.width));
        Dithered { display, ditherer, next_row: None }
    }

    /// `display`, its rows dithered across the `width` columns from
    /// `left`.
    pub(crate) fn across(
        display: &'t mut D,
        dithering: Dithering,
        left: i32,
        width: u32,
        rows: &'b mut [i16],
    ) -> Result<Self, ErrorRowTooShort> {
        let ditherer = match D::Color::PANEL {
            Some(panel) => Some(Ditherer::new(panel, dithering, Point::new(left, 0), width, rows)?),
            None => None,
        };
        Ok(Dithered { display, ditherer, next_row: None })
    }

    /// The display behind it.
    pub fn display(&mut self) -> &mut D {
        self.display
    }
}

impl<D: Dimensions> Dimensions for Dithered<'_, '_, D> {
    fn bounding_box(&self) -> Rectangle {
        self.display.bounding_box()
    }
}

impl<D> DrawTarget for Dithered<'_, '_, D>
where
    D: DrawTarget,
    D::Color: TracedColor,
{
    type Color = Rgb888;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        let ditherer = self.ditherer.as_ref();
        self.display.draw_iter(pixels.into_iter().map(|Pixel(p, c)| Pixel(p, alone(ditherer, p, c))))
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(&mut self, area: &Rectangle, colors: I) -> Result<(), D::Error> {
        let Some(ditherer) = self
            .ditherer
            .as_mut()
            .filter(|d| d.dithering().diffuses() && area.top_left.x == d.left() && area.size.width == d.width())
        else {
            // Pixel by pixel: nothing to carry.
            let ditherer = self.ditherer.as_ref();
            let colors = area.points().zip(colors).map(|(p, c)| alone(ditherer, p, c));
            return self.display.fill_contiguous(area, colors);
        };
        if self.next_row != Some(area.top_left.y) {
            ditherer.restart(area.top_left.y);
        }
        let end = Point::new(area.top_left.x, area.top_left.y + area.size.height as i32);
        let colors = colors.into_iter().take(area.size.width as usize * area.size.height as usize);
        let drawn = self.display.fill_contiguous(area, colors.map(|c| D::Color::from_level(ditherer.next(c))));
        // A display that stopped short leaves the picture to start again.
        self.next_row = (drawn.is_ok() && ditherer.position() == end).then_some(end.y);
        drawn
    }
}

/// The colour of a pixel drawn on its own.
fn alone<C: TracedColor>(ditherer: Option<&Ditherer<'_>>, position: Point, color: Rgb888) -> C {
    match ditherer {
        Some(d) => C::from_level(d.panel().level_at(d.dithering(), position, color)),
        None => C::from(color),
    }
}

#[cfg(test)]
mod tests {
    use super::super::Panel;
    use super::*;
    use embedded_graphics_core::geometry::{OriginDimensions, Size};
    use embedded_graphics_core::pixelcolor::{BinaryColor, Rgb565};

    /// A 16×8 display that keeps what it is given.
    #[derive(Debug)]
    struct Grid<C>([[Option<C>; 16]; 8]);

    impl<C> OriginDimensions for Grid<C> {
        fn size(&self) -> Size {
            Size::new(16, 8)
        }
    }

    impl<C: TracedColor> DrawTarget for Grid<C> {
        type Color = C;
        type Error = ();

        fn draw_iter<I: IntoIterator<Item = Pixel<C>>>(&mut self, pixels: I) -> Result<(), ()> {
            for Pixel(p, c) in pixels {
                if self.bounding_box().contains(p) {
                    self.0[p.y as usize][p.x as usize] = Some(c);
                }
            }
            Ok(())
        }
    }

    /// A smooth picture, 16×8.
    fn color(x: i32, y: i32) -> Rgb888 {
        Rgb888::new((x * 15) as u8, (y * 30) as u8, 90)
    }

    fn rows(area: Rectangle) -> impl Iterator<Item = Rgb888> {
        area.points().map(|p| color(p.x, p.y))
    }

    fn whole<C: TracedColor>(dithering: Dithering, bands: &[(i32, u32)]) -> Grid<C> {
        let mut grid = Grid([[None; 16]; 8]);
        let mut storage = [0i16; 32];
        let mut dithered = Dithered::new(&mut grid, dithering, &mut storage).unwrap();
        for &(top, height) in bands {
            let area = Rectangle::new(Point::new(0, top), Size::new(16, height));
            dithered.fill_contiguous(&area, rows(area)).unwrap();
        }
        grid
    }

    #[test]
    fn bands_in_order_are_one_picture() {
        for dithering in Dithering::ALL {
            let at_once = whole::<BinaryColor>(dithering, &[(0, 8)]);
            let in_bands = whole::<BinaryColor>(dithering, &[(0, 3), (3, 1), (4, 4)]);
            assert_eq!(at_once.0, in_bands.0, "{dithering:?}");
        }
    }

    #[test]
    fn a_band_out_of_order_starts_again() {
        let at_once = whole::<BinaryColor>(Dithering::FsPe, &[(0, 8)]);
        let twice = whole::<BinaryColor>(Dithering::FsPe, &[(0, 8), (0, 8)]);
        assert_eq!(at_once.0, twice.0, "a second draw is the same picture");
        // Rows 4 to 7 drawn alone are those of a picture starting there.
        let alone = whole::<BinaryColor>(Dithering::FsPe, &[(4, 4)]);
        let mut storage = [0i16; 16];
        let mut ditherer = Ditherer::new(Panel::Mono, Dithering::FsPe, Point::new(0, 4), 16, &mut storage).unwrap();
        for p in Rectangle::new(Point::new(0, 4), Size::new(16, 4)).points() {
            let level = ditherer.next(color(p.x, p.y));
            assert_eq!(alone.0[p.y as usize][p.x as usize], Some(BinaryColor::from_level(level)));
        }
    }

    #[test]
    fn other_drawing_is_pixel_by_pixel() {
        let mut grid = Grid([[None; 16]; 8]);
        let mut storage = [0i16; 16];
        let mut dithered = Dithered::new(&mut grid, Dithering::FsPe, &mut storage).unwrap();
        // Part of a row, and single pixels: the nearest level.
        let part = Rectangle::new(Point::new(2, 1), Size::new(5, 2));
        dithered.fill_contiguous(&part, rows(part)).unwrap();
        dithered.draw_iter([Pixel(Point::new(15, 7), Rgb888::new(130, 130, 130))]).unwrap();
        for p in part.points() {
            assert_eq!(grid.0[p.y as usize][p.x as usize], Some(BinaryColor::from(color(p.x, p.y))));
        }
        assert_eq!(grid.0[7][15], Some(BinaryColor::On));
    }

    #[test]
    fn a_truecolour_display_is_converted() {
        let grid = whole::<Rgb565>(Dithering::FsPe, &[(0, 8)]);
        for p in Rectangle::new(Point::zero(), Size::new(16, 8)).points() {
            assert_eq!(grid.0[p.y as usize][p.x as usize], Some(Rgb565::from(color(p.x, p.y))));
        }
    }

    #[test]
    fn too_little_room_is_refused() {
        let mut grid = Grid::<BinaryColor>([[None; 16]; 8]);
        let e = Dithered::new(&mut grid, Dithering::FloydSteinberg, &mut [0i16; 15]).unwrap_err();
        assert_eq!(e, ErrorRowTooShort { needed: 16, given: 15 });
        assert!(Dithered::new(&mut grid, Dithering::Bayer, &mut []).is_ok());
    }
}
