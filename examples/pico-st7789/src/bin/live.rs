//! octrace live on a Raspberry Pi Pico: flash it once, then send it scenes.
//! The Pico enumerates as a USB serial port; `host-sim board PORT
//! scene.txt` (or the studio's "Send to board") sends a scene, and the Pico
//! answers with its errors at line and column, or draws it on the panel
//! with both cores (sending the rows back when asked), then waits for the
//! next. An animation (a scene with `FRAMES`) is played in a loop on both
//! cores, each frame re-tracing only the tiles its motion can change and
//! drawing only their runs (sent back as runs), until the host sends
//! anything. The protocol is octrace-link's (`docs/board-protocol.md`).
//!
//! Invariants: the USB device lives in the USB interrupt, which moves bytes
//! between it and two rings (`INPUT`, `OUTPUT`); the main loop on core 0
//! is octrace-link's board loop (`Link`), which only reads `INPUT` and
//! writes `OUTPUT` (this file is its `Line`: the rings, the timer, sleep
//! and the watchdog), so the port answers the host while a picture is
//! traced. While `INPUT` is full the interrupt is masked and the host waits
//! (its bytes stay in the port); reading makes room and unmasks it. A frame
//! from the host while drawing stops the picture within a millisecond and a
//! ray on both cores, and is answered next. The watchdog runs while the
//! board works on a frame (fed each time a drawing reads the port, every
//! millisecond, and at every write to and wait for the host) and is
//! stopped while it sleeps waiting for one: a board wedged at work resets
//! itself. Nothing the host sends can make the board panic.

#![no_std]
#![no_main]

use core::cell::RefCell;
use core::ops::ControlFlow;
use critical_section::Mutex;
use embedded_graphics::pixelcolor::{Rgb565, Rgb888};
use embedded_graphics::prelude::*;
use embedded_graphics::primitives::Rectangle;
use hal::multicore::Stack;
use hal::pac::interrupt;
use hal::{entry, pac, Timer, Watchdog};
use octrace_core::animation::{AnimationNeeds, AnimationRoom};
use octrace_core::{ConstStaticCell, Raytracer, RendererRoom};
use octrace_link::board::{Line, Link, Ring};
use octrace_link::{Panel, PixelFormat};
use octrace_pico::animation::{self, Runs};
use octrace_pico::sleep::Nap;
use octrace_pico::{board, both_cores};
use octrace_pico_st7789::measure::{self, Meter};
use octrace_pico_st7789::panel;
use octrace_pico_st7789::usb::{self, SerialDevice};
use panic_halt as _;
use rp2040_hal as hal;

// boot2, and what build.rs places in SRAM (OCTRACE_CODE_IN) copied there at boot.
octrace_pico::boot!();

/// What the board says it is (octrace-link's `board` answer).
const FIRMWARE: &str = concat!("octrace-pico-live ", env!("CARGO_PKG_VERSION"));

octrace_core::profile! {
    /// The largest scene this firmware holds: what the Pico's 264 KiB of
    /// SRAM leaves beside the code, both cores' stacks and rooms, the
    /// scene's text and the USB rings (README.md states it in objects).
    pub struct LiveProfile {
        spheres: 400, boxes: 32, superquadrics: 32, triangles: 160, rectangles: 160,
        surfaces: 64, lights: 8,
        octree_boxes: 1600, octree_references: 4800,
        light_buffer_lights: 8, light_buffer_words: 4096,
    }
    named_walk: false
    first_hits: true
    coherence: true
}

/// Room for the scene, its octree and core 0's mailbox and lists.
static RAYTRACER: ConstStaticCell<Raytracer<LiveProfile>> = ConstStaticCell::new(Raytracer::new());

