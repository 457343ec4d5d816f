// The ST7789 panel wired to a Pico as examples/pico-st7789 wires it (the
// Waveshare Pico-LCD-1.3): SPI1's clock on GP10 and data on GP11, chip
// select GP9, data/command GP8, reset GP12, backlight GP13; each byte takes
// its 8 clocks of the bus, at the rate SPI1's prescaler and serial clock
// rate make of clk_peri; and the run's phases told from the panel.
//
// Invariants: the panel sees exactly the bytes SPI1 sends while its chip
// select is low and the two bus pins have the SPI function; a byte's time
// is a whole number of clk_peri cycles, so that at a clk_peri of whole
// nanoseconds a cycle (clk_sys, 125 or 200 MHz) it is exact; a phase is
// null until the run has got there.

import { GPIOPinState } from 'rp2040js';
import { ST7789 } from './st7789.mjs';
import { RunError } from './errors.mjs';

/** The Pico-LCD-1.3's wiring: SPI1 on GP10 (clock) and GP11 (data); the panel's control lines. */
export const WIRING = { clock: 10, data: 11, chipSelect: 9, dataCommand: 8, reset: 12, backlight: 13 };
const GPIO_FUNCTION_SPI = 1;
/** SSPCR0's serial clock rate (SCR) and SSPCPSR's divisor (PL022: clk_peri / (CPSDVSR × (1 + SCR))). */
const SCR_SHIFT = 8;
const SCR_MASK = 0xff;

/**
 * Connects an ST7789 (`options`: its size and place) to `rp2040`'s SPI1 and
 * the control pins; `now()` is the machine's time in cycles. Returns the
 * panel, the times the run's phases are told by (when the backlight came
 * on: the template turns it on once the panel is cleared, before it loads
 * the scene; the first command after that, the picture's first row; the
 * last pixel; when the whole panel had been written; how many rows, RAMWRs,
 * it has taken) and the phases.
 */
export function wireLcd(rp2040, now, options) {
  const panel = new ST7789(options);
  const gpio = rp2040.gpio;
  const spi = rp2040.spi[1];
  const events = { backlightOn: null, pictureStart: null, lastPixel: null, fullPanel: null, memoryWrites: 0 };
  let chipSelected = false;
  const level = (pin) => gpio[pin].value === GPIOPinState.High;

  // Chip select frames bytes; the controller keeps its command across frames.
  gpio[WIRING.chipSelect].addListener((state) => {
    chipSelected = state === GPIOPinState.Low;
  });
  gpio[WIRING.reset].addListener((state) => {
    if (state === GPIOPinState.Low) {
      panel.reset();
    }
  });
  gpio[WIRING.backlight].addListener((state) => {
    if (state === GPIOPinState.High && events.backlightOn === null) {
      events.backlightOn = now();
    }
  });

  // A byte takes 8 clocks of the bus; the next starts when it is out.
  const done = rp2040.clock.createAlarm(() => spi.completeTransmit(0));
  spi.onTransmit = (byte) => {
    const routed = [WIRING.clock, WIRING.data].every((pin) => gpio[pin].functionSelect === GPIO_FUNCTION_SPI);
    if (routed && chipSelected) {
      const dataCommand = level(WIRING.dataCommand);
      receive(panel, byte, dataCommand);
      if (!dataCommand && events.backlightOn !== null && events.pictureStart === null) {
        events.pictureStart = now();
        panel.startCoverage();
      }
      if (panel.command?.name === 'RAMWR') {
        if (dataCommand) {
          events.lastPixel = now();
          if (events.fullPanel === null && events.pictureStart !== null && panel.fullyCovered) events.fullPanel = now();
        } else {
          events.memoryWrites++;
        }
      }
    }
    done.schedule(byteNanos(rp2040, spi));
  };
  return { panel, events, phases: () => phases(events) };
}

/** A frame's time on SPI1: its bits, each CPSDVSR × (1 + SCR) cycles of clk_peri. */
function byteNanos(rp2040, spi) {
  if (!spi.clockDivisor) {
    throw new RunError('SPI1 transmits with no clock (SSPCPSR is 0)');
  }
  const perBit = spi.clockDivisor * (1 + ((spi.control0 >> SCR_SHIFT) & SCR_MASK));
  return (spi.dataBits * perBit * 1e9) / rp2040.clkPeri;
}

function receive(panel, byte, dataCommand) {
  try {
    panel.receive(byte, dataCommand);
  } catch (error) {
    throw new RunError(error.message);
  }
}

/**
 * The run's phases in cycles: start-up (clocks, the panel's set-up and
 * clear, up to the backlight), parse and index (up to the picture's first
 * command), render (to its last pixel), first full panel (from the
 * picture's first command until every pixel of the panel has been written
 * once: the render's length for a top-to-bottom render).
 */
function phases({ backlightOn, pictureStart, lastPixel, fullPanel }) {
  const picture = backlightOn != null && pictureStart != null && lastPixel > pictureStart;
  return {
    startUp: backlightOn ?? null,
    parseAndIndex: picture ? pictureStart - backlightOn : null,
    render: picture ? lastPixel - pictureStart : null,
    firstFullPanel: picture && fullPanel != null ? fullPanel - pictureStart : null,
  };
}
