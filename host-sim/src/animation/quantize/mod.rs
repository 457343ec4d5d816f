//! GIF colours for a whole animation: a colour table chosen from every
//! colour the loop shows, each weighted by the pixels and frames it shows
//! in ([`table`]); a frame whose new colours that table serves badly gets
//! a table of its own; error diffusion that chooses anew only the pixels a
//! frame changed ([`dither`]), so what did not move keeps its index.
//!
//! Written here, not taken from a crate: of the MIT/Apache ones,
//! `color_quant` (NeuQuant) and `exoquant` choose colours in floating
//! point, and `quantette` (Wu's cut, k-means) in floating point too, in
//! its colour spaces and over threads, so each would have to be proved to
//! give the same table on every machine; none weighs colours over a loop,
//! gives a frame its own table, or diffuses error around kept pixels, which
//! is most of this module. (`gifski` and `imagequant` are AGPL and GPL.)
//!
//! Invariants: the indices depend on the frames' pixels alone, in
//! integers: the same frames give the same file on every machine, however
//! they were rendered (together with coherence, whole, or apart and
//! merged). Each frame's table has at most 255 colours; index 255 is left
//! free for GIF's transparent pixels.

mod dither;
pub(crate) mod table;

use super::changes::{Area, Changes, LoopFrames};
use dither::{diffuse, Canvas};
use std::collections::HashMap;
use table::{distance, table_for, Nearest, Weighted};

/// Colours a table holds: GIF's 256 less the transparent index.
pub const ENTRIES: usize = 255;
/// The index no table uses: GIF's transparent pixels.
pub const TRANSPARENT: u8 = 255;

/// Every colour of the loop `frames`, weighted by the pixels and frames it
/// shows in.
fn colours(frames: &LoopFrames) -> Vec<Weighted> {
    let mut weights: HashMap<[u8; 3], u64> = HashMap::new();
    let mut since = vec![0u32; frames.first.len() / 3];
    let mut frame = frames.first.clone();
    for (k, delta) in frames.later.iter().enumerate() {
        let Some(area) = delta.bounds else { continue };
        for (j, i) in area.indices(frames.width).enumerate() {
            if delta.changed[j] {
                let old = [frame[3 * i], frame[3 * i + 1], frame[3 * i + 2]];
                *weights.entry(old).or_default() += u64::from(k as u32 + 1 - since[i]);
                since[i] = k as u32 + 1;
                frame[3 * i..3 * i + 3].copy_from_slice(&delta.pixels[3 * j..3 * j + 3]);
            }
        }
    }
    let count = frames.len() as u32;
    for (i, p) in frame.chunks(3).enumerate() {
        *weights.entry([p[0], p[1], p[2]]).or_default() += u64::from(count - since[i]);
    }
    weights.into_iter().collect()
}

/// One frame of the GIF: the area it covers and each pixel's index there
/// (or [`TRANSPARENT`]: the pixel shows what it showed), and its own
/// table, if it has one (else the GIF's).
pub struct GifFrame {
    pub area: Area,
    pub indices: Vec<u8>,
    pub table: Option<Vec<[u8; 3]>>,
}

/// The loop quantized: the GIF's table and its frames.
pub struct Quantized {
    pub table: Vec<[u8; 3]>,
    pub frames: Vec<GifFrame>,
}

/// Quantizes `frames` for a GIF.
pub fn quantize(frames: &LoopFrames) -> Quantized {
    let (width, height) = (frames.width, frames.height);
    let global = table_for(&colours(frames), ENTRIES);
    let global_nearest = Nearest::new(&global);
    let mut wanted = frames.first.clone();
    let mut shown = vec![0u8; wanted.len()];
    let mut indices = vec![0u8; wanted.len() / 3];
    let mut out = Vec::with_capacity(frames.len());
    let whole = Area::whole(width, height);
    let all = vec![true; indices.len()];
    let mut canvas = Canvas { wanted: &wanted, width, shown: &mut shown, indices: &mut indices };
    diffuse(&mut canvas, whole, &all, &global_nearest);
    out.push(GifFrame { area: whole, indices: indices.clone(), table: None });
    let mut changed = vec![false; indices.len()];
    for delta in &frames.later {
        let Some(area) = delta.bounds else {
            out.push(GifFrame {
                area: Area { x: 0, y: 0, width: 1, height: 1 },
                indices: vec![TRANSPARENT],
                table: None,
            });
            continue;
        };
        let mut new_colours: Vec<[u8; 3]> = Vec::new();
        for (j, i) in area.indices(width).enumerate() {
            changed[i] = delta.changed[j];
            wanted[3 * i..3 * i + 3].copy_from_slice(&delta.pixels[3 * j..3 * j + 3]);
            if changed[i] {
                new_colours.push([delta.pixels[3 * j], delta.pixels[3 * j + 1], delta.pixels[3 * j + 2]]);
            }
        }
        let local = own_table(&new_colours, &global_nearest);
        let nearest = local.as_ref().unwrap_or(&global_nearest);
        let before: Vec<u8> =
            area.indices(width).flat_map(|i| [shown[3 * i], shown[3 * i + 1], shown[3 * i + 2]]).collect();
        let mut canvas = Canvas { wanted: &wanted, width, shown: &mut shown, indices: &mut indices };
        diffuse(&mut canvas, area, &changed, nearest);
        out.push(changed_frame(area, &before, &shown, &indices, width, local.map(|n| n.table().to_vec())));
        area.indices(width).for_each(|i| changed[i] = false);
    }
    Quantized { table: global, frames: out }
}

