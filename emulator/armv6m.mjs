// Corrections to rp2040js 1.4.1's Cortex-M0+ core, where it computes a
// different result from the Armv6-M Architecture Reference Manual (and from
// qemu, which `node test/instructions.mjs` checks these against):
//
// - ADCS and SBCS compute the overflow flag V from `Rm + carry` (or
//   `Rm + 1 - carry`) folded into one 32-bit operand, which wraps: V comes
//   out inverted when ADCS adds to 0x7fffffff with the carry set, or SBCS
//   subtracts 0x7fffffff with the carry clear. A signed 64-bit comparison
//   with i64::MAX (whose high word is 0x7fffffff) is such an SBCS, so
//   `x < i64::MAX` came out false for every x >= 0.
// - LSLS, LSRS, ASRS and RORS by a register: a shift of 0 must leave the
//   carry alone (rp2040js sets it from bit 31: JavaScript masks the shift
//   count -1 to 31), and LSLS by 33 to 255 must clear it.
//
// - WFI with PRIMASK set: a pending interrupt that would be taken were
//   PRIMASK clear ends the sleep (or keeps WFI from sleeping at all, if it
//   was pending already), and is taken only once PRIMASK is cleared
//   (Armv6-M ARM, B1.5.18, "WFI" and "Wakeup events"); rp2040js takes it at
//   once, inside the firmware's critical section, or sleeps through one
//   pending before the WFI. A firmware that masks interrupts, checks for
//   work and sleeps (the usual race-free wait) ran its interrupt handler
//   inside what the mask guards, or slept for ever.
//
// - Exception entry: the handler's address comes from the vector table
//   with its Thumb bit set, and rp2040js keeps that bit in the PC (its
//   reset and BX clear it). Fetches mask it, but everything that reads the
//   PC as a value is then one too high: `add rN, pc` in a handler (a
//   compiled `match`'s jump table) read the wrong entry and jumped wild.
//
// Each corrected instruction is executed here instead of by rp2040js, with
// the same cycle count (1); every other instruction is rp2040js's own.
//
// Invariant: `addWithCarry` and `shiftCarry` are the manual's pseudocode
// functions of the same names; nothing else is changed. The look at the next
// instruction is a `peek` (no count, no stall); the fetch that executes it
// is the core's own read, once.

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

/** The manual's Shift_C for a shift by a register (its bottom byte): result and carry out. */
function shiftCarry(value, type, amount, carryIn) {
  if (amount === 0) {
    return [value, carryIn];
  }
  switch (type) {
    case LSL:
      if (amount > 32) return [0, false];
      return [amount === 32 ? 0 : (value << amount) >>> 0, ((value >>> (32 - amount)) & 1) === 1];
    case LSR:
      if (amount > 32) return [0, false];
      return [amount === 32 ? 0 : value >>> amount, ((value >>> (amount - 1)) & 1) === 1];
    case ASR: {
      const n = Math.min(amount, 32);
      const result = n === 32 ? (value & 0x80000000 ? 0xffffffff : 0) : (value | 0) >> n;
      return [result >>> 0, ((value | 0) >> (n - 1)) & 1 ? true : false];
    }
    case ROR: {
      const n = amount % 32;
      const result = n === 0 ? value : ((value >>> n) | (value << (32 - n))) >>> 0;
      return [result, result >= 0x80000000];
    }
  }
  throw new Error(`shift type ${type}`);
}

// The 16-bit "data processing" encodings 0100 00oo ooMM MDDD, by their
// opcode field oooo.
const ADCS = 0b0101;
const SBCS = 0b0110;
const SHIFTS = new Map([
  [0b0010, LSL],
  [0b0011, LSR],
  [0b0100, ASR],
  [0b0111, ROR],
]);

/** The instructions corrected here, by mnemonic. */
export const CORRECTED = ['adcs', 'sbcs', 'lsls', 'lsrs', 'asrs', 'rors'];

