//! A loaded scene as an embedded-graphics image: drawn whole or in part,
//! traced as the display takes its rows, dithered onto a panel of few
//! levels.

use crate::panel::{Dithered, Dithering, TracedColor, IMAGE_ERROR_WORDS};
use crate::profile::Profile;
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, OriginDimensions, Point, Size};
use embedded_graphics_core::image::ImageDrawable;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;

use super::{DrawError, LoadedScene};

/// A traced scene as an embedded-graphics image, `size` pixels in the colour
/// `C`, like `tinybmp::Bmp<C>`. Each draw traces the pixels as the display
/// takes them, one scanline at a time: no framebuffer.
///
/// A truecolour `C` (`Rgb565`, `Rgb888`, …) takes each pixel converted; a
/// panel of few levels (`BinaryColor`, `Gray2`, `Gray4`,
/// [`BlackWhiteRed`](crate::panel::BlackWhiteRed)) takes it dithered, by
/// [`Dithering::FsPe`] unless [`TracedImage::dithered`] says otherwise (see
/// [`panel`](crate::panel): a sub-image is dithered as an image of its own).
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
pub struct TracedImage<'s, 'r, P: Profile, C> {
    pub(super) scene: &'s LoadedScene<'r, P>,
    pub(super) size: Size,
    pub(super) dithering: Dithering,
    pub(super) color: core::marker::PhantomData<C>,
}

/// A loaded scene's pictures as images (drawn through `embedded-graphics`'
/// [`Image`](https://docs.rs/embedded-graphics/latest/embedded_graphics/image/struct.Image.html)).
impl<'r, P: Profile> LoadedScene<'r, P> {
    /// The scene as an image of `size` pixels in the colour `C`.
    pub fn image<C>(&self, size: Size) -> TracedImage<'_, 'r, P, C> {
        TracedImage { scene: self, size, dithering: Dithering::default(), color: core::marker::PhantomData }
    }

    /// The scene as an image as large as `target`, in its colour: what
    /// `Image::new(&scene.image_for(&display), Point::zero())` draws.
    pub fn image_for<D: DrawTarget>(&self, target: &D) -> TracedImage<'_, 'r, P, D::Color> {
        self.image(target.bounding_box().size)
    }
}

impl<P: Profile, C> fmt::Debug for TracedImage<'_, '_, P, C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TracedImage")
            .field("size", &self.size)
            .field("dithering", &self.dithering)
            .field("scene", self.scene)
            .finish()
    }
}

impl<P: Profile, C> Clone for TracedImage<'_, '_, P, C> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile, C> Copy for TracedImage<'_, '_, P, C> {}

impl<P: Profile, C> TracedImage<'_, '_, P, C> {
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
        TracedImage { dithering, ..self }
    }

    /// How it is dithered on a panel of few levels.
    pub fn dithering(&self) -> Dithering {
        self.dithering
    }
}

impl<P: Profile, C: TracedColor> TracedImage<'_, '_, P, C> {
    /// Draws the image at the origin of `target`, telling a camera that
    /// cannot be set up (a zero size), or an image too wide for the error
    /// row on the stack, apart from the display's errors;
    /// [`ImageDrawable::draw`] draws nothing then.
    pub fn try_draw<D: DrawTarget<Color = C>>(&self, target: &mut D) -> Result<(), DrawError<D::Error>> {
        self.draw_area(&self.bounding_box(), target, None)
    }

    /// [`TracedImage::try_draw`] with error diffusion's rows in `rows`
    /// (at least [`Panel::error_words`](crate::panel::Panel::error_words)
    /// of the image's width) instead of on the draw's stack: for an image
    /// wider than [`IMAGE_ERROR_WORDS`] allows, or a board short of stack.
    ///
    /// ```
    /// use embedded_graphics::{mock_display::MockDisplay, pixelcolor::Gray4, prelude::*};
    /// use octrace_core::{panel::Panel, profile::Board16K, Raytracer};
    ///
    /// let mut raytracer = Raytracer::<Board16K>::new();
    /// let scene = raytracer.load("BACKGROUND 0.5 0.5 0.5\n")?;
    /// let mut display = MockDisplay::<Gray4>::new();
    /// let mut rows = [0i16; Panel::Gray4.error_words(64)];
    /// scene.image_for(&display).try_draw_with(&mut display, &mut rows)?;
    ///
    /// let mut on_the_stack = MockDisplay::<Gray4>::new();
    /// scene.image_for(&on_the_stack).try_draw(&mut on_the_stack)?;
    /// assert_eq!(display, on_the_stack);
    /// # Ok::<(), Box<dyn core::error::Error>>(())
    /// ```
    pub fn try_draw_with<D: DrawTarget<Color = C>>(
        &self,
        target: &mut D,
        rows: &mut [i16],
    ) -> Result<(), DrawError<D::Error>> {
        self.draw_area(&self.bounding_box(), target, Some(rows))
    }

    /// Draws `area` of the image with its top-left pixel at the origin of
    /// `target`, dithered for a panel in `rows` or on the stack.
    fn draw_area<D: DrawTarget<Color = C>>(
        &self,
        area: &Rectangle,
        target: &mut D,
        rows: Option<&mut [i16]>,
    ) -> Result<(), DrawError<D::Error>> {
        let mut shifted = Shifted { target, offset: Point::zero() - area.top_left };
        // The pixels there are: the rows a ditherer is set up for.
        let area = &area.intersection(&self.bounding_box());
        match (C::PANEL, rows) {
            (None, _) => self.scene.render_area(self.size, area, &mut shifted),
            (Some(_), Some(rows)) => self.draw_dithered(area, &mut shifted, rows),
            // A small panel's row in a small frame.
            (Some(panel), None) if panel.error_words(area.size.width) <= SMALL_ERROR_WORDS => {
                self.draw_dithered_on_stack::<SMALL_ERROR_WORDS, _>(area, &mut shifted)
            }
            (Some(_), None) => self.draw_dithered_on_stack::<IMAGE_ERROR_WORDS, _>(area, &mut shifted),
        }
    }

