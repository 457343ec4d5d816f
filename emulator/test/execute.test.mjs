// execute.mjs against rp2040js 1.4.1's own core, opcode by opcode: every
// opcode that execute.mjs takes and rp2040js computes alike (all but the
// corrections, which test/armv6m.test.mjs checks against qemu; a BL with
// random second halves) runs on both from the same random registers and
// flags (seeded; the seed is printed), with the core's memory a stand-in
// that logs each read and write. Asserts the same registers, flags, cycles
// (PUSH with LR and POP with PC a cycle more, as the manual counts them)
// and the same reads and writes in the same order; and that every other
// opcode is left to rp2040js, untouched.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { RP2040 } from 'rp2040js';
import { AS_RP2040JS, execute } from '../execute.mjs';

const seed = Number(process.env.OCTRACE_SEED ?? Date.now() % 0xffffffff) >>> 0 || 1;
console.log(`execute: seed ${seed} (replay with OCTRACE_SEED=${seed})`);
let state = seed;
/** xorshift32: the next random 32-bit word. */
function next() {
  state ^= state << 13;
  state ^= state >>> 17;
  state ^= state << 5;
  return state >>> 0;
}

const PC = 0x10000100;
const STATES = 4;

/**
 * A core whose memory answers every read with a word made from its
 * address (the instruction's at PC: `opcode()`), and logs it.
 */
function standInCore(log, opcode, second = () => 0) {
  const core = new RP2040().core;
  const word = (address) => Math.imul((address >>> 0) ^ 0x9e3779b9, 0x85ebca6b) >>> 0;
  core.readUint32 = (address) => (log.push(['r32', address >>> 0]), word(address));
  core.readUint16 = (address) => (log.push(['r16', address >>> 0]), (address >>> 0) === PC ? opcode() : (address >>> 0) === PC + 2 ? second() : word(address) & 0xffff);
  core.readUint8 = (address) => (log.push(['r8', address >>> 0]), word(address) & 0xff);
  core.writeUint32 = (address, value) => log.push(['w32', address >>> 0, value >>> 0]);
  core.writeUint16 = (address, value) => log.push(['w16', address >>> 0, value & 0xffff]);
  core.writeUint8 = (address, value) => log.push(['w8', address >>> 0, value & 0xff]);
  return core;
}

/** Sets `core`'s registers and flags from `values` (17 words). */
function load(core, values) {
  for (let i = 0; i < 15; i++) core.registers[i] = values[i];
  core.registers[13] &= ~3;
  core.registers[15] = PC;
  core.APSR = values[16] & 0xf0000000;
  core.cycles = 1000;
}

function after(core, returned) {
  return { registers: Array.from(core.registers), apsr: core.APSR >>> 0, cycles: core.cycles, returned };
}

test('execute.mjs computes what rp2040js computes, with its cycles and accesses, for every opcode it takes', () => {
  const rp2040jsExecute = Object.getPrototypeOf(new RP2040().core).executeInstruction;
  const log = [];
  let opcode = 0;
  let second = 0;
  const ours = standInCore(log, () => opcode, () => second);
  const theirs = standInCore(log, () => opcode, () => second);
  let checked = 0;
  for (; opcode < 0x10000; opcode++) {
    if (!AS_RP2040JS(opcode)) continue;
    for (let k = 0; k < STATES; k++) {
      // Small operands now and then, so that shifts, carries and zero results come up.
      const values = Array.from({ length: 17 }, () => (next() & 3 ? next() : next() & 0x3f));
      load(ours, values);
      load(theirs, values);
      log.length = 0;
      // A BL's second halfword: 11J1 J... .... .... (bits 15, 14 and 12 set).
      second = 0xd000 | (next() & 0x2fff);
      const expected = after(theirs, rp2040jsExecute.call(theirs));
      if ((opcode & 0xff00) === 0xb500 || (opcode & 0xff00) === 0xbd00) {
        expected.cycles++;
        expected.returned++;
      }
      const theirAccesses = log.splice(0);
      const got = after(ours, execute(ours, opcode, PC, second));
      const context = `opcode 0x${opcode.toString(16).padStart(4, '0')} from ${values.map((v) => v.toString(16)).join(' ')}`;
      assert.deepEqual(got, expected, context);
      assert.deepEqual(log, theirAccesses, context);
      checked++;
    }
  }
  console.log(`execute: ${checked} cases alike`);
  assert.ok(checked > 40_000 * STATES, `${checked} cases`);
});

test('execute.mjs leaves the 32-bit instructions but BL, BX, BLX, the hints and system instructions to rp2040js', () => {
  const log = [];
  const core = standInCore(log, () => 0);
  const others = [[0xf3bf, 0x8f50], [0xf3ef, 0x8000], [0xf380, 0x8808], [0xf7f0, 0xa000], [0xe800, 0]];
  for (const opcode of [0x4770, 0x4788, 0xbf30, 0xbf20, 0xbf00, 0xb662, 0xb672, 0xba00, 0xde00, 0xdf00, 0xbe00]) others.push([opcode, 0]);
  for (const [opcode, second] of others) {
    load(core, new Array(17).fill(0));
    assert.equal(execute(core, opcode, PC, second), 0, `0x${opcode.toString(16)} 0x${second.toString(16)}`);
    assert.equal(core.registers[15], PC);
    assert.deepEqual(log, []);
  }
});
