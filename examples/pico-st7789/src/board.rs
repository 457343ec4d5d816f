//! The Pico's start-up, the same for every firmware: clocks from the 12 MHz
//! crystal (125 MHz system clock, 48 MHz USB clock), the panel on its pins
//! (`panel`), and core 1 waiting for jobs (`both_cores`).
//!
//! Invariants: called once, at the start of `main`; what it does not use
//! of the chip (the USB controller, for the live firmware) is handed back
//! untouched.

use crate::both_cores::SecondCore;
use crate::panel::{self, Panel, PanelPins};
use hal::clocks::UsbClock;
use hal::gpio::Pins;
use hal::multicore::{Multicore, StackAllocation};
use hal::{pac, Clock, Sio, Timer, Watchdog};
use rp2040_hal as hal;

/// The Pico's crystal.
const CRYSTAL_HZ: u32 = 12_000_000;

/// The board, started: the panel (cleared, backlight on), core 1 waiting
/// for jobs, the timer, and what the firmware may use besides.
pub struct Board {
    pub display: Panel,
    pub core1: SecondCore,
    pub timer: Timer,
    /// The bus fabric's control and performance counters, untouched.
    pub busctrl: pac::BUSCTRL,
    /// The USB controller and its clock, untouched.
    pub usb: UsbParts,
    pub resets: pac::RESETS,
}

/// What a USB device needs of the chip (`rp2040_hal::usb::UsbBus::new`).
pub struct UsbParts {
    pub regs: pac::USBCTRL_REGS,
    pub dpram: pac::USBCTRL_DPRAM,
    pub clock: UsbClock,
}

/// Starts the board: `panel_buffer` batches pixels for the panel's bus
/// (512 bytes is plenty), `core1_stack` is core 1's. Panics only where the
/// chip itself refuses to start (a clock that does not lock), as the HAL
/// does.
pub fn start(panel_buffer: &'static mut [u8], core1_stack: StackAllocation) -> Board {
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
    let panel_pins = PanelPins {
        clock: pins.gpio10,
        data: pins.gpio11,
        chip_select: pins.gpio9,
        data_command: pins.gpio8,
        reset: pins.gpio12,
        backlight: pins.gpio13,
    };
    let display = panel::init(
        peripherals.SPI1,
        panel_pins,
        &mut peripherals.RESETS,
        clocks.peripheral_clock.freq(),
        timer,
        panel_buffer,
    );
    let mut multicore = Multicore::new(&mut peripherals.PSM, &mut peripherals.PPB, &mut sio.fifo);
    let core1 = SecondCore::start(&mut multicore.cores()[1], core1_stack)
        .unwrap_or_else(|_| panic!("core 1 did not answer its launch"));
    Board {
        display,
        core1,
        timer,
        busctrl: peripherals.BUSCTRL,
        usb: UsbParts { regs: peripherals.USBCTRL_REGS, dpram: peripherals.USBCTRL_DPRAM, clock: clocks.usb_clock },
        resets: peripherals.RESETS,
    }
}
