//! The studio's "Send to board": `POST /board` sends the editor's text to
//! the board `--board` names, through what `host-sim board --check` sends
//! and compares with, and answers with the board's errors or its picture
//! and verdict; `GET /board` names the board and how far its drawing is.
//!
//! Invariants: one send at a time (another is refused as busy, never
//! queued, so two never interleave on the port); a send waits for the
//! board as `host-sim board` does (as long as it keeps drawing, or says it
//! is still working; given up when it falls silent, after
//! `--board-patience` times the usual allowance; capped only by
//! `--board-timeout`); the errors are the board's, at the line and column
//! it gave; the verdict is the count of pixels that differ from host-sim's
//! render at the board's panel size.

use super::http::Response;
use crate::board::{differing_pixels, send_scene, BoardTiming, Progress, Sent, Waits};
use crate::exit::CliError;
use crate::terminal::shown;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::time::Instant;

/// The board the studio sends to, and its send under way.
pub(crate) struct BoardSender {
    port: String,
    /// How long a send waits for the board.
    waits: Waits,
    /// Whether a send is under way; set and cleared by [`Claim`].
    busy: AtomicBool,
    /// The drawing under way (or the last): rows received, of how many.
    rows: AtomicU32,
    height: AtomicU32,
    /// When the board last said it was still working: milliseconds into
    /// the drawing by its clock ([`NOT_WORKING`]: not in this drawing).
    working_ms: AtomicU64,
}

/// `working_ms` of a drawing the board has not said it is working on.
const NOT_WORKING: u64 = u64::MAX;

/// A send's hold on the board, let go when dropped (a failed send too).
struct Claim<'a>(&'a AtomicBool);

impl Drop for Claim<'_> {
    fn drop(&mut self) {
        self.0.store(false, Ordering::SeqCst);
    }
}

impl BoardSender {
    pub(crate) fn new(port: String, waits: Waits) -> BoardSender {
        BoardSender {
            port,
            waits,
            busy: AtomicBool::new(false),
            rows: AtomicU32::new(0),
            height: AtomicU32::new(0),
            working_ms: AtomicU64::new(NOT_WORKING),
        }
    }

    pub(crate) fn port(&self) -> &str {
        &self.port
    }

    /// `GET /board`: the port, whether a send is under way, its rows, and
    /// when the board last said it was still working (seconds into the
    /// drawing by its clock, or null).
    pub(crate) fn status(&self) -> Response {
        let working = match self.working_ms.load(Ordering::SeqCst) {
            NOT_WORKING => "null".to_string(),
            ms => format!("{:.3}", ms as f64 / 1000.0),
        };
        let body = format!(
            "{{\"port\":{},\"busy\":{},\"rows\":{},\"height\":{},\"working\":{working}}}",
            json_string(&self.port),
            self.busy.load(Ordering::SeqCst),
            self.rows.load(Ordering::SeqCst),
            self.height.load(Ordering::SeqCst)
        );
        Response::new(200, "application/json", body.into_bytes())
    }

