// A small Thumb (Armv6-M) assembler: just the instructions the boot ROM
// stand-in, the instruction checks and the test programs are written in, so
// the emulator runs real machine code for them (and counts its cycles) with
// no toolchain.
//
// Invariant: every encoding here is the Armv6-M Architecture Reference
// Manual's (16-bit ones for low registers, and the 32-bit BL, MRS, MSR);
// an operand out of range, a branch or literal out of reach throws.

const COND = { eq: 0, ne: 1, cs: 2, cc: 3, mi: 4, pl: 5, vs: 6, vc: 7, hi: 8, ls: 9, ge: 10, lt: 11, gt: 12, le: 13 };

function low(register) {
  if (!Number.isInteger(register) || register < 0 || register > 7) {
    throw new RangeError(`r${register} is not a low register`);
  }
  return register;
}

function unsigned(value, bits, what) {
  if (!Number.isInteger(value) || value < 0 || value >= 1 << bits) {
    throw new RangeError(`${what} ${value} does not fit ${bits} bits`);
  }
  return value;
}

/** Assembles code placed at `base`; labels are strings, branches resolve at `bytes()`. */
export class Thumb {
  constructor(base) {
    this.base = base;
    this.halves = [];
    this.labels = new Map();
    this.branches = [];
    /** LDR (literal)s still to point at their constant: { at, value }. */
    this.literals = [];
  }

  /** The address of the next instruction. */
  get here() {
    return this.base + 2 * this.halves.length;
  }

  label(name) {
    if (this.labels.has(name)) {
      throw new Error(`label ${name} defined twice`);
    }
    this.labels.set(name, this.here);
    return this;
  }

  /** Appends what `write(this, ...args)` assembles (a routine shared by several). */
  inline(write, ...args) {
    write(this, ...args);
    return this;
  }

  emit(half) {
    this.halves.push(half & 0xffff);
    return this;
  }

  // Data processing (flags set, as the 16-bit encodings do outside IT blocks).
  movsImm(rd, imm8) { return this.emit(0x2000 | (low(rd) << 8) | unsigned(imm8, 8, 'immediate')); }
  movs(rd, rm) { return this.emit((low(rm) << 3) | low(rd)); } // LSLS rd, rm, #0
  mov(rd, rm) { return this.emit(0x4600 | ((rd & 8) << 4) | (rm << 3) | (rd & 7)); } // any registers, flags kept
  addsImm(rdn, imm8) { return this.emit(0x3000 | (low(rdn) << 8) | unsigned(imm8, 8, 'immediate')); }
  subsImm(rdn, imm8) { return this.emit(0x3800 | (low(rdn) << 8) | unsigned(imm8, 8, 'immediate')); }
  cmpImm(rn, imm8) { return this.emit(0x2800 | (low(rn) << 8) | unsigned(imm8, 8, 'immediate')); }
  adds(rd, rn, rm) { return this.emit(0x1800 | (low(rm) << 6) | (low(rn) << 3) | low(rd)); }
  subs(rd, rn, rm) { return this.emit(0x1a00 | (low(rm) << 6) | (low(rn) << 3) | low(rd)); }
  lslsImm(rd, rm, imm5) { return this.emit((unsigned(imm5, 5, 'shift') << 6) | (low(rm) << 3) | low(rd)); }
  lsrsImm(rd, rm, imm5) { return this.emit(0x0800 | (unsigned(imm5, 5, 'shift') << 6) | (low(rm) << 3) | low(rd)); }
  asrsImm(rd, rm, imm5) { return this.emit(0x1000 | (unsigned(imm5, 5, 'shift') << 6) | (low(rm) << 3) | low(rd)); }
  uxtb(rd, rm) { return this.emit(0xb2c0 | (low(rm) << 3) | low(rd)); }
  rev(rd, rm) { return this.emit(0xba00 | (low(rm) << 3) | low(rd)); }
  // Two-register data processing: RDN = RDN op RM.
  alu(op, rdn, rm) {
    const ops = ['ands', 'eors', 'lsls', 'lsrs', 'asrs', 'adcs', 'sbcs', 'rors', 'tst', 'rsbs', 'cmp', 'cmn', 'orrs', 'muls', 'bics', 'mvns'];
    const index = ops.indexOf(op);
    if (index < 0) {
      throw new Error(`unknown data-processing instruction ${op}`);
    }
    return this.emit(0x4000 | (index << 6) | (low(rm) << 3) | low(rdn));
  }

