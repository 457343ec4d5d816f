// The RP2040's on-chip voltage regulator and chip-level reset block
// (VREG_AND_CHIP_RESET, 0x40064000; datasheet 2.9 and 2.12), which rp2040js
// leaves out: VREG (EN, HIZ, VSEL, and ROK, set while the regulator
// regulates), BOD (the brown-out detector's enable and threshold) and
// CHIP_RESET (why the chip last reset: a power-on, here). The core voltage
// is what lets clk_sys run faster (clocks.mjs checks the two together).
//
// Invariants: VSEL 0 to 5 all give 0.80 V and each step above adds 0.05 V,
// up to 1.30 V (VSEL 15); a write to a field the block does not have, or
// switching the regulator off or into high impedance (the Pico's core would
// lose its supply), ends the run with an error naming it, never a guess.

import { BasePeripheral } from 'rp2040js';
import { RunError } from './errors.mjs';

const VREG = 0x00;
const BOD = 0x04;
const CHIP_RESET = 0x08;

const VREG_EN = 1 << 0;
const VREG_HIZ = 1 << 1;
const VREG_VSEL_SHIFT = 4;
const VREG_VSEL_MASK = 0xf;
const VREG_ROK = 1 << 12;
const VREG_WRITABLE = 0xf3;
const BOD_WRITABLE = 0xf1;
/** CHIP_RESET after a power-on: HAD_POR. */
const HAD_POR = 1 << 8;
const PSM_RESTART_FLAG = 1 << 24;

/** The voltage VSEL selects (datasheet 2.9.5, VREG). */
export function vselVolts(vsel) {
  return vsel <= 5 ? 0.8 : 0.8 + 0.05 * (vsel - 5);
}

export class Vreg extends BasePeripheral {
  /** `onVoltage(volts)`: called after each change of the core voltage. */
  constructor(rp2040, { onVoltage = () => {} } = {}) {
    super(rp2040, 'VREG_AND_CHIP_RESET');
    this.onVoltage = onVoltage;
    this.vreg = 0xb1; // enabled, VSEL 1011: 1.10 V
    this.bod = 0x91; // enabled, 0.86 V
    this.chipReset = HAD_POR;
  }

  /** The core voltage the regulator holds, in volts (to the hundredth). */
  get volts() {
    return Math.round(100 * vselVolts((this.vreg >>> VREG_VSEL_SHIFT) & VREG_VSEL_MASK)) / 100;
  }

  readUint32(offset) {
    switch (offset) {
      case VREG:
        return this.vreg | VREG_ROK;
      case BOD:
        return this.bod;
      case CHIP_RESET:
        return this.chipReset;
    }
    return super.readUint32(offset);
  }

  writeUint32(offset, value) {
    value >>>= 0;
    switch (offset) {
      case VREG: {
        if (value & ~(VREG_WRITABLE | VREG_ROK)) this.fail(`VREG 0x${value.toString(16)}: bits the register does not have`);
        if (!(value & VREG_EN) || value & VREG_HIZ) {
          this.fail(`VREG 0x${value.toString(16)}: the regulator off or in high impedance leaves the Pico's core without its supply`);
        }
        const before = this.volts;
        this.vreg = value & VREG_WRITABLE;
        if (this.volts !== before) this.onVoltage(this.volts);
        return;
      }
      case BOD:
        if (value & ~BOD_WRITABLE) this.fail(`BOD 0x${value.toString(16)}: bits the register does not have`);
        this.bod = value;
        return;
      case CHIP_RESET:
        // PSM_RESTART_FLAG is cleared by writing 1; the rest is read-only.
        this.chipReset &= ~(value & PSM_RESTART_FLAG);
        return;
    }
    super.writeUint32(offset, value);
  }

  fail(message) {
    throw new RunError(`${this.name}: ${message}`);
  }
}
