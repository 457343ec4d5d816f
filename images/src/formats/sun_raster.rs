//! Sun raster files: standard, RGB-ordered, old or byte-encoded, 8, 24 or 32 bits a pixel.
//!
//! Invariant: rows are stored padded to an even number of bytes ([`row_padding`]), both ways.

use super::bytes::{pick, read_exactly, take};
use super::error::{invalid, unsupported, FormatError};
use super::image::{Header, Image};
use crate::RgbImage;
use std::borrow::Cow;

pub(super) const MAGIC: u32 = 0x59a6_6a95;
const RT_OLD: u32 = 0;
const RT_STANDARD: u32 = 1;
pub(super) const RT_BYTE_ENCODED: u32 = 2;
const RT_FORMAT_RGB: u32 = 3;
const RMT_NONE: u32 = 0;
const RMT_EQUAL_RGB: u32 = 1;
/// The escape byte of RT_BYTE_ENCODED data.
const RUN: u8 = 0x80;

/// The header and colour map of a standard Sun raster.
pub(super) fn header_bytes(header: &Header) -> Result<Vec<u8>, FormatError> {
    let (width, height) = (header.width, header.height);
    let (depth, pixel_bytes, map_type, map) = match &header.palette {
        None => (24, 3, RMT_NONE, Vec::new()),
        Some(palette) => {
            let map: Vec<u8> = (0..3).flat_map(|channel| palette.iter().map(move |entry| entry[channel])).collect();
            (8, 1, RMT_EQUAL_RGB, map)
        }
    };
    let row = width as u64 * pixel_bytes;
    let Ok(length) = u32::try_from((row + row % 2) * u64::from(height)) else {
        return invalid(format!("a {width}×{height} image is too large for a Sun raster"));
    };
    let fields = [MAGIC, width, height, depth, length, RT_STANDARD, map_type, map.len() as u32];
    let mut out: Vec<u8> = fields.into_iter().flat_map(u32::to_be_bytes).collect();
    out.extend(map);
    Ok(out)
}

/// The seven big-endian words after the magic number (width, height, depth, length, type, map type, map
/// length), read from `input`, which is left after the 32-byte header.
fn header_words(input: &mut impl std::io::Read) -> Result<[u32; 7], FormatError> {
    let mut b = [0; 32];
    read_exactly(input, &mut b, "Sun raster header")?;
    Ok(std::array::from_fn(|i| {
        let at = 4 * (i + 1);
        u32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
    }))
}

/// A Sun raster read whole.
pub(super) fn read(bytes: &[u8]) -> Result<Image, FormatError> {
    let mut input = bytes;
    let [width, height, depth, _length, kind, map_type, map_length] = header_words(&mut input)?;
    if width == 0 || height == 0 {
        return invalid(format!("the Sun raster is {width}×{height} pixels"));
    }
    let map = take(&mut input, map_length as usize, "Sun raster colour map")?;
    let pixel_bytes = match depth {
        8 => 1,
        24 => 3,
        32 => 4,
        _ => return unsupported(format!("Sun rasters of {depth} bits per pixel are not supported")),
    };
    // Rows are padded to 16 bits.
    let row = (width as usize).saturating_mul(pixel_bytes);
    let stored_row = row.saturating_add(row_padding(row));
    let size = stored_row.saturating_mul(height as usize);
    let stored = match kind {
        RT_OLD | RT_STANDARD | RT_FORMAT_RGB => Cow::Borrowed(take(&mut input, size, "Sun raster pixels")?),
        RT_BYTE_ENCODED => Cow::Owned(unpack(input, size)?),
        _ => return unsupported(format!("Sun raster type {kind} is not supported")),
    };
    let pixels: Vec<u8> = stored.chunks_exact(stored_row).flat_map(|r| &r[..row]).copied().collect();
    if depth > 8 {
        // A 32-bit pixel's pad byte comes first.
        let last = pixel_bytes - 1;
        let offsets = if kind == RT_FORMAT_RGB { [last - 2, last - 1, last] } else { [last, last - 1, last - 2] };
        let data = pick(&pixels, pixel_bytes, offsets);
        return Ok(Image::Rgb(RgbImage { width, height, data }));
    }
    if map_type != RMT_EQUAL_RGB {
        return unsupported(format!("8-bit Sun rasters with colour map type {map_type} are not supported"));
    }
    if map.len() % 3 != 0 {
        return invalid(format!("a Sun raster colour map of {} bytes is not three equal parts", map.len()));
    }
    let palette = equal_rgb_palette(map);
    Ok(Image::Indexed { width, height, palette, indices: pixels })
}

