//! Reads and writes the thesis's image files (PNG, Targa and Sun raster), each truecolour or colour-mapped.
//!
//! Written:
//! - PNG: 8-bit RGB (colour type 2), or 8-bit indices with a PLTE chunk (colour type 3).
//! - Targa: uncompressed, origin top-left (descriptor bit 5), no image ID: truecolour as image type 2 with
//!   24-bit BGR pixels, colour-mapped as image type 1 with a 24-bit BGR map (first entry 0) and 8-bit indices.
//! - Sun raster: RT_STANDARD (type 1): truecolour with 24-bit BGR pixels and no map, colour-mapped with 8-bit
//!   indices and an RMT_EQUAL_RGB map (all reds, then all greens, then all blues); each row padded to an
//!   even number of bytes.
//!
//! Read, besides everything written: PNG indices of 1, 2 or 4 bits (transparency ignored); Targa images
//! stored bottom-up or right-to-left, run-length encoded (types 9 and 10), with an image ID, with 32-bit
//! pixels or map entries (alpha dropped), or truecolour with a colour map (skipped); Sun rasters of type 0
//! (RT_OLD), 2 (RT_BYTE_ENCODED) and 3 (RT_FORMAT_RGB, stored RGB), and with 32-bit pixels (pad byte
//! dropped). Anything else, and any malformed file, is a [`FormatError`]: reading never panics, and rejects
//! declared sizes the file is too short to hold (even fully compressed) before allocating for them.

use crate::RgbImage;
use std::borrow::Cow;
use std::fmt;
use std::io::Write;
use std::path::Path;

/// An image file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Format {
    Png,
    Tga,
    Ras,
}

impl Format {
    /// The format named by `path`'s extension (png, tga or ras, any case).
    pub fn from_path(path: &Path) -> Option<Format> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        [Format::Png, Format::Tga, Format::Ras].into_iter().find(|f| f.name() == extension)
    }

    /// The format's usual file name extension, which also names it.
    pub fn name(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Tga => "tga",
            Format::Ras => "ras",
        }
    }
}

/// An image as a file holds it: pixels, or indices into a palette.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Image {
    Rgb(RgbImage),
    /// `indices` row-major, one per pixel.
    Indexed {
        width: u32,
        height: u32,
        palette: Vec<[u8; 3]>,
        indices: Vec<u8>,
    },
}

impl Image {
    pub fn width(&self) -> u32 {
        match self {
            Image::Rgb(rgb) => rgb.width,
            Image::Indexed { width, .. } => *width,
        }
    }

    pub fn height(&self) -> u32 {
        match self {
            Image::Rgb(rgb) => rgb.height,
            Image::Indexed { height, .. } => *height,
        }
    }

    /// The image's pixels; an index outside the palette gives black.
    pub fn to_rgb(&self) -> RgbImage {
        match self {
            Image::Rgb(rgb) => rgb.clone(),
            Image::Indexed { width, height, palette, indices } => {
                let pixels = *width as usize * *height as usize;
                let colour = |i: usize| indices.get(i).and_then(|&index| palette.get(index as usize));
                let data = (0..pixels).flat_map(|i| *colour(i).unwrap_or(&[0; 3])).collect();
                RgbImage { width: *width, height: *height, data }
            }
        }
    }
}

impl From<RgbImage> for Image {
    fn from(rgb: RgbImage) -> Image {
        Image::Rgb(rgb)
    }
}

/// Why an image could not be read or written.
#[derive(Debug)]
pub enum FormatError {
    /// Writing the file failed.
    Io(std::io::Error),
    /// The file ends inside the named part.
    Truncated(&'static str),
    /// A kind of file this module does not handle.
    Unsupported(String),
    /// A malformed file, or an image that no file can hold as it is.
    Invalid(String),
}

impl fmt::Display for FormatError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FormatError::Io(e) => write!(f, "{e}"),
            FormatError::Truncated(part) => write!(f, "truncated {part}"),
            FormatError::Unsupported(what) | FormatError::Invalid(what) => f.write_str(what),
        }
    }
}

