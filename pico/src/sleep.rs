//! A delay that sleeps the core until a timer alarm, where the HAL's
//! `Timer` reads the counter in a loop: for a panel's set-up waits (an
//! ST7789's take 300 ms), so that the core draws no current for them and
//! an emulator jumps over them instead of running 60 M cycles of polling.
//! Other interrupts wait until a sleep ends: use it where none matters
//! yet, as in a panel's set-up before the firmware's interrupts start.
//!
//! Invariants: interrupts stay masked (PRIMASK) while it sleeps, so the
//! alarm's interrupt only wakes the core (WFI wakes on a pending interrupt
//! that PRIMASK holds back) and no handler runs for it; the alarm's
//! interrupt is enabled in the NVIC only for the wait, and left neither
//! pending nor enabled; a wait shorter than [`SLEEP_FROM_US`], or without
//! the alarm, polls as the HAL does.

use cortex_m::asm::wfi;
use cortex_m::interrupt;
use embedded_hal::delay::DelayNs;
use rp2040_hal::fugit::MicrosDurationU32;
use rp2040_hal::pac::{Interrupt, NVIC};
use rp2040_hal::timer::{Alarm, Alarm3};
use rp2040_hal::Timer;

/// Waits under this many microseconds are polled: sleeping would cost more
/// than it saves.
pub const SLEEP_FROM_US: u32 = 20;

/// The interrupt of [`Alarm3`], the alarm a [`SleepingDelay`] takes.
const ALARM_INTERRUPT: Interrupt = Interrupt::TIMER_IRQ_3;

/// [`DelayNs`] that sleeps: give it to a driver's set-up in place of the
/// `Timer`. Takes the timer's alarm 3.
pub struct SleepingDelay {
    timer: Timer,
    /// None if alarm 3 was taken before: then every wait polls.
    alarm: Option<Alarm3>,
}

impl SleepingDelay {
    /// A delay on `timer`'s alarm 3 (one that polls, if the alarm was
    /// taken before).
    pub fn new(mut timer: Timer) -> SleepingDelay {
        SleepingDelay { alarm: timer.alarm_3(), timer }
    }
}

impl DelayNs for SleepingDelay {
    fn delay_ns(&mut self, ns: u32) {
        self.delay_us(ns.div_ceil(1000));
    }

    fn delay_us(&mut self, us: u32) {
        let Some(alarm) = self.alarm.as_mut().filter(|_| us >= SLEEP_FROM_US) else {
            return self.timer.delay_us(us);
        };
        interrupt::free(|_| {
            alarm.clear_interrupt();
            alarm.enable_interrupt();
            if alarm.schedule(MicrosDurationU32::micros(us)).is_ok() {
                // SAFETY: PRIMASK is set until the interrupt is masked and
                // unpended again, so its (absent) handler never runs.
                unsafe { NVIC::unmask(ALARM_INTERRUPT) };
                // An alarm that fires between the look and the WFI is
                // pending by then, and the WFI does not sleep.
                while !alarm.finished() {
                    wfi();
                }
                NVIC::mask(ALARM_INTERRUPT);
            } else {
                self.timer.delay_us(us);
            }
            alarm.disable_interrupt();
            alarm.clear_interrupt();
            NVIC::unpend(ALARM_INTERRUPT);
        });
    }
}