/// RT_BYTE_ENCODED data expanded to `size` bytes: `0x80 n v` is n + 1 copies of v, `0x80 0` one 0x80.
fn unpack(mut input: &[u8], size: usize) -> Result<Vec<u8>, FormatError> {
    // No run (three bytes) expands to more than 256 bytes.
    if size > input.len().saturating_mul(86) {
        return Err(FormatError::Truncated("Sun raster run-length data"));
    }
    let mut out = Vec::with_capacity(size);
    while out.len() < size {
        let byte = take(&mut input, 1, "Sun raster run-length data")?[0];
        if byte != RUN {
            out.push(byte);
            continue;
        }
        match take(&mut input, 1, "Sun raster run-length data")?[0] {
            0 => out.push(RUN),
            n => {
                let value = take(&mut input, 1, "Sun raster run-length data")?[0];
                out.resize(out.len() + n as usize + 1, value);
            }
        }
    }
    out.truncate(size);
    Ok(out)
}

/// The bytes of padding after a stored row of `row_bytes`: rows are padded to 16 bits.
pub(super) fn row_padding(row_bytes: usize) -> usize {
    row_bytes % 2
}

/// The header of a Sun raster this crate writes (standard, 24 bits or 8 with an RGB map), read from
/// `input`, which is left at the first row.
pub(super) fn stream_header(input: &mut impl std::io::Read) -> Result<Header, FormatError> {
    let [width, height, depth, _length, kind, map_type, map_length] = header_words(input)?;
    let palette = match (depth, kind, map_type) {
        (24, RT_STANDARD, RMT_NONE) => None,
        (8, RT_STANDARD, RMT_EQUAL_RGB) if map_length % 3 == 0 && map_length <= 768 => {
            let mut map = vec![0; map_length as usize];
            read_exactly(input, &mut map, "Sun raster colour map")?;
            Some(equal_rgb_palette(&map))
        }
        _ => {
            return unsupported(format!(
                "Sun raster of type {kind}, {depth} bits, map {map_type}: not one host-sim writes"
            ))
        }
    };
    Ok(Header { width, height, palette, text: None })
}

/// An RMT_EQUAL_RGB map (all reds, then all greens, then all blues) as palette entries.
fn equal_rgb_palette(map: &[u8]) -> Vec<[u8; 3]> {
    let entries = map.len() / 3;
    (0..entries).map(|i| [map[i], map[entries + i], map[2 * entries + i]]).collect()
}

#[cfg(test)]
mod tests {
    use super::super::tests::{encode, indexed, rgb};
    use super::super::{read, Format};
    use super::*;

    #[test]
    fn sun_rasters_store_bgr_rows_padded_to_even_lengths() {
        let image = rgb(1, 2);
        let bytes = encode(&image, Format::Ras);
        let field = |i: usize| u32::from_be_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap());
        assert_eq!((0..8).map(field).collect::<Vec<_>>(), [MAGIC, 1, 2, 24, 8, RT_STANDARD, RMT_NONE, 0]);
        let Image::Rgb(pixels) = &image else { unreachable!() };
        let [r, g, b] = pixels.pixel(0, 1);
        assert_eq!(bytes[32..], [pixels.data[2], pixels.data[1], pixels.data[0], 0, b, g, r, 0]);

        let mut as_rgb = bytes.clone();
        as_rgb[23] = RT_FORMAT_RGB as u8;
        for row in as_rgb[32..].chunks_mut(4) {
            row.swap(0, 2);
        }
        assert_eq!(read(&as_rgb).unwrap(), image);

        let image = indexed(3, 1, 2);
        let bytes = encode(&image, Format::Ras);
        assert_eq!(bytes[28..32], 6u32.to_be_bytes(), "maplength is three bytes per entry");
        let Image::Indexed { palette, indices, .. } = &image else { unreachable!() };
        let map: Vec<u8> = (0..3).flat_map(|c| [palette[0][c], palette[1][c]]).collect();
        assert_eq!(bytes[32..38], map[..]);
        assert_eq!(bytes[38..], [indices[0], indices[1], indices[2], 0]);
    }

    #[test]
    fn run_length_sun_rasters_are_read() {
        let image = Image::Rgb(RgbImage { width: 3, height: 1, data: vec![30, 20, 10, 0x80, 0x80, 0x80, 7, 7, 7] });
        let mut bytes = encode(&image, Format::Ras);
        // The stored row is 10 20 30 80 80 80 07 07 07 00 (BGR, padded): literals, an escaped 0x80, runs.
        let body = [10, 20, 30, 0x80, 0, 0x80, 1, 0x80, 0x80, 2, 7, 0];
        bytes.splice(32.., body);
        bytes[16..24].copy_from_slice(&[0, 0, 0, body.len() as u8, 0, 0, 0, RT_BYTE_ENCODED as u8]);
        assert_eq!(read(&bytes).unwrap(), image);
    }
}