/// A table of the frame's own for `colours`, the frame's new pixels, when
/// `global` serves them badly: when their mean squared distance to it is
/// over [`OWN_TABLE_ABOVE`] and one made for them halves it, and the frame
/// changes enough pixels that the 768 bytes of a table are a small part
/// of it. (A frame's own table costs more than its bytes: every pixel it
/// changes is drawn anew, none left transparent for keeping its index.)
fn own_table(colours: &[[u8; 3]], global: &Nearest) -> Option<Nearest> {
    if colours.len() < 4096 {
        return None;
    }
    let mut counts: HashMap<[u8; 3], u64> = HashMap::new();
    colours.iter().for_each(|&c| *counts.entry(c).or_default() += 1);
    let counts: Vec<Weighted> = counts.into_iter().collect();
    let error = |nearest: &Nearest| -> u64 {
        counts.iter().map(|&(c, w)| w * u64::from(distance(c, nearest.table()[nearest.index(c) as usize]))).sum()
    };
    let served = error(global);
    if served <= OWN_TABLE_ABOVE * colours.len() as u64 {
        return None;
    }
    let own = Nearest::new(&table_for(&counts, ENTRIES));
    (2 * error(&own) < served).then_some(own)
}

/// The mean squared distance (over the three channels) of a frame's new
/// pixels to the loop's table above which a table of the frame's own is
/// tried: 8, about 44 dB.
const OWN_TABLE_ABOVE: u64 = 8;

/// The GIF frame of `area` whose pixels showed `before` (RGB, the area's
/// pixels row by row) and show `shown` now (RGB, the whole image), chosen
/// as `indices`: the smallest area holding every pixel whose colour
/// changed, the others in it transparent.
fn changed_frame(
    area: Area,
    before: &[u8],
    shown: &[u8],
    indices: &[u8],
    width: u32,
    table: Option<Vec<[u8; 3]>>,
) -> GifFrame {
    let now: Vec<u8> = area.indices(width).flat_map(|i| [shown[3 * i], shown[3 * i + 1], shown[3 * i + 2]]).collect();
    let differs = Changes::between(before, &now, area.width, 3, None);
    let Some(inner) = differs.bounds else {
        return GifFrame {
            area: Area { x: area.x, y: area.y, width: 1, height: 1 },
            indices: vec![TRANSPARENT],
            table: None,
        };
    };
    let indices = inner
        .indices(area.width)
        .map(|j| {
            let i = (area.y as usize + j / area.width as usize) * width as usize
                + area.x as usize
                + j % area.width as usize;
            if differs.changed[j] {
                indices[i]
            } else {
                TRANSPARENT
            }
        })
        .collect();
    GifFrame { area: Area { x: area.x + inner.x, y: area.y + inner.y, ..inner }, indices, table }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shown(q: &Quantized, width: u32, height: u32) -> Vec<Vec<u8>> {
        let mut canvas = vec![0u8; 3 * (width * height) as usize];
        let mut frames = Vec::new();
        for frame in &q.frames {
            let table = frame.table.as_ref().unwrap_or(&q.table);
            for (j, i) in frame.area.indices(width).enumerate() {
                if frame.indices[j] != TRANSPARENT {
                    canvas[3 * i..3 * i + 3].copy_from_slice(&table[frame.indices[j] as usize]);
                }
            }
            frames.push(canvas.clone());
        }
        frames
    }

    #[test]
    fn a_moving_dot_changes_only_around_it_and_the_rest_keeps_its_pixels() {
        let (w, h) = (32u32, 24u32);
        let frame = |k: u32| -> Vec<u8> {
            let mut f: Vec<u8> = (0..w * h).flat_map(|i| [(i % w * 8) as u8, (i / w * 10) as u8, 90]).collect();
            let i = (10 * w + 4 + 3 * k) as usize;
            f[3 * i..3 * i + 3].copy_from_slice(&[255, 255, 255]);
            f
        };
        let mut frames = LoopFrames::new(w, h);
        (0..4).for_each(|k| frames.push(&frame(k), None));
        let q = quantize(&frames);
        assert_eq!(q.frames.len(), 4);
        assert_eq!(q.frames[0].area, Area::whole(w, h));
        let shown = shown(&q, w, h);
        for k in 1..4 {
            let area = q.frames[k].area;
            // The dot's old and new places and what the diffusion moved
            // near them; nothing else.
            assert!(area.y >= 10 && area.y + area.height <= 12 && area.width <= 8, "frame {k}: {area:?}");
            let differ = shown[k].chunks(3).zip(shown[k - 1].chunks(3)).filter(|(a, b)| a != b).count();
            assert!(differ <= 16, "frame {k}: {differ} pixels shimmer");
        }
        // Pushing the same frames again, told nothing of where they
        // changed: the same quantization.
        let mut again = LoopFrames::new(w, h);
        let tiles = [Area { x: 0, y: 8, width: 32, height: 4 }];
        (0..4).for_each(|k| again.push(&frame(k), Some(&tiles)));
        let r = quantize(&again);
        assert_eq!(r.table, q.table);
        assert!(r.frames.iter().zip(&q.frames).all(|(a, b)| (a.area, &a.indices) == (b.area, &b.indices)));
    }
}
