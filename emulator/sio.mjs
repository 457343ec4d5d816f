// Each core's view of the RP2040's SIO (single-cycle I/O, datasheet 2.3.1):
// what is per core (CPUID, its ends of the inter-core FIFOs, its hardware
// divider and interpolators) and what both cores share (GPIO, the 32
// spinlocks, which rp2040js's own SIO block keeps).
//
// The inter-core FIFOs (2.3.1.5): one each way, 32 bits wide, 8 deep. A
// core writes its TX FIFO at FIFO_WR and reads its RX FIFO at FIFO_RD;
// FIFO_ST has VLD (RX not empty), RDY (TX not full) and the sticky WOF
// (written when full: the word is dropped) and ROE (read when empty: the
// FIFO is unchanged and the read returns 0, the datasheet's "invalid data").
// WOF and ROE clear when a 1 is written to their bit (the SVD's oneToClear;
// the datasheet's prose says "writing any value"). Each core's SIO IRQ
// (SIO_IRQ_PROC0 = 15 for core 0, SIO_IRQ_PROC1 = 16 for core 1) is the OR of
// its VLD, WOF and ROE, and like every IRQ line it reaches both cores'
// NVICs.
//
// The divider (2.3.1.5) computes in 8 cycles while the core runs on: a
// write of a dividend or divisor starts it and costs the store's one cycle,
// CSR.READY is clear until 8 cycles after that store, and the quotient and
// remainder are valid from then on. rp2040js instead charges the 8 cycles
// to the core on every operand written (16 for a division); here they
// cost nothing, and a read of QUOTIENT or REMAINDER before the result is
// valid (undefined on the chip) ends the run with an error, never a value
// silicon would not give. rp2040-hal's division waits exactly the 8
// cycles, with four branches.
//
// Invariants: core 0's divider and interpolators are rp2040js's own, so a
// one-core firmware's SIO is today's; core 1 has instances of the same
// classes acting on core 1; a spinlock read claims it for whichever core
// reads.

import { RunError } from './errors.mjs';

const CPUID = 0x000;
const FIFO_ST = 0x050;
const FIFO_WR = 0x054;
const FIFO_RD = 0x058;
/** The divider (0x060..0x078) and the two interpolators (0x080..0x0fc) are per core. */
const PER_CORE_FIRST = 0x060;
const PER_CORE_LAST = 0x0fc;
const DIV_SDIVISOR = 0x06c;
const DIV_QUOTIENT = 0x070;
const DIV_REMAINDER = 0x074;
const DIV_CSR = 0x078;
const DIV_CSR_READY = 1 << 0;
/** Cycles from a divider operand's store to a valid result (2.3.1.5). */
export const DIVIDER_CYCLES = 8;

const VLD = 1 << 0;
const RDY = 1 << 1;
const WOF = 1 << 2;
const ROE = 1 << 3;

const FIFO_DEPTH = 8;
/** SIO_IRQ_PROC0 and SIO_IRQ_PROC1: each core's FIFO interrupt line. */
const SIO_IRQ = [15, 16];

/** The two mailboxes: `words[k]` is written by core k and read by the other core. */
export class InterCoreFifos {
  /** `setInterrupt(irq, level)` drives an IRQ line into both cores' NVICs. */
  constructor(setInterrupt) {
    this.setInterrupt = setInterrupt;
    this.words = [new Uint32Array(FIFO_DEPTH), new Uint32Array(FIFO_DEPTH)];
    this.head = [0, 0];
    this.count = [0, 0];
    this.flags = [0, 0]; // each core's sticky WOF and ROE
  }

  /** Core k's FIFO_ST. */
  status(k) {
    const rx = 1 - k;
    return (this.count[rx] > 0 ? VLD : 0) | (this.count[k] < FIFO_DEPTH ? RDY : 0) | this.flags[k];
  }

  /** Core k writes FIFO_WR. */
  write(k, value) {
    if (this.count[k] === FIFO_DEPTH) {
      this.flags[k] |= WOF;
    } else {
      this.words[k][(this.head[k] + this.count[k]) % FIFO_DEPTH] = value;
      this.count[k]++;
    }
    this.updateInterrupts();
  }

