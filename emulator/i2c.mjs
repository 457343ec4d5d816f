// The RP2040's I2C controllers (datasheet 4.3, Synopsys DW_apb_i2c) in
// controller mode: rp2040js 1.4.1's RPI2C (its registers, its 16-entry
// FIFOs, the START, RESTART and STOP sequencing of IC_DATA_CMD's flags, the
// aborts and their sources, the interrupts) with what it lacks:
//
// - The bus's time. rp2040js completes every START, byte and STOP at once;
//   here each takes the clocks the datasheet gives (4.3.14): SCL is high
//   for HCNT + SPKLEN + 7 and low for LCNT + 1 cycles of clk_sys (the
//   standard-speed counts in standard mode, the fast ones otherwise), a
//   byte and its acknowledge are 9 such bits, a START holds SDA low for
//   HCNT (tHD;STA), a RESTART first waits its set-up time (tSU;STA: the
//   fast HCNT, or the standard LCNT), a STOP takes one SCL low and its
//   set-up HCNT (tSU;STO), and the next START waits the bus-free time LCNT
//   (tBUF) after it. SCL's rise and fall times, which the pull-ups set on a
//   real bus, are left out (ideal edges), as is a device stretching SCL.
// - The pins: a transfer reaches the bus only when both of the wiring's
//   pins have the I2C function selected (GPIO function 3); otherwise no
//   device answers and the address is not acknowledged.
// - Registers rp2040js gets wrong: IC_SDA_HOLD (rp2040js warns on any
//   value but its reset value; here it holds its 24 bits), IC_FS_SPKLEN
//   (rp2040js tests the written value's bit 0 for the enable bit, so an odd
//   spike length was dropped; its minimum is 1), IC_CON.SPEED (a value
//   outside 1..2 becomes 2, the RP2040's IC_MAX_SPEED_MODE, where rp2040js
//   made 0 high speed), the SCL counts' minimums (HCNT 6, LCNT 8: a smaller
//   value written becomes the minimum), and IC_DATA_CMD's FIRST_DATA_BYTE,
//   bit 11 on a read (rp2040js sets bit 10).
// - The rule that IC_CON, the four SCL counts, IC_FS_SPKLEN and IC_SDA_HOLD
//   take writes only while the controller is disabled (IC_ENABLE.ENABLE
//   clear): the chip ignores such a write, so here it is an error naming the
//   register, since a firmware relying on it does not do on a Pico what it
//   meant to.
// - A change of direction (a read after a write, or the reverse) within a
//   transfer: with IC_CON.IC_RESTART_EN set the controller issues a RESTART
//   before it (4.3.7); rp2040js went on without one.
// - The datasheet's limits on the counts (4.3.14.1): a transfer started
//   with LCNT ≤ SPKLEN + 7 or HCNT ≤ SPKLEN + 5 is an error.
//
// Invariants: at most one bus phase (START, byte, STOP) is under way per
// controller, and it ends at its alarm; every byte a device takes, it takes
// at the end of its ninth clock, where it acknowledges it (or not); a device
// error is thrown as a RunError at that time.

import { RPI2C } from 'rp2040js';
import { RunError } from './errors.mjs';

const IC_CON = 0x00;
const IC_DATA_CMD = 0x10;
const IC_SS_SCL_HCNT = 0x14;
const IC_SS_SCL_LCNT = 0x18;
const IC_FS_SCL_HCNT = 0x1c;
const IC_FS_SCL_LCNT = 0x20;
const IC_SDA_HOLD = 0x7c;
const IC_FS_SPKLEN = 0xa0;

/** Registers that take writes only while the controller is disabled, by offset. */
const WRITTEN_ONLY_DISABLED = new Map([
  [IC_CON, 'IC_CON'],
  [IC_SS_SCL_HCNT, 'IC_SS_SCL_HCNT'],
  [IC_SS_SCL_LCNT, 'IC_SS_SCL_LCNT'],
  [IC_FS_SCL_HCNT, 'IC_FS_SCL_HCNT'],
  [IC_FS_SCL_LCNT, 'IC_FS_SCL_LCNT'],
  [IC_SDA_HOLD, 'IC_SDA_HOLD'],
  [IC_FS_SPKLEN, 'IC_FS_SPKLEN'],
]);

const ENABLE = 1 << 0;
const IC_RESTART_EN = 1 << 5;
const SPEED_SHIFT = 1;
const SPEED_MASK = 0x3;
const SPEED_STANDARD = 1;
const SPEED_FAST = 2;
/** IC_DATA_CMD: a read command (CMD), RESTART before it, and on a read the first byte's flag. */
const CMD = 1 << 8;
const RESTART = 1 << 10;
const RSVD_FIRST_DATA_BYTE_RP2040JS = 1 << 10;
const FIRST_DATA_BYTE = 1 << 11;
/** rp2040js's `state` while connected to a device. */
const STATE_CONNECTED = 3;

