//! The signals that stop host-sim cleanly: Ctrl-C (SIGINT), SIGTERM (what
//! `kill`, `timeout` and job schedulers such as Slurm send) and SIGHUP (the
//! terminal closed). Each sets one flag, which a render, an animation and
//! the studio ask between rays; the run then ends as it does on any error,
//! its temporary file removed, with 128 + the signal's number as its exit
//! code (what a shell reports for a process the signal ended).
//!
//! Invariant: the handlers are installed once per process, when the flag
//! is first asked for; from then on the first of these signals never ends
//! the process mid-write. A second one does, at once, with the same exit
//! code (what a user whose first was not heard, a blocked write, asks),
//! having removed the temporary files being written ([`Unfinished`]): no
//! partial file is left however many signals come. The same signal sent
//! twice at once (`timeout` signals host-sim, then its process group)
//! counts once.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

/// A signal that stops a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopSignal {
    /// SIGINT: Ctrl-C in the terminal.
    Interrupt,
    /// SIGTERM: `kill`, `timeout`, a job scheduler.
    Terminate,
    /// SIGHUP: the terminal closed.
    HangUp,
}

impl StopSignal {
    /// The signals handled where this build runs (Windows has no SIGHUP).
    const HANDLED: &'static [StopSignal] = &[
        StopSignal::Interrupt,
        StopSignal::Terminate,
        #[cfg(unix)]
        StopSignal::HangUp,
    ];

    /// Its number (2, 15, 1 on Linux).
    pub fn number(self) -> i32 {
        match self {
            StopSignal::Interrupt => signal_hook::consts::SIGINT,
            StopSignal::Terminate => signal_hook::consts::SIGTERM,
            #[cfg(unix)]
            StopSignal::HangUp => signal_hook::consts::SIGHUP,
            #[cfg(not(unix))]
            StopSignal::HangUp => 1,
        }
    }

    /// The handled signal of number `number` (Ctrl-C for any other: the
    /// stop flag set another way).
    fn of_number(number: usize) -> StopSignal {
        StopSignal::HANDLED.iter().copied().find(|s| s.number() as usize == number).unwrap_or(StopSignal::Interrupt)
    }

    /// The exit code of a run it stopped: 128 + its number (130 for Ctrl-C).
    pub fn exit_code(self) -> i32 {
        128 + self.number()
    }
}

impl fmt::Display for StopSignal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            StopSignal::Interrupt => "Ctrl-C",
            StopSignal::Terminate => "SIGTERM",
            StopSignal::HangUp => "SIGHUP",
        })
    }
}

/// The flag any of the signals sets, and the number of the last one.
struct Flags {
    stop: Arc<AtomicBool>,
    which: Arc<AtomicUsize>,
}

static FLAGS: OnceLock<Flags> = OnceLock::new();

fn flags() -> &'static Flags {
    FLAGS.get_or_init(|| {
        let flags = Flags { stop: Arc::new(AtomicBool::new(false)), which: Arc::new(AtomicUsize::new(0)) };
        for &signal in StopSignal::HANDLED {
            // Which one first, so that a run that sees the flag finds it. A
            // signal that cannot be handled here keeps its default action.
            let number = signal.number();
            let _ = signal_hook::flag::register_usize(number, Arc::clone(&flags.which), number as usize);
            let _ = signal_hook::flag::register(number, Arc::clone(&flags.stop));
        }
        end_at_a_second_signal(&flags.stop);
        flags
    })
}

/// A second stop signal ends the process at once (a write blocked on a pipe
/// no one reads, say, which a handler returns into), its unfinished files
/// removed first: a thread the signals wake, out of the handlers' narrow
/// rules. The same signal sent again before it wakes counts once.
#[cfg(unix)]
fn end_at_a_second_signal(_stop: &Arc<AtomicBool>) {
    let numbers: Vec<i32> = StopSignal::HANDLED.iter().map(|s| s.number()).collect();
    let Ok(mut signals) = signal_hook::iterator::Signals::new(&numbers) else { return };
    let _ = std::thread::Builder::new().name("second-signal".into()).spawn(move || {
        let mut taken = 0;
        for number in signals.forever() {
            taken += 1;
            if taken < 2 {
                continue;
            }
            let signal = StopSignal::of_number(number as usize);
            // Held to the end: no unfinished file is renamed into place now.
            let unfinished = unfinished_files();
            for path in unfinished.iter() {
                let _ = std::fs::remove_file(path);
            }
            eprintln!("host-sim: stopped ({signal}) by a second signal; nothing more written");
            std::process::exit(signal.exit_code());
        }
    });
}

/// Without a thread to wake (no signal iterator here), the second signal
/// ends the process from its handler.
#[cfg(not(unix))]
fn end_at_a_second_signal(stop: &Arc<AtomicBool>) {
    for &signal in StopSignal::HANDLED {
        let _ = signal_hook::flag::register_conditional_shutdown(signal.number(), signal.exit_code(), Arc::clone(stop));
    }
}

/// The temporary files being written now.
static UNFINISHED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn unfinished_files() -> MutexGuard<'static, Vec<PathBuf>> {
    UNFINISHED.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A temporary file being written, which a second stop signal removes
/// before it ends the process; no longer listed once dropped.
pub(crate) struct Unfinished(PathBuf);

impl Unfinished {
    pub(crate) fn new(path: &Path) -> Unfinished {
        unfinished_files().push(path.to_owned());
        Unfinished(path.to_owned())
    }

    /// Runs `finish`, the step that puts the file in its place, where a
    /// second stop signal cannot remove it midway.
    pub(crate) fn finish<T>(&self, finish: impl FnOnce() -> T) -> T {
        let _listed = unfinished_files();
        finish()
    }
}

impl Drop for Unfinished {
    fn drop(&mut self) {
        unfinished_files().retain(|path| *path != self.0);
    }
}

/// Whether a stop signal has arrived, without installing the handlers (a
/// process that never asked for the flag was never stopped by one).
pub(crate) fn stop_requested() -> bool {
    FLAGS.get().is_some_and(|flags| flags.stop.load(Ordering::SeqCst))
}

/// The flag the stop signals set, their handlers installed on the first
/// call.
pub(crate) fn stop_flag() -> &'static AtomicBool {
    &flags().stop
}

/// The signal that stopped the run (Ctrl-C when the flag was set another
/// way).
pub(crate) fn arrived() -> StopSignal {
    StopSignal::of_number(flags().which.load(Ordering::SeqCst))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_are_the_shells() {
        assert_eq!(StopSignal::Interrupt.exit_code(), 130);
        assert_eq!(StopSignal::Terminate.exit_code(), 143);
        #[cfg(unix)]
        assert_eq!(StopSignal::HangUp.exit_code(), 129);
    }
}
