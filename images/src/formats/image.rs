//! What every format shares: the formats' names, an image as a file holds
//! it, what a file says before its rows, and the checks that every image
//! written or read passes (not empty, its data as long as its size says, at
//! most 256 colours, every index inside the table).

use super::error::invalid;
use super::FormatError;
use crate::RgbImage;
use std::path::Path;

/// An image file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    Png,
    Tga,
    Ras,
}

impl Format {
    /// Every format.
    pub const ALL: [Format; 3] = [Format::Png, Format::Tga, Format::Ras];

    /// The format named by `path`'s extension (png, tga or ras, any case).
    pub fn from_path(path: &Path) -> Option<Format> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        Format::ALL.into_iter().find(|f| f.name() == extension)
    }

    /// The format's usual file name extension, which also names it.
    pub fn name(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Tga => "tga",
            Format::Ras => "ras",
        }
    }

    /// The format's name in prose.
    pub fn title(self) -> &'static str {
        match self {
            Format::Png => "PNG",
            Format::Tga => "Targa",
            Format::Ras => "Sun raster",
        }
    }

    /// Every format's title, as a sentence lists them ("PNG, Targa or Sun
    /// raster"), so that a message naming them all follows [`Format::ALL`].
    pub fn any_title() -> String {
        let [rest @ .., last] = Format::ALL.map(Format::title);
        match &rest[..] {
            [] => last.into(),
            _ => format!("{} or {last}", rest.join(", ")),
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

impl Header {
    /// Bytes a pixel takes in a row: 3 (RGB) or 1 (an index).
    pub(crate) fn bytes_per_pixel(&self) -> usize {
        if self.palette.is_some() {
            1
        } else {
            3
        }
    }
}

/// The keyword of the PNG `tEXt` chunk that carries [`Header::text`].
pub const TEXT_KEYWORD: &str = "octrace";

/// Why a file is read as none of the formats: it is not one of them.
pub(super) fn not_an_image() -> FormatError {
    FormatError::Unsupported(format!("not a {} image", Format::any_title()))
}

/// Fails unless `image` is one every format can hold: not empty, the data as long as the size says, at most
/// 256 palette entries and every index inside the palette.
pub(super) fn check(image: &Image) -> Result<(), FormatError> {
    let (width, height) = (image.width(), image.height());
    check_size(width, height)?;
    let (length, per_pixel) = match image {
        Image::Rgb(rgb) => (rgb.data.len(), 3),
        Image::Indexed { indices, .. } => (indices.len(), 1),
    };
    if length as u64 != u64::from(width) * u64::from(height) * per_pixel {
        return invalid(format!("{length} bytes of pixel data for a {width}×{height} image"));
    }
    if let Image::Indexed { palette, indices, .. } = image {
        check_palette_length(palette)?;
        check_indices(indices, palette)?;
    }
    Ok(())
}

/// Fails for an image without pixels.
pub(super) fn check_size(width: u32, height: u32) -> Result<(), FormatError> {
    if width == 0 || height == 0 {
        return invalid(format!("the image is {width}×{height} pixels"));
    }
    Ok(())
}

/// Fails for a colour table no format holds (more than 256 entries).
pub(super) fn check_palette_length(palette: &[[u8; 3]]) -> Result<(), FormatError> {
    if palette.len() > 256 {
        return invalid(format!("palette has {} entries, at most 256", palette.len()));
    }
    Ok(())
}

/// Fails for an index past the end of `palette`.
pub(super) fn check_indices(indices: &[u8], palette: &[[u8; 3]]) -> Result<(), FormatError> {
    if let Some(index) = indices.iter().find(|&&i| i as usize >= palette.len()) {
        return invalid(format!("index {index} is outside the {}-entry palette", palette.len()));
    }
    Ok(())
}
