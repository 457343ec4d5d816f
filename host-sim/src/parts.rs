//! Rendering an image in horizontal bands ("parts") on many machines, and merging the parts back.
//!
//! Invariants: part I of N holds the rows `(I−1)·H/N .. I·H/N` of the whole image (rounded down), so the
//! parts of one N cover every row once and differ by at most one row. Each part file carries a line of
//! text (PNG `tEXt`, Targa image ID) naming the scene (a hash of its bytes), the whole image's size, the
//! palette mode and the part's rows; `merge` trusts nothing else and refuses parts that do not fit.

use crate::exit::ShownPath;
use octrace_images::formats::{Format, FormatError, Header, RowReader, RowWriter};
use octrace_images::palette::PaletteMode;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Which part to render: `I/N`, or `auto/N` with I from the scheduler's environment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PartSpec {
    /// 1-based; `None` for `auto`.
    pub index: Option<u32>,
    pub count: u32,
}

impl std::str::FromStr for PartSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<PartSpec, String> {
        let (index, count) = s.split_once('/').ok_or_else(|| format!("expected I/N or auto/N, found `{s}`"))?;
        let count: u32 = count.parse().map_err(|_| format!("N in `{s}` is not a whole number"))?;
        if count == 0 {
            return Err("N must be at least 1".into());
        }
        let index = match index {
            "auto" => None,
            i => {
                let i: u32 = i.parse().map_err(|_| format!("I in `{s}` is neither a whole number nor `auto`"))?;
                if !(1..=count).contains(&i) {
                    return Err(format!("part {i} of {count}: I counts from 1 to N"));
                }
                Some(i)
            }
        };
        Ok(PartSpec { index, count })
    }
}

/// Why `auto/N` found no part number.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AutoError {
    /// Neither SLURM_ARRAY_TASK_ID nor JOB_COMPLETION_INDEX is set.
    Unset,
    /// The variable `name` holds `value`, which is not a whole number.
    NotANumber { name: &'static str, value: String },
    /// The variable gives part `index` (1-based, possibly ≤ 0), outside 1 to N.
    OutOfRange { name: &'static str, value: String, index: i64, count: u32 },
}

impl fmt::Display for AutoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AutoError::Unset => f.write_str(
                "--part auto/N takes the part from SLURM_ARRAY_TASK_ID (a Slurm job array) or \
                 JOB_COMPLETION_INDEX (a Kubernetes Indexed Job), and neither is set; give I/N instead",
            ),
            AutoError::NotANumber { name, value } => write!(f, "{name}=`{value}` is not a whole number"),
            AutoError::OutOfRange { name, value, index, count } => {
                write!(f, "{name}={value} makes this part {index} of {count}, outside 1 to {count}")
            }
        }
    }
}

impl std::error::Error for AutoError {}

/// The 1-based part `auto/count` stands for, from the environment `var`: SLURM_ARRAY_TASK_ID counted from
/// SLURM_ARRAY_TASK_MIN (from 1 when that is not set), else JOB_COMPLETION_INDEX counted from 0.
pub fn auto_index(count: u32, var: impl Fn(&str) -> Option<String>) -> Result<u32, AutoError> {
    let number = |name: &'static str, value: &str| -> Result<i64, AutoError> {
        value.trim().parse().map_err(|_| AutoError::NotANumber { name, value: value.to_owned() })
    };
    let (name, value, index) = if let Some(value) = var("SLURM_ARRAY_TASK_ID") {
        let id = number("SLURM_ARRAY_TASK_ID", &value)?;
        let index = match var("SLURM_ARRAY_TASK_MIN") {
            Some(min) => id - number("SLURM_ARRAY_TASK_MIN", &min)? + 1,
            None => id,
        };
        ("SLURM_ARRAY_TASK_ID", value, index)
    } else if let Some(value) = var("JOB_COMPLETION_INDEX") {
        let index = number("JOB_COMPLETION_INDEX", &value)?.saturating_add(1);
        ("JOB_COMPLETION_INDEX", value, index)
    } else {
        return Err(AutoError::Unset);
    };
    match u32::try_from(index) {
        Ok(i) if (1..=count).contains(&i) => Ok(i),
        _ => Err(AutoError::OutOfRange { name, value, index, count }),
    }
}

