//! octrace on a Cortex-M board: the scene text lives in flash, is parsed on
//! the board into static arenas, and is rendered row by row straight into
//! the display driver: a host file over semihosting, or on the
//! LM3S6965EVB its OLED panel (`ssd0323`). No heap, no framebuffer.
//! Build-time choices are in `build.rs`.
//!
//! Exit codes: 0 rendered, 2 the scene has errors, 3 the display (the host
//! file, the panel) refused the output, 101 panic, 102 HardFault, 103
//! unexpected interrupt. The LM3S6965EVB keeps its picture on the panel
//! until the runner has grabbed the screen, then exits.

#![no_std]
#![no_main]

#[cfg(not(board = "lm3s6965evb"))]
mod display;
mod semihosting;
#[cfg(board = "lm3s6965evb")]
mod ssd0323;

mod config {
    include!(concat!(env!("OUT_DIR"), "/config.rs"));
}

use core::cell::RefCell;
use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::hprintln;
use critical_section::Mutex;
use embedded_graphics_core::draw_target::DrawTarget;
use octrace_core::accel::{Accelerator, Naive, Octree, OctreeConfig, Traversal};
use octrace_core::parse::parse;
use octrace_core::render::Renderer;
use octrace_core::scene::{Scene, SceneView};
use octrace_core::shade::Stats;
use semihosting::exit;
// What the boards that stream to a host file use.
#[cfg(not(board = "lm3s6965evb"))]
use {
    display::StreamDisplay,
    embedded_graphics_core::geometry::Size,
    embedded_graphics_core::pixelcolor::{Gray4, Rgb565, Rgb888},
    octrace_core::palette::{render_indexed, Dither, PaletteIndex},
    semihosting::HostFile,
};

/// The intersection mode, chosen at build time.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Accel {
    /// Naive up to 16 objects, else dda (as host-sim's `auto`).
    Auto,
    Naive,
    Octree,
    Dda,
}

/// The display's pixel format, chosen at build time.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Wire {
    Rgb888,
    Rgb565,
    /// Palette indices, ordered-dithered onto the 6×6×6 cube.
    Dither,
    /// 16 gray levels (embedded-graphics' conversion from Rgb888).
    Gray4,
}

/// What each board holds: the capacity profile, the octree's walk depth and
/// its subdivision criterion (shallow on the micro:bit, whose stack is 6 KiB
/// and whose octree arenas are small).
#[cfg(board = "microbit")]
mod board {
    use octrace_core::accel::{OctreeConfig, Traversal};
    pub type Profile = octrace_core::capacity::Board16K;
    pub const FRAMES: usize = 4;
    pub const OCTREE: OctreeConfig = OctreeConfig { max_objects: 8, max_depth: 3, traversal: Traversal::Dda };
}
#[cfg(board = "mps2-an385")]
mod board {
    use octrace_core::accel::{OctreeConfig, Traversal};
    pub type Profile = octrace_core::capacity::Board64K;
    pub const FRAMES: usize = 13;
    pub const OCTREE: OctreeConfig = OctreeConfig { max_objects: 4, max_depth: 12, traversal: Traversal::Dda };
}
#[cfg(board = "lm3s6965evb")]
#[path = "lm3s6965evb.rs"]
mod board;
use board::Profile;
type BoardOctree = Octree<Profile, { board::FRAMES }>;

/// Objects the mailbox covers (one bit each).
const MAILBOX_WORDS: usize = 16;

static SCENE: Mutex<RefCell<Scene<Profile>>> = Mutex::new(RefCell::new(Scene::new()));
static OCTREE: Mutex<RefCell<BoardOctree>> = Mutex::new(RefCell::new(Octree::new()));

/// Marks the stretch qemu-count measures (`insns_between_markers`): the
/// render alone, without parsing and building.
#[no_mangle]
#[inline(never)]
pub extern "C" fn bench_marker(id: u32) {
    core::hint::black_box(id);
}

#[entry]
fn main() -> ! {
    let code = critical_section::with(|cs| {
        let mut scene = SCENE.borrow_ref_mut(cs);
        let mut octree = OCTREE.borrow_ref_mut(cs);
        if !load(&mut scene) {
            return 2;
        }
        hprintln!("stack after parsing: {} bytes", peak_stack());
        run(&mut scene, &mut octree)
    });
    hprintln!("peak stack: {} bytes", peak_stack());
    #[cfg(board = "lm3s6965evb")]
    if code == 0 {
        board::show_until_grabbed();
    }
    exit(code)
}

/// Parses the scene from flash; false (with every error printed) if it has
/// errors. Not inlined, so its frame is gone while rendering.
#[inline(never)]
fn load(scene: &mut Scene<Profile>) -> bool {
    let mut errors = 0;
    let parsed = parse(config::SCENE, scene, &mut |e| {
        errors += 1;
        hprintln!("{}.txt:{}", config::SCENE_NAME, e);
    });
    if parsed.is_err() {
        hprintln!("{} error(s); nothing rendered", errors);
    }
    parsed.is_ok()
}

