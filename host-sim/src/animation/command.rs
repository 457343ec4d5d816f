//! `host-sim anim.txt OUT` for a scene with FRAMES, and `host-sim merge`
//! of frame files: the command line's animation side.
//!
//! Invariants: nothing is left behind by a run that fails (the GIF or APNG
//! through a temporary file, frame files each through one, renamed only
//! once every frame is written); a scene error at any frame is reported as
//! `file:line:col` with exit code 2, as for a still.

use super::apng::ApngWriter;
use super::frames::{check_every_frame, render_frames, AnimationError, AnimationOptions, AnimationReport, FrameImage};
use super::gif::{gif_delay, GifWriter, GIF_FASTEST};
use super::writers::{write_frame_file, FrameInfo, Output};
use crate::arguments::not_the_scene;
use crate::exit::{CliError, ShownPath};
use crate::output::{is_stream, refuse_read_only, replace_with, temporary_beside, write_atomically};
use crate::parts::{auto_index, band_rows, scene_hash, PartSpec, Render};
use crate::terminal::{progress_bar, Threads};
use octrace_core::scene::Frames;
use octrace_images::formats::{Format, FormatError, Image, RowReader};
use octrace_images::palette::{self, PaletteMode};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What the command line asks of an animation.
pub struct Request<'a> {
    pub scene_path: &'a Path,
    pub bytes: &'a [u8],
    pub frames: Frames,
    pub out: &'a Path,
    /// `--palette`, if given.
    pub palette: Option<PaletteMode>,
    pub format: Option<Format>,
    pub part: Option<PartSpec>,
    /// The frames' size.
    pub size: (u32, u32),
    pub options: AnimationOptions,
    pub quiet: bool,
}

/// Refuses a frame asked for alone (`--frame K`) of an animation that does
/// not load at every frame with the error the whole loop's render gives.
pub fn check_frames(scene_path: &Path, bytes: &[u8], out: &Path) -> Result<(), CliError> {
    check_every_frame(bytes).map_err(|e| refused(e, scene_path, out))
}

/// The command line's error for rendering the animation at `scene_path`
/// into `out`: a scene's errors at `file:line:col`, as for a still.
fn refused(e: AnimationError, scene_path: &Path, out: &Path) -> CliError {
    let name = ShownPath(scene_path).to_string();
    match e {
        AnimationError::Scene { frame, errors } => CliError::Scene {
            file: frame.map_or_else(|| name.clone(), |frame| format!("{name} (frame {frame})")),
            errors: errors.into_iter().map(|e| format!("{name}:{e}")).collect(),
        },
        AnimationError::Setup(message) => CliError::Invalid(message),
        AnimationError::Stopped => CliError::stopped(),
        AnimationError::Write(e) => CliError::write(out, e),
    }
}

