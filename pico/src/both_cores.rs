//! Both cores trace a still, core 0 presents it: [`draw`] is the picture
//! row by row (through the scene's image, each core taking the next row
//! of its [`areas`](octrace_core::TracedImage::areas)), [`draw_progressive`] in a
//! progressive order. Each core takes the next piece no core has taken
//! (under the chip's lock) and traces it with a renderer of its own, on
//! its SRAM bank's stack; core 1 (a [`SecondCore`] job) hands its pieces
//! over in a [`Handoff`] ring; core 0 presents every piece in order. Each
//! waits for the other with `wfe`, woken by the other's `sev`.
//!
//! Invariants: any split of the pieces between the cores gives the same
//! bits as one core; core 0 presents the pieces in their order, so a
//! display fed row by row sees the rows top to bottom.

use crate::bank_stack::on_bank_stack;
use crate::second_core::SecondCore;
use core::cell::{Cell, RefCell};
use core::ops::ControlFlow;
use core::sync::atomic::{AtomicBool, Ordering};
use cortex_m::asm::{sev, wfe};
use critical_section::Mutex;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Point, Size};
use embedded_graphics_core::pixelcolor::{Rgb888, RgbColor};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::panel::{Dithered, Dithering, TracedColor, IMAGE_ERROR_WORDS};
use octrace_core::profile::Profile;
use octrace_core::render::{Handoff, Progressive, Renderer, Unit};
use octrace_core::{DrawError, LoadedScene, RendererRoom};

/// Why a picture stopped before its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unfinished {
    /// The camera cannot be set up at the panel's size.
    Camera,
    /// The panel refused a row, or the order is not the panel's.
    Panel,
    /// `each_row` or the caller's ask said stop.
    Stopped,
}

impl Unfinished {
    /// Why a draw of the scene's image ended, `target` telling what its
    /// target's error means.
    pub(crate) fn of<E>(drawn: DrawError<E>, target: impl FnOnce(E) -> Unfinished) -> Unfinished {
        match drawn {
            DrawError::Camera(_) => Unfinished::Camera,
            DrawError::Stopped => Unfinished::Stopped,
            DrawError::Target(e) => target(e),
            DrawError::ErrorRow(_) | DrawError::TooLarge { .. } => Unfinished::Panel,
        }
    }
}

/// Traces `scene` into `display` with both cores, row by row, core 1
/// rendering in `room` (its own mailbox and screen lists) and handing rows
/// over through `ring`, which holds at least a row of the display. Each row
/// goes to the display in one `fill_contiguous`, in its colour: dithered
/// onto a panel of few levels as the scene's image dithers it
/// (`image_for`: the method its colour type calls for, the error carried
/// from row to row), converted for any other. `each_row` sees every row as
/// traced (in `Rgb888`) as it goes to the display, in order, and may stop
/// the picture there.
pub fn draw<P, D, const LEN: usize, const SLOTS: usize>(
    core1: &mut SecondCore,
    scene: &LoadedScene<'_, P>,
    room: &mut RendererRoom<P>,
    ring: &Handoff<LEN, SLOTS>,
    display: &mut D,
    each_row: impl FnMut(u32, &[Rgb888]) -> ControlFlow<()>,
) -> Result<(), Unfinished>
where
    P: Profile,
    D: DrawTarget,
    D::Color: TracedColor,
{
    draw_rows::<P, D, LEN, SLOTS, false>(Cores { core1, scene, room, ring }, display, each_row, &mut || false)
}

/// [`draw`], stopped inside a pixel: core 0 asks `stop` before every ray
/// and while it waits for core 1's rows, core 1 a flag core 0 sets when
/// `stop` says so; core 1 wakes core 0 at each of its asks, so that core 0
/// asks at least as often while it waits. A row stopped is not drawn:
/// `Err(Unfinished::Stopped)` after the rows before it.
pub fn draw_until<P, D, const LEN: usize, const SLOTS: usize>(
    core1: &mut SecondCore,
    scene: &LoadedScene<'_, P>,
    room: &mut RendererRoom<P>,
    ring: &Handoff<LEN, SLOTS>,
    display: &mut D,
    each_row: impl FnMut(u32, &[Rgb888]) -> ControlFlow<()>,
    mut stop: impl FnMut() -> bool,
) -> Result<(), Unfinished>
where
    P: Profile,
    D: DrawTarget,
    D::Color: TracedColor,
{
    draw_rows::<P, D, LEN, SLOTS, true>(Cores { core1, scene, room, ring }, display, each_row, &mut stop)
}