/// The rows of part `index` (1-based) of `count` of an image `height` rows high: as even as possible,
/// the larger parts last.
pub fn band_rows(height: u32, index: u32, count: u32) -> Range<u32> {
    let edge = |i: u32| (u64::from(height) * u64::from(i) / u64::from(count.max(1))) as u32;
    edge(index - 1)..edge(index)
}

/// A 64-bit FNV-1a hash: enough to tell scenes apart, not to resist forgery.
pub fn scene_hash(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &b| (hash ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// What a part file says about itself.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartInfo {
    /// The render it is a part of (its size the whole image's).
    pub render: Render,
    /// This part's rows of the whole image.
    pub rows: Range<u32>,
    /// Part `index` of `count` (1-based).
    pub index: u32,
    pub count: u32,
    /// The animation's frame it is a band of (`--frame K`); `None` for a
    /// still's.
    pub frame: Option<u32>,
}

/// The text every part's line starts with (and the version of the line's layout).
const MAGIC: &str = "octrace-part 1";

impl fmt::Display for PartInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{MAGIC} {} rows={}..{} part={}/{}",
            self.render, self.rows.start, self.rows.end, self.index, self.count
        )?;
        match self.frame {
            Some(frame) => write!(f, " frame={frame}"),
            None => Ok(()),
        }
    }
}

impl PartInfo {
    /// The text [`PartInfo`]'s `Display` writes, read back; `None` for anything else.
    pub fn parse(text: &str) -> Option<PartInfo> {
        let mut fields = Fields::after(text, MAGIC)?;
        let render = fields.render()?;
        let (start, end) = fields.next("rows")?.split_once("..")?;
        let (index, count) = fields.next("part")?.split_once('/')?;
        let info = PartInfo {
            render,
            rows: start.parse().ok()?..end.parse().ok()?,
            index: index.parse().ok()?,
            count: count.parse().ok()?,
            // Last, and only in a band of an animation's frame.
            frame: match fields.0.next() {
                Some(field) => Some(field.strip_prefix("frame=")?.parse().ok()?),
                None => None,
            },
        };
        let valid = info.index >= 1
            && info.index <= info.count
            && info.rows == band_rows(info.render.height, info.index, info.count)
            && !info.rows.is_empty()
            && info.render.width > 0;
        (fields.end() && valid).then_some(info)
    }
}

/// What every piece of a render split across machines says first: who
/// rendered what, how large, in which palette.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Render {
    /// The host-sim version that rendered it: another version may give other bits.
    pub version: String,
    /// [`scene_hash`] of the scene file's bytes.
    pub scene: u64,
    /// The whole image's size.
    pub width: u32,
    pub height: u32,
    pub palette: PaletteMode,
}

impl fmt::Display for Render {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Render { version, scene, width, height, palette } = self;
        write!(f, "version={version} scene={scene:016x} size={width}x{height} palette={}", palette.name())
    }
}

impl Render {
    /// How a file of this render differs from one of `first`, as a merge
    /// refuses it: another host-sim version, scene, size or palette
    /// (`None`: none of them).
    pub(crate) fn difference(&self, first: &Render) -> Option<String> {
        Some(if self.version != first.version {
            format!("rendered by host-sim {} and {}, which may give other bits", self.version, first.version)
        } else if self.scene != first.scene {
            format!("another scene (scene hash {:016x}, not {:016x})", self.scene, first.scene)
        } else if (self.width, self.height) != (first.width, first.height) {
            format!("another size ({}×{}, not {}×{})", self.width, self.height, first.width, first.height)
        } else if self.palette != first.palette {
            format!("another palette (--palette {}, not {})", self.palette.name(), first.palette.name())
        } else {
            return None;
        })
    }
}

/// The `name=value` fields of a metadata line after its magic words, read
/// in order.
pub(crate) struct Fields<'a>(std::str::Split<'a, char>);

impl<'a> Fields<'a> {
    /// The fields of `text`, if it starts with `magic` and a space.
    pub(crate) fn after(text: &'a str, magic: &str) -> Option<Fields<'a>> {
        Some(Fields(text.strip_prefix(magic)?.strip_prefix(' ')?.split(' ')))
    }

    /// The next field's value, if it is `name`'s.
    pub(crate) fn next(&mut self, name: &str) -> Option<&'a str> {
        self.0.next()?.strip_prefix(name)?.strip_prefix('=')
    }

