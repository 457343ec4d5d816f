//! The panel: a 128×64 SSD1306 OLED module on I2C0 (SDA GP4, SCL GP5, at
//! its usual address 0x3C) at 400 kHz, driven through the `ssd1306` crate's
//! buffered graphics mode, set up and cleared.
//!
//! Invariants: the pins are the wiring README.md gives; the bus runs at the
//! SSD1306's fastest, 400 kHz (its datasheet's I2C timing); the crate's
//! 1 KiB buffer holds the picture until `flush` sends it.

use hal::clocks::ClocksManager;
use hal::fugit::RateExtU32;
use hal::gpio::bank0::{Gpio4, Gpio5};
use hal::gpio::{FunctionI2C, FunctionNull, Pin, PullDown, PullUp};
use hal::{pac, Clock, I2C};
use rp2040_hal as hal;
use ssd1306::mode::BufferedGraphicsMode;
use ssd1306::prelude::*;
use ssd1306::{I2CDisplayInterface, Ssd1306};

/// The panel's width and height in pixels.
pub const WIDTH: usize = 128;
pub const HEIGHT: usize = 64;

/// The bus's clock: the SSD1306's fastest.
const BUS_HZ: u32 = 400_000;

type Bus = I2C<pac::I2C0, (Pin<Gpio4, FunctionI2C, PullUp>, Pin<Gpio5, FunctionI2C, PullUp>)>;

/// The panel as an embedded-graphics `DrawTarget` of `BinaryColor` (the
/// crate's buffer: `flush` sends what changed).
pub type Panel = Ssd1306<I2CInterface<Bus>, DisplaySize128x64, BufferedGraphicsMode<DisplaySize128x64>>;

/// Sets up the panel on I2C0's pins GP4 (SDA) and GP5 (SCL) and clears it
/// (the SSD1306's memory holds noise at power-on). Panics where the panel
/// does not answer (not wired, or at another address).
pub fn init(
    i2c0: pac::I2C0,
    sda: Pin<Gpio4, FunctionNull, PullDown>,
    scl: Pin<Gpio5, FunctionNull, PullDown>,
    resets: &mut pac::RESETS,
    clocks: &ClocksManager,
) -> Panel {
    // The Pico's own pull-ups as well as the module's.
    let bus = I2C::i2c0(i2c0, sda.reconfigure(), scl.reconfigure(), BUS_HZ.Hz(), resets, clocks.system_clock.freq());
    let mut display = Ssd1306::new(I2CDisplayInterface::new(bus), DisplaySize128x64, DisplayRotation::Rotate0)
        .into_buffered_graphics_mode();
    // `init` also clears the buffer; the flush clears the panel.
    if display.init().and_then(|()| display.flush()).is_err() {
        panic!("the panel did not answer at 0x3C");
    }
    display
}
