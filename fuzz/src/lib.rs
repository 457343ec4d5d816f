//! The fuzz targets' checks, as plain functions: the targets call them on
//! libFuzzer's inputs, and `tests/regressions.rs` calls them on every kept
//! reproducer (on stable Rust, in CI). A check panics on a finding.

mod board;
mod link;
mod parse;
mod render;

pub use board::{check_board_loop, seeds as board_loop_seeds};
pub use link::{check_link, seeds as link_seeds};
pub use parse::check_parse;
pub use render::check_render;

use core::convert::Infallible;
use core::fmt::Write as _;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::Pixel;
use octrace_core::parse::{parse_bytes, ParseError, Parsed};
use octrace_core::scene::SceneCapacities;
use octrace_core::scene::{Camera, Normalization, Scene};

/// Parses `bytes` into `scene` and checks what the parser promises:
/// - it returns (never panics; libFuzzer catches panics and timeouts);
/// - `Err(n)`: exactly `n` errors were reported and the scene is cleared;
/// - `Ok`: no error was reported, the camera is valid and every light lies
///   within the normalised range;
/// - every error formats (its `Display` must not panic either).
///
/// Returns whether the scene parsed.
pub fn parse_checked<C: SceneCapacities>(bytes: &[u8], scene: &mut Scene<C>) -> bool {
    let mut reported = 0usize;
    let mut text = String::new();
    let result: Result<Parsed<'_>, usize> = parse_bytes(bytes, scene, &mut |e: ParseError<'_>| {
        reported += 1;
        text.clear();
        let _ = write!(text, "{e}");
        assert!(!text.is_empty(), "an error formats to nothing: {e:?}");
    });
    match result {
        Err(n) => {
            assert_eq!(n, reported, "returned error count differs from the errors reported");
            assert!(n > 0, "Err(0)");
            assert_eq!(scene.view().object_count(), 0, "a scene with errors must be cleared");
            false
        }
        Ok(parsed) => {
            assert_eq!(reported, 0, "Ok although errors were reported");
            let view = scene.view();
            assert!(Camera::check(&view.settings.view).is_ok(), "Ok with an invalid camera");
            for light in view.lights {
                assert!(Normalization::in_range(light.position), "light out of range: {light:?}");
            }
            if let Some(name) = parsed.imagefile {
                assert!(!name.is_empty() || bytes.contains(&b'"'), "empty IMAGEFILE from an unquoted token");
            }
            true
        }
    }
}

/// An 8×8 (or any size up to 16×16) RGB sink: the smallest `DrawTarget`.
pub struct Sink {
    pub size: Size,
    pub pixels: [Rgb888; 256],
    /// Pixels drawn outside the image (a renderer bug if ever non-zero).
    pub outside: u32,
}

impl Sink {
    pub fn new(width: u32, height: u32) -> Sink {
        assert!(width * height <= 256);
        Sink { size: Size::new(width, height), pixels: [Rgb888::new(0, 0, 0); 256], outside: 0 }
    }
}

impl OriginDimensions for Sink {
    fn size(&self) -> Size {
        self.size
    }
}

impl DrawTarget for Sink {
    type Color = Rgb888;
    type Error = Infallible;

    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Infallible>
    where
        I: IntoIterator<Item = Pixel<Rgb888>>,
    {
        for Pixel(p, c) in pixels {
            let (w, h) = (self.size.width as i32, self.size.height as i32);
            if p.x < 0 || p.y < 0 || p.x >= w || p.y >= h {
                self.outside += 1;
                continue;
            }
            self.pixels[(p.y * w + p.x) as usize] = c;
        }
        Ok(())
    }
}
