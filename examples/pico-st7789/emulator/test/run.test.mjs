// The runner's command line on small firmwares written here: how a run
// ends (the core asleep; a fault, an endless loop, a ROM function it lacks,
// no valid boot2), its exit codes, and that a failed run leaves no picture.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { Thumb } from '../thumb.mjs';

const RUN = join(dirname(fileURLToPath(import.meta.url)), '..', 'run.mjs');
const FLASH = 0x10000000;

/** The boot ROM's check of boot2: CRC-32/MPEG-2 of its first 252 bytes. */
function crc32Mpeg2(bytes) {
  let crc = 0xffffffff;
  for (const byte of bytes) {
    crc ^= byte << 24;
    for (let bit = 0; bit < 8; bit++) crc = crc & 0x80000000 ? (crc << 1) ^ 0x04c11db7 : crc << 1;
  }
  return crc >>> 0;
}

/**
 * A firmware ELF: boot2 (valid unless `badBoot2`), a vector table at
 * 0x10000100 and `program` (a function of a Thumb assembler) at 0x10000200.
 */
function firmware(program, { badBoot2 = false } = {}) {
  const image = new Uint8Array(0x400);
  const view = new DataView(image.buffer);
  view.setUint32(252, crc32Mpeg2(image.subarray(0, 252)) ^ (badBoot2 ? 1 : 0), true);
  view.setUint32(0x100, 0x20042000, true);
  view.setUint32(0x104, (FLASH + 0x200) | 1, true);
  const code = new Thumb(FLASH + 0x200);
  program(code);
  image.set(code.bytes(), 0x200);

  // ELF32, little-endian, ARM, one PT_LOAD segment of the whole image.
  const elf = Buffer.alloc(52 + 32 + image.length);
  elf.set([0x7f, 0x45, 0x4c, 0x46, 1, 1, 1], 0);
  elf.writeUInt16LE(2, 16); // executable
  elf.writeUInt16LE(40, 18); // ARM
  elf.writeUInt32LE(1, 20);
  elf.writeUInt32LE(FLASH + 0x201, 24);
  elf.writeUInt32LE(52, 28); // program headers
  elf.writeUInt16LE(52, 40);
  elf.writeUInt16LE(32, 42);
  elf.writeUInt16LE(1, 44);
  elf.writeUInt16LE(40, 46);
  const header = 52;
  elf.writeUInt32LE(1, header); // PT_LOAD
  elf.writeUInt32LE(84, header + 4);
  elf.writeUInt32LE(FLASH, header + 8);
  elf.writeUInt32LE(FLASH, header + 12);
  elf.writeUInt32LE(image.length, header + 16);
  elf.writeUInt32LE(image.length, header + 20);
  elf.set(image, 84);
  return elf;
}

function run(elf, ...args) {
  const dir = mkdtempSync(join(tmpdir(), 'pico-run-'));
  try {
    const path = join(dir, 'firmware.elf');
    writeFileSync(path, elf);
    const out = join(dir, 'panel.png');
    const result = spawnSync(process.execPath, [RUN, path, '--out', out, ...args], { encoding: 'utf8' });
    return { status: result.status, stderr: result.stderr, stdout: result.stdout, wrote: existsSync(out) };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

const sleep = (t) => t.emit(0xbf30); // wfi, with nothing to wake the core

test('a firmware that sleeps ends the run: exit 0, the picture written, dark when the panel never woke', () => {
  const result = run(firmware(sleep), '--json');
  assert.equal(result.status, 0, result.stderr);
  assert.ok(result.wrote);
  const report = JSON.parse(result.stdout);
  assert.match(report.dark, /asleep/);
  assert.equal(report.cycles.startUp, null, 'the backlight never came on');
});

test('what a real Pico would not survive ends the run with exit 1, a message and no picture', () => {
  const cases = [
    [firmware((t) => t.label('here').b('here')), /endless loop in 0x10000200/],
    [firmware(sleep, { badBoot2: true }), /no valid boot2/],
    [firmware((t) => t.emit(0xde00)), /undefined instruction \(#0\) at 0x10000200/], // udf
    // rom_func_lookup(*0x14, 'RE'): flash_range_erase, which the stand-in lacks.
    [
      firmware((t) =>
        t.movsImm(2, 0x14).ldrh(0, 2).ldrh(3, 2, 4).movsImm(1, 0x45).lslsImm(1, 1, 8).addsImm(1, 0x52).emit(0x4798), // blx r3
      ),
      /boot ROM function 'RE', which the runner's ROM does not stand in for/,
    ],
    [Buffer.from('not an ELF'), /not an ELF file/],
  ];
  for (const [elf, message] of cases) {
    const result = run(elf, '--max-seconds', '1');
    assert.equal(result.status, 1, result.stderr);
    assert.match(result.stderr, message);
    assert.ok(!result.wrote, `no picture after: ${result.stderr}`);
  }
});

test('a run out of time says where it was', () => {
  // A loop that is not a branch to itself: it ends only by the budget.
  const result = run(firmware((t) => t.label('loop').addsImm(0, 1).b('loop')), '--max-seconds', '0.01');
  assert.equal(result.status, 1);
  assert.match(result.stderr, /still running after 1250000 cycles \(0\.01 s at 125 MHz\), in 0x1000020/);
});

test('bad arguments exit 2 with the usage', () => {
  for (const args of [[], ['a.elf', 'b.elf'], ['a.elf', '--panel', '240'], ['a.elf', '--out', 'x.bmp'], ['a.elf', '--max-seconds', '0']]) {
    const result = spawnSync(process.execPath, [RUN, ...args], { encoding: 'utf8' });
    assert.equal(result.status, 2, `${args.join(' ')}: ${result.stderr}`);
    assert.match(result.stderr, /usage: node run\.mjs ELF/);
  }
});
