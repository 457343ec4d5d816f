//! 256-colour output: the four ways of the thesis to show an image on a
//! display with a 256-entry colour table, streaming, without a framebuffer.
//!
//! - [`Scan`]: the thesis's method. Colours are hashed into the table as
//!   they come; a close enough entry is reused, otherwise a free one is
//!   taken, and once the table is full the closest entry is used.
//! - [`Dither`]: ordered (8×8 Bayer) dithering onto a fixed 6×6×6 colour
//!   cube.
//! - [`Coarse`]: [`Dither`] with black outlines where the object under the
//!   pixel changes ("it forms boundaries around objects").
//! - [`Gray`]: 256 gray levels by luma.
//!
//! Every mode works on the gamma-encoded colours the display shows, pixel by
//! pixel in raster order, and gives the same indices on every target.
//! [`render_indexed`] streams a renderer's rows through a mode into any
//! `DrawTarget` of [`PaletteIndex`] colours; [`Quantized`] puts a mode in
//! front of such a display as a truecolour `DrawTarget`.

mod dither;
mod gray;
mod scan;

pub use dither::{Coarse, Dither, BAYER_8X8, CUBE_LEVELS};
pub use gray::Gray;
pub use scan::{Scan, CLOSE_ENOUGH};

use crate::accel::Linked;
use crate::render::Renderer;
use crate::scene::ObjectId;
use crate::shade::Stats;
use core::ops::Range;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, Point, Size};
use embedded_graphics_core::pixelcolor::raw::RawU8;
use embedded_graphics_core::pixelcolor::{PixelColor, Rgb888, RgbColor};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;

/// A colour given as an entry of a 256-entry colour table: what a palette
/// display (or an indexed image file) takes. embedded-graphics has no such
/// colour type.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PaletteIndex(pub u8);

impl PixelColor for PaletteIndex {
    type Raw = RawU8;
}

impl From<RawU8> for PaletteIndex {
    fn from(raw: RawU8) -> Self {
        PaletteIndex(embedded_graphics_core::pixelcolor::raw::RawData::into_inner(raw))
    }
}

/// A 256-entry colour table; entries not in use are black.
pub type ColorTable = [Rgb888; 256];

/// A way to map colours onto a colour table.
pub trait Quantizer {
    /// The index for the pixel at (`x`, `y`), which shows `color` and
    /// `object` (`None`: background). Pixels must come in raster order
    /// (rows top to bottom, each left to right) for modes that look at
    /// neighbours or learn as they go.
    fn quantize(&mut self, x: u32, y: u32, color: Rgb888, object: Option<ObjectId>) -> u8;

    /// The colour table as it stands (a learning mode's grows as it goes).
    fn table(&self) -> &ColorTable;

    /// How many entries of the table are in use.
    fn used(&self) -> usize;
}

/// Renders `rows` (clipped to the image) through `quantizer` into `target`,
/// one `fill_contiguous` per row; returns the counters of this call. Rows
/// are traced in order, as the neighbour-aware modes need.
///
/// ```
/// use embedded_graphics::{mock_display::MockDisplay, prelude::*, primitives::Rectangle};
/// use octrace_core::{profile::Board16K, Raytracer};
/// use octrace_core::palette::{render_indexed, Dither, PaletteIndex, Quantizer};
///
/// let mut raytracer = Raytracer::<Board16K>::new();
/// let scene = raytracer.load("RASTER 8 8\nVIEWPOINT 0 0 5\nORIGIN 0 0 0\nUPVECTOR 0 1 0\nBACKGROUND 0 0 1\nLIGHT 10 5 5 5\nSPHERE 1 1.5 0 0 0\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n")?;
/// let mut display = MockDisplay::<PaletteIndex>::new();
/// scene.with_renderer(scene.raster(), |renderer| render_indexed(renderer, 0..8, &mut Dither, &mut display))??;
/// assert_eq!(display.affected_area(), Rectangle::new(Point::zero(), Size::new(8, 8)));
/// let corner = display.get_pixel(Point::zero()).unwrap();
/// assert_eq!(Dither.table()[corner.0 as usize].b(), 255, "the blue background");
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
pub fn render_indexed<L, Q, D>(
    renderer: &mut Renderer<'_, L>,
    rows: Range<u32>,
    quantizer: &mut Q,
    target: &mut D,
) -> Result<Stats, D::Error>
where
    L: Linked,
    Q: Quantizer,
    D: DrawTarget<Color = PaletteIndex>,
{
    let size = renderer.size();
    let before = renderer.stats();
    for y in rows.start.min(size.height)..rows.end.min(size.height) {
        let line = Rectangle::new(Point::new(0, y as i32), Size::new(size.width, 1));
        // The renderer and the quantizer are both borrowed by the row
        // iterator: a pixel is traced, then mapped, as the target pulls it.
        let pixels = renderer.row(y, 0..size.width);
        let indices = pixels.enumerate().map(|(x, p)| PaletteIndex(quantizer.quantize(x as u32, y, p.color, p.object)));
        target.fill_contiguous(&line, indices)?;
    }
    Ok(renderer.stats().since(&before))
}