/// How a core asks whether to stop, inside a piece it traces: one type for
/// every picture and both cores ([`crate::animation`]'s frames too), so
/// that a firmware links the tracer once.
pub(crate) type Asked<'s> = &'s mut dyn FnMut() -> bool;

/// What both cores trace a picture of a scene with: core 1, the room its
/// renderer traces in, and the ring it hands its pieces over in.
struct Cores<'c, 'r, P: Profile, const LEN: usize, const SLOTS: usize> {
    core1: &'c mut SecondCore,
    scene: &'c LoadedScene<'r, P>,
    room: &'c mut RendererRoom<P>,
    ring: &'c Handoff<LEN, SLOTS>,
}

/// The rows of [`draw`] (asking nothing) and [`draw_until`] (asking
/// `stop`, if `ASKED`: known when it compiles, so that a firmware links
/// one tracer), presented in `display`'s colour.
fn draw_rows<P, D, const LEN: usize, const SLOTS: usize, const ASKED: bool>(
    cores: Cores<'_, '_, P, LEN, SLOTS>,
    display: &mut D,
    mut each_row: impl FnMut(u32, &[Rgb888]) -> ControlFlow<()>,
    stop: Asked<'_>,
) -> Result<(), Unfinished>
where
    P: Profile,
    D: DrawTarget,
    D::Color: TracedColor,
{
    let size = display.bounding_box().size;
    if size.width as usize > LEN {
        return Err(Unfinished::Panel);
    }
    let mut each_row = |y: u32, colors: &[Rgb888]| match each_row(y, colors) {
        ControlFlow::Continue(()) => Ok(()),
        ControlFlow::Break(()) => Err(Unfinished::Stopped),
    };
    let row = |y: u32| Rectangle::new(Point::new(0, y as i32), Size::new(size.width, 1));
    // Known when it compiles: a truecolour display links no dithering.
    if D::Color::PANEL.is_none() {
        let present = |y: u32, colors: &[Rgb888]| {
            let mut line = [D::Color::from(Rgb888::BLACK); LEN];
            let line = &mut line[..colors.len()];
            for (pixel, &color) in line.iter_mut().zip(colors) {
                *pixel = color.into();
            }
            display.fill_contiguous(&row(y), line.iter().copied()).map_err(|_| Unfinished::Panel)?;
            each_row(y, colors)
        };
        return rows_on_both::<P, LEN, SLOTS, ASKED>(cores, size, present, stop);
    }
    let mut error_rows = [0; IMAGE_ERROR_WORDS];
    let mut dithered = Dithered::new(display, Dithering::default(), &mut error_rows).map_err(|_| Unfinished::Panel)?;
    let present = |y: u32, colors: &[Rgb888]| {
        dithered.fill_contiguous(&row(y), colors.iter().copied()).map_err(|_| Unfinished::Panel)?;
        each_row(y, colors)
    };
    rows_on_both::<P, LEN, SLOTS, ASKED>(cores, size, present, stop)
}

