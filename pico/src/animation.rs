//! Both cores play an animation (a scene with `FRAMES` and `MOVE`) in a
//! loop: each frame is loaded, then only the tiles its motion can change
//! are traced again (octrace-core's [`Coherence`](octrace_core::animation::Coherence)) and only their runs of
//! pixels drawn, so the panel shows each frame exactly as if drawn whole.
//! Any panel's colour ([`TracedColor`]): a truecolour panel gets each
//! pixel converted; a panel of few levels gets ordered (Bayer) dithering,
//! each pixel from its own colour alone, the one method that draws a run
//! the same whatever was drawn around it (so its frames are not the error
//! diffusion of its stills).
//!
//! Each frame: core 0 loads it (core 1 building its light buffer, if any),
//! plans its tiles and lists its bands of tiles, most pixels first; then
//! each core takes the next band no core has taken and traces it with a
//! renderer of its own. Core 0 draws its runs straight into the panel, and
//! between them the runs core 1 handed over in a [`Runs`] ring. The LED is
//! lit while the board works on a frame and goes out once the frame is
//! whole on the panel; a frame does not start before its time (the scene's
//! rate: at most that many frames a second).
//!
//! Invariants: the tiles' counts are planned once a frame (as it loads), on
//! core 0, before either core traces; a band is traced by one core, once a
//! frame; every run core 1 traced is on the panel before the LED goes out;
//! the motion is recorded once, as frame 0 loads, and serves every frame.

use crate::bank_stack::{on_bank_stack, with_both_banks};
use crate::both_cores::{slot_free, Asked, Unfinished};
use crate::second_core::SecondCore;
use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use cortex_m::asm::{sev, wfe};
use critical_section::Mutex;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, OriginDimensions, Point, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use embedded_hal::digital::OutputPin;
use octrace_core::animation::Animation;
use octrace_core::panel::{Dithered, TracedColor};
use octrace_core::profile::Profile;
use octrace_core::render::Handoff;
use octrace_core::{Frame, Raytracer, RendererRoom};
use rp2040_hal::Timer;

/// The most bands of tiles a panel may have (a panel up to 512 rows high).
const MOST_BANDS: usize = 128;

/// The widest and highest panel a piece's rectangle can name.
const MOST_PIXELS: u32 = 1 << 10;

/// Why an animation stopped playing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stopped {
    /// A frame did not load: the scene has an error (check it with
    /// `host-sim`, whose errors name the line, the column and a frame), or
    /// the animation's room is not the scene's size.
    Frame(u32),
    /// A frame could not be drawn.
    Picture(Unfinished),
}

/// What plays an animation on a Pico: both cores (core 1 tracing in its
/// own room and handing its runs over through `runs`), the raytracer the
/// frames load into, and the animation (its motion and tiles, at the
/// panel's size, in an `AnimationRoom` of the firmware's).
pub struct Player<'a, P: Profile, const LEN: usize, const SLOTS: usize> {
    pub core1: &'a mut SecondCore,
    pub raytracer: &'a mut Raytracer<P>,
    pub animation: Animation<'a>,
    pub room: &'a mut RendererRoom<P>,
    pub runs: &'a Runs<LEN, SLOTS>,
}

/// Runs of pixels on their way from core 1 to core 0: each piece is one
/// row of a run of tiles (up to `LEN` pixels) and the rectangle it fills.
///
/// Invariant: a piece's rectangle is stored before its colours are
/// published (the ring's release store), and read after it is seen.
pub struct Runs<const LEN: usize, const SLOTS: usize> {
    colors: Handoff<LEN, SLOTS>,
    /// Each slot's rectangle: x, y and width, 10 bits each.
    areas: [AtomicU32; SLOTS],
}

impl<const LEN: usize, const SLOTS: usize> Runs<LEN, SLOTS> {
    /// Every slot free.
    pub const fn new() -> Self {
        Runs { colors: Handoff::new(), areas: [const { AtomicU32::new(0) }; SLOTS] }
    }

