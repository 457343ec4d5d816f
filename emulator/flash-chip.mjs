// The Pico's flash chip, a Winbond W25Q16JV (2 MiB, QSPI), as the SSI talks
// to it: its status registers and the commands a boot ROM and a boot2 send
// (its datasheet's command table), and the state that decides how the next
// read must be framed (continuous read mode).
//
// Standard SPI commands, one a chip-select period (`select`, a byte at a
// time through `exchange`, `deselect`):
//   05h, 35h, 15h  read status register 1, 2, 3 (every byte after the opcode)
//   06h, 04h       write enable, write disable (WEL, status register 1 bit 1)
//   01h            write status registers 1 and 2 (one or two bytes), 31h
//                  write status register 2: with WEL set, the chip is busy
//                  (status register 1 bit 0) for tW (10 ms, the datasheet's
//                  typical), then holds the new values and clears WEL
//   9Fh            JEDEC ID: EF 40 15
//   03h            read data (24-bit address, then the bytes)
// Reads framed by the SSI's enhanced (XIP) format (`read`):
//   03h            1 lane, 24-bit address, no wait
//   0Bh            1 lane, 24-bit address, 8 wait clocks
//   EBh            fast read quad I/O: instruction on 1 lane, 24-bit address
//                  and 8 mode bits on 4, 4 wait clocks; needs QE (status
//                  register 2 bit 1). Mode bits M5-4 = 10 put the chip in
//                  continuous read mode: the next read has no instruction
//                  (address and mode first), until mode bits other than
//                  M5-4 = 10 end it.
//
// Its serial clock (what the SSI makes of clk_sys, `serialClockHz`, set by
// the SSI before each transfer) is checked against its rating, the
// datasheet's AC electrical characteristics: fR, 50 MHz, for Read Data
// (03h); FR, 133 MHz, for every other instruction (the quad reads XIP makes
// included).
//
// Invariants: a command the model does not know, a read framed other than
// the chip takes it in its present mode, a command while it is busy, quad
// I/O without QE, or a serial clock faster than the instruction's rating is
// an error naming it, never a guess: on a real board each of these reads
// garbage. The memory is the emulator's flash array itself.

import { RunError } from './errors.mjs';

const BUSY = 1 << 0;
const WEL = 1 << 1;
const QE = 1 << 1;
/** tW, the write-status-register time: 10 ms typical. */
const STATUS_WRITE_SECONDS = 0.01;
const JEDEC_ID = [0xef, 0x40, 0x15];
const TRANS_1C1A = 0;
const TRANS_1C2A = 1;
/** The fastest serial clock: fR for Read Data (03h), FR for the rest. */
const READ_DATA_MAX_HZ = 50_000_000;
const MAX_HZ = 133_000_000;

const hex = (byte) => `${byte.toString(16).padStart(2, '0')}h`;

export class W25Q16JV {
  /**
   * `memory`: the flash's bytes. `nowSeconds()`: the machine's time.
   * `statusRegister2`: its power-on value; the Pico's W25Q16JVUXIQ ships
   * with QE set (0x02).
   */
  constructor(memory, nowSeconds, { statusRegister2 = QE } = {}) {
    Object.assign(this, { memory, nowSeconds });
    this.status = [0, statusRegister2, 0x60];
    this.pendingStatus = null;
    this.busyUntil = 0;
    this.continuous = false;
    this.command = null;
    /** The serial clock of the transfer under way (the SSI sets it). */
    this.serialClockHz = 0;
  }

  /** Instruction `opcode` at the serial clock the SSI runs: within the chip's rating, or an error. */
  checkClock(opcode) {
    const max = opcode === 0x03 ? READ_DATA_MAX_HZ : MAX_HZ;
    if (this.serialClockHz > max) {
      const mhz = (hz) => `${+(hz / 1e6).toFixed(3)} MHz`;
      this.fail(`${hex(opcode)} at a ${mhz(this.serialClockHz)} serial clock: the chip is rated for ${mhz(max)}`);
    }
  }

  fail(message) {
    throw new RunError(`flash chip (W25Q16JV): ${message}`);
  }

  /** Status register n (1-based), with BUSY as of now. */
  statusRegister(n) {
    this.settle();
    return n === 1 ? this.status[0] | (this.busyUntil > this.nowSeconds() ? BUSY : 0) : this.status[n - 1];
  }

  /** A status write that has taken its tW is in effect. */
  settle() {
    if (this.pendingStatus && this.nowSeconds() >= this.busyUntil) {
      this.status[0] = this.pendingStatus[0] & ~(BUSY | WEL); // both read-only
      this.status[1] = this.pendingStatus[1];
      this.pendingStatus = null;
    }
  }

  get busy() {
    this.settle();
    return this.pendingStatus !== null;
  }

