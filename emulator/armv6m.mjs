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
// Timing, where rp2040js 1.4.1 counts other cycles than the Cortex-M0+
// Technical Reference Manual (ARM DDI 0484C) and the RP2040 datasheet:
//
// - PUSH with LR and POP with PC (TRM 3.3, table 3-1: PUSH 1 + N, POP
//   1 + N, POP and return 3 + N, N the registers in the list): rp2040js
//   leaves LR and PC out of N, a cycle short each (execute.mjs counts them).
// - Loads and stores on the APB (datasheet 2.1.3, the APB bridge: a read
//   takes 3 cycles, a write 4): rp2040js charges 4 and 5.
// - Exception entry: 15 cycles from the interrupt to the handler's first
//   instruction (TRM 3.6.1, zero wait states); rp2040js charges none.
//   Exception return: the eight words of the frame loaded as a POP loads
//   them, a cycle each, beyond the returning BX or POP; rp2040js charges
//   nothing for them.
//
// And, when the core is on the bus fabric (fabric.mjs), its instruction
// fetches: the M0+ fetches 32 bits at a time, so a word of code is fetched
// once for the two 16-bit instructions in it, in the last cycle of the
// instruction before (the cycle the prefetch overlaps); a taken branch,
// a call, a return or an exception refetches at its target, in its own
// last cycle; a 32-bit instruction whose second half is in the next word
// fetches that word in its first cycle. Its loads and stores (the bus
// counts them) address the bus in the instruction's first cycles, one a
// cycle (LDM, STM, PUSH and POP one register a cycle), so that none falls
// in the cycle of the next fetch. Each access is arbitrated there; a
// stall delays the rest of the instruction.
//
// Each corrected instruction, and each of those a firmware spends nearly
// all of its time in, is executed by execute.mjs instead of by rp2040js,
// with rp2040js's cycle counts; every other instruction is rp2040js's own.
//
// Invariant: no result is changed but the corrected instructions'. The
// look at the next instruction is a `peek` (no count, no stall); the read
// that executes it is the core's own, once, and the bus takes it for a
// fetch (`slot` below zero), not for a load.

import { FETCH, NO_PORT, portOf } from './fabric.mjs';
import { execute } from './execute.mjs';

// rp2040js's own executeInstruction, which the corrected one calls: one for
// every core (they are of one class). The corrected one is a single
// function too, for all cores alike (a closure per core would keep V8 from
// specialising it, costing a tenth of the emulator's speed).
let executeOriginal = null;

/** TRM 3.6.1: the cycles from an interrupt to its handler's first instruction. */
export const EXCEPTION_ENTRY_CYCLES = 15;
/** The exception frame's eight words, loaded a cycle each on return. */
export const EXCEPTION_RETURN_CYCLES = 8;

function executeInstruction() {
  if (this.interruptsUpdated && this.checkForInterrupts()) {
    this.waiting = false;
  }
  const fabric = this.fabric;
  if (this.entering) {
    // The exception's frame is stacked: the handler starts 15 cycles on, its first word fetched in the last.
    this.entering = false;
    this.cycles += EXCEPTION_ENTRY_CYCLES;
    if (fabric !== null) fetch(this, this.registers[15] & ~3, this.cycles - 1);
  }
  const pc = this.registers[15] & ~1;
  const opcode = this.peekInstruction(this.peekContext, pc);
  const wide = opcode >= 0xe800;
  if (fabric !== null) {
    this.slot = wide ? -2 : -1;
    if (wide && ((pc + 2) & ~3) !== this.fetchedWord) fetch(this, (pc + 2) & ~3, this.cycles);
  }
  let cycles = execute(this, opcode, pc, wide ? this.peekInstruction(this.peekContext, pc + 2) : 0);
  if (cycles === 0) {
    // Interrupts were just checked: rp2040js need not look again first.
    const pending = this.interruptsUpdated;
    this.interruptsUpdated = false;
    cycles = executeOriginal.call(this);
    this.interruptsUpdated ||= pending;
    // A WFI with PRIMASK set does not sleep while an interrupt is pending.
    if (opcode === WFI && this.waiting && this.PM && interruptPending(this)) {
      this.waiting = false;
    }
  }
  if (fabric !== null) {
    // The next instruction's word, unless this one's was it and the flow is sequential.
    const next = this.registers[15] & ~1;
    const word = next & ~3;
    if (word !== this.fetchedWord || next !== pc + (wide ? 4 : 2)) fetch(this, word, this.cycles - 1);
  }
  return cycles;
}

