//! Images a row at a time, so that neither side holds more than a row: host-sim streams a render into a
//! file this way, and reads the parts it merges.
//!
//! Invariant: a [`RowWriter`] has written exactly the rows it was given, in order, after the header; a
//! [`RowReader`] hands back rows of exactly `width` pixels, every index inside the palette.

use super::bytes::{read_exactly, BGR};
use super::error::{invalid, unsupported, FormatError};
use super::image::{check_indices, check_palette_length, check_size, not_an_image, Format, Header};
use super::{png, sun_raster, targa};
use std::io::{BufRead, BufReader, Write};

/// Writes an image a row at a time, top to bottom, so that no more than a row is held: the file's header
/// first, then each row as it comes. Every row must come; [`RowWriter::finish`] says if one is missing.
pub struct RowWriter<'a> {
    encoder: RowEncoder<'a>,
    row_bytes: usize,
    rows_left: u32,
    /// A row as stored (BGR, padded), reused.
    stored: Vec<u8>,
}

enum RowEncoder<'a> {
    /// The encoder owns its output, so it writes into a buffer that is drained into `out` after each row.
    Png { writer: Box<::png::StreamWriter<'static, png::Buffer>>, buffer: png::Buffer, out: &'a mut dyn Write },
    /// Targa and Sun raster rows: BGR when truecolour, padded to `pad` extra bytes.
    Raw { out: &'a mut dyn Write, bgr: bool, pad: usize },
}

impl<'a> RowWriter<'a> {
    /// Writes the header of a `format` file to `out`; the rows follow through [`RowWriter::write_row`].
    pub fn new(format: Format, header: &Header, out: &'a mut dyn Write) -> Result<RowWriter<'a>, FormatError> {
        check_size(header.width, header.height)?;
        if let Some(palette) = &header.palette {
            check_palette_length(palette)?;
        }
        let row_bytes = header.width as usize * header.bytes_per_pixel();
        let encoder = match format {
            Format::Png => {
                let buffer = png::Buffer::default();
                let writer = Box::new(png::stream_writer(header, buffer.clone())?);
                let mut encoder = RowEncoder::Png { writer, buffer, out };
                encoder.drain()?;
                encoder
            }
            Format::Tga => {
                out.write_all(&targa::header_bytes(header)?)?;
                RowEncoder::Raw { out, bgr: header.palette.is_none(), pad: 0 }
            }
            Format::Ras => {
                if header.text.is_some() {
                    return unsupported("a Sun raster cannot carry text: use PNG or Targa".into());
                }
                out.write_all(&sun_raster::header_bytes(header)?)?;
                RowEncoder::Raw { out, bgr: header.palette.is_none(), pad: sun_raster::row_padding(row_bytes) }
            }
        };
        Ok(RowWriter { encoder, row_bytes, rows_left: header.height, stored: Vec::new() })
    }

    /// Writes the next row: `width` RGB triples, or `width` indices into the palette.
    pub fn write_row(&mut self, row: &[u8]) -> Result<(), FormatError> {
        if row.len() != self.row_bytes {
            return invalid(format!("a row of {} bytes where {} were expected", row.len(), self.row_bytes));
        }
        if self.rows_left == 0 {
            return invalid("more rows than the image has".into());
        }
        self.rows_left -= 1;
        match &mut self.encoder {
            RowEncoder::Png { writer, .. } => {
                writer.write_all(row).map_err(|e| match e.downcast::<::png::EncodingError>() {
                    Ok(e) => png::encoding_error(e),
                    Err(e) => FormatError::Io(e),
                })?;
                self.encoder.drain()
            }
            RowEncoder::Raw { out, bgr, pad } => {
                let stored = if *bgr {
                    self.stored.clear();
                    self.stored.extend(row.chunks_exact(3).flat_map(|p| BGR.map(|i| p[i])));
                    self.stored.extend_from_slice(&[0][..*pad]);
                    &self.stored[..]
                } else if *pad > 0 {
                    self.stored.clear();
                    self.stored.extend_from_slice(row);
                    self.stored.push(0);
                    &self.stored[..]
                } else {
                    row
                };
                Ok(out.write_all(stored)?)
            }
        }
    }

    /// Ends the file; fails if rows are missing.
    pub fn finish(self) -> Result<(), FormatError> {
        if self.rows_left > 0 {
            return invalid(format!("{} rows of the image were never written", self.rows_left));
        }
        match self.encoder {
            RowEncoder::Png { writer, buffer, out } => {
                writer.finish().map_err(png::encoding_error)?;
                out.write_all(&buffer.take())?;
                Ok(out.flush()?)
            }
            RowEncoder::Raw { out, .. } => Ok(out.flush()?),
        }
    }
}

impl RowEncoder<'_> {
    /// Moves what the PNG encoder wrote so far to the file.
    fn drain(&mut self) -> Result<(), FormatError> {
        if let RowEncoder::Png { buffer, out, .. } = self {
            out.write_all(&buffer.take())?;
        }
        Ok(())
    }
}

/// Reads an image a row at a time, top to bottom, holding no more than a row: the files this crate writes
/// (PNG of 8-bit RGB or indices, not interlaced; uncompressed top-down Targa; standard Sun rasters), with
/// the text they carry. Other files (which [`super::read`] takes whole) are refused.
pub struct RowReader {
    header: Header,
    decoder: RowDecoder,
    rows_left: u32,
    row: Vec<u8>,
}

enum RowDecoder {
    Png(Box<::png::Reader<BufReader<std::fs::File>>>),
    /// Targa and Sun raster rows as stored: BGR when truecolour, padded.
    Raw {
        input: BufReader<std::fs::File>,
        bgr: bool,
        stored: Vec<u8>,
    },
}

