//! `host-sim convert`: an image between PNG, Targa and Sun raster, its
//! pixels kept (an animated PNG, a transparent pixel, or OUT the input
//! itself refused).

use crate::arguments::{output_format, same_file};
use crate::exit::{CliError, ShownPath};
use crate::output::write_atomically;
use octrace_images::formats::{self, Format};
use std::path::Path;

/// Converts the image `input` into `output`.
pub(crate) fn run(input: &Path, output: &Path, format: Option<Format>) -> Result<(), CliError> {
    let format = output_format(format, output)?;
    let bytes = std::fs::read(input).map_err(|e| CliError::read(input, e))?;
    // Converted in place, a file would lose what only its own format holds
    // (octrace's metadata, which merge reads) for nothing.
    if same_file(input, output) {
        return Err(CliError::Invalid(format!(
            "convert: refusing to write over {}, the file it converts: name another OUT",
            ShownPath(input)
        )));
    }
    if let Some(frames) = animated_png_frames(&bytes) {
        return Err(CliError::Invalid(format!(
            "{}: an animated PNG of {frames} frames; convert takes still images (host-sim writes an animation's \
             frames one file each with OUT 'f%04d.png')",
            ShownPath(input)
        )));
    }
    let image = formats::read(&bytes).map_err(|e| CliError::Invalid(format!("{}: {e}", ShownPath(input))))?;
    write_atomically(output, |f| formats::write(&image, format, f).map_err(std::io::Error::other))
        .map_err(|e| CliError::write(output, e))
}

/// The frames of an animated PNG (an `acTL` chunk with more than one);
/// `None` for anything else.
fn animated_png_frames(bytes: &[u8]) -> Option<u32> {
    let reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().ok()?;
    reader.info().animation_control().map(|control| control.num_frames).filter(|&frames| frames > 1)
}
