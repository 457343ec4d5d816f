// The emulator's instructions against qemu's Cortex-M0 (qemu-system-arm
// -machine microbit): each flag-setting data-processing instruction, with
// every pair of a set of edge operands and both carries, runs on qemu, on
// rp2040js as published and on rp2040js with armv6m.mjs's corrections.
//
// What it asserts: the corrected emulator agrees with qemu on every case,
// and rp2040js as published differs from qemu in exactly the instructions
// armv6m.mjs corrects (so a correction that is no longer needed, or a new
// difference, fails here). Run `node --test test/` for the table of the
// differences, each with its smallest case.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { RP2040 } from 'rp2040js';
import { Thumb } from '../thumb.mjs';
import { correctInstructions } from '../armv6m.mjs';
import { CORRECTED } from '../execute.mjs';

// Operands: the edges of every carry and overflow, and of shifts by a register.
const VALUES = [
  0, 1, 2, 31, 32, 33, 0x7f, 0x80, 0xff, 0x100, 0x7ffffffe, 0x7fffffff, 0x80000000, 0x80000001, 0xfffffffe,
  0xffffffff,
];
// Flags in: all clear, and all set (C in both states; N, Z, V kept or not).
const FLAGS_IN = [0x00000000, 0xf0000000];

// Each instruction: its name and how it is assembled with r0 = Rdn (or Rd) and r1 = Rm (or Rn).
const INSTRUCTIONS = [
  ...['ands', 'eors', 'lsls', 'lsrs', 'asrs', 'adcs', 'sbcs', 'rors', 'tst', 'rsbs', 'cmp', 'cmn', 'orrs', 'muls', 'bics', 'mvns'].map(
    (op) => [`${op} r0, r1`, (t) => t.alu(op, 0, 1)],
  ),
  ['adds r0, r0, r1', (t) => t.adds(0, 0, 1)],
  ['subs r0, r0, r1', (t) => t.subs(0, 0, 1)],
  ...[1, 31].map((n) => [`lsls r0, r1, #${n}`, (t) => t.lslsImm(0, 1, n)]),
  ...[0, 1, 31].map((n) => [`lsrs r0, r1, #${n || 32}`, (t) => t.lsrsImm(0, 1, n)]),
  ...[0, 1, 31].map((n) => [`asrs r0, r1, #${n || 32}`, (t) => t.asrsImm(0, 1, n)]),
  ['adds r0, #255', (t) => t.addsImm(0, 255)],
  ['subs r0, #255', (t) => t.subsImm(0, 255)],
  ['cmp r0, #255', (t) => t.cmpImm(0, 255)],
];

const CASES = FLAGS_IN.flatMap((flags) => VALUES.flatMap((x) => VALUES.map((y) => [x, y, flags])));
const RESULTS = 0x20000000; // one instruction's results (12 bytes a case) before they are written out
const SEMIHOSTING_BLOCK = 0x20003f00;
const SYS_OPEN = 0x01;
const SYS_WRITE = 0x05;
const SYS_EXIT = 0x18;
const EXIT_APPLICATION = 0x20026;

/**
 * The program, at address 0 (the micro:bit's flash; rp2040js's ROM): for
 * each instruction, a loop over the cases that sets r0, r1 and the flags,
 * runs it, and stores r0, r1 and the flags; then writes the results to the
 * host by semihosting.
 */
function program() {
  const t = new Thumb(0);
  t.emit(0x4000).emit(0x2000); // initial SP 0x20004000 (unused)
  t.emit(0x0041).emit(0x0000); // reset: 0x40, Thumb
  while (t.here < 0x40) t.emit(0);
  // Constants by shifts (the code must not depend on literal pools).
  const load = (register, value) => {
    const scratch = register === 3 ? 2 : 3;
    t.movsImm(register, value >>> 24);
    for (const shift of [16, 8, 0]) {
      t.lslsImm(register, register, 8).movsImm(scratch, (value >>> shift) & 0xff).alu('orrs', register, scratch);
    }
  };
  const semihost = (operation, words) => {
    load(5, SEMIHOSTING_BLOCK);
    words.forEach((word, i) => {
      if (typeof word === 'number') load(3, word);
      else t.mov(3, word.register);
      t.str(3, 5, 4 * i);
    });
    t.movsImm(0, operation).movs(1, 5).bkpt(0xab);
  };
  const name = casesAddress() - 16; // ":tt", after the code
  semihost(SYS_OPEN, [name, 4 /* "w" */, 3]);
  t.mov(8, 0); // the handle, kept in r8
  INSTRUCTIONS.forEach(([, assemble], k) => {
    load(7, casesAddress());
    load(6, RESULTS);
    load(4, CASES.length);
    t.label(`case.${k}`)
      .ldr(0, 7, 0)
      .ldr(1, 7, 4)
      .ldr(2, 7, 8)
      .msrApsr(2);
    assemble(t);
    t.mrsApsr(2).stmia(6, [0, 1, 2]).addsImm(7, 12).subsImm(4, 1).bcc('ne', `case.${k}`);
    semihost(SYS_WRITE, [{ register: 8 }, RESULTS, 12 * CASES.length]);
  });
  t.movsImm(0, SYS_EXIT);
  load(1, EXIT_APPLICATION);
  t.bkpt(0xab);
  const code = t.bytes();
  if (code.length > name) throw new Error('the program outgrew its room');
  const image = new Uint8Array(casesAddress() + 12 * CASES.length);
  image.set(code);
  image.set([0x3a, 0x74, 0x74, 0], name);
  const view = new DataView(image.buffer);
  CASES.forEach(([x, y, flags], i) => {
    view.setUint32(casesAddress() + 12 * i, x, true);
    view.setUint32(casesAddress() + 12 * i + 4, y, true);
    view.setUint32(casesAddress() + 12 * i + 8, flags, true);
  });
  return image;
}