/** Core `core` fetches the word at `word` in cycle `cycle`, arbitrated by its fabric. */
function fetch(core, word, cycle) {
  core.fetchedWord = word;
  const port = portOf(word >>> 0);
  if (port === NO_PORT) return;
  const waited = core.fabric.access(core.busIndex, port, cycle, FETCH);
  if (waited !== 0) core.cycles += waited;
}

/**
 * Puts the corrections in front of `core.executeInstruction`. Pending
 * interrupts are taken first, exactly once, as rp2040js does; the corrected
 * instruction is then the one at the (possibly new) PC. `peek(context,
 * address)` reads an instruction without side effects (default: the core's
 * read, with the core as the context); one function for all cores, as the
 * corrected executeInstruction is. With `fabric` (fabric.mjs) and the
 * core's `busIndex` on it, its fetches are arbitrated there (its loads and
 * stores are the bus's to arbitrate, bus.mjs).
 */
export function correctInstructions(core, peek = readInstruction, context = core, { fabric = null, busIndex = 0 } = {}) {
  const prototype = Object.getPrototypeOf(core);
  executeOriginal ??= prototype.executeInstruction;
  checkOriginal ??= prototype.checkForInterrupts;
  entryOriginal ??= prototype.exceptionEntry;
  returnOriginal ??= prototype.exceptionReturn;
  if (
    prototype.executeInstruction !== executeOriginal ||
    prototype.checkForInterrupts !== checkOriginal ||
    prototype.exceptionEntry !== entryOriginal ||
    prototype.exceptionReturn !== returnOriginal
  ) {
    throw new Error("correctInstructions: a core of another class than the first one's");
  }
  core.peekInstruction = peek;
  core.peekContext = context;
  core.fabric = fabric;
  core.busIndex = busIndex;
  core.fetchedWord = -1;
  core.slot = 0;
  core.entering = false;
  core.executeInstruction = executeInstruction;
  core.checkForInterrupts = checkForInterrupts;
  core.exceptionEntry = exceptionEntry;
  core.exceptionReturn = exceptionReturn;
  core.cyclesIO = cyclesIO;
}

// rp2040js's own exceptionEntry and exceptionReturn, which the corrected ones call.
let entryOriginal = null;
let returnOriginal = null;

/**
 * rp2040js's exception entry, the handler's address taken as the
 * architecture does: without its Thumb bit. The frame's stores are the
 * bus's from the entry's first cycle; the 15 cycles are counted when the
 * core next runs (it may be asleep now, its time not yet brought up to the
 * machine's).
 */
function exceptionEntry(exception) {
  this.slot = 0;
  entryOriginal.call(this, exception);
  this.PC = this.PC & ~1;
  this.entering = true;
}

/** rp2040js's exception return, with the eight loads of the frame counted. */
function exceptionReturn(excReturn) {
  returnOriginal.call(this, excReturn);
  this.cycles += EXCEPTION_RETURN_CYCLES;
}

const APB_BASE = 0x40000000;
const APB_END = 0x50000000;
const SIO_BASE = 0xd0000000;
const SIO_END = 0xe0000000;

/**
 * The cycles a single load or store to `address` takes beyond its first:
 * none to the SIO (the IOPORT, 2.3.1), 2 and 3 on the APB (a read in 3, a
 * write in 4: datasheet 2.1.3), else 1 (AHB-Lite, no wait states).
 */
function cyclesIO(address, write = false) {
  address >>>= 0;
  if (address >= SIO_BASE && address < SIO_END) return 0;
  if (address >= APB_BASE && address < APB_END) return write ? 3 : 2;
  return 1;
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
