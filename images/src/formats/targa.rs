//! Targa files: uncompressed or run-length, truecolour or colour-mapped, stored in any row order.
//!
//! Invariant: run-length data is checked to be long enough for the pixels it claims (128 a packet at
//! most) before they are allocated.

use super::bytes::{opaque, pick, read_exactly, take, BGR};
use super::error::{invalid, unsupported, FormatError};
use super::image::{not_an_image, Header, Image};
use crate::RgbImage;
use std::borrow::Cow;

/// Whether a file of no other format's signature that starts with `start`
/// can be a Targa file, which has none: a whole header whose colour map
/// type, image type and pixel size are ones the format defines. Anything
/// else (a text file's first bytes, say) is no image at all, and is told
/// so rather than what of a Targa header it fails.
pub(super) fn could_be(start: &[u8]) -> bool {
    let Some(header) = start.first_chunk::<18>() else { return false };
    let (map_type, image_type, pixel_bits) = (header[1], header[2], header[16]);
    map_type <= 1 && matches!(image_type, 0..=3 | 9..=11 | 32 | 33) && matches!(pixel_bits, 8 | 15 | 16 | 24 | 32)
}

/// What a file that [`could_be`] a Targa file is when it does not read as
/// one: with no signature, it may still be something else.
pub(super) fn no_image(e: FormatError) -> FormatError {
    match e {
        FormatError::Io(e) => FormatError::Io(e),
        e => FormatError::Unsupported(format!("{} (as a Targa file: {e})", not_an_image())),
    }
}

/// Descriptor bit 5: the first row stored is the top one.
const TOP_DOWN: u8 = 0x20;
/// Descriptor bit 4: each row is stored right to left.
const RIGHT_TO_LEFT: u8 = 0x10;
/// Descriptor bits: how many bits of each pixel are attributes (alpha).
const ATTRIBUTE_BITS: u8 = 0x0f;

/// The header, image ID and colour map of a top-down, uncompressed Targa file.
pub(super) fn header_bytes(header: &Header) -> Result<Vec<u8>, FormatError> {
    let (width, height) = (header.width, header.height);
    let (Ok(width), Ok(height)) = (u16::try_from(width), u16::try_from(height)) else {
        return invalid(format!("a Targa image is at most 65535×65535 pixels, not {width}×{height}"));
    };
    let id = header.text.as_deref().unwrap_or("").as_bytes();
    let Ok(id_length) = u8::try_from(id.len()) else {
        return invalid(format!("a Targa image ID is at most 255 bytes, not {}", id.len()));
    };
    let (map_type, image_type, map, map_bits, pixel_bits) = match &header.palette {
        None => (0, 2, Vec::new(), 0, 24),
        Some(palette) => (1, 1, pick(&palette.concat(), 3, BGR), 24, 8),
    };
    let mut out = Vec::with_capacity(18 + id.len() + map.len());
    out.extend([id_length, map_type, image_type]);
    out.extend(0u16.to_le_bytes().into_iter().chain((map.len() as u16 / 3).to_le_bytes()));
    out.extend([map_bits, 0, 0, 0, 0]);
    out.extend(width.to_le_bytes().into_iter().chain(height.to_le_bytes()));
    out.extend([pixel_bits, TOP_DOWN]);
    out.extend(id);
    out.extend(map);
    Ok(out)
}

/// The 18 bytes every Targa file starts with, as fields.
struct Fixed {
    id_length: u8,
    map_type: u8,
    image_type: u8,
    map_first: u16,
    map_length: usize,
    map_bits: u8,
    width: u16,
    height: u16,
    pixel_bits: u8,
    descriptor: u8,
}

impl Fixed {
    /// Reads them from `input`, which is left after them.
    fn read(input: &mut impl std::io::Read) -> Result<Fixed, FormatError> {
        let mut b = [0; 18];
        read_exactly(input, &mut b, "Targa header")?;
        let u16_at = |i: usize| u16::from_le_bytes([b[i], b[i + 1]]);
        Ok(Fixed {
            id_length: b[0],
            map_type: b[1],
            image_type: b[2],
            map_first: u16_at(3),
            map_length: u16_at(5) as usize,
            map_bits: b[7],
            width: u16_at(12),
            height: u16_at(14),
            pixel_bits: b[16],
            descriptor: b[17],
        })
    }
}

