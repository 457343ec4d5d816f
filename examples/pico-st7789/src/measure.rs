//! What a firmware measures of a scene, so that a real Pico can be set
//! beside the emulated one: how long the load (parse and index) and the
//! render took by the TIMER (a microsecond a tick, RP2040 datasheet 4.6),
//! and how many accesses to the four striped SRAM banks waited for the
//! other core at the bus fabric over each (BUSCTRL's performance counters,
//! events `sram0_contested` to `sram3_contested`, 2.1.1.2).
//!
//! Invariants: the [`Meter`] owns BUSCTRL, so nothing else changes its
//! events; each [`Span`] covers the time since the meter's last `start` or
//! `split`, its counts cleared at the span's start. The counters are 24
//! bits and saturate (fig5_1's render counts under 6 M a bank, a scene
//! drawn for minutes far more): [`Meter::fold`], called more often than
//! they can fill, adds them into 32-bit counts, and a count that ran over
//! (a counter full at a fold, or a sum past 32 bits) is [`RAN_OVER`],
//! never a smaller number.

use core::fmt;
use rp2040_hal::{pac, Timer};

/// The counters' events, in BUSCTRL's names: SRAM0 to SRAM3's contested accesses.
pub const EVENTS: [&str; 4] = ["sram0_contested", "sram1_contested", "sram2_contested", "sram3_contested"];

/// A [`Span`]'s count that ran over: more accesses than it can say (the
/// board protocol's own mark, which the live firmware sends as it is).
pub const RAN_OVER: u32 = octrace_link::Counter::RAN_OVER;

/// What a counter holds once full: it counts no further.
const COUNTER_FULL: u32 = (1 << 24) - 1;

/// A stretch of a scene's life: its time and its contested accesses to
/// each striped bank ([`RAN_OVER`] for a count that ran over).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Span {
    pub micros: u64,
    pub contested: [u32; 4],
}

/// The TIMER and BUSCTRL, measuring [`Span`]s.
pub struct Meter {
    timer: Timer,
    busctrl: pac::BUSCTRL,
    since: u64,
    /// What the counters counted in this span before their last fold.
    folded: [u32; 4],
}

impl Meter {
    /// Takes the timer and BUSCTRL, and sets the four counters to
    /// [`EVENTS`].
    pub fn new(timer: Timer, busctrl: pac::BUSCTRL) -> Meter {
        busctrl.perfsel0().write(|w| w.perfsel0().sram0_contested());
        busctrl.perfsel1().write(|w| w.perfsel1().sram1_contested());
        busctrl.perfsel2().write(|w| w.perfsel2().sram2_contested());
        busctrl.perfsel3().write(|w| w.perfsel3().sram3_contested());
        Meter { timer, busctrl, since: 0, folded: [0; 4] }
    }

    /// A span starts now.
    pub fn start(&mut self) {
        self.fold();
        self.folded = [0; 4];
        self.since = self.timer.get_counter().ticks();
    }

    /// The span since the last `start` or `split`; the next starts now.
    pub fn split(&mut self) -> Span {
        let now = self.timer.get_counter().ticks();
        self.fold();
        let contested = core::mem::take(&mut self.folded);
        let micros = now - self.since;
        self.since = now;
        Span { micros, contested }
    }

    /// Adds what the counters counted to the span's counts and clears
    /// them: needed at least every 84 ms (2^24 contested accesses at
    /// 200 MHz) for counts that never run over. An access between a
    /// counter's read and its clearing, a few cycles, goes uncounted.
    pub fn fold(&mut self) {
        let bus = &self.busctrl;
        // Each read and cleared at once (any write clears a counter: its
        // reset value, say), so that little goes uncounted in between.
        let mut counted = [0; 4];
        counted[0] = bus.perfctr0().read().perfctr0().bits();
        bus.perfctr0().reset();
        counted[1] = bus.perfctr1().read().perfctr1().bits();
        bus.perfctr1().reset();
        counted[2] = bus.perfctr2().read().perfctr2().bits();
        bus.perfctr2().reset();
        counted[3] = bus.perfctr3().read().perfctr3().bits();
        bus.perfctr3().reset();
        for (sum, count) in self.folded.iter_mut().zip(counted) {
            *sum = match count {
                COUNTER_FULL => RAN_OVER,
                _ => sum.saturating_add(count),
            };
        }
    }
}

/// What the embedded-scene firmware says of its scene, one line: its
/// name, the scene's, the load's and the render's microseconds and their
/// contested accesses bank by bank (4294967295, [`RAN_OVER`], for a count
/// that ran over), as `key=value` words:
///
/// `octrace-pico-st7789 0.1.0 scene=fig5_1 load_us=10731 render_us=1838270 load_contested=1,2,3,4 render_contested=5,6,7,8`
pub struct Report<'a> {
    pub firmware: &'a str,
    pub scene: &'a str,
    pub load: Span,
    pub render: Span,
}

impl fmt::Display for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let counts = |f: &mut fmt::Formatter<'_>, key: &str, span: &Span| {
            let [a, b, c, d] = span.contested;
            write!(f, " {key}={a},{b},{c},{d}")
        };
        write!(
            f,
            "{} scene={} load_us={} render_us={}",
            self.firmware, self.scene, self.load.micros, self.render.micros
        )?;
        counts(f, "load_contested", &self.load)?;
        counts(f, "render_contested", &self.render)
    }
}
