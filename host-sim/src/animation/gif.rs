//! An animation as an animated GIF that stores only what changes: the
//! first frame whole, each other as the smallest rectangle holding every
//! pixel whose shown colour changed, the pixels in it that did not change
//! transparent, on top of the frame before (disposal "keep").
//!
//! Truecolour frames are quantized for the whole loop (`quantize`: one
//! table, or a frame's own where that pays, and error diffusion that
//! leaves alone what did not move); frames already indexed (the thesis's
//! `--palette` modes) keep their indices and tables.
//!
//! Invariants: the file depends on the frames' pixels alone, however they
//! were rendered; its frames' delays add up to the loop's length in
//! hundredths of a second (rounded), so its frame rate is the scene's on
//! average; it loops forever.

use super::changes::{Area, Changes, LoopFrames};
use super::quantize::{quantize, ENTRIES, TRANSPARENT};
use octrace_core::scene::Frames;
use octrace_images::formats::Image;
use std::io::Write;

/// The most frames a second a GIF plays: browsers show a delay under
/// 2/100 s as 10/100.
pub const GIF_FASTEST: u32 = 50;

/// The delay of frame `k` of `frames`, in hundredths of a second: the
/// rounded time of its end less that of its start (24 frames a second:
/// 4 or 5), so the loop lasts its length; at least 2 (browsers show a
/// shorter delay as 10).
pub fn gif_delay(frames: Frames, k: u32) -> u16 {
    let at = |k: u32| (200 * u64::from(k) + u64::from(frames.rate)) / (2 * u64::from(frames.rate.max(1)));
    (at(k + 1) - at(k)).clamp(u64::from(100 / GIF_FASTEST), u64::from(u16::MAX)) as u16
}

/// An animated GIF being written, a frame at a time.
///
/// ```
/// use host_sim::animation::{Area, GifWriter};
/// use host_sim::RgbImage;
/// use octrace_core::scene::Frames;
/// use octrace_images::formats::Image;
///
/// // A gray square with a white dot that moves one pixel right.
/// let frame = |x: usize| {
///     let mut image = RgbImage { width: 8, height: 8, data: vec![90; 8 * 8 * 3] };
///     image.data[3 * (8 * 4 + x)..][..3].copy_from_slice(&[255; 3]);
///     Image::Rgb(image)
/// };
/// let mut gif = GifWriter::new(Vec::new(), 8, 8, Frames { count: 2, rate: 24 })?;
/// gif.frame(&frame(2), None)?;
/// // The second frame traced only row 4 (as the coherence would say).
/// gif.frame(&frame(3), Some(&[Area { x: 0, y: 4, width: 8, height: 1 }]))?;
/// let bytes = gif.finish()?;
/// // Its second image is the two pixels that changed, nothing more.
/// let mut decoder = gif::DecodeOptions::new().read_info(&bytes[..]).unwrap();
/// decoder.read_next_frame().unwrap();
/// let second = decoder.read_next_frame().unwrap().unwrap();
/// assert_eq!((second.left, second.top, second.width, second.height), (2, 4, 2, 1));
/// # Ok::<(), std::io::Error>(())
/// ```
pub struct GifWriter<W: Write> {
    out: Option<W>,
    width: u32,
    height: u32,
    frames: Frames,
    /// Truecolour frames, held until the loop is complete.
    held: LoopFrames,
    /// Indexed frames, written as they come: the encoder, the colours
    /// shown and the frames written.
    encoder: Option<gif::Encoder<W>>,
    shown: Vec<u8>,
    written: u32,
}

fn gif_error(e: gif::EncodingError) -> std::io::Error {
    match e {
        gif::EncodingError::Io(e) => e,
        e => std::io::Error::other(e),
    }
}

impl<W: Write> GifWriter<W> {
    /// A GIF of `width` × `height` frames at `frames`' rate, looping
    /// forever.
    pub fn new(out: W, width: u32, height: u32, frames: Frames) -> std::io::Result<GifWriter<W>> {
        if u16::try_from(width).is_err() || u16::try_from(height).is_err() {
            return Err(std::io::Error::other("a GIF is at most 65535 pixels a side"));
        }
        let held = LoopFrames::new(width, height);
        Ok(GifWriter { out: Some(out), width, height, frames, held, encoder: None, shown: Vec::new(), written: 0 })
    }

    /// Appends `frame`: truecolour (quantized with the whole loop) or
    /// indexed; `retraced` the areas that can differ from the frame
    /// before (`None`: any).
    pub fn frame(&mut self, frame: &Image, retraced: Option<&[Area]>) -> std::io::Result<()> {
        let mixed = || std::io::Error::other("a GIF's frames are all truecolour or all indexed");
        match frame {
            Image::Rgb(rgb) if self.encoder.is_none() => {
                self.held.push(&rgb.data, retraced);
                Ok(())
            }
            Image::Indexed { palette, indices, .. } if self.held.is_empty() => self.indexed(palette, indices),
            _ => Err(mixed()),
        }
    }

