// The boot ROM stand-in's functions, run on the corrected emulator, against
// their definitions in the RP2040 datasheet (computed here in JavaScript):
// edge values and a seeded set of random ones (the seed is printed).

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { RP2040 } from 'rp2040js';
import { buildBootrom, codeLetters, MISSING_FUNCTION_BREAKPOINT } from '../bootrom.mjs';
import { correctInstructions } from '../armv6m.mjs';
import { Thumb } from '../thumb.mjs';

const RETURN = 0x20040000; // a `bkpt #1` the functions return to
const BUFFER = 0x20020000;

function pico() {
  const rp2040 = new RP2040();
  rp2040.logger = { debug() {}, info() {}, warn: fatal, error: fatal };
  correctInstructions(rp2040.core);
  const rom = buildBootrom();
  rp2040.loadBootrom(rom.image);
  rp2040.sram.set(new Thumb(RETURN).bkpt(1).bytes(), RETURN - 0x20000000);
  return { rp2040, rom };
}

function fatal(component, message) {
  throw new Error(`${component}: ${message}`);
}

/** Calls the ROM function at `address` with r0..r2; returns r0 and the breakpoint it stopped at. */
function call(rp2040, address, args) {
  const core = rp2040.core;
  args.forEach((value, i) => (core.registers[i] = value));
  core.LR = RETURN | 1;
  core.PC = address;
  let stopped = null;
  rp2040.onBreak = (code) => (stopped = code);
  for (let steps = 0; stopped === null; steps++) {
    assert.ok(steps < 1_000_000, 'the function did not return');
    core.executeInstruction();
  }
  return { result: core.registers[0] >>> 0, stopped };
}

function random(seed) {
  let x = BigInt(seed) || 1n;
  return () => {
    x ^= x << 13n;
    x ^= x >> 7n;
    x ^= x << 17n;
    x &= 0xffffffffffffffffn;
    return Number(x & 0xffffffffn);
  };
}

const seed = Number(process.env.OCTRACE_SEED ?? Date.now() % 0xffffffff);
console.log(`bootrom: seed ${seed} (replay with OCTRACE_SEED=${seed})`);
const next = random(seed);
const words = [0, 1, 2, 3, 0x7fffffff, 0x80000000, 0x80000001, 0xffffffff, 0x00010000, 0x0000ffff];
for (let i = 0; i < 200; i++) words.push(next() >>> (next() % 32));

const clz = (x) => Math.clz32(x);
const ctz = (x) => (x === 0 ? 32 : 31 - Math.clz32(x & -x));
const popcount = (x) => [...(x >>> 0).toString(2)].filter((b) => b === '1').length;
const reverse = (x) => parseInt([...(x >>> 0).toString(2).padStart(32, '0')].reverse().join(''), 2);

test('the bit functions compute what the datasheet defines', () => {
  const { rp2040, rom } = pico();
  const cases = { L3: clz, T3: ctz, P3: popcount, R3: reverse };
  for (const [letters, reference] of Object.entries(cases)) {
    for (const x of words) {
      const { result } = call(rp2040, rom.addresses[letters], [x]);
      assert.equal(result, reference(x), `${letters}(0x${x.toString(16)})`);
    }
  }
});

test('memset, memset4, memcpy and memcpy44 write exactly their bytes and return their destination', () => {
  const { rp2040, rom } = pico();
  const sram = rp2040.sram;
  const at = (address) => address - 0x20000000;
  for (let round = 0; round < 60; round++) {
    const aligned = round % 2 === 0;
    const dest = BUFFER + (aligned ? 4 * (next() % 16) : next() % 64);
    const src = BUFFER + 0x1000 + (aligned ? 4 * (next() % 16) : next() % 64);
    const n = round < 4 ? round : next() % 300;
    for (let i = 0; i < 0x2000; i++) sram[at(BUFFER) + i] = next() & 0xff;
    const before = Uint8Array.from(sram.subarray(at(BUFFER), at(BUFFER) + 0x2000));
    const expected = Uint8Array.from(before);
    const byte = next() & 0xff;
    let name;
    if (round % 4 < 2) {
      name = aligned ? 'S4' : 'MS';
      expected.fill(byte, dest - BUFFER, dest - BUFFER + n);
      // The byte is passed as an int; only its low 8 bits count.
      assert.equal(call(rp2040, rom.addresses[name], [dest, byte | 0x1200, n]).result, dest);
    } else {
      name = aligned ? 'C4' : 'MC';
      expected.copyWithin(dest - BUFFER, src - BUFFER, src - BUFFER + n);
      assert.equal(call(rp2040, rom.addresses[name], [dest, src, n]).result, dest);
    }
    assert.deepEqual(sram.subarray(at(BUFFER), at(BUFFER) + 0x2000), expected, `${name} of ${n} bytes at 0x${dest.toString(16)}`);
  }
});

