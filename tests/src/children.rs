//! Child processes of a test that also opens serial ports in its own
//! process: every child is started through [`spawn`] or [`output`], and
//! every port this process closes is followed by [`settle_after_closing`].
//!
//! Why: a port is opened with a lock (an exclusive or shared `flock`), and
//! a child started on another thread holds a copy of every open descriptor
//! from its fork until its exec. A port closed in that window stays locked
//! until the child execs, so the next opener (host-sim, the studio) is
//! refused "Unable to acquire exclusive lock" — which a busy machine's CI
//! saw. Invariant: once [`settle_after_closing`] returns, no child started
//! by this process holds a descriptor of a port closed before the call.

use std::io;
use std::process::{Child, Command, Output, Stdio};
use std::sync::{PoisonError, RwLock};

/// Held shared while a child starts (fork to exec), exclusively to wait
/// until no child is starting.
static STARTING: RwLock<()> = RwLock::new(());

/// Starts `command` (as [`Command::spawn`]).
pub fn spawn(command: &mut Command) -> io::Result<Child> {
    let _starting = STARTING.read().unwrap_or_else(PoisonError::into_inner);
    // `spawn` returns once the child has exec'd (or failed to).
    command.spawn()
}

/// Runs `command` to its end, its output collected (as [`Command::output`]).
pub fn output(command: &mut Command) -> io::Result<Output> {
    let child = spawn(command.stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped()))?;
    child.wait_with_output()
}

/// Waits until every child that was starting has exec'd: call it after
/// this process closes a serial port, before anyone opens it again.
pub fn settle_after_closing() {
    drop(STARTING.write().unwrap_or_else(PoisonError::into_inner));
}