/// Both cores draw the scene's image of `size` a row at a time, each
/// taking the next row not yet taken (a core whose rows are cheap, or
/// that has less else to do, takes more of them): core 1 hands its rows
/// over through the ring, and core 0 `present`s every row in order.
///
/// Why not halves: core 0 also presents every row (the colours' format,
/// the panel's commands, the bus), 4 to 5 % of its time on the Pico, and
/// rows differ in cost (a row of sky against a row of spheres), so fixed
/// halves left core 1 waiting for 10 M cycles of fig5_3's picture.
fn rows_on_both<P, const LEN: usize, const SLOTS: usize, const ASKED: bool>(
    cores: Cores<'_, '_, P, LEN, SLOTS>,
    size: Size,
    present: impl FnMut(u32, &[Rgb888]) -> Result<(), Unfinished>,
    stop: Asked<'_>,
) -> Result<(), Unfinished>
where
    P: Profile,
{
    let Cores { core1, scene, room, ring } = cores;
    let stopping = AtomicBool::new(false);
    // The next row to take: read and advanced under the chip's lock
    // (ARMv6-M has no atomic read-modify-write). None once every row is
    // taken or the picture stopped.
    let next = Mutex::new(Cell::new(0u32));
    let take_next = || {
        let y = critical_section::with(|cs| {
            let taken = next.borrow(cs).get();
            next.borrow(cs).set(taken.saturating_add(1));
            taken
        });
        let going = y < size.height && !stopping.load(Ordering::Acquire);
        going.then(|| Rectangle::new(Point::new(0, y as i32), Size::new(size.width, 1)))
    };
    let shared = scene.share();
    // What a stopped picture left in the ring is not this picture's.
    ring.clear();
    let core1_part = || {
        // Taken whole (a room is not shared between cores), drawn in here.
        let room: &mut RendererRoom<P> = room;
        let image = shared.image::<Rgb888>(room, size).areas(&take_next);
        let mut handing = HandingRows { ring, stopping: &stopping, size };
        // Each ask wakes core 0, which asks its own (it may be waiting for
        // this core's row).
        let mut asked = || {
            sev();
            stopping.load(Ordering::Acquire)
        };
        let asked: Asked<'_> = &mut asked;
        let _ = match ASKED {
            true => image.try_draw_until(&mut handing, &mut { asked }),
            false => image.try_draw(&mut handing),
        };
    };
    let core0_part = || {
        let asked = RefCell::new(|| {
            let stopped = stop();
            if stopped {
                stopping.store(true, Ordering::Release);
                sev();
            }
            stopped
        });
        let mut presenting = PresentingRows {
            ring,
            present,
            asked: &asked,
            size,
            shown: 0,
            own: [Rgb888::BLACK; LEN],
            handed: [Rgb888::BLACK; LEN],
        };
        let image = scene.image::<Rgb888>(size).areas(&take_next);
        let mut ask = || (asked.borrow_mut())();
        let ask: Asked<'_> = &mut ask;
        let drawn = match ASKED {
            true => image.try_draw_until(&mut presenting, &mut { ask }),
            false => image.try_draw(&mut presenting),
        };
        // Core 1's rows after core 0's last.
        let result = drawn.map_err(|e| Unfinished::of(e, |e| e)).and_then(|_| presenting.show_up_to(size.height));
        if result.is_err() {
            stopping.store(true, Ordering::Release);
            sev();
        }
        result
    };
    core1.scope(core1_part, core0_part)
}

/// Core 1's rows as it draws them: row `y` handed over in piece `y` of
/// the ring, once its slot is free, until core 0 raises `stopping`.
struct HandingRows<'a, const LEN: usize, const SLOTS: usize> {
    ring: &'a Handoff<LEN, SLOTS>,
    stopping: &'a AtomicBool,
    size: Size,
}

impl<const LEN: usize, const SLOTS: usize> OriginDimensions for HandingRows<'_, LEN, SLOTS> {
    fn size(&self) -> Size {
        self.size
    }
}

impl<const LEN: usize, const SLOTS: usize> DrawTarget for HandingRows<'_, LEN, SLOTS> {
    type Color = Rgb888;
    type Error = Unfinished;

    /// Never called: a still's areas are drawn a row at a time.
    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, _: I) -> Result<(), Unfinished> {
        Err(Unfinished::Panel)
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(
        &mut self,
        row: &Rectangle,
        colors: I,
    ) -> Result<(), Unfinished> {
        let y = row.top_left.y as u32;
        if !slot_free(self.ring, y, self.stopping) {
            return Err(Unfinished::Stopped);
        }
        // Traced as the ring takes them, on this core's bank stack. Free,
        // so published.
        let ring = self.ring;
        let _ = on_bank_stack(|| ring.send(y, colors));
        sev();
        Ok(())
    }
}