  // Loads and stores with an immediate offset in bytes.
  ldr(rt, rn, offset = 0) { return this.emit(0x6800 | (unsigned(offset / 4, 5, 'offset') << 6) | (low(rn) << 3) | low(rt)); }
  str(rt, rn, offset = 0) { return this.emit(0x6000 | (unsigned(offset / 4, 5, 'offset') << 6) | (low(rn) << 3) | low(rt)); }
  ldrh(rt, rn, offset = 0) { return this.emit(0x8800 | (unsigned(offset / 2, 5, 'offset') << 6) | (low(rn) << 3) | low(rt)); }
  ldrb(rt, rn, offset = 0) { return this.emit(0x7800 | (unsigned(offset, 5, 'offset') << 6) | (low(rn) << 3) | low(rt)); }
  strh(rt, rn, offset = 0) { return this.emit(0x8000 | (unsigned(offset / 2, 5, 'offset') << 6) | (low(rn) << 3) | low(rt)); }
  ldrbReg(rt, rn, rm) { return this.emit(0x5c00 | (low(rm) << 6) | (low(rn) << 3) | low(rt)); }
  strbReg(rt, rn, rm) { return this.emit(0x5400 | (low(rm) << 6) | (low(rn) << 3) | low(rt)); }
  strb(rt, rn, offset = 0) { return this.emit(0x7000 | (unsigned(offset, 5, 'offset') << 6) | (low(rn) << 3) | low(rt)); }
  ldmia(rn, registers) { return this.emit(0xc800 | (low(rn) << 8) | registerList(registers)); }
  stmia(rn, registers) { return this.emit(0xc000 | (low(rn) << 8) | registerList(registers)); }
  /** PUSH {registers} (low ones), with LR when `lr`. */
  push(registers, lr = false) { return this.emit(0xb400 | (lr ? 0x100 : 0) | registerList(registers)); }
  /** POP {registers} (low ones), with PC (a return) when `pc`. */
  pop(registers, pc = false) { return this.emit(0xbc00 | (pc ? 0x100 : 0) | registerList(registers)); }

  /** LDR rt, =value: the constant goes to the pool `bytes()` puts after the code. */
  ldrConst(rt, value) {
    this.literals.push({ at: this.halves.length, value: value >>> 0 });
    return this.emit(0x4800 | (low(rt) << 8));
  }
  strReg(rt, rn, rm) { return this.emit(0x5000 | (low(rm) << 6) | (low(rn) << 3) | low(rt)); }
  ldrReg(rt, rn, rm) { return this.emit(0x5800 | (low(rm) << 6) | (low(rn) << 3) | low(rt)); }

