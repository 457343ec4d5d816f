// The Thumb instructions the emulator executes itself instead of handing
// them to rp2040js 1.4.1's core: those rp2040js computes wrongly (ADCS,
// SBCS and the shifts by a register: armv6m.mjs says how), and those a
// firmware spends nearly all of its time in (the 16-bit data processing,
// loads and stores, PUSH, POP, LDM, STM, and the branches but BX and BLX:
// over 99 % of fig5_1's instructions on the ST7789 template). rp2040js
// finds an instruction by testing its opcode against each encoding in
// turn, in alphabetical order, about 60 tests before a load from the
// stack; here a table made once from the opcode names the instruction,
// which takes a fifth to a quarter off a run.
//
// Invariants: every instruction here has rp2040js's results and cycles
// (1, 2 for a taken branch or a write to the PC, loads and stores 1 plus
// the core's `cyclesIO`) and makes the same reads and writes through the
// core, in the same order: the fetch of its opcode first, then its load or
// store. The corrected ones compute what the Armv6-M Architecture
// Reference Manual's pseudocode computes (`addWithCarry`, `shiftCarry`);
// test/execute.test.mjs checks the rest against rp2040js, opcode by
// opcode, and test/armv6m.test.mjs all of them against qemu. Anything
// else (32-bit instructions but BL, BX, BLX, hints, system instructions)
// is rp2040js's: `execute` returns 0 for it. PUSH with LR and POP with PC
// take a cycle more than rp2040js counts, as the manual counts them
// (armv6m.mjs).

import { plainSramFetch } from './bus.mjs';

/** The manual's AddWithCarry: sets N, Z, C, V and returns the 32-bit result. */
function addWithCarry(core, x, y, carryIn) {
  const unsignedSum = x + y + carryIn;
  const signedSum = (x | 0) + (y | 0) + carryIn;
  const result = unsignedSum >>> 0;
  core.N = result >= 0x80000000;
  core.Z = result === 0;
  core.C = unsignedSum > 0xffffffff;
  core.V = (result | 0) !== signedSum;
  return result;
}

const LSL = 0;
const LSR = 1;
const ASR = 2;
const ROR = 3;

/** The manual's Shift_C for a shift by a register (its bottom byte): sets N, Z, C and returns the result. */
function shiftCarry(core, value, type, amount) {
  let result = value;
  let carry = core.C;
  if (amount !== 0) {
    switch (type) {
      case LSL:
        result = amount >= 32 ? 0 : (value << amount) >>> 0;
        carry = amount > 32 ? false : ((value >>> (32 - amount)) & 1) === 1;
        break;
      case LSR:
        result = amount >= 32 ? 0 : value >>> amount;
        carry = amount > 32 ? false : ((value >>> (amount - 1)) & 1) === 1;
        break;
      case ASR: {
        const n = Math.min(amount, 32);
        result = n === 32 ? (value & 0x80000000 ? 0xffffffff : 0) : ((value | 0) >> n) >>> 0;
        carry = (((value | 0) >> (n - 1)) & 1) === 1;
        break;
      }
      case ROR: {
        const n = amount % 32;
        result = n === 0 ? value : ((value >>> n) | (value << (32 - n))) >>> 0;
        carry = result >= 0x80000000;
        break;
      }
    }
  }
  core.N = result >= 0x80000000;
  core.Z = result === 0;
  core.C = carry;
  return result;
}

/** SUBS, CMP: sets N, Z, C, V and returns the 32-bit result of x - y. */
function subtract(core, x, y) {
  return addWithCarry(core, x, ~y >>> 0, 1);
}

/** Sets N and Z from a logical result (as int32 or uint32) and returns it. */
function logical(core, result) {
  core.N = result < 0 || result >= 0x80000000;
  core.Z = result === 0;
  return result;
}

