//! The studio's player: an animation's frames traced one after another, each
//! re-tracing only the tiles the motion can have changed since the frame
//! traced before it (the core's [`Coherence`]), into an image it keeps.
//!
//! Invariants: `colours` and `objects` hold frame `shown` of `text` at
//! `size`, bit for bit the frame traced whole; `counts` are the tiles'
//! counts after that frame (the coherence's own bytes, kept between calls);
//! a frame of another text or size starts again from every tile.

use crate::error::StudioError;
use embedded_graphics_core::geometry::Size;
use embedded_graphics_core::pixelcolor::RgbColor;
use embedded_graphics_core::primitives::Rectangle;
use octrace_core::accel::{Accelerator, Mailbox};
use octrace_core::animation::{Coherence, Key, Motion, Track};
use octrace_core::render::{PixelSample, Renderer, ScreenBound};
use octrace_core::scene::{Frames, SceneView};
use octrace_images::NO_OBJECT;
use std::convert::Infallible;
use std::sync::atomic::{AtomicU8, Ordering};

/// The side of the tiles re-traced together: host-sim's
/// (`COHERENCE_TILE`, chosen by measurement; see BENCHMARKS.md).
const TILE: u32 = 4;

/// After this many transitions every count has run out (the longest kept is
/// 253) but a tile's that nothing can change: stepping further changes
/// nothing.
const LONGEST_STEP: u32 = 255;

/// The frame to trace: frame `frame` of `text` (an animation of `frames`) at
/// `size`.
pub(crate) struct Shown<'t> {
    pub text: &'t str,
    pub frames: Frames,
    pub frame: u32,
    pub size: (u32, u32),
}

/// The last frame traced, and what its tiles still hold.
#[derive(Default)]
pub(crate) struct Player {
    text: String,
    size: (u32, u32),
    shown: Option<u32>,
    counts: Vec<AtomicU8>,
    colours: Vec<u8>,
    objects: Vec<u32>,
}

impl Player {
    /// Traces `frame`, loaded as `view` with `accel`, into the image kept:
    /// only the tiles whose count ran out on the way from the frame traced
    /// last (every tile for another text or size). Returns how many pixels
    /// it traced.
    pub(crate) fn trace<A: Accelerator>(
        &mut self,
        view: SceneView<'_>,
        accel: &A,
        frame: &Shown<'_>,
    ) -> Result<u64, StudioError> {
        let (w, h) = frame.size;
        let steps = match self.shown {
            Some(shown) if self.text == frame.text && self.size == frame.size => {
                // Forward round the loop from the frame shown.
                let count = frame.frames.count.max(1);
                Some(((frame.frame % count + count - shown % count) % count).min(LONGEST_STEP))
            }
            _ => None,
        };
        if steps.is_none() {
            self.text = frame.text.to_string();
            self.size = frame.size;
            self.counts = (0..Coherence::tiles_for(w, h, TILE)).map(|_| AtomicU8::new(0)).collect();
            self.colours = vec![0; 3 * w as usize * h as usize];
            self.objects = vec![NO_OBJECT; w as usize * h as usize];
        }
        // Nothing is shown until this frame is traced whole.
        self.shown = None;
        // `Coherence::new` marks every tile to trace: the counts after the
        // frame shown are put back, then stepped to this frame.
        let kept: Vec<u8> = self.counts.iter().map(|c| c.load(Ordering::Relaxed)).collect();
        let coherence =
            Coherence::new(&self.counts, Size::new(w, h), TILE).map_err(|e| StudioError::Motion(e.to_string()))?;
        if let Some(steps) = steps {
            for (count, byte) in self.counts.iter().zip(kept) {
                count.store(byte, Ordering::Relaxed);
            }
            (0..steps).for_each(|_| {
                coherence.plan();
            });
        }
        let traced = coherence.traced_pixels();
        let needs = Motion::needs(frame.text);
        let (mut tracks, mut keys, mut table) =
            (vec![Track::EMPTY; needs.tracks], vec![Key::default(); needs.keys], vec![[0; 3]; needs.displacements]);
        let motion = Motion::read(frame.text, frame.frames, &view, frame.frame, &mut tracks, &mut keys, &mut table)
            .map_err(|e| StudioError::Motion(e.to_string()))?;
        let objects = view.object_count();
        let mut words = vec![0u32; Mailbox::words_for(objects)];
        let mut bounds = vec![ScreenBound::EMPTY; objects];
        let mut positions = vec![0; ScreenBound::positions_for(objects)];
        let renderer = Renderer::with_size(view, accel, w, h).map_err(|e| StudioError::Camera(format!("{e:?}")))?;
        let mut renderer = renderer.with_mailbox(&mut words).with_first_hits(&mut bounds, &mut positions);
        let (colours, objects) = (&mut self.colours, &mut self.objects);
        let mut write = |line: &Rectangle, pixels: &mut dyn Iterator<Item = PixelSample>| -> Result<(), Infallible> {
            let at = line.top_left.y as usize * w as usize + line.top_left.x as usize;
            for (i, p) in pixels.enumerate() {
                colours[3 * (at + i)..3 * (at + i) + 3].copy_from_slice(&[p.color.r(), p.color.g(), p.color.b()]);
                objects[at + i] = p.object.map_or(NO_OBJECT, |o| o.0);
            }
            Ok(())
        };
        for band in 0..coherence.bands() {
            let Ok(_) = coherence.trace_band(&mut renderer, &motion, frame.frame, band, &mut write);
        }
        self.shown = Some(frame.frame);
        Ok(traced)
    }

    /// The image kept, as [`crate::Studio::render_rect`] writes one: its
    /// colours, then the object under each pixel.
    pub(crate) fn write(&self, out: &mut Vec<u8>) {
        out.clear();
        out.extend_from_slice(&self.colours);
        out.extend(self.objects.iter().flat_map(|o| o.to_le_bytes()));
    }
}
