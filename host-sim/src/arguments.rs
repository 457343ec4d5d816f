//! The command line's values that more than one command reads: the names
//! of the vocabularies (accel, color, dither, palette, format), sizes, and the
//! image file to write (its format, and never the scene file itself).
//!
//! Invariant: every name is parsed from its vocabulary's own list (`ALL`
//! and `name`), so a new variant is accepted, and listed in the error,
//! without a change here.

use crate::exit::CliError;
use crate::exit::ShownPath;
use octrace_core::panel::Dithering;
use octrace_core::render::PanelColor;
use octrace_core::scene::MAX_SIDE;
use octrace_core::AccelMode;
use octrace_images::formats::Format;
use octrace_images::palette::PaletteMode;
use std::path::Path;

/// An `--accel` name: the core's [`AccelMode`] vocabulary.
pub(crate) fn parse_accel(text: &str) -> Result<AccelMode, String> {
    parse_name(text, &AccelMode::ALL, AccelMode::name)
}

/// A `--color` name: the core's [`PanelColor`] vocabulary.
pub(crate) fn parse_color(text: &str) -> Result<PanelColor, String> {
    parse_name(text, &PanelColor::ALL, PanelColor::name)
}

/// A `--dither` name: the core's [`Dithering`] vocabulary.
pub(crate) fn parse_dithering(text: &str) -> Result<Dithering, String> {
    parse_name(text, &Dithering::ALL, Dithering::name)
}

/// A `--palette` name: [`PaletteMode`]'s vocabulary.
pub(crate) fn parse_palette(text: &str) -> Result<PaletteMode, String> {
    parse_name(text, &PaletteMode::ALL, PaletteMode::name)
}

/// A `--format` name: [`Format`]'s vocabulary.
pub(crate) fn parse_format(text: &str) -> Result<Format, String> {
    parse_name(text, &Format::ALL, Format::name)
}

/// The one of `all` that `text` names (case-insensitive).
pub(crate) fn parse_name<T: Copy>(text: &str, all: &[T], name: fn(T) -> &'static str) -> Result<T, String> {
    all.iter().copied().find(|&v| name(v).eq_ignore_ascii_case(text)).ok_or_else(|| {
        let names: Vec<&str> = all.iter().map(|&v| name(v)).collect();
        format!("expected one of {}", names.join(", "))
    })
}

pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let expected = format!("expected WxH (for example 160x128), found `{s}`");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| expected.clone())?;
    let dim = |v: &str| -> Result<u32, String> {
        if v.is_empty() {
            return Err(format!("{expected}: a side is missing"));
        }
        if !v.bytes().all(|b| b.is_ascii_digit()) {
            return Err(format!("`{v}` is not a whole number"));
        }
        // Digits alone: too many for a u32 is out of range as well.
        match v.parse::<u32>() {
            Ok(n) if (1..=MAX_SIDE).contains(&n) => Ok(n),
            _ => Err(format!("{v} is outside 1 to {MAX_SIDE}")),
        }
    };
    Ok((dim(w)?, dim(h)?))
}

/// The format to write `path` in: the one asked for, else the one its
/// extension names, else (no extension) PNG. Any other extension is refused
/// before anything is rendered: a PNG named `.bmp` would mislead whatever
/// opens it, and so would a Targa named `.png`: `--format` names the format
/// of a file whose extension names none, and may not contradict one.
pub(crate) fn output_format(asked: Option<Format>, path: &Path) -> Result<Format, CliError> {
    let named = Format::from_path(path);
    if let Some(format) = asked {
        return match named {
            Some(named) if named != format => Err(CliError::Invalid(format!(
                "--format {}: {} names a {} file; give OUT a .{} name, or leave --format out",
                format.name(),
                ShownPath(path),
                named.name().to_ascii_uppercase(),
                format.name()
            ))),
            _ => Ok(format),
        };
    }
    let Some(extension) = path.extension() else {
        return Ok(Format::Png);
    };
    named.ok_or_else(|| {
        let names: Vec<&str> = Format::ALL.iter().map(|f| f.name()).collect();
        let extension = extension.to_string_lossy();
        let animated = match extension.eq_ignore_ascii_case("gif") {
            true => " (a GIF holds a whole animation: a scene with FRAMES, rendered without --frame, to one file)",
            false => "",
        };
        CliError::Invalid(format!(
            "{}: `.{extension}` is not a format host-sim writes a still image in{animated}; it writes {} \
             (chosen by the extension, or by --format <{}>)",
            ShownPath(path),
            names.join(", "),
            names.join("|"),
        ))
    })
}

/// Refuses an image path `out` that names the scene file `scene` (itself,
/// through `..` or through a link): writing it would destroy the scene.
pub(crate) fn not_the_scene(scene: &Path, out: &Path) -> Result<(), CliError> {
    if !same_file(scene, out) {
        return Ok(());
    }
    let through = match out == scene {
        true => String::new(),
        false => format!(" (which {} names)", ShownPath(out)),
    };
    Err(CliError::Invalid(format!("refusing to overwrite the scene file {}{through} with the image", ShownPath(scene))))
}

/// Whether two paths name the same existing file.
pub(crate) fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("160x128"), Ok((160, 128)));
        assert_eq!(parse_size("8X8"), Ok((8, 8)));
        assert!(parse_size("0x5").is_err());
        assert!(parse_size("12").is_err());
        assert!(parse_size("20000x5").is_err());
        // A whole number past u32 is out of range too, not "not a whole number".
        assert_eq!(parse_size("4294967296x1"), Err(format!("4294967296 is outside 1 to {MAX_SIDE}")));
        assert_eq!(parse_size("3x"), Err("expected WxH (for example 160x128), found `3x`: a side is missing".into()));
        assert_eq!(parse_size("3x-4"), Err("`-4` is not a whole number".into()));
    }
}