/// Renders the animation `request` asks for and writes it.
pub fn animate(request: &Request<'_>, stderr: &mut dyn Write) -> Result<(), CliError> {
    let output = Output::of(request.out, request.format).map_err(CliError::Invalid)?;
    let frames = request.frames;
    let palette =
        match (&output, request.palette) {
            (Output::Gif, Some(PaletteMode::None)) => return Err(CliError::Invalid(
                "a GIF holds 256 colours a frame: leave --palette out for colours chosen for the whole loop, or give \
                 scan, dither, coarse or gray"
                    .into(),
            )),
            // Without --palette, a GIF's colours are chosen from the
            // truecolour frames of the whole loop.
            (_, mode) => mode.unwrap_or(PaletteMode::None),
        };
    let range = match (request.part, &output) {
        (None, _) => frames.all(),
        (Some(spec), Output::Files(_)) => {
            if spec.count > frames.count {
                return Err(CliError::Invalid(format!(
                    "--part: {} parts of an animation of {} frames: at most {}",
                    spec.count, frames.count, frames.count
                )));
            }
            let index = match spec.index {
                Some(i) => i,
                None => auto_index(spec.count, |name| std::env::var(name).ok())
                    .map_err(|e| CliError::Invalid(format!("--part: {e}")))?,
            };
            band_rows(frames.count, index, spec.count)
        }
        (Some(_), _) => {
            return Err(CliError::Invalid(
                "--part splits an animation's frames: write them one file a frame ('frames/f%04d.png'), then \
                 `host-sim merge out.gif frames/f*.png`"
                    .into(),
            ))
        }
    };
    let (width, height) = request.size;
    let started = Instant::now();
    let bar = progress_bar(u64::from(range.len() as u32), request.quiet);
    let progress = |_: u64| {};
    let scene_error = |e: AnimationError| refused(e, request.scene_path, request.out);
    let mut outcome: Option<Result<AnimationReport, AnimationError>> = None;
    let mut render = |each: &mut dyn FnMut(u32, &FrameImage) -> std::io::Result<()>| {
        let mut counted = |frame: u32, image: &FrameImage| {
            if let Some(bar) = &bar {
                bar.inc(1);
            }
            each(frame, image)
        };
        let result = render_frames(request.bytes, range.clone(), &request.options, &progress, &mut counted);
        let failed = result.is_err();
        outcome = Some(result);
        match failed {
            true => Err(std::io::Error::other("no animation")),
            false => Ok(()),
        }
    };
    let info = |frame: u32, width: u32, height: u32| FrameInfo {
        render: Render {
            version: env!("CARGO_PKG_VERSION").into(),
            scene: scene_hash(request.bytes),
            width,
            height,
            palette,
        },
        frame,
        frames,
    };
    let written = match &output {
        Output::Gif => write_atomically(request.out, |f| {
            let mut gif = GifWriter::new(f, width, height, frames)?;
            render(&mut |_, frame| {
                gif.frame(&palette::apply(&frame.image, &frame.objects, palette), frame.retraced.as_deref())
            })?;
            gif.finish().map(|_| ())
        }),
        Output::Apng => write_atomically(request.out, |f| {
            let mut apng = ApngWriter::new(f, width, height, frames)?;
            render(&mut |_, frame| {
                // A palette mode's colours can change outside the tiles
                // re-traced (`scan` learns a table a frame).
                let retraced = frame.retraced.as_deref().filter(|_| palette == PaletteMode::None);
                apng.frame(&palette::apply(&frame.image, &frame.objects, palette).to_rgb().data, retraced)
            })?;
            apng.finish()
        }),
        Output::Files(pattern) => {
            let format = match crate::arguments::output_format(request.format, &pattern.name(0)) {
                Ok(format) if format != Format::Ras => format,
                // With --format, only a name that contradicts it is refused.
                Err(contradiction) if request.format.is_some() => return Err(contradiction),
                _ => {
                    return Err(CliError::Invalid(format!(
                        "{}: frame files are PNG or Targa, one file a frame (a Sun raster has no room for the \
                         frame's metadata; a GIF or an APNG of the whole loop is one file: OUT.gif, OUT.png)",
                        ShownPath(&pattern.name(0))
                    )))
                }
            };
            // Each frame's file as a still's: not the scene, not a
            // read-only file, not a directory; refused before anything is
            // rendered.
            for k in range.clone() {
                let path = pattern.name(k);
                not_the_scene(request.scene_path, &path)?;
                refuse_read_only(&path).map_err(|e| CliError::write(&path, e))?;
                if path.is_dir() || is_stream(&path) {
                    return Err(CliError::write(&path, "not a file a frame can be written to"));
                }
            }
            // Each frame's temporary file, its path, and whether a file was
            // there before.
            let mut done: Vec<(PathBuf, PathBuf, bool)> = Vec::new();
            let named = |path: &Path| {
                let path = ShownPath(path).to_string();
                move |e: std::io::Error| std::io::Error::new(e.kind(), format!("{path}: {e}"))
            };
            let result = render(&mut |k, frame| {
                let path = pattern.name(k);
                let shown = palette::apply(&frame.image, &frame.objects, palette);
                let (tmp, file) = temporary_beside(&path).map_err(named(&path))?;
                let write = || -> std::io::Result<()> {
                    let mut file = std::io::BufWriter::new(file);
                    let info = info(k, frame.image.width, frame.image.height);
                    write_frame_file(&shown, &info, format, &mut file).map_err(into_io)?;
                    file.into_inner().map_err(|e| e.into_error())?.sync_all()
                };
                let result = write().map_err(named(&path));
                let existed = path.exists();
                done.push((tmp, path, existed));
                result
            });
            let mut renamed = Vec::new();
            let result = result.and_then(|()| {
                done.iter().try_for_each(|(tmp, path, existed)| {
                    replace_with(tmp, path).map_err(named(path))?;
                    renamed.push((path, *existed));
                    Ok(())
                })
            });
            if result.is_err() {
                // A failed run leaves no frame of its own: neither those
                // written nor those already renamed where no file was (a
                // file it replaced cannot come back; the checks above
                // make that a race with another program).
                done.iter().for_each(|(tmp, _, _)| drop(std::fs::remove_file(tmp)));
                renamed.iter().filter(|(_, existed)| !existed).for_each(|(path, _)| drop(std::fs::remove_file(path)));
            }
            result
        }
    };
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let report = match (outcome, written) {
        (Some(Err(e)), _) => return Err(scene_error(e)),
        (_, Err(e)) => return Err(CliError::write(request.out, e)),
        (Some(Ok(report)), Ok(())) => report,
        (None, Ok(())) => return Err(CliError::write(request.out, "no frame was rendered")),
    };
    // Said even with --quiet: the file does not play as the scene asks.
    if let Some(note) = slower_gif(&output, frames, request.out) {
        let _ = writeln!(stderr, "{note}");
    }
    if !request.quiet {
        let share = 100.0 * report.traced as f64 / report.pixels.max(1) as f64;
        let _ = writeln!(
            stderr,
            "{} frames of {} ({} a second) in {:.3} s ({}, {}): {:.1} % of the pixels traced, \
             loading {:.3} s, tracing {:.3} s: {} rays, {} shadow rays -> {}",
            report.frames,
            frames.count,
            frames.rate,
            started.elapsed().as_secs_f64(),
            Threads(request.options.render.threads),
            if request.options.coherence { "coherence" } else { "every frame whole" },
            share,
            report.loading.as_secs_f64(),
            report.tracing.as_secs_f64(),
            report.stats.rays,
            report.stats.shadow_rays,
            ShownPath(request.out)
        );
    }
    Ok(())
}