// The instructions, by what `execute` switches on.
const OTHER = 0; // rp2040js's
const LSLS_IMM = 1;
const LSRS_IMM = 2;
const ASRS_IMM = 3;
const ADDS_REG = 4;
const SUBS_REG = 5;
const ADDS_IMM3 = 6;
const SUBS_IMM3 = 7;
const MOVS_IMM = 8;
const CMP_IMM = 9;
const ADDS_IMM8 = 10;
const SUBS_IMM8 = 11;
const ANDS = 12;
const EORS = 13;
const LSLS_REG = 14;
const LSRS_REG = 15;
const ASRS_REG = 16;
const ADCS = 17;
const SBCS = 18;
const RORS = 19;
const TST = 20;
const RSBS = 21;
const CMP_REG = 22;
const CMN = 23;
const ORRS = 24;
const MULS = 25;
const BICS = 26;
const MVNS = 27;
const ADD_HIGH = 28;
const CMP_HIGH = 29;
const MOV_HIGH = 30;
const LDR_LITERAL = 31;
const TRANSFER_REG = 32; // a load or store at Rn + Rm (`ACCESS` says which)
const TRANSFER_IMM = 33; // at Rn + imm5 × its width
const TRANSFER_SP = 34; // at SP + imm8 × 4
const ADR = 35;
const ADD_SP_TO_REG = 36;
const ADD_SP = 37;
const SUB_SP = 38;
const SXTH = 39;
const SXTB = 40;
const UXTH = 41;
const UXTB = 42;
const B_COND = 43;
const B = 44;
const PUSH = 45;
const POP = 46;
const STM = 47;
const LDM = 48;
const BL = 49; // its first halfword; the second says whether it is one

/** The 16-bit data-processing instructions 0100 00oo oo.., by oooo. */
const DATA_PROCESSING = [ANDS, EORS, LSLS_REG, LSRS_REG, ASRS_REG, ADCS, SBCS, RORS, TST, RSBS, CMP_REG, CMN, ORRS, MULS, BICS, MVNS];
// A load's or store's access: its width in bytes, whether it stores, and
// whether it sign-extends what it loads.
const STORE = 8;
const SIGNED = 16;
/** The loads and stores by a register, 0101 ooo.: by ooo. */
const BY_REGISTER = [4 | STORE, 2 | STORE, 1 | STORE, 1 | SIGNED, 4, 2, 1, 2 | SIGNED];
/** The loads and stores with an immediate offset, 011B L... and 100. L...: by opcode >> 11. */
const BY_IMMEDIATE = { 0b01100: 4 | STORE, 0b01101: 4, 0b01110: 1 | STORE, 0b01111: 1, 0b10000: 2 | STORE, 0b10001: 2 };
const EXTENDS = [SXTH, SXTB, UXTH, UXTB];

/** The instruction `opcode` (its first halfword) is, by the manual's 16-bit Thumb encodings. */
function decode(opcode) {
  const top5 = opcode >> 11;
  if (top5 <= 2) return [LSLS_IMM, LSRS_IMM, ASRS_IMM][top5];
  if (top5 === 3) return [ADDS_REG, SUBS_REG, ADDS_IMM3, SUBS_IMM3][(opcode >> 9) & 3];
  if (top5 <= 7) return [MOVS_IMM, CMP_IMM, ADDS_IMM8, SUBS_IMM8][top5 - 4];
  if (opcode >> 10 === 0b010000) return DATA_PROCESSING[(opcode >> 6) & 0xf];
  if (opcode >> 8 === 0x44) return ADD_HIGH;
  if (opcode >> 8 === 0x45) return CMP_HIGH;
  if (opcode >> 8 === 0x46) return MOV_HIGH;
  if (top5 === 0b01001) return LDR_LITERAL;
  if (opcode >> 12 === 0b0101) return TRANSFER_REG;
  if (top5 in BY_IMMEDIATE) return TRANSFER_IMM;
  if (top5 === 0b10010 || top5 === 0b10011) return TRANSFER_SP;
  if (top5 === 0b10100) return ADR;
  if (top5 === 0b10101) return ADD_SP_TO_REG;
  if (opcode >> 7 === 0b101100000) return ADD_SP;
  if (opcode >> 7 === 0b101100001) return SUB_SP;
  if (opcode >> 8 === 0xb2) return EXTENDS[(opcode >> 6) & 3];
  if (opcode >> 12 === 0xd && ((opcode >> 8) & 0xf) < 0xe) return B_COND;
  if (top5 === 0b11100) return B;
  if (opcode >> 9 === 0b1011010) return PUSH;
  if (opcode >> 9 === 0b1011110) return POP;
  if (top5 === 0b11000) return STM;
  if (top5 === 0b11001) return LDM;
  if (top5 === 0b11110) return BL;
  return OTHER;
}

