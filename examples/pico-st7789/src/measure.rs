//! What a firmware measures of a scene, so that a real Pico can be set
//! beside the emulated one: how long the load (parse and index) and the
//! render took by the TIMER (a microsecond a tick, RP2040 datasheet 4.6),
//! and how many accesses to the four striped SRAM banks waited for the
//! other core at the bus fabric over each (BUSCTRL's performance counters,
//! events `sram0_contested` to `sram3_contested`, 2.1.1.2).
//!
//! Invariants: the [`Meter`] owns BUSCTRL, so nothing else changes its
//! events; each [`Span`] covers the time since the meter's last `start` or
//! `split`, its counts cleared at the span's start; the counters are 24
//! bits and saturate (fig5_1's render, the longest measured, counts under
//! 6 M a bank).

use core::fmt;
use rp2040_hal::{pac, Timer};

/// The counters' events, in BUSCTRL's names: SRAM0 to SRAM3's contested accesses.
pub const EVENTS: [&str; 4] = ["sram0_contested", "sram1_contested", "sram2_contested", "sram3_contested"];

/// A stretch of a scene's life: its time and its contested accesses to each striped bank.
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
}

impl Meter {
    /// Takes the timer and BUSCTRL, and sets the four counters to
    /// [`EVENTS`].
    pub fn new(timer: Timer, busctrl: pac::BUSCTRL) -> Meter {
        busctrl.perfsel0().write(|w| w.perfsel0().sram0_contested());
        busctrl.perfsel1().write(|w| w.perfsel1().sram1_contested());
        busctrl.perfsel2().write(|w| w.perfsel2().sram2_contested());
        busctrl.perfsel3().write(|w| w.perfsel3().sram3_contested());
        Meter { timer, busctrl, since: 0 }
    }

    /// A span starts now.
    pub fn start(&mut self) {
        self.clear();
        self.since = self.timer.get_counter().ticks();
    }

    /// The span since the last `start` or `split`; the next starts now.
    pub fn split(&mut self) -> Span {
        let now = self.timer.get_counter().ticks();
        let bus = &self.busctrl;
        let contested = [
            bus.perfctr0().read().perfctr0().bits(),
            bus.perfctr1().read().perfctr1().bits(),
            bus.perfctr2().read().perfctr2().bits(),
            bus.perfctr3().read().perfctr3().bits(),
        ];
        self.clear();
        let micros = now - self.since;
        self.since = now;
        Span { micros, contested }
    }

    fn clear(&mut self) {
        // Any write clears a counter: its reset value, say.
        let bus = &self.busctrl;
        bus.perfctr0().reset();
        bus.perfctr1().reset();
        bus.perfctr2().reset();
        bus.perfctr3().reset();
    }
}

/// What the embedded-scene firmware says of its scene, one line: its
/// name, the scene's, the load's and the render's microseconds and their
/// contested accesses bank by bank, as `key=value` words:
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
