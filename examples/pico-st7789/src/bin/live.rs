//! octrace live on a Raspberry Pi Pico: flash it once, then send it scenes.
//! The Pico enumerates as a USB serial port; `host-sim board PORT
//! scene.txt` (or the studio's "Send to board") sends a scene, and the Pico
//! answers with its errors at line and column, or draws it on the panel
//! with both cores (sending the rows back when asked), then waits for the
//! next. The protocol is octrace-link's (`docs/board-protocol.md`).
//!
//! Invariants: the USB device lives in the USB interrupt, which moves bytes
//! between it and two rings (`INPUT`, `OUTPUT`); the main loop on core 0
//! only reads `INPUT` and writes `OUTPUT`, so the port answers the host
//! while a picture is traced. While `INPUT` is full the interrupt is masked
//! and the host waits (its bytes stay in the port); reading makes room and
//! unmasks it. A frame from the host while drawing stops the
//! picture after the current row, and is answered next. A host that stops
//! reading for `STALLED_AFTER_US` loses what the board would send, never
//! wedges it. Nothing the host sends can make the board panic: every frame
//! gets an answer from octrace-link's `Board`.

#![no_std]
#![no_main]

use core::cell::RefCell;
use core::ops::ControlFlow;
use core::time::Duration;
use critical_section::Mutex;
use hal::multicore::Stack;
use hal::pac::interrupt;
use hal::{entry, pac, Timer};
use heapless::Deque;
use octrace_core::render::Handoff;
use octrace_core::{ConstStaticCell, Raytracer, RendererRoom};
use octrace_link::board::Board;
use octrace_link::{Counter, Counters, Decoder, Panel, PixelFormat, Sink, Timing};
use octrace_pico_st7789::measure::{self, Meter, Span};
use octrace_pico_st7789::usb::{self, SerialDevice};
use octrace_pico_st7789::{board, both_cores, panel};
use panic_halt as _;
use rp2040_hal as hal;

// The render path runs from SRAM (build.rs): copied there at boot.
octrace_pico_st7789::copy_code_into_sram!();

/// The second-stage loader for the Pico's W25Q16JV flash (see memory.x).
#[link_section = ".boot2"]
#[used]
static BOOT2: [u8; 256] = rp2040_boot2::BOOT_LOADER_W25Q080;

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
}

/// Room for the scene, its octree and core 0's mailbox and lists.
static RAYTRACER: ConstStaticCell<Raytracer<LiveProfile>> = ConstStaticCell::new(Raytracer::new());

/// Core 1's own mailbox and screen lists.
static CORE1_ROOM: ConstStaticCell<RendererRoom<LiveProfile>> = ConstStaticCell::new(RendererRoom::new());

/// Core 1's stack: 16 KiB.
static CORE1_STACK: Stack<4096> = Stack::new();

/// Core 1's rows on their way to the panel.
static ROWS: Handoff<{ panel::WIDTH as usize }, 4> = Handoff::new();

/// The panel's bus buffer.
static PANEL_BUFFER: ConstStaticCell<[u8; 512]> = ConstStaticCell::new([0; 512]);

/// A received frame, the scene's text in it: the longest scene the board takes.
static FRAME_BUFFER: ConstStaticCell<[u8; 24 * 1024]> = ConstStaticCell::new([0; 24 * 1024]);

/// The USB device and its serial port, owned by the USB interrupt.
static USB: Mutex<RefCell<Option<SerialDevice>>> = Mutex::new(RefCell::new(None));

/// Bytes from the host, not yet read by the main loop; and bytes for the
/// host, not yet taken by the USB device.
static INPUT: Mutex<RefCell<Deque<u8, 1024>>> = Mutex::new(RefCell::new(Deque::new()));
static OUTPUT: Mutex<RefCell<Deque<u8, 1024>>> = Mutex::new(RefCell::new(Deque::new()));

/// How long the board waits for a host that does not read before it drops
/// what it sends (a second).
const STALLED_AFTER_US: u64 = 1_000_000;

