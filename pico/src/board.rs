//! The Pico's start-up, the same for every firmware: the system clock from
//! the 12 MHz crystal at [`SYSTEM_CLOCK`] (the RP2040's rated 200 MHz, with
//! the core voltage it needs; 48 MHz for USB), the timer, the GPIO pins
//! handed out, and core 1 waiting for jobs ([`SecondCore`]); the firmware
//! then sets up its panel from [`Board`]'s pins and peripherals.
//!
//! Invariants: called once, at the start of `main`; every peripheral it
//! does not use to start the chip is handed back untouched in [`Board`];
//! the core voltage is raised, and has settled, before clk_sys leaves the
//! crystal for a clock that needs it; the flash's serial clock stays within
//! its rating (checked when this crate builds).

use crate::boot::BOOT2_FLASH_DIVIDER;
use crate::second_core::SecondCore;
use hal::clocks::{Clock, ClockSource, ClocksManager};
use hal::fugit::{HertzU32, RateExtU32};
use hal::gpio::Pins;
use hal::multicore::{Multicore, StackAllocation};
use hal::pac::vreg_and_chip_reset::vreg::VSEL_A;
use hal::pll::{common_configs::PLL_USB_48MHZ, setup_pll_blocking, PLLConfig};
use hal::xosc::setup_xosc_blocking;
use hal::{pac, Sio, Timer, Watchdog};
use rp2040_hal as hal;

/// The clock every Pico firmware runs at. For the Pico SDK's default and
/// the RP2040's first rating, 125 MHz at the reset voltage, make this
/// `SystemClock::SDK_DEFAULT_125_MHZ`.
pub const SYSTEM_CLOCK: SystemClock = SystemClock::RATED_200_MHZ;

/// A system clock the start-up sets: PLL_SYS's setting from the crystal,
/// and the core voltage the RP2040's datasheet rates that clock at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SystemClock {
    /// clk_sys, and clk_peri with it (the SPI's and UART's reference).
    pub hz: u32,
    /// PLL_SYS's VCO, a multiple of the crystal's 12 MHz (750 to 1600 MHz).
    pub vco_mhz: u32,
    /// PLL_SYS's two post dividers (1 to 7 each): `hz` is the VCO over both.
    pub post_dividers: (u8, u8),
    /// The core voltage the clock needs at least (the regulator's VSEL).
    pub core_voltage: VSEL_A,
}

impl SystemClock {
    /// 200 MHz, the RP2040's fastest rated clock (its datasheet's current
    /// revision), as the Pico SDK sets it under
    /// `PICO_USE_FASTEST_SUPPORTED_CLOCK`: the VCO at 1200 MHz (100 × 12 MHz)
    /// over 6 and 1, the core at 1.15 V, raised 1 ms before clk_sys leaves
    /// the crystal.
    pub const RATED_200_MHZ: SystemClock =
        SystemClock { hz: 200_000_000, vco_mhz: 1200, post_dividers: (6, 1), core_voltage: VSEL_A::VOLTAGE1_15 };

    /// 125 MHz, the Pico SDK's default: the VCO at 1500 MHz over 6 and 2,
    /// at the regulator's reset voltage, 1.10 V.
    pub const SDK_DEFAULT_125_MHZ: SystemClock =
        SystemClock { hz: 125_000_000, vco_mhz: 1500, post_dividers: (6, 2), core_voltage: VSEL_A::VOLTAGE1_10 };

    /// PLL_SYS's setting, from the crystal undivided.
    fn pll(&self) -> PLLConfig {
        let (post_div1, post_div2) = self.post_dividers;
        PLLConfig { vco_freq: HertzU32::MHz(self.vco_mhz), refdiv: 1, post_div1, post_div2 }
    }
}

/// The Pico's crystal.
const CRYSTAL_HZ: u32 = 12_000_000;

/// How long the core voltage takes to settle once raised: the Pico SDK's
/// wait (`SYS_CLK_VREG_VOLTAGE_AUTO_ADJUST_DELAY_US`), 1 ms.
const VOLTAGE_SETTLE_CYCLES_AT_CRYSTAL: u32 = CRYSTAL_HZ / 1000;

