//! How long the host waits for a board (docs/board-protocol.md, Timing): a
//! deadline on silence and on progress, not on the conversation's length.
//! A board that keeps moving the conversation on (taking host-sim's bytes,
//! sending rows and runs, saying it is still working) is waited for as
//! long as it does; one that stops is given up after [`SILENCE`] (or
//! [`LOADING`] while it may be loading a scene, which it does without a
//! word), each times the [`Waits::patience`] asked for (`--patience`, for
//! an emulated board on a busy machine), with what it last did.
//!
//! Invariants: only progress restarts the wait, so frames that are not
//! progress (scene errors, frames skipped, runs after the hello that stops
//! an animation) cannot keep a conversation going; the wait never outlasts
//! the cap (`--timeout`) when one is set; every deadline is read on the
//! port's clock ([`super::Port::now`]), so that tests can run it on their own.

use std::fmt;
use std::time::{Duration, Instant};

/// The longest a board may say nothing that moves the conversation on,
/// where it can speak: 8 s. A board at work speaks at least every 40 ms of
/// its clock and a ray (a row, a run, or `working`), so this is 200 times
/// that: room for an emulated board a hundred times slower than a Pico on
/// a busy machine, and a board gone silent is still reported within 10 s.
pub const SILENCE: Duration = Duration::from_secs(8);

/// The longest a board may say nothing while it may be loading a scene
/// (parsing it, building its octree and light buffer, none of which is
/// interrupted): 120 s. The live firmware loads the dearest scene it holds
/// in 5.2 s of its clock, and its watchdog ends a load past 8 s; an
/// emulated board on a busy machine takes a hundred times longer.
pub const LOADING: Duration = Duration::from_secs(120);

/// How long host-sim waits for a board: at most `cap` for the whole
/// conversation (`--timeout`), if set, and `patience` times [`SILENCE`]
/// and [`LOADING`] for a board that says nothing (`--patience`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Waits {
    /// The most the whole conversation may take.
    pub cap: Option<Duration>,
    /// How many times the allowances a board may say nothing: 1 for a
    /// board at a real board's speed.
    pub patience: u32,
}

impl Waits {
    /// A real board's: no cap, the allowances as they are.
    pub const BOARD: Waits = Waits { cap: None, patience: 1 };

    /// [`Waits::BOARD`] with a cap of `cap`.
    pub fn capped(cap: Option<Duration>) -> Waits {
        Waits { cap, ..Waits::BOARD }
    }
}

/// What the board last did that moved the conversation on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Step {
    /// Nothing yet: the port was just opened.
    Opened,
    /// It took `taken` bytes of host-sim's frame of `of` bytes.
    Took { taken: usize, of: usize },
    /// It described itself.
    Described,
    /// It took the scene's last byte: it loads the scene.
    TookScene,
    /// It began drawing the scene, of `rows` rows.
    Began { rows: u16 },
    /// It began playing the animation of `frames` frames: it loads the first.
    Playing { frames: u32 },
    /// Row `y` came, the `drawn`th of `rows`.
    Row { y: u16, drawn: usize, rows: u16 },
    /// It said it was still working, `elapsed` into the request by its clock.
    Working { elapsed: Option<Duration> },
    /// A run of row `y` of frame `frame` came.
    Run { y: u16, frame: u32 },
    /// Frame `frame` was drawn whole: it loads the next.
    FrameDrawn { frame: u32 },
    /// It took the hello that stops the animation.
    TookStop,
    /// It stopped the animation.
    Stopped,
}

impl fmt::Display for Step {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Step::Opened => write!(f, "the port was opened"),
            Step::Took { taken, of } => write!(f, "it took {taken} of the {of} bytes host-sim sent"),
            Step::Described => write!(f, "it described itself"),
            Step::TookScene => write!(f, "it took the scene (a board loads a scene without a word)"),
            Step::Began { rows } => write!(f, "it began drawing the scene's {rows} rows"),
            Step::Playing { frames } => {
                write!(f, "it began playing the animation's {frames} frames (a board loads each without a word)")
            }
            Step::Row { y, drawn, rows } => write!(f, "row {y} ({drawn} of {rows} rows drawn)"),
            Step::Working { elapsed: Some(t) } => {
                write!(f, "it said it was still working, {:.3} s into the scene by its clock", t.as_secs_f64())
            }
            Step::Working { elapsed: None } => write!(f, "it said it was still working"),
            Step::Run { y, frame } => write!(f, "a run of row {y} of frame {frame}"),
            Step::FrameDrawn { frame } => write!(f, "frame {frame} was drawn (a board loads the next without a word)"),
            Step::TookStop => write!(f, "it took the hello that stops the animation"),
            Step::Stopped => write!(f, "it stopped the animation"),
        }
    }
}

