//! What to draw of a loaded scene or of a frame, and how: an
//! embedded-graphics image with options (an area, the progressive order, a
//! frame's bands, the dithering), drawn whole or stopped inside a pixel.

use super::draw::{self, Request, Source};
use super::picture::{Areas, Bands, InOrder, Picture, Still};
use super::DrawError;
use crate::panel::{Dithering, TracedColor};
use crate::profile::Profile;
use crate::render::{Polling, Progressive, Stop};
use crate::shade::{Stats, Unpolled};
use core::cell::RefCell;
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, OriginDimensions, Size};
use embedded_graphics_core::image::ImageDrawable;
use embedded_graphics_core::primitives::Rectangle;

/// What to draw of a loaded scene or of a frame of an animation, and how:
/// an image `size` pixels in the colour `C`, like `tinybmp::Bmp<C>`. Each
/// draw traces the pixels as the display takes them, one scanline at a
/// time: no framebuffer. It is the one way a scene is drawn: as
/// embedded-graphics draws any image (`Image::new(&image, point)`), or
/// with [`TracedImage::try_draw`] (which tells why a picture is not whole
/// and counts the rays) and [`TracedImage::try_draw_until`] (stopped
/// inside a pixel); what it draws is set by its options, each of which
/// gives it the type of its picture (`K`, a [`picture`](crate::picture):
/// a firmware links the drawing of only the pictures it draws):
///
/// - the whole picture, or an [`area`](TracedImage::area) of it, or the
///   [`areas`](TracedImage::areas) a thread or core takes one after
///   another;
/// - the [`progressive`](TracedImage::progressive) order: coarse blocks
///   first;
/// - for a [`Frame`](crate::Frame) of an animation, the tiles its motion
///   can have changed, every band of them or the
///   [`bands`](TracedImage::bands) a core takes one after another;
/// - on a panel of few levels, the [`dithering`](TracedImage::dithered).
///
/// A truecolour `C` (`Rgb565`, `Rgb888`, …) takes each pixel converted; a
/// panel of few levels (`BinaryColor`, `Gray2`, `Gray4`,
/// [`BlackWhiteRed`](crate::panel::BlackWhiteRed)) takes it dithered, by
/// [`Dithering::FsPe`] unless [`TracedImage::dithered`] says otherwise
/// (see [`panel`](crate::panel): an area is dithered as an image of its
/// own; the progressive order and a frame's tiles by
/// [`Dithering::Bayer`], the one method that needs no order).
/// [`PixelSample`](crate::render::PixelSample) takes each pixel with the
/// object it sees.
///
/// ```
/// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb565, prelude::*};
/// use octrace_core::{profile::Board16K, Raytracer};
///
/// let mut raytracer = Raytracer::<Board16K>::new();
/// let scene = raytracer.load("BACKGROUND 0 0 1\n").unwrap();
/// let mut display = MockDisplay::<Rgb565>::new();
/// Image::new(&scene.image::<Rgb565>(Size::new(4, 2)), Point::zero()).draw(&mut display).unwrap();
/// display.assert_pattern(&["BBBB", "BBBB"]);
/// ```
pub struct TracedImage<'s, 'r, P: Profile, C, K: Picture = Still> {
    request: Request<'s, 'r, P>,
    color: core::marker::PhantomData<(C, K)>,
}

impl<P: Profile, C, K: Picture> fmt::Debug for TracedImage<'_, '_, P, C, K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let picture = match self.request.picture {
            draw::Picture::Area(area) => area,
            _ => self.bounding_box(),
        };
        f.debug_struct("TracedImage")
            .field("size", &self.request.size)
            .field("dithering", &self.request.dithering)
            .field("area", &picture)
            .field("objects", &self.request.source.view.object_count())
            .finish_non_exhaustive()
    }
}

impl<P: Profile, C, K: Picture> Clone for TracedImage<'_, '_, P, C, K> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile, C, K: Picture> Copy for TracedImage<'_, '_, P, C, K> {}

impl<'s, 'r, P: Profile, C, K: Picture> TracedImage<'s, 'r, P, C, K> {
    /// The image of `size` pixels traced from `source`, drawing `picture`
    /// (which is `K`'s).
    pub(super) fn new(source: Source<'s, 'r, P>, size: Size, picture: draw::Picture<'s>) -> Self {
        let request = Request { source, size, dithering: Dithering::default(), picture, rows: None };
        TracedImage { request, color: core::marker::PhantomData }
    }