  /** Core k reads FIFO_RD. */
  read(k) {
    const rx = 1 - k;
    if (this.count[rx] === 0) {
      this.flags[k] |= ROE;
      this.updateInterrupts();
      return 0;
    }
    const value = this.words[rx][this.head[rx]];
    this.head[rx] = (this.head[rx] + 1) % FIFO_DEPTH;
    this.count[rx]--;
    this.updateInterrupts();
    return value;
  }

  /** Core k writes FIFO_ST: a 1 clears WOF or ROE. */
  clearFlags(k, value) {
    this.flags[k] &= ~(value & (WOF | ROE));
    this.updateInterrupts();
  }

  updateInterrupts() {
    for (let k = 0; k < 2; k++) {
      this.setInterrupt(SIO_IRQ[k], (this.status(k) & (VLD | WOF | ROE)) !== 0);
    }
  }
}

export class CoreSio {
  /**
   * `index`: the core. `shared`: rp2040js's SIO block (GPIO, spinlocks).
   * `own`: the block whose divider and interpolators are this core's
   * (`shared` itself for core 0). `now()`: the core's time in cycles, at
   * the start of the instruction that accesses the SIO.
   */
  constructor(index, fifos, shared, own, now) {
    Object.assign(this, { index, fifos, shared, own, now });
    /** When the divider's result is valid. */
    this.dividerReadyAt = 0;
    // rp2040js's division, with its cycles taken back: silicon charges none.
    const divide = Object.getPrototypeOf(own).updateHardwareDivider;
    own.updateHardwareDivider = function (signed) {
      const core = this.rp2040.core;
      const cycles = core.cycles;
      divide.call(this, signed);
      core.cycles = cycles;
    };
  }

  readUint32(offset) {
    switch (offset) {
      case CPUID:
        return this.index;
      case FIFO_ST:
        return this.fifos.status(this.index);
      case FIFO_WR:
        return 0; // write-only
      case FIFO_RD:
        return this.fifos.read(this.index);
    }
    if (offset >= PER_CORE_FIRST && offset <= PER_CORE_LAST) {
      return offset >= DIV_QUOTIENT && offset <= DIV_CSR ? this.readDivider(offset) : this.own.readUint32(offset);
    }
    return this.shared.readUint32(offset);
  }

  /** QUOTIENT, REMAINDER (valid only once ready) or CSR (READY as the time says). */
  readDivider(offset) {
    const early = this.dividerReadyAt - this.now();
    if (offset === DIV_CSR) {
      const csr = this.own.readUint32(offset);
      return early > 0 ? csr & ~DIV_CSR_READY : csr;
    }
    if (early > 0) {
      const name = offset === DIV_QUOTIENT ? 'QUOTIENT' : 'REMAINDER';
      throw new RunError(
        `core ${this.index} read the divider's ${name} ${DIVIDER_CYCLES - early} cycles after its operand, ` +
          `before the result is valid (${DIVIDER_CYCLES} cycles, datasheet 2.3.1.5: undefined on the chip)`,
      );
    }
    return this.own.readUint32(offset);
  }

  writeUint32(offset, value) {
    switch (offset) {
      case CPUID:
      case FIFO_RD:
        return; // read-only
      case FIFO_ST:
        this.fifos.clearFlags(this.index, value);
        return;
      case FIFO_WR:
        this.fifos.write(this.index, value);
        return;
    }
    if (offset >= PER_CORE_FIRST && offset <= PER_CORE_LAST) {
      this.own.writeUint32(offset, value);
      // An operand starts a division; a result written (a saved state put back) is valid at once.
      if (offset <= DIV_SDIVISOR) this.dividerReadyAt = this.now() + 1 + DIVIDER_CYCLES;
      else if (offset <= DIV_REMAINDER) this.dividerReadyAt = 0;
      return;
    }
    this.shared.writeUint32(offset, value);
  }

  /** The SIO takes 32-bit stores only: a narrower one is not modelled. */
  narrowWrite(offset, bits) {
    const address = (0xd0000000 + offset).toString(16);
    throw new RunError(`core ${this.index}: a ${bits}-bit store to SIO 0x${address} (the emulator models 32-bit SIO stores only)`);
  }
}