    /// `version`, `scene`, `size` and `palette`.
    pub(crate) fn render(&mut self) -> Option<Render> {
        let version = self.next("version")?.to_owned();
        let scene = u64::from_str_radix(self.next("scene")?, 16).ok()?;
        let (width, height) = self.next("size")?.split_once('x')?;
        let palette_name = self.next("palette")?;
        let palette = PaletteMode::ALL.into_iter().find(|m| m.name() == palette_name)?;
        Some(Render { version, scene, width: width.parse().ok()?, height: height.parse().ok()?, palette })
    }

    /// Whether no field is left.
    pub(crate) fn end(mut self) -> bool {
        self.0.next().is_none()
    }
}

/// Why parts could not be merged.
#[derive(Debug)]
pub enum MergeError {
    /// A part could not be read (exit code 1).
    Io { path: PathBuf, error: FormatError },
    /// The parts do not make one image (exit code 2): the message names the files.
    Refused(String),
    /// The merged image could not be written (exit code 1).
    Output(FormatError),
}

impl fmt::Display for MergeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MergeError::Io { path, error } => write!(f, "{}: {error}", ShownPath(path)),
            MergeError::Refused(why) => f.write_str(why),
            MergeError::Output(error) => write!(f, "the merged image: {error}"),
        }
    }
}

impl std::error::Error for MergeError {}

fn open(path: &Path) -> Result<RowReader, MergeError> {
    let file = std::fs::File::open(path).map_err(|e| MergeError::Io { path: path.to_owned(), error: e.into() })?;
    RowReader::new(file).map_err(|error| unreadable(path, error))
}

/// A part that could not be read: the system's failure, or what is in it.
fn unreadable(path: &Path, error: FormatError) -> MergeError {
    match error {
        FormatError::Io(_) => MergeError::Io { path: path.to_owned(), error },
        e => MergeError::Refused(format!("{}: not an image host-sim can merge: {e}", ShownPath(path))),
    }
}

fn rows(r: &Range<u32>) -> String {
    format!("rows {}..{}", r.start, r.end)
}