    /// The image drawing what `request` asks, as the picture `L`.
    fn with<L: Picture>(self, request: Request<'s, 'r, P>) -> TracedImage<'s, 'r, P, C, L> {
        TracedImage { request, color: core::marker::PhantomData }
    }

    /// The image dithered by `dithering` on a panel of few levels (a
    /// truecolour display ignores it).
    ///
    /// ```
    /// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::BinaryColor, prelude::*};
    /// use octrace_core::{panel::Dithering, profile::Board16K, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("BACKGROUND 0.5 0.5 0.5\n")?;
    /// let mut display = MockDisplay::<BinaryColor>::new();
    /// let image = scene.image_for(&display).dithered(Dithering::Bayer);
    /// Image::new(&image, Point::zero()).draw(&mut display)?;
    /// // Ordered: the same 4×4 pattern all over.
    /// assert_eq!(display.get_pixel(Point::new(1, 2)), display.get_pixel(Point::new(41, 62)));
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn dithered(self, dithering: Dithering) -> Self {
        self.with(Request { dithering, ..self.request })
    }

    /// How it is dithered on a panel of few levels.
    pub fn dithering(&self) -> Dithering {
        self.request.dithering
    }

    /// Error diffusion's rows in `rows` (at least
    /// [`Panel::error_words`](crate::panel::Panel::error_words) of the
    /// width drawn) instead of on the draw's stack: for an image wider
    /// than [`IMAGE_ERROR_WORDS`](crate::panel::IMAGE_ERROR_WORDS) allows, or a board short of stack.
    ///
    /// ```
    /// use core::cell::RefCell;
    /// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::Gray4, prelude::*};
    /// use octrace_core::{panel::Panel, profile::Board16K, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("BACKGROUND 0.5 0.5 0.5\n")?;
    /// let mut display = MockDisplay::<Gray4>::new();
    /// let rows = RefCell::new([0i16; Panel::Gray4.error_words(64)]);
    /// scene.image_for(&display).error_rows(&rows).try_draw(&mut display)?;
    ///
    /// let mut on_the_stack = MockDisplay::<Gray4>::new();
    /// scene.image_for(&on_the_stack).try_draw(&mut on_the_stack)?;
    /// assert_eq!(display, on_the_stack);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn error_rows(self, rows: &'s RefCell<[i16]>) -> Self {
        self.with(Request { rows: Some(rows), ..self.request })
    }
}

impl<'s, 'r, P: Profile, C> TracedImage<'s, 'r, P, C, Still> {
    /// A still's pixels in `area` only (in the image's coordinates), drawn
    /// with the area's top-left pixel at the target's origin: what
    /// [`ImageDrawable::draw_sub_image`] draws. On a panel of few levels the
    /// area is dithered as an image of its own.
    ///
    /// ```
    /// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*, primitives::Rectangle};
    /// use octrace_core::{profile::Board16K, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n")?;
    /// let mut whole = MockDisplay::<Rgb888>::new();
    /// scene.image::<Rgb888>(Size::new(16, 16)).try_draw(&mut whole)?;
    /// let mut corner = MockDisplay::<Rgb888>::new();
    /// let area = Rectangle::new(Point::new(8, 8), Size::new(4, 4));
    /// scene.image::<Rgb888>(Size::new(16, 16)).area(area).try_draw(&mut corner)?;
    /// assert_eq!(corner.get_pixel(Point::new(1, 2)), whole.get_pixel(Point::new(9, 10)));
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn area(self, area: Rectangle) -> Self {
        self.with(Request { picture: draw::Picture::Area(area), ..self.request })
    }