    /// Draws `area` dithered, its error row of `WORDS` on this frame. Not
    /// inlined: a truecolour draw never holds the row.
    #[inline(never)]
    fn draw_dithered_on_stack<const WORDS: usize, D: DrawTarget<Color = C>>(
        &self,
        area: &Rectangle,
        target: &mut D,
    ) -> Result<(), DrawError<D::Error>> {
        self.draw_dithered(area, target, &mut [0; WORDS])
    }

    /// Not inlined: one copy of the render loop whatever frame the row is in.
    #[inline(never)]
    fn draw_dithered<D: DrawTarget<Color = C>>(
        &self,
        area: &Rectangle,
        target: &mut D,
        rows: &mut [i16],
    ) -> Result<(), DrawError<D::Error>> {
        let (left, width) = (area.top_left.x, area.size.width);
        let mut dithered = Dithered::across(target, self.dithering, left, width, rows).map_err(DrawError::ErrorRow)?;
        self.scene.render_area(self.size, area, &mut dithered)
    }
}

impl<P: Profile, C> OriginDimensions for TracedImage<'_, '_, P, C> {
    fn size(&self) -> Size {
        self.size
    }
}

impl<P: Profile, C: TracedColor> ImageDrawable for TracedImage<'_, '_, P, C> {
    type Color = C;

    fn draw<D: DrawTarget<Color = C>>(&self, target: &mut D) -> Result<(), D::Error> {
        self.draw_sub_image(target, &self.bounding_box())
    }

    fn draw_sub_image<D: DrawTarget<Color = C>>(&self, target: &mut D, area: &Rectangle) -> Result<(), D::Error> {
        match self.draw_area(area, target, None) {
            Ok(()) | Err(DrawError::Camera(_) | DrawError::ErrorRow(_) | DrawError::Stopped) => Ok(()),
            Err(DrawError::Target(e)) => Err(e),
        }
    }
}

/// The error row of a panel image up to 256 `i16`s wide (a one-bit 128×64
/// OLED needs 128) takes only this much of the draw's stack (512 bytes).
const SMALL_ERROR_WORDS: usize = 256;

/// A target seen shifted by `offset`: a sub-image's pixels land at the
/// target's origin.
pub(super) struct Shifted<'t, D> {
    pub(super) target: &'t mut D,
    pub(super) offset: Point,
}

impl<D: DrawTarget> Dimensions for Shifted<'_, D> {
    fn bounding_box(&self) -> Rectangle {
        let b = self.target.bounding_box();
        Rectangle::new(b.top_left - self.offset, b.size)
    }
}

impl<D: DrawTarget> DrawTarget for Shifted<'_, D> {
    type Color = D::Color;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<D::Color>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        let offset = self.offset;
        self.target.draw_iter(pixels.into_iter().map(|Pixel(p, c)| Pixel(p + offset, c)))
    }

    fn fill_contiguous<I: IntoIterator<Item = D::Color>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), D::Error> {
        self.target.fill_contiguous(&Rectangle::new(area.top_left + self.offset, area.size), colors)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{Grid, SCENE};
    use super::*;
    use crate::panel::{Ditherer, ErrorRowTooShort};
    use crate::profile::Board16K;
    use crate::render::Progressive;
    use crate::Raytracer;
    use embedded_graphics_core::pixelcolor::{BinaryColor, Gray4, Rgb565, Rgb888};
    use embedded_graphics_core::primitives::PointsIter;
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
        image.try_draw_with(&mut again, &mut [0; 801]).unwrap();
        assert!(again.0[0].iter().all(|c| c.is_some()));
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
        scene.draw_progressive(&Progressive::new(Size::new(12, 8), 4), &mut progressive).unwrap();
        assert_eq!(progressive.0, ordered(&scene));
    }

    #[test]
    fn an_animated_panel_shows_each_frames_ordered_picture() {
        use crate::animation::{Coherence, Key, Motion, Track};
        use core::sync::atomic::AtomicU8;
        let text = "FRAMES 4\nRASTER 12 8\nBACKGROUND .4 .4 .4\nSURFACE 1 .1 .1 .1 .7 .2 .2 0 0 0 1 0 0\n\
                    LIGHT 10 5 5 5\nSPHERE 1 2 0 0 -4\nSPHERE 1 0.5 -3 2 0 MOVE 0 0 0 0  3 1.5 0 0\n";
        let counts: [AtomicU8; Coherence::tiles_for(12, 8, 4)] = [const { AtomicU8::new(0) }; 6];
        let coherence = Coherence::new(&counts, Size::new(12, 8), 4).unwrap();
        let (mut tracks, mut keys, mut displacements) = ([Track::EMPTY; 1], [Key::default(); 2], [[0; 3]; 4]);
        let mut raytracer = Raytracer::<Board16K>::new();
        let first = raytracer.load_frame(text, 0).unwrap();
        let frames = first.frames().unwrap();
        let motion = Motion::read(text, frames, &first.view(), 0, &mut tracks, &mut keys, &mut displacements).unwrap();
        let mut panel = Overdrawn([[None; 12]; 8]);
        for frame in frames.all().chain(frames.all()) {
            let scene = raytracer.load_frame(text, frame).unwrap();
            coherence.plan();
            scene.draw_changes(&motion, frame, &coherence, &mut panel).unwrap();
            assert_eq!(panel.0, ordered(&scene), "frame {frame}");
        }
    }
}
