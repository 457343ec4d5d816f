//! PNG files through the `png` crate: 8-bit RGB or indexed, written with an optional `tEXt` chunk.
//!
//! Invariant: a declared size is checked against what the file's bytes could inflate to before anything
//! is allocated for it.

use super::bytes::{opaque, pick, RGB};
use super::error::{invalid, unsupported, FormatError};
use super::image::{Header, Image, TEXT_KEYWORD};
use crate::RgbImage;
use std::io::{BufReader, Write};

pub(crate) const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

/// Deflate turns no byte into more than this many.
const DEFLATE_MAX_RATIO: u64 = 1032;

pub(super) fn encoding_error(e: png::EncodingError) -> FormatError {
    match e {
        png::EncodingError::IoError(e) => FormatError::Io(e),
        e => FormatError::Invalid(format!("PNG encoder: {e}")),
    }
}

pub(super) fn decoding_error(e: png::DecodingError) -> FormatError {
    match e {
        png::DecodingError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            FormatError::Truncated("PNG file")
        }
        e => FormatError::Invalid(format!("malformed PNG file: {e}")),
    }
}

/// Bytes the PNG encoder has written and the file has not yet received (the stream writer owns its output,
/// so it writes here and the row writer moves the bytes on).
#[derive(Clone, Default)]
pub(super) struct Buffer(std::rc::Rc<std::cell::RefCell<Vec<u8>>>);

impl Buffer {
    /// The bytes written since the last call.
    pub(super) fn take(&self) -> Vec<u8> {
        std::mem::take(&mut self.0.borrow_mut())
    }
}

impl Write for Buffer {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().extend_from_slice(bytes);
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A stream writer that has written `header` (and its text) into `out`.
pub(super) fn stream_writer(header: &Header, out: Buffer) -> Result<png::StreamWriter<'static, Buffer>, FormatError> {
    let mut encoder = png::Encoder::new(out, header.width, header.height);
    encoder.set_depth(png::BitDepth::Eight);
    match &header.palette {
        None => encoder.set_color(png::ColorType::Rgb),
        Some(palette) => {
            encoder.set_color(png::ColorType::Indexed);
            encoder.set_palette(palette.concat());
        }
    }
    if let Some(text) = &header.text {
        encoder.add_text_chunk(TEXT_KEYWORD.into(), text.clone()).map_err(encoding_error)?;
    }
    encoder.write_header().map_err(encoding_error)?.into_stream_writer().map_err(encoding_error)
}

/// An 8-bit grayscale PNG file of `gray`, one byte a pixel.
pub(super) fn write_gray(width: u32, height: u32, gray: &[u8], out: &mut dyn Write) -> Result<(), FormatError> {
    let mut encoder = png::Encoder::new(out, width, height);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(encoding_error)?;
    writer.write_image_data(gray).map_err(encoding_error)?;
    writer.finish().map_err(encoding_error)
}

/// A PNG colour type as a user knows it.
fn colour_name(colour: png::ColorType) -> &'static str {
    match colour {
        png::ColorType::Grayscale => "gray",
        png::ColorType::Rgb => "RGB colour",
        png::ColorType::Indexed => "indexed colour",
        png::ColorType::GrayscaleAlpha => "gray with alpha",
        png::ColorType::Rgba => "RGBA colour",
    }
}

