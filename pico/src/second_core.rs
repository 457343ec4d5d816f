//! Core 1 as a job runner: [`SecondCore::start`] starts it once, in a loop
//! that waits for jobs; [`SecondCore::scope`] runs a job on core 1 while
//! core 0 does its own part, and returns only when both are done, so a job
//! may borrow anything core 0 has (like `std::thread::scope`). Each waits
//! for the other with `wfe`, woken by the other's `sev`.
//!
//! Invariants: `JOB` is null or points at core 0's `&mut dyn FnMut()` for
//! the job, which core 0 keeps alive until core 1 has set `JOB` back to
//! null; panics abort (`panic = "abort"`, `panic-halt`), so core 0 never
//! leaves a scope early by unwinding.

use crate::bank_stack;
use core::ptr;
use core::sync::atomic::{AtomicPtr, Ordering};
use cortex_m::asm::{sev, wfe};
use rp2040_hal::multicore::{Core, Error as SpawnError, StackAllocation};

/// Core 0's job for core 1, or null.
static JOB: AtomicPtr<()> = AtomicPtr::new(ptr::null_mut());

/// Core 1, waiting for jobs.
pub struct SecondCore {
    _started: (),
}

impl SecondCore {
    /// Starts core 1 on `stack`, waiting for jobs; both cores' bank
    /// stacks guarded ([`bank_stack::guard`]).
    pub fn start(core1: &mut Core<'_>, stack: StackAllocation) -> Result<SecondCore, SpawnError> {
        core1.spawn(stack, || {
            bank_stack::guard();
            loop {
                let job = JOB.load(Ordering::Acquire).cast::<&mut (dyn FnMut() + Send)>();
                if job.is_null() {
                    wfe();
                    continue;
                }
                // SAFETY: core 0 keeps the job alive, and touches it not,
                // until JOB is null again (see `scope`).
                unsafe { (*job)() };
                JOB.store(ptr::null_mut(), Ordering::Release);
                sev();
            }
        })?;
        bank_stack::guard();
        Ok(SecondCore { _started: () })
    }

    /// Runs `job` on core 1 while `here` runs on core 0, and returns what
    /// `here` returns once `job` is done too.
    pub fn scope<R>(&mut self, job: impl FnOnce() + Send, here: impl FnOnce() -> R) -> R {
        let mut job = Some(job);
        let mut call = || {
            if let Some(job) = job.take() {
                job();
            }
        };
        let mut erased: &mut (dyn FnMut() + Send) = &mut call;
        JOB.store(ptr::from_mut(&mut erased).cast(), Ordering::Release);
        sev();
        let result = here();
        while !JOB.load(Ordering::Acquire).is_null() {
            wfe();
        }
        result
    }
}