#[entry]
fn main() -> ! {
    let board::Board { mut display, mut core1, timer, busctrl, usb, mut resets } =
        board::start(PANEL_BUFFER.take(), CORE1_STACK.take().unwrap());

    // The USB serial port, served by its interrupt from here on.
    let device = usb::serial_device(usb, &mut resets, "octrace live");
    critical_section::with(|cs| USB.borrow_ref_mut(cs).replace(device));
    // SAFETY: the handler only touches what the critical sections guard.
    unsafe { pac::NVIC::unmask(pac::Interrupt::USBCTRL_IRQ) };

    let mut decoder = Decoder::new(FRAME_BUFFER.take());
    let size = display.bounding_box_size();
    let panel = Panel { width: size.0, height: size.1, format: PixelFormat::Rgb565 };
    let board = Board::new(panel, FIRMWARE, &decoder);
    let raytracer = RAYTRACER.take();
    let room = CORE1_ROOM.take();
    let mut host = Host { timer, stalled: false };
    let mut meter = Meter::new(timer, busctrl);
    // A frame that came while drawing, to be answered next.
    let mut pending = false;
    loop {
        if !pending {
            let byte = next_input_byte();
            if decoder.push(byte).is_none() {
                continue;
            }
        }
        pending = false;
        let Some(received) = decoder.received() else { continue };
        host.stalled = false;
        // The board's time from the whole scene received to the last row
        // drawn: the load (parse and index), then the render.
        meter.start();
        let Ok(Some(drawing)) = board.answer(received, raytracer, &mut host) else { continue };
        let load = meter.split();
        let mut rows = 0u16;
        let drawn = both_cores::draw(&mut core1, drawing.scene(), room, &ROWS, &mut display, |y, row| {
            rows = y as u16 + 1;
            if drawing.send_row(y as u16, row, &mut host).is_err() {
                return ControlFlow::Break(());
            }
            // Between rows, without waiting: a new frame stops the picture.
            while let Some(byte) = try_input_byte() {
                if decoder.push(byte).is_some() {
                    pending = true;
                    return ControlFlow::Break(());
                }
            }
            ControlFlow::Continue(())
        });
        let answered = match drawn {
            Ok(()) => {
                let render = meter.split();
                let counters = core::array::from_fn::<_, 4, _>(|bank| Counter {
                    name: measure::EVENTS[bank],
                    load: load.contested[bank],
                    render: render.contested[bank],
                });
                let micros = |span: Span| Some(Duration::from_micros(span.micros));
                let timing = Timing {
                    elapsed: Some(Duration::from_micros(load.micros + render.micros)),
                    load: micros(load),
                    render: micros(render),
                    counters: Counters::new(&counters),
                };
                drawing.finish(&timing, &mut host)
            }
            Err(_) => drawing.cancel(rows, &mut host),
        };
        // A host that stopped reading gets nothing more of this picture.
        if answered.is_err() {
            critical_section::with(|cs| OUTPUT.borrow_ref_mut(cs).clear());
        }
    }
}

trait BoundingBoxSize {
    fn bounding_box_size(&self) -> (u16, u16);
}

impl<D: embedded_graphics::prelude::OriginDimensions> BoundingBoxSize for D {
    fn bounding_box_size(&self) -> (u16, u16) {
        let size = self.size();
        (size.width as u16, size.height as u16)
    }
}

/// The host's side of the port, as octrace-link writes to it: bytes into
/// `OUTPUT`, waiting while it is full, up to `STALLED_AFTER_US`.
struct Host {
    timer: Timer,
    /// The host stopped reading: what is left of this answer is dropped.
    stalled: bool,
}

/// The host did not read what the board sends.
#[derive(Debug)]
struct Stalled;

impl Sink for Host {
    type Error = Stalled;

    fn write_all(&mut self, bytes: &[u8]) -> Result<(), Stalled> {
        if self.stalled {
            return Err(Stalled);
        }
        let mut rest = bytes;
        let mut since = self.timer.get_counter();
        while !rest.is_empty() {
            let taken = critical_section::with(|cs| {
                let taken = {
                    let mut output = OUTPUT.borrow_ref_mut(cs);
                    let room = output.capacity() - output.len();
                    let taken = room.min(rest.len());
                    for &byte in &rest[..taken] {
                        // Room was checked: never refused.
                        let _ = output.push_back(byte);
                    }
                    taken
                };
                // Sent now, whether or not the interrupt is masked.
                serve_usb(cs);
                taken
            });
            rest = &rest[taken..];
            if taken > 0 {
                since = self.timer.get_counter();
            } else if (self.timer.get_counter() - since).to_micros() > STALLED_AFTER_US {
                self.stalled = true;
                return Err(Stalled);
            }
        }
        Ok(())
    }
}

/// The next byte from the host, sleeping until one comes.
fn next_input_byte() -> u8 {
    loop {
        // With interrupts masked, so that one arriving between the look and
        // the sleep still wakes the core (WFI wakes on a pending interrupt).
        cortex_m::interrupt::disable();
        let byte = try_input_byte();
        if byte.is_none() {
            cortex_m::asm::wfi();
        }
        // SAFETY: enabled again as they were: main runs with interrupts on.
        unsafe { cortex_m::interrupt::enable() };
        if let Some(byte) = byte {
            return byte;
        }
    }
}

/// The next byte from the host, if one has come.
fn try_input_byte() -> Option<u8> {
    let (byte, was_full) = critical_section::with(|cs| {
        let mut input = INPUT.borrow_ref_mut(cs);
        let was_full = input.capacity() - input.len() < 64;
        (input.pop_front(), was_full)
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
    while input.capacity() - input.len() >= packet.len() {
        match serial.read(&mut packet) {
            Ok(read) if read > 0 => packet[..read].iter().for_each(|&byte| {
                let _ = input.push_back(byte);
            }),
            _ => break,
        }
    }
    // A full ring leaves the port's data unread, and so the interrupt
    // pending: masked until the main loop has made room, or it would run
    // again at once, for ever (meanwhile the main loop serves the port
    // itself when it sends).
    if input.capacity() - input.len() < packet.len() {
        pac::NVIC::mask(pac::Interrupt::USBCTRL_IRQ);
    }
    let mut output = OUTPUT.borrow_ref_mut(cs);
    while !output.is_empty() {
        let (front, _) = output.as_slices();
        match serial.write(front) {
            Ok(written) if written > 0 => {
                for _ in 0..written {
                    output.pop_front();
                }
            }
            _ => break,
        }
    }
}
