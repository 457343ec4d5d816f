//! Both cores trace a scene: core 1 runs what core 0 hands it, core 0
//! drives the panel.
//!
//! [`SecondCore::start`] starts core 1 once, in a loop that waits for jobs.
//! [`SecondCore::scope`] runs a job on core 1 while core 0 does its own
//! part, and returns only when both are done, so a job may borrow anything
//! core 0 has (like `std::thread::scope`). [`draw`] is the picture: core
//! `c` traces the rows `interleaved_rows(height, c, 2)` with a renderer of
//! its own; core 1 hands its rows over in a [`Handoff`] ring; core 0 sends
//! every row to the panel in order. Each waits for the other with `wfe`,
//! woken by the other's `sev`.
//!
//! Invariants: `JOB` is null or points at core 0's `&mut dyn FnMut()` for
//! the job, which core 0 keeps alive until core 1 has set `JOB` back to
//! null; panics abort (`panic = "abort"`, `panic-halt`), so core 0 never
//! leaves a scope early by unwinding.

use core::ops::ControlFlow;
use core::ptr;
use core::sync::atomic::{AtomicBool, AtomicPtr, Ordering};
use cortex_m::asm::{sev, wfe};
use embedded_graphics::pixelcolor::Rgb565;
use embedded_graphics::prelude::*;
use embedded_graphics::primitives::Rectangle;
use octrace_core::profile::Profile;
use octrace_core::render::{interleaved_rows, Handoff};
use octrace_core::{LoadedScene, RendererRoom};
use rp2040_hal::multicore::{Core, Error as SpawnError, StackAllocation};

/// Core 0's job for core 1, or null.
static JOB: AtomicPtr<()> = AtomicPtr::new(ptr::null_mut());

/// Core 1, waiting for jobs.
pub struct SecondCore {
    _started: (),
}

impl SecondCore {
    /// Starts core 1 on `stack`, waiting for jobs.
    pub fn start(core1: &mut Core<'_>, stack: StackAllocation) -> Result<SecondCore, SpawnError> {
        core1.spawn(stack, || loop {
            let job = JOB.load(Ordering::Acquire).cast::<&mut (dyn FnMut() + Send)>();
            if job.is_null() {
                wfe();
                continue;
            }
            // SAFETY: core 0 keeps the job alive, and touches it not, until
            // JOB is null again (see `scope`).
            unsafe { (*job)() };
            JOB.store(ptr::null_mut(), Ordering::Release);
            sev();
        })?;
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

/// Why [`draw`] stopped before the last row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unfinished {
    /// The camera cannot be set up at the panel's size.
    Camera,
    /// The panel refused a row.
    Panel,
    /// `each_row` asked to stop.
    Stopped,
}

/// Traces `scene` into `display` with both cores, core 1 rendering in
/// `room` (its own mailbox and screen lists) and handing rows over through
/// `rows`. `each_row` sees every row as it goes to the panel, in order, and
/// may stop the picture there. `W` is the panel's width.
pub fn draw<P, D, const W: usize, const SLOTS: usize>(
    core1: &mut SecondCore,
    scene: &LoadedScene<'_, P>,
    room: &mut RendererRoom<P>,
    rows: &Handoff<W, SLOTS>,
    display: &mut D,
    mut each_row: impl FnMut(u32, &[Rgb565]) -> ControlFlow<()>,
) -> Result<(), Unfinished>
where
    P: Profile,
    D: DrawTarget<Color = Rgb565>,
{
    let size = display.bounding_box().size;
    let width = size.width.min(W as u32);
    let stop = AtomicBool::new(false);
    let shared = scene.share();
    // What a stopped picture left in the ring is not this picture's.
    rows.clear();
    let core1_rows = || {
        let Ok(mut renderer) = shared.renderer(room, size) else { return };
        for y in interleaved_rows(size.height, 1, 2) {
            loop {
                // Asked first: a stopped picture traces no further row.
                if stop.load(Ordering::Acquire) {
                    return;
                }
                if rows.is_free_for(y) {
                    break;
                }
                wfe();
            }
            // Free, so the row is traced and published.
            let _ = rows.send(y, renderer.row(y, 0..width).map(|p| p.color));
            sev();
        }
    };
    let core0_rows = || {
        let drawn = scene.with_renderer(size, |renderer| {
            let mut line = [Rgb565::BLACK; W];
            let line = &mut line[..width as usize];
            for y in 0..size.height {
                if y % 2 == 0 {
                    for (pixel, sample) in line.iter_mut().zip(renderer.row(y, 0..width)) {
                        *pixel = sample.color.into();
                    }
                } else {
                    let colors = loop {
                        match rows.take(y) {
                            Some(colors) => break colors,
                            None => wfe(),
                        }
                    };
                    for (pixel, color) in line.iter_mut().zip(colors) {
                        *pixel = color.into();
                    }
                    // The slot is free again: wake core 1 if it waits for it.
                    sev();
                }
                let area = Rectangle::new(Point::new(0, y as i32), Size::new(width, 1));
                display.fill_contiguous(&area, line.iter().copied()).map_err(|_| Unfinished::Panel)?;
                if each_row(y, line).is_break() {
                    return Err(Unfinished::Stopped);
                }
            }
            Ok(())
        });
        let result = drawn.map_err(|_| Unfinished::Camera).and_then(|rows| rows);
        if result.is_err() {
            stop.store(true, Ordering::Release);
            sev();
        }
        result
    };
    core1.scope(core1_rows, core0_rows)
}