/// Reads and checks every part, returning them ordered top to bottom with the merged image's header.
pub fn check_parts(parts: &[PathBuf]) -> Result<(Vec<(PathBuf, PartInfo)>, Header), MergeError> {
    if parts.is_empty() {
        return Err(MergeError::Refused("no parts to merge".into()));
    }
    let mut found: Vec<(PathBuf, PartInfo, Header)> = Vec::new();
    for path in parts {
        let reader = open(path)?;
        let header = reader.header().clone();
        let name = ShownPath(path);
        let info = match header.text.as_deref() {
            None => return Err(MergeError::Refused(format!("{name}: not a part (no octrace part metadata in it)"))),
            Some(text) => PartInfo::parse(text)
                .ok_or_else(|| MergeError::Refused(format!("{name}: unreadable part metadata `{text}`")))?,
        };
        if (header.width, header.height) != (info.render.width, info.rows.len() as u32)
            || header.palette.is_some() != (info.render.palette != PaletteMode::None)
        {
            return Err(MergeError::Refused(format!(
                "{name}: the image ({}×{}, {}) does not match its metadata ({}×{} for {}, palette {})",
                header.width,
                header.height,
                if header.palette.is_some() { "indexed" } else { "truecolour" },
                info.render.width,
                info.rows.len(),
                rows(&info.rows),
                info.render.palette.name()
            )));
        }
        if let Some((first, first_info, _)) = found.first() {
            let other = || format!("{name} and {} are not parts of one render:", ShownPath(first));
            if let Some(difference) = info.render.difference(&first_info.render) {
                return Err(MergeError::Refused(format!("{} {difference}", other())));
            }
            if info.frame != first_info.frame {
                let frame = |frame: Option<u32>| frame.map_or("no frame (a still)".into(), |k| format!("frame {k}"));
                return Err(MergeError::Refused(format!(
                    "{} another frame of the animation ({}, not {})",
                    other(),
                    frame(info.frame),
                    frame(first_info.frame)
                )));
            }
        }
        found.push((path.clone(), info, header));
    }
    found.sort_by_key(|(_, info, _)| (info.rows.start, info.rows.end));
    let (width, height) = (found[0].1.render.width, found[0].1.render.height);
    // Every row once: each part starts where the one above ended.
    let mut end = 0;
    let mut above: Option<&(PathBuf, PartInfo, Header)> = None;
    for part in &found {
        let (path, info, _) = part;
        if info.rows.start > end {
            return Err(MergeError::Refused(missing(&found, end..info.rows.start, above.map(|a| &a.0), Some(path))));
        }
        if let Some((above_path, above_info, _)) = above.filter(|_| info.rows.start < end) {
            let what = if above_info.rows == info.rows { "the same band" } else { "overlapping bands" };
            return Err(MergeError::Refused(format!(
                "{} (part {}/{}, {}) and {} (part {}/{}, {}) are {what}",
                ShownPath(above_path),
                above_info.index,
                above_info.count,
                rows(&above_info.rows),
                ShownPath(path),
                info.index,
                info.count,
                rows(&info.rows)
            )));
        }
        end = info.rows.end;
        above = Some(part);
    }
    if end < height {
        return Err(MergeError::Refused(missing(&found, end..height, above.map(|a| &a.0), None)));
    }
    // The parts' colour tables are cut after their last entry in use: all
    // are beginnings of the same table, the whole image's is the longest.
    let palettes: Vec<(&PathBuf, &Vec<[u8; 3]>)> =
        found.iter().filter_map(|(path, _, header)| Some(path).zip(header.palette.as_ref())).collect();
    let palette = palettes.iter().max_by_key(|(_, p)| p.len()).map(|(path, longest)| {
        match palettes.iter().find(|(_, p)| !longest.starts_with(p)) {
            Some((other, _)) => Err(MergeError::Refused(format!(
                "{} and {} have different colour tables: not parts of one render",
                ShownPath(other),
                ShownPath(path)
            ))),
            None => Ok((*longest).clone()),
        }
    });
    let palette = palette.transpose()?;
    let header = Header { width, height, palette, text: None };
    Ok((found.into_iter().map(|(path, info, _)| (path, info)).collect(), header))
}

/// The message for rows no part holds, between the parts `above` and `below` (if any).
fn missing(
    found: &[(PathBuf, PartInfo, Header)],
    gap: Range<u32>,
    above: Option<&PathBuf>,
    below: Option<&PathBuf>,
) -> String {
    let count = found[0].1.count;
    let mut message = format!("{} of the image are in no part", rows(&gap));
    if found.iter().all(|(_, info, _)| info.count == count) {
        let absent: Vec<String> = (1..=count)
            .filter(|&i| {
                let r = band_rows(found[0].1.render.height, i, count);
                r.start >= gap.start && r.end <= gap.end
            })
            .map(|i| format!("{i}/{count}"))
            .collect();
        message += &format!(" (missing part{} {})", if absent.len() == 1 { "" } else { "s" }, absent.join(", "));
    }
    match (above, below) {
        (Some(a), Some(b)) => message + &format!(", between {} and {}", ShownPath(a), ShownPath(b)),
        (Some(a), None) => message + &format!(", after {}", ShownPath(a)),
        (None, Some(b)) => message + &format!(", before {}", ShownPath(b)),
        (None, None) => message,
    }
}