/// The display as core 0 draws a still into it: its own rows as they are
/// traced, each after core 1's rows before it, all in order.
struct PresentingRows<'a, F, A: ?Sized, const LEN: usize, const SLOTS: usize> {
    ring: &'a Handoff<LEN, SLOTS>,
    present: F,
    /// Core 0's ask, while it waits for core 1's rows too.
    asked: &'a RefCell<A>,
    size: Size,
    /// The rows before it are presented.
    shown: u32,
    own: [Rgb888; LEN],
    handed: [Rgb888; LEN],
}

impl<F, A, const LEN: usize, const SLOTS: usize> PresentingRows<'_, F, A, LEN, SLOTS>
where
    F: FnMut(u32, &[Rgb888]) -> Result<(), Unfinished>,
    A: FnMut() -> bool + ?Sized,
{
    /// Core 1's rows up to `end`, waiting for each.
    fn show_up_to(&mut self, end: u32) -> Result<(), Unfinished> {
        while self.shown < end {
            let asked = self.asked;
            let len = receive(self.ring, self.shown, &mut self.handed, &mut || (asked.borrow_mut())())?;
            (self.present)(self.shown, &self.handed[..len])?;
            self.shown += 1;
        }
        Ok(())
    }
}

impl<F, A: ?Sized, const LEN: usize, const SLOTS: usize> OriginDimensions for PresentingRows<'_, F, A, LEN, SLOTS> {
    fn size(&self) -> Size {
        self.size
    }
}

impl<F, A, const LEN: usize, const SLOTS: usize> DrawTarget for PresentingRows<'_, F, A, LEN, SLOTS>
where
    F: FnMut(u32, &[Rgb888]) -> Result<(), Unfinished>,
    A: FnMut() -> bool + ?Sized,
{
    type Color = Rgb888;
    type Error = Unfinished;

    /// Never called: a still's areas are drawn a row at a time.
    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, _: I) -> Result<(), Unfinished> {
        Err(Unfinished::Panel)
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(
        &mut self,
        row: &Rectangle,
        colors: I,
    ) -> Result<(), Unfinished> {
        let y = row.top_left.y as u32;
        let own = &mut self.own;
        let traced = on_bank_stack(|| own.iter_mut().zip(colors).map(|(slot, color)| *slot = color).count());
        // Stopped inside it: a row stopped is not drawn.
        if traced < row.size.width as usize {
            return Err(Unfinished::Stopped);
        }
        self.show_up_to(y)?;
        (self.present)(y, &self.own[..traced])?;
        self.shown = y + 1;
        // Core 1's rows that are here go to the panel now: their slots
        // free up for the rows core 1 takes next.
        while self.shown < self.size.height && self.ring.holds(self.shown) {
            self.show_up_to(self.shown + 1)?;
        }
        Ok(())
    }
}

/// Traces `scene` into `display` with both cores in the progressive
/// `order` (the whole panel in coarse blocks first, then finer: the same
/// picture as [`draw`] at the end on a truecolour display; on a panel of
/// few levels, ordered (Bayer) dithering, the one method a block order
/// keeps), each core taking the next unit, core 1 tracing in `room` and
/// handing its colours over through `ring`, which holds
/// `order.max_unit_pixels()`.
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
    D: DrawTarget,
    D::Color: TracedColor,
{
    if order.size() != display.bounding_box().size || order.max_unit_pixels() > LEN {
        return Err(Unfinished::Panel);
    }
    let mut display = Dithered::new(display, Dithering::Bayer, &mut []).map_err(|_| Unfinished::Panel)?;
    let trace = |renderer: &mut Renderer<'_, P>, unit: &Unit, colors: &mut [Rgb888], _: Asked<'_>| {
        Some(unit.trace(renderer, colors).map_or(0, |traced| traced.colors().len()))
    };
    let present = |unit: &Unit, colors: &[Rgb888]| {
        let traced = unit.with_colors(colors).map_err(|_| Unfinished::Panel)?;
        traced.draw(&mut display).map_err(|_| Unfinished::Panel)
    };
    share(Cores { core1, scene, room, ring }, order.size(), || order.units(), trace, present, || false)
}