    /// A still whole in the [`Progressive`] order (at the order's size):
    /// the whole picture in coarse blocks first, then finer, until it is
    /// exactly the picture drawn row by row. Every pixel is traced once;
    /// the drawing streams (no framebuffer), in a few calls a pass. On a
    /// panel of few levels every pass is dithered by [`Dithering::Bayer`]:
    /// the last pass is then the image with that method.
    ///
    /// ```
    /// use embedded_graphics::{image::Image, mock_display::MockDisplay, pixelcolor::Rgb565, prelude::*};
    /// use octrace_core::{profile::Board16K, render::Progressive, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n")?;
    /// let mut display = MockDisplay::<Rgb565>::new();
    /// display.set_allow_overdraw(true); // later passes draw over the coarse blocks
    /// let order = Progressive::new(display.size(), 16);
    /// let stats = scene.image_for(&display).progressive(&order).try_draw(&mut display)?;
    /// assert_eq!(stats.rays, 64 * 64, "every pixel traced once: nothing reflects");
    ///
    /// let mut direct = MockDisplay::<Rgb565>::new();
    /// Image::new(&scene.image_for(&direct), Point::zero()).draw(&mut direct)?;
    /// assert_eq!(display, direct);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn progressive(self, order: &'s Progressive) -> TracedImage<'s, 'r, P, C, InOrder> {
        self.with(Request { picture: draw::Picture::Progressive(order), ..self.request })
    }

    /// A still's areas, the next one `next` gives until it gives none,
    /// each drawn at its place in the image (clipped to it): where threads
    /// or cores share a still, each draws the next area none has taken
    /// yet, through one renderer (its screen lists made once, not an
    /// area). On a panel of few levels they are dithered by
    /// [`Dithering::Bayer`], which needs no order.
    ///
    /// ```
    /// use core::cell::Cell;
    /// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*, primitives::Rectangle};
    /// use octrace_core::{profile::Board16K, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n")?;
    /// let mut whole = MockDisplay::<Rgb888>::new();
    /// scene.image::<Rgb888>(Size::new(16, 16)).try_draw(&mut whole)?;
    /// // The four quarters, bottom right first, as four threads might take them.
    /// let quarter = Cell::new(4);
    /// let next = || {
    ///     let left = quarter.get();
    ///     quarter.set(left.max(1) - 1);
    ///     (left > 0).then(|| Rectangle::new(Point::new(8 * (left - 1) % 16, 8 * ((left - 1) / 2)), Size::new(8, 8)))
    /// };
    /// let mut quarters = MockDisplay::<Rgb888>::new();
    /// scene.image::<Rgb888>(Size::new(16, 16)).areas(&next).try_draw(&mut quarters)?;
    /// assert_eq!(quarters, whole);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn areas(self, next: &'s dyn Fn() -> Option<Rectangle>) -> TracedImage<'s, 'r, P, C, Areas> {
        self.with(Request { picture: draw::Picture::Areas(next), ..self.request })
    }
}

impl<'s, 'r, P: Profile, C> TracedImage<'s, 'r, P, C, Bands> {
    /// A frame's bands of tiles (rows of tiles, [`TILE`](crate::animation::TILE)
    /// pixels high), the next one `next` gives until it gives none,
    /// instead of every band: on a board whose cores share a frame, each
    /// core draws the next band no core has taken yet.
    pub fn bands(self, next: &'s dyn Fn() -> Option<u32>) -> Self {
        match self.request.picture {
            draw::Picture::Bands(playing, _) => {
                self.with(Request { picture: draw::Picture::Bands(playing, Some(next)), ..self.request })
            }
            // Never: a frame's image draws its bands.
            _ => self,
        }
    }
}

impl<P: Profile, C: TracedColor, K: Picture> TracedImage<'_, '_, P, C, K> {
    /// Draws what the image is set to into `target`; returns the counters
    /// of its rays, or why the picture is not whole: a camera that cannot
    /// be set up (a zero size), an image too wide for the error row on the
    /// stack, the display's error ([`ImageDrawable::draw`] tells only the
    /// last).
    pub fn try_draw<D: DrawTarget<Color = C>>(&self, target: &mut D) -> Result<Stats, DrawError<D::Error>> {
        draw::draw::<P, C, K, D, _>(&self.request, target, &mut Unpolled)
    }

