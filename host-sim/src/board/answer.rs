//! What a board says, as host-sim keeps it: its description, a scene's
//! errors, what it measured of a drawing, how it answered a scene, and
//! each step of a drawing as it comes.
//!
//! Invariant: the board's text (names, messages) is kept with its control
//! characters escaped ([`shown`]).

use crate::terminal::shown;
use octrace_link::{Counter, Panel, Timing};
use std::time::Duration;

/// What a board says it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoardDescription {
    pub panel: Panel,
    /// The longest scene text it takes, in bytes.
    pub max_scene: u32,
    /// Its capacity profile's name.
    pub profile: String,
    pub firmware: String,
    /// Its profile's capacities by `profile!` field name.
    pub capacities: Vec<(String, u32)>,
}

/// One error of a scene, as the board reported it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BoardSceneError {
    /// From 1; 0 for an error of the whole scene.
    pub line: u32,
    pub column: u32,
    /// For an error of capacity: its `profile!` field name, how many the
    /// scene needs (when the board knows) and how many the board holds.
    pub capacity: Option<(String, Option<u32>, u32)>,
    /// The message, as octrace-core writes it.
    pub message: String,
}

impl BoardSceneError {
    /// `file:line:col: message`, as host-sim prints its own errors.
    pub fn located(&self, file: &str) -> String {
        match self.line {
            0 => format!("{file}: {}", self.message),
            line => format!("{file}:{line}:{}: {}", self.column, self.message),
        }
    }
}

/// What a board measured of a scene it drew (the protocol's `done`): its
/// times by its own clock, and what its hardware counted over the load and
/// the render.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BoardTiming {
    /// From the scene received to its last row drawn.
    pub elapsed: Option<Duration>,
    /// Parsing and indexing the scene.
    pub load: Option<Duration>,
    /// Drawing it.
    pub render: Option<Duration>,
    /// Each counter: its name (control characters escaped), its count
    /// over the load and over the render.
    pub counters: Vec<(String, u32, u32)>,
}

impl BoardTiming {
    pub(crate) fn of(timing: &Timing<'_>) -> BoardTiming {
        BoardTiming {
            elapsed: timing.elapsed,
            load: timing.load,
            render: timing.render,
            counters: timing.counters.iter().map(|c| (shown(c.name), c.load, c.render)).collect(),
        }
    }

    /// "in 1.850 s by its clock (load 0.011 s, render 1.839 s; sram0_contested 12 + 3456, …)",
    /// or the host's time when the board has no clock.
    pub fn describe(&self, here: Duration) -> String {
        let seconds = |t: Duration| format!("{:.3} s", t.as_secs_f64());
        let mut text = match self.elapsed {
            Some(t) => format!("in {} by its clock", seconds(t)),
            None => format!("in {} here", seconds(here)),
        };
        let mut parts = Vec::new();
        if let (Some(load), Some(render)) = (self.load, self.render) {
            parts.push(format!("load {}, render {}", seconds(load), seconds(render)));
        }
        if !self.counters.is_empty() {
            let count = |n: u32| match n {
                Counter::RAN_OVER => "(ran over)".to_string(),
                n => n.to_string(),
            };
            let counters: Vec<_> = self
                .counters
                .iter()
                .map(|&(ref name, load, render)| format!("{name} {} + {}", count(load), count(render)))
                .collect();
            parts.push(counters.join(", "));
        }
        if !parts.is_empty() {
            text.push_str(&format!(" ({})", parts.join("; ")));
        }
        text
    }
}

/// How the board answered a scene.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Answer {
    /// It drew the scene at its panel's size, and measured it so.
    Drawn { panel: Panel, timing: BoardTiming },
    /// It played the animation at its panel's size: the frames followed,
    /// in order, before host-sim stopped it.
    Played { panel: Panel, frames: Vec<PlayedFrame> },
    /// The scene has errors (all of them, in the order found); nothing drawn.
    Rejected(Vec<BoardSceneError>),
}

/// A frame of an animation the board drew whole.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlayedFrame {
    /// Which, from 0.
    pub frame: u32,
    /// Pixels the board traced for it.
    pub traced: u32,
    /// Its time by the board's clock, if it has one.
    pub elapsed: Option<Duration>,
}

/// What happens while a board draws.
#[derive(Debug)]
pub enum Progress<'a> {
    /// The scene loaded; its rows follow.
    Drawing(Panel),
    /// Row `y` is drawn: its pixels in the panel's format, if asked for.
    Row { y: u16, pixels: &'a [u8] },
    /// The scene is an animation of `frames` frames; its runs follow.
    Playing { panel: Panel, frames: u32 },
    /// A run of row `y` from column `x` of the frame being played is
    /// drawn: its pixels in the panel's format, if asked for.
    Run { y: u16, x: u16, pixels: &'a [u8] },
    /// A frame is whole: every run of it has come.
    FrameDrawn(PlayedFrame),
    /// The board is still working, though it sent nothing else for a
    /// while: `elapsed` into the request by its clock, if it has one.
    Working { elapsed: Option<Duration> },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_count_that_ran_over_is_said_so_and_not_shown_as_a_number() {
        let ms = Duration::from_millis;
        let timing = BoardTiming {
            elapsed: Some(ms(1850)),
            load: Some(ms(11)),
            render: Some(ms(1839)),
            counters: vec![("sram0_contested".into(), 12, Counter::RAN_OVER), ("sram1_contested".into(), 0, 3456)],
        };
        assert_eq!(
            timing.describe(Duration::ZERO),
            "in 1.850 s by its clock (load 0.011 s, render 1.839 s; \
             sram0_contested 12 + (ran over), sram1_contested 0 + 3456)"
        );
    }
}