impl RowReader {
    /// Reads the header of the image file `file` (told apart by content).
    pub fn new(file: std::fs::File) -> Result<RowReader, FormatError> {
        let mut input = BufReader::new(file);
        let start = input.fill_buf()?;
        let (header, decoder) = if start.starts_with(png::SIGNATURE) {
            let (header, reader) = png::row_reader(input)?;
            (header, RowDecoder::Png(Box::new(reader)))
        } else {
            let is_ras = start.starts_with(&sun_raster::MAGIC.to_be_bytes());
            let header = if is_ras {
                sun_raster::stream_header(&mut input)?
            } else if targa::could_be(start) {
                targa::stream_header(&mut input).map_err(targa::no_image)?
            } else {
                return Err(not_an_image());
            };
            let row_bytes = header.width as usize * header.bytes_per_pixel();
            let pad = if is_ras { sun_raster::row_padding(row_bytes) } else { 0 };
            let (bgr, stored) = (header.palette.is_none(), vec![0; row_bytes + pad]);
            (header, RowDecoder::Raw { input, bgr, stored })
        };
        check_size(header.width, header.height)?;
        Ok(RowReader { rows_left: header.height, header, decoder, row: Vec::new() })
    }

    /// The file's header, with its text.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The next row (RGB triples or indices); an error past the last row.
    pub fn next_row(&mut self) -> Result<&[u8], FormatError> {
        if self.rows_left == 0 {
            return invalid("no rows left".into());
        }
        self.rows_left -= 1;
        self.row.clear();
        match &mut self.decoder {
            RowDecoder::Png(reader) => {
                let row = reader.next_row().map_err(png::decoding_error)?;
                let row = row.ok_or(FormatError::Truncated("PNG image data"))?;
                self.row.extend_from_slice(row.data());
            }
            RowDecoder::Raw { input, bgr, stored } => {
                read_exactly(input, stored, "pixels")?;
                let width = self.header.width as usize;
                if *bgr {
                    self.row.extend(stored[..3 * width].chunks_exact(3).flat_map(|p| BGR.map(|i| p[i])));
                } else {
                    self.row.extend_from_slice(&stored[..width]);
                }
            }
        }
        if let Some(palette) = &self.header.palette {
            check_indices(&self.row, palette)?;
        }
        Ok(&self.row)
    }

    /// Reads on to the end the format marks, after the last row: a PNG's
    /// IEND, its chunks' checksums on the way, so that a file cut short
    /// after its pixels is not taken for whole (Targa and Sun raster files
    /// end with their pixels).
    pub fn finish(self) -> Result<(), FormatError> {
        match self.decoder {
            RowDecoder::Png(mut reader) => reader.finish().map_err(png::decoding_error),
            RowDecoder::Raw { .. } => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::samples;
    use super::super::{read, Image};
    use super::*;

    #[test]
    fn rows_read_back_with_their_text() {
        let dir = std::env::temp_dir().join(format!("octrace-rows-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for format in Format::ALL {
            for image in samples() {
                let text = (format != Format::Ras).then(|| "octrace-part 1 and some words".to_string());
                let (palette, data) = match &image {
                    Image::Rgb(rgb) => (None, rgb.data.clone()),
                    Image::Indexed { palette, indices, .. } => (Some(palette.clone()), indices.clone()),
                };
                let header = Header { width: image.width(), height: image.height(), palette, text };
                let mut bytes = Vec::new();
                let mut writer = RowWriter::new(format, &header, &mut bytes).unwrap();
                let row_bytes = data.len() / image.height() as usize;
                data.chunks(row_bytes).for_each(|row| writer.write_row(row).unwrap());
                writer.finish().unwrap();
                assert_eq!(read(&bytes).unwrap(), image, "{} as a whole", format.name());
                let path = dir.join(format!("image.{}", format.name()));
                std::fs::write(&path, &bytes).unwrap();
                let mut reader = RowReader::new(std::fs::File::open(&path).unwrap()).unwrap();
                assert_eq!(reader.header(), &header, "{}", format.name());
                for row in data.chunks(row_bytes) {
                    assert_eq!(reader.next_row().unwrap(), row);
                }
                assert!(reader.next_row().is_err());
                reader.finish().unwrap();
                // A PNG cut after its pixels, its IEND or its checksum's
                // last byte gone, is refused at the end.
                if format == Format::Png {
                    for cut in [1, 12] {
                        std::fs::write(&path, &bytes[..bytes.len() - cut]).unwrap();
                        let mut reader = RowReader::new(std::fs::File::open(&path).unwrap()).unwrap();
                        for _ in 0..image.height() {
                            reader.next_row().unwrap();
                        }
                        assert!(reader.finish().is_err(), "cut by {cut}");
                    }
                }
            }
        }
        let header = Header { width: 1, height: 1, palette: None, text: Some("t".into()) };
        assert!(RowWriter::new(Format::Ras, &header, &mut Vec::new()).is_err(), "a Sun raster has no room for text");
        let mut sink = std::io::sink();
        let mut writer = RowWriter::new(Format::Png, &Header { text: None, ..header }, &mut sink).unwrap();
        assert!(writer.write_row(&[0; 4]).is_err(), "a row of the wrong length");
        // A text file is no image, not a Targa file of some unknown type.
        let text = dir.join("notes.txt");
        std::fs::write(&text, "Rows are written top to bottom, each as stored.\n").unwrap();
        let refused = RowReader::new(std::fs::File::open(&text).unwrap()).err().map(|e| e.to_string());
        assert_eq!(refused.as_deref(), Some("not a PNG, Targa or Sun raster image"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