/// What the animations it plays may take: a byte a tile of the 240×240
/// panel (3,600), and 8 `MOVE`s of 32 keys in all, however many frames
/// (anim_fig5_1 takes 1 and 6): 6.6 KiB.
const ANIMATION: AnimationNeeds = AnimationNeeds {
    tiles: AnimationNeeds::tiles_for(Size::new(panel::WIDTH as u32, panel::HEIGHT as u32)),
    tracks: 8,
    keys: 32,
};
static ANIMATION_ROOM: ConstStaticCell<AnimationRoom<{ ANIMATION.tiles }, { ANIMATION.tracks }, { ANIMATION.keys }>> =
    ConstStaticCell::new(AnimationRoom::new());

/// Core 1's own mailbox and screen lists.
static CORE1_ROOM: ConstStaticCell<RendererRoom<LiveProfile>> = ConstStaticCell::new(RendererRoom::new());

/// Core 1's stack: 16 KiB, as the template's: its job loop, a drawing's
/// renderer, and an animation's bands, which it traces here (a still's
/// rows it traces on SRAM5, `octrace_pico::bank_stack`; this firmware
/// loads every scene on core 0).
static CORE1_STACK: Stack<4096> = Stack::new();

/// Core 1's rows (a still's) or runs (an animation's) on their way to the panel.
static RUNS: Runs<{ panel::WIDTH as usize }, 4> = Runs::new();

/// The panel's bus buffer.
static PANEL_BUFFER: ConstStaticCell<[u8; 512]> = ConstStaticCell::new([0; 512]);

/// A received frame, the scene's text in it: the longest scene the board takes.
static FRAME_BUFFER: ConstStaticCell<[u8; 32 * 1024]> = ConstStaticCell::new([0; 32 * 1024]);

/// The USB device and its serial port, owned by the USB interrupt.
static USB: Mutex<RefCell<Option<SerialDevice>>> = Mutex::new(RefCell::new(None));

/// Bytes from the host, not yet read by the main loop; and bytes for the
/// host, not yet taken by the USB device.
static INPUT: Mutex<RefCell<Ring<1024>>> = Mutex::new(RefCell::new(Ring::new()));
static OUTPUT: Mutex<RefCell<Ring<1024>>> = Mutex::new(RefCell::new(Ring::new()));

/// The longest the board works on a frame without a sign of life before
/// its watchdog resets it: eight seconds, nearly the RP2040's longest
/// (8.39 s). The longest stretch without one is loading a scene, which is
/// not polled: 4.6 s for the dearest scene this firmware holds (every
/// object of every kind, all overlapping; README.md); a drawing gives one
/// every millisecond.
const WATCHDOG_US: u32 = 8_000_000;

