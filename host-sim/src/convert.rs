//! `host-sim convert`: an image between PNG, Targa and Sun raster, its
//! pixels kept (an animated PNG, a transparent pixel, or OUT the input
//! itself refused), and octrace's metadata of a part or a frame with them
//! where the format holds it (PNG, Targa: the file still merges).

use crate::arguments::{output_format, same_file};
use crate::exit::{CliError, ShownPath};
use crate::output::write_atomically;
use octrace_images::formats::{self, Format, RowReader};
use std::io::Write;
use std::path::Path;

/// Converts the image `input` into `output`.
pub(crate) fn run(input: &Path, output: &Path, format: Option<Format>, stderr: &mut dyn Write) -> Result<(), CliError> {
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
    // A part's or a frame's metadata, which merge reads (the files octrace
    // writes are the ones RowReader reads).
    let text = std::fs::File::open(input).ok().and_then(|file| RowReader::new(file).ok()?.header().text.clone());
    let text = match (text, format) {
        (Some(_), Format::Ras) => {
            let _ = writeln!(
                stderr,
                "host-sim: {} carries octrace's metadata (a part's or a frame's), which a Sun raster cannot: \
                 {} holds the pixels alone, and merge will not take it",
                ShownPath(input),
                ShownPath(output)
            );
            None
        }
        (text, _) => text,
    };
    write_atomically(output, |f| formats::write_with_text(&image, text, format, f).map_err(std::io::Error::other))
        .map_err(|e| CliError::write(output, e))
}

/// The frames of an animated PNG (an `acTL` chunk with more than one);
/// `None` for anything else.
fn animated_png_frames(bytes: &[u8]) -> Option<u32> {
    let reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().ok()?;
    reader.info().animation_control().map(|control| control.num_frames).filter(|&frames| frames > 1)
}
