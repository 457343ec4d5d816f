//! Streams a render's rows into an image file, truecolour or through a palette mode, holding a row at a
//! time in memory; and what a panel shows of an image (host-sim's and `host-sim board --check`'s preview).
//!
//! Invariants: rows arrive in order, each once. A truecolour file is written as the rows come. An indexed
//! file's colour table ends at its last entry in use, which is known only at the end, so its indices wait in
//! a spool file beside the output (1 byte a pixel, on disk, removed when done); `scan` also spools the
//! image's colours (3 bytes a pixel) while it learns its table, then maps them (the host's two passes).

use crate::{RgbImage, NO_OBJECT};
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};
use octrace_core::palette::{Coarse, Dither, Gray, Quantizer, Scan};
use octrace_core::panel::Dithering;
use octrace_core::render::PanelColor;
use octrace_core::scene::ObjectId;
use octrace_images::formats::{Format, FormatError, Header, Image, RowWriter};
use octrace_images::palette::PaletteMode;
use octrace_images::panel;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Seek, Write};
use std::path::{Path, PathBuf};

/// What a `color` panel shows of `image` ([`octrace_images::panel`]),
/// dithered by `dithering` if it has few levels, or `None` for the colours
/// that need no conversion.
pub(crate) fn panel_preview(image: &RgbImage, color: PanelColor, dithering: Dithering) -> Option<Image> {
    match (color, color.panel()) {
        (_, Some(shown)) => Some(panel::dithered(image, shown, dithering)),
        (PanelColor::Rgb565, None) => Some(Image::Rgb(panel::rgb565(image))),
        _ => None,
    }
}

/// What a palette mode did to the image, for the report host-sim prints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaletteSummary {
    /// Distinct colours the indexed image shows.
    pub colors_used: usize,
    /// Peak signal-to-noise ratio against the truecolour image, in dB.
    pub psnr: f64,
}

/// A temporary file that is removed when dropped.
struct Spool {
    writer: BufWriter<File>,
    path: PathBuf,
}

impl Spool {
    fn new(dir: &Path, name: &str) -> std::io::Result<Spool> {
        let path = dir.join(format!(".{name}.{}.spool.tmp", std::process::id()));
        let file = File::options().read(true).write(true).create_new(true).open(&path)?;
        // Where an open file outlives its name, drop the name now: not even
        // a killed process leaves the spool behind.
        #[cfg(unix)]
        std::fs::remove_file(&path)?;
        Ok(Spool { writer: BufWriter::with_capacity(1 << 16, file), path })
    }

    /// The bytes written so far, from the start.
    fn reader(&mut self) -> std::io::Result<BufReader<File>> {
        self.writer.flush()?;
        let mut file = self.writer.get_ref().try_clone()?;
        file.rewind()?;
        Ok(BufReader::with_capacity(1 << 16, file))
    }
}

impl Drop for Spool {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// A palette mode's quantizer, kept whole between rows.
enum RowQuantizer {
    Gray,
    Dither,
    /// Outlines need the objects of the row above: the last row seen.
    Coarse {
        above: Vec<u32>,
        previous: Option<(u32, Vec<u32>)>,
    },
    /// A frozen table.
    Scan(Box<Scan>),
}

impl RowQuantizer {
    /// Row `y`'s indices into `out`.
    fn quantize_row(&mut self, y: u32, colors: &[u8], objects: &[u32], out: &mut Vec<u8>) {
        out.clear();
        let object = |x: usize| objects.get(x).copied().filter(|&o| o != NO_OBJECT).map(ObjectId);
        let mut run = |quantizer: &mut dyn Quantizer| {
            out.extend(
                colors
                    .chunks_exact(3)
                    .enumerate()
                    .map(|(x, p)| quantizer.quantize(x as u32, y, Rgb888::new(p[0], p[1], p[2]), object(x))),
            );
        };
        match self {
            RowQuantizer::Gray => run(&mut Gray),
            RowQuantizer::Dither => run(&mut Dither),
            RowQuantizer::Scan(scan) => run(scan.as_mut()),
            RowQuantizer::Coarse { above, previous } => {
                // A fresh `Coarse` fed the row above (output dropped) is in
                // the state it would have after streaming that row.
                let mut coarse = Coarse::new(above);
                if let Some((previous_y, previous_objects)) = previous.as_ref().filter(|(py, _)| py + 1 == y) {
                    for (x, &o) in previous_objects.iter().enumerate() {
                        let o = Some(o).filter(|&o| o != NO_OBJECT).map(ObjectId);
                        coarse.quantize(x as u32, *previous_y, Rgb888::BLACK, o);
                    }
                }
                run(&mut coarse);
                match previous {
                    Some((py, row)) => {
                        *py = y;
                        row.clear();
                        row.extend_from_slice(objects);
                    }
                    None => *previous = Some((y, objects.to_vec())),
                }
            }
        }
    }

