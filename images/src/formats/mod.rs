//! The thesis's image files (PNG, Targa and Sun raster), each truecolour or colour-mapped, read whole or a
//! row at a time ([`RowReader`], [`RowWriter`]); one module a format.
//!
//! Written:
//! - PNG: 8-bit RGB (colour type 2), or 8-bit indices with a PLTE chunk (colour type 3).
//! - Targa: uncompressed, origin top-left (descriptor bit 5), no image ID: truecolour as image type 2 with
//!   24-bit BGR pixels, colour-mapped as image type 1 with a 24-bit BGR map (first entry 0) and 8-bit indices.
//! - Sun raster: RT_STANDARD (type 1): truecolour with 24-bit BGR pixels and no map, colour-mapped with 8-bit
//!   indices and an RMT_EQUAL_RGB map (all reds, then all greens, then all blues); each row padded to an
//!   even number of bytes.
//!
//! Read, besides everything written: PNG indices of 1, 2 or 4 bits, and 8-bit gray with alpha, RGB with alpha
//! and indices with a tRNS chunk when every pixel is opaque (a transparent one is a [`FormatError`]: no format
//! here holds it); Targa images stored bottom-up or right-to-left, run-length encoded (types 9 and 10), with an
//! image ID, with 32-bit pixels or map entries (opaque, or alpha all zero or not counted by the descriptor, as
//! writers without alpha leave it), or truecolour with a colour map (skipped); Sun rasters of type 0
//! (RT_OLD), 2 (sun_raster::RT_BYTE_ENCODED) and 3 (RT_FORMAT_RGB, stored RGB), and with 32-bit pixels (pad byte
//! dropped). Anything else, and any malformed file, is a [`FormatError`]: reading never panics, and rejects
//! declared sizes the file is too short to hold (even fully compressed) before allocating for them.

mod bytes;
mod error;
mod image;
mod png;
mod rows;
mod sun_raster;
mod targa;

pub use error::FormatError;
pub use image::{Format, Header, Image, TEXT_KEYWORD};
pub use rows::{RowReader, RowWriter};

use error::invalid;
use image::{check, not_an_image};
use std::io::Write;

/// Writes `image` to `out` as a `format` file.
pub fn write(image: &Image, format: Format, out: &mut dyn Write) -> Result<(), FormatError> {
    write_with_text(image, None, format, out)
}

/// [`write()`], the file carrying `text` as [`Header::text`] says (a Sun
/// raster cannot: an error).
pub fn write_with_text(
    image: &Image,
    text: Option<String>,
    format: Format,
    out: &mut dyn Write,
) -> Result<(), FormatError> {
    check(image)?;
    let (palette, data) = match image {
        Image::Rgb(rgb) => (None, &rgb.data),
        Image::Indexed { palette, indices, .. } => (Some(palette.clone()), indices),
    };
    let header = Header { width: image.width(), height: image.height(), palette, text };
    let row_bytes = header.width as usize * header.bytes_per_pixel();
    let mut writer = RowWriter::new(format, &header, out)?;
    for row in data.chunks_exact(row_bytes) {
        writer.write_row(row)?;
    }
    writer.finish()
}

/// Writes an indexed image whose colour table is all grays (red, green and blue equal, as
/// [`crate::panel::dithered`] makes for a gray panel) as an 8-bit grayscale PNG file, the smallest file that holds it.
pub fn write_gray_png(image: &Image, out: &mut dyn Write) -> Result<(), FormatError> {
    check(image)?;
    let Image::Indexed { width, height, palette, indices } = image else {
        return invalid("a grayscale PNG is written from a gray colour table, not from RGB pixels".into());
    };
    if let Some(entry) = palette.iter().find(|[r, g, b]| r != g || g != b) {
        return invalid(format!("colour {entry:?} of the table is not a gray"));
    }
    let gray: Vec<u8> = indices.iter().map(|&i| palette[i as usize][0]).collect();
    png::write_gray(*width, *height, &gray, out)
}

