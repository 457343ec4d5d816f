//! The LM3S6965EVB's 128×64 OLED with 16 gray levels: an SSD0323 controller
//! on the chip's SSI0 port (SPI), as an embedded-graphics `DrawTarget` with
//! colour `Gray4`. Invariants: no framebuffer (the panel's own RAM is the
//! only copy of the picture, so nothing is ever read back); every transfer
//! waits until its byte has left the port, so the command/data pin is never
//! switched under a byte still being shifted out.
//!
//! Wiring (the board's, and qemu's `lm3s6965evb` model of it):
//!
//! | signal | pin | use |
//! | --- | --- | --- |
//! | SSI0Clk, SSI0Fss, SSI0Tx | PA2, PA3, PA5 | SPI clock, the OLED's chip select, data to the panel |
//! | D/C | PC7 | low: the byte is a command; high: display data |
//! | SD card select | PD0 | driven high: the SD card on the same port stays deselected (qemu also takes this line as the OLED's select, active high) |
//!
//! The controller's display RAM has 64 byte columns × 80 rows; each byte
//! holds two pixels, the left one in the high nibble (as qemu's model shows
//! them), and the panel shows rows 0 to 63. A drawing sets a column window
//! (command `0x15`, first and last byte column) and a row window (`0x75`),
//! then streams bytes: the controller steps right through the window and
//! down row by row. So an area must start on an even column and be an even
//! number of pixels wide (the renderer's whole rows are); single pixels would
//! need the neighbour sharing their byte, which a write-only SPI panel cannot
//! give back — both are reported as errors, never drawn wrong.
//!
//! Tested against qemu's SSD0323 model only; a real panel may want the
//! OSRAM module's contrast, current and phase settings and a different
//! remap byte (nibble order, row order) — see its datasheet.

use core::sync::atomic::{AtomicBool, Ordering};
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{Dimensions, OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::{Gray4, GrayColor};
use embedded_graphics_core::primitives::{PointsIter, Rectangle};
use embedded_graphics_core::Pixel;

/// The panel's size in pixels.
pub const WIDTH: u32 = 128;
pub const HEIGHT: u32 = 64;
/// Rows of the controller's display RAM (the panel shows the first 64).
const RAM_ROWS: u8 = 80;

/// Register addresses of the LM3S6965 (its datasheet's memory map).
mod register {
    /// System control: run-mode clock gating for SSI0 and the GPIO ports.
    pub const RCGC1: usize = 0x400F_E104;
    pub const RCGC2: usize = 0x400F_E108;
    pub const RCGC1_SSI0: u32 = 1 << 4;
    pub const RCGC2_GPIO_ACD: u32 = (1 << 0) | (1 << 2) | (1 << 3);

    pub const GPIO_A: usize = 0x4000_4000;
    pub const GPIO_C: usize = 0x4000_6000;
    pub const GPIO_D: usize = 0x4000_7000;
    /// Offsets in a GPIO port: data (bits 9:2 of the address mask which
    /// pins a write touches), direction, alternate function, digital enable.
    pub const GPIO_DIR: usize = 0x400;
    pub const GPIO_AFSEL: usize = 0x420;
    pub const GPIO_DEN: usize = 0x51C;

    pub const SSI0: usize = 0x4000_8000;
    pub const SSI_CR0: usize = 0x00;
    pub const SSI_CR1: usize = 0x04;
    pub const SSI_DR: usize = 0x08;
    pub const SSI_SR: usize = 0x0C;
    pub const SSI_CPSR: usize = 0x10;
    /// Status: transmit FIFO not full, receive FIFO not empty.
    pub const SR_TNF: u32 = 1 << 1;
    pub const SR_RNE: u32 = 1 << 2;
    /// Control 1: port enabled (master mode is the reset value).
    pub const CR1_SSE: u32 = 1 << 1;
}

/// Pins, as bit masks within their port.
const PA_SSI: u32 = (1 << 2) | (1 << 3) | (1 << 5);
const PC7_DATA_COMMAND: u32 = 1 << 7;
const PD0_SD_SELECT: u32 = 1 << 0;

/// Why a drawing was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error {
    /// Single pixels: each shares its byte with a neighbour the driver
    /// cannot read back.
    SinglePixels,
    /// An area (after clipping to the panel) that starts on an odd column
    /// or is an odd number of pixels wide.
    OddColumns,
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Error::SinglePixels => "the SSD0323 takes pixels in pairs: draw areas, not single pixels",
            Error::OddColumns => {
                "the SSD0323 takes pixels in pairs: areas must start on an even column and be an even width"
            }
        })
    }
}

impl core::error::Error for Error {}

/// Whether the bytes sent next are commands or display data.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    Command,
    Data,
}

/// The OLED, brought up and cleared. At most one exists: it owns SSI0 and
/// the pins above.
pub struct Ssd0323 {
    mode: Mode,
}

/// Set once the one `Ssd0323` has been made.
static TAKEN: AtomicBool = AtomicBool::new(false);

