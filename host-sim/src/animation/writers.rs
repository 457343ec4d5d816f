//! Where an animation's frames go: an animated GIF (`gif.rs`), an APNG
//! (`apng.rs`) or one image file a frame named by a pattern
//! (`f%04d.png`), each frame file carrying what `host-sim merge` needs to
//! assemble frames rendered apart.
//!
//! Invariants: the frame files of a render and the animation made of them
//! by `merge` hold the very pixels (and indices) a direct render to the
//! animation writes; the GIF and APNG loop forever.

use crate::parts::{Fields, Render};
use octrace_core::scene::Frames;
use octrace_images::formats::{Format, FormatError, Header, Image, RowWriter};
use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where an animation goes, told from the output path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Output {
    /// `out.gif`.
    Gif,
    /// `out.png`: an animated PNG.
    Apng,
    /// One file a frame, `frames/f%04d.png` (PNG, Targa or Sun raster).
    Files(FramePattern),
}

impl Output {
    /// The output `path` names, written in `format` (`--format`, which
    /// only frame files choose: a GIF is a GIF, an APNG a PNG), or why it
    /// names none.
    pub fn of(path: &Path, format: Option<Format>) -> Result<Output, String> {
        let text = path.to_string_lossy();
        if text.contains('%') {
            return FramePattern::parse(&text).map(Output::Files);
        }
        let output = match path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).as_deref() {
            Some("gif") => Output::Gif,
            Some("png") => Output::Apng,
            _ => {
                return Err(format!(
                    "{text}: an animation is written as an animated GIF (.gif), an APNG (.png) or one file a frame \
                 (a name with %d, such as 'frames/f%04d.png'); --frame K renders one frame as a still image"
                ))
            }
        };
        match (format, &output) {
            (None | Some(Format::Png), Output::Apng) | (None, _) => Ok(output),
            (Some(format), _) => Err(format!(
                "--format {}: {text} is written as {}; --format chooses the format of frame files (a name with %d)",
                format.name(),
                if output == Output::Gif { "an animated GIF" } else { "an APNG" }
            )),
        }
    }
}

/// A file name with one frame number in it: `%d`, or `%0Nd` for N digits
/// (`%%` is a `%`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FramePattern {
    before: String,
    width: usize,
    after: String,
}

impl FramePattern {
    /// The pattern `text`, or why it is none.
    pub fn parse(text: &str) -> Result<FramePattern, String> {
        let refuse = || format!("{text}: a frame pattern holds one %d or %0Nd (and %% for a %)");
        let (mut before, mut rest, mut found) = (String::new(), text, None);
        while let Some(at) = rest.find('%') {
            before.push_str(&rest[..at]);
            let spec = &rest[at + 1..];
            if let Some(after) = spec.strip_prefix('%') {
                before.push('%');
                rest = after;
                continue;
            }
            let digits: String = spec.chars().take_while(|c| c.is_ascii_digit()).collect();
            let after = spec[digits.len()..].strip_prefix('d').ok_or_else(refuse)?;
            if found.is_some() || (!digits.is_empty() && !digits.starts_with('0')) {
                return Err(refuse());
            }
            let width = if digits.is_empty() { 0 } else { digits.parse().map_err(|_| refuse())? };
            found = Some((std::mem::take(&mut before), width));
            rest = after;
        }
        before.push_str(rest);
        let (head, width) = found.ok_or_else(refuse)?;
        Ok(FramePattern { before: head, width, after: before })
    }

    /// The file name of frame `frame`.
    pub fn name(&self, frame: u32) -> PathBuf {
        PathBuf::from(format!("{}{:0width$}{}", self.before, frame, self.after, width = self.width))
    }
}

/// What a frame file says about itself, for `host-sim merge`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameInfo {
    /// The render it is a frame of.
    pub render: Render,
    /// Frame `frame` of the animation's `frames`.
    pub frame: u32,
    pub frames: Frames,
}

const MAGIC: &str = "octrace-frame 1";

impl fmt::Display for FrameInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{MAGIC} {} frame={}/{} rate={}", self.render, self.frame, self.frames.count, self.frames.rate)
    }
}

impl FrameInfo {
    /// The text `Display` writes, read back; `None` for anything else.
    pub fn parse(text: &str) -> Option<FrameInfo> {
        let mut fields = Fields::after(text, MAGIC)?;
        let render = fields.render()?;
        let (frame, count) = fields.next("frame")?.split_once('/')?;
        let rate = fields.next("rate")?.parse().ok()?;
        let info =
            FrameInfo { render, frame: frame.parse().ok()?, frames: Frames { count: count.parse().ok()?, rate } };
        let valid = info.frame < info.frames.count && info.render.width > 0 && info.render.height > 0;
        (fields.end() && valid).then_some(info)
    }
}

/// Writes `image` as a `format` file carrying `info`.
pub fn write_frame_file(
    image: &Image,
    info: &FrameInfo,
    format: Format,
    out: &mut dyn Write,
) -> Result<(), FormatError> {
    let (palette, rows): (Option<Vec<[u8; 3]>>, &[u8]) = match image {
        Image::Indexed { palette, indices, .. } => (Some(palette.clone()), indices),
        Image::Rgb(rgb) => (None, &rgb.data),
    };
    let (width, height) = (info.render.width, info.render.height);
    let header = Header { width, height, palette, text: Some(info.to_string()) };
    let row = width as usize * header.palette.as_ref().map_or(3, |_| 1);
    let mut writer = RowWriter::new(format, &header, out)?;
    for chunk in rows.chunks(row) {
        writer.write_row(chunk)?;
    }
    writer.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use octrace_images::palette::PaletteMode;

    #[test]
    fn patterns() {
        let p = FramePattern::parse("frames/f%04d.png").unwrap();
        assert_eq!(p.name(7), PathBuf::from("frames/f0007.png"));
        assert_eq!(p.name(12345), PathBuf::from("frames/f12345.png"));
        assert_eq!(FramePattern::parse("a%d-100%%.tga").unwrap().name(3), PathBuf::from("a3-100%.tga"));
        for bad in ["f%4d.png", "f%d%d.png", "f%x.png", "f%%.png", "f%0.png"] {
            assert!(FramePattern::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(Output::of(Path::new("a.gif"), None), Ok(Output::Gif));
        assert_eq!(Output::of(Path::new("a.PNG"), None), Ok(Output::Apng));
        assert!(Output::of(Path::new("a.tga"), None).unwrap_err().contains("--frame K"));
        // --format chooses frame files' format; an animation's is its own.
        assert_eq!(Output::of(Path::new("a.png"), Some(Format::Png)), Ok(Output::Apng));
        assert!(Output::of(Path::new("a.gif"), Some(Format::Tga)).unwrap_err().contains("animated GIF"));
        assert!(Output::of(Path::new("a.png"), Some(Format::Tga)).unwrap_err().contains("an APNG"));
        assert!(matches!(Output::of(Path::new("f%d.tga"), Some(Format::Tga)), Ok(Output::Files(_))));
    }

    #[test]
    fn frame_info_reads_back() {
        let render =
            Render { version: "0.1.0".into(), scene: 0xabc, width: 4, height: 3, palette: PaletteMode::Dither };
        let info = FrameInfo { render, frame: 5, frames: Frames { count: 48, rate: 24 } };
        assert_eq!(FrameInfo::parse(&info.to_string()), Some(info.clone()));
        assert_eq!(FrameInfo::parse(&info.to_string().replace("5/48", "48/48")), None);
    }
}
