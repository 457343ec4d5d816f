//! A loaded scene as an embedded-graphics image: drawn whole or in part,
//! traced as the display takes its rows.

use crate::profile::Profile;
use crate::scene::CameraError;
use core::fmt;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, OriginDimensions, Point, Size};
use embedded_graphics_core::image::ImageDrawable;
use embedded_graphics_core::pixelcolor::{PixelColor, Rgb888};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;

use super::LoadedScene;

/// Why a [`TracedImage`] could not be drawn with
/// [`TracedImage::try_draw`].
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawError<E> {
    /// The camera cannot be set up for this size (see [`CameraError`]).
    Camera(CameraError),
    /// The display's own error.
    Target(E),
}

impl<E: fmt::Display> fmt::Display for DrawError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DrawError::Camera(e) => write!(f, "{e}"),
            DrawError::Target(e) => write!(f, "the display failed: {e}"),
        }
    }
}

impl<E: fmt::Debug + fmt::Display> core::error::Error for DrawError<E> {}

/// A traced scene as an embedded-graphics image, `size` pixels in the colour
/// `C` (any colour that converts from `Rgb888`: `Rgb565`, `Gray4`, …), like
/// `tinybmp::Bmp<C>`. Each draw traces the pixels as the display takes
/// them, one scanline at a time: no framebuffer.
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
    pub(super) color: core::marker::PhantomData<C>,
}

impl<P: Profile, C> fmt::Debug for TracedImage<'_, '_, P, C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TracedImage").field("size", &self.size).field("scene", self.scene).finish()
    }
}

impl<P: Profile, C> Clone for TracedImage<'_, '_, P, C> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: Profile, C> Copy for TracedImage<'_, '_, P, C> {}

impl<P: Profile, C: PixelColor + From<Rgb888>> TracedImage<'_, '_, P, C> {
    /// Draws the image at the origin of `target`, telling a camera that
    /// cannot be set up (a zero size) apart from the display's errors;
    /// [`ImageDrawable::draw`] draws nothing then.
    pub fn try_draw<D: DrawTarget<Color = C>>(&self, target: &mut D) -> Result<(), DrawError<D::Error>> {
        self.scene.draw_area(self.size, &Rectangle::new(Point::zero(), self.size), Point::zero(), target)
    }
}

impl<P: Profile, C> OriginDimensions for TracedImage<'_, '_, P, C> {
    fn size(&self) -> Size {
        self.size
    }
}

impl<P: Profile, C: PixelColor + From<Rgb888>> ImageDrawable for TracedImage<'_, '_, P, C> {
    type Color = C;

    fn draw<D: DrawTarget<Color = C>>(&self, target: &mut D) -> Result<(), D::Error> {
        self.draw_sub_image(target, &self.bounding_box())
    }

    fn draw_sub_image<D: DrawTarget<Color = C>>(&self, target: &mut D, area: &Rectangle) -> Result<(), D::Error> {
        match self.scene.draw_area(self.size, area, Point::zero(), target) {
            Ok(()) | Err(DrawError::Camera(_)) => Ok(()),
            Err(DrawError::Target(e)) => Err(e),
        }
    }
}

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
    use crate::profile::Board16K;
    use crate::Raytracer;
    use embedded_graphics_core::pixelcolor::{Gray4, Rgb565};

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
}