impl std::error::Error for FormatError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            FormatError::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl From<std::io::Error> for FormatError {
    fn from(e: std::io::Error) -> FormatError {
        FormatError::Io(e)
    }
}

fn invalid<T>(message: String) -> Result<T, FormatError> {
    Err(FormatError::Invalid(message))
}

fn unsupported<T>(message: String) -> Result<T, FormatError> {
    Err(FormatError::Unsupported(message))
}

/// Writes `image` to `out` as a `format` file.
pub fn write(image: &Image, format: Format, out: &mut dyn Write) -> Result<(), FormatError> {
    check(image)?;
    let (width, row_bytes) = (image.width() as usize, image.width() as usize * image.bytes_per_pixel());
    let (palette, data) = match image {
        Image::Rgb(rgb) => (None, &rgb.data),
        Image::Indexed { palette, indices, .. } => (Some(palette.clone()), indices),
    };
    let header = Header { width: width as u32, height: image.height(), palette, text: None };
    let mut writer = RowWriter::new(format, &header, out)?;
    for row in data.chunks_exact(row_bytes) {
        writer.write_row(row)?;
    }
    writer.finish()
}

/// What a file says before its rows.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Header {
    pub width: u32,
    pub height: u32,
    /// The colour table of an indexed image (rows are then one index a pixel), or `None` for truecolour (rows
    /// of RGB triples).
    pub palette: Option<Vec<[u8; 3]>>,
    /// Text carried in the file: a PNG `tEXt` chunk under [`TEXT_KEYWORD`] or a Targa image ID (at most 255
    /// bytes). Sun rasters have nowhere to put it.
    pub text: Option<String>,
}

/// The keyword of the PNG `tEXt` chunk that carries [`Header::text`].
pub const TEXT_KEYWORD: &str = "octrace";

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
    Png { writer: Box<png::StreamWriter<'static, Buffer>>, buffer: Buffer, out: &'a mut dyn Write },
    /// Targa and Sun raster rows: BGR when truecolour, padded to `pad` extra bytes.
    Raw { out: &'a mut dyn Write, bgr: bool, pad: usize },
}

fn png_encoding_error(e: png::EncodingError) -> FormatError {
    match e {
        png::EncodingError::IoError(e) => FormatError::Io(e),
        e => FormatError::Invalid(format!("PNG encoder: {e}")),
    }
}

impl<'a> RowWriter<'a> {
    /// Writes the header of a `format` file to `out`; the rows follow through [`RowWriter::write_row`].
    pub fn new(format: Format, header: &Header, out: &'a mut dyn Write) -> Result<RowWriter<'a>, FormatError> {
        let (width, height) = (header.width, header.height);
        if width == 0 || height == 0 {
            return invalid(format!("the image is {width}×{height} pixels"));
        }
        if let Some(palette) = &header.palette {
            if palette.len() > 256 {
                return invalid(format!("palette has {} entries, at most 256", palette.len()));
            }
        }
        let pixel_bytes = if header.palette.is_some() { 1 } else { 3 };
        let row_bytes = width as usize * pixel_bytes;
        let encoder = match format {
            Format::Png => {
                let buffer = Buffer::default();
                let writer = Box::new(png_stream_writer(header, buffer.clone())?);
                let mut encoder = RowEncoder::Png { writer, buffer, out };
                encoder.drain()?;
                encoder
            }
            Format::Tga => {
                out.write_all(&tga_header(header)?)?;
                RowEncoder::Raw { out, bgr: header.palette.is_none(), pad: 0 }
            }
            Format::Ras => {
                if header.text.is_some() {
                    return unsupported("a Sun raster cannot carry text: use PNG or Targa".into());
                }
                out.write_all(&ras_header(header)?)?;
                RowEncoder::Raw { out, bgr: header.palette.is_none(), pad: row_bytes % 2 }
            }
        };
        Ok(RowWriter { encoder, row_bytes, rows_left: height, stored: Vec::new() })
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
                writer.write_all(row).map_err(|e| match e.downcast::<png::EncodingError>() {
                    Ok(e) => png_encoding_error(e),
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
                writer.finish().map_err(png_encoding_error)?;
                let mut encoder = RowEncoder::Raw { out, bgr: false, pad: 0 };
                encoder.write_buffered(&buffer)?;
                encoder.flush()
            }
            mut raw @ RowEncoder::Raw { .. } => raw.flush(),
        }
    }
}

/// Bytes the PNG encoder has written and the file has not yet received.
#[derive(Clone, Default)]
struct Buffer(std::rc::Rc<std::cell::RefCell<Vec<u8>>>);

impl Write for Buffer {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().extend_from_slice(bytes);
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl RowEncoder<'_> {
    /// Moves what the PNG encoder wrote so far to the file.
    fn drain(&mut self) -> Result<(), FormatError> {
        match self {
            RowEncoder::Png { buffer, out, .. } => {
                let mut bytes = buffer.0.borrow_mut();
                out.write_all(&bytes)?;
                bytes.clear();
                Ok(())
            }
            RowEncoder::Raw { .. } => Ok(()),
        }
    }

