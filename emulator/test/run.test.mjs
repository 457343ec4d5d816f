// The runner's command line on small firmwares written here: how a run
// ends (both cores asleep; a fault, an endless loop, a ROM function it
// lacks, no valid boot2), its exit codes, its report, that a failed run
// leaves no picture, and --frames: frames told by the LED, each written.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readdirSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { boot2, CORE0_CODE, elf, flashImage, SIO } from './firmware.mjs';

const RUN = join(dirname(fileURLToPath(import.meta.url)), '..', 'run.mjs');

/** A firmware ELF: boot2 (valid unless `badBoot2`) and `program` at CORE0_CODE, the reset vector. */
function firmware(program, { badBoot2 = false } = {}) {
  return elf(flashImage({ boot2: boot2({ badCrc: badBoot2 }), programs: { [CORE0_CODE]: program } }));
}

function run(elf, ...args) {
  const dir = mkdtempSync(join(tmpdir(), 'pico-run-'));
  try {
    const path = join(dir, 'firmware.elf');
    writeFileSync(path, elf);
    const frames = args.includes('--frames');
    const out = join(dir, frames ? 'f%02d.png' : 'panel.png');
    const result = spawnSync(process.execPath, [RUN, path, '--out', out, ...args], { encoding: 'utf8' });
    const written = readdirSync(dir).filter((name) => name.endsWith('.png')).sort();
    return { status: result.status, stderr: result.stderr, stdout: result.stdout, wrote: existsSync(out), written };
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
  assert.equal(report.cycles.firstFullPanel, null);
  assert.equal(report.cores, 1, 'core 1 stayed in the boot ROM');
  for (const core of report.coreCycles) {
    assert.equal(core.busy + core.waiting, report.cycles.total, `core ${core.core}'s busy and waiting cycles make the run`);
  }
  // The ROM reads boot2 as 32 lines of 03h reads at clk_sys / 6: (8 + 24 + 64) × 6 = 576 cycles each;
  // the rest are boot2's quad continuous reads at clk_sys / 2: (8 + 4 + 16) × 2 + 1 = 57.
  const cache = report.xipCache;
  assert.equal(cache.lineReadCycles, 57);
  assert.equal(cache.stallCycles, 32 * 576 + 57 * (cache.misses - 32));
  assert.equal(cache.accesses, cache.hits + cache.misses);
});