    /// `POST /board`: sends scene `text` (called `name` in messages) and
    /// answers with the board's errors, or its picture and verdict.
    pub(crate) fn send(&self, name: &str, text: &[u8]) -> Response {
        if self.busy.compare_exchange(false, true, Ordering::SeqCst, Ordering::SeqCst).is_err() {
            return Response::text(
                409,
                &format!(
                    "busy: the board at {} is still answering an earlier send; send again when it is done",
                    shown(&self.port)
                ),
            );
        }
        let _claim = Claim(&self.busy);
        self.rows.store(0, Ordering::SeqCst);
        self.height.store(0, Ordering::SeqCst);
        self.working_ms.store(NOT_WORKING, Ordering::SeqCst);
        let started = Instant::now();
        // An animation: its first frame (the scene as a still), then the
        // board is stopped.
        let sent = send_scene(&self.port, self.waits, name, text, true, 1, &mut |step| match step {
            Progress::Drawing(panel) | Progress::Playing { panel, .. } => {
                self.height.store(panel.height.into(), Ordering::SeqCst)
            }
            Progress::Row { .. } => {
                self.rows.fetch_add(1, Ordering::SeqCst);
            }
            Progress::FrameDrawn(_) => self.rows.store(self.height.load(Ordering::SeqCst), Ordering::SeqCst),
            Progress::Working { elapsed } => {
                let ms = elapsed.map_or(0, |t| u64::try_from(t.as_millis()).unwrap_or(u64::MAX));
                self.working_ms.store(ms.min(NOT_WORKING - 1), Ordering::SeqCst);
            }
            Progress::Run { .. } => {}
        });
        let sent = sent.map(|sent| match sent {
            Sent::Played { panel, mut frames } if !frames.is_empty() => {
                let (first, picture) = frames.swap_remove(0);
                let timing = BoardTiming { elapsed: first.elapsed, load: None, render: None, counters: Vec::new() };
                Sent::Drawn { panel, timing, picture }
            }
            other => other,
        });
        let body = match sent {
            // Not the board's fault: the scene is longer than it takes.
            Err(e @ CliError::Invalid(_)) => return Response::text(422, &message(e)),
            Err(e) => return Response::text(502, &message(e)),
            Ok(Sent::Rejected(errors)) => {
                let errors: Vec<String> = errors
                    .iter()
                    .map(|e| {
                        format!(
                            "{{\"line\":{},\"column\":{},\"message\":{}}}",
                            e.line,
                            e.column,
                            json_string(&e.message)
                        )
                    })
                    .collect();
                format!("{{\"answer\":\"rejected\",\"errors\":[{}]}}", errors.join(","))
            }
            Ok(Sent::Drawn { panel, timing, picture: Some(picture) }) => {
                let (seconds, clock) = match timing.elapsed {
                    Some(elapsed) => (elapsed.as_secs_f64(), "board"),
                    None => (started.elapsed().as_secs_f64(), "host"),
                };
                let (differ, problem) = match differing_pixels(name, text, 0, panel, &picture) {
                    Ok(differ) => (differ.to_string(), "null".to_string()),
                    Err(e) => ("null".to_string(), json_string(&message(e))),
                };
                format!(
                    "{{\"answer\":\"drawn\",\"width\":{},\"height\":{},\"format\":\"{}\",\"seconds\":{seconds:.3},\
                     \"clock\":\"{clock}\",\"differ\":{differ},\"problem\":{problem},\"rgb\":\"{}\"}}",
                    panel.width,
                    panel.height,
                    panel.format,
                    base64(&picture.data)
                )
            }
            Ok(Sent::Drawn { picture: None, .. } | Sent::Played { .. }) => {
                return Response::text(502, &format!("the board at {} drew without its pixels", shown(&self.port)));
            }
        };
        Response::new(200, "application/json", body.into_bytes())
    }
}

/// What `e` says, without the `host-sim:` a terminal gets.
fn message(e: CliError) -> String {
    match e {
        CliError::Io(message) | CliError::Invalid(message) | CliError::Mismatch(message) => message,
        CliError::Scene { errors, .. } => errors.join("\n"),
        CliError::Stopped(signal) => format!("stopped ({signal})"),
    }
}

/// `text` as a JSON string, quotes included.
fn json_string(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Standard base64 with padding: how the picture's RGB bytes travel in
/// the JSON answer.
fn base64(bytes: &[u8]) -> String {
    const SYMBOLS: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let bits = chunk.iter().enumerate().fold(0u32, |acc, (i, &b)| acc | u32::from(b) << (16 - 8 * i));
        for i in 0..4 {
            out.push(if i <= chunk.len() { SYMBOLS[(bits >> (18 - 6 * i)) as usize & 63] as char } else { '=' });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_strings_escape_what_json_needs() {
        assert_eq!(json_string("a \"b\" \\ c\nd\u{1}é"), r#""a \"b\" \\ c\nd\u0001é""#);
    }

    #[test]
    fn base64_pads_as_the_standard_says() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"h"), "aA==");
        assert_eq!(base64(b"he"), "aGU=");
        assert_eq!(base64(b"hello"), "aGVsbG8=");
        assert_eq!(base64(&[0, 255, 0]), "AP8A");
    }
}
