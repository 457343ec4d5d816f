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
// Invariants: core 0's divider and interpolators are rp2040js's own, so a
// one-core firmware's SIO is today's; core 1 has instances of the same
// classes acting on core 1 (the divider charges its 8 cycles to the core
// that started it); a spinlock read claims it for whichever core reads.

import { RunError } from './errors.mjs';

const CPUID = 0x000;
const FIFO_ST = 0x050;
const FIFO_WR = 0x054;
const FIFO_RD = 0x058;
/** The divider (0x060..0x078) and the two interpolators (0x080..0x0fc) are per core. */
const PER_CORE_FIRST = 0x060;
const PER_CORE_LAST = 0x0fc;

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
   * (`shared` itself for core 0).
   */
  constructor(index, fifos, shared, own) {
    Object.assign(this, { index, fifos, shared, own });
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
      return this.own.readUint32(offset);
    }
    return this.shared.readUint32(offset);
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