    fn write_buffered(&mut self, buffer: &Buffer) -> Result<(), FormatError> {
        if let RowEncoder::Raw { out, .. } = self {
            out.write_all(&buffer.0.borrow())?;
        }
        Ok(())
    }

    fn flush(&mut self) -> Result<(), FormatError> {
        match self {
            RowEncoder::Png { out, .. } | RowEncoder::Raw { out, .. } => Ok(out.flush()?),
        }
    }
}

impl Image {
    /// Bytes a pixel takes in memory: 3 (RGB) or 1 (an index).
    pub fn bytes_per_pixel(&self) -> usize {
        match self {
            Image::Rgb(_) => 3,
            Image::Indexed { .. } => 1,
        }
    }
}

/// Reads an image file of any of the formats, told apart by their content.
pub fn read(bytes: &[u8]) -> Result<Image, FormatError> {
    let image = if bytes.starts_with(PNG_SIGNATURE) {
        read_png(bytes)?
    } else if bytes.starts_with(&RAS_MAGIC.to_be_bytes()) {
        read_ras(bytes)?
    } else {
        // Targa files have no signature.
        read_tga(bytes)?
    };
    check(&image)?;
    Ok(image)
}

/// Fails unless `image` is one every format can hold: not empty, the data as long as the size says, at most
/// 256 palette entries and every index inside the palette.
fn check(image: &Image) -> Result<(), FormatError> {
    let (width, height) = (image.width(), image.height());
    if width == 0 || height == 0 {
        return invalid(format!("the image is {width}×{height} pixels"));
    }
    let (length, per_pixel) = match image {
        Image::Rgb(rgb) => (rgb.data.len(), 3),
        Image::Indexed { indices, .. } => (indices.len(), 1),
    };
    if length as u64 != u64::from(width) * u64::from(height) * per_pixel {
        return invalid(format!("{length} bytes of pixel data for a {width}×{height} image"));
    }
    if let Image::Indexed { palette, indices, .. } = image {
        if palette.len() > 256 {
            return invalid(format!("palette has {} entries, at most 256", palette.len()));
        }
        if let Some(index) = indices.iter().find(|&&i| i as usize >= palette.len()) {
            return invalid(format!("index {index} is outside the {}-entry palette", palette.len()));
        }
    }
    Ok(())
}

/// The first `n` bytes of `input`, which moves past them.
fn take<'a>(input: &mut &'a [u8], n: usize, part: &'static str) -> Result<&'a [u8], FormatError> {
    let (head, rest) = input.split_at_checked(n).ok_or(FormatError::Truncated(part))?;
    *input = rest;
    Ok(head)
}

/// Pixels of `pixel_bytes` bytes each, red, green and blue at `offsets` in each, as RGB (or, as the
/// offsets are their own inverse, RGB as BGR); other bytes (alpha, padding) are dropped.
fn pick(pixels: &[u8], pixel_bytes: usize, offsets: [usize; 3]) -> Vec<u8> {
    pixels.chunks_exact(pixel_bytes).flat_map(|p| offsets.map(|i| p[i])).collect()
}

const BGR: [usize; 3] = [2, 1, 0];

const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

/// Deflate turns no byte into more than this many.
const DEFLATE_MAX_RATIO: u64 = 1032;

fn png_stream_writer(header: &Header, out: Buffer) -> Result<png::StreamWriter<'static, Buffer>, FormatError> {
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
        encoder.add_text_chunk(TEXT_KEYWORD.into(), text.clone()).map_err(png_encoding_error)?;
    }
    encoder.write_header().map_err(png_encoding_error)?.into_stream_writer().map_err(png_encoding_error)
}