/** Each opcode's instruction, decoded once. */
const KIND = Uint8Array.from({ length: 0x10000 }, (_, opcode) => decode(opcode));

/** A load's or store's access (0 for any other instruction), by opcode. */
const ACCESS = Uint8Array.from({ length: 0x10000 }, (_, opcode) => {
  switch (KIND[opcode]) {
    case TRANSFER_REG: return BY_REGISTER[(opcode >> 9) & 7];
    case TRANSFER_IMM: return BY_IMMEDIATE[opcode >> 11];
    case TRANSFER_SP: return opcode & 0x800 ? 4 : 4 | STORE;
    case LDR_LITERAL: return 4;
    default: return 0;
  }
});

/**
 * Instruction `opcode`'s load or store at `address`, of or to register
 * `t`: the cycles it takes beyond the first.
 */
function transfer(core, opcode, address, t) {
  const access = ACCESS[opcode];
  const r = core.registers;
  if (access & STORE) {
    const cycles = core.cyclesIO(address, true);
    if ((access & 7) === 4) core.writeUint32(address, r[t]);
    else if ((access & 7) === 2) core.writeUint16(address, r[t]);
    else core.writeUint8(address, r[t]);
    return cycles;
  }
  const cycles = core.cyclesIO(address);
  switch (access) {
    case 4: r[t] = core.readUint32(address); break;
    case 2: r[t] = core.readUint16(address); break;
    case 1: r[t] = core.readUint8(address); break;
    case 2 | SIGNED: r[t] = (core.readUint16(address) << 16) >> 16; break;
    case 1 | SIGNED: r[t] = (core.readUint8(address) << 24) >> 24; break;
  }
  return cycles;
}

/** The instructions rp2040js gets wrong, which `execute` computes as the manual does, by mnemonic. */
const CORRECTIONS = { adcs: ADCS, sbcs: SBCS, lsls: LSLS_REG, lsrs: LSRS_REG, asrs: ASRS_REG, rors: RORS };
export const CORRECTED = Object.keys(CORRECTIONS);
const CORRECTED_KINDS = Object.values(CORRECTIONS);

/** The instructions `execute` takes and rp2040js computes alike (the rest of its own are corrections). */
export const AS_RP2040JS = (opcode) => KIND[opcode] !== OTHER && !CORRECTED_KINDS.includes(KIND[opcode]);

/** Register `n` as ADD and MOV with high registers read it: the PC as the instruction's address + 4. */
function readHigh(r, n) {
  return n === 15 ? r[15] + 2 : r[n];
}

/**
 * Writes `value` to register `d` as ADD and MOV with high registers do: to
 * the PC a branch (a cycle more, returned), to SP word-aligned.
 */
function writeHigh(r, d, value) {
  if (d === 15) {
    r[15] = value & ~1;
    return 1;
  }
  r[d] = d === 13 ? value & ~3 : value;
  return 0;
}

/** Stores the low registers in `list` from `at` up, a word each: where they end. */
function storeList(core, list, at) {
  for (let i = 0; i < 8; i++) {
    if (list & (1 << i)) {
      core.writeUint32(at, core.registers[i]);
      at += 4;
    }
  }
  return at;
}

/** Loads the low registers in `list` from `at` up, a word each: where they end. */
function loadList(core, list, at) {
  for (let i = 0; i < 8; i++) {
    if (list & (1 << i)) {
      core.registers[i] = core.readUint32(at);
      at += 4;
    }
  }
  return at;
}

/** The number of bits set in the byte `bits`. */
function bitCount(bits) {
  let n = 0;
  for (let b = bits; b !== 0; b &= b - 1) n++;
  return n;
}

/** Whether condition `cond` (0 to 13) holds for `core`'s flags. */
function holds(core, cond) {
  let result;
  switch (cond >> 1) {
    case 0: result = core.Z; break;
    case 1: result = core.C; break;
    case 2: result = core.N; break;
    case 3: result = core.V; break;
    case 4: result = core.C && !core.Z; break;
    case 5: result = core.N === core.V; break;
    default: result = core.N === core.V && !core.Z; break;
  }
  return cond & 1 ? !result : result;
}