/// Why waiting for the board ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Expired {
    /// The board said nothing that moved the conversation on for `waited`
    /// after `after`, and sent `idle` frames meanwhile that did not.
    Silent { waited: Duration, after: Step, idle: u64 },
    /// The cap on the whole conversation (`--timeout`) came.
    Capped(Duration),
}

/// The wait on one conversation.
#[derive(Debug)]
pub(crate) struct Patience {
    /// When the board last moved the conversation on (or the port opened),
    /// and what it did.
    since: Instant,
    last: Step,
    /// How long it may now say nothing that moves it on.
    allowance: Duration,
    /// What each allowance is multiplied by.
    patience: u32,
    /// Frames since then that did not.
    idle: u64,
    /// When the whole conversation must end, if capped, and the cap.
    cap: Option<(Instant, Duration)>,
}

impl Patience {
    /// The wait from `now`, the port just opened: [`SILENCE`] for the
    /// board's first word (times the patience), and the cap on the whole,
    /// if any.
    pub(crate) fn new(now: Instant, waits: Waits) -> Patience {
        let patience = waits.patience.max(1);
        Patience {
            since: now,
            last: Step::Opened,
            allowance: SILENCE.saturating_mul(patience),
            patience,
            idle: 0,
            cap: waits.cap.map(|cap| (now + cap, cap)),
        }
    }

    /// The board did `step` at `now`; from then it may say nothing that
    /// moves the conversation on for `allowance` (times the patience).
    pub(crate) fn moved(&mut self, now: Instant, step: Step, allowance: Duration) {
        let allowance = allowance.saturating_mul(self.patience);
        (self.since, self.last, self.allowance, self.idle) = (now, step, allowance, 0);
    }

    /// The board sent a frame that does not move the conversation on.
    pub(crate) fn idle_frame(&mut self) {
        self.idle = self.idle.saturating_add(1);
    }

    /// What the board last did.
    pub(crate) fn last(&self) -> Step {
        self.last
    }

    /// Whether the wait has ended at `now`, and why.
    pub(crate) fn expired(&self, now: Instant) -> Option<Expired> {
        if let Some((end, cap)) = self.cap {
            if now >= end && end <= self.since + self.allowance {
                return Some(Expired::Capped(cap));
            }
        }
        (now >= self.since + self.allowance).then_some(Expired::Silent {
            waited: self.allowance,
            after: self.last,
            idle: self.idle,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_restarts_the_wait_and_nothing_else_does() {
        let start = Instant::now();
        let at = |ms| start + Duration::from_millis(ms);
        let mut patience = Patience::new(start, Waits::BOARD);
        assert_eq!(patience.expired(at(7_999)), None);
        let silent = Expired::Silent { waited: SILENCE, after: Step::Opened, idle: 0 };
        assert_eq!(patience.expired(at(8_000)), Some(silent));
        patience.moved(at(5_000), Step::Described, SILENCE);
        for _ in 0..1000 {
            patience.idle_frame();
        }
        assert_eq!(patience.expired(at(12_999)), None);
        let silent = Expired::Silent { waited: SILENCE, after: Step::Described, idle: 1000 };
        assert_eq!(patience.expired(at(13_000)), Some(silent));
        patience.moved(at(13_000), Step::TookScene, LOADING);
        assert_eq!(patience.expired(at(132_999)), None);
        assert!(patience.expired(at(133_000)).is_some());
    }

    #[test]
    fn patience_multiplies_every_allowance() {
        let start = Instant::now();
        let at = |s| start + Duration::from_secs(s);
        let mut patience = Patience::new(start, Waits { cap: None, patience: 5 });
        assert_eq!(patience.expired(at(39)), None);
        let silent = Expired::Silent { waited: SILENCE * 5, after: Step::Opened, idle: 0 };
        assert_eq!(patience.expired(at(40)), Some(silent));
        patience.moved(at(40), Step::TookScene, LOADING);
        assert_eq!(patience.expired(at(639)), None);
        assert!(patience.expired(at(640)).is_some());
    }

    #[test]
    fn the_cap_ends_the_conversation_however_the_board_moves_it_on() {
        let start = Instant::now();
        let at = |ms| start + Duration::from_millis(ms);
        let mut patience = Patience::new(start, Waits::capped(Some(Duration::from_secs(2))));
        for ms in (0..2_000).step_by(10) {
            patience.moved(at(ms), Step::Row { y: 0, drawn: 1, rows: 2 }, SILENCE);
            assert_eq!(patience.expired(at(ms)), None);
        }
        assert_eq!(patience.expired(at(2_000)), Some(Expired::Capped(Duration::from_secs(2))));
        // Silent before the cap: said as silence.
        let patience = Patience::new(start, Waits::capped(Some(Duration::from_secs(60))));
        let silent = Expired::Silent { waited: SILENCE, after: Step::Opened, idle: 0 };
        assert_eq!(patience.expired(at(8_000)), Some(silent));
    }
}