/// A PNG file read whole.
pub(super) fn read(bytes: &[u8]) -> Result<Image, FormatError> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let header = decoder.read_header_info().map_err(decoding_error)?;
    let (width, height) = (header.width, header.height);
    // An 8-bit gray file (what `write_gray` writes) is read as indices
    // into the 256 grays. With alpha, 8-bit RGB and gray are read as
    // without, once every pixel is found opaque.
    let gray = header.bit_depth == png::BitDepth::Eight
        && matches!(header.color_type, png::ColorType::Grayscale | png::ColorType::GrayscaleAlpha);
    let with_alpha = matches!(header.color_type, png::ColorType::Rgba | png::ColorType::GrayscaleAlpha);
    let bits = match (header.color_type, header.bit_depth) {
        (png::ColorType::Rgb, png::BitDepth::Eight) => 24,
        (png::ColorType::Rgba, png::BitDepth::Eight) => 32,
        (png::ColorType::Indexed, depth) => depth as u64,
        (png::ColorType::GrayscaleAlpha, png::BitDepth::Eight) => 16,
        _ if gray => 8,
        (colour, depth) => {
            return unsupported(format!(
                "a PNG of {} at {} bits: host-sim reads PNGs of 8-bit RGB, 8-bit gray or indexed colour (with \
                 alpha where every pixel is opaque)",
                colour_name(colour),
                depth as u8
            ))
        }
    };
    let what = format!("a PNG of {}", colour_name(header.color_type));
    // Each row is a filter byte and its pixels, deflated.
    let inflated = u64::from(height) * (1 + (u64::from(width) * bits).div_ceil(8));
    if inflated > bytes.len() as u64 * DEFLATE_MAX_RATIO {
        return invalid(format!("a {width}×{height} PNG image cannot fit in {} bytes", bytes.len()));
    }
    let mut reader = decoder.read_info().map_err(decoding_error)?;
    let palette: Option<Vec<[u8; 3]>> = match gray {
        true => Some((0..=255).map(|g| [g; 3]).collect()),
        false => reader.info().palette.as_ref().map(|p| p.chunks_exact(3).map(|e| [e[0], e[1], e[2]]).collect()),
    };
    let size = reader.output_buffer_size().ok_or_else(|| FormatError::Invalid("PNG image too large".into()))?;
    let mut buffer = vec![0; size];
    let frame = reader.next_frame(&mut buffer).map_err(decoding_error)?;
    buffer.truncate(frame.buffer_size());
    // Up to IEND, so that a file cut short is not taken for whole.
    reader.finish().map_err(decoding_error)?;
    if with_alpha {
        let pixel_bytes = bits as usize / 8;
        opaque(buffer.chunks_exact(pixel_bytes).map(|p| p[pixel_bytes - 1]), width, &what)?;
    }
    match bits {
        24 => return Ok(Image::Rgb(RgbImage { width, height, data: buffer })),
        32 => return Ok(Image::Rgb(RgbImage { width, height, data: pick(&buffer, 4, RGB) })),
        _ => {}
    }
    let palette = palette.ok_or_else(|| FormatError::Invalid("indexed PNG file without a PLTE chunk".into()))?;
    let indices = match bits {
        8 => buffer,
        16 => buffer.chunks_exact(2).map(|p| p[0]).collect(),
        _ => {
            let (bits, per_byte) = (bits as usize, 8 / bits as usize);
            let unpack =
                |row: &[u8], x: usize| row[x / per_byte] >> (8 - bits * (x % per_byte + 1)) & ((1 << bits) - 1);
            let rows = buffer.chunks_exact(frame.line_size);
            rows.flat_map(|row| (0..width as usize).map(move |x| unpack(row, x))).collect()
        }
    };
    // A colour table's transparency (tRNS), entry by entry.
    if let Some(alpha) = reader.info().trns.as_deref().filter(|_| !gray) {
        opaque(indices.iter().map(|&i| alpha.get(usize::from(i)).copied().unwrap_or(u8::MAX)), width, &what)?;
    }
    Ok(Image::Indexed { width, height, palette, indices })
}

/// The header of a PNG file this crate writes, and a reader positioned at its first row.
pub(super) fn row_reader(
    input: BufReader<std::fs::File>,
) -> Result<(Header, png::Reader<BufReader<std::fs::File>>), FormatError> {
    // Rows are decoded one at a time: the whole image is never allocated.
    let decoder = png::Decoder::new_with_limits(input, png::Limits { bytes: usize::MAX });
    let reader = decoder.read_info().map_err(decoding_error)?;
    let info = reader.info();
    let palette = match (info.color_type, info.bit_depth, info.interlaced) {
        (png::ColorType::Rgb, png::BitDepth::Eight, false) => None,
        (png::ColorType::Indexed, png::BitDepth::Eight, false) => {
            let palette = info
                .palette
                .as_ref()
                .ok_or_else(|| FormatError::Invalid("indexed PNG file without a PLTE chunk".into()))?;
            Some(palette.chunks_exact(3).map(|e| [e[0], e[1], e[2]]).collect())
        }
        (colour, depth, interlaced) => {
            return unsupported(format!(
                "a PNG of {} at {} bits{}: not one host-sim writes",
                colour_name(colour),
                depth as u8,
                if interlaced { ", interlaced" } else { "" }
            ))
        }
    };
    let text = info.uncompressed_latin1_text.iter().find(|t| t.keyword == TEXT_KEYWORD).map(|t| t.text.clone());
    Ok((Header { width: info.width, height: info.height, palette, text }, reader))
}

#[cfg(test)]
mod tests {
    use super::super::tests::{encode, samples};
    use super::super::Format;
    use super::*;