  // Control.
  bxLr() { return this.emit(0x4770); }
  bx(rm) { return this.emit(0x4700 | (rm << 3)); } // any register
  blx(rm) { return this.emit(0x4780 | (rm << 3)); } // any register but pc
  nop() { return this.emit(0xbf00); }
  wfe() { return this.emit(0xbf20); }
  wfi() { return this.emit(0xbf30); }
  sev() { return this.emit(0xbf40); }
  cpsie() { return this.emit(0xb662); }
  cpsid() { return this.emit(0xb672); }
  udf(imm8) { return this.emit(0xde00 | unsigned(imm8, 8, 'immediate')); }
  /** MSR MSP, rn (32 bits). */
  msrMsp(rn) { return this.emit(0xf380 | low(rn)).emit(0x8808); }
  /** BL label (32 bits): a call within ±4 MiB. */
  bl(label) {
    this.branches.push({ at: this.halves.length, label, cond: 'bl' });
    return this.emit(0).emit(0);
  }
  /** A 32-bit little-endian data word (at a word-aligned address). */
  word(value) {
    if (this.here % 4 !== 0) {
      throw new RangeError(`a data word at 0x${this.here.toString(16)} is not word-aligned`);
    }
    return this.emit(value & 0xffff).emit(value >>> 16);
  }
  /** Pads with NOPs to a multiple of 4 bytes (after data bytes, with a zero byte). */
  align4() {
    if (this.pendingByte !== undefined) this.byte(0);
    return this.here % 4 === 0 ? this : this.nop();
  }
  bkpt(imm8) { return this.emit(0xbe00 | unsigned(imm8, 8, 'breakpoint')); }
  /** MRS rd, APSR (32 bits). */
  mrsApsr(rd) { return this.emit(0xf3ef).emit(0x8000 | (low(rd) << 8)); }
  /** MSR APSR_nzcvq, rn (32 bits). */
  msrApsr(rn) { return this.emit(0xf380 | low(rn)).emit(0x8800); }
  b(label) {
    this.branches.push({ at: this.halves.length, label, cond: null });
    return this.emit(0);
  }
  /** ADR rd, label: the address of a word-aligned label at most 1020 bytes ahead. */
  adr(rd, label) {
    this.branches.push({ at: this.halves.length, label, cond: 'adr' });
    return this.emit(0xa000 | (low(rd) << 8));
  }
  /** A byte of data (padded to a halfword by the next `byte` or `align4`). */
  byte(value) {
    unsigned(value, 8, 'byte');
    if (this.pendingByte === undefined) {
      this.pendingByte = value;
      return this.emit(value);
    }
    this.halves[this.halves.length - 1] |= value << 8;
    this.pendingByte = undefined;
    return this;
  }
  bcc(cond, label) {
    if (!(cond in COND)) {
      throw new Error(`unknown condition ${cond}`);
    }
    this.branches.push({ at: this.halves.length, label, cond: COND[cond] });
    return this.emit(0);
  }

  /** Puts the pending LDR (literal)s' constants here, each once (after an unconditional branch or a return). */
  pool() {
    this.align4();
    const addresses = new Map();
    for (const { value } of this.literals) {
      if (!addresses.has(value)) {
        addresses.set(value, this.here);
        this.word(value);
      }
    }
    for (const { at, value } of this.literals) {
      const offset = addresses.get(value) - ((this.base + 2 * at + 4) & ~3);
      if (offset < 0 || offset > 1020) {
        throw new RangeError(`the constant 0x${value.toString(16)} is out of an LDR's reach`);
      }
      this.halves[at] |= offset / 4;
    }
    this.literals = [];
  }

  /**
   * The machine code, little-endian, with every branch resolved and the
   * literal pool (each distinct constant once) after the code.
   */
  bytes() {
    if (this.literals.length > 0) {
      this.pool();
    }
    for (const { at, label, cond } of this.branches) {
      const target = this.labels.get(label);
      if (target === undefined) {
        throw new Error(`branch to undefined label ${label}`);
      }
      const offset = (target - (this.base + 2 * at + 4)) >> 1;
      if (cond === 'adr') {
        const distance = target - ((this.base + 2 * at + 4) & ~3);
        if (target % 4 !== 0 || distance < 0 || distance > 1020) throw new RangeError(`ADR to ${label}: not a word-aligned label in reach`);
        this.halves[at] |= distance / 4;
      } else if (cond === 'bl') {
        if (offset < -(1 << 23) || offset >= 1 << 23) throw new RangeError(`call to ${label} is too far`);
        const s = offset < 0 ? 1 : 0;
        const j1 = (~(offset >> 22) ^ s) & 1;
        const j2 = (~(offset >> 21) ^ s) & 1;
        this.halves[at] = 0xf000 | (s << 10) | ((offset >> 11) & 0x3ff);
        this.halves[at + 1] = 0xd000 | (j1 << 13) | (j2 << 11) | (offset & 0x7ff);
      } else if (cond === null) {
        if (offset < -1024 || offset > 1023) throw new RangeError(`branch to ${label} is too far`);
        this.halves[at] = 0xe000 | (offset & 0x7ff);
      } else {
        if (offset < -128 || offset > 127) throw new RangeError(`branch to ${label} is too far`);
        this.halves[at] = 0xd000 | (cond << 8) | (offset & 0xff);
      }
    }
    const out = new Uint8Array(2 * this.halves.length);
    this.halves.forEach((half, i) => {
      out[2 * i] = half & 0xff;
      out[2 * i + 1] = half >> 8;
    });
    return out;
  }
}

function registerList(registers) {
  return registers.reduce((mask, r) => mask | (1 << low(r)), 0);
}