/** Whether `second` is the second halfword of a BL (10.1 .... .... ....). */
const isBl = (second) => (second & 0xd000) === 0xd000;

/**
 * Executes the instruction `opcode` at `pc` on `core` (`second`, its second
 * halfword if it is a 32-bit one), if it is one of those this module takes:
 * fetches it through the core, executes it, counts its cycles and returns
 * them. Returns 0, having done nothing, for any other.
 */
export function execute(core, opcode, pc, second) {
  const kind = KIND[opcode];
  if (kind === OTHER || (kind === BL && !isBl(second))) return 0;
  // The fetch, for what it costs: a plain SRAM read only takes its slots.
  const halfwords = kind === BL ? 2 : 1;
  if (plainSramFetch(core, pc, halfwords)) {
    core.slot += halfwords;
  } else {
    core.readUint16(pc);
    if (kind === BL) core.readUint16(pc + 2);
  }
  const r = core.registers;
  r[15] += 2;
  const low0 = opcode & 7;
  const low3 = (opcode >> 3) & 7;
  const low6 = (opcode >> 6) & 7;
  const high8 = (opcode >> 8) & 7;
  const imm5 = (opcode >> 6) & 0x1f;
  const imm8 = opcode & 0xff;
  let cycles = 1;
  switch (kind) {
    case LSLS_IMM: {
      const input = r[low3];
      if (imm5 !== 0) core.C = ((input >>> (32 - imm5)) & 1) === 1;
      r[low0] = logical(core, (input << imm5) >>> 0);
      break;
    }
    case LSRS_IMM: {
      const input = r[low3];
      core.C = ((input >>> (imm5 === 0 ? 31 : imm5 - 1)) & 1) === 1;
      r[low0] = logical(core, imm5 === 0 ? 0 : input >>> imm5);
      break;
    }
    case ASRS_IMM: {
      const input = r[low3] | 0;
      const n = imm5 === 0 ? 32 : imm5;
      core.C = ((input >> (n - 1)) & 1) === 1;
      r[low0] = logical(core, n === 32 ? input >> 31 : input >> n);
      break;
    }
    case ADDS_REG: r[low0] = addWithCarry(core, r[low3], r[low6], 0); break;
    case SUBS_REG: r[low0] = subtract(core, r[low3], r[low6]); break;
    case ADDS_IMM3: r[low0] = addWithCarry(core, r[low3], low6, 0); break;
    case SUBS_IMM3: r[low0] = subtract(core, r[low3], low6); break;
    case MOVS_IMM: r[high8] = logical(core, imm8); break;
    case CMP_IMM: subtract(core, r[high8], imm8); break;
    case ADDS_IMM8: r[high8] = addWithCarry(core, r[high8], imm8, 0); break;
    case SUBS_IMM8: r[high8] = subtract(core, r[high8], imm8); break;
    case ANDS: r[low0] = logical(core, r[low0] & r[low3]); break;
    case EORS: r[low0] = logical(core, r[low0] ^ r[low3]); break;
    case LSLS_REG: r[low0] = shiftCarry(core, r[low0], LSL, r[low3] & 0xff); break;
    case LSRS_REG: r[low0] = shiftCarry(core, r[low0], LSR, r[low3] & 0xff); break;
    case ASRS_REG: r[low0] = shiftCarry(core, r[low0], ASR, r[low3] & 0xff); break;
    case ADCS: r[low0] = addWithCarry(core, r[low0], r[low3], core.C ? 1 : 0); break;
    case SBCS: r[low0] = addWithCarry(core, r[low0], ~r[low3] >>> 0, core.C ? 1 : 0); break;
    case RORS: r[low0] = shiftCarry(core, r[low0], ROR, r[low3] & 0xff); break;
    case TST: logical(core, r[low0] & r[low3]); break;
    case RSBS: r[low0] = subtract(core, 0, r[low3]); break;
    case CMP_REG: subtract(core, r[low0], r[low3]); break;
    case CMN: addWithCarry(core, r[low0], r[low3], 0); break;
    case ORRS: r[low0] = logical(core, r[low0] | r[low3]); break;
    case MULS: r[low0] = logical(core, Math.imul(r[low3], r[low0])); break;
    case BICS: r[low0] = logical(core, r[low0] & ~r[low3]); break;
    case MVNS: r[low0] = logical(core, ~r[low3]); break;
    case ADD_HIGH: {
      const d = ((opcode >> 4) & 8) | low0;
      cycles += writeHigh(r, d, readHigh(r, d) + readHigh(r, (opcode >> 3) & 0xf));
      break;
    }
    case CMP_HIGH: subtract(core, r[((opcode >> 4) & 8) | low0], r[(opcode >> 3) & 0xf]); break;
    case MOV_HIGH: cycles += writeHigh(r, ((opcode >> 4) & 8) | low0, readHigh(r, (opcode >> 3) & 0xf)); break;
    case LDR_LITERAL: cycles += transfer(core, opcode, ((r[15] + 2) & 0xfffffffc) + (imm8 << 2), high8); break;
    case TRANSFER_REG: cycles += transfer(core, opcode, r[low6] + r[low3], low0); break;
    case TRANSFER_IMM: cycles += transfer(core, opcode, r[low3] + imm5 * (ACCESS[opcode] & 7), low0); break;
    case TRANSFER_SP: cycles += transfer(core, opcode, r[13] + (imm8 << 2), high8); break;
    case ADR: r[high8] = (pc & 0xfffffffc) + 4 + (imm8 << 2); break;
    case ADD_SP_TO_REG: r[high8] = r[13] + (imm8 << 2); break;
    case ADD_SP: r[13] = (r[13] + ((opcode & 0x7f) << 2)) & ~3; break;
    case SUB_SP: r[13] = (r[13] - ((opcode & 0x7f) << 2)) & ~3; break;
    case SXTH: r[low0] = (r[low3] << 16) >> 16; break;
    case SXTB: r[low0] = (r[low3] << 24) >> 24; break;
    case UXTH: r[low0] = r[low3] & 0xffff; break;
    case UXTB: r[low0] = r[low3] & 0xff; break;
    case B_COND:
      if (holds(core, (opcode >> 8) & 0xf)) {
        r[15] += ((imm8 << 24) >> 23) + 2;
        cycles++;
      }
      break;
    case B:
      r[15] += (((opcode & 0x7ff) << 21) >> 20) + 2;
      cycles++;
      break;
    case PUSH: {
      // Low registers up from the lowest address, LR last; a cycle each (LR's too: armv6m.mjs).
      const withLr = (opcode >> 8) & 1;
      const count = bitCount(imm8) + withLr;
      const at = storeList(core, imm8, r[13] - 4 * count);
      if (withLr) core.writeUint32(at, r[14]);
      r[13] = (r[13] - 4 * count) & ~3;
      cycles += count;
      break;
    }
    case POP: {
      const at = loadList(core, imm8, r[13]);
      cycles += bitCount(imm8);
      if (opcode & 0x100) {
        // A return: PC's load takes its cycle (armv6m.mjs), the branch two more.
        r[13] = (at + 4) & ~3;
        core.BXWritePC(core.readUint32(at));
        cycles += 3;
      } else {
        r[13] = at & ~3;
      }
      break;
    }
    case STM:
    case LDM: {
      // Written back unless the base is in the list, as rp2040js does.
      const at = kind === STM ? storeList(core, imm8, r[high8]) : loadList(core, imm8, r[high8]);
      if (!(imm8 & (1 << high8))) r[high8] = at;
      cycles += bitCount(imm8);
      break;
    }
    case BL: {
      const s = (opcode >> 10) & 1;
      const i1 = 1 - (s ^ ((second >> 13) & 1));
      const i2 = 1 - (s ^ ((second >> 11) & 1));
      const offset = (s ? 0xff000000 : 0) | (i1 << 23) | (i2 << 22) | ((opcode & 0x3ff) << 12) | ((second & 0x7ff) << 1);
      r[14] = (r[15] + 2) | 1;
      r[15] += 2 + offset;
      cycles += 2;
      core.blTaken(core, false);
      break;
    }
  }
  core.cycles += cycles;
  return cycles;
}
