// The system clock the firmware set, and the machine's time in it. The
// cores count cycles of clk_sys; the peripherals (the TIMER's microseconds,
// the SPI's and I2C's bits, USB's packets, the watchdog) run on the
// machine's clock in nanoseconds. clk_sys comes from the registers the
// firmware writes (CLOCKS' CLK_REF and CLK_SYS, PLL_SYS, the XOSC's 12 MHz,
// as rp2040js decodes them): from reset the ring oscillator (6.5 MHz, its
// nominal; a real chip's lies between 1.8 and 12 MHz, datasheet 2.16), and
// after a template's set-up the PLL's 200 MHz (or 125 MHz). Each change
// opens an epoch: from its cycle on, a cycle lasts 1e9 / hz nanoseconds, so
// the time of any cycle, and the cycle of any time, is exact for the whole
// run (`nanosAt`, `cyclesAt`).
//
// The rating (the RP2040 datasheet's current revision, and the Pico SDK's
// PICO_USE_FASTEST_SUPPORTED_CLOCK): clk_sys up to 133 MHz at the
// regulator's reset voltage, 1.10 V, and up to 200 MHz from 1.15 V. A clock
// faster than the voltage allows, at any moment, ends the run with an
// error, as does lowering the voltage under the clock: a real chip may run
// there, or may not, and the emulator cannot tell which.
//
// Invariants: epochs start at whole nanoseconds when a cycle is a whole
// number of them (125 MHz: 8 ns, 200 MHz: 5 ns), so that from the PLL's
// clock on every time and cycle is an integer and the arithmetic exact; a
// new epoch starts at the changing core's cycle, never before the machine's
// clock (the core behind runs first).

import { RunError } from './errors.mjs';

/** The RP2040's rating: the fastest clk_sys for a core voltage. */
export const RATINGS = [
  { volts: 1.1, hz: 133_000_000 },
  { volts: 1.15, hz: 200_000_000 },
];

/** The fastest clk_sys the rating allows at `volts` (0 below the lowest rated voltage). */
export function ratedHz(volts) {
  return RATINGS.filter((rating) => volts >= rating.volts).reduce((fastest, rating) => Math.max(fastest, rating.hz), 0);
}

const mhz = (hz) => `${+(hz / 1e6).toFixed(3)} MHz`;

export class SystemClock {
  /**
   * Follows `rp2040`'s clk_sys from its registers. `now()`: the cycle of the
   * core executing (where a change takes effect); `volts()`: the core
   * voltage; `onChange(hz)`: called after each change.
   */
  constructor(rp2040, { now, volts, onChange = () => {} }) {
    Object.assign(this, { rp2040, now, volts, onChange });
    // rp2040js starts at 125 MHz until the firmware writes a clock register; the reset state is the ROSC's.
    rp2040.updateClocks();
    this.hz = rp2040.clkSys;
    this.nanosPerCycle = 1e9 / this.hz;
    /** The epochs: from `cycles` on, a cycle lasts `nanosPerCycle`; `nanos` is when it starts. */
    this.epochs = [{ cycles: 0, nanos: 0, hz: this.hz, nanosPerCycle: this.nanosPerCycle }];
    rp2040.addClockListener((hz) => this.change(hz));
  }

  /** The current epoch: the last. */
  get epoch() {
    return this.epochs[this.epochs.length - 1];
  }

  change(hz) {
    this.check(hz, this.volts());
    const cycles = this.now();
    let nanos = this.nanosAt(cycles);
    const nanosPerCycle = 1e9 / hz;
    if (Number.isInteger(nanosPerCycle)) nanos = Math.ceil(nanos);
    const epoch = { cycles, nanos, hz, nanosPerCycle };
    if (this.epoch.cycles === cycles) this.epochs[this.epochs.length - 1] = epoch;
    else this.epochs.push(epoch);
    this.hz = hz;
    this.nanosPerCycle = nanosPerCycle;
    this.onChange(hz);
  }

  /** The regulator changed the core voltage: the clock must stay within its rating. */
  voltageChanged(volts) {
    this.check(this.hz, volts);
  }

  check(hz, volts) {
    if (hz > ratedHz(volts)) {
      const rated = RATINGS.map((r) => `${mhz(r.hz)} from ${r.volts.toFixed(2)} V`).join(', ');
      throw new RunError(
        `clk_sys at ${mhz(hz)} with the core at ${volts.toFixed(2)} V: outside the RP2040's rating (${rated}); ` +
          'raise VREG before the clock, lower the clock before VREG',
      );
    }
  }

  /** The epoch `cycles` is in. */
  epochOfCycle(cycles) {
    let k = this.epochs.length - 1;
    while (k > 0 && this.epochs[k].cycles > cycles) k--;
    return this.epochs[k];
  }

  /** When cycle `cycles` starts, in the machine clock's nanoseconds. */
  nanosAt(cycles) {
    const epoch = this.epochOfCycle(cycles);
    return epoch.nanos + (cycles - epoch.cycles) * epoch.nanosPerCycle;
  }

  /** The cycle (fractional between two) at the machine clock's `nanos`. */
  cyclesAt(nanos) {
    let k = this.epochs.length - 1;
    while (k > 0 && this.epochs[k].nanos > nanos) k--;
    const epoch = this.epochs[k];
    return epoch.cycles + ((nanos - epoch.nanos) * epoch.hz) / 1e9;
  }

  /** The first whole cycle at or after `nanos` (a fraction of a picosecond's rounding forgiven). */
  cycleAtOrAfter(nanos) {
    return Math.ceil(this.cyclesAt(nanos) - 1e-6);
  }

  /** The seconds between cycles `from` and `to`. */
  secondsBetween(from, to) {
    return (this.nanosAt(to) - this.nanosAt(from)) / 1e9;
  }

  /** What the JSON report says of the clock: clk_sys now (the one the firmware set), and every change. */
  report() {
    return {
      sysHz: this.hz,
      changes: this.epochs.map(({ cycles, hz }) => ({ cycles, hz })),
    };
  }
}
