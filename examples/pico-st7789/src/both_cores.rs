//! Both cores trace a scene: core 1 runs what core 0 hands it, core 0
//! drives the panel.
//!
//! [`SecondCore::start`] starts core 1 once, in a loop that waits for jobs.
//! [`SecondCore::scope`] runs a job on core 1 while core 0 does its own
//! part, and returns only when both are done, so a job may borrow anything
//! core 0 has (like `std::thread::scope`). [`draw`] is the picture: each
//! core takes the next row no core has taken (under the chip's lock) and
//! traces it with a renderer of its own; core 1 hands its rows over in a
//! [`Handoff`] ring; core 0 sends every row to the panel in order. Each
//! waits for the other with `wfe`, woken by the other's `sev`.
//!
//! Invariants: `JOB` is null or points at core 0's `&mut dyn FnMut()` for
//! the job, which core 0 keeps alive until core 1 has set `JOB` back to
//! null; panics abort (`panic = "abort"`, `panic-halt`), so core 0 never
//! leaves a scope early by unwinding.

use crate::bank_stack::{self, on_bank_stack};
use core::cell::Cell;
use core::ops::ControlFlow;
use core::ptr;
use core::sync::atomic::{AtomicBool, AtomicPtr, Ordering};
use cortex_m::asm::{sev, wfe};
use critical_section::Mutex;
use embedded_graphics::pixelcolor::{Rgb565, Rgb888};
use embedded_graphics::prelude::*;
use embedded_graphics::primitives::Rectangle;
use octrace_core::profile::Profile;
use octrace_core::render::{Handoff, Progressive, Renderer, Unit};
use octrace_core::{LoadedScene, RendererRoom, SceneAccelerator};
use rp2040_hal::multicore::{Core, Error as SpawnError, StackAllocation};

/// Core 0's job for core 1, or null.
static JOB: AtomicPtr<()> = AtomicPtr::new(ptr::null_mut());

/// Core 1 for good: each job core 0 hands it, run to its end.
fn core1_loop() -> ! {
    loop {
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
    }
}

/// Core 1, waiting for jobs.
pub struct SecondCore {
    _started: (),
}