    fn table(&self) -> [[u8; 3]; 256] {
        let table = match self {
            RowQuantizer::Gray => *Gray.table(),
            RowQuantizer::Dither | RowQuantizer::Coarse { .. } => *Dither.table(),
            RowQuantizer::Scan(scan) => *scan.table(),
        };
        table.map(|c| [c.r(), c.g(), c.b()])
    }
}

/// Indices spooled until the palette's length is known.
struct Indices {
    quantizer: RowQuantizer,
    spool: Spool,
    row: Vec<u8>,
    used: [bool; 256],
    squared_error: u64,
    pixels: u64,
}

impl Indices {
    fn push(&mut self, y: u32, colors: &[u8], objects: &[u32]) -> std::io::Result<()> {
        self.quantizer.quantize_row(y, colors, objects, &mut self.row);
        let table = self.quantizer.table();
        for (&index, p) in self.row.iter().zip(colors.chunks_exact(3)) {
            self.used[index as usize] = true;
            let entry = table[index as usize];
            self.squared_error += (0..3).map(|c| (i64::from(p[c]) - i64::from(entry[c])).pow(2) as u64).sum::<u64>();
        }
        self.pixels += self.row.len() as u64;
        self.spool.writer.write_all(&self.row)
    }
}

enum Stage<'a> {
    Truecolour(RowWriter<'a>),
    Indexed(Box<Indices>),
    /// `scan`'s first pass: colours spooled while the table is learnt.
    Learning {
        scan: Box<Scan>,
        colors: Spool,
    },
}

/// Writes a render's rows to an image file as they come.
pub struct FileSink<'a> {
    stage: Stage<'a>,
    /// Where the file goes once an indexed image's palette is known.
    out: Option<&'a mut dyn Write>,
    format: Format,
    header: Header,
    /// Rows before this one only prime the quantizer (a part's row above).
    first_row: u32,
    rows_written: u32,
    spool_dir: PathBuf,
    spool_name: String,
}