const MIN_HCNT = 6;
const MIN_LCNT = 8;
const MIN_SPKLEN = 1;
const SDA_HOLD_RESET = 0x0001;
/** Clocks of a byte on the bus: 8 bits and the acknowledge. */
const BITS_A_BYTE = 9;
/** The RP2040's GPIO function number for I2C. */
export const GPIO_FUNCTION_I2C = 3;

/** Which controller (0 or 1) GPIO `pin` carries, and whether as SDA (even pins) or SCL (odd). */
export function i2cPinRole(pin) {
  return { controller: (pin >> 1) & 1, line: pin % 2 === 0 ? 'SDA' : 'SCL' };
}

export class I2cController extends RPI2C {
  /**
   * rp2040js's controller `index` (0 or 1) at the chip's `irq`, timed in
   * cycles of clk_sys, whose length `systemClock.nanosPerCycle` gives
   * (clocks.mjs: it follows the clock the firmware sets).
   */
  constructor(rp2040, index, irq, { systemClock }) {
    super(rp2040, `I2C${index}`, irq);
    this.index = index;
    this.systemClock = systemClock;
    this.sdaHold = SDA_HOLD_RESET;
    this.spikelen = 0x07;
    /** The devices on this controller's bus, by 7-bit address, and the pins the bus is wired to. */
    this.devices = new Map();
    this.wiring = null;
    /** The device addressed in the current transfer (null: none answered), and its direction. */
    this.device = null;
    this.reading = false;
    /** When the bus is free again after the last STOP (tBUF), in the clock's nanoseconds. */
    this.busFreeAt = 0;
    this.alarm = rp2040.clock.createAlarm(() => this.phaseEnded());
    this.afterPhase = null;
    /** Called when a transfer starts and stops: (event, address), for the runner's phase times. */
    this.onBusEvent = () => {};

    this.onStart = (repeated) => this.startCondition(repeated);
    this.onConnect = (address, mode) => this.addressDevice(address, mode);
    this.onWriteByte = (byte) => this.byteOut(byte);
    this.onReadByte = () => this.byteIn();
    this.onStop = () => this.stopCondition();
  }

  /**
   * Puts `device` on the bus wired to GPIO `sda` and `scl` (which must be
   * this controller's pins): it answers at `device.address`.
   */
  attach(device, { sda, scl }) {
    for (const [pin, line] of [
      [sda, 'SDA'],
      [scl, 'SCL'],
    ]) {
      const role = i2cPinRole(pin);
      if (role.controller !== this.index || role.line !== line) {
        throw new RunError(`GPIO ${pin} is not I2C${this.index}'s ${line}: it can carry I2C${role.controller}'s ${role.line}`);
      }
    }
    this.wiring = { sda, scl };
    this.devices.set(device.address, device);
  }

  /** Both of the bus's pins have the I2C function: the controller drives the wires. */
  get routed() {
    if (!this.wiring) return false;
    const gpio = this.rp2040.gpio;
    return gpio[this.wiring.sda].functionSelect === GPIO_FUNCTION_I2C && gpio[this.wiring.scl].functionSelect === GPIO_FUNCTION_I2C;
  }

  // --- registers -------------------------------------------------------

  readUint32(offset) {
    switch (offset) {
      case IC_SDA_HOLD:
        return this.sdaHold;
      case IC_FS_SPKLEN:
        return this.spikelen;
      case IC_DATA_CMD: {
        const value = super.readUint32(offset);
        return value & RSVD_FIRST_DATA_BYTE_RP2040JS ? (value & ~RSVD_FIRST_DATA_BYTE_RP2040JS) | FIRST_DATA_BYTE : value;
      }
      default:
        return super.readUint32(offset);
    }
  }

  writeUint32(offset, value) {
    const name = WRITTEN_ONLY_DISABLED.get(offset);
    if (name && this.enable & ENABLE) {
      throw new RunError(
        `${this.name}: ${name} written (0x${value.toString(16)}) while the controller is enabled: the RP2040 ignores ` +
          `such a write (datasheet 4.3.17, ${name}); disable it first (IC_ENABLE)`,
      );
    }
    switch (offset) {
      case IC_CON: {
        const speed = (value >> SPEED_SHIFT) & SPEED_MASK;
        if (speed !== SPEED_STANDARD && speed !== SPEED_FAST) {
          value = (value & ~(SPEED_MASK << SPEED_SHIFT)) | (SPEED_FAST << SPEED_SHIFT);
        }
        this.control = value;
        return;
      }
      case IC_SS_SCL_HCNT:
        this.ssClockHighPeriod = Math.max(MIN_HCNT, value & 0xffff);
        return;
      case IC_SS_SCL_LCNT:
        this.ssClockLowPeriod = Math.max(MIN_LCNT, value & 0xffff);
        return;
      case IC_FS_SCL_HCNT:
        this.fsClockHighPeriod = Math.max(MIN_HCNT, value & 0xffff);
        return;
      case IC_FS_SCL_LCNT:
        this.fsClockLowPeriod = Math.max(MIN_LCNT, value & 0xffff);
        return;
      case IC_SDA_HOLD:
        this.sdaHold = value & 0xffffff;
        return;
      case IC_FS_SPKLEN:
        this.spikelen = Math.max(MIN_SPKLEN, value & 0xff);
        return;
      default:
        super.writeUint32(offset, value);
    }
  }