/** Executes `opcode` if it is one rp2040js gets wrong; false when it is not. */
function executeCorrected(core, opcode) {
  if (opcode >> 10 !== 0b010000) {
    return false;
  }
  const operation = (opcode >> 6) & 0xf;
  const rm = (opcode >> 3) & 7;
  const rdn = opcode & 7;
  const registers = core.registers;
  if (operation === ADCS) {
    registers[rdn] = addWithCarry(core, registers[rdn], registers[rm], core.C ? 1 : 0);
  } else if (operation === SBCS) {
    registers[rdn] = addWithCarry(core, registers[rdn], ~registers[rm] >>> 0, core.C ? 1 : 0);
  } else if (SHIFTS.has(operation)) {
    const [result, carry] = shiftCarry(registers[rdn], SHIFTS.get(operation), registers[rm] & 0xff, core.C);
    registers[rdn] = result;
    core.N = result >= 0x80000000;
    core.Z = result === 0;
    core.C = carry;
  } else {
    return false;
  }
  return true;
}

// rp2040js's own executeInstruction, which the corrected one calls: one for
// every core (they are of one class). The corrected one is a single
// function too, for all cores alike (a closure per core would keep V8 from
// specialising it, costing a tenth of the emulator's speed).
let executeOriginal = null;

function executeInstruction() {
  if (this.interruptsUpdated && this.checkForInterrupts()) {
    this.waiting = false;
  }
  const pc = this.registers[15] & ~1;
  const opcode = this.peekInstruction(this.peekContext, pc);
  if (executeCorrected(this, opcode)) {
    this.readUint16(pc); // the fetch, for what it costs
    this.PC += 2;
    this.cycles += 1;
    return 1;
  }
  // Interrupts were just checked: rp2040js need not look again first.
  const pending = this.interruptsUpdated;
  this.interruptsUpdated = false;
  const cycles = executeOriginal.call(this);
  this.interruptsUpdated ||= pending;
  // A WFI with PRIMASK set does not sleep while an interrupt is pending.
  if (opcode === WFI && this.waiting && this.PM && interruptPending(this)) {
    this.waiting = false;
  }
  return cycles;
}

/**
 * Puts the corrections in front of `core.executeInstruction`. Pending
 * interrupts are taken first, exactly once, as rp2040js does; the corrected
 * instruction is then the one at the (possibly new) PC. `peek(context,
 * address)` reads an instruction without side effects (default: the core's
 * read, with the core as the context); one function for all cores, as the
 * corrected executeInstruction is.
 */
export function correctInstructions(core, peek = readInstruction, context = core) {
  const prototype = Object.getPrototypeOf(core);
  executeOriginal ??= prototype.executeInstruction;
  checkOriginal ??= prototype.checkForInterrupts;
  entryOriginal ??= prototype.exceptionEntry;
  if (
    prototype.executeInstruction !== executeOriginal ||
    prototype.checkForInterrupts !== checkOriginal ||
    prototype.exceptionEntry !== entryOriginal
  ) {
    throw new Error("correctInstructions: a core of another class than the first one's");
  }
  core.peekInstruction = peek;
  core.peekContext = context;
  core.executeInstruction = executeInstruction;
  core.checkForInterrupts = checkForInterrupts;
  core.exceptionEntry = exceptionEntry;
}

// rp2040js's own exceptionEntry, which the corrected one calls.
let entryOriginal = null;

/** rp2040js's exception entry, the handler's address taken as the architecture does: without its Thumb bit. */
function exceptionEntry(exception) {
  entryOriginal.call(this, exception);
  this.PC = this.PC & ~1;
}

// rp2040js's own checkForInterrupts (takes a pending exception, if any may
// be taken now), which the corrected one calls.
let checkOriginal = null;

/**
 * rp2040js's check, but a core asleep with PRIMASK set only wakes: its
 * callers end the sleep when this returns true, and the interrupt is taken
 * at the first check after PRIMASK clears (CPSIE and MSR PRIMASK mark the
 * interrupts for checking). An NMI ignores PRIMASK, as on the chip.
 */
function checkForInterrupts() {
  if (!(this.waiting && this.PM) || this.pendingNMI) {
    return checkOriginal.call(this);
  }
  const wakes = interruptPending(this);
  if (wakes) {
    this.interruptsUpdated = true;
  }
  return wakes;
}

/** Whether `core` has an interrupt pending that PRIMASK alone holds back. */
function interruptPending(core) {
  return (core.pendingInterrupts & core.enabledInterrupts) !== 0 || core.pendingSystick || core.pendingPendSV;
}

const WFI = 0xbf30;

function readInstruction(core, address) {
  return core.readUint16(address);
}