#[entry]
fn main() -> ! {
    let board::Board { mut core1, pins, clocks, mut timer, watchdog, mut resets, peripherals } =
        board::start(CORE1_STACK.take().unwrap());
    let (mut display, _) = panel::init(peripherals.spi1, pins, &mut resets, &clocks, timer, PANEL_BUFFER.take());

    // The USB serial port, served by its interrupt from here on.
    let device = usb::serial_device(
        peripherals.usbctrl_regs,
        peripherals.usbctrl_dpram,
        clocks.usb_clock,
        &mut resets,
        "octrace live",
    );
    critical_section::with(|cs| USB.borrow_ref_mut(cs).replace(device));
    // SAFETY: the handler only touches what the critical sections guard.
    unsafe { pac::NVIC::unmask(pac::Interrupt::USBCTRL_IRQ) };

    let size = display.size();
    let panel = Panel { width: size.width as u16, height: size.height as u16, format: PixelFormat::Rgb565 };
    let mut link = Link::new(panel, FIRMWARE, FRAME_BUFFER.take());
    if let Ok(animation) = ANIMATION_ROOM.take().animation(size) {
        link = link.with_animations(animation);
    }
    let raytracer = RAYTRACER.take();
    let room = CORE1_ROOM.take();
    // Alarm 3, free again once the panel's set-up has slept.
    let nap = Nap::new(&mut timer).expect("the timer's alarm 3 is free after the panel's set-up");
    let mut line = UsbLine { timer, watchdog, meter: Meter::new(timer, peripherals.busctrl), nap };
    loop {
        link.serve(&mut line, raytracer, |drawing, rows| {
            let rows = RefCell::new(rows);
            // Never borrowed twice: a row or a run is sent between asks.
            let mut stop = || rows.try_borrow_mut().map_or(true, |mut rows| rows.poll());
            if let Some(frame) = drawing.frame() {
                // An animation's frame: its planned runs, on both cores,
                // each shown and sent back whole.
                let mut panel = SentRuns {
                    display: &mut display,
                    sent: |area: &Rectangle, run: &[Rgb565]| {
                        let (x, y) = (area.top_left.x as u16, area.top_left.y as u16);
                        if let Ok(mut rows) = rows.try_borrow_mut() {
                            rows.send_run(drawing, y, x, run);
                        }
                    },
                };
                let drawn = animation::draw_frame_until(&mut core1, frame, &mut *room, &RUNS, &mut panel, &mut stop);
                return if drawn.is_ok() { drawing.panel().height } else { 0 };
            }
            let mut drawn = 0;
            let each_row = |y: u32, traced: &[Rgb888]| {
                if let Ok(mut rows) = rows.try_borrow_mut() {
                    // The row as the panel shows it.
                    let mut row = [Rgb565::BLACK; panel::WIDTH as usize];
                    for (pixel, &color) in row.iter_mut().zip(traced) {
                        *pixel = color.into();
                    }
                    rows.send(drawing, y as u16, &row[..traced.len()]);
                }
                drawn = y as u16 + 1;
                ControlFlow::Continue(())
            };
            let _ = both_cores::draw_until(
                &mut core1,
                drawing.scene(),
                &mut *room,
                RUNS.rows(),
                &mut display,
                each_row,
                stop,
            );
            drawn
        });
    }
}

/// The panel as an animation's frame is drawn into it: each run, whole,
/// goes to the display as the panel's colours and then to `sent` (the
/// host); a run cut short (the frame stopped inside it) goes nowhere.
struct SentRuns<'d, D, F> {
    display: &'d mut D,
    sent: F,
}

impl<D: OriginDimensions, F> OriginDimensions for SentRuns<'_, D, F> {
    fn size(&self) -> Size {
        self.display.size()
    }
}

impl<D, F> DrawTarget for SentRuns<'_, D, F>
where
    D: DrawTarget<Color = Rgb565> + OriginDimensions,
    F: FnMut(&Rectangle, &[Rgb565]),
{
    type Color = Rgb888;
    type Error = D::Error;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), D::Error> {
        self.display.draw_iter(pixels.into_iter().map(|Pixel(at, color)| Pixel(at, color.into())))
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb888>>(&mut self, area: &Rectangle, colors: I) -> Result<(), D::Error> {
        let mut run = [Rgb565::BLACK; panel::WIDTH as usize];
        let mut width = 0;
        for (pixel, color) in run.iter_mut().zip(colors) {
            *pixel = color.into();
            width += 1;
        }
        if width < area.size.width as usize {
            return Ok(());
        }
        self.display.fill_contiguous(area, run[..width].iter().copied())?;
        (self.sent)(area, &run[..width]);
        Ok(())
    }
}

/// The USB serial port as the board loop's line: the rings, the timer, the
/// core's sleep, the watchdog and the bus fabric's counters.
struct UsbLine {
    timer: Timer,
    watchdog: Watchdog,
    meter: Meter,
    nap: Nap,
}

impl Line for UsbLine {
    fn read(&mut self) -> Option<u8> {
        try_input_byte()
    }

    fn write(&mut self, bytes: &[u8]) -> usize {
        critical_section::with(|cs| {
            let taken = OUTPUT.borrow_ref_mut(cs).push(bytes);
            // Sent now, whether or not the interrupt is masked.
            serve_usb(cs);
            taken
        })
    }