  /** A command of the other direction than the transfer's gets a RESTART first when IC_RESTART_EN is set. */
  nextCommand() {
    const fifo = this.txFIFO;
    if (this.state === STATE_CONNECTED && !fifo.empty && !this.busy) {
      const read = (fifo.peek() & CMD) !== 0;
      if (read !== this.reading) {
        if (!(this.control & IC_RESTART_EN)) {
          throw new RunError(`${this.name}: a change of direction with IC_CON.IC_RESTART_EN clear (a STOP and a START) is not modelled`);
        }
        fifo.buffer[fifo.start] |= RESTART;
      }
    }
    super.nextCommand();
  }

  // --- the bus's time ----------------------------------------------------

  /** SCL's counts in clk_sys cycles for the speed IC_CON selects. */
  get counts() {
    const standard = this.speed === SPEED_STANDARD;
    const high = standard ? this.ssClockHighPeriod : this.fsClockHighPeriod;
    const low = standard ? this.ssClockLowPeriod : this.fsClockLowPeriod;
    return { standard, high, low, spike: this.spikelen };
  }

  /** A cycle of clk_sys (the controller's ic_clk) in nanoseconds, now. */
  get nanosPerCycle() {
    return this.systemClock.nanosPerCycle;
  }

  /** One SCL period in cycles: high HCNT + SPKLEN + 7, low LCNT + 1. */
  get bitCycles() {
    const { high, low, spike } = this.counts;
    return high + spike + 7 + low + 1;
  }

  /** The SCL frequency the counts make at `clockHz`. */
  sclHz(clockHz) {
    return clockHz / this.bitCycles;
  }

  /** Runs `then` once `cycles` of clk_sys have passed. */
  after(cycles, then) {
    this.afterPhase = then;
    this.alarm.schedule(cycles * this.nanosPerCycle);
  }

  phaseEnded() {
    const then = this.afterPhase;
    this.afterPhase = null;
    then();
  }

  startCondition(repeated) {
    const { standard, high, low, spike } = this.counts;
    if (low <= spike + 7 || high <= spike + 5) {
      throw new RunError(
        `${this.name}: SCL counts HCNT ${high}, LCNT ${low} with SPKLEN ${spike}: the datasheet (4.3.14.1) requires ` +
          `LCNT > SPKLEN + 7 and HCNT > SPKLEN + 5`,
      );
    }
    let cycles = high; // tHD;STA
    if (repeated) {
      cycles += standard ? low : high; // tSU;STA
    } else {
      const now = this.rp2040.clock.nanos;
      if (this.busFreeAt > now) cycles += Math.ceil((this.busFreeAt - now) / this.nanosPerCycle);
    }
    this.device = null;
    this.after(cycles, () => this.completeStart());
  }

  addressDevice(address, mode) {
    const read = mode === 1;
    this.after(BITS_A_BYTE * this.bitCycles, () => {
      const device = this.routed ? this.devices.get(address) : undefined;
      this.device = device ?? null;
      this.reading = read;
      if (device) {
        this.onBusEvent('start', address);
        const sclHz = this.sclHz(1e9 / this.nanosPerCycle);
        this.deviceCall(() => device.start({ read, sclHz }));
      }
      this.completeConnect(Boolean(device));
    });
  }

  byteOut(byte) {
    this.after(BITS_A_BYTE * this.bitCycles, () => {
      const acknowledged = this.device ? this.deviceCall(() => this.device.write(byte)) : false;
      this.completeWrite(acknowledged);
    });
  }

  byteIn() {
    this.after(BITS_A_BYTE * this.bitCycles, () => {
      const device = this.device;
      if (!device?.read) {
        throw new RunError(`${this.name}: a read from the device at 0x${this.targetAddress.toString(16)}, which does not answer reads`);
      }
      this.completeRead(this.deviceCall(() => device.read()) & 0xff);
    });
  }

  stopCondition() {
    const { high, low } = this.counts;
    // SCL low, then up; SDA rises tSU;STO later.
    this.after(low + 1 + high, () => {
      this.busFreeAt = this.rp2040.clock.nanos + low * this.nanosPerCycle; // tBUF
      if (this.device) {
        this.deviceCall(() => this.device.stop());
        this.onBusEvent('stop', this.device.address);
      }
      this.device = null;
      this.completeStop();
    });
  }

  /** A device's error ends the run with its message. */
  deviceCall(call) {
    try {
      return call();
    } catch (error) {
      if (error instanceof RunError) throw error;
      throw new RunError(error.message);
    }
  }
}
