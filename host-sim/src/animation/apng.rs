//! An animation as an APNG that stores only what changes: the first frame
//! whole, each other as the smallest rectangle holding every pixel that
//! changed (its `fcTL` region), blended over the frame before
//! (`APNG_BLEND_OP_OVER`, disposal `APNG_DISPOSE_OP_NONE`), the pixels in
//! it that did not change in a colour no frame shows, which the `tRNS`
//! chunk makes transparent; or, where that compresses better (most of the
//! rectangle changed), as they are (`APNG_BLEND_OP_SOURCE`). Lossless:
//! every frame shows the frame's pixels exactly.
//!
//! Invariants: the file depends on the frames' pixels alone, however they
//! were rendered; it loops forever at the scene's rate. The frames are
//! held (the first whole, the others' changes) until the last: the
//! transparent colour must be one no frame shows.

use super::changes::{Area, LoopFrames};
use octrace_core::scene::Frames;
use std::io::Write;

/// An APNG being written, a frame at a time.
pub struct ApngWriter<'w, W: Write> {
    out: &'w mut W,
    frames: Frames,
    held: LoopFrames,
}

/// The size of `pixels` (RGB, `area`'s) compressed quickly, to choose
/// between a frame's two forms: it chose as the file's own compression did
/// (anim_fig5_1's and anim_light's files byte for byte the same), where
/// compressing both as the file is took twice the time of the whole run.
fn compressed(pixels: &[u8], area: Area) -> std::io::Result<usize> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, area.width, area.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().map_err(png_error)?;
    writer.write_image_data(pixels).map_err(png_error)?;
    writer.finish().map_err(png_error)?;
    Ok(out.len())
}

fn png_error(e: png::EncodingError) -> std::io::Error {
    match e {
        png::EncodingError::IoError(e) => e,
        e => std::io::Error::other(e),
    }
}

impl<'w, W: Write> ApngWriter<'w, W> {
    /// An APNG of frames of `width` × `height` at `frames`' rate, looping
    /// forever.
    pub fn new(out: &'w mut W, width: u32, height: u32, frames: Frames) -> std::io::Result<Self> {
        Ok(ApngWriter { out, frames, held: LoopFrames::new(width, height) })
    }

    /// Appends `frame` (RGB), `retraced` the areas that can differ from
    /// the frame before (`None`: any).
    pub fn frame(&mut self, frame: &[u8], retraced: Option<&[Area]>) -> std::io::Result<()> {
        self.held.push(frame, retraced);
        Ok(())
    }

    /// Writes the file.
    pub fn finish(self) -> std::io::Result<()> {
        let held = &self.held;
        // A colour no frame shows marks the pixels that keep theirs; with
        // none (every 2²⁴ colour shown), the frames after the first are
        // stored whole over their rectangle.
        let key = held.unused_colour();
        let mut encoder = png::Encoder::new(&mut *self.out, held.width, held.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        if let Some(key) = key {
            encoder.set_trns(key.iter().flat_map(|&v| [0, v]).collect::<Vec<u8>>());
        }
        encoder.set_animated(held.len() as u32, 0).map_err(png_error)?;
        encoder.set_frame_delay(1, self.frames.rate as u16).map_err(png_error)?;
        let mut writer = encoder.write_header().map_err(png_error)?;
        writer.write_image_data(&held.first).map_err(png_error)?;
        let mut shown = held.first.clone();
        for delta in &held.later {
            let area = delta.bounds.unwrap_or(Area { x: 0, y: 0, width: 1, height: 1 });
            let (mut keyed, mut plain) = (Vec::with_capacity(3 * area.pixels()), Vec::with_capacity(3 * area.pixels()));
            for (j, i) in area.indices(held.width).enumerate() {
                let changed = delta.changed.get(j).copied().unwrap_or(false);
                if changed {
                    shown[3 * i..3 * i + 3].copy_from_slice(&delta.pixels[3 * j..3 * j + 3]);
                }
                plain.extend_from_slice(&shown[3 * i..3 * i + 3]);
                match key {
                    Some(key) if !changed => keyed.extend_from_slice(&key),
                    _ => keyed.extend_from_slice(&shown[3 * i..3 * i + 3]),
                }
            }
            // The unchanged pixels transparent, or as they are where that
            // compresses better (most of the rectangle changed).
            let transparent = key.is_some() && compressed(&keyed, area)? < compressed(&plain, area)?;
            let blend = if transparent { png::BlendOp::Over } else { png::BlendOp::Source };
            writer.set_blend_op(blend).map_err(png_error)?;
            writer.set_dispose_op(png::DisposeOp::None).map_err(png_error)?;
            writer.reset_frame_position().map_err(png_error)?;
            writer.set_frame_dimension(area.width, area.height).map_err(png_error)?;
            writer.set_frame_position(area.x, area.y).map_err(png_error)?;
            writer.write_image_data(if transparent { &keyed } else { &plain }).map_err(png_error)?;
        }
        writer.finish().map_err(png_error)
    }
}
