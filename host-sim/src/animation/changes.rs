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
                    let pixel =
                        Area { x: (i % width as usize) as u32, y: (i / width as usize) as u32, width: 1, height: 1 };
                    changes.bounds = Some(changes.bounds.map_or(pixel, |b| b.union(pixel)));
                }
            }
        }
        changes
    }
}

/// A frame after the first: the pixels it changed.
pub struct Delta {
    /// Where they lie (`None`: nothing changed).
    pub bounds: Option<Area>,
    /// Within `bounds`, row-major: whether each pixel changed, and every
    /// pixel's colour (RGB).
    pub changed: Vec<bool>,
    pub pixels: Vec<u8>,
}

/// An animation's frames held until the loop is complete (for its colours,
/// or a colour none of them shows): the first whole, each other
/// as what it changed.
pub struct LoopFrames {
    pub width: u32,
    pub height: u32,
    /// The first frame (RGB), and each other's changes.
    pub first: Vec<u8>,
    pub later: Vec<Delta>,
    /// The last frame, whole.
    current: Vec<u8>,
}

impl LoopFrames {
    /// No frame yet, of `width` × `height`.
    pub fn new(width: u32, height: u32) -> LoopFrames {
        LoopFrames { width, height, first: Vec::new(), later: Vec::new(), current: Vec::new() }
    }

    /// Adds the next frame (RGB), `retraced` the areas that can differ
    /// from the one before (`None`: any).
    pub fn push(&mut self, frame: &[u8], retraced: Option<&[Area]>) {
        if self.current.is_empty() {
            self.first = frame.to_vec();
            self.current = frame.to_vec();
            return;
        }
        let changes = Changes::between(&self.current, frame, self.width, 3, retraced);
        let mut delta = Delta { bounds: changes.bounds, changed: Vec::new(), pixels: Vec::new() };
        if let Some(area) = changes.bounds {
            for i in area.indices(self.width) {
                delta.changed.push(changes.changed[i]);
                delta.pixels.extend_from_slice(&frame[3 * i..3 * i + 3]);
            }
        }
        self.current.copy_from_slice(frame);
        self.later.push(delta);
    }

    /// Frames held.
    pub fn len(&self) -> usize {
        usize::from(!self.first.is_empty()) + self.later.len()
    }

    /// Whether no frame is held.
    pub fn is_empty(&self) -> bool {
        self.first.is_empty()
    }

    /// A colour no frame shows (`None` when every one of the 2²⁴ does).
    pub fn unused_colour(&self) -> Option<[u8; 3]> {
        let mut seen = vec![0u64; 1 << 18];
        let pixels = self.first.chunks(3).chain(self.later.iter().flat_map(|d| d.pixels.chunks(3)));
        for p in pixels {
            let c = (usize::from(p[0]) << 16) | (usize::from(p[1]) << 8) | usize::from(p[2]);
            seen[c >> 6] |= 1 << (c & 63);
        }
        let (word, bits) = seen.iter().enumerate().find(|(_, &bits)| bits != u64::MAX)?;
        let c = (word << 6) | (!bits).trailing_zeros() as usize;
        Some([(c >> 16) as u8, (c >> 8) as u8, c as u8])
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
        assert_eq!(
            Changes::between(&before, &now, 6, 3, Some(&edge)).bounds,
            Some(Area { x: 4, y: 2, width: 1, height: 1 })
        );
        assert_eq!(Area { x: 1, y: 1, width: 2, height: 1 }.indices(6).collect::<Vec<_>>(), [7, 8]);
    }
}