test('the lookup finds each function by its code, and stops at a code it lacks', () => {
  const { rp2040, rom } = pico();
  const lookup = rp2040.readUint16(0x18);
  const functions = rp2040.readUint16(0x14);
  assert.equal(lookup & 1, 1, 'a Thumb address');
  for (const [letters, address] of Object.entries(rom.addresses)) {
    const code = letters.charCodeAt(0) | (letters.charCodeAt(1) << 8);
    assert.deepEqual(call(rp2040, lookup & ~1, [functions, code]), { result: address | 1, stopped: 1 }, letters);
  }
  const flashErase = 'R'.charCodeAt(0) | ('E'.charCodeAt(0) << 8);
  assert.equal(call(rp2040, lookup & ~1, [functions, flashErase]).stopped, MISSING_FUNCTION_BREAKPOINT);
});

/** The cycles `call` took. */
function cycles(rp2040, address, args) {
  const before = rp2040.core.cycles;
  call(rp2040, address, args);
  return rp2040.core.cycles - before;
}

test("the functions cost the real ROM's: 2 cycles a word set and 3.25 a word copied in their loops, the table walked in its order at 11 cycles a code", () => {
  const { rp2040, rom } = pico();
  const more = (letters, n, args) => cycles(rp2040, rom.addresses[letters], [BUFFER, ...args, n + 64]) - cycles(rp2040, rom.addresses[letters], [BUFFER, ...args, n]);
  for (const n of [16, 100]) {
    assert.equal(more('S4', n, [0x5a]), 16 * 2, `memset4: 16 more words from ${n} bytes`);
    assert.equal(more('MS', n, [0x5a]), 16 * 2, `memset: the same loop`);
    assert.equal(more('C4', n, [BUFFER + 0x1000]), 16 * 3.25, `memcpy44: 16 more words from ${n} bytes`);
    assert.equal(more('MC', n, [BUFFER + 0x1000]), 16 * 3.25, 'memcpy of co-aligned buffers: the same loop');
  }
  assert.equal(more('MC', 16, [BUFFER + 0x1001]), 64 * 7, 'memcpy of buffers aligned apart: a byte at a time');

  const functions = rp2040.readUint16(0x14);
  const order = [];
  for (let at = functions; rp2040.readUint16(at) !== 0; at += 4) order.push(codeLetters(rp2040.readUint16(at)));
  assert.deepEqual(order, ['P3', 'R3', 'L3', 'T3', 'MS', 'S4', 'MC', 'C4'], "the real ROM's order");
  const lookup = rp2040.readUint16(0x18) & ~1;
  const code = (letters) => letters.charCodeAt(0) | (letters.charCodeAt(1) << 8);
  const find = (letters) => cycles(rp2040, lookup, [functions, code(letters)]);
  assert.equal(find('C4') - find('P3'), 7 * 11, 'seven codes further');
  // The real ROM's, on uniform inputs: popcount 18, reverse 21, clz 13, ctz 12 (its source's table).
  for (const [letters, most] of [['P3', 23], ['R3', 26], ['L3', 20], ['T3', 16]]) {
    const worst = Math.max(...words.map((x) => cycles(rp2040, rom.addresses[letters], [x])));
    assert.ok(worst <= most, `${letters}: ${worst} cycles at worst`);
  }
});
