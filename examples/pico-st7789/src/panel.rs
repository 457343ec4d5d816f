//! The panel: a Waveshare Pico-LCD-1.3 (ST7789VW, 240×240 IPS) on SPI1, set
//! up through `mipidsi` and cleared to black, backlight on.
//!
//! Invariants: the pins are the Pico-LCD-1.3's (README.md has the table);
//! the bus runs at [`BUS_HZ`] or the fastest of SPI1's rates under it, its
//! transmit FIFO kept full; the panel shows true colours only with the
//! controller's inversion on.

use embedded_graphics::pixelcolor::Rgb565;
use embedded_graphics::prelude::*;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::{ErrorType, SpiBus, MODE_0};
use embedded_hal_bus::spi::ExclusiveDevice;
use embedded_hal_nb::spi::FullDuplex;
use hal::clocks::ClocksManager;
use hal::fugit::RateExtU32;
use hal::gpio::bank0::{Gpio10, Gpio11, Gpio12, Gpio25, Gpio8, Gpio9};
use hal::gpio::{FunctionSioOutput, FunctionSpi, Pin, Pins, PullDown};
use hal::spi::Enabled;
use hal::{pac, Clock, Spi, Timer};
use mipidsi::interface::SpiInterface;
use mipidsi::models::ST7789;
use mipidsi::options::ColorInversion;
use mipidsi::{Builder, Display};
use octrace_pico::sleep::SleepingDelay;
use rp2040_hal as hal;

/// The panel's size in pixels.
pub const WIDTH: u16 = 240;
pub const HEIGHT: u16 = 240;

/// The bus's clock, at most: 33⅓ MHz, a sixth of the rated 200 MHz system
/// clock (at 125 MHz SPI1 makes 31.25 MHz of it, a quarter). The ST7789
/// takes up to 62.5 MHz (its 16 ns write cycle); jumper wires to a loose
/// panel carry this too, and the tracer, not the bus, sets the pace.
pub const BUS_HZ: u32 = 33_333_333;

type Output<Id> = Pin<Id, FunctionSioOutput, PullDown>;

/// The Pico's own LED (GP25), off: the embedded-scene firmware lights it
/// while it works on a picture or a frame (the emulator tells frames by it).
pub type Led = Output<Gpio25>;
type SpiPin<Id> = Pin<Id, FunctionSpi, PullDown>;
type Spi1 = Spi<Enabled, pac::SPI1, (SpiPin<Gpio11>, SpiPin<Gpio10>), 8>;

/// The panel as an embedded-graphics `DrawTarget` of `Rgb565`.
pub type Panel = Display<
    SpiInterface<'static, ExclusiveDevice<StreamingBus, Output<Gpio9>, Timer>, Output<Gpio8>>,
    ST7789,
    Output<Gpio12>,
>;

/// SPI1 writing as pico-sdk's `spi_write_blocking` does: the next byte goes
/// into the transmit FIFO while the last ones shift out, and what comes back
/// is thrown away as it arrives. rp2040-hal's `SpiBus::write` waits for each
/// byte's answer before it sends the next, which cost core 0 about three
/// times the wire's time (12 M cycles a 240×240 picture, against under 5 M).
pub struct StreamingBus(Spi1);

impl StreamingBus {
    /// Empties the receive FIFO.
    fn drain(&mut self) {
        while FullDuplex::read(&mut self.0).is_ok() {}
    }

    /// Waits until the last byte is out, then empties the receive FIFO: what
    /// comes back after that answers the next byte sent.
    fn settle(&mut self) {
        let Ok(()) = SpiBus::flush(&mut self.0);
        self.drain();
    }
}

impl ErrorType for StreamingBus {
    type Error = core::convert::Infallible;
}

impl SpiBus for StreamingBus {
    fn read(&mut self, words: &mut [u8]) -> Result<(), Self::Error> {
        self.settle();
        SpiBus::read(&mut self.0, words)
    }

    fn write(&mut self, words: &[u8]) -> Result<(), Self::Error> {
        for &word in words {
            while FullDuplex::write(&mut self.0, word).is_err() {}
            // The receive FIFO holds 8 answers: keep it from overflowing.
            self.drain();
        }
        Ok(())
    }

    fn transfer(&mut self, read: &mut [u8], write: &[u8]) -> Result<(), Self::Error> {
        self.settle();
        SpiBus::transfer(&mut self.0, read, write)
    }

    fn transfer_in_place(&mut self, words: &mut [u8]) -> Result<(), Self::Error> {
        self.settle();
        SpiBus::transfer_in_place(&mut self.0, words)
    }

    /// Before the chip select or the data/command pin changes.
    fn flush(&mut self) -> Result<(), Self::Error> {
        self.settle();
        Ok(())
    }
}

/// Sets up the panel on the Pico-LCD-1.3's pins (README.md: SPI1 clock
/// GP10, data GP11; chip select GP9, data/command GP8, reset GP12,
/// backlight GP13), clears it to black and turns its backlight on;
/// returns it with the Pico's LED, the one pin left that a firmware uses.
/// `buffer` batches pixels for the bus (512 bytes is plenty).
pub fn init(
    spi1: pac::SPI1,
    pins: Pins,
    resets: &mut pac::RESETS,
    clocks: &ClocksManager,
    timer: Timer,
    buffer: &'static mut [u8],
) -> (Panel, Led) {
    let bus = Spi::<_, _, _, 8>::new(
        spi1,
        (pins.gpio11.into_function::<FunctionSpi>(), pins.gpio10.into_function::<FunctionSpi>()),
    )
    .init(resets, clocks.peripheral_clock.freq(), BUS_HZ.Hz(), MODE_0);
    let chip_select = pins.gpio9.into_push_pull_output();
    let device = ExclusiveDevice::new(StreamingBus(bus), chip_select, timer).unwrap_or_else(|never| match never {});
    let interface = SpiInterface::new(device, pins.gpio8.into_push_pull_output(), buffer);
    // The set-up's 300 ms of waits asleep.
    let mut display = Builder::new(ST7789, interface)
        .display_size(WIDTH, HEIGHT)
        .invert_colors(ColorInversion::Inverted)
        .reset_pin(pins.gpio12.into_push_pull_output())
        .init(&mut SleepingDelay::new(timer))
        .unwrap_or_else(|_| panic!("the panel did not take its set-up"));
    display.clear(Rgb565::BLACK).unwrap_or_else(|never| match never {});
    let mut backlight = pins.gpio13.into_push_pull_output();
    backlight.set_high().unwrap_or_else(|never| match never {});
    (display, pins.gpio25.into_push_pull_output())
}