impl<'a> FileSink<'a> {
    /// A sink writing `header.width` × `header.height` pixels in `mode` as a `format` file to `out`, the
    /// header's text carried along; rows before `first_row` are not written (for `coarse`, they are the
    /// row above). Spool files go in `spool_dir`, named after `spool_name`.
    pub fn new(
        mode: PaletteMode,
        format: Format,
        header: Header,
        first_row: u32,
        out: &'a mut dyn Write,
        spool_dir: &Path,
        spool_name: &str,
    ) -> Result<FileSink<'a>, FormatError> {
        let spool = |suffix: &str| Spool::new(spool_dir, &format!("{spool_name}.{suffix}"));
        let indices = |quantizer| -> Result<Stage<'a>, FormatError> {
            Ok(Stage::Indexed(Box::new(Indices {
                quantizer,
                spool: spool("indices")?,
                row: Vec::new(),
                used: [false; 256],
                squared_error: 0,
                pixels: 0,
            })))
        };
        let (stage, out) = match mode {
            PaletteMode::None => {
                let header = Header { palette: None, ..header.clone() };
                (Stage::Truecolour(RowWriter::new(format, &header, out)?), None)
            }
            PaletteMode::Gray => (indices(RowQuantizer::Gray)?, Some(out)),
            PaletteMode::Dither => (indices(RowQuantizer::Dither)?, Some(out)),
            PaletteMode::Coarse => {
                let above = vec![NO_OBJECT; header.width as usize];
                (indices(RowQuantizer::Coarse { above, previous: None })?, Some(out))
            }
            PaletteMode::Scan => (Stage::Learning { scan: Box::new(Scan::new()), colors: spool("colors")? }, Some(out)),
        };
        Ok(FileSink {
            stage,
            out,
            format,
            header,
            first_row,
            rows_written: 0,
            spool_dir: spool_dir.to_owned(),
            spool_name: spool_name.to_owned(),
        })
    }

    /// Ends the file once every row has come: for an indexed image, writes the header, the palette up to its
    /// last entry in use and the spooled indices.
    pub fn finish(self) -> Result<Option<PaletteSummary>, FormatError> {
        let FileSink { stage, out, format, header, rows_written, spool_dir, spool_name, .. } = self;
        if rows_written != header.height {
            return Err(FormatError::Invalid(format!("{rows_written} rows of {} were rendered", header.height)));
        }
        let mut indices = match stage {
            Stage::Truecolour(writer) => return writer.finish().map(|()| None),
            Stage::Indexed(indices) => indices,
            Stage::Learning { scan, mut colors } => {
                let scan = relearn(*scan, &mut colors, header.width)?;
                let mut indices = Box::new(Indices {
                    quantizer: RowQuantizer::Scan(Box::new(scan)),
                    spool: Spool::new(&spool_dir, &format!("{spool_name}.indices"))?,
                    row: Vec::new(),
                    used: [false; 256],
                    squared_error: 0,
                    pixels: 0,
                });
                let mut reader = colors.reader()?;
                let mut row = vec![0; 3 * header.width as usize];
                for y in 0..header.height {
                    reader.read_exact(&mut row)?;
                    indices.push(y, &row, &[])?;
                }
                indices
            }
        };
        let table = indices.quantizer.table();
        let entries = indices.used.iter().rposition(|&u| u).map_or(1, |last| last + 1);
        let mut shown: Vec<[u8; 3]> = (0..256).filter(|&i| indices.used[i]).map(|i| table[i]).collect();
        shown.sort_unstable();
        shown.dedup();
        let summary = PaletteSummary {
            colors_used: shown.len(),
            psnr: if indices.squared_error == 0 {
                f64::INFINITY
            } else {
                let mean = indices.squared_error as f64 / (3 * indices.pixels.max(1)) as f64;
                10.0 * (255.0f64 * 255.0 / mean).log10()
            },
        };
        let out = out.ok_or_else(|| FormatError::Invalid("the output was already used".into()))?;
        let header = Header { palette: Some(table[..entries].to_vec()), ..header };
        let mut writer = RowWriter::new(format, &header, out)?;
        let mut reader = indices.spool.reader()?;
        let mut row = vec![0; header.width as usize];
        for _ in 0..header.height {
            reader.read_exact(&mut row)?;
            writer.write_row(&row)?;
        }
        writer.finish()?;
        Ok(Some(summary))
    }
}

/// `scan`'s first pass finished from the spooled colours: while the table
/// overflows, learns again with a closeness limit half as large again; then
/// freezes it (as [`octrace_images::palette::apply`] does).
fn relearn(mut scan: Scan, colors: &mut Spool, width: u32) -> std::io::Result<Scan> {
    // Past 3·255², every colour is close to every entry.
    while scan.overflowed() && scan.closeness() <= 3 * 255 * 255 {
        scan = Scan::with_closeness(scan.closeness() * 3 / 2);
        let mut reader = colors.reader()?;
        let mut row = vec![0; 3 * width as usize];
        loop {
            match reader.read_exact(&mut row) {
                Ok(()) => row.chunks_exact(3).for_each(|p| scan.learn(Rgb888::new(p[0], p[1], p[2]))),
                Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
                Err(e) => return Err(e),
            }
        }
    }
    scan.freeze();
    Ok(scan)
}