    /// The ring of colours alone, for a still's rows
    /// ([`both_cores::draw`](crate::both_cores::draw)): a firmware that
    /// draws stills and animations keeps one ring for both.
    pub fn rows(&self) -> &Handoff<LEN, SLOTS> {
        &self.colors
    }

    /// Core 1: traces `pixels` into piece `piece`'s slot, once it is free,
    /// for `area`; false if `stop` said so first.
    fn send(&self, piece: u32, area: &Rectangle, pixels: impl Iterator<Item = Rgb888>, stop: &AtomicBool) -> bool {
        if !slot_free(&self.colors, piece, stop) {
            return false;
        }
        let (x, y, width) = (area.top_left.x as u32, area.top_left.y as u32, area.size.width);
        self.areas[piece as usize % SLOTS].store(x | y << 10 | width << 20, Ordering::Relaxed);
        // Free, so published.
        let _ = self.colors.send(piece, pixels);
        sev();
        true
    }

    /// Core 0: piece `piece`, if core 1 has sent it, onto `display`.
    fn present<D>(&self, piece: u32, display: &mut D) -> Option<Result<(), D::Error>>
    where
        D: DrawTarget<Color = Rgb888>,
    {
        let colors = self.colors.take(piece)?;
        let area = self.areas[piece as usize % SLOTS].load(Ordering::Relaxed);
        let (x, y, width) = (area & 0x3ff, area >> 10 & 0x3ff, area >> 20);
        let row = Rectangle::new(Point::new(x as i32, y as i32), Size::new(width, 1));
        let drawn = display.fill_contiguous(&row, colors);
        // The slot is free again: wake core 1 if it waits for it.
        sev();
        Some(drawn)
    }
}

/// The panel as core 0 draws a frame into it: its own runs as they are
/// traced, each followed by the runs core 1 has handed over by then.
struct Panel<'a, D, const LEN: usize, const SLOTS: usize> {
    display: &'a mut D,
    runs: &'a Runs<LEN, SLOTS>,
    /// Core 1's pieces before this one are on the panel.
    shown: u32,
}

impl<D: DrawTarget<Color = Rgb888>, const LEN: usize, const SLOTS: usize> Panel<'_, D, LEN, SLOTS> {
    /// Core 1's pieces handed over so far, onto the panel.
    fn show_handed(&mut self) -> Result<(), D::Error> {
        while let Some(drawn) = self.runs.present(self.shown, self.display) {
            drawn?;
            self.shown += 1;
        }
        Ok(())
    }
}

impl<D: DrawTarget<Color = Rgb888>, const LEN: usize, const SLOTS: usize> OriginDimensions
    for Panel<'_, D, LEN, SLOTS>
{
    fn size(&self) -> Size {
        self.display.bounding_box().size
    }
}

impl<D: DrawTarget<Color = Rgb888>, const LEN: usize, const SLOTS: usize> DrawTarget for Panel<'_, D, LEN, SLOTS> {
    type Color = Rgb888;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        self.display.draw_iter(pixels)?;
        self.show_handed()
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(&mut self, area: &Rectangle, colors: I) -> Result<(), D::Error> {
        self.display.fill_contiguous(area, colors)?;
        self.show_handed()
    }
}

impl<const LEN: usize, const SLOTS: usize> Default for Runs<LEN, SLOTS> {
    fn default() -> Self {
        Self::new()
    }
}

/// Core 1's runs as it draws them: each handed over in the next piece of
/// `runs` (once its slot is free), until `stop` is raised.
struct Handing<'a, const LEN: usize, const SLOTS: usize> {
    runs: &'a Runs<LEN, SLOTS>,
    stop: &'a AtomicBool,
    size: Size,
    /// Pieces handed over.
    pieces: u32,
}

/// Core 0 raised the stop while core 1 waited for a slot.
struct Raised;

impl<const LEN: usize, const SLOTS: usize> OriginDimensions for Handing<'_, LEN, SLOTS> {
    fn size(&self) -> Size {
        self.size
    }
}

