//! octrace on a Cortex-M or RISC-V board: the scene text lives in flash, is parsed on
//! the board into static arenas sized for it at build time, and is drawn row
//! by row straight into the display driver (a host file over semihosting,
//! or on the LM3S6965EVB its OLED panel, `ssd0323`) as an embedded-graphics
//! image. No heap, no framebuffer. Build-time choices are in `build.rs`.
//!
//! Exit codes: 0 rendered, 2 the scene has errors, 3 the display (the host
//! file, the panel) refused the output, 101 panic, 102 HardFault (a RISC-V
//! exception), 103 unexpected interrupt. The LM3S6965EVB keeps its picture on the panel
//! until the runner has grabbed the screen, then exits.

#![no_std]
#![no_main]

#[cfg(board = "mps2-an521")]
mod both_cores;
#[cfg(not(board = "lm3s6965evb"))]
mod display;
#[cfg(board = "lm3s6965evb")]
mod lm3s6965evb;
mod semihosting;
#[cfg(board = "lm3s6965evb")]
mod ssd0323;

mod config;

use embedded_graphics_core::geometry::Size;
use octrace_core::render::PanelColor;
use octrace_core::{ConstStaticCell, LoadedScene, Raytracer};
use semihosting::exit;
#[cfg(target_arch = "arm")]
use {
    // The single-core critical section the cell's flag takes on a Cortex-M0.
    cortex_m as _,
    cortex_m_rt::{entry, exception, ExceptionFrame},
    cortex_m_semihosting::hprintln,
};
#[cfg(target_arch = "riscv32")]
use {
    // The same for a RISC-V hart without atomics.
    riscv as _,
    riscv_rt::{entry, TrapFrame},
    riscv_semihosting::hprintln,
};
// What the boards that stream to a host file use.
#[cfg(not(board = "lm3s6965evb"))]
use {
    display::{StreamDisplay, WireColor},
    embedded_graphics_core::draw_target::DrawTarget,
    embedded_graphics_core::pixelcolor::{BinaryColor, Gray2, Gray4, Rgb565, Rgb888},
    octrace_core::palette::{Dither, PaletteIndex, Quantized},
    octrace_core::panel::{BlackWhiteRed, TracedColor},
    semihosting::HostFile,
};

/// The capacity profile, sized by `build.rs` for exactly the embedded scene.
use config::Profile;

/// Scene, octree and mailbox: zero bits, in `.bss`, taken once.
static RAYTRACER: ConstStaticCell<Raytracer<Profile>> = ConstStaticCell::new(Raytracer::new());

/// Marks the stretch qemu-count measures (`insns_between_markers`): the
/// render alone, without parsing and building.
#[no_mangle]
#[inline(never)]
pub extern "C" fn bench_marker(id: u32) {
    core::hint::black_box(id);
}

#[entry]
fn main() -> ! {
    #[cfg(target_arch = "riscv32")]
    paint_stack();
    let code = run(RAYTRACER.take());
    hprintln!("peak stack: {} bytes", peak_stack());
    #[cfg(board = "lm3s6965evb")]
    if code == 0 {
        lm3s6965evb::show_until_grabbed();
    }
    exit(code)
}

/// Loads the scene from flash and draws it; the exit code.
fn run(raytracer: &'static mut Raytracer<Profile>) -> u32 {
    let Some(scene) = load(raytracer) else { return 2 };
    hprintln!("stack after parsing: {} bytes", peak_stack());
    let view = scene.view();
    hprintln!(
        "octrace on {}: {} ({} objects, {}) at {}x{}",
        config::BOARD,
        config::SCENE_NAME,
        view.object_count(),
        scene.mode(),
        config::WIDTH,
        config::HEIGHT
    );
    if let Some(report) = scene.octree_report() {
        hprintln!(
            "octree: {} boxes, {} leaves, {} references (peak {}), depth {}, {} bytes{}",
            report.nodes,
            report.leaves,
            report.references,
            report.peak_references,
            report.depth,
            report.bytes,
            if report.unsplit > 0 { " (some boxes left unsplit: arenas full)" } else { "" }
        );
    }
    let lights = scene.light_buffer().report();
    if !config::LIGHT_BUFFER.is_empty() {
        hprintln!(
            "light buffer: {} of {} lights, {} cells a side, {} cells, {} entries, {} bytes",
            lights.lights,
            view.lights.len(),
            lights.cells_a_side,
            lights.cells,
            lights.entries,
            4 * lights.words
        );
    }
    let Some(output) = open_output() else {
        hprintln!("cannot open the display (or the output file on the host)");
        return 3;
    };
    bench_marker(0);
    let drawn = draw_on(&scene, output);
    bench_marker(1);
    if !drawn {
        hprintln!("the display refused the pixels");
        return 3;
    }
    #[cfg(not(board = "lm3s6965evb"))]
    say_where_the_pixels_went();
    // Both cores' renderers count their own (printed by `draw_into`).
    #[cfg(not(board = "mps2-an521"))]
    {
        let stats = scene.stats();
        hprintln!("{} rays, {} shadow rays, {} cells", stats.rays, stats.shadow_rays, stats.cells);
    }
    0
}