test('what a real Pico would not survive ends the run with exit 1, a message and no picture', () => {
  const cases = [
    [firmware((t) => t.label('here').b('here')), /endless loop in 0x10000400 on core 0/],
    [firmware(sleep, { badBoot2: true }), /no valid boot2/],
    [firmware((t) => t.emit(0xde00)), /undefined instruction \(#0\) at 0x10000400 on core 0/], // udf
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
  // A firmware that sets no clock runs on the ring oscillator, 6.5 MHz.
  assert.match(
    result.stderr,
    /still running after 0\.\d+ s of the Pico's time \(\d+ cycles, clk_sys 6\.5 MHz now\), past its budget of 0\.01 s, in 0x1000040. on core 0/,
  );
});

test('--display ssd1306 wires the SSD1306 module alone: a firmware that never talks to it leaves it dark, 128x64', () => {
  const result = run(firmware(sleep), '--json', '--display', 'ssd1306');
  assert.equal(result.status, 0, result.stderr);
  const report = JSON.parse(result.stdout);
  assert.deepEqual([report.display, report.panel], ['SSD1306', '128x64']);
  assert.match(report.dark, /display is off/);
  assert.equal(report.cycles.render, null, 'the LED never lit');
});

/** Starts the watchdog with `micros` µs (LOAD is twice that: RP2040-E1), then counts in r0 for ever. */
const wedged = (micros) => (t) =>
  t
    .ldrConst(1, 0x40058000) // WATCHDOG
    .ldrConst(2, 2 * micros)
    .str(2, 1, 4) // LOAD
    .ldrConst(2, 1 << 30)
    .str(2, 1, 0) // CTRL: ENABLE
    .label('loop')
    .addsImm(0, 1)
    .b('loop');

test('a firmware whose watchdog runs out is reset: the run ends saying when', () => {
  const when = (micros) => {
    const result = run(firmware(wedged(micros)), '--max-seconds', '1');
    assert.equal(result.status, 1, result.stderr);
    assert.ok(!result.wrote);
    const [, seconds] = result.stderr.match(/the watchdog ran out at (\d+\.\d+) s: the board resets \(0x1000040. on core 0\)/) ?? [];
    assert.ok(seconds, result.stderr);
    return Number(seconds);
  };
  // The same start (boot2 and the set-up at the ring oscillator's pace), 1 ms more.
  assert.ok(Math.abs(when(2000) - when(1000) - 0.001) < 2e-6);
});

test('served as a serial board, a firmware whose watchdog runs out starts again', async () => {
  const dir = mkdtempSync(join(tmpdir(), 'pico-run-'));
  const path = join(dir, 'firmware.elf');
  writeFileSync(path, firmware(wedged(1000)));
  const serve = spawn(process.execPath, [RUN, path, '--serial'], { stdio: ['pipe', 'pipe', 'pipe'] });
  try {
    let stderr = '';
    const restarts = () => (stderr.match(/the watchdog ran out at .*: the board resets \(.*\); it starts again/g) ?? []).length;
    await new Promise((resolve, reject) => {
      serve.stderr.on('data', (chunk) => {
        stderr += chunk;
        if (restarts() >= 2) resolve();
      });
      serve.on('exit', (code) => reject(new Error(`the serve ended (exit ${code}): ${stderr}`)));
    });
    // A command's answer: the new machine's clock.
    const answer = await new Promise((resolve) => {
      let stdout = '';
      serve.stdout.on('data', (chunk) => {
        stdout += chunk;
        const line = stdout.split('\n').find((l) => l.startsWith('times '));
        if (line) resolve(line);
      });
      serve.stdin.write('times\n');
    });
    assert.match(answer, /^times - - \d+ (\d+|-) [01]$/);
  } finally {
    serve.stdin.end();
    rmSync(dir, { recursive: true, force: true });
  }
});

test('bad arguments exit 2 with the usage', () => {
  const cases = [[], ['a.elf', 'b.elf'], ['a.elf', '--panel', '240'], ['a.elf', '--out', 'x.bmp'], ['a.elf', '--max-seconds', '0'], ['a.elf', '--display', 'lcd']];
  for (const args of cases) {
    const result = spawnSync(process.execPath, [RUN, ...args], { encoding: 'utf8' });
    assert.equal(result.status, 2, `${args.join(' ')}: ${result.stderr}`);
    assert.match(result.stderr, /usage: node run\.mjs ELF/);
  }
});

const IO_BANK0_GPIO25_CTRL = 0x400140cc;
const FUNCSEL_SIO = 5;
const GPIO_OUT_SET = 0x14;
const GPIO_OUT_CLR = 0x18;
const GPIO_OE_SET = 0x24;

/** Lights the LED (GP25) and puts it out `times` times, about 3,000 cycles lit and 9,000 dark, then sleeps. */
function blinking(times) {
  return firmware((t) => {
    t.ldrConst(3, IO_BANK0_GPIO25_CTRL).movsImm(1, FUNCSEL_SIO).str(1, 3);
    t.ldrConst(3, SIO).ldrConst(2, 1 << 25).str(2, 3, GPIO_OE_SET).movsImm(4, times);
    const wait = (label, cycles) => t.ldrConst(0, cycles / 3).label(label).subsImm(0, 1).bcc('ne', label); // subs 1 + bne 2
    t.label('frame').str(2, 3, GPIO_OUT_SET);
    wait('lit', 3000);
    t.str(2, 3, GPIO_OUT_CLR);
    wait('dark', 9000);
    t.subsImm(4, 1).bcc('ne', 'frame').wfi().pool();
  });
}

test('--frames N: each time the LED goes out a frame is drawn, written, and timed; the run stops after N', () => {
  const result = run(blinking(3), '--frames', '2', '--json');
  assert.equal(result.status, 0, result.stderr);
  assert.deepEqual(result.written, ['f00.png', 'f01.png']);
  const { frames } = JSON.parse(result.stdout);
  assert.deepEqual(
    frames.map(({ index, out }) => [index, out.slice(-7)]),
    [
      [0, 'f00.png'],
      [1, 'f01.png'],
    ],
  );
  // The first frame runs from the LED lit; the next from the first's end, its dark stretch included
  // (within what the loops' few flash misses add).
  const [first, second] = frames;
  const near = (cycles, expected) => Math.abs(cycles - expected) < 300;
  assert.ok(near(first.lit, 3000) && first.cycles === first.lit, JSON.stringify(first));
  assert.ok(near(second.lit, 3000) && near(second.cycles, 12000), JSON.stringify(second));
  assert.equal(second.busy[0], second.cycles, 'core 0 never slept');
  assert.equal(second.busy[1], 0, 'core 1 stayed asleep in the ROM');
});

test('--profile-from K charges the frames from K on, and wants --profile and --frames', () => {
  const whole = run(blinking(3), '--frames', '3', '--profile', '5', '--json');
  const later = run(blinking(3), '--frames', '3', '--profile', '5', '--profile-from', '1', '--json');
  assert.equal(whole.status, 0, whole.stderr);
  assert.equal(later.status, 0, later.stderr);
  const charged = (report) => report.profile.reduce((sum, { cycles }) => sum + cycles, 0);
  const [reportWhole, reportLater] = [JSON.parse(whole.stdout), JSON.parse(later.stdout)];
  const [, second, third] = reportLater.frames;
  // Frames 1 and 2, within a sample (256 instructions, a loop pass of 3 cycles each).
  assert.equal(reportLater.profileFrom, 1);
  assert.ok(Math.abs(charged(reportLater) - (second.cycles + third.cycles)) < 800, `${charged(reportLater)}`);
  assert.ok(charged(reportWhole) > charged(reportLater) + reportLater.frames[0].cycles - 800, `${charged(reportWhole)}`);
  for (const args of [['--profile-from', '1'], ['--frames', '3', '--profile-from', '1'], ['--frames', '3', '--profile', '5', '--profile-from', '3']]) {
    const result = spawnSync(process.execPath, [RUN, 'a.elf', ...args], { encoding: 'utf8' });
    assert.equal(result.status, 2, `${args.join(' ')}: ${result.stderr}`);
    assert.match(result.stderr, /--profile-from/);
  }
});

test('--frames N with fewer drawn, or a pattern without a number, fails and writes no frame', () => {
  const fewer = run(blinking(3), '--frames', '5');
  assert.equal(fewer.status, 1, fewer.stderr);
  assert.match(fewer.stderr, /went to sleep after drawing 3 of 5 frames/);
  assert.deepEqual(fewer.written, []);
  for (const args of [['--frames', '0'], ['--frames', '2', '--out', 'panel.png'], ['--frames', '2', '--out', 'f%3d%d.png']]) {
    const result = spawnSync(process.execPath, [RUN, 'a.elf', ...args], { encoding: 'utf8' });
    assert.equal(result.status, 2, `${args.join(' ')}: ${result.stderr}`);
    assert.match(result.stderr, /usage: node run\.mjs ELF/);
  }
});