fn read_png(bytes: &[u8]) -> Result<Image, FormatError> {
    let decoding_error = |e| match e {
        png::DecodingError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            FormatError::Truncated("PNG file")
        }
        e => FormatError::Invalid(format!("malformed PNG file: {e}")),
    };
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let header = decoder.read_header_info().map_err(decoding_error)?;
    let (width, height) = (header.width, header.height);
    let bits = match (header.color_type, header.bit_depth) {
        (png::ColorType::Rgb, png::BitDepth::Eight) => 24,
        (png::ColorType::Indexed, depth) => depth as u64,
        (colour, depth) => {
            return unsupported(format!("PNG files of {colour:?} colour at {} bits are not supported", depth as u8))
        }
    };
    // Each row is a filter byte and its pixels, deflated.
    let inflated = u64::from(height) * (1 + (u64::from(width) * bits).div_ceil(8));
    if inflated > bytes.len() as u64 * DEFLATE_MAX_RATIO {
        return invalid(format!("a {width}×{height} PNG image cannot fit in {} bytes", bytes.len()));
    }
    let mut reader = decoder.read_info().map_err(decoding_error)?;
    let palette: Option<Vec<[u8; 3]>> =
        reader.info().palette.as_ref().map(|p| p.chunks_exact(3).map(|e| [e[0], e[1], e[2]]).collect());
    let size = reader.output_buffer_size().ok_or_else(|| FormatError::Invalid("PNG image too large".into()))?;
    let mut buffer = vec![0; size];
    let frame = reader.next_frame(&mut buffer).map_err(decoding_error)?;
    buffer.truncate(frame.buffer_size());
    // Up to IEND, so that a file cut short is not taken for whole.
    reader.finish().map_err(decoding_error)?;
    if bits == 24 {
        return Ok(Image::Rgb(RgbImage { width, height, data: buffer }));
    }
    let palette = palette.ok_or_else(|| FormatError::Invalid("indexed PNG file without a PLTE chunk".into()))?;
    let indices = match bits {
        8 => buffer,
        _ => {
            let (bits, per_byte) = (bits as usize, 8 / bits as usize);
            let unpack =
                |row: &[u8], x: usize| row[x / per_byte] >> (8 - bits * (x % per_byte + 1)) & ((1 << bits) - 1);
            let rows = buffer.chunks_exact(frame.line_size);
            rows.flat_map(|row| (0..width as usize).map(move |x| unpack(row, x))).collect()
        }
    };
    Ok(Image::Indexed { width, height, palette, indices })
}

/// Reads an image a row at a time, top to bottom, holding no more than a row: the files this module writes
/// (PNG of 8-bit RGB or indices, not interlaced; uncompressed top-down Targa; standard Sun rasters), with
/// the text they carry. Other files (which [`read`] takes whole) are refused.
pub struct RowReader {
    header: Header,
    decoder: RowDecoder,
    rows_left: u32,
    row: Vec<u8>,
}

enum RowDecoder {
    Png(Box<png::Reader<std::io::BufReader<std::fs::File>>>),
    Raw { input: std::io::BufReader<std::fs::File>, bgr: bool, stored: Vec<u8> },
}

