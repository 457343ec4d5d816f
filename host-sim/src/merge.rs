//! `host-sim merge`: a still's band parts (`--part I/N`) stacked into the
//! image one render gives, or an animation's frame files assembled into its
//! GIF or APNG; refused, nothing written, for files of other renders, rows
//! or frames missing or given twice.

use crate::animation::{is_frame_file, merge_frames, Output};
use crate::arguments::{output_format, same_file};
use crate::exit::{CliError, ShownPath};
use crate::output::write_atomically;
use crate::parts::{self, MergeError};
use octrace_images::formats::{Format, FormatError};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Merges `parts` (band parts or frame files, one kind) into `output`.
pub(crate) fn run(
    output: &Path,
    parts: &[PathBuf],
    format: Option<Format>,
    stderr: &mut dyn Write,
) -> Result<(), CliError> {
    if let Some(part) = parts.iter().find(|part| same_file(part, output)) {
        return Err(CliError::Invalid(format!(
            "merge: refusing to write over {}, one of the files it merges; nothing written",
            ShownPath(part)
        )));
    }
    // Frame files or band parts, one kind at a time; a file that cannot be
    // opened is said so, not taken for a kind of file it is not.
    let frames = parts
        .iter()
        .map(|part| {
            is_frame_file(part)
                .map_err(|e| CliError::Io(format!("merge: cannot read {}: {e}; nothing written", ShownPath(part))))
        })
        .collect::<Result<Vec<bool>, _>>()?;
    if let Some(other) = frames.iter().position(|&frame| frame != frames[0]) {
        let kind = |frame: bool| if frame { "an animation's frame file" } else { "not a frame file" };
        return Err(CliError::Invalid(format!(
            "merge: {} is {} and {} {}: merge a still's band parts or an animation's frame files; nothing \
             written",
            ShownPath(&parts[0]),
            kind(frames[0]),
            ShownPath(&parts[other]),
            kind(frames[other])
        )));
    }
    match frames.first() == Some(&true) {
        true => merge_frames(output, parts, format, stderr),
        false => merge_parts(output, parts, format),
    }
}

/// A still's band parts stacked into the image `output` names.
fn merge_parts(output: &Path, parts: &[PathBuf], format: Option<Format>) -> Result<(), CliError> {
    let format = output_format(format, output).map_err(|e| match Output::of(output, None) {
        Ok(Output::Gif) => CliError::Invalid(format!(
            "merge: {}: a still's band parts merge into a {} image, and a GIF is assembled from an animation's \
             frame files; nothing written",
            ShownPath(output),
            Format::any_title()
        )),
        _ => e,
    })?;
    let refused = |e: MergeError| {
        let message = format!("merge: {e}; nothing written");
        match e {
            MergeError::Refused(_) => CliError::Invalid(message),
            MergeError::Io { .. } | MergeError::Output(_) => CliError::Io(message),
        }
    };
    let (ordered, header) = parts::check_parts(parts).map_err(refused)?;
    // A part that fails while its rows are read is the part's fault, not
    // the output's: kept aside from the write's own failures.
    let mut unread = None;
    let written = write_atomically(output, |f| match parts::write_merged(&ordered, &header, format, f) {
        Err(MergeError::Output(FormatError::Io(e))) => Err(e),
        Err(MergeError::Output(e)) => Err(std::io::Error::other(e)),
        Err(e) => {
            let message = e.to_string();
            unread = Some(e);
            Err(std::io::Error::other(message))
        }
        Ok(()) => Ok(()),
    });
    match (written, unread) {
        (_, Some(e)) => Err(refused(e)),
        (Err(e), None) => Err(CliError::Io(format!("merge: cannot write {}: {e}", ShownPath(output)))),
        (Ok(()), None) => Ok(()),
    }
}