impl SecondCore {
    /// Starts core 1 on `stack`, waiting for jobs; both cores' bank stacks
    /// guarded.
    pub fn start(core1: &mut Core<'_>, stack: StackAllocation) -> Result<SecondCore, SpawnError> {
        core1.spawn(stack, || {
            bank_stack::guard();
            core1_loop()
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

/// Why a picture stopped before its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unfinished {
    /// The camera cannot be set up at the panel's size.
    Camera,
    /// The panel refused a row, or the order is not the panel's.
    Panel,
    /// `each_row` asked to stop.
    Stopped,
}

/// Traces `scene` into `display` with both cores, row by row, core 1
/// rendering in `room` (its own mailbox and screen lists) and handing rows
/// over through `ring`. `each_row` sees every row as it goes to the panel,
/// in order, and may stop the picture there.
pub fn draw<P, D, const LEN: usize, const SLOTS: usize>(
    core1: &mut SecondCore,
    scene: &LoadedScene<'_, P>,
    room: &mut RendererRoom<P>,
    ring: &Handoff<LEN, SLOTS>,
    display: &mut D,
    mut each_row: impl FnMut(u32, &[Rgb565]) -> ControlFlow<()>,
) -> Result<(), Unfinished>
where
    P: Profile,
    D: DrawTarget<Color = Rgb565>,
{
    let size = display.bounding_box().size;
    let width = size.width.min(LEN as u32);
    let trace = |renderer: &mut Renderer<'_, SceneAccelerator<'_, P>>, y: &u32, colors: &mut [Rgb888]| {
        let mut traced = 0;
        for (color, pixel) in colors.iter_mut().zip(renderer.row(*y, 0..width)) {
            *color = pixel.color;
            traced += 1;
        }
        traced
    };
    let present = |y: &u32, colors: &[Rgb888]| {
        let mut line = [Rgb565::BLACK; LEN];
        let line = &mut line[..colors.len()];
        for (pixel, &color) in line.iter_mut().zip(colors) {
            *pixel = color.into();
        }
        let area = Rectangle::new(Point::new(0, *y as i32), Size::new(width, 1));
        display.fill_contiguous(&area, line.iter().copied()).map_err(|_| Unfinished::Panel)?;
        match each_row(*y, line) {
            ControlFlow::Continue(()) => Ok(()),
            ControlFlow::Break(()) => Err(Unfinished::Stopped),
        }
    };
    share(core1, scene, room, ring, size, || 0..size.height, trace, present)
}

/// Traces `scene` into `display` with both cores in the progressive
/// `order` (the whole panel in coarse blocks first, then finer: the same
/// picture as [`draw`] at the end), each core taking the next unit, core 1
/// tracing in `room` and handing its colours over through `ring`, which
/// holds `order.max_unit_pixels()`.
pub fn draw_progressive<P, D, const LEN: usize, const SLOTS: usize>(
    core1: &mut SecondCore,
    scene: &LoadedScene<'_, P>,
    room: &mut RendererRoom<P>,
    ring: &Handoff<LEN, SLOTS>,
    display: &mut D,
    order: &Progressive,
) -> Result<(), Unfinished>
where
    P: Profile,
    D: DrawTarget<Color = Rgb565>,
{
    if order.size() != display.bounding_box().size || order.max_unit_pixels() > LEN {
        return Err(Unfinished::Panel);
    }
    let trace = |renderer: &mut Renderer<'_, SceneAccelerator<'_, P>>, unit: &Unit, colors: &mut [Rgb888]| {
        unit.trace(renderer, colors).map_or(0, |traced| traced.colors().len())
    };
    let present = |unit: &Unit, colors: &[Rgb888]| {
        let traced = unit.with_colors(colors).map_err(|_| Unfinished::Panel)?;
        traced.draw(&mut Converted(display)).map_err(|_| Unfinished::Panel)
    };
    share(core1, scene, room, ring, order.size(), || order.units(), trace, present)
}

/// Both cores trace the pieces (rows, or a progressive order's units) of
/// an image of `size` that `pieces` lists, each taking the next piece not
/// yet taken (a core that finds its pieces cheap, or has less else to do,
/// takes more of them); core 1 hands its pieces over through `ring`, and
/// core 0 presents every piece, in order. `trace` fills a piece's colours
/// and says how many; `present` shows them, or stops the picture.
///
/// Why not halves: core 0 also presents every piece (the colours' format,
/// the panel's commands, the bus), 4 to 5 % of its time on the Pico, and
/// pieces differ in cost (a row of sky against a row of spheres), so fixed
/// halves left core 1 waiting for 10 M cycles of fig5_3's picture.
#[allow(clippy::too_many_arguments)]
fn share<'r, P, T, I, const LEN: usize, const SLOTS: usize>(
    core1: &mut SecondCore,
    scene: &LoadedScene<'r, P>,
    room: &mut RendererRoom<P>,
    ring: &Handoff<LEN, SLOTS>,
    size: Size,
    pieces: impl Fn() -> I + Sync,
    trace: impl Fn(&mut Renderer<'_, SceneAccelerator<'r, P>>, &T, &mut [Rgb888]) -> usize + Sync,
    mut present: impl FnMut(&T, &[Rgb888]) -> Result<(), Unfinished>,
) -> Result<(), Unfinished>
where
    P: Profile,
    I: Iterator<Item = T>,
{
    let stop = AtomicBool::new(false);
    // The number of the next piece to take: read and advanced under the
    // chip's lock (ARMv6-M has no atomic read-modify-write).
    let next = Mutex::new(Cell::new(0u32));
    let take_next = || {
        critical_section::with(|cs| {
            let taken = next.borrow(cs).get();
            next.borrow(cs).set(taken.saturating_add(1));
            taken
        })
    };
    let count = pieces().count() as u32;
    let shared = scene.share();
    // What a stopped picture left in the ring is not this picture's.
    ring.clear();
    let core1_part = || {
        let Ok(mut renderer) = shared.renderer(room, size) else { return };
        let mut colors = [Rgb888::BLACK; LEN];
        let mut pieces = pieces().zip(0u32..);
        // Asked first: a stopped picture traces no further piece.
        while !stop.load(Ordering::Acquire) {
            let number = take_next();
            let Some((piece, _)) = pieces.find(|&(_, n)| n == number) else { return };
            // Its slot is free once core 0 has presented the piece SLOTS
            // before it, which it does without waiting for this core.
            while !ring.is_free_for(number) {
                if stop.load(Ordering::Acquire) {
                    return;
                }
                wfe();
            }
            let traced = on_bank_stack(|| trace(&mut renderer, &piece, &mut colors));
            // Free, so published.
            let _ = ring.send(number, colors[..traced].iter().copied());
            sev();
        }
    };
    let core0_part = || {
        let presented = scene.with_renderer(size, |renderer| {
            let mut own = [Rgb888::BLACK; LEN];
            let mut handed = [Rgb888::BLACK; LEN];
            // The pieces in order for the panel, and ahead of them core 0's.
            let (mut to_show, mut to_trace) = (pieces().zip(0u32..), pieces().zip(0u32..));
            // Every piece before `shown` is on the panel.
            let mut shown = 0;
            while shown < count {
                // Core 1's next piece, if ready, goes to the panel first: its
                // slot frees up for the piece core 1 takes next.
                if ring.holds(shown) {
                    let Some((piece, number)) = to_show.next() else { break };
                    let handed_len = receive(ring, number, &mut handed);
                    present(&piece, &handed[..handed_len])?;
                    shown += 1;
                    continue;
                }
                let number = take_next();
                let traced = to_trace
                    .find(|&(_, n)| n == number)
                    .map(|(piece, _)| on_bank_stack(|| trace(renderer, &piece, &mut own)));
                // The pieces from `shown` up to this one are core 1's.
                for (piece, n) in to_show.by_ref() {
                    match traced {
                        Some(traced) if n == number => {
                            present(&piece, &own[..traced])?;
                            break;
                        }
                        _ => {
                            let handed_len = receive(ring, n, &mut handed);
                            present(&piece, &handed[..handed_len])?;
                        }
                    }
                }
                shown = number.saturating_add(1).min(count);
            }
            Ok(())
        });
        let result = presented.map_err(|_| Unfinished::Camera).and_then(|pieces| pieces);
        if result.is_err() {
            stop.store(true, Ordering::Release);
            sev();
        }
        result
    };
    core1.scope(core1_part, core0_part)
}

/// Core 1's piece `number` from `ring` into `colors`, once it is there;
/// returns how many colours it has.
fn receive<const LEN: usize, const SLOTS: usize>(
    ring: &Handoff<LEN, SLOTS>,
    number: u32,
    colors: &mut [Rgb888],
) -> usize {
    let handed = loop {
        match ring.take(number) {
            Some(handed) => break handed,
            None => wfe(),
        }
    };
    let mut len = 0;
    for (color, handed) in colors.iter_mut().zip(handed) {
        *color = handed;
        len += 1;
    }
    // The slot is free again: wake core 1 if it waits for it.
    sev();
    len
}

/// A display of `Rgb565` taking the progressive order's `Rgb888` blocks.
struct Converted<'d, D>(&'d mut D);

impl<D: DrawTarget<Color = Rgb565>> OriginDimensions for Converted<'_, D> {
    fn size(&self) -> Size {
        self.0.bounding_box().size
    }
}

impl<D: DrawTarget<Color = Rgb565>> DrawTarget for Converted<'_, D> {
    type Color = Rgb888;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        self.0.draw_iter(pixels.into_iter().map(|Pixel(at, color)| Pixel(at, color.into())))
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(&mut self, area: &Rectangle, colors: I) -> Result<(), D::Error> {
        self.0.fill_contiguous(area, colors.into_iter().map(Into::into))
    }

    fn fill_solid(&mut self, area: &Rectangle, color: Rgb888) -> Result<(), D::Error> {
        self.0.fill_solid(area, color.into())
    }
}