/// The fastest serial clock the Pico's flash, a W25Q16JV, takes for the
/// quad reads XIP makes (FR in its datasheet's AC characteristics).
const FLASH_MAX_HZ: u32 = 133_000_000;

// The PLL makes the clock named.
const _: () = assert!(
    SYSTEM_CLOCK.vco_mhz * 1_000_000 / (SYSTEM_CLOCK.post_dividers.0 as u32 * SYSTEM_CLOCK.post_dividers.1 as u32)
        == SYSTEM_CLOCK.hz
);
// The flash runs at clk_sys over boot2's divider (2, the Pico SDK's
// PICO_FLASH_SPI_CLKDIV for the Pico): 100 MHz at 200 MHz. A faster
// clock needs a boot2 with a larger divider.
const _: () = assert!(SYSTEM_CLOCK.hz / BOOT2_FLASH_DIVIDER <= FLASH_MAX_HZ);

/// The board, started: core 1 waiting for jobs, the clocks and the timer
/// running, and what the firmware sets its panel (and the rest) up from.
pub struct Board {
    pub core1: SecondCore,
    /// Every GPIO pin, as `Pins::new` hands them out.
    pub pins: Pins,
    /// The clocks: `system_clock` at [`SYSTEM_CLOCK`] (`peripheral_clock`
    /// follows it), `usb_clock` at 48 MHz.
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
    let clocks = start_clocks(
        (peripherals.XOSC, peripherals.CLOCKS, peripherals.PLL_SYS, peripherals.PLL_USB),
        &mut peripherals.VREG_AND_CHIP_RESET,
        &mut peripherals.RESETS,
        &mut watchdog,
    )
    .unwrap_or_else(|| panic!("the clocks did not start"));
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

/// The clocks, as rp2040-hal's `init_clocks_and_plls` starts them but at
/// [`SYSTEM_CLOCK`]: the crystal (and the watchdog's microsecond tick from
/// it), both PLLs, the core voltage the clock needs, then clk_sys from
/// PLL_SYS, clk_peri from clk_sys, USB, ADC and RTC from PLL_USB. None when
/// a clock does not start.
fn start_clocks(
    (xosc, clocks, pll_sys, pll_usb): (pac::XOSC, pac::CLOCKS, pac::PLL_SYS, pac::PLL_USB),
    vreg: &mut pac::VREG_AND_CHIP_RESET,
    resets: &mut pac::RESETS,
    watchdog: &mut Watchdog,
) -> Option<ClocksManager> {
    let xosc = setup_xosc_blocking(xosc, CRYSTAL_HZ.Hz()).ok()?;
    watchdog.enable_tick_generation((CRYSTAL_HZ / 1_000_000) as u8);
    let mut clocks = ClocksManager::new(clocks);
    // These leave clk_sys on clk_ref, clk_ref on the ring oscillator.
    let pll_sys =
        setup_pll_blocking(pll_sys, xosc.operating_frequency(), SYSTEM_CLOCK.pll(), &mut clocks, resets).ok()?;
    let pll_usb = setup_pll_blocking(pll_usb, xosc.operating_frequency(), PLL_USB_48MHZ, &mut clocks, resets).ok()?;
    if hal::vreg::get_voltage(vreg).is_none_or(|now| u8::from(now) < u8::from(SYSTEM_CLOCK.core_voltage)) {
        // On the crystal, so that the wait is timed: 12,000 cycles of clk_sys are then 1 ms.
        clocks.reference_clock.configure_clock(&xosc, xosc.get_freq()).ok()?;
        hal::vreg::set_voltage(vreg, SYSTEM_CLOCK.core_voltage);
        cortex_m::asm::delay(VOLTAGE_SETTLE_CYCLES_AT_CRYSTAL);
    }
    clocks.init_default(&xosc, &pll_sys, &pll_usb).ok()?;
    (clocks.system_clock.freq().to_Hz() == SYSTEM_CLOCK.hz).then_some(clocks)
}