#[inline(never)]
fn run(scene: &mut Scene<Profile>, octree: &mut BoardOctree) -> u32 {
    let view = scene.view();
    let accel = match config::ACCEL {
        Accel::Auto if view.object_count() <= 16 => Accel::Naive,
        Accel::Auto => Accel::Dda,
        a => a,
    };
    let traversal = match accel {
        Accel::Octree => Some(Traversal::Named),
        Accel::Dda => Some(Traversal::Dda),
        _ => None,
    };
    hprintln!(
        "octrace on {}: {} ({} objects) at {}x{}",
        config::BOARD,
        config::SCENE_NAME,
        view.object_count(),
        config::WIDTH,
        config::HEIGHT
    );
    let Some(file) = open_output() else {
        hprintln!("cannot open the display (or the output file on the host)");
        return 3;
    };
    let result = match traversal {
        None => draw(view, &Naive, file),
        Some(traversal) => {
            let report = octree.build(&view, &OctreeConfig { traversal, ..board::OCTREE });
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
            draw(view, &*octree, file)
        }
    };
    match result {
        Some(stats) => {
            hprintln!("{} rays, {} shadow rays, {} cells", stats.rays, stats.shadow_rays, stats.cells);
            0
        }
        None => {
            hprintln!("the display refused the pixels");
            3
        }
    }
}

// The display: a host file on the boards without one (the pixels streamed
// in the configured format), the OLED panel on the LM3S6965EVB.
#[cfg(not(board = "lm3s6965evb"))]
fn open_output() -> Option<HostFile> {
    HostFile::create(config::OUTPUT)
}
#[cfg(board = "lm3s6965evb")]
use board::open_output;

/// Renders into the display in the configured pixel format. Not inlined:
/// each instance keeps its renderer in its own frame, so only one is ever on
/// the stack.
#[cfg(not(board = "lm3s6965evb"))]
#[inline(never)]
fn draw<A: Accelerator>(view: SceneView<'_>, accel: &A, file: HostFile) -> Option<Stats> {
    let size = Size::new(config::WIDTH, config::HEIGHT);
    match config::WIRE {
        Wire::Rgb888 => render(view, accel, || StreamDisplay::<Rgb888>::new(file, size), |r, d| r.render(d)),
        Wire::Rgb565 => render(view, accel, || StreamDisplay::<Rgb565>::new(file, size), |r, d| r.render(d)),
        Wire::Gray4 => render(view, accel, || StreamDisplay::<Gray4>::new(file, size), |r, d| r.render(d)),
        Wire::Dither => render(
            view,
            accel,
            || StreamDisplay::<PaletteIndex>::new(file, size),
            |r, d| render_indexed(r, 0..config::HEIGHT, &mut Dither, d),
        ),
    }
}

/// The panel shows 16 grays: build.rs allows no other format here.
#[cfg(board = "lm3s6965evb")]
#[inline(never)]
fn draw<A: Accelerator>(view: SceneView<'_>, accel: &A, panel: board::Output) -> Option<Stats> {
    debug_assert!(config::WIRE == Wire::Gray4);
    render(view, accel, || panel, |r, d| r.render(d))
}

#[inline(never)]
fn render<A: Accelerator, D: DrawTarget>(
    view: SceneView<'_>,
    accel: &A,
    display: impl FnOnce() -> D,
    paint: impl FnOnce(&mut Renderer<'_, A>, &mut D) -> Result<Stats, D::Error>,
) -> Option<Stats> {
    let mut words = [0u32; MAILBOX_WORDS];
    // Made here, in this frame, as the renderer is.
    let mut display = display();
    let Ok(mut renderer) = Renderer::with_size(view, accel, config::WIDTH, config::HEIGHT) else { return None };
    renderer.set_mailbox(&mut words);
    bench_marker(0);
    let stats = paint(&mut renderer, &mut display).ok()?;
    bench_marker(1);
    Some(stats)
}

/// Bytes of stack used at most: `paint-stack` filled it with a pattern at
/// reset; the lowest word no longer holding it is the high-water mark.
fn peak_stack() -> usize {
    extern "C" {
        static _stack_end: u32;
        static _stack_start: u32;
    }
    // SAFETY: the linker places both symbols at the ends of the stack
    // region; only their addresses are taken, and every word between them
    // is RAM owned by the stack.
    unsafe {
        let low = core::ptr::addr_of!(_stack_end) as usize;
        let high = core::ptr::addr_of!(_stack_start) as usize;
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

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("HardFault at {:#010x}", frame.pc());
    exit(102)
}

#[exception]
unsafe fn DefaultHandler(irq: i16) {
    hprintln!("unexpected interrupt {}", irq);
    exit(103)
}