impl Ssd0323 {
    /// Brings up the clocks, pins and SSI0, initialises the controller and
    /// clears the panel's RAM (it holds noise at power-up). `None` if the
    /// panel has already been taken.
    pub fn take() -> Option<Ssd0323> {
        use register::*;
        if TAKEN.swap(true, Ordering::Relaxed) {
            return None;
        }
        write(RCGC1, read(RCGC1) | RCGC1_SSI0);
        write(RCGC2, read(RCGC2) | RCGC2_GPIO_ACD);
        // A peripheral must not be touched for a few cycles after its clock
        // is enabled: these reads are those cycles.
        for _ in 0..3 {
            read(RCGC2);
        }
        write(GPIO_A + GPIO_AFSEL, read(GPIO_A + GPIO_AFSEL) | PA_SSI);
        write(GPIO_A + GPIO_DEN, read(GPIO_A + GPIO_DEN) | PA_SSI);
        for (port, pin) in [(GPIO_C, PC7_DATA_COMMAND), (GPIO_D, PD0_SD_SELECT)] {
            write(port + GPIO_DIR, read(port + GPIO_DIR) | pin);
            write(port + GPIO_DEN, read(port + GPIO_DEN) | pin);
        }
        write_pins(GPIO_D, PD0_SD_SELECT, PD0_SD_SELECT);
        write_pins(GPIO_C, PC7_DATA_COMMAND, 0);

        // SPI mode 3 (clock idles high, data sampled on the rising edge,
        // where the SSD0323 latches it), 8-bit frames, the system clock
        // divided by 8 (prescaler 4, serial clock rate 1): 1 MHz from the
        // board's 8 MHz crystal, about 2 MHz at most from the chip's
        // internal oscillator, within the controller's limit.
        write(SSI0 + SSI_CR1, 0);
        write(SSI0 + SSI_CPSR, 4);
        write(SSI0 + SSI_CR0, (1 << 8) | (1 << 7) | (1 << 6) | 7);
        write(SSI0 + SSI_CR1, CR1_SSE);

        // The pin was set low just above.
        let mut panel = Ssd0323 { mode: Mode::Command };
        panel.command(&[
            0xAE, // display off while it is set up
            0xA0, 0x00, // remap: horizontal address increment
            0xA1, 0x00, // display start line 0
            0xA2, 0x00, // display offset 0
            0xA8, 0x3F, // multiplex ratio: 64 rows
            0xA4, // normal display (RAM contents, not all on or inverted)
        ]);
        panel.window(0, 63, 0, RAM_ROWS - 1);
        panel.set_mode(Mode::Data);
        for _ in 0..64 * RAM_ROWS as u32 {
            transfer(0);
        }
        panel.command(&[0xAF]); // display on
        Some(panel)
    }

    fn set_mode(&mut self, mode: Mode) {
        if self.mode != mode {
            write_pins(register::GPIO_C, PC7_DATA_COMMAND, if mode == Mode::Data { PC7_DATA_COMMAND } else { 0 });
            self.mode = mode;
        }
    }

    fn command(&mut self, bytes: &[u8]) {
        self.set_mode(Mode::Command);
        for &b in bytes {
            transfer(b);
        }
    }

    /// Sets the byte columns and rows (inclusive) the next data fills.
    fn window(&mut self, first_column: u8, last_column: u8, first_row: u8, last_row: u8) {
        self.command(&[0x15, first_column, last_column, 0x75, first_row, last_row]);
    }
}

impl OriginDimensions for Ssd0323 {
    fn size(&self) -> Size {
        Size::new(WIDTH, HEIGHT)
    }
}

impl DrawTarget for Ssd0323 {
    type Color = Gray4;
    type Error = Error;

    /// Refused (unless empty): see [`Error::SinglePixels`].
    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Error>
    where
        I: IntoIterator<Item = Pixel<Gray4>>,
    {
        match pixels.into_iter().next() {
            None => Ok(()),
            Some(_) => Err(Error::SinglePixels),
        }
    }

    /// Streams `area` (clipped to the panel) row by row through one window.
    fn fill_contiguous<I>(&mut self, area: &Rectangle, colors: I) -> Result<(), Error>
    where
        I: IntoIterator<Item = Gray4>,
    {
        let shown = area.intersection(&self.bounding_box());
        if shown.size.width == 0 || shown.size.height == 0 {
            return Ok(());
        }
        let (x, y) = (shown.top_left.x as u32, shown.top_left.y as u32);
        if !x.is_multiple_of(2) || !shown.size.width.is_multiple_of(2) {
            return Err(Error::OddColumns);
        }
        // Inside the panel, so every bound fits a byte.
        let last_x = x + shown.size.width - 1;
        let last_y = y + shown.size.height - 1;
        self.window((x / 2) as u8, (last_x / 2) as u8, y as u8, last_y as u8);
        self.set_mode(Mode::Data);
        let mut left = None;
        for (point, color) in area.points().zip(colors) {
            if !shown.contains(point) {
                continue;
            }
            match left.take() {
                None => left = Some(color.luma()),
                Some(l) => transfer((l << 4) | color.luma()),
            }
        }
        Ok(())
    }
}

/// Sends one byte and waits until it has gone: the port answers each byte
/// with one received (ignored), so its arrival means the byte left the wire.
fn transfer(byte: u8) {
    use register::*;
    while read(SSI0 + SSI_SR) & SR_TNF == 0 {}
    write(SSI0 + SSI_DR, byte as u32);
    while read(SSI0 + SSI_SR) & SR_RNE == 0 {}
    read(SSI0 + SSI_DR);
}

/// Sets the pins `mask` of a GPIO port to `value` (masked), leaving the
/// port's other pins alone: the address selects the pins a write touches.
fn write_pins(port: usize, mask: u32, value: u32) {
    write(port + ((mask as usize) << 2), value & mask);
}

fn read(address: usize) -> u32 {
    // SAFETY: every caller passes one of the LM3S6965's memory-mapped
    // registers above: word-aligned, always mapped, and reading them has no
    // effect the driver does not expect (the SSI data register's read pops
    // the reply `transfer` discards).
    unsafe { core::ptr::read_volatile(address as *const u32) }
}

fn write(address: usize, value: u32) {
    // SAFETY: as for `read`; the driver owns SSI0 and the pins it writes
    // (`take` makes at most one `Ssd0323`), so no other code races these writes.
    unsafe { core::ptr::write_volatile(address as *mut u32, value) }
}