impl RowReader {
    /// Reads the header of the image file `file` (told apart by content).
    pub fn new(file: std::fs::File) -> Result<RowReader, FormatError> {
        use std::io::BufRead;
        let mut input = std::io::BufReader::new(file);
        let start = input.fill_buf()?;
        if start.starts_with(PNG_SIGNATURE) {
            return RowReader::png(input);
        }
        let is_ras = start.starts_with(&RAS_MAGIC.to_be_bytes());
        let mut fixed = vec![0; if is_ras { 32 } else { 18 }];
        let part = if is_ras { "Sun raster header" } else { "Targa header" };
        read_exactly(&mut input, &mut fixed, part)?;
        let (width, height, palette, text, pixel_bytes, pad) = if is_ras {
            let field =
                |i: usize| u32::from_be_bytes([fixed[4 * i], fixed[4 * i + 1], fixed[4 * i + 2], fixed[4 * i + 3]]);
            let [width, height, depth, _length, kind, map_type, map_length] = std::array::from_fn(|i| field(i + 1));
            let palette = match (depth, kind, map_type) {
                (24, RT_STANDARD, RMT_NONE) => None,
                (8, RT_STANDARD, RMT_EQUAL_RGB) if map_length % 3 == 0 && map_length <= 768 => {
                    let mut map = vec![0; map_length as usize];
                    read_exactly(&mut input, &mut map, "Sun raster colour map")?;
                    let entries = map.len() / 3;
                    Some((0..entries).map(|i| [map[i], map[entries + i], map[2 * entries + i]]).collect())
                }
                _ => {
                    return unsupported(format!(
                        "Sun raster of type {kind}, {depth} bits, map {map_type}: not one host-sim writes"
                    ))
                }
            };
            let pixel_bytes = if palette.is_some() { 1 } else { 3 };
            (width, height, palette, None, pixel_bytes, width as usize * pixel_bytes % 2)
        } else {
            let u16_at = |i: usize| u16::from_le_bytes([fixed[i], fixed[i + 1]]);
            let [id_length, map_type, image_type] = [fixed[0], fixed[1], fixed[2]];
            let (map_first, map_length, map_bits) = (u16_at(3), u16_at(5) as usize, fixed[7]);
            let (width, height, pixel_bits, descriptor) = (u16_at(12), u16_at(14), fixed[16], fixed[17]);
            let mut id = vec![0; id_length as usize];
            read_exactly(&mut input, &mut id, "Targa image ID")?;
            let text = String::from_utf8(id).ok().filter(|t| !t.is_empty());
            let palette = match (map_type, image_type, pixel_bits, map_bits, map_first, descriptor) {
                (0, 2, 24, _, _, TGA_TOP_DOWN) => None,
                (1, 1, 8, 24, 0, TGA_TOP_DOWN) if map_length <= 256 => {
                    let mut map = vec![0; map_length * 3];
                    read_exactly(&mut input, &mut map, "Targa colour map")?;
                    Some(map.chunks_exact(3).map(|e| [e[2], e[1], e[0]]).collect())
                }
                _ => return unsupported(format!("Targa image type {image_type}, {pixel_bits} bits, descriptor {descriptor:#x}: not one host-sim writes")),
            };
            let pixel_bytes = if palette.is_some() { 1 } else { 3 };
            (u32::from(width), u32::from(height), palette, text, pixel_bytes, 0)
        };
        if width == 0 || height == 0 {
            return invalid(format!("the image is {width}×{height} pixels"));
        }
        let bgr = palette.is_none();
        let stored = vec![0; width as usize * pixel_bytes + pad];
        let header = Header { width, height, palette, text };
        Ok(RowReader { header, decoder: RowDecoder::Raw { input, bgr, stored }, rows_left: height, row: Vec::new() })
    }