/// What to tell of a GIF written to `out` that plays slower than `frames`'
/// rate (faster than [`GIF_FASTEST`] frames a second), if it is one.
fn slower_gif(output: &Output, frames: Frames, out: &Path) -> Option<String> {
    if *output != Output::Gif || frames.rate <= GIF_FASTEST {
        return None;
    }
    let played: u32 = frames.all().map(|k| u32::from(gif_delay(frames, k))).sum();
    Some(format!(
        "host-sim: note: a GIF shows a frame for {}/100 s at least, so {} at {} frames a second plays its loop in \
         {:.2} s, not {:.2} s (an APNG, OUT.png, keeps the rate)",
        100 / GIF_FASTEST,
        ShownPath(out),
        frames.rate,
        f64::from(played) / 100.0,
        f64::from(frames.count) / f64::from(frames.rate)
    ))
}

fn into_io(e: FormatError) -> std::io::Error {
    match e {
        FormatError::Io(e) => e,
        e => std::io::Error::other(e),
    }
}

/// Whether `path` is a frame file (its metadata says so), or why it cannot
/// be opened.
pub fn is_frame_file(path: &Path) -> std::io::Result<bool> {
    let file = std::fs::File::open(path)?;
    Ok(RowReader::new(file).is_ok_and(|r| r.header().text.as_deref().and_then(FrameInfo::parse).is_some()))
}