impl<const LEN: usize, const SLOTS: usize> DrawTarget for Handing<'_, LEN, SLOTS> {
    type Color = Rgb888;
    type Error = Raised;

    /// Never called: a frame's draw hands over runs.
    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, _: I) -> Result<(), Raised> {
        Ok(())
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(&mut self, area: &Rectangle, colors: I) -> Result<(), Raised> {
        // The run's pixels are traced as the ring takes them: on core 1's
        // bank (and SRAM4 below it), off the striped banks core 0 uses.
        let (runs, piece, stop) = (self.runs, self.pieces, self.stop);
        if !on_bank_stack(|| runs.send(piece, area, colors.into_iter(), stop)) {
            return Err(Raised);
        }
        self.pieces += 1;
        Ok(())
    }
}

impl<'a, P: Profile, const LEN: usize, const SLOTS: usize> Player<'a, P, LEN, SLOTS> {
    /// Plays the animation `text` into `display` for ever, with both cores,
    /// in the display's colour as the module says. `show` puts each frame
    /// on the panel once it is drawn (a buffered display's flush; `|_|
    /// Ok(())` for a panel drawn into directly). `led` is lit while a frame
    /// is on its way, until it is shown; `timer` paces the frames. Returns
    /// only when it cannot go on.
    #[inline(never)]
    pub fn play<D, L>(
        mut self,
        text: &str,
        display: &mut D,
        mut show: impl FnMut(&mut D) -> Result<(), D::Error>,
        led: &mut L,
        timer: &Timer,
    ) -> Stopped
    where
        D: DrawTarget,
        D::Color: TracedColor,
        L: OutputPin,
    {
        let mut display = Dithered::ordered(display);
        let size = display.bounding_box().size;
        let fits = size.width < MOST_PIXELS
            && size.height < MOST_PIXELS
            && self.animation.tiles().bands() as usize <= MOST_BANDS;
        if !fits || LEN < self.animation.tiles().longest_row() as usize {
            return Stopped::Picture(Unfinished::Panel);
        }
        let mut frame = 0;
        loop {
            let started = timer.get_counter().ticks();
            let _ = led.set_high();
            let core1 = &mut *self.core1;
            let loaded =
                self.animation.load_on_two_cores(self.raytracer, text, frame, |beside, here| core1.scope(beside, here));
            let Ok(loaded) = loaded else { return Stopped::Frame(frame) };
            let (frames, period_us) = (loaded.frames(), 1_000_000 / u64::from(loaded.frames().rate.max(1)));
            let drawn = draw_frame::<P, _, LEN, SLOTS, false>(
                self.core1,
                &loaded,
                self.room,
                self.runs,
                &mut display,
                &mut || false,
            );
            if let Err(unfinished) = drawn {
                return Stopped::Picture(unfinished);
            }
            if show(display.display()).is_err() {
                return Stopped::Picture(Unfinished::Panel);
            }
            let _ = led.set_low();
            frame = frames.after(frame);
            // Not before its time.
            while timer.get_counter().ticks() < started + period_us {}
        }
    }
}

/// Draws `frame` (loaded, its tiles planned) after the frame before it in
/// the loop (or, at first, everything): both cores trace the planned tiles,
/// core 1 in `room` handing its runs over through `runs`, and core 0 draws
/// every run into `display` (each row of a run in one `fill_contiguous`).
/// `stop` is asked on core 0 before every ray it traces; once it says
/// stop, core 1 stops before its next ray too and the frame ends
/// [`Unfinished::Stopped`] (the tiles not drawn keep their mark): how the
/// live firmware draws each frame of an animation the host sent.
/// [`Player::play`] draws its frames asking nothing (the same code
/// without the asking: its tracer is linked once, unpolled, and inlined as
/// a still's).
///
/// Core 0 checks for core 1's runs after each of its own rows (a run's
/// row of up to 128 pixels): core 1 may trace `SLOTS` rows ahead.
pub fn draw_frame_until<P, D, const LEN: usize, const SLOTS: usize>(
    core1: &mut SecondCore,
    frame: &Frame<'_, '_, P>,
    room: &mut RendererRoom<P>,
    runs: &Runs<LEN, SLOTS>,
    display: &mut D,
    stop: Asked<'_>,
) -> Result<(), Unfinished>
where
    P: Profile,
    D: DrawTarget<Color = Rgb888>,
{
    draw_frame::<P, D, LEN, SLOTS, true>(core1, frame, room, runs, display, stop)
}

