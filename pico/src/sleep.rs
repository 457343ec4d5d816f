//! Sleeping on a timer alarm where the HAL's `Timer` reads the counter in
//! a loop, so that the core draws no current and an emulator jumps over
//! the wait instead of running its polling: [`SleepingDelay`] for a
//! panel's set-up waits (an ST7789's take 300 ms), [`Nap`] for a firmware
//! that waits for something an interrupt brings (its host taking bytes)
//! but must look at its clock now and then. Other interrupts wait until a
//! delay ends: use it where none matters yet, as in a panel's set-up
//! before the firmware's interrupts start; a nap ends at any interrupt.
//!
//! Invariants: interrupts stay masked (PRIMASK) while the core sleeps, so
//! the alarm's interrupt only wakes it (WFI wakes on a pending interrupt
//! that PRIMASK holds back) and no handler runs for it; the alarm's
//! interrupt is enabled in the NVIC only for the wait, and left neither
//! pending nor enabled; a delay shorter than [`SLEEP_FROM_US`], or without
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

/// The interrupt of [`Alarm3`], the alarm a [`SleepingDelay`] or a [`Nap`] takes.
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
        // An alarm that fires between the look and the WFI is pending by
        // then, and the WFI does not sleep.
        let slept = on_alarm(alarm, us, |alarm| {
            while !alarm.finished() {
                wfi();
            }
        });
        if !slept {
            self.timer.delay_us(us);
        }
    }
}

/// Sleeps the core until an interrupt comes or a time has passed. Takes
/// the timer's alarm 3 (free again once the nap is dropped).
pub struct Nap {
    alarm: Alarm3,
}

impl Nap {
    /// A nap on `timer`'s alarm 3; None if it is taken (a
    /// [`SleepingDelay`] that still lives).
    pub fn new(timer: &mut Timer) -> Option<Nap> {
        timer.alarm_3().map(|alarm| Nap { alarm })
    }

    /// Sleeps until an interrupt that the NVIC lets through is pending, or
    /// for `us` microseconds, if `still()` says to; returns at once
    /// otherwise (and when the alarm cannot be set). `still` is asked with
    /// interrupts masked, so an interrupt that would change its answer
    /// wakes the core instead of coming unseen before the sleep; the
    /// interrupt's handler runs once the nap is over.
    pub fn at_most(&mut self, us: u32, still: impl FnOnce() -> bool) {
        on_alarm(&mut self.alarm, us, |_| {
            if still() {
                wfi();
            }
        });
    }
}

/// Runs `sleep` with interrupts masked and `alarm` set to fire in `us`
/// microseconds, its interrupt able to wake the core; false, and `sleep`
/// not run, if the alarm could not be set.
fn on_alarm(alarm: &mut Alarm3, us: u32, sleep: impl FnOnce(&mut Alarm3)) -> bool {
    interrupt::free(|_| {
        alarm.clear_interrupt();
        alarm.enable_interrupt();
        let scheduled = alarm.schedule(MicrosDurationU32::micros(us)).is_ok();
        if scheduled {
            // SAFETY: PRIMASK is set until the interrupt is masked and
            // unpended again, so its (absent) handler never runs.
            unsafe { NVIC::unmask(ALARM_INTERRUPT) };
            sleep(alarm);
            NVIC::mask(ALARM_INTERRUPT);
        }
        alarm.disable_interrupt();
        alarm.clear_interrupt();
        NVIC::unpend(ALARM_INTERRUPT);
        scheduled
    })
}
