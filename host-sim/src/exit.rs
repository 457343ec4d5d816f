//! How a host-sim command fails: [`CliError`], whose exit code is derived in
//! one place ([`CliError::exit_code`]): 0 done, 1 a file could not be read
//! or written (or a board talked to), 2 a bad scene or bad arguments, 3 a
//! board's picture that differs from host-sim's, 128 + the signal for a
//! run a signal stopped (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP, as a shell
//! reports a process the signal ended).

use crate::signals::{self, StopSignal};
use std::fmt;
use std::path::Path;

/// Exit code for a bad scene or bad arguments.
pub const EXIT_SCENE: i32 = 2;
/// Exit code for a file that cannot be read or written, or a board that
/// cannot be talked to.
pub const EXIT_IO: i32 = 1;
/// Exit code for a board's picture that differs from host-sim's
/// (`host-sim board --check`).
pub const EXIT_MISMATCH: i32 = 3;
/// Exit code for a render Ctrl-C stopped (SIGTERM and SIGHUP: [`StopSignal::exit_code`]).
pub const EXIT_STOPPED: i32 = 130;

/// Why a command stopped; printed to stderr as it is displayed.
#[derive(Debug)]
pub enum CliError {
    /// A file could not be read or written, or a board talked to; the
    /// message says which and why.
    Io(String),
    /// The arguments, or an input other than a scene, are not usable.
    Invalid(String),
    /// The scene file has errors, each `file:line:col: message`.
    Scene { file: String, errors: Vec<String> },
    /// A board's picture is not host-sim's; the message says how.
    Mismatch(String),
    /// A signal (Ctrl-C, SIGTERM, SIGHUP) stopped the render; nothing was
    /// written.
    Stopped(StopSignal),
}

impl CliError {
    /// `path` could not be read.
    pub fn read(path: &Path, error: impl fmt::Display) -> CliError {
        CliError::Io(format!("cannot read {}: {error}", ShownPath(path)))
    }

    /// `path` could not be written; a stop signal that arrived meanwhile
    /// (which cut the wait for a FIFO's reader, say) is reported as such.
    pub fn write(path: &Path, error: impl fmt::Display) -> CliError {
        if signals::stop_requested() {
            return CliError::stopped();
        }
        CliError::Io(format!("cannot write {}: {error}", ShownPath(path)))
    }

    /// A run stopped by the signal that arrived.
    pub fn stopped() -> CliError {
        CliError::Stopped(signals::arrived())
    }

    /// The process's exit code for this error.
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::Io(_) => EXIT_IO,
            CliError::Invalid(_) | CliError::Scene { .. } => EXIT_SCENE,
            CliError::Mismatch(_) => EXIT_MISMATCH,
            CliError::Stopped(signal) => signal.exit_code(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Io(message) | CliError::Invalid(message) | CliError::Mismatch(message) => {
                write!(f, "host-sim: {message}")
            }
            CliError::Scene { file, errors } => {
                for error in errors {
                    writeln!(f, "{error}")?;
                }
                write!(f, "host-sim: {} error(s) in {file}; nothing rendered", errors.len())
            }
            CliError::Stopped(signal) => write!(f, "host-sim: stopped ({signal}); nothing written"),
        }
    }
}

impl std::error::Error for CliError {}

/// A path as a message shows it: its control characters and invisible
/// reordering ones escaped (`\u{1b}`, `\u{202e}`), as any text from
/// outside is shown, so that a name from a scene's IMAGEFILE cannot drive
/// the terminal or show another name.
pub struct ShownPath<'a>(pub &'a Path);

impl fmt::Display for ShownPath<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&crate::terminal::shown(&self.0.to_string_lossy()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_is_shown_with_what_would_hide_or_reorder_it_escaped() {
        let shown = |name: &str| ShownPath(Path::new(name)).to_string();
        assert_eq!(shown("out\u{1b}[2J.png"), "out\\u{1b}[2J.png");
        assert_eq!(shown("\u{feff}gnp.\u{202e}exe.png"), "\\u{feff}gnp.\\u{202e}exe.png");
        assert_eq!(shown("frames/é%04d.png"), "frames/é%04d.png");
    }
}
