//! Reading a file's bytes: a part of the given length or a `Truncated`
//! error naming it, stored pixels picked apart into RGB, and their alpha
//! checked opaque.

use super::FormatError;

/// The first `n` bytes of `input`, which moves past them.
pub(super) fn take<'a>(input: &mut &'a [u8], n: usize, part: &'static str) -> Result<&'a [u8], FormatError> {
    let (head, rest) = input.split_at_checked(n).ok_or(FormatError::Truncated(part))?;
    *input = rest;
    Ok(head)
}

/// Refuses an image with a transparent pixel, `alpha` being every pixel's
/// alpha in reading order and `what` the file as a user knows it: no format
/// here holds transparency, and dropping it would change the picture. An
/// alpha channel that says every pixel is opaque loses nothing.
pub(super) fn opaque(mut alpha: impl Iterator<Item = u8>, width: u32, what: &str) -> Result<(), FormatError> {
    match alpha.position(|a| a != u8::MAX) {
        None => Ok(()),
        Some(i) => Err(FormatError::Unsupported(format!(
            "{what} with transparent pixels (the first at x {}, y {}): host-sim keeps every pixel as it is, and \
             its formats hold no transparency",
            i % width as usize,
            i / width as usize
        ))),
    }
}

/// Pixels of `pixel_bytes` bytes each, red, green and blue at `offsets` in each, as RGB (or, as the
/// offsets are their own inverse, RGB as BGR); other bytes (alpha, padding) are dropped.
pub(super) fn pick(pixels: &[u8], pixel_bytes: usize, offsets: [usize; 3]) -> Vec<u8> {
    pixels.chunks_exact(pixel_bytes).flat_map(|p| offsets.map(|i| p[i])).collect()
}

/// Where red, green and blue sit in a stored Targa or Sun raster pixel.
pub(super) const BGR: [usize; 3] = [2, 1, 0];
/// Where they sit in a PNG's RGBA pixel.
pub(super) const RGB: [usize; 3] = [0, 1, 2];

pub(super) fn read_exactly(
    input: &mut impl std::io::Read,
    buffer: &mut [u8],
    part: &'static str,
) -> Result<(), FormatError> {
    input.read_exact(buffer).map_err(|e| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => FormatError::Truncated(part),
        _ => FormatError::Io(e),
    })
}