    #[test]
    fn written_pngs_decode_with_the_png_crate() {
        for image in samples() {
            let bytes = encode(&image, Format::Png);
            let mut reader = png::Decoder::new(std::io::Cursor::new(&bytes)).read_info().unwrap();
            let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
            let frame = reader.next_frame(&mut buffer).unwrap();
            assert_eq!(
                (frame.width, frame.height, frame.bit_depth),
                (image.width(), image.height(), png::BitDepth::Eight)
            );
            buffer.truncate(frame.buffer_size());
            match &image {
                Image::Rgb(rgb) => {
                    assert_eq!(frame.color_type, png::ColorType::Rgb);
                    assert_eq!(buffer, rgb.data);
                }
                Image::Indexed { palette, indices, .. } => {
                    assert_eq!(frame.color_type, png::ColorType::Indexed);
                    assert_eq!(reader.info().palette.as_deref(), Some(&palette.concat()[..]));
                    assert_eq!(&buffer, indices);
                }
            }
        }
    }

    #[test]
    fn a_gray_png_reads_back_as_indices_into_the_grays() {
        let grays = [0, 17, 34, 255, 128, 1];
        let mut bytes = Vec::new();
        write_gray(3, 2, &grays, &mut bytes).unwrap();
        let Image::Indexed { width: 3, height: 2, palette, indices } = read(&bytes).unwrap() else {
            panic!("a gray PNG is read as an indexed image");
        };
        assert_eq!(indices, grays);
        assert!(palette.iter().enumerate().all(|(g, entry)| *entry == [g as u8; 3]) && palette.len() == 256);
    }

    /// A 3×2 PNG of `colour` made by the png crate, with `trns` if given.
    fn encoded(colour: png::ColorType, data: &[u8], palette: Option<&[u8]>, trns: Option<&[u8]>) -> Vec<u8> {
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, 3, 2);
        encoder.set_color(colour);
        encoder.set_depth(png::BitDepth::Eight);
        if let Some(palette) = palette {
            encoder.set_palette(palette.to_vec());
        }
        if let Some(trns) = trns {
            encoder.set_trns(trns.to_vec());
        }
        encoder.write_header().unwrap().write_image_data(data).unwrap();
        bytes
    }

    #[test]
    fn alpha_is_read_where_every_pixel_is_opaque_and_a_transparent_one_refused() {
        let rgb: Vec<u8> = (0..18).collect();
        let rgba: Vec<u8> = rgb.chunks(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
        let gray_alpha = [7, 255, 8, 255, 9, 255, 10, 255, 11, 255, 12, 255];
        let (palette, indices) = ((0..9).collect::<Vec<u8>>(), [0, 1, 2, 2, 1, 0]);
        let cases = [
            (png::ColorType::Rgba, &rgba[..], None, None, 4),
            (png::ColorType::GrayscaleAlpha, &gray_alpha[..], None, None, 2),
            (png::ColorType::Indexed, &indices[..], Some(&palette[..]), Some(&[255, 255, 255][..]), 1),
        ];
        for (colour, data, palette, trns, pixel_bytes) in cases {
            let opaque = read(&encoded(colour, data, palette, trns)).unwrap();
            let want = match colour {
                png::ColorType::Rgba => Image::Rgb(RgbImage { width: 3, height: 2, data: rgb.clone() }),
                png::ColorType::GrayscaleAlpha => {
                    let palette = (0..=255).map(|g| [g; 3]).collect();
                    Image::Indexed { width: 3, height: 2, palette, indices: vec![7, 8, 9, 10, 11, 12] }
                }
                _ => Image::Indexed {
                    width: 3,
                    height: 2,
                    palette: vec![[0, 1, 2], [3, 4, 5], [6, 7, 8]],
                    indices: indices.to_vec(),
                },
            };
            assert_eq!(opaque, want, "{colour:?}");
            // Pixel (1, 1), the fifth, made transparent: in the pixel's alpha,
            // or (indexed) in its entry's, index 1.
            let (mut data, mut trns) = (data.to_vec(), trns.map(<[u8]>::to_vec));
            match &mut trns {
                Some(trns) => trns[1] = 254,
                None => data[5 * pixel_bytes - 1] = 254,
            }
            let message = read(&encoded(colour, &data, palette, trns.as_deref())).unwrap_err().to_string();
            let first = if trns.is_some() { "x 1, y 0" } else { "x 1, y 1" };
            assert!(message.contains(&format!("with transparent pixels (the first at {first})")), "{message}");
        }
    }
}