    fn png(input: std::io::BufReader<std::fs::File>) -> Result<RowReader, FormatError> {
        let decoding_error = |e| match e {
            png::DecodingError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                FormatError::Truncated("PNG file")
            }
            e => FormatError::Invalid(format!("malformed PNG file: {e}")),
        };
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
                    "PNG of {colour:?} colour at {} bits{}: not one host-sim writes",
                    depth as u8,
                    if interlaced { ", interlaced" } else { "" }
                ))
            }
        };
        let text = info.uncompressed_latin1_text.iter().find(|t| t.keyword == TEXT_KEYWORD).map(|t| t.text.clone());
        let header = Header { width: info.width, height: info.height, palette, text };
        Ok(RowReader { rows_left: header.height, header, decoder: RowDecoder::Png(Box::new(reader)), row: Vec::new() })
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
        match &mut self.decoder {
            RowDecoder::Png(reader) => {
                let row = reader.next_row().map_err(|e| match e {
                    png::DecodingError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                        FormatError::Truncated("PNG file")
                    }
                    e => FormatError::Invalid(format!("malformed PNG file: {e}")),
                })?;
                let row = row.ok_or(FormatError::Truncated("PNG image data"))?;
                self.row.clear();
                self.row.extend_from_slice(row.data());
            }
            RowDecoder::Raw { input, bgr, stored } => {
                read_exactly(input, stored, "pixels")?;
                self.row.clear();
                let width = self.header.width as usize;
                if *bgr {
                    self.row.extend(stored[..3 * width].chunks_exact(3).flat_map(|p| BGR.map(|i| p[i])));
                } else {
                    self.row.extend_from_slice(&stored[..width]);
                }
            }
        }
        if let Some(palette) = &self.header.palette {
            if let Some(index) = self.row.iter().find(|&&i| i as usize >= palette.len()) {
                return invalid(format!("index {index} is outside the {}-entry palette", palette.len()));
            }
        }
        Ok(&self.row)
    }
}

fn read_exactly(input: &mut impl std::io::Read, buffer: &mut [u8], part: &'static str) -> Result<(), FormatError> {
    input.read_exact(buffer).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => FormatError::Truncated(part),
        _ => FormatError::Io(e),
    })
}

/// Descriptor bit 5: the first row stored is the top one.
const TGA_TOP_DOWN: u8 = 0x20;
/// Descriptor bit 4: each row is stored right to left.
const TGA_RIGHT_TO_LEFT: u8 = 0x10;

fn tga_header(header: &Header) -> Result<Vec<u8>, FormatError> {
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
    out.extend([pixel_bits, TGA_TOP_DOWN]);
    out.extend(id);
    out.extend(map);
    Ok(out)
}

fn read_tga(bytes: &[u8]) -> Result<Image, FormatError> {
    let mut input = bytes;
    let header = take(&mut input, 18, "Targa header")?;
    let u16_at = |i: usize| u16::from_le_bytes([header[i], header[i + 1]]);
    let [id_length, map_type, image_type] = [header[0], header[1], header[2]];
    let (map_first, map_length, map_bits) = (u16_at(3), u16_at(5) as usize, header[7]);
    let (width, height, pixel_bits, descriptor) = (u16_at(12), u16_at(14), header[16], header[17]);
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
        unpack_tga(input, count, pixel_bytes)?
    } else {
        take(&mut input, count.saturating_mul(pixel_bytes), "Targa pixels")?.to_vec()
    };
    let pixels = orient(&stored, width as usize, pixel_bytes, descriptor);
    let (width, height) = (u32::from(width), u32::from(height));
    if !mapped {
        return Ok(Image::Rgb(RgbImage { width, height, data: pick(&pixels, pixel_bytes, BGR) }));
    }
    let palette = map.chunks_exact(map_entry_bytes).map(|e| [e[2], e[1], e[0]]).collect();
    // Pixel values count from the map's first entry.
    let index = |&value: &u8| match u16::from(value).checked_sub(map_first) {
        Some(index) => Ok(index as u8),
        None => invalid(format!("Targa pixel value {value} is below the colour map's first entry {map_first}")),
    };
    let indices = pixels.iter().map(index).collect::<Result<_, _>>()?;
    Ok(Image::Indexed { width, height, palette, indices })
}