impl crate::RowSink for FileSink<'_> {
    fn row(&mut self, y: u32, colors: &[u8], objects: &[u32]) -> std::io::Result<()> {
        if y < self.first_row {
            // The row above a part: only `coarse` looks at it.
            if let Stage::Indexed(indices) = &mut self.stage {
                let mut discard = Vec::new();
                indices.quantizer.quantize_row(y, colors, objects, &mut discard);
            }
            return Ok(());
        }
        self.rows_written += 1;
        match &mut self.stage {
            Stage::Truecolour(writer) => writer.write_row(colors).map_err(into_io),
            Stage::Indexed(indices) => indices.push(y, colors, objects),
            Stage::Learning { scan, colors: spool } => {
                colors.chunks_exact(3).for_each(|p| scan.learn(Rgb888::new(p[0], p[1], p[2])));
                spool.writer.write_all(colors)
            }
        }
    }
}

fn into_io(e: FormatError) -> std::io::Error {
    match e {
        FormatError::Io(e) => e,
        e => std::io::Error::other(e),
    }
}

/// Writes `path` through a temporary file in the same directory
/// ([`temporary_beside`]), renamed into place only when `write` succeeds
/// ([`replace_with`]); on failure no file is left behind. A `path` that is
/// a device, a pipe or a socket (`/dev/null`, a FIFO) is written into as
/// a shell's `>` would: a rename would replace the node itself. A symbolic
/// link is written through, as `>` would too: the file it names is
/// replaced, the link stays.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let (path, tmp, file) = match destination(path)? {
        Destination::Stream(path) => {
            let mut w = std::io::BufWriter::new(open_stream(&path)?);
            write(&mut w)?;
            return w.flush();
        }
        Destination::File { path, tmp, file } => (path, tmp, file),
    };
    let unfinished = crate::signals::Unfinished::new(&tmp);
    let result = (|| {
        let mut w = std::io::BufWriter::new(file);
        write(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        unfinished.finish(|| replace_with(&tmp, &path))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Whether [`write_atomically`] could write `path` now (its directory there
/// and writable, the file not read-only), asked before a long piece of
/// work whose result would otherwise be lost at the end (a board's
/// drawing). A stream is not opened: opening a FIFO waits for its reader.
pub(crate) fn check_writable(path: &Path) -> std::io::Result<()> {
    match destination(path)? {
        Destination::Stream(_) => Ok(()),
        Destination::File { tmp, .. } => std::fs::remove_file(tmp),
    }
}

/// The stream `path` opened for writing. A FIFO without a reader is
/// waited for, saying so once, until one comes or a stop signal arrives
/// (then an error): open(2) itself would wait on through the signal, its
/// handler returning into the call. (A reader gone between the probe and
/// the open leaves the open waiting: a second signal ends host-sim, see
/// `signals`.)
fn open_stream(path: &Path) -> std::io::Result<File> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
        if std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo()) {
            let stop = crate::signals::stop_flag();
            let mut said = false;
            let probe = loop {
                match File::options().write(true).custom_flags(libc::O_NONBLOCK).open(path) {
                    Ok(probe) => break probe,
                    // No reader yet.
                    Err(e) if e.raw_os_error() == Some(libc::ENXIO) => {}
                    Err(e) => return Err(e),
                }
                if stop.load(std::sync::atomic::Ordering::SeqCst) {
                    // Not `Interrupted`, which the standard library's
                    // writers retry.
                    return Err(std::io::Error::other("stopped while waiting for the FIFO's reader"));
                }
                if !said {
                    eprintln!("host-sim: {} is a FIFO: waiting for its reader", crate::exit::ShownPath(path));
                    said = true;
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            };
            // Opened while the probe holds the reader's end: the reader
            // cannot see an end of file in between, and writes then wait
            // for it as a shell's `>` would.
            let file = File::options().write(true).open(path);
            drop(probe);
            return file;
        }
    }
    File::options().write(true).open(path)
}

/// Where [`write_atomically`] writes `path`, its symbolic links followed.
enum Destination {
    /// A device, a pipe or a socket: written into.
    Stream(PathBuf),
    /// A file, replaced by `tmp` (open as `file`) once it is written.
    File { path: PathBuf, tmp: PathBuf, file: File },
}

fn destination(path: &Path) -> std::io::Result<Destination> {
    // Asked of the path as given, which open(2) follows: a stream's links
    // may end where no path does (`/dev/stdout` on a pipe: `pipe:[N]`).
    if is_stream(path) {
        return Ok(Destination::Stream(path.to_path_buf()));
    }
    let path = through_links(path);
    // Refused before anything is written (the rename would refuse it last),
    // as is `DIR/` where there is no DIR (the rename: "Not a directory").
    if path.is_dir() || path.as_os_str().as_encoded_bytes().ends_with(b"/") {
        #[cfg(unix)]
        return Err(std::io::Error::from_raw_os_error(libc::EISDIR));
        #[cfg(not(unix))]
        return Err(std::io::ErrorKind::IsADirectory.into());
    }
    refuse_read_only(&path)?;
    let (tmp, file) = temporary_beside(&path)?;
    Ok(Destination::File { path, tmp, file })
}

/// The file `path` names once its symbolic links are followed (a dangling
/// one, the file it would create), at most 40 deep (the kernel's limit,
/// past which the path itself, which then fails as the kernel says).
fn through_links(path: &Path) -> PathBuf {
    let mut path = path.to_path_buf();
    for _ in 0..40 {
        let Ok(target) = std::fs::read_link(&path) else { break };
        // A relative target is relative to the link's directory (joined,
        // an absolute one replaces it).
        path = path.parent().unwrap_or(Path::new("")).join(target);
    }
    path
}

/// Whether `path` names something other than a file or a directory: a
/// device, a pipe or a socket, which output is written into, not renamed
/// over.
pub(crate) fn is_stream(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Refuses an existing read-only `path`: a rename would replace it, where
/// writing to it directly would fail.
pub(crate) fn refuse_read_only(path: &Path) -> std::io::Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if m.permissions().readonly() => {
            Err(std::io::Error::new(std::io::ErrorKind::PermissionDenied, "the file is read-only"))
        }
        _ => Ok(()),
    }
}

/// A new, empty file beside `path` to write it through: `.NAME.PID.R.tmp`
/// in its directory, `R` random, created only where nothing is (so never
/// through a link another user placed there, in a directory they may
/// write too), with the permissions a new file gets.
pub(crate) fn temporary_beside(path: &Path) -> std::io::Result<(PathBuf, File)> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "the output path names no file"))?
        .to_string_lossy();
    create_unguessable(File::options().write(true).create_new(true), || {
        dir.join(format!(".{name}.{}.{}.tmp", std::process::id(), random_hex()))
    })
}