/// A Targa file read whole.
pub(super) fn read(bytes: &[u8]) -> Result<Image, FormatError> {
    let mut input = bytes;
    let Fixed {
        id_length,
        map_type,
        image_type,
        map_first,
        map_length,
        map_bits,
        width,
        height,
        pixel_bits,
        descriptor,
    } = Fixed::read(&mut input)?;
    let (mapped, run_length) = match image_type {
        1 => (true, false),
        2 => (false, false),
        9 => (true, true),
        10 => (false, true),
        _ => return unsupported(format!("Targa image type {image_type} is not supported")),
    };
    if map_type > 1 || mapped && map_type == 0 {
        return invalid(format!("Targa colour map type {map_type} with image type {image_type}"));
    }
    if width == 0 || height == 0 {
        return invalid(format!("the Targa image is {width}×{height} pixels"));
    }
    take(&mut input, id_length as usize, "Targa image ID")?;
    let map_entry_bytes = map_bits.div_ceil(8) as usize;
    let map = take(&mut input, map_length * map_entry_bytes * map_type as usize, "Targa colour map")?;
    let pixel_bytes = match (mapped, pixel_bits, map_bits) {
        (true, 8, 24 | 32) => 1,
        (false, 24, _) => 3,
        (false, 32, _) => 4,
        (true, 8, _) => return unsupported(format!("Targa colour map entries of {map_bits} bits are not supported")),
        _ => {
            return unsupported(format!(
                "Targa image type {image_type} at {pixel_bits} bits per pixel is not supported"
            ))
        }
    };
    let count = width as usize * height as usize;
    let stored = if run_length {
        unpack(input, count, pixel_bytes)?
    } else {
        take(&mut input, count.saturating_mul(pixel_bytes), "Targa pixels")?.to_vec()
    };
    let pixels = orient(&stored, width as usize, pixel_bytes, descriptor);
    let (width, height) = (u32::from(width), u32::from(height));
    if !mapped {
        if let Some(alpha) = alpha(&pixels, pixel_bytes, descriptor) {
            opaque(alpha.into_iter(), width, "a Targa image of 32-bit pixels")?;
        }
        return Ok(Image::Rgb(RgbImage { width, height, data: pick(&pixels, pixel_bytes, BGR) }));
    }
    let palette = map.chunks_exact(map_entry_bytes).map(|e| [e[2], e[1], e[0]]).collect();
    // Pixel values count from the map's first entry.
    let index = |&value: &u8| match u16::from(value).checked_sub(map_first) {
        Some(index) => Ok(index as u8),
        None => invalid(format!("Targa pixel value {value} is below the colour map's first entry {map_first}")),
    };
    let indices: Vec<u8> = pixels.iter().map(index).collect::<Result<_, _>>()?;
    if let Some(alpha) = alpha(map, map_entry_bytes, descriptor) {
        let used = indices.iter().map(|&i| alpha.get(usize::from(i)).copied().unwrap_or(u8::MAX));
        opaque(used, width, "a Targa image of 32-bit colour map entries")?;
    }
    Ok(Image::Indexed { width, height, palette, indices })
}

/// The alpha of each of `colours` (pixels or map entries of `bytes` bytes),
/// if they have any: a 32-bit colour's fourth byte is alpha when the
/// descriptor counts attribute bits, unless it is zero throughout, as
/// writers without alpha leave it.
fn alpha(colours: &[u8], bytes: usize, descriptor: u8) -> Option<Vec<u8>> {
    if bytes != 4 || descriptor & ATTRIBUTE_BITS == 0 {
        return None;
    }
    let alpha: Vec<u8> = colours.chunks_exact(bytes).map(|c| c[3]).collect();
    alpha.iter().any(|&a| a != 0).then_some(alpha)
}

