//! The Pico's start-up, the same for every firmware: clocks from the 12 MHz
//! crystal (125 MHz system clock, 48 MHz USB clock), the timer, the GPIO
//! pins handed out, and core 1 waiting for jobs ([`SecondCore`]); the
//! firmware then sets up its panel from [`Board`]'s pins and peripherals.
//!
//! Invariants: called once, at the start of `main`; every peripheral it
//! does not use to start the chip is handed back untouched in [`Board`].

use crate::second_core::SecondCore;
use hal::clocks::ClocksManager;
use hal::gpio::Pins;
use hal::multicore::{Multicore, StackAllocation};
use hal::{pac, Sio, Timer, Watchdog};
use rp2040_hal as hal;

/// The Pico's crystal.
const CRYSTAL_HZ: u32 = 12_000_000;

/// The board, started: core 1 waiting for jobs, the clocks and the timer
/// running, and what the firmware sets its panel (and the rest) up from.
pub struct Board {
    pub core1: SecondCore,
    /// Every GPIO pin, as `Pins::new` hands them out.
    pub pins: Pins,
    /// The clocks: `system_clock` at 125 MHz (`peripheral_clock` follows
    /// it), `usb_clock` at 48 MHz.
    pub clocks: ClocksManager,
    pub timer: Timer,
    /// The watchdog, ticking (the clocks' set-up starts its tick) but not
    /// started.
    pub watchdog: Watchdog,
    pub resets: pac::RESETS,
    /// The peripherals a panel or a host link takes, untouched.
    pub peripherals: Peripherals,
}

/// The peripherals [`start`] leaves untouched, for the firmware.
pub struct Peripherals {
    pub spi0: pac::SPI0,
    pub spi1: pac::SPI1,
    pub i2c0: pac::I2C0,
    pub i2c1: pac::I2C1,
    pub uart0: pac::UART0,
    pub uart1: pac::UART1,
    pub pwm: pac::PWM,
    pub dma: pac::DMA,
    pub pio0: pac::PIO0,
    pub pio1: pac::PIO1,
    pub usbctrl_regs: pac::USBCTRL_REGS,
    pub usbctrl_dpram: pac::USBCTRL_DPRAM,
    /// The bus fabric's control and performance counters.
    pub busctrl: pac::BUSCTRL,
}

/// Starts the board, core 1 on `core1_stack`. Panics only where the chip
/// itself refuses to start (a clock that does not lock, core 1 that does
/// not answer its launch), as the HAL does.
pub fn start(core1_stack: StackAllocation) -> Board {
    let mut peripherals = pac::Peripherals::take().unwrap();
    let mut watchdog = Watchdog::new(peripherals.WATCHDOG);
    let clocks = hal::clocks::init_clocks_and_plls(
        CRYSTAL_HZ,
        peripherals.XOSC,
        peripherals.CLOCKS,
        peripherals.PLL_SYS,
        peripherals.PLL_USB,
        &mut peripherals.RESETS,
        &mut watchdog,
    )
    .unwrap_or_else(|_| panic!("the clocks did not start"));
    let timer = Timer::new(peripherals.TIMER, &mut peripherals.RESETS, &clocks);
    let mut sio = Sio::new(peripherals.SIO);
    let pins = Pins::new(peripherals.IO_BANK0, peripherals.PADS_BANK0, sio.gpio_bank0, &mut peripherals.RESETS);
    let mut multicore = Multicore::new(&mut peripherals.PSM, &mut peripherals.PPB, &mut sio.fifo);
    let core1 = SecondCore::start(&mut multicore.cores()[1], core1_stack)
        .unwrap_or_else(|_| panic!("core 1 did not answer its launch"));
    Board {
        core1,
        pins,
        clocks,
        timer,
        watchdog,
        resets: peripherals.RESETS,
        peripherals: Peripherals {
            spi0: peripherals.SPI0,
            spi1: peripherals.SPI1,
            i2c0: peripherals.I2C0,
            i2c1: peripherals.I2C1,
            uart0: peripherals.UART0,
            uart1: peripherals.UART1,
            pwm: peripherals.PWM,
            dma: peripherals.DMA,
            pio0: peripherals.PIO0,
            pio1: peripherals.PIO1,
            usbctrl_regs: peripherals.USBCTRL_REGS,
            usbctrl_dpram: peripherals.USBCTRL_DPRAM,
            busctrl: peripherals.BUSCTRL,
        },
    }
}
