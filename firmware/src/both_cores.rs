//! Both Cortex-M33s of the MPS2-AN521 render the picture. Core `c` renders
//! the rows `interleaved_rows(HEIGHT, c, 2)` with a `Renderer` of its own
//! (its own mailbox and screen lists) over the one scene and accelerator;
//! core 0 alone writes to the display, in row order, taking core 1's rows
//! from a ring of row buffers handed over with atomics: no heap, no lock.
//!
//! Invariants: core 1 starts only after the scene and its accelerator are
//! published (and never touches the scene's `Raytracer` or semihosting); a
//! ring slot is written only by core 1 while its row number is 0 and read
//! only by core 0 while it holds the row's number plus one.

use crate::config::{self, Profile};
use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Point, Size};
use embedded_graphics_core::pixelcolor::Rgb888;
use embedded_graphics_core::primitives::Rectangle;
use octrace_core::accel::Mailbox;
use octrace_core::render::{interleaved_rows, Renderer, ScreenBound};
use octrace_core::scene::SceneView;
use octrace_core::{LoadedScene, SceneAccelerator};

const WIDTH: usize = config::WIDTH as usize;
/// Rows core 1 may render ahead of the display.
const SLOTS: usize = 4;

/// One of core 1's rows on its way to the display.
struct Slot {
    /// The row's number plus one while it holds that row; 0 while free.
    row: AtomicU32,
    pixels: UnsafeCell<[Rgb888; WIDTH]>,
}

struct Ring([Slot; SLOTS]);

// SAFETY: each slot's pixels have one writer (core 1, while `row` is 0) and
// one reader (core 0, while `row` names the row), handed over by `row`'s
// release stores and acquire loads.
unsafe impl Sync for Ring {}

static RING: Ring =
    Ring([const { Slot { row: AtomicU32::new(0), pixels: UnsafeCell::new([Rgb888::new(0, 0, 0); WIDTH]) } }; SLOTS]);

/// What core 1 renders from, published by core 0 before it starts core 1.
struct Shared {
    ready: AtomicBool,
    scene: UnsafeCell<Option<(SceneView<'static>, SceneAccelerator<'static, Profile>)>>,
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
    D::Color: From<Rgb888>,
{
    // SAFETY: core 1 is still held in reset: nothing else reads `scene`.
    unsafe { *SHARED.scene.get() = Some((scene.view(), scene.accelerator())) };
    SHARED.ready.store(true, Ordering::Release);
    // SAFETY: the documented registers of this board; core 1 starts at the
    // table above, with a stack of its own.
    unsafe {
        INITSVTOR1.write_volatile(&CORE1_VECTORS as *const Vectors as usize as u32);
        CPUWAIT.write_volatile(CPUWAIT.read_volatile() & !0b10);
    }
    let accelerator = scene.accelerator();
    let mut lists = Lists::new();
    let mut renderer = lists.renderer(scene.view(), &accelerator);
    let width = config::WIDTH;
    for y in 0..config::HEIGHT {
        let area = Rectangle::new(Point::new(0, y as i32), Size::new(width, 1));
        if y % 2 == 0 {
            display.fill_contiguous(&area, renderer.row(y, 0..width).map(|p| p.color.into()))?;
            continue;
        }
        let slot = &RING.0[(y / 2) as usize % SLOTS];
        wait_until(&slot.row, y + 1);
        // SAFETY: the slot holds row y: core 1 will not write it again
        // until it is freed below.
        let pixels = unsafe { &*slot.pixels.get() };
        display.fill_contiguous(&area, pixels.iter().map(|&c| c.into()))?;
        slot.row.store(0, Ordering::Release);
    }
    Ok([renderer.stats().rays, CORE1_RAYS.load(Ordering::Acquire) as u64])
}

/// Rays core 1 traced, once it is done.
static CORE1_RAYS: AtomicU32 = AtomicU32::new(0);

/// Spins until `cell` holds `value`. Not inlined: the instruction counter
/// tells a core's waiting from its work by this function's addresses.
#[no_mangle]
#[inline(never)]
pub extern "C" fn octrace_wait_until(cell: &AtomicU32, value: u32) {
    while cell.load(Ordering::Acquire) != value {
        core::hint::spin_loop();
    }
}

fn wait_until(cell: &AtomicU32, value: u32) {
    octrace_wait_until(cell, value);
}

/// A core's own mailbox and screen lists.
struct Lists {
    words: [u32; Mailbox::words_for(config::OBJECTS)],
    bounds: [ScreenBound; config::OBJECTS],
    positions: [u16; ScreenBound::positions_for(config::OBJECTS)],
}

impl Lists {
    fn new() -> Self {
        Lists {
            words: [0; Mailbox::words_for(config::OBJECTS)],
            bounds: [ScreenBound::EMPTY; config::OBJECTS],
            positions: [0; ScreenBound::positions_for(config::OBJECTS)],
        }
    }

    fn renderer<'a>(
        &'a mut self,
        view: SceneView<'a>,
        accelerator: &'a SceneAccelerator<'static, Profile>,
    ) -> Renderer<'a, SceneAccelerator<'static, Profile>> {
        // The size was checked when core 0 loaded the scene.
        let renderer = match Renderer::with_size(view, accelerator, config::WIDTH, config::HEIGHT) {
            Ok(renderer) => renderer,
            Err(_) => crate::semihosting::exit(2),
        };
        renderer.with_mailbox(&mut self.words).with_first_hits(&mut self.bounds, &mut self.positions)
    }
}

/// Core 1: renders its rows into the ring, then sleeps.
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
    let Some((view, accelerator)) = (unsafe { *SHARED.scene.get() }) else { crate::semihosting::exit(104) };
    let mut lists = Lists::new();
    let mut renderer = lists.renderer(view, &accelerator);
    for y in interleaved_rows(config::HEIGHT, 1, 2) {
        let slot = &RING.0[(y / 2) as usize % SLOTS];
        wait_until(&slot.row, 0);
        // SAFETY: the slot is free: core 0 reads it only once it names a row.
        let pixels = unsafe { &mut *slot.pixels.get() };
        for (pixel, sample) in pixels.iter_mut().zip(renderer.row(y, 0..config::WIDTH)) {
            *pixel = sample.color;
        }
        slot.row.store(y + 1, Ordering::Release);
    }
    CORE1_RAYS.store(renderer.stats().rays as u32, Ordering::Release);
    loop {
        cortex_m::asm::wfi();
    }
}
