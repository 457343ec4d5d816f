//! Ways to cut an image into pieces that can be rendered independently, in
//! any order, on any number of cores: every pixel depends only on its
//! coordinates, so every cut gives the same bits.
//!
//! The core has no threads; the caller hands the pieces out. Two cuts:
//! tiles, for a work queue (a shared counter picks the next tile index, so
//! a core that finishes early takes more), and interleaved rows, for a
//! fixed split between the cores of a dual-core part (row `y` to core
//! `y mod cores`: neighbouring rows cost about the same, so the cores finish
//! together without any coordination).
//!
//! # Both cores of a dual-core part
//!
//! 1. Load the scene once ([`Raytracer::load`](crate::Raytracer::load)),
//!    on one core.
//! 2. Hand the other core the scene's [`share`](crate::LoadedScene::share)
//!    (`Copy`, read-only, `Send`), then start it.
//! 3. Give each core a [`Renderer`](super::Renderer) of its own: the
//!    loading core's with [`LoadedScene::with_renderer`](crate::LoadedScene::with_renderer),
//!    every other core's with [`SharedScene::renderer`](crate::SharedScene::renderer)
//!    in a [`RendererRoom`](crate::RendererRoom) of its own (a mailbox and
//!    screen lists, the only state a render writes).
//! 4. Core `c` renders the rows [`interleaved_rows`]`(height, c, 2)` with
//!    [`Renderer::row`](super::Renderer::row). One core sends all rows to
//!    the display in order; the other hands its rows over through a
//!    [`Handoff`](super::Handoff), a ring of a few row buffers, each with an
//!    atomic row number: no heap, no lock, no `unsafe`.
//!
//! octrace's firmware does exactly this on qemu's two-core MPS2-AN521
//! (`firmware/src/both_cores.rs`), and so does the Raspberry Pi Pico
//! template (`examples/pico-st7789`): their pictures are bit for bit the
//! one-core picture, and each core does about half of the work.

use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::primitives::Rectangle;

/// An image of `size` cut into tiles of at most `side` × `side` pixels, in
/// row-major order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiles {
    size: Size,
    side: u32,
    across: u32,
    down: u32,
}

impl Tiles {
    /// The tiles of an image of `size`; `side` is at least 1.
    pub fn new(size: Size, side: u32) -> Tiles {
        let side = side.max(1);
        Tiles { size, side, across: size.width.div_ceil(side), down: size.height.div_ceil(side) }
    }

    /// How many tiles there are.
    pub fn count(&self) -> u32 {
        self.across * self.down
    }

    /// Tile `index` (0 ≤ index < count), clipped to the image.
    pub fn get(&self, index: u32) -> Option<Rectangle> {
        if index >= self.count() {
            return None;
        }
        let (x, y) = ((index % self.across) * self.side, (index / self.across) * self.side);
        let size = Size::new(self.side.min(self.size.width - x), self.side.min(self.size.height - y));
        Some(Rectangle::new(Point::new(x as i32, y as i32), size))
    }

    /// The tiles in raster order.
    pub fn iter(&self) -> impl Iterator<Item = Rectangle> + '_ {
        (0..self.count()).filter_map(|i| self.get(i))
    }
}

/// The rows core `core` of `cores` renders when rows are dealt out in turn:
/// `core`, `core + cores`, … below `height`.
pub fn interleaved_rows(height: u32, core: u32, cores: u32) -> impl Iterator<Item = u32> {
    let cores = cores.max(1);
    (core.min(height)..height).step_by(cores as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once() {
        for (w, h, side) in [(1, 1, 16), (160, 128, 32), (33, 17, 8), (5, 40, 7), (320, 240, 1000)] {
            let tiles = Tiles::new(Size::new(w, h), side);
            let mut covered = [[0u8; 320]; 240];
            for t in tiles.iter() {
                let (x0, y0) = (t.top_left.x as usize, t.top_left.y as usize);
                for row in &mut covered[y0..y0 + t.size.height as usize] {
                    for c in &mut row[x0..x0 + t.size.width as usize] {
                        *c += 1;
                    }
                }
            }
            for (y, row) in covered.iter().enumerate() {
                for (x, &c) in row.iter().enumerate() {
                    let inside = (x as u32) < w && (y as u32) < h;
                    assert_eq!(c, inside as u8, "{w}x{h}/{side} at ({x}, {y})");
                }
            }
            assert_eq!(tiles.get(tiles.count()), None);
        }
        assert_eq!(Tiles::new(Size::new(0, 5), 4).count(), 0);
    }

    #[test]
    fn interleaved_rows_deal_every_row_to_one_core() {
        for (height, cores) in [(128, 2), (7, 3), (1, 2), (5, 1), (3, 8)] {
            let mut seen = [0u8; 128];
            for core in 0..cores {
                for y in interleaved_rows(height, core, cores) {
                    assert_eq!(y % cores, core);
                    seen[y as usize] += 1;
                }
            }
            assert!(seen[..height as usize].iter().all(|&n| n == 1), "{height} rows on {cores} cores");
        }
    }
}