/// Both cores trace the pieces (a progressive order's units) of an image
/// of `size` that `pieces` lists, each taking the next piece not yet taken
/// (as [`rows_on_both`] takes rows); core 1 hands its pieces over through
/// `ring`, and core 0 presents every piece, in order. `trace` fills a
/// piece's colours and says how many, or None when the core's ask said
/// stop; `present` shows them, or stops the picture. Core 0 asks `stop`
/// (inside its pieces and while it waits for core 1's), core 1 the flag
/// core 0 sets then.
fn share<P, T, I, const LEN: usize, const SLOTS: usize>(
    cores: Cores<'_, '_, P, LEN, SLOTS>,
    size: Size,
    pieces: impl Fn() -> I + Sync,
    trace: impl Fn(&mut Renderer<'_, P>, &T, &mut [Rgb888], Asked<'_>) -> Option<usize> + Sync,
    mut present: impl FnMut(&T, &[Rgb888]) -> Result<(), Unfinished>,
    mut stop_asked: impl FnMut() -> bool,
) -> Result<(), Unfinished>
where
    P: Profile,
    I: Iterator<Item = T>,
{
    let Cores { core1, scene, room, ring } = cores;
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
            if !slot_free(ring, number, &stop) {
                return;
            }
            // Each ask wakes core 0, which asks its own (it may be waiting
            // for this piece).
            let mut asked = || {
                sev();
                stop.load(Ordering::Acquire)
            };
            let Some(traced) = on_bank_stack(|| trace(&mut renderer, &piece, &mut colors, &mut asked)) else { return };
            // Free, so published.
            let _ = ring.send(number, colors[..traced].iter().copied());
            sev();
        }
    };
    let core0_part = || {
        let mut asked = || {
            let stopped = stop_asked();
            if stopped {
                stop.store(true, Ordering::Release);
                sev();
            }
            stopped
        };
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
                    let handed_len = receive(ring, number, &mut handed, &mut asked)?;
                    present(&piece, &handed[..handed_len])?;
                    shown += 1;
                    continue;
                }
                let number = take_next();
                let traced = match to_trace.find(|&(_, n)| n == number) {
                    Some((piece, _)) => Some(
                        on_bank_stack(|| trace(renderer, &piece, &mut own, &mut asked)).ok_or(Unfinished::Stopped)?,
                    ),
                    None => None,
                };
                // The pieces from `shown` up to this one are core 1's.
                for (piece, n) in to_show.by_ref() {
                    match traced {
                        Some(traced) if n == number => {
                            present(&piece, &own[..traced])?;
                            break;
                        }
                        _ => {
                            let handed_len = receive(ring, n, &mut handed, &mut asked)?;
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

/// Core 1: waits until `ring`'s slot for piece `piece` is free (once core
/// 0 has presented the piece SLOTS before it, which it does without
/// waiting for core 1); false if core 0 raised `stopping` first.
pub(crate) fn slot_free<const LEN: usize, const SLOTS: usize>(
    ring: &Handoff<LEN, SLOTS>,
    piece: u32,
    stopping: &AtomicBool,
) -> bool {
    while !ring.is_free_for(piece) {
        if stopping.load(Ordering::Acquire) {
            return false;
        }
        wfe();
    }
    true
}

/// Core 1's piece `number` from `ring` into `colors`, once it is there;
/// returns how many colours it has. `asked` is asked at each wake-up
/// meanwhile: stopped, the piece may never come.
fn receive<const LEN: usize, const SLOTS: usize>(
    ring: &Handoff<LEN, SLOTS>,
    number: u32,
    colors: &mut [Rgb888],
    asked: Asked<'_>,
) -> Result<usize, Unfinished> {
    let handed = loop {
        match ring.take(number) {
            Some(handed) => break handed,
            None if asked() => return Err(Unfinished::Stopped),
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
    Ok(len)
}