/** The cases fill the end of the 16 KiB that rp2040js's ROM holds. */
function casesAddress() {
  return 0x4000 - 12 * CASES.length;
}

function runOnQemu(image) {
  const dir = mkdtempSync(join(tmpdir(), 'armv6m-'));
  try {
    const file = join(dir, 'program.bin');
    writeFileSync(file, image);
    return execFileSync(
      'qemu-system-arm',
      ['-machine', 'microbit', '-nographic', '-monitor', 'none', '-serial', 'none', '-semihosting-config', 'enable=on,target=native', '-kernel', file],
      // Half an hour: only a guard against a hang, on a machine however busy.
      { maxBuffer: 64 << 20, timeout: 30 * 60_000 },
    );
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

function runOnRp2040js(image, corrected) {
  const rp2040 = new RP2040();
  rp2040.logger = { debug() {}, info() {}, warn: fatal, error: fatal };
  const core = rp2040.core;
  if (corrected) correctInstructions(core);
  const rom = new Uint8Array(4 * rp2040.bootrom.length);
  rom.set(image);
  rp2040.loadBootrom(new Uint32Array(rom.buffer));
  const output = [];
  let running = true;
  rp2040.onBreak = (code) => {
    assert.equal(code, 0xab, `breakpoint #${code}`);
    const block = (i) => rp2040.readUint32(core.registers[1] + 4 * i);
    switch (core.registers[0]) {
      case SYS_OPEN:
        core.registers[0] = 1;
        break;
      case SYS_WRITE: {
        const [address, length] = [block(1), block(2)];
        output.push(Buffer.from(rp2040.sram.subarray(address - 0x20000000, address - 0x20000000 + length)));
        core.registers[0] = 0;
        break;
      }
      case SYS_EXIT:
        running = false;
        break;
      default:
        throw new Error(`semihosting operation ${core.registers[0]}`);
    }
  };
  core.PC = 0x40;
  for (let steps = 0; running; steps++) {
    assert.ok(steps < 10_000_000, 'the program did not finish');
    core.executeInstruction();
  }
  return Buffer.concat(output);
}

function fatal(component, message) {
  throw new Error(`${component}: ${message}`);
}

const hex = (v) => `0x${(v >>> 0).toString(16).padStart(8, '0')}`;
const flags = (apsr) => ['N', 'Z', 'C', 'V'].map((f, i) => ((apsr >>> (31 - i)) & 1 ? f : f.toLowerCase())).join('');

/** The instructions whose results differ, each with its first differing case. */
function differences(expected, actual) {
  const found = new Map();
  INSTRUCTIONS.forEach(([name], k) => {
    CASES.forEach(([x, y, flagsIn], i) => {
      const at = 12 * (k * CASES.length + i);
      const want = [0, 4, 8].map((o) => expected.readUInt32LE(at + o));
      const got = [0, 4, 8].map((o) => actual.readUInt32LE(at + o));
      if (!found.has(name) && want.some((v, j) => v !== got[j])) {
        found.set(
          name,
          `${name} with r0=${hex(x)} r1=${hex(y)} flags ${flags(flagsIn)}: ` +
            `qemu r0=${hex(want[0])} ${flags(want[2])}, rp2040js r0=${hex(got[0])} ${flags(got[2])}`,
        );
      }
    });
  });
  return found;
}

test('rp2040js with its corrections computes what qemu computes, and needs each correction', () => {
  const image = program();
  const qemu = runOnQemu(image);
  assert.equal(qemu.length, 12 * CASES.length * INSTRUCTIONS.length, 'qemu wrote every result');
  const published = differences(qemu, runOnRp2040js(image, false));
  for (const line of published.values()) console.log(`rp2040js 1.4.1 differs: ${line}`);
  assert.deepEqual(differences(qemu, runOnRp2040js(image, true)), new Map());
  const differing = [...new Set([...published.keys()].map((name) => name.split(' ')[0]))].sort();
  assert.deepEqual(differing, [...CORRECTED].sort(), 'execute.mjs corrects exactly the instructions that differ');
});
