//! Both Cortex-M33s of the MPS2-AN521 render the picture. Core `c` draws
//! the rows `c`, `c + 2`, `c + 4`, … of the scene's image, as its
//! areas (`TracedImage::areas`), with a renderer of its own (core 0's in
//! its `Raytracer`, core 1's in a `RendererRoom`) over the one scene,
//! shared with `LoadedScene::share`; core 0 alone writes to the
//! display, in row order, taking core 1's rows from a `Handoff` ring: no
//! heap, no lock. A panel of few levels is dithered as one picture, every
//! row going through one `Dithered` target in order.
//!
//! Invariants: core 1 starts only after the shared scene is published (and
//! never touches the scene's `Raytracer` or semihosting).

use crate::config::{self, Profile};
use core::cell::{Cell, UnsafeCell};
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Point, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use octrace_core::panel::{Dithered, TracedColor};
use octrace_core::render::Handoff;
use octrace_core::{ConstStaticCell, DrawError, LoadedScene, RendererRoom, SharedScene};

const WIDTH: usize = config::WIDTH as usize;

/// Core 1's rows on their way to the display: it may render four ahead.
static RING: Handoff<WIDTH, 4> = Handoff::new();

/// Core 1's own mailbox and screen lists.
static CORE1_ROOM: ConstStaticCell<RendererRoom<Profile>> = ConstStaticCell::new(RendererRoom::new());

/// What core 1 renders from, published by core 0 before it starts core 1.
struct Shared {
    ready: AtomicBool,
    scene: UnsafeCell<Option<SharedScene<'static, Profile>>>,
}

// SAFETY: `scene` is written once, by core 0, before `ready` is set (and
// before core 1 runs at all); core 1 reads it only after seeing `ready`.
unsafe impl Sync for Shared {}

static SHARED: Shared = Shared { ready: AtomicBool::new(false), scene: UnsafeCell::new(None) };

/// Core 1's stack (64 KiB, 8-byte aligned as the architecture wants).
#[repr(C, align(8))]
struct Stack(UnsafeCell<[u8; 64 * 1024]>);

// SAFETY: only core 1 uses it, as its stack.
unsafe impl Sync for Stack {}

static CORE1_STACK: Stack = Stack(UnsafeCell::new([0; 64 * 1024]));

/// Core 1's vector table: the initial stack pointer and the reset handler,
/// aligned as the vector table base register requires.
#[repr(C, align(128))]
struct Vectors {
    stack: *const u8,
    reset: extern "C" fn() -> !,
}

// SAFETY: read only, by the hardware.
unsafe impl Sync for Vectors {}

static CORE1_VECTORS: Vectors =
    Vectors { stack: CORE1_STACK.0.get().cast::<u8>().wrapping_add(64 * 1024), reset: core1_main };

/// The SSE-200's system control registers (Secure): core 1's reset vector
/// table base, and the bits that hold each core in reset.
const INITSVTOR1: *mut u32 = 0x5002_1114 as *mut u32;
const CPUWAIT: *mut u32 = 0x5002_1118 as *mut u32;

/// Draws `scene` into `display` with both cores; what core 0 renders and
/// writes, and how many rays each core traced.
pub fn draw<D>(scene: &LoadedScene<'static, Profile>, display: &mut D) -> Result<[u64; 2], D::Error>
where
    D: DrawTarget,
    D::Color: TracedColor,
{
    let mut rows = [0; config::ERROR_WORDS];
    // Sized for the display by the build script.
    let Ok(mut display) = Dithered::new(display, config::DITHERING, &mut rows) else { crate::semihosting::exit(3) };
    // SAFETY: core 1 is still held in reset: nothing else reads `SHARED`.
    unsafe { *SHARED.scene.get() = Some(scene.share()) };
    SHARED.ready.store(true, Ordering::Release);
    // SAFETY: the documented registers of this board; core 1 starts at the
    // table above, with a stack of its own.
    unsafe {
        INITSVTOR1.write_volatile(&CORE1_VECTORS as *const Vectors as usize as u32);
        CPUWAIT.write_volatile(CPUWAIT.read_volatile() & !0b10);
    }
    let next = rows_of(0);
    let mut interleaving = Interleaving { display: &mut display };
    // The size was checked when core 0 loaded the scene.
    let drawn = scene.image::<Rgb888>(SIZE).areas(&next).try_draw(&mut interleaving);
    let core0_rays = match drawn {
        Ok(stats) => stats.rays,
        Err(DrawError::Target(e)) => return Err(e),
        Err(_) => crate::semihosting::exit(2),
    };
    Ok([core0_rays, CORE1_RAYS.load(Ordering::Acquire) as u64])
}

/// The picture's size.
const SIZE: Size = Size::new(config::WIDTH, config::HEIGHT);

/// Core `core`'s rows of the picture, every other one from its own, one
/// after another: its areas.
fn rows_of(core: u32) -> impl Fn() -> Option<Rectangle> {
    let next = Cell::new(core);
    move || {
        let y = next.get();
        next.set(y + 2);
        (y < config::HEIGHT).then(|| Rectangle::new(Point::new(0, y as i32), Size::new(config::WIDTH, 1)))
    }
}

/// The display as core 0 draws into it: each of its own rows, then core
/// 1's row after it, from the ring.
struct Interleaving<'d, D> {
    display: &'d mut D,
}