  /** Chip select goes low: a new command starts. */
  select() {
    if (this.continuous) {
      this.fail('a standard SPI command while in continuous read mode (the chip takes its first bits as an address)');
    }
    this.command = { opcode: null, bytes: [] };
  }

  /** One byte each way while selected. */
  exchange(out) {
    const command = this.command;
    if (command.opcode === null) {
      if (this.busy && out !== 0x05 && out !== 0x35 && out !== 0x15) {
        this.fail(`command ${hex(out)} while a status write is in progress (only status reads are taken)`);
      }
      this.checkClock(out);
      command.opcode = out;
      return 0xff;
    }
    command.bytes.push(out);
    const n = command.bytes.length;
    switch (command.opcode) {
      case 0x05:
        return this.statusRegister(1);
      case 0x35:
        return this.statusRegister(2);
      case 0x15:
        return this.statusRegister(3);
      case 0x9f:
        return JEDEC_ID[(n - 1) % 3];
      case 0x03:
        if (n <= 3) return 0xff;
        return this.memory[(((command.bytes[0] << 16) | (command.bytes[1] << 8) | command.bytes[2]) + n - 4) % this.memory.length];
      case 0x01:
      case 0x31:
        return 0xff;
    }
    this.fail(`command ${hex(command.opcode)} is not modelled`);
  }

  /** Chip select goes high: a write command takes effect. */
  deselect() {
    const { opcode, bytes } = this.command;
    this.command = null;
    switch (opcode) {
      case 0x06:
        this.status[0] |= WEL;
        return;
      case 0x04:
        this.status[0] &= ~WEL;
        return;
      case 0x01:
      case 0x31: {
        const values = opcode === 0x01 ? bytes : [this.status[0], ...bytes];
        if (values.length === 0 || values.length > 2) {
          this.fail(`status write ${hex(opcode)} with ${bytes.length} data bytes`);
        }
        if (!(this.status[0] & WEL)) {
          return; // the chip ignores a write without write enable
        }
        this.pendingStatus = [values[0], values.length > 1 ? values[1] : this.status[1]];
        this.busyUntil = this.nowSeconds() + STATUS_WRITE_SECONDS;
        return;
      }
      case null:
      case 0x05:
      case 0x35:
      case 0x15:
      case 0x9f:
      case 0x03:
        return;
    }
    this.fail(`command ${hex(opcode)} is not modelled`);
  }

  /**
   * A read framed by the SSI's enhanced format: `instruction` (null: none
   * sent), the transfer type, data lanes, address-and-mode bits, wait clocks
   * and the mode bits sent. Checks the chip takes it so, and enters or
   * leaves continuous read mode.
   */
  read({ instruction, transType, lanes, addressBits, waitClocks, mode }) {
    if (this.busy) {
      this.fail('a read while a status write is in progress');
    }
    const framing = `${lanes}-lane data, ${addressBits} address bits, ${waitClocks} wait clocks`;
    // In continuous read mode the chip is still in its EBh.
    this.checkClock(instruction ?? 0xeb);
    if (this.continuous) {
      if (instruction !== null) {
        this.fail(`a read with instruction ${hex(instruction)} in continuous read mode (the chip takes it as address bits)`);
      }
      this.checkQuadIo(transType, lanes, addressBits, waitClocks, framing, 'continuous read');
    } else {
      if (instruction === null) {
        this.fail(`a read with no instruction out of continuous read mode (${framing})`);
      }
      if (transType !== TRANS_1C1A && transType !== TRANS_1C2A) {
        this.fail(`instruction ${hex(instruction)} sent over ${lanes} lanes: the chip takes instructions on one`);
      }
      switch (instruction) {
        case 0x03:
        case 0x0b:
          if (transType !== TRANS_1C1A || lanes !== 1 || addressBits !== 24 || waitClocks !== (instruction === 0x0b ? 8 : 0)) {
            const wait = instruction === 0x0b ? 8 : 0;
            this.fail(`${hex(instruction)} takes 1-lane data, a 24-bit address and ${wait} wait clocks; the SSI sent ${framing}`);
          }
          return;
        case 0xeb:
          this.checkQuadIo(transType, lanes, addressBits, waitClocks, framing, 'EBh');
          break;
        default:
          this.fail(`read instruction ${hex(instruction)} is not modelled`);
      }
    }
    this.continuous = (mode & 0x30) === 0x20;
  }

  checkQuadIo(transType, lanes, addressBits, waitClocks, framing, what) {
    if (!(this.status[1] & QE)) {
      this.fail(`${what}: quad I/O with QE clear (status register 2 is 0x${this.status[1].toString(16)})`);
    }
    if (transType === TRANS_1C1A || lanes !== 4 || addressBits !== 32 || waitClocks !== 4) {
      this.fail(`${what} takes the address and mode on 4 lanes (32 bits) and 4 wait clocks; the SSI sent ${framing}`);
    }
  }
}
