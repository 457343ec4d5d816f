//! An animation as an APNG that stores only what changes: the first frame
//! whole, each other as the smallest rectangle holding every pixel that
//! changed (its `fcTL` region), the pixels in it that did not change
//! fully transparent and blended over the frame before (`APNG_BLEND_OP_OVER`,
//! disposal `APNG_DISPOSE_OP_NONE`). Lossless: every frame shows the
//! frame's pixels exactly.
//!
//! Invariants: the file depends on the frames' pixels alone, however they
//! were rendered; it loops forever at the scene's rate.

use super::changes::{Area, Changes};
use octrace_core::scene::Frames;
use std::io::Write;

/// An APNG being written, a frame at a time.
pub struct ApngWriter<'w, W: Write> {
    writer: png::Writer<&'w mut W>,
    width: u32,
    /// The last frame (RGB), `None` before the first.
    shown: Option<Vec<u8>>,
}

fn png_error(e: png::EncodingError) -> std::io::Error {
    match e {
        png::EncodingError::IoError(e) => e,
        e => std::io::Error::other(e),
    }
}

impl<'w, W: Write> ApngWriter<'w, W> {
    /// An APNG of `count` frames of `width` × `height` at `frames`' rate,
    /// looping forever.
    pub fn new(out: &'w mut W, width: u32, height: u32, count: u32, frames: Frames) -> std::io::Result<Self> {
        let mut encoder = png::Encoder::new(out, width, height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        encoder.set_animated(count, 0).map_err(png_error)?;
        encoder.set_frame_delay(1, frames.rate as u16).map_err(png_error)?;
        Ok(ApngWriter { writer: encoder.write_header().map_err(png_error)?, width, shown: None })
    }

    /// Appends `frame` (RGB), `retraced` the areas that can differ from
    /// the frame before (`None`: any).
    pub fn frame(&mut self, frame: &[u8], retraced: Option<&[Area]>) -> std::io::Result<()> {
        let (area, changes) = match &self.shown {
            None => {
                let height = (frame.len() / 3 / self.width.max(1) as usize) as u32;
                (Area::whole(self.width, height), Changes::everything(self.width, height))
            }
            Some(shown) => {
                let changes = Changes::between(shown, frame, self.width, 3, retraced);
                (changes.bounds.unwrap_or(Area { x: 0, y: 0, width: 1, height: 1 }), changes)
            }
        };
        let pixels: Vec<u8> = area
            .indices(self.width)
            .flat_map(|i| match changes.changed[i] {
                true => [frame[3 * i], frame[3 * i + 1], frame[3 * i + 2], 255],
                false => [0; 4],
            })
            .collect();
        let first = self.shown.is_none();
        let blend = if first { png::BlendOp::Source } else { png::BlendOp::Over };
        self.writer.set_blend_op(blend).map_err(png_error)?;
        self.writer.set_dispose_op(png::DisposeOp::None).map_err(png_error)?;
        self.writer.reset_frame_position().map_err(png_error)?;
        self.writer.set_frame_dimension(area.width, area.height).map_err(png_error)?;
        self.writer.set_frame_position(area.x, area.y).map_err(png_error)?;
        self.writer.write_image_data(&pixels).map_err(png_error)?;
        self.shown = Some(frame.to_vec());
        Ok(())
    }

    /// Ends the file.
    pub fn finish(self) -> std::io::Result<()> {
        self.writer.finish().map_err(png_error)
    }
}