/// [`draw_frame_until`], asking `stop` only if `ASKED` (known when it
/// compiles, so that a firmware links one tracer: the asking one, or the
/// one that asks nothing).
fn draw_frame<P, D, const LEN: usize, const SLOTS: usize, const ASKED: bool>(
    core1: &mut SecondCore,
    frame: &Frame<'_, '_, P>,
    room: &mut RendererRoom<P>,
    runs: &Runs<LEN, SLOTS>,
    display: &mut D,
    stop: Asked<'_>,
) -> Result<(), Unfinished>
where
    P: Profile,
    D: DrawTarget<Color = Rgb888>,
{
    let tiles = frame.tiles();
    let size = tiles.size();
    if size != display.bounding_box().size || LEN < tiles.longest_row() as usize {
        return Err(Unfinished::Panel);
    }
    // The bands with tiles to trace, most pixels first: the last band
    // taken is a small one, so neither core waits long for the other.
    let mut order = [(0u32, 0u16); MOST_BANDS];
    let mut bands = 0;
    for band in 0..tiles.bands().min(MOST_BANDS as u32) {
        let pixels = tiles.band_pixels(band) as u32;
        if pixels > 0 {
            let mut at = bands;
            while at > 0 && order[at - 1].0 < pixels {
                order[at] = order[at - 1];
                at -= 1;
            }
            order[at] = (pixels, band as u16);
            bands += 1;
        }
    }
    let order = &order[..bands];
    let stopping = AtomicBool::new(false);
    // How many pieces core 1 handed over in all, once it is done.
    let handed = AtomicU32::new(u32::MAX);
    // The next band to take, read and advanced under the chip's lock
    // (ARMv6-M has no atomic read-modify-write).
    let next = Mutex::new(Cell::new(0usize));
    let take_next = || {
        critical_section::with(|cs| {
            let taken = next.borrow(cs).get();
            next.borrow(cs).set(taken + 1);
            order.get(taken).map(|&(_, band)| u32::from(band))
        })
    };
    let shared = frame.share();
    runs.colors.clear();
    let core1_part = || {
        // Taken whole (a room is not shared between cores), drawn in here.
        let room: &mut RendererRoom<P> = room;
        let mut handing = Handing { runs, stop: &stopping, size, pieces: 0 };
        let image = shared.image::<Rgb888>(room, size).bands(&take_next);
        // Core 0 draws into the panel on its main stack, so core 1's runs
        // may take both banks.
        // Asked through an `Asked`, as core 0 is and a still's rows are,
        // so that the firmware links one asking tracer.
        let mut stopped = || stopping.load(Ordering::Acquire);
        let asked: Asked<'_> = &mut stopped;
        let _ = with_both_banks(|| match ASKED {
            true => image.try_draw_until(&mut handing, &mut { asked }),
            false => image.try_draw(&mut handing),
        });
        handed.store(handing.pieces, Ordering::Release);
        sev();
    };
    let core0_part = || {
        let mut panel = Panel { display, runs, shown: 0 };
        let image = frame.image::<Rgb888>().bands(&take_next);
        let drawn = match ASKED {
            true => image.try_draw_until(&mut panel, &mut { stop }),
            false => image.try_draw(&mut panel),
        };
        let mut result = drawn.map(|_| ()).map_err(|e| Unfinished::of(e, |_| Unfinished::Panel));
        // The rest of core 1's.
        while result.is_ok() {
            result = panel.show_handed().map_err(|_| Unfinished::Panel);
            if handed.load(Ordering::Acquire) == panel.shown {
                break;
            }
            wfe();
        }
        if result.is_err() {
            stopping.store(true, Ordering::Release);
            sev();
        }
        result
    };
    core1.scope(core1_part, core0_part)
}