/// A truecolour `DrawTarget` in front of a palette display: every pixel
/// drawn is mapped by the quantizer and passed on as a [`PaletteIndex`].
/// Anything that draws `Rgb888` (the renderer, or embedded-graphics text
/// and shapes) can so draw on a 256-colour display. It does not know the
/// objects under the pixels: [`Coarse`] draws no outlines through it (use
/// [`render_indexed`]).
///
/// ```
/// use embedded_graphics::{mock_display::MockDisplay, prelude::*};
/// use octrace_core::{profile::Board16K, Raytracer};
/// use octrace_core::palette::{Gray, PaletteIndex, Quantized, Quantizer};
///
/// let mut raytracer = Raytracer::<Board16K>::new();
/// let scene = raytracer.load("RASTER 8 8\nVIEWPOINT 0 0 5\nORIGIN 0 0 0\nUPVECTOR 0 1 0\nBACKGROUND 0 0 1\nLIGHT 10 5 5 5\nSPHERE 1 1.5 0 0 0\nSURFACE 1 .1 .1 .1 .8 .2 .2 0 0 0 1 0 0\n")?;
/// let mut gray = Gray;
/// let mut target = Quantized { display: MockDisplay::<PaletteIndex>::new(), quantizer: &mut gray };
/// scene.image(scene.raster()).try_draw(&mut target)?;
/// let corner = target.display.get_pixel(Point::zero()).unwrap();
/// let centre = target.display.get_pixel(Point::new(4, 4)).unwrap();
/// assert_ne!(corner, centre, "the sphere stands out from the background");
/// let shade = gray.table()[centre.0 as usize];
/// assert!(shade.r() == shade.g() && shade.g() == shade.b());
/// # Ok::<(), Box<dyn core::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct Quantized<'a, D, Q> {
    /// The palette display the indices go to.
    pub display: D,
    /// Maps each truecolour pixel to an index (and may keep state: dither).
    pub quantizer: &'a mut Q,
}

impl<D: Dimensions, Q> Dimensions for Quantized<'_, D, Q> {
    fn bounding_box(&self) -> Rectangle {
        self.display.bounding_box()
    }
}

impl<D, Q> DrawTarget for Quantized<'_, D, Q>
where
    D: DrawTarget<Color = PaletteIndex>,
    Q: Quantizer,
{
    type Color = Rgb888;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        let quantizer = &mut *self.quantizer;
        self.display.draw_iter(pixels.into_iter().map(|Pixel(p, c)| {
            let index = quantizer.quantize(p.x.max(0) as u32, p.y.max(0) as u32, c, None);
            Pixel(p, PaletteIndex(index))
        }))
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(&mut self, area: &Rectangle, colors: I) -> Result<(), D::Error> {
        let (quantizer, width) = (&mut *self.quantizer, area.size.width.max(1));
        let origin = area.top_left;
        let indices = colors.into_iter().enumerate().map(|(i, c)| {
            let (x, y) = (origin.x + (i as u32 % width) as i32, origin.y + (i as u32 / width) as i32);
            PaletteIndex(quantizer.quantize(x.max(0) as u32, y.max(0) as u32, c, None))
        });
        self.display.fill_contiguous(area, indices)
    }
}

/// The squared distance of two colours in RGB.
#[inline]
fn distance_squared(a: Rgb888, b: Rgb888) -> u32 {
    let d = |x: u8, y: u8| (x as i32 - y as i32).unsigned_abs().pow(2);
    d(a.r(), b.r()) + d(a.g(), b.g()) + d(a.b(), b.b())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parse::parse;
    use crate::profile::Board16K;
    use crate::scene::Scene;
    use embedded_graphics_core::geometry::OriginDimensions;

    /// A strict palette display: every pixel must land inside it, once.
    struct Mock {
        pixels: [[Option<u8>; 6]; 4],
    }

    impl OriginDimensions for Mock {
        fn size(&self) -> Size {
            Size::new(6, 4)
        }
    }

    impl DrawTarget for Mock {
        type Color = PaletteIndex;
        type Error = ();

        fn draw_iter<I: IntoIterator<Item = Pixel<PaletteIndex>>>(&mut self, pixels: I) -> Result<(), ()> {
            for Pixel(p, c) in pixels {
                assert!(self.bounding_box().contains(p), "{p:?} outside");
                let slot = &mut self.pixels[p.y as usize][p.x as usize];
                assert!(slot.is_none(), "{p:?} drawn twice");
                *slot = Some(c.0);
            }
            Ok(())
        }
    }

    #[test]
    fn render_indexed_and_quantized_draw_the_same_indices() {
        let mut scene: Scene<Board16K> = Scene::new();
        let text = "RASTER 6 4 LIGHT 10 0 0 10 SPHERE 1 1 0 0 0 SURFACE 1 0.1 0.1 0.1 0.8 0.4 0.2 0 0 0 0 0 0";
        parse(text, &mut scene, &mut |e| panic!("{e}")).unwrap();
        let view = scene.view();
        let mut direct = Mock { pixels: [[None; 6]; 4] };
        let naive = crate::accel::SceneAccelerator::<Board16K>::new(None, crate::accel::LightBuffer::NONE);
        let mut renderer = Renderer::new(view, &naive).unwrap();
        render_indexed(&mut renderer, 0..4, &mut Dither, &mut direct).unwrap();
        let mut through = Quantized { display: Mock { pixels: [[None; 6]; 4] }, quantizer: &mut Dither };
        Renderer::new(view, &naive).unwrap().render(&mut through).unwrap();
        assert_eq!(direct.pixels, through.display.pixels);
        assert!(direct.pixels.iter().flatten().all(|p| p.is_some()));
        // Single pixels go through the quantizer too.
        let mut single = Quantized { display: Mock { pixels: [[None; 6]; 4] }, quantizer: &mut Gray };
        single.draw_iter([Pixel(Point::new(5, 3), Rgb888::new(255, 255, 255))]).unwrap();
        assert_eq!(single.display.pixels[3][5], Some(255));
    }
}