    fn discard(&mut self) {
        critical_section::with(|cs| OUTPUT.borrow_ref_mut(cs).clear());
    }

    fn now_us(&mut self) -> u64 {
        self.timer.get_counter().ticks()
    }

    fn sleep(&mut self) -> bool {
        // Nothing can wedge while the core sleeps for the host, and an
        // alarm to feed the watchdog would wake it for nothing.
        self.watchdog.disable();
        // With interrupts masked, so that a byte arriving between the look
        // and the sleep still wakes the core (WFI wakes on a pending
        // interrupt).
        cortex_m::interrupt::disable();
        if critical_section::with(|cs| INPUT.borrow_ref(cs).is_empty()) {
            cortex_m::asm::wfi();
        }
        // SAFETY: enabled again as they were: main runs with interrupts on.
        unsafe { cortex_m::interrupt::enable() };
        self.watchdog.start(hal::fugit::MicrosDurationU32::micros(WATCHDOG_US));
        true
    }

    fn wait_for_room(&mut self, at_most_us: u64) {
        // The USB interrupt wakes the core when the host takes a packet
        // (or sends one); the alarm when the wait is over.
        let full = || critical_section::with(|cs| OUTPUT.borrow_ref(cs).room() == 0);
        self.nap.at_most(u32::try_from(at_most_us).unwrap_or(u32::MAX), full);
    }

    fn alive(&mut self) {
        self.watchdog.feed();
        // At least every millisecond while drawing: the counts never run over.
        self.meter.fold();
    }

    fn counter_names(&self) -> &'static [&'static str] {
        &measure::EVENTS
    }

    fn take_counts(&mut self, counts: &mut [u32]) {
        for (count, contested) in counts.iter_mut().zip(self.meter.split().contested) {
            *count = contested;
        }
    }
}

/// The next byte from the host, if one has come.
fn try_input_byte() -> Option<u8> {
    let (byte, was_full) = critical_section::with(|cs| {
        let mut input = INPUT.borrow_ref_mut(cs);
        let was_full = input.room() < 64;
        (input.pop(), was_full)
    });
    // The interrupt stopped reading the port, masked, while the ring was
    // full: there is room again.
    if was_full {
        // SAFETY: the handler only touches what the critical sections guard.
        unsafe { pac::NVIC::unmask(pac::Interrupt::USBCTRL_IRQ) };
        pac::NVIC::pend(pac::Interrupt::USBCTRL_IRQ);
    }
    byte
}

/// Serves the USB device, and moves bytes between it and the rings.
#[interrupt]
fn USBCTRL_IRQ() {
    critical_section::with(serve_usb);
}

/// Polls the USB device and moves bytes between it and the rings: from the
/// USB interrupt, and from the main loop while it waits to send.
fn serve_usb(cs: critical_section::CriticalSection<'_>) {
    let mut usb = USB.borrow_ref_mut(cs);
    let Some((device, serial)) = usb.as_mut() else { return };
    device.poll(&mut [serial]);
    let mut input = INPUT.borrow_ref_mut(cs);
    let mut packet = [0u8; 64];
    // Only as much as the ring holds: the rest waits in the device (the
    // host is told to wait), never lost.
    while input.room() >= packet.len() {
        match serial.read(&mut packet) {
            // Room was checked: all of it is taken.
            Ok(read) if read > 0 => _ = input.push(&packet[..read]),
            _ => break,
        }
    }
    // A full ring leaves the port's data unread, and so the interrupt
    // pending: masked until the main loop has made room, or it would run
    // again at once, for ever (meanwhile the main loop serves the port
    // itself when it sends).
    if input.room() < packet.len() {
        pac::NVIC::mask(pac::Interrupt::USBCTRL_IRQ);
    }
    let mut output = OUTPUT.borrow_ref_mut(cs);
    while !output.is_empty() {
        match serial.write(output.front()) {
            Ok(written) if written > 0 => output.consume(written),
            _ => break,
        }
    }
}