    /// Writes an indexed frame: what changed of the colours shown.
    fn indexed(&mut self, table: &[[u8; 3]], indices: &[u8]) -> std::io::Result<()> {
        let now: Vec<u8> = indices.iter().flat_map(|&i| table.get(usize::from(i)).copied().unwrap_or([0; 3])).collect();
        let frame = match self.written {
            0 => Area::whole(self.width, self.height),
            _ => Changes::between(&self.shown, &now, self.width, 3, None).bounds.unwrap_or(Area {
                x: 0,
                y: 0,
                width: 1,
                height: 1,
            }),
        };
        // A table with room for one more entry: that entry is the
        // transparent pixels', those that did not change.
        let transparent = (self.written > 0 && table.len() < 256).then_some(table.len() as u8);
        let pixels = frame
            .indices(self.width)
            .map(|i| match transparent {
                Some(index) if now[3 * i..3 * i + 3] == self.shown[3 * i..3 * i + 3] => index,
                _ => indices[i],
            })
            .collect();
        if self.encoder.is_none() {
            let out = self.out.take().ok_or_else(|| std::io::Error::other("the GIF is already written"))?;
            self.encoder = Some(start(out, self.width, self.height, &[])?);
        }
        let encoder = self.encoder.as_mut().ok_or_else(|| std::io::Error::other("no encoder"))?;
        let delay = gif_delay(self.frames, self.written);
        write(encoder, frame, pixels, Some(table), transparent, delay)?;
        self.shown = now;
        self.written += 1;
        Ok(())
    }

    /// Ends the file: the held truecolour frames quantized and written.
    pub fn finish(mut self) -> std::io::Result<W> {
        if let Some(encoder) = self.encoder {
            return encoder.into_inner().map_err(gif_error);
        }
        if self.held.is_empty() {
            return Err(std::io::Error::other("an animation of no frames"));
        }
        let out = self.out.take().ok_or_else(|| std::io::Error::other("the GIF is already written"))?;
        let quantized = quantize(&self.held);
        // One entry more: the transparent pixels'.
        let table = [&quantized.table[..], &[[0; 3]]].concat();
        let mut encoder = start(out, self.width, self.height, &table)?;
        for (k, mut frame) in quantized.frames.into_iter().enumerate() {
            let delay = gif_delay(self.frames, k as u32);
            // The transparent index becomes the first past the frame's
            // table, so a small table keeps short codes.
            let entries = frame.table.as_ref().unwrap_or(&quantized.table).len().min(ENTRIES) as u8;
            let transparent = frame.indices.contains(&TRANSPARENT).then_some(entries);
            frame.indices.iter_mut().filter(|p| **p == TRANSPARENT).for_each(|p| *p = entries);
            write(&mut encoder, frame.area, frame.indices, frame.table.as_deref(), transparent, delay)?;
        }
        encoder.into_inner().map_err(gif_error)
    }
}

/// The GIF's header: its size, its global `table` (if any), looping.
fn start<W: Write>(out: W, width: u32, height: u32, table: &[[u8; 3]]) -> std::io::Result<gif::Encoder<W>> {
    let bytes: Vec<u8> = table.iter().flatten().copied().collect();
    let mut encoder = gif::Encoder::new(out, width as u16, height as u16, &bytes).map_err(gif_error)?;
    encoder.set_repeat(gif::Repeat::Infinite).map_err(gif_error)?;
    Ok(encoder)
}

/// Writes one frame: `pixels` over `area`, indices into `table` (`None`:
/// the global one), `transparent` the index of the pixels that keep what
/// they show, if any (the first past the table).
fn write<W: Write>(
    encoder: &mut gif::Encoder<W>,
    area: Area,
    pixels: Vec<u8>,
    table: Option<&[[u8; 3]]>,
    transparent: Option<u8>,
    delay: u16,
) -> std::io::Result<()> {
    let frame = gif::Frame {
        delay,
        dispose: gif::DisposalMethod::Keep,
        transparent,
        left: area.x as u16,
        top: area.y as u16,
        width: area.width as u16,
        height: area.height as u16,
        palette: table
            .map(|t| t.iter().flatten().copied().chain(transparent.map(|_| [0; 3]).into_iter().flatten()).collect()),
        buffer: std::borrow::Cow::Owned(pixels),
        ..gif::Frame::default()
    };
    encoder.write_frame(&frame).map_err(gif_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delays_add_up_to_the_loop() {
        let frames = Frames { count: 48, rate: 24 };
        let delays: Vec<u16> = (0..48).map(|k| gif_delay(frames, k)).collect();
        assert_eq!(delays.iter().map(|&d| u32::from(d)).sum::<u32>(), 200);
        assert!(delays.iter().all(|&d| d == 4 || d == 5), "{delays:?}");
        assert_eq!(gif_delay(Frames { count: 1, rate: 10 }, 0), 10);
        assert_eq!(gif_delay(Frames { count: 1, rate: 1000 }, 0), 2);
    }
}