/// Parses the scene from flash; `None` (with every error printed) if it
/// has errors. Not inlined, so its frame is gone while rendering.
#[inline(never)]
fn load(raytracer: &'static mut Raytracer<Profile>) -> Option<LoadedScene<'static, Profile>> {
    let loaded = raytracer.load_with(config::SCENE.as_bytes(), config::ACCEL, &mut |e| {
        hprintln!("{}.txt:{}", config::SCENE_NAME, e);
    });
    match loaded {
        Ok(mut scene) => {
            // The light buffer the build script made for this scene, checked
            // against it (a buffer for another scene is refused).
            if !config::LIGHT_BUFFER.is_empty() {
                if let Err(e) = scene.use_light_buffer(&config::LIGHT_BUFFER) {
                    hprintln!("light buffer not used: {}", e);
                }
            }
            Some(scene)
        }
        Err(e) => {
            hprintln!("{} error(s); nothing rendered", e.count);
            None
        }
    }
}

/// Where the pixels went: a host file of rows without a header. Out of
/// line, so that its arguments do not widen `run`'s frame, under which the
/// drawing runs.
#[cfg(not(board = "lm3s6965evb"))]
#[inline(never)]
fn say_where_the_pixels_went() {
    hprintln!(
        "pixels ({}x{}, {}, rows top to bottom, no header) -> {}",
        config::WIDTH,
        config::HEIGHT,
        config::WIRE.name(),
        config::OUTPUT_NAME
    );
}

// The display: a host file on the boards without one (the pixels streamed
// in the configured format), the OLED panel on the LM3S6965EVB.
#[cfg(not(board = "lm3s6965evb"))]
fn open_output() -> Option<HostFile> {
    HostFile::create(config::OUTPUT)
}
#[cfg(board = "lm3s6965evb")]
use lm3s6965evb::open_output;

/// Draws the scene into the host file in the configured pixel format.
#[cfg(not(board = "lm3s6965evb"))]
fn draw_on(scene: &LoadedScene<'static, Profile>, file: HostFile) -> bool {
    match config::WIRE {
        PanelColor::Rgb888 => draw::<Rgb888>(scene, file),
        PanelColor::Rgb565 => draw::<Rgb565>(scene, file),
        PanelColor::Mono => draw::<BinaryColor>(scene, file),
        PanelColor::Gray2 => draw::<Gray2>(scene, file),
        PanelColor::Gray4 => draw::<Gray4>(scene, file),
        PanelColor::Bwr => draw::<BlackWhiteRed>(scene, file),
        PanelColor::Dither => draw_dithered(scene, file),
    }
}

/// Draws the scene onto the panel, in its 16 grays (build.rs allows no
/// other format here), at its top left. Not inlined, as `draw`.
#[cfg(board = "lm3s6965evb")]
#[inline(never)]
fn draw_on(scene: &LoadedScene<'_, Profile>, mut panel: ssd0323::Ssd0323) -> bool {
    debug_assert!(config::WIRE == PanelColor::Gray4);
    let image = scene.image(Size::new(config::WIDTH, config::HEIGHT)).dithered(config::DITHERING);
    let rows = core::cell::RefCell::new([0; config::ERROR_WORDS]);
    image.error_rows(&rows).try_draw(&mut panel).is_ok()
}

/// Draws the scene into a display of colour `C`. Not inlined: each colour's
/// instance keeps its frame to itself.
#[cfg(not(board = "lm3s6965evb"))]
#[inline(never)]
fn draw<C: WireColor + TracedColor>(scene: &LoadedScene<'static, Profile>, file: HostFile) -> bool {
    let mut display = StreamDisplay::<C>::new(file, Size::new(config::WIDTH, config::HEIGHT));
    draw_into(scene, &mut display)
}

/// Draws the scene into a 256-colour display, ordered-dithered.
#[cfg(not(board = "lm3s6965evb"))]
#[inline(never)]
fn draw_dithered(scene: &LoadedScene<'static, Profile>, file: HostFile) -> bool {
    let display = StreamDisplay::<PaletteIndex>::new(file, Size::new(config::WIDTH, config::HEIGHT));
    let mut dithered = Quantized { display, quantizer: &mut Dither };
    draw_into(scene, &mut dithered)
}

/// Draws the scene into `display` as an embedded-graphics image; a panel
/// of few levels keeps error diffusion's row, exactly as wide as the
/// panel, in this frame (less stack than the image's own 512 bytes).
#[cfg(not(any(board = "lm3s6965evb", board = "mps2-an521")))]
fn draw_into<D: DrawTarget>(scene: &LoadedScene<'static, Profile>, display: &mut D) -> bool
where
    D::Color: TracedColor,
{
    let rows = core::cell::RefCell::new([0; config::ERROR_WORDS]);
    scene.image_for(display).dithered(config::DITHERING).error_rows(&rows).try_draw(display).is_ok()
}

/// Draws the scene into `display` with both cores.
#[cfg(board = "mps2-an521")]
fn draw_into<D: DrawTarget>(scene: &LoadedScene<'static, Profile>, display: &mut D) -> bool
where
    D::Color: TracedColor,
{
    match both_cores::draw(scene, display) {
        Ok([core0, core1]) => {
            hprintln!("rays: core 0 {}, core 1 {}", core0, core1);
            true
        }
        Err(_) => false,
    }
}

/// The stack's lowest and highest addresses, from the linker script.
fn stack_ends() -> (usize, usize) {
    #[cfg(target_arch = "arm")]
    extern "C" {
        static _stack_end: u32;
        static _stack_start: u32;
    }
    // riscv-rt's names for them.
    #[cfg(target_arch = "riscv32")]
    extern "C" {
        #[link_name = "__estack"]
        static _stack_end: u32;
        #[link_name = "__sstack"]
        static _stack_start: u32;
    }
    // Only the symbols' addresses are taken, never their values.
    (core::ptr::addr_of!(_stack_end) as usize, core::ptr::addr_of!(_stack_start) as usize)
}

/// Fills the stack below this frame with the pattern `peak_stack` looks
/// for, as cortex-m-rt's `paint-stack` does at reset (riscv-rt has none).
#[cfg(target_arch = "riscv32")]
#[inline(never)]
fn paint_stack() {
    let here = 0u32;
    // Well below this frame: what this function and its callee use.
    let top = (core::ptr::addr_of!(here) as usize - 256) & !3;
    let (low, _) = stack_ends();
    let mut p = low;
    while p < top {
        // SAFETY: every word from the stack's bottom to below this frame
        // is stack RAM that nothing uses yet.
        unsafe { core::ptr::write_volatile(p as *mut u32, 0xCCCC_CCCC) };
        p += 4;
    }
    core::hint::black_box(&here);
}

/// Bytes of stack used at most: the stack was filled with a pattern at
/// reset; the lowest word no longer holding it is the high-water mark.
fn peak_stack() -> usize {
    let (low, high) = stack_ends();
    // SAFETY: every word between the stack's ends is RAM owned by the stack.
    unsafe {
        let mut p = low;
        while p < high && core::ptr::read_volatile(p as *const u32) == 0xCCCC_CCCC {
            p += 4;
        }
        high - p
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    exit(101)
}

#[cfg(target_arch = "arm")]
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("HardFault at {:#010x}", frame.pc());
    exit(102)
}

#[cfg(target_arch = "arm")]
#[exception]
unsafe fn DefaultHandler(irq: i16) {
    hprintln!("unexpected interrupt {}", irq);
    exit(103)
}

#[cfg(target_arch = "riscv32")]
#[export_name = "ExceptionHandler"]
fn exception_handler(_frame: &TrapFrame) -> ! {
    hprintln!("exception {:#x} at {:#010x}", riscv::register::mcause::read().bits(), riscv::register::mepc::read());
    exit(102)
}

#[cfg(target_arch = "riscv32")]
#[export_name = "DefaultHandler"]
fn default_handler() {
    hprintln!("unexpected interrupt {:#x}", riscv::register::mcause::read().bits());
    exit(103)
}