impl<D: DrawTarget<Color = Rgb888>> OriginDimensions for Interleaving<'_, D> {
    fn size(&self) -> Size {
        SIZE
    }
}

impl<D: DrawTarget<Color = Rgb888>> DrawTarget for Interleaving<'_, D> {
    type Color = Rgb888;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        self.display.draw_iter(pixels)
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(&mut self, row: &Rectangle, colors: I) -> Result<(), D::Error> {
        self.display.fill_contiguous(row, colors)?;
        let y = row.top_left.y as u32 + 1;
        if y < config::HEIGHT {
            octrace_wait_until(y, true);
            // Held, so taken: the row's colours, its slot freed after.
            if let Some(taken) = RING.take(y) {
                self.display.fill_contiguous(&Rectangle::new(Point::new(0, y as i32), row.size), taken)?;
            }
        }
        Ok(())
    }
}

/// Rays core 1 traced, once it is done.
static CORE1_RAYS: AtomicU32 = AtomicU32::new(0);

/// Spins until the ring holds row `y` (`sent`) or is free for it (not
/// `sent`). Not inlined: the instruction counter tells a core's waiting
/// from its work by this function's addresses (`tools/cores.sh`).
#[no_mangle]
#[inline(never)]
pub extern "C" fn octrace_wait_until(y: u32, sent: bool) {
    while if sent { !RING.holds(y) } else { !RING.is_free_for(y) } {
        core::hint::spin_loop();
    }
}

/// Core 1's rows as it draws them, each into the ring once its slot is
/// free.
struct Handing;

impl OriginDimensions for Handing {
    fn size(&self) -> Size {
        SIZE
    }
}

impl DrawTarget for Handing {
    type Color = Rgb888;
    type Error = core::convert::Infallible;

    /// Never called: the image's areas are drawn a row at a time.
    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, _: I) -> Result<(), Self::Error> {
        crate::semihosting::exit(104)
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(
        &mut self,
        row: &Rectangle,
        colors: I,
    ) -> Result<(), Self::Error> {
        let y = row.top_left.y as u32;
        octrace_wait_until(y, false);
        // Free, so the row is traced as the ring takes it, and published.
        let _ = RING.send(y, colors);
        Ok(())
    }
}

/// Core 1: draws its rows into the ring, then sleeps.
extern "C" fn core1_main() -> ! {
    // The FPU, as cortex-m-rt enables it for core 0 (CPACR: CP10, CP11).
    // SAFETY: the architecture's register; enabling it is all this does.
    unsafe {
        let cpacr = 0xE000_ED88 as *mut u32;
        cpacr.write_volatile(cpacr.read_volatile() | 0xF << 20);
    }
    cortex_m::asm::dsb();
    cortex_m::asm::isb();
    while !SHARED.ready.load(Ordering::Acquire) {
        core::hint::spin_loop();
    }
    // SAFETY: published before `ready`, never written again.
    let Some(shared) = (unsafe { *SHARED.scene.get() }) else { crate::semihosting::exit(104) };
    let next = rows_of(1);
    let Ok(stats) = shared.image::<Rgb888>(CORE1_ROOM.take(), SIZE).areas(&next).try_draw(&mut Handing) else {
        crate::semihosting::exit(104)
    };
    CORE1_RAYS.store(stats.rays as u32, Ordering::Release);
    loop {
        cortex_m::asm::wfi();
    }
}
