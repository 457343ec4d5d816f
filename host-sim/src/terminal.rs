//! What host-sim shows on a terminal: progress bars, and text that comes
//! from outside (a board's) with its control characters escaped.
//!
//! Invariant: text from outside goes through [`shown`] before it reaches a
//! terminal, a file of messages or the studio's page, so that it cannot
//! move the cursor, recolour the screen or fake a line of host-sim's own.

use indicatif::{ProgressBar, ProgressStyle};
use octrace_core::parse::escaped_in_messages;
use std::io::IsTerminal;

/// A count of threads as a summary line says it: "1 thread", "2 threads".
pub(crate) struct Threads(pub usize);

impl std::fmt::Display for Threads {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} thread{}", self.0, if self.0 == 1 { "" } else { "s" })
    }
}

/// A progress bar of `total` steps on stderr, if it is a terminal and
/// the run is not `quiet`.
pub(crate) fn progress_bar(total: u64, quiet: bool) -> Option<ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent}%, eta {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    Some(bar)
}

/// `text` with every control character (a line's end and an escape
/// included) and every invisible character that reorders or hides text
/// written as its Unicode escape (`\u{1b}`), as octrace-core shows hostile
/// scene text ([`escaped_in_messages`]).
pub(crate) fn shown(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if escaped_in_messages(c) {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_shown_escaped() {
        assert_eq!(
            shown("red \u{1b}[31mtext\n\rhost-sim: ok\u{7}é"),
            "red \\u{1b}[31mtext\\u{a}\\u{d}host-sim: ok\\u{7}é"
        );
        // A name that shows reversed, or with a mark no one sees.
        assert_eq!(shown("scene\u{202e}txt.gpj\u{feff}"), "scene\\u{202e}txt.gpj\\u{feff}");
        assert_eq!(shown("plain"), "plain");
    }
}