/// Writes the checked parts' rows, top to bottom, as one `format` image to `out`.
pub fn write_merged(
    parts: &[(PathBuf, PartInfo)],
    header: &Header,
    format: Format,
    out: &mut dyn std::io::Write,
) -> Result<(), MergeError> {
    let mut writer = RowWriter::new(format, header, out).map_err(MergeError::Output)?;
    for (path, info) in parts {
        // Opened again (a merge of thousands of parts would run out of
        // descriptors holding them all open): a part replaced since its
        // check would give rows of another render.
        let mut reader = open(path)?;
        if reader.header().text.as_deref().and_then(PartInfo::parse).as_ref() != Some(info) {
            return Err(MergeError::Refused(format!(
                "{}: changed while the parts were merged (it is no longer part {}/{} of the scene checked): merge again",
                ShownPath(path),
                info.index,
                info.count
            )));
        }
        for _ in info.rows.clone() {
            let row = reader.next_row().map_err(|error| unreadable(path, error))?;
            writer.write_row(row).map_err(MergeError::Output)?;
        }
        reader.finish().map_err(|error| unreadable(path, error))?;
    }
    writer.finish().map_err(MergeError::Output)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_every_row_once_and_differ_by_at_most_one() {
        for height in [1, 2, 7, 240, 961, 16384] {
            for count in 1..=height.min(40) {
                let bands: Vec<_> = (1..=count).map(|i| band_rows(height, i, count)).collect();
                assert_eq!(bands[0].start, 0);
                assert_eq!(bands.last().unwrap().end, height);
                assert!(bands.windows(2).all(|w| w[0].end == w[1].start));
                let (min, max) = (bands.iter().map(|b| b.len()).min(), bands.iter().map(|b| b.len()).max());
                assert!(max.unwrap() - min.unwrap() <= 1, "{height} rows in {count}");
            }
        }
        assert_eq!(band_rows(10, 1, 3), 0..3);
        assert_eq!(band_rows(10, 3, 3), 6..10);
    }

    #[test]
    fn part_specs() {
        assert_eq!("2/5".parse(), Ok(PartSpec { index: Some(2), count: 5 }));
        assert_eq!("auto/8".parse(), Ok(PartSpec { index: None, count: 8 }));
        for bad in ["0/3", "4/3", "1/0", "3", "a/3", "1/b", "-1/3"] {
            assert!(bad.parse::<PartSpec>().is_err(), "{bad}");
        }
    }

    #[test]
    fn auto_reads_slurm_then_kubernetes() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |name: &str| pairs.iter().find(|(n, _)| *n == name).map(|(_, v)| v.to_string())
        };
        assert_eq!(auto_index(4, env(&[("SLURM_ARRAY_TASK_ID", "3")])), Ok(3));
        assert_eq!(auto_index(4, env(&[("SLURM_ARRAY_TASK_ID", "0"), ("SLURM_ARRAY_TASK_MIN", "0")])), Ok(1));
        assert_eq!(auto_index(4, env(&[("SLURM_ARRAY_TASK_ID", "13"), ("SLURM_ARRAY_TASK_MIN", "10")])), Ok(4));
        assert_eq!(auto_index(4, env(&[("JOB_COMPLETION_INDEX", "0")])), Ok(1));
        assert_eq!(auto_index(4, env(&[("JOB_COMPLETION_INDEX", "3"), ("SLURM_ARRAY_TASK_ID", "2")])), Ok(2));
        assert_eq!(auto_index(4, env(&[])), Err(AutoError::Unset));
        assert!(matches!(
            auto_index(4, env(&[("JOB_COMPLETION_INDEX", "4")])),
            Err(AutoError::OutOfRange { index: 5, .. })
        ));
        assert!(matches!(
            auto_index(4, env(&[("SLURM_ARRAY_TASK_ID", "0")])),
            Err(AutoError::OutOfRange { index: 0, .. })
        ));
        assert!(matches!(auto_index(4, env(&[("SLURM_ARRAY_TASK_ID", "x")])), Err(AutoError::NotANumber { .. })));
    }

    #[test]
    fn metadata_round_trips_and_rejects_inconsistent_text() {
        let render = Render {
            version: "0.1.0".into(),
            scene: 0x0123_4567_89ab_cdef,
            width: 320,
            height: 240,
            palette: PaletteMode::Coarse,
        };
        let info = PartInfo { render, rows: band_rows(240, 2, 7), index: 2, count: 7, frame: None };
        let text = info.to_string();
        assert_eq!(PartInfo::parse(&text), Some(info.clone()));
        let framed = PartInfo { frame: Some(12), ..info.clone() };
        assert!(framed.to_string().ends_with(" part=2/7 frame=12"), "{framed}");
        assert_eq!(PartInfo::parse(&framed.to_string()), Some(framed));
        assert_eq!(PartInfo::parse(&format!("{text} frame=x")), None);
        assert_eq!(PartInfo::parse(&text.replace("rows=34..68", "rows=34..69")), None);
        assert_eq!(PartInfo::parse(&text.replace("part=2/7", "part=8/7")), None);
        assert_eq!(PartInfo::parse(&format!("{text} more")), None);
        assert_eq!(PartInfo::parse("hello"), None);
    }
}
