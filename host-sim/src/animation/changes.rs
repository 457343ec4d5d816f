//! What a frame of an animation changed from the frame before: the pixels
//! whose colour differs, and the rectangle that bounds them, which is all
//! the GIF and APNG writers store of a frame after the first.
//!
//! Invariants: the result depends on the two frames' pixels alone. Told
//! which areas the coherence re-traced, only those are compared (every
//! other pixel is the one before, by the coherence's exactness); told
//! nothing (frames rendered elsewhere and merged), every pixel is: both
//! give the same changes, so a merged animation is the direct render's
//! file byte for byte.

/// A rectangle of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Area {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl Area {
    /// The whole of a `width` × `height` image.
    pub fn whole(width: u32, height: u32) -> Area {
        Area { x: 0, y: 0, width, height }
    }

    /// The smallest area that holds both.
    pub fn union(self, other: Area) -> Area {
        let (x, y) = (self.x.min(other.x), self.y.min(other.y));
        let right = (self.x + self.width).max(other.x + other.width);
        let bottom = (self.y + self.height).max(other.y + other.height);
        Area { x, y, width: right - x, height: bottom - y }
    }

    /// Pixels in the area.
    pub fn pixels(self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Each pixel's index in a row-major image `width` pixels wide, row
    /// by row.
    pub fn indices(self, width: u32) -> impl Iterator<Item = usize> {
        (self.y..self.y + self.height)
            .flat_map(move |y| (self.x..self.x + self.width).map(move |x| y as usize * width as usize + x as usize))
    }

    /// The part of the area inside a `width` × `height` image.
    fn clipped(self, width: u32, height: u32) -> Area {
        let (x, y) = (self.x.min(width), self.y.min(height));
        Area { x, y, width: self.width.min(width - x), height: self.height.min(height - y) }
    }
}

/// The pixels a frame changed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Changes {
    /// One flag a pixel of the image, row-major: whether its colour
    /// differs from the frame before.
    pub changed: Vec<bool>,
    /// The smallest area that holds every changed pixel, `None` when
    /// none changed.
    pub bounds: Option<Area>,
}

impl Changes {
    /// Every pixel of a `width` × `height` frame changed: a first frame.
    pub fn everything(width: u32, height: u32) -> Changes {
        let bounds = (width > 0 && height > 0).then_some(Area::whole(width, height));
        Changes { changed: vec![true; width as usize * height as usize], bounds }
    }

    /// The pixels of `now` (`width` pixels a row, `channels` bytes a
    /// pixel) that differ from `before`, looked for within `retraced` when
    /// given (the areas the coherence re-traced: outside them nothing
    /// changed), else everywhere.
    pub fn between(before: &[u8], now: &[u8], width: u32, channels: usize, retraced: Option<&[Area]>) -> Changes {
        let pixels = now.len() / channels;
        let height = (pixels / width.max(1) as usize) as u32;
        let mut changes = Changes { changed: vec![false; pixels], bounds: None };
        let whole = [Area::whole(width, height)];
        for area in retraced.unwrap_or(&whole) {
            let area = area.clipped(width, height);
            for i in area.indices(width) {
                let at = i * channels..(i + 1) * channels;
                if before.get(at.clone()) != now.get(at) {
                    changes.changed[i] = true;
                    let pixel = Area { x: (i % width as usize) as u32, y: (i / width as usize) as u32, width: 1, height: 1 };
                    changes.bounds = Some(changes.bounds.map_or(pixel, |b| b.union(pixel)));
                }
            }
        }
        changes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_changes_are_the_pixels_that_differ_and_their_bounds() {
        let before = vec![0u8; 3 * 6 * 4];
        let mut now = before.clone();
        for (x, y) in [(1, 1), (4, 2)] {
            now[3 * (y * 6 + x) + 1] = 9;
        }
        let whole = Changes::between(&before, &now, 6, 3, None);
        assert_eq!(whole.bounds, Some(Area { x: 1, y: 1, width: 4, height: 2 }));
        assert_eq!(whole.changed.iter().filter(|&&c| c).count(), 2);
        // Told where to look (tiles of 2 that cover the changes), the same.
        let tiles = [Area { x: 0, y: 0, width: 2, height: 2 }, Area { x: 4, y: 2, width: 2, height: 2 }];
        assert_eq!(Changes::between(&before, &now, 6, 3, Some(&tiles)), whole);
        assert_eq!(Changes::between(&before, &before, 6, 3, None).bounds, None);
        // A tile past the image's edge is cut to it.
        let edge = [Area { x: 4, y: 2, width: 4, height: 4 }];
        assert_eq!(Changes::between(&before, &now, 6, 3, Some(&edge)).bounds, Some(Area { x: 4, y: 2, width: 1, height: 1 }));
        assert_eq!(Area { x: 1, y: 1, width: 2, height: 1 }.indices(6).collect::<Vec<_>>(), [7, 8]);
    }
}