/// Targa run-length packets expanded to `count` pixels of `pixel_bytes` each.
fn unpack_tga(mut input: &[u8], count: usize, pixel_bytes: usize) -> Result<Vec<u8>, FormatError> {
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
    let (top_down, right_to_left) = (descriptor & TGA_TOP_DOWN != 0, descriptor & TGA_RIGHT_TO_LEFT != 0);
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

const RAS_MAGIC: u32 = 0x59a6_6a95;
const RT_OLD: u32 = 0;
const RT_STANDARD: u32 = 1;
const RT_BYTE_ENCODED: u32 = 2;
const RT_FORMAT_RGB: u32 = 3;
const RMT_NONE: u32 = 0;
const RMT_EQUAL_RGB: u32 = 1;
/// The escape byte of RT_BYTE_ENCODED data.
const RAS_RUN: u8 = 0x80;

fn ras_header(header: &Header) -> Result<Vec<u8>, FormatError> {
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
    let fields = [RAS_MAGIC, width, height, depth, length, RT_STANDARD, map_type, map.len() as u32];
    let mut out: Vec<u8> = fields.into_iter().flat_map(u32::to_be_bytes).collect();
    out.extend(map);
    Ok(out)
}

fn read_ras(bytes: &[u8]) -> Result<Image, FormatError> {
    let mut input = bytes;
    let header = take(&mut input, 32, "Sun raster header")?;
    let field = |i: usize| u32::from_be_bytes([header[4 * i], header[4 * i + 1], header[4 * i + 2], header[4 * i + 3]]);
    let [width, height, depth, _length, kind, map_type, map_length] = std::array::from_fn(|i| field(i + 1));
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
    let stored_row = row.saturating_add(row % 2);
    let size = stored_row.saturating_mul(height as usize);
    let stored = match kind {
        RT_OLD | RT_STANDARD | RT_FORMAT_RGB => Cow::Borrowed(take(&mut input, size, "Sun raster pixels")?),
        RT_BYTE_ENCODED => Cow::Owned(unpack_ras(input, size)?),
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
    let entries = map.len() / 3;
    let palette = (0..entries).map(|i| [map[i], map[entries + i], map[2 * entries + i]]).collect();
    Ok(Image::Indexed { width, height, palette, indices: pixels })
}

/// RT_BYTE_ENCODED data expanded to `size` bytes: `0x80 n v` is n + 1 copies of v, `0x80 0` one 0x80.
fn unpack_ras(mut input: &[u8], size: usize) -> Result<Vec<u8>, FormatError> {
    // No run (three bytes) expands to more than 256 bytes.
    if size > input.len().saturating_mul(86) {
        return Err(FormatError::Truncated("Sun raster run-length data"));
    }
    let mut out = Vec::with_capacity(size);
    while out.len() < size {
        let byte = take(&mut input, 1, "Sun raster run-length data")?[0];
        if byte != RAS_RUN {
            out.push(byte);
            continue;
        }
        match take(&mut input, 1, "Sun raster run-length data")?[0] {
            0 => out.push(RAS_RUN),
            n => {
                let value = take(&mut input, 1, "Sun raster run-length data")?[0];
                out.resize(out.len() + n as usize + 1, value);
            }
        }
    }
    out.truncate(size);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FORMATS: [Format; 3] = [Format::Png, Format::Tga, Format::Ras];

    fn rgb(width: u32, height: u32) -> Image {
        let data = (0..width * height * 3).map(|i| (i * 37 + 11) as u8).collect();
        Image::Rgb(RgbImage { width, height, data })
    }

    fn indexed(width: u32, height: u32, entries: usize) -> Image {
        let palette = (0..entries).map(|i| [i as u8, (i * 7 + 1) as u8, 255 - (i * 3) as u8]).collect();
        let indices = (0..width as usize * height as usize).map(|i| ((i * 5 + 3) % entries) as u8).collect();
        Image::Indexed { width, height, palette, indices }
    }

    fn samples() -> Vec<Image> {
        let sizes = [(1, 1), (3, 2), (7, 5)];
        let mut images: Vec<Image> = sizes.iter().flat_map(|&(w, h)| [rgb(w, h), indexed(w, h, 12)]).collect();
        images.extend([indexed(1, 1, 1), indexed(16, 16, 256), indexed(5, 3, 256)]);
        images
    }

    fn encode(image: &Image, format: Format) -> Vec<u8> {
        let mut bytes = Vec::new();
        write(image, format, &mut bytes).unwrap();
        bytes
    }

    #[test]
    fn every_format_round_trips_truecolour_and_indexed_images() {
        for format in FORMATS {
            for image in samples() {
                let back = read(&encode(&image, format));
                assert_eq!(back.as_ref().ok(), Some(&image), "{} {}×{}", format.name(), image.width(), image.height());
            }
        }
    }

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
    fn written_targas_decode_with_the_image_crate() {
        for image in samples() {
            let bytes = encode(&image, Format::Tga);
            let decoded = ::image::load_from_memory_with_format(&bytes, ::image::ImageFormat::Tga).unwrap().to_rgb8();
            assert_eq!(decoded.dimensions(), (image.width(), image.height()));
            assert_eq!(decoded.into_raw(), image.to_rgb().data);
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
            let decoded = ::image::load_from_memory_with_format(&bytes, ::image::ImageFormat::Tga).unwrap();
            assert_eq!(decoded.to_rgb8().into_raw(), image.to_rgb().data);
        }
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
            let decoded = ::image::load_from_memory_with_format(&bytes, ::image::ImageFormat::Tga).unwrap();
            assert_eq!(decoded.to_rgb8().into_raw(), image.to_rgb().data);
        }
    }

    #[test]
    fn sun_rasters_store_bgr_rows_padded_to_even_lengths() {
        let image = rgb(1, 2);
        let bytes = encode(&image, Format::Ras);
        let field = |i: usize| u32::from_be_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap());
        assert_eq!((0..8).map(field).collect::<Vec<_>>(), [RAS_MAGIC, 1, 2, 24, 8, RT_STANDARD, RMT_NONE, 0]);
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

    #[test]
    fn invalid_images_are_not_written() {
        let message = |image: &Image, format| write(image, format, &mut Vec::new()).unwrap_err().to_string();
        for format in FORMATS {
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
        assert_eq!(message(&[]), "truncated Targa header");
        assert_eq!(message(&RAS_MAGIC.to_be_bytes()), "truncated Sun raster header");
        assert_eq!(message(PNG_SIGNATURE), "truncated PNG file");
        let mut tga = encode(&rgb(3, 2), Format::Tga);
        tga[2] = 3;
        assert_eq!(message(&tga), "Targa image type 3 is not supported");
        tga[2] = 2;
        tga[12..16].copy_from_slice(&[0xff; 4]);
        assert_eq!(message(&tga), "truncated Targa pixels");
        tga[2] = 10;
        assert_eq!(message(&tga), "truncated Targa run-length data");

        let mut ras = encode(&indexed(3, 2, 12), Format::Ras);
        ras[32 + 36 + 1] = 12;
        assert_eq!(message(&ras), "index 12 is outside the 12-entry palette");
        ras[4..12].copy_from_slice(&[0xff; 8]);
        assert_eq!(message(&ras), "truncated Sun raster pixels");
        ras[23] = RT_BYTE_ENCODED as u8;
        assert_eq!(message(&ras), "truncated Sun raster run-length data");
        ras[23] = 5;
        assert_eq!(message(&ras), "Sun raster type 5 is not supported");
        ras[28..32].copy_from_slice(&[0xff; 4]);
        assert_eq!(message(&ras), "truncated Sun raster colour map");

        let mut huge = Vec::new();
        let mut encoder = png::Encoder::new(&mut huge, 1 << 20, 1 << 20);
        encoder.set_color(png::ColorType::Rgb);
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
        for format in FORMATS {
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
    fn rows_read_back_with_their_text() {
        let dir = std::env::temp_dir().join(format!("octrace-rows-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for format in FORMATS {
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
            }
        }
        let header = Header { width: 1, height: 1, palette: None, text: Some("t".into()) };
        assert!(RowWriter::new(Format::Ras, &header, &mut Vec::new()).is_err(), "a Sun raster has no room for text");
        let mut sink = std::io::sink();
        let mut writer = RowWriter::new(Format::Png, &Header { text: None, ..header }, &mut sink).unwrap();
        assert!(writer.write_row(&[0; 4]).is_err(), "a row of the wrong length");
        std::fs::remove_dir_all(&dir).unwrap();
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