/// Targa run-length packets expanded to `count` pixels of `pixel_bytes` each.
fn unpack(mut input: &[u8], count: usize, pixel_bytes: usize) -> Result<Vec<u8>, FormatError> {
    // No packet (a byte and a pixel at least) holds more than 128 pixels.
    if count > input.len() / (1 + pixel_bytes) * 128 {
        return Err(FormatError::Truncated("Targa run-length data"));
    }
    let mut out = Vec::with_capacity(count * pixel_bytes);
    while out.len() < count * pixel_bytes {
        let packet = take(&mut input, 1, "Targa run-length data")?[0];
        let repeats = (packet & 0x7f) as usize + 1;
        if packet & 0x80 != 0 {
            let pixel = take(&mut input, pixel_bytes, "Targa run-length data")?;
            (0..repeats).for_each(|_| out.extend_from_slice(pixel));
        } else {
            out.extend_from_slice(take(&mut input, repeats * pixel_bytes, "Targa run-length data")?);
        }
    }
    out.truncate(count * pixel_bytes);
    Ok(out)
}

/// Targa pixels reordered from the order `descriptor` says they are stored in to top-down, left-to-right.
fn orient(stored: &[u8], width: usize, pixel_bytes: usize, descriptor: u8) -> Cow<'_, [u8]> {
    let (top_down, right_to_left) = (descriptor & TOP_DOWN != 0, descriptor & RIGHT_TO_LEFT != 0);
    if top_down && !right_to_left {
        return Cow::Borrowed(stored);
    }
    let rows = stored.chunks_exact(width * pixel_bytes);
    let rows: Box<dyn Iterator<Item = &[u8]>> = if top_down { Box::new(rows) } else { Box::new(rows.rev()) };
    let mut out = Vec::with_capacity(stored.len());
    for row in rows {
        match right_to_left {
            true => row.chunks_exact(pixel_bytes).rev().for_each(|pixel| out.extend_from_slice(pixel)),
            false => out.extend_from_slice(row),
        }
    }
    Cow::Owned(out)
}

/// The header of a Targa file this crate writes (uncompressed, top-down), read from `input`, which is left
/// at the first row.
pub(super) fn stream_header(input: &mut impl std::io::Read) -> Result<Header, FormatError> {
    let fixed = Fixed::read(input)?;
    let mut id = vec![0; fixed.id_length as usize];
    read_exactly(input, &mut id, "Targa image ID")?;
    let text = String::from_utf8(id).ok().filter(|t| !t.is_empty());
    let Fixed { map_type, image_type, pixel_bits, map_bits, map_first, descriptor, map_length, .. } = fixed;
    let palette = match (map_type, image_type, pixel_bits, map_bits, map_first, descriptor) {
        (0, 2, 24, _, _, TOP_DOWN) => None,
        (1, 1, 8, 24, 0, TOP_DOWN) if map_length <= 256 => {
            let mut map = vec![0; map_length * 3];
            read_exactly(input, &mut map, "Targa colour map")?;
            Some(map.chunks_exact(3).map(|e| [e[2], e[1], e[0]]).collect())
        }
        _ => {
            return unsupported(format!(
                "Targa image type {image_type}, {pixel_bits} bits, descriptor {descriptor:#x}: not one host-sim writes"
            ))
        }
    };
    Ok(Header { width: u32::from(fixed.width), height: u32::from(fixed.height), palette, text })
}

#[cfg(test)]
mod tests {
    use super::super::tests::{encode, rgb, samples};
    use super::super::{read, Format};
    use super::*;

    /// The Targa file as another project's reader decodes it (ffmpeg's,
    /// which the test command installs): RGB, rows top to bottom.
    fn decoded_by_ffmpeg(bytes: &[u8]) -> Vec<u8> {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let file = dir.path().join("image.tga");
        std::fs::write(&file, bytes).expect("the Targa file written");
        let output = std::process::Command::new("ffmpeg")
            .args(["-v", "error", "-i"])
            .arg(&file)
            .args(["-f", "rawvideo", "-pix_fmt", "rgb24", "-"])
            .output()
            .expect("ffmpeg is missing: install Debian's ffmpeg (scripts/test-all does)");
        assert!(output.status.success(), "ffmpeg: {}", String::from_utf8_lossy(&output.stderr));
        output.stdout
    }