/// The signatures of images of other formats, named rather than read as
/// Targa files (which have none): none of them can begin a Targa file, whose
/// second byte, the colour map's type, is 0 or 1.
const OTHER_SIGNATURES: [(&[u8], &str); 5] =
    [(b"GIF87a", "GIF"), (b"GIF89a", "GIF"), (b"\xff\xd8\xff", "JPEG"), (b"BM", "BMP"), (b"RIFF", "RIFF (WebP)")];

/// Reads an image file of any of the formats, told apart by their content.
pub fn read(bytes: &[u8]) -> Result<Image, FormatError> {
    let image = if bytes.starts_with(png::SIGNATURE) {
        png::read(bytes)?
    } else if bytes.starts_with(&sun_raster::MAGIC.to_be_bytes()) {
        sun_raster::read(bytes)?
    } else if let Some(&(_, name)) = OTHER_SIGNATURES.iter().find(|(signature, _)| bytes.starts_with(signature)) {
        return Err(FormatError::Unsupported(format!("a {name} image, {}", not_an_image())));
    } else if targa::could_be(bytes) {
        targa::read(bytes).map_err(targa::no_image)?
    } else {
        return Err(not_an_image());
    };
    check(&image)?;
    Ok(image)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::RgbImage;
    use std::path::Path;

    pub(crate) fn rgb(width: u32, height: u32) -> Image {
        let data = (0..width * height * 3).map(|i| (i * 37 + 11) as u8).collect();
        Image::Rgb(RgbImage { width, height, data })
    }

    pub(crate) fn indexed(width: u32, height: u32, entries: usize) -> Image {
        let palette = (0..entries).map(|i| [i as u8, (i * 7 + 1) as u8, 255 - (i * 3) as u8]).collect();
        let indices = (0..width as usize * height as usize).map(|i| ((i * 5 + 3) % entries) as u8).collect();
        Image::Indexed { width, height, palette, indices }
    }

    pub(crate) fn samples() -> Vec<Image> {
        let sizes = [(1, 1), (3, 2), (7, 5)];
        let mut images: Vec<Image> = sizes.iter().flat_map(|&(w, h)| [rgb(w, h), indexed(w, h, 12)]).collect();
        images.extend([indexed(1, 1, 1), indexed(16, 16, 256), indexed(5, 3, 256)]);
        images
    }

    pub(crate) fn encode(image: &Image, format: Format) -> Vec<u8> {
        let mut bytes = Vec::new();
        write(image, format, &mut bytes).unwrap();
        bytes
    }

    #[test]
    fn every_format_round_trips_truecolour_and_indexed_images() {
        for format in Format::ALL {
            for image in samples() {
                let back = read(&encode(&image, format));
                assert_eq!(back.as_ref().ok(), Some(&image), "{} {}×{}", format.name(), image.width(), image.height());
            }
        }
    }

    #[test]
    fn invalid_images_are_not_written() {
        let message = |image: &Image, format| write(image, format, &mut Vec::new()).unwrap_err().to_string();
        for format in Format::ALL {
            assert_eq!(message(&indexed(3, 2, 300), format), "palette has 300 entries, at most 256");
            let Image::Indexed { width, height, palette, mut indices } = indexed(3, 2, 12) else { unreachable!() };
            indices[4] = 17;
            let image = Image::Indexed { width, height, palette, indices };
            assert_eq!(message(&image, format), "index 17 is outside the 12-entry palette");
            assert_eq!(message(&rgb(0, 4), format), "the image is 0×4 pixels");
            let short = Image::Rgb(RgbImage { width: 2, height: 2, data: vec![0; 11] });
            assert_eq!(message(&short, format), "11 bytes of pixel data for a 2×2 image");
        }
        assert!(message(&rgb(65536, 1), Format::Tga).contains("at most 65535×65535"));
    }

    #[test]
    fn malformed_files_give_errors() {
        let message = |bytes: &[u8]| read(bytes).unwrap_err().to_string();
        // A file without a PNG's or Sun raster's signature is read as a
        // Targa file when its header can be one's; otherwise it is no image.
        let no_image = "not a PNG, Targa or Sun raster image";
        let as_targa = |detail: &str| format!("{no_image} (as a Targa file: {detail})");
        assert_eq!(message(b"GIF89a, a GIF of some kind"), "a GIF image, not a PNG, Targa or Sun raster image");
        assert_eq!(message(b"\xff\xd8\xff\xe0 JFIF"), "a JPEG image, not a PNG, Targa or Sun raster image");
        assert_eq!(message(b"GIF90a, of no kind at all"), no_image);
        assert_eq!(message(b"FRAMES 48 24\nRASTER    240 180\n"), no_image, "a text file");
        assert_eq!(message(&[]), no_image);
        assert_eq!(message(&encode(&rgb(3, 2), Format::Tga)[..17]), no_image, "shorter than a Targa header");
        assert_eq!(message(&sun_raster::MAGIC.to_be_bytes()), "truncated Sun raster header");
        assert_eq!(message(png::SIGNATURE), "truncated PNG file");
        let mut tga = encode(&rgb(3, 2), Format::Tga);
        tga[2] = 3;
        assert_eq!(message(&tga), as_targa("Targa image type 3 is not supported"));
        tga[2] = 2;
        tga[12..16].copy_from_slice(&[0xff; 4]);
        assert_eq!(message(&tga), as_targa("truncated Targa pixels"));
        tga[2] = 10;
        assert_eq!(message(&tga), as_targa("truncated Targa run-length data"));

        let mut ras = encode(&indexed(3, 2, 12), Format::Ras);
        ras[32 + 36 + 1] = 12;
        assert_eq!(message(&ras), "index 12 is outside the 12-entry palette");
        ras[4..12].copy_from_slice(&[0xff; 8]);
        assert_eq!(message(&ras), "truncated Sun raster pixels");
        ras[23] = sun_raster::RT_BYTE_ENCODED as u8;
        assert_eq!(message(&ras), "truncated Sun raster run-length data");
        ras[23] = 5;
        assert_eq!(message(&ras), "Sun raster type 5 is not supported");
        ras[28..32].copy_from_slice(&[0xff; 4]);
        assert_eq!(message(&ras), "truncated Sun raster colour map");

        let mut huge = Vec::new();
        let mut encoder = ::png::Encoder::new(&mut huge, 1 << 20, 1 << 20);
        encoder.set_color(::png::ColorType::Rgb);
        drop(encoder.write_header().unwrap());
        assert!(message(&huge).contains("cannot fit in"));
    }

    #[test]
    fn mutated_files_never_panic() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut random = move |below: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % below as u64) as usize
        };
        for format in Format::ALL {
            for image in [rgb(7, 5), indexed(7, 5, 12), indexed(2, 1, 1)] {
                let valid = encode(&image, format);
                for length in 0..valid.len() {
                    assert!(read(&valid[..length]).is_err(), "{} cut to {length} bytes", format.name());
                }
                for _ in 0..2000 {
                    let mut bytes = valid.clone();
                    for _ in 0..1 + random(4) {
                        let at = random(bytes.len());
                        bytes[at] = if random(2) == 0 { bytes[at] ^ 1 << random(8) } else { random(256) as u8 };
                    }
                    bytes.truncate(bytes.len() - random(4));
                    let _ = read(&bytes);
                }
            }
        }
    }

    #[test]
    fn formats_are_named_by_extension() {
        assert_eq!(Format::from_path(Path::new("out/fig5_1.PNG")), Some(Format::Png));
        assert_eq!(Format::from_path(Path::new("a.tga")), Some(Format::Tga));
        assert_eq!(Format::from_path(Path::new("a.b.Ras")), Some(Format::Ras));
        assert_eq!(Format::from_path(Path::new("ras")), None);
        assert_eq!(Format::from_path(Path::new("a.jpg")), None);
    }
}
