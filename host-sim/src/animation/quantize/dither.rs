//! Error diffusion of a frame onto a colour table that leaves alone what
//! did not change: within the area a frame changed, only its changed
//! pixels are chosen anew; every other pixel keeps the colour already
//! shown, and passes on its error (what it wants, and the error it
//! received, less what it shows) as a chosen pixel does, so the new pixels
//! blend into the kept ones. Nothing shimmers where nothing moved.
//!
//! The kernel is Sierra's two-row "lite" filter (½ right, ¼ below left,
//! ¼ below), in raster order, in whole levels, carrying half of each
//! pixel's error: enough to break the bands between the table's colours,
//! and much closer to the frame, and much smaller once compressed, than
//! the whole error (on anim_fig5_1 at 1024×768, 50.7 dB and 1.17 MB
//! against 45.5 dB and 1.72 MB; BENCHMARKS.md).
//!
//! Invariants: integers only (the same indices on every machine); a pixel
//! outside the area or not flagged as changed keeps its index and colour.

use super::table::Nearest;
use crate::animation::changes::Area;

/// An error is held within this many levels, so a run of colours the
/// table cannot reach does not pile error up without end.
const LIMIT: i32 = 48;

/// One frame's pixels and what is shown of them.
pub struct Canvas<'a> {
    /// The frame: RGB, `width` pixels a row.
    pub wanted: &'a [u8],
    pub width: u32,
    /// What the file shows at each pixel (RGB), updated where chosen.
    pub shown: &'a mut [u8],
    /// Each pixel's index in the table it was chosen from, updated where
    /// chosen.
    pub indices: &'a mut [u8],
}

/// Diffuses `canvas`'s pixels within `area` onto `nearest`'s table,
/// choosing anew the pixels `changed` flags (row-major, the whole image).
pub fn diffuse(canvas: &mut Canvas<'_>, area: Area, changed: &[bool], nearest: &Nearest) {
    let span = area.width as usize + 2;
    // Errors for this row and the next, a pixel of margin on each side.
    let (mut here, mut below) = (vec![[0i32; 3]; span], vec![[0i32; 3]; span]);
    for y in area.y..area.y + area.height {
        for x in area.x..area.x + area.width {
            let i = y as usize * canvas.width as usize + x as usize;
            let at = (x - area.x) as usize + 1;
            let wanted = [0, 1, 2].map(|c| i32::from(canvas.wanted[3 * i + c]) + here[at][c]);
            let shown = if changed[i] {
                let target = wanted.map(|v| v.clamp(0, 255) as u8);
                let index = nearest.index(target);
                let colour = nearest.table()[index as usize];
                canvas.indices[i] = index;
                canvas.shown[3 * i..3 * i + 3].copy_from_slice(&colour);
                colour
            } else {
                [0, 1, 2].map(|c| canvas.shown[3 * i + c])
            };
            for c in 0..3 {
                // Half the error, carried on.
                let error = (wanted[c] - i32::from(shown[c])).clamp(-LIMIT, LIMIT) / 2;
                let half = error / 2;
                let quarter = (error - half) / 2;
                here[at + 1][c] += half;
                below[at - 1][c] += quarter;
                below[at][c] += error - half - quarter;
            }
        }
        std::mem::swap(&mut here, &mut below);
        below.iter_mut().for_each(|e| *e = [0; 3]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat colour between two entries is shown as a mix of both whose
    /// mean is near the colour; a pixel not flagged keeps what it showed.
    #[test]
    fn a_flat_colour_mixes_to_its_mean_and_kept_pixels_stay() {
        let (w, h) = (16u32, 16u32);
        let wanted = vec![100u8; 3 * (w * h) as usize];
        let nearest = Nearest::new(&[[96; 3], [104; 3]]);
        let mut shown = vec![0u8; wanted.len()];
        let mut indices = vec![7u8; (w * h) as usize];
        let mut changed = vec![true; (w * h) as usize];
        changed[5] = false;
        shown[15..18].copy_from_slice(&[96; 3]);
        let mut canvas = Canvas { wanted: &wanted, width: w, shown: &mut shown, indices: &mut indices };
        diffuse(&mut canvas, Area::whole(w, h), &changed, &nearest);
        assert_eq!((indices[5], &shown[15..18]), (7, &[96; 3][..]));
        let chosen: Vec<u32> =
            shown.chunks(3).enumerate().filter(|&(i, _)| i != 5).map(|(_, p)| u32::from(p[0])).collect();
        let mean = chosen.iter().sum::<u32>() as f64 / chosen.len() as f64;
        assert!((mean - 100.0).abs() < 1.5, "{mean}");
        assert!(chosen.contains(&96) && chosen.contains(&104));
    }
}