/// `host-sim merge OUT FRAMES…`: frame files rendered apart, assembled into
/// the animation `output` names, bit for bit what a render straight to it
/// writes.
pub fn merge_frames(
    output: &Path,
    files: &[PathBuf],
    format: Option<Format>,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    let refuse = |message: String| CliError::Invalid(format!("merge: {message}; nothing written"));
    let kind = match Output::of(output, format) {
        Ok(kind @ (Output::Gif | Output::Apng)) => kind,
        // An animation's name with a --format that contradicts it: that is
        // what is wrong, not the name.
        Err(contradiction) if matches!(Output::of(output, None), Ok(Output::Gif | Output::Apng)) => {
            return Err(refuse(contradiction))
        }
        _ => {
            return Err(refuse(format!(
                "{}: frames merge into an animated GIF (.gif) or an APNG (.png)",
                ShownPath(output)
            )))
        }
    };
    let mut found: Vec<(FrameInfo, Image, &Path)> = Vec::new();
    for path in files {
        let name = ShownPath(path);
        let file = std::fs::File::open(path).map_err(|e| CliError::read(path, e))?;
        let mut reader = RowReader::new(file).map_err(|e| refuse(format!("{name}: {e}")))?;
        let header = reader.header().clone();
        let info = header
            .text
            .as_deref()
            .and_then(FrameInfo::parse)
            .ok_or_else(|| refuse(format!("{name}: not a frame file (no octrace frame metadata in it)")))?;
        if (header.width, header.height) != (info.render.width, info.render.height)
            || header.palette.is_some() != (info.render.palette != PaletteMode::None)
        {
            return Err(refuse(format!("{name}: the image does not match its metadata")));
        }
        let mut data = Vec::new();
        for _ in 0..header.height {
            data.extend_from_slice(reader.next_row().map_err(|e| refuse(format!("{name}: {e}")))?);
        }
        reader.finish().map_err(|e| refuse(format!("{name}: {e}")))?;
        let image = match header.palette {
            Some(palette) => Image::Indexed { width: header.width, height: header.height, palette, indices: data },
            None => Image::Rgb(crate::RgbImage { width: header.width, height: header.height, data }),
        };
        if let Some((first, _, first_path)) = found.first() {
            let (frames, first_frames) = (info.frames, first.frames);
            let difference = info.render.difference(&first.render).or_else(|| {
                (frames != first_frames).then(|| {
                    format!(
                        "another FRAMES ({} at {} a second, not {} at {})",
                        frames.count, frames.rate, first_frames.count, first_frames.rate
                    )
                })
            });
            if let Some(difference) = difference {
                let first = ShownPath(first_path);
                return Err(refuse(format!("{name} is not a frame of the animation of {first}: {difference}")));
            }
        }
        found.push((info, image, path));
    }
    found.sort_by_key(|(info, _, _)| info.frame);
    let Some((first, _, _)) = found.first() else { return Err(refuse("no frames to merge".into())) };
    let (frames, (width, height)) = (first.frames, (first.render.width, first.render.height));
    if let Some(pair) = found.windows(2).find(|pair| pair[0].0.frame == pair[1].0.frame) {
        let (frame, a, b) = (pair[0].0.frame, ShownPath(pair[0].2), ShownPath(pair[1].2));
        return Err(refuse(format!("frame {frame} is given twice: {a} and {b}")));
    }
    let missing = missing_frames(found.iter().map(|(info, _, _)| info.frame), frames.count);
    if !missing.is_empty() {
        let s = if frames.count == 1 { "" } else { "s" };
        return Err(refuse(format!("{missing} missing (the animation has {} frame{s})", frames.count)));
    }
    let written = match kind {
        Output::Gif => write_atomically(output, |f| {
            let mut gif = GifWriter::new(f, width, height, frames)?;
            found.iter().try_for_each(|(_, image, _)| gif.frame(image, None))?;
            gif.finish().map(|_| ())
        }),
        Output::Apng => write_atomically(output, |f| {
            let mut apng = ApngWriter::new(f, width, height, frames)?;
            found.iter().try_for_each(|(_, image, _)| apng.frame(&image.to_rgb().data, None))?;
            apng.finish()
        }),
        Output::Files(_) => return Err(refuse("merge writes one animation (.gif or .png)".into())),
    };
    written.map_err(|e| CliError::Io(format!("merge: cannot write {}: {e}", ShownPath(output))))?;
    if let Some(note) = slower_gif(&kind, frames, output) {
        let _ = writeln!(stderr, "{note}");
    }
    Ok(())
}

/// The frames of `0..count` that are not in `present` (in order), as one
/// reads them: `frame 47`, `frames 0 to 3, 12 to 23`; empty when none is.
fn missing_frames(present: impl Iterator<Item = u32>, count: u32) -> String {
    let mut ranges = Vec::new();
    let mut next = 0;
    for frame in present.filter(|&frame| frame < count).chain([count]) {
        if frame > next {
            ranges.push((next, frame - 1));
        }
        next = next.max(frame + 1);
    }
    let range = |&(from, to): &(u32, u32)| if from == to { from.to_string() } else { format!("{from} to {to}") };
    match ranges.as_slice() {
        [] => String::new(),
        [(from, to)] if from == to => format!("frame {from}"),
        _ => format!("frames {}", ranges.iter().map(range).collect::<Vec<_>>().join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_frames_are_listed_as_ranges() {
        let missing = |present: &[u32], count| missing_frames(present.iter().copied(), count);
        assert_eq!(missing(&[0, 1, 2], 3), "");
        assert_eq!(missing(&[0, 1], 3), "frame 2");
        assert_eq!(missing(&[4, 5, 6, 7, 8, 9, 10, 11, 24, 26], 28), "frames 0 to 3, 12 to 23, 25, 27");
        assert_eq!(missing(&[], 2), "frames 0 to 1");
    }
}