    /// [`TracedImage::try_draw`], asking `stop` before every ray (as
    /// [`Renderer::pixel_until`](crate::render::Renderer::pixel_until)
    /// does): [`DrawError::Stopped`] as soon as it says so, the row being
    /// traced handed to the target up to the pixel it stopped in (a
    /// frame's tiles not drawn are kept to be traced).
    ///
    /// ```
    /// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::Rgb888, prelude::*};
    /// use octrace_core::{profile::Board16K, DrawError, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("SURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\nLIGHT 10 5 5 5\nSPHERE 1 1 0 0 0\n")?;
    /// let mut display = MockDisplay::<Rgb888>::new();
    /// let mut asked = 0;
    /// let stopped = scene.image::<Rgb888>(Size::new(8, 8)).try_draw_until(&mut display, &mut || {
    ///     asked += 1;
    ///     asked > 20
    /// });
    /// assert_eq!(stopped, Err(DrawError::Stopped));
    /// // Two rows of 8 and the first pixels of the third.
    /// assert_eq!(display.affected_area().size, Size::new(8, 3));
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn try_draw_until<D: DrawTarget<Color = C>, S: Stop>(
        &self,
        target: &mut D,
        stop: &mut S,
    ) -> Result<Stats, DrawError<D::Error>> {
        draw::draw::<P, C, K, D, _>(&self.request, target, &mut Polling { stop, stopped: false })
    }
}

impl<P: Profile, C, K: Picture> OriginDimensions for TracedImage<'_, '_, P, C, K> {
    fn size(&self) -> Size {
        self.request.size
    }
}

impl<P: Profile, C: TracedColor, K: Picture> ImageDrawable for TracedImage<'_, '_, P, C, K> {
    type Color = C;

    /// Draws the picture, as [`TracedImage::try_draw`] does; but
    /// embedded-graphics' `draw` can return only the display's error, so
    /// octrace's own (a camera that cannot be set up, a row of error too
    /// short for the image's width, an image too large) leave the picture
    /// undrawn or partial and say nothing. Where that can happen (a scene
    /// or a display not known when the firmware is built), use `try_draw`.
    fn draw<D: DrawTarget<Color = C>>(&self, target: &mut D) -> Result<(), D::Error> {
        match self.try_draw(target) {
            Ok(_)
            | Err(DrawError::Camera(_) | DrawError::ErrorRow(_) | DrawError::Stopped | DrawError::TooLarge { .. }) => {
                Ok(())
            }
            Err(DrawError::Target(e)) => Err(e),
        }
    }

    fn draw_sub_image<D: DrawTarget<Color = C>>(&self, target: &mut D, area: &Rectangle) -> Result<(), D::Error> {
        // A frame's area too: the frame's scene traced there.
        let still = self.with::<Still>(Request { picture: draw::Picture::Area(*area), ..self.request });
        ImageDrawable::draw(&still, target)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{Grid, SCENE};
    use super::*;
    use crate::panel::{Ditherer, ErrorRowTooShort, IMAGE_ERROR_WORDS};
    use crate::profile::Board16K;
    use crate::render::Progressive;
    use crate::{LoadedScene, Raytracer};
    use embedded_graphics_core::geometry::Point;
    use embedded_graphics_core::pixelcolor::{BinaryColor, Gray4, Rgb565, Rgb888};
    use embedded_graphics_core::primitives::PointsIter;
    use embedded_graphics_core::Pixel;
    use std::string::ToString;
    use std::vec::Vec;

    extern crate std;

    #[test]
    fn an_image_sized_from_its_target_draws_every_pixel_once() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let mut grid = Grid::<Gray4, 12, 8>([[None; 12]; 8]);
        let image = scene.image_for(&grid);
        assert_eq!(image.size(), Size::new(12, 8));
        image.draw(&mut grid).unwrap();
        assert!(grid.0.iter().flatten().all(|c| c.is_some()));
        assert_eq!(scene.stats().rays, 96);
    }