    #[test]
    fn written_targas_decode_with_another_reader() {
        for image in samples() {
            let bytes = encode(&image, Format::Tga);
            assert_eq!(decoded_by_ffmpeg(&bytes), image.to_rgb().data);
        }
    }

    #[test]
    fn targa_rows_stored_bottom_up_or_right_to_left_are_reordered() {
        let image = rgb(3, 2);
        let top_down = encode(&image, Format::Tga);
        let (header, pixels) = top_down.split_at(18);
        let rows: Vec<&[u8]> = pixels.chunks(9).collect();
        let stored =
            |descriptor: u8, rows: Vec<Vec<u8>>| [header[..17].to_vec(), vec![descriptor], rows.concat()].concat();
        let mirrored = |row: &[u8]| row.chunks(3).rev().flatten().copied().collect::<Vec<u8>>();
        let bottom_up = stored(0, rows.iter().rev().map(|r| r.to_vec()).collect());
        let right_to_left = stored(0x30, rows.iter().map(|r| mirrored(r)).collect());
        let both = stored(0x10, rows.iter().rev().map(|r| mirrored(r)).collect());
        for bytes in [bottom_up, right_to_left, both] {
            assert_eq!(read(&bytes).unwrap(), image);
            assert_eq!(decoded_by_ffmpeg(&bytes), image.to_rgb().data);
        }
    }

    #[test]
    fn a_32_bit_targa_is_read_unless_its_alpha_makes_a_pixel_transparent() {
        // Two pixels, BGRA, top-down; `attributes` the descriptor's alpha bits.
        let targa = |attributes: u8, alpha: [u8; 2]| {
            let mut bytes = vec![0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 32, TOP_DOWN | attributes];
            bytes.extend([3, 2, 1, alpha[0], 6, 5, 4, alpha[1]]);
            bytes
        };
        let image = Image::Rgb(RgbImage { width: 2, height: 1, data: vec![1, 2, 3, 4, 5, 6] });
        for (attributes, alpha) in [(8, [255, 255]), (8, [0, 0]), (0, [255, 128])] {
            assert_eq!(read(&targa(attributes, alpha)).unwrap(), image, "{attributes} {alpha:?}");
        }
        let message = read(&targa(8, [255, 128])).unwrap_err().to_string();
        assert!(message.contains("32-bit pixels with transparent pixels (the first at x 1, y 0)"), "{message}");
    }

    #[test]
    fn run_length_targas_are_read() {
        let (palette, indices) =
            ((0..7).map(|i| [i, 2 * i, 3 * i]).collect(), vec![1, 1, 1, 2, 3, 3, 3, 3, 3, 0, 4, 5, 6, 6, 6]);
        let image = Image::Indexed { width: 5, height: 3, palette, indices };
        let map_end = 18 + 7 * 3;
        // Runs (high bit set) and raw packets, a run crossing from the first row into the second.
        let packets = [0x82, 1, 0x00, 2, 0x84, 3, 0x01, 0, 4, 0x00, 5, 0x82, 6];
        let mut indexed = [&encode(&image, Format::Tga)[..map_end], &packets].concat();
        indexed[2] = 9;

        let [p, q, r] = [[1, 2, 3], [4, 5, 6], [7, 8, 9]];
        let truecolour = Image::Rgb(RgbImage { width: 2, height: 2, data: [p, q, q, r].concat() });
        let bgr = |[r, g, b]: [u8; 3]| [b, g, r];
        let packets = [&[0x00][..], &bgr(p), &[0x81], &bgr(q), &[0x00], &bgr(r)].concat();
        let mut rgb = [&encode(&truecolour, Format::Tga)[..18], &packets].concat();
        rgb[2] = 10;

        for (bytes, image) in [(indexed, image), (rgb, truecolour)] {
            assert_eq!(read(&bytes).unwrap(), image);
            assert_eq!(decoded_by_ffmpeg(&bytes), image.to_rgb().data);
        }
    }
}