/// A file made with `options` (which create only where nothing is) at the
/// first of a few of `names()` that is free.
pub(crate) fn create_unguessable(
    options: &std::fs::OpenOptions,
    names: impl Fn() -> PathBuf,
) -> std::io::Result<(PathBuf, File)> {
    let mut last = None;
    for _ in 0..8 {
        let path = names();
        match options.open(&path) {
            Ok(file) => return Ok((path, file)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last.unwrap_or_else(|| std::io::Error::other("no new file could be made")))
}

/// 64 random bits in hex: keys the standard library draws from the
/// operating system's randomness, a fresh pair each time.
pub(crate) fn random_hex() -> String {
    use std::hash::{BuildHasher, Hasher};
    let mut random = std::collections::hash_map::RandomState::new().build_hasher();
    random.write_u32(std::process::id());
    format!("{:016x}", random.finish())
}

/// Renames the written `tmp` to `path`, giving it first the permissions of
/// the file it replaces (a private scene stays private).
pub(crate) fn replace_with(tmp: &Path, path: &Path) -> std::io::Result<()> {
    if let Ok(replaced) = std::fs::metadata(path) {
        std::fs::set_permissions(tmp, replaced.permissions())?;
    }
    std::fs::rename(tmp, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{RgbImage, RowSink};
    use octrace_images::formats::read;

    /// A directory of its own under the system's temporary one.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("host-sim-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A pipe (as `/dev/null` or `/dev/stdout` would be) is written into:
    /// renamed over, it would be replaced by a file.
    #[cfg(unix)]
    #[test]
    fn a_pipe_is_written_into_not_replaced() {
        use std::os::unix::fs::FileTypeExt;
        let dir = scratch("fifo");
        let fifo = dir.join("out.png");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        write_atomically(&fifo, |w| w.write_all(b"image")).unwrap();
        assert_eq!(reader.join().unwrap(), b"image");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo(), "still a pipe");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "no temporary file");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_replaced_file_keeps_its_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("mode");
        let private = dir.join("s.txt");
        std::fs::write(&private, "old").unwrap();
        std::fs::set_permissions(&private, std::fs::Permissions::from_mode(0o600)).unwrap();
        write_atomically(&private, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&private).unwrap(), b"new");
        assert_eq!(std::fs::metadata(&private).unwrap().permissions().mode() & 0o777, 0o600);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "no temporary file left");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn temporary_files_are_new_and_named_apart() {
        let dir = scratch("names");
        let target = dir.join("a.png");
        let (first, _) = temporary_beside(&target).unwrap();
        let (second, _) = temporary_beside(&target).unwrap();
        assert_ne!(first, second);
        for tmp in [&first, &second] {
            let name = tmp.file_name().unwrap().to_string_lossy().into_owned();
            assert!(name.starts_with(".a.png.") && name.ends_with(".tmp"), "{name}");
            assert_eq!(tmp.parent(), Some(dir.as_path()));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A gradient with objects in vertical stripes, and what `apply` makes of it.
    fn sample(mode: PaletteMode) -> (RgbImage, Vec<u32>, octrace_images::formats::Image) {
        let (w, h) = (37u32, 23u32);
        let data = (0..w * h).flat_map(|i| [(i * 7) as u8, (i / w * 11) as u8, (i % w * 5) as u8]).collect();
        let image = RgbImage { width: w, height: h, data };
        let objects: Vec<u32> =
            (0..w * h).map(|i| if i % w < 9 { NO_OBJECT } else { i % w / 10 + i / w / 8 }).collect();
        let expected = octrace_images::palette::apply(&image, &objects, mode);
        (image, objects, expected)
    }

    #[test]
    fn streamed_rows_give_what_apply_gives_in_every_mode_and_rows_from_the_middle() {
        let dir = std::env::temp_dir().join(format!("octrace-output-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for mode in PaletteMode::ALL {
            let (image, objects, expected) = sample(mode);
            let w = image.width as usize;
            // The whole image, then rows 5.. with the row above given first (a part).
            for first in [0u32, 5] {
                if first > 0 && mode == PaletteMode::Scan {
                    // Learnt from the rows it sees: parts refuse it.
                    continue;
                }
                let header = Header { width: image.width, height: image.height - first, palette: None, text: None };
                let mut bytes = Vec::new();
                let mut sink = FileSink::new(mode, Format::Png, header, first, &mut bytes, &dir, "t").unwrap();
                for y in first.saturating_sub(1)..image.height {
                    let y_ = y as usize;
                    sink.row(y, &image.data[3 * y_ * w..3 * (y_ + 1) * w], &objects[y_ * w..(y_ + 1) * w]).unwrap();
                }
                sink.finish().unwrap();
                let got = read(&bytes).unwrap();
                if first == 0 {
                    assert_eq!(got, expected, "{}", mode.name());
                } else if let (Some(got), Some(expected)) = (indexed(&got), indexed(&expected)) {
                    assert_eq!(got, &expected[first as usize * w..], "{} from row {first}", mode.name());
                }
            }
        }
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "spool files left behind");
        std::fs::remove_dir(&dir).unwrap();
    }

    fn indexed(image: &octrace_images::formats::Image) -> Option<&[u8]> {
        match image {
            octrace_images::formats::Image::Indexed { indices, .. } => Some(indices),
            octrace_images::formats::Image::Rgb(_) => None,
        }
    }

    #[test]
    fn missing_rows_are_an_error() {
        let header = Header { width: 2, height: 3, palette: None, text: None };
        let mut bytes = Vec::new();
        let mut sink =
            FileSink::new(PaletteMode::None, Format::Tga, header, 0, &mut bytes, Path::new("."), "t").unwrap();
        sink.row(0, &[0; 6], &[NO_OBJECT; 2]).unwrap();
        assert!(sink.finish().unwrap_err().to_string().contains("1 rows of 3"));
    }
}