    #[test]
    fn a_sub_image_is_the_same_pixels_at_the_origin() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let mut whole = Grid::<Rgb565, 12, 8>([[None; 12]; 8]);
        scene.image_for(&whole).draw(&mut whole).unwrap();
        let mut part = Grid::<Rgb565, 5, 3>([[None; 5]; 3]);
        let image = scene.image::<Rgb565>(Size::new(12, 8));
        image.draw_sub_image(&mut part, &Rectangle::new(Point::new(4, 2), Size::new(5, 3))).unwrap();
        for y in 0..3 {
            assert_eq!(part.0[y], whole.0[y + 2][4..9], "row {y}");
        }
    }

    /// The scene's truecolour pixels at `W`×`H`, dithered by `dithering`
    /// onto `C`'s panel over the rectangle `area`, as a ditherer alone gives
    /// them.
    fn dithered_by_hand<C: TracedColor, const W: usize, const H: usize>(
        dithering: Dithering,
        area: Rectangle,
    ) -> Vec<C> {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let mut truecolour = Grid::<Rgb888, W, H>([[None; W]; H]);
        scene.image_for(&truecolour).draw(&mut truecolour).unwrap();
        let panel = C::PANEL.unwrap();
        let mut rows = std::vec![0; panel.error_words(area.size.width)];
        let mut ditherer = Ditherer::new(panel, dithering, area.top_left, area.size.width, &mut rows).unwrap();
        area.points().map(|p| C::from_level(ditherer.next(truecolour.0[p.y as usize][p.x as usize].unwrap()))).collect()
    }

    #[test]
    fn a_panel_image_is_its_pixels_dithered_in_raster_order() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        for dithering in Dithering::ALL {
            let mut grid = Grid::<BinaryColor, 12, 8>([[None; 12]; 8]);
            scene.image_for(&grid).dithered(dithering).draw(&mut grid).unwrap();
            let whole = Rectangle::new(Point::zero(), Size::new(12, 8));
            let drawn: Vec<BinaryColor> = grid.0.iter().flatten().map(|c| c.unwrap()).collect();
            assert_eq!(drawn, dithered_by_hand::<BinaryColor, 12, 8>(dithering, whole), "{dithering:?}");
        }
        // A row of more than 256 words: the larger frame, the same picture.
        let mut wide = Grid::<Gray4, 300, 2>([[None; 300]; 2]);
        scene.image_for(&wide).draw(&mut wide).unwrap();
        let drawn: Vec<Gray4> = wide.0.iter().flatten().map(|c| c.unwrap()).collect();
        let whole = Rectangle::new(Point::zero(), Size::new(300, 2));
        assert_eq!(drawn, dithered_by_hand::<Gray4, 300, 2>(Dithering::FsPe, whole));
    }

    #[test]
    fn a_dithered_sub_image_is_dithered_as_an_image_of_its_own() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let area = Rectangle::new(Point::new(3, 2), Size::new(6, 4));
        for dithering in Dithering::ALL {
            let mut part = Grid::<BinaryColor, 6, 4>([[None; 6]; 4]);
            scene.image::<BinaryColor>(Size::new(12, 8)).dithered(dithering).draw_sub_image(&mut part, &area).unwrap();
            let drawn: Vec<BinaryColor> = part.0.iter().flatten().map(|c| c.unwrap()).collect();
            // Its own raster order from the area's corner; ordered dithering
            // keeps the whole image's pattern there.
            assert_eq!(drawn, dithered_by_hand::<BinaryColor, 12, 8>(dithering, area), "{dithering:?}");
        }
        // An area reaching past the image: what there is of it.
        let beyond = Rectangle::new(Point::new(5, 3), Size::new(8, 6));
        let mut part = Grid::<BinaryColor, 8, 6>([[None; 8]; 6]);
        scene.image::<BinaryColor>(Size::new(12, 8)).draw_sub_image(&mut part, &beyond).unwrap();
        let drawn: Vec<BinaryColor> = part.0[..5].iter().flat_map(|row| row[..7].iter().map(|c| c.unwrap())).collect();
        let inside = Rectangle::new(Point::new(5, 3), Size::new(7, 5));
        assert_eq!(drawn, dithered_by_hand::<BinaryColor, 12, 8>(Dithering::FsPe, inside));
        assert_eq!(part.0.iter().flatten().filter(|c| c.is_some()).count(), 35);
    }

    #[test]
    fn an_image_too_wide_for_the_stack_needs_storage_of_its_own() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let mut wide = Grid::<BinaryColor, 801, 1>([[None; 801]; 1]);
        let image = scene.image_for(&wide);
        let e = image.try_draw(&mut wide).unwrap_err();
        assert_eq!(e, DrawError::ErrorRow(ErrorRowTooShort { needed: 801, given: IMAGE_ERROR_WORDS }));
        assert_eq!(e.to_string(), "error diffusion needs a row of 801 accumulators here, but was given room for 800");
        image.draw(&mut wide).unwrap();
        assert!(wide.0[0].iter().all(|c| c.is_none()), "nothing drawn");
        // Bayer keeps no row; with the caller's storage, diffusion draws.
        image.dithered(Dithering::Bayer).try_draw(&mut wide).unwrap();
        let mut again = Grid::<BinaryColor, 801, 1>([[None; 801]; 1]);
        let rows = RefCell::new([0; 801]);
        image.error_rows(&rows).try_draw(&mut again).unwrap();
        assert!(again.0[0].iter().all(|c| c.is_some()));
    }

    #[test]
    fn an_image_wider_than_a_side_can_be_is_refused_not_clipped() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let mut drawn = 0;
        let mut counting = Counting { size: Size::new(70_000, 1), drawn: &mut drawn };
        let e = scene.image_for(&counting).try_draw(&mut counting).unwrap_err();
        assert_eq!(e, DrawError::TooLarge { width: 70_000, height: 1 });
        assert_eq!(e.to_string(), "an image of 70000×1 pixels: its sides are at most 16384");
        assert_eq!(drawn, 0, "nothing drawn");
    }

    /// A display of any size that counts the pixels it is given.
    struct Counting<'a> {
        size: Size,
        drawn: &'a mut usize,
    }

    impl OriginDimensions for Counting<'_> {
        fn size(&self) -> Size {
            self.size
        }
    }

    impl DrawTarget for Counting<'_> {
        type Color = Rgb565;
        type Error = core::convert::Infallible;

        fn draw_iter<I: IntoIterator<Item = Pixel<Rgb565>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
            *self.drawn += pixels.into_iter().count();
            Ok(())
        }
    }

    /// A 12×8 gray panel that keeps the last colour drawn at each pixel.
    struct Overdrawn([[Option<Gray4>; 12]; 8]);

    impl OriginDimensions for Overdrawn {
        fn size(&self) -> Size {
            Size::new(12, 8)
        }
    }

    impl DrawTarget for Overdrawn {
        type Color = Gray4;
        type Error = core::convert::Infallible;

        fn draw_iter<I: IntoIterator<Item = Pixel<Gray4>>>(&mut self, pixels: I) -> Result<(), Self::Error> {
            for Pixel(p, c) in pixels {
                self.0[p.y as usize][p.x as usize] = Some(c);
            }
            Ok(())
        }
    }

    /// `scene`'s 12×8 picture, dithered by Bayer.
    fn ordered<P: Profile>(scene: &LoadedScene<'_, P>) -> [[Option<Gray4>; 12]; 8] {
        let mut grid = Grid::<Gray4, 12, 8>([[None; 12]; 8]);
        scene.image_for(&grid).dithered(Dithering::Bayer).draw(&mut grid).unwrap();
        grid.0
    }

    #[test]
    fn a_progressive_panel_ends_in_the_ordered_picture() {
        let mut raytracer = Raytracer::<Board16K>::new();
        let scene = raytracer.load(SCENE).unwrap();
        let mut progressive = Overdrawn([[None; 12]; 8]);
        let order = Progressive::new(Size::new(12, 8), 4);
        scene.image_for(&progressive).progressive(&order).try_draw(&mut progressive).unwrap();
        assert_eq!(progressive.0, ordered(&scene));
    }

    #[test]
    fn an_animated_panel_shows_each_frames_ordered_picture() {
        use crate::animation::AnimationRoom;
        let text = "FRAMES 4\nRASTER 12 8\nBACKGROUND .4 .4 .4\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n\
                    LIGHT 10 5 5 5\nSPHERE 1 2 0 0 -4\nSPHERE 1 0.5 -3 2 0 MOVE 0 0 0 0  3 1.5 0 0\n";
        let mut room = AnimationRoom::<6, 1, 2>::new();
        let mut animation = room.animation(Size::new(12, 8)).unwrap();
        let mut raytracer = Raytracer::<Board16K>::new();
        let mut panel = Overdrawn([[None; 12]; 8]);
        for frame in (0..4).chain(0..4) {
            let loaded = animation.load(&mut raytracer, text, frame).unwrap();
            loaded.image_for(&panel).try_draw(&mut panel).unwrap();
            assert_eq!(panel.0, ordered(loaded.scene()), "frame {frame}");
        }
    }
}
