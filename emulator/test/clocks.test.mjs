// The clock the firmware sets (clocks.mjs) and the regulator it needs
// (vreg.mjs): clk_sys from reset is the ring oscillator's; a firmware that
// sets PLL_SYS to the RP2040's rated 200 MHz (1200 MHz over 6 and 1) runs
// each cycle in 5 ns, the TIMER's microsecond ticking every 200 cycles;
// the rating (the datasheet's current revision) is held: 200 MHz needs
// the core at 1.15 V; the flash's serial clock is clk_sys over the SSI's
// divider, so an XIP miss costs the same cycles at 125 and 200 MHz, and
// the W25Q16JV refuses a serial clock over its rating.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { CORE0_CODE, RECORD, delay, flashImage, halt, machine, values } from './firmware.mjs';
import { ratedHz } from '../clocks.mjs';
import { vselVolts } from '../vreg.mjs';
import { W25Q16JV } from '../flash-chip.mjs';
import { RunError } from '../errors.mjs';

const record = (t, r) => t.bkpt(RECORD + r);

const TIMERAWL = 0x40054028;
const XOSC_CTRL = 0x40024000;
const CLK_REF_CTRL = 0x40008030;
const CLK_SYS_CTRL = 0x4000803c;
const CLK_PERI_CTRL = 0x40008048;
const PLL_SYS = 0x40028000;
const VREG = 0x40064000;
/** VREG's EN with VSEL 1.10 V (its reset value) and 1.15 V. */
const VREG_1_10 = 0xb1;
const VREG_1_15 = 0xc1;

/**
 * The steps of a clock set-up, as the Pico SDK and rp2040-hal take them:
 * the crystal, clk_ref on it, PLL_SYS at 12 MHz × `fbdiv` / `post1` /
 * `post2`, the regulator at `vreg`, then clk_sys and clk_peri from the PLL.
 */
function setClock(t, { fbdiv, post1, post2, vreg }) {
  return t
    .ldrConst(1, XOSC_CTRL)
    .ldrConst(0, (0xfab << 12) | 0xaa0)
    .str(0, 1)
    .ldrConst(1, CLK_REF_CTRL)
    .movsImm(0, 2) // XOSC
    .str(0, 1)
    .ldrConst(1, PLL_SYS)
    .movsImm(0, 1)
    .str(0, 1, 0x00) // CS: REFDIV 1
    .movsImm(0, fbdiv)
    .str(0, 1, 0x08) // FBDIV_INT
    .movsImm(0, 0x08)
    .str(0, 1, 0x04) // PWR: on, but for the post dividers
    .ldrConst(0, (post1 << 16) | (post2 << 12))
    .str(0, 1, 0x0c) // PRIM
    .movsImm(0, 0)
    .str(0, 1, 0x04) // PWR: all on
    .ldrConst(1, VREG)
    .ldrConst(0, vreg)
    .str(0, 1)
    .ldrConst(1, CLK_SYS_CTRL)
    .movsImm(0, 1) // the aux source, PLL_SYS
    .str(0, 1)
    .ldrConst(1, CLK_PERI_CTRL)
    .ldrConst(0, 1 << 11) // enabled, from clk_sys
    .str(0, 1);
}

/** Reads TIMERAWL into r0 and records it (BKPT: the time too). */
const timer = (t) => t.ldrConst(1, TIMERAWL).ldr(0, 1).inline(record, 0);

/** A firmware running `program` from SRAM (so that no flash miss falls between its timings). */
function fromSram(program) {
  const code = 0x20010000;
  const image = flashImage({ programs: { [CORE0_CODE]: (t) => t.ldrConst(0, code | 1).bx(0) } });
  return machine(image, { sram: { [code]: (t) => halt(program(t)) } });
}

/** A firmware: `before` (a clock set-up, or none), then the TIMER read around a loop of `n` turns. */
const timed = (before, n = 20000) => fromSram((t) => timer(delay(timer(before(t)), n)));

test('from reset clk_sys is the ring oscillator, 6.5 MHz: the TIMER counts its cycles at that pace', () => {
  const { pico, records } = timed((t) => t);
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.equal(pico.systemClock.hz, 6.5e6);
  const [before, after] = records[0];
  const micros = after.value - before.value;
  assert.ok(Math.abs(micros - (after.time - before.time) / 6.5) <= 1, `${micros} µs for ${after.time - before.time} cycles`);
});

test('PLL_SYS at 1200 MHz over 6 and 1 with the core at 1.15 V: 200 MHz, a TIMER microsecond every 200 cycles, in the report', () => {
  const { pico, records } = timed((t) => setClock(t, { fbdiv: 100, post1: 6, post2: 1, vreg: VREG_1_15 }));
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.equal(pico.systemClock.hz, 200e6);
  const [before, after] = records[0];
  const cycles = after.time - before.time;
  assert.ok(Math.abs(after.value - before.value - cycles / 200) <= 1, `${after.value - before.value} µs for ${cycles} cycles`);
  const report = pico.clockReport();
  assert.equal(report.sysHz, 200e6);
  assert.equal(report.periHz, 200e6, 'clk_peri follows clk_sys');
  assert.equal(report.flashHz, 100e6, "boot2's divider of 2");
  assert.equal(report.coreVolts, 1.15);
  // The reset's ring oscillator, the crystal's 12 MHz once clk_ref took it, then the PLL's.
  assert.deepEqual(
    report.changes.map(({ hz }) => hz),
    [6.5e6, 12e6, 200e6],
  );
  assert.ok(report.changes.every(({ cycles }, k) => k === 0 || cycles > report.changes[k - 1].cycles));
});

test("125 MHz (1500 MHz over 6 and 2) runs at the reset voltage; a cycle's time follows each epoch exactly", () => {
  const { pico } = timed((t) => setClock(t, { fbdiv: 125, post1: 6, post2: 2, vreg: VREG_1_10 }));
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  const clock = pico.systemClock;
  assert.equal(clock.hz, 125e6);
  const last = clock.epoch;
  assert.ok(Number.isInteger(last.nanos), 'the PLL epoch starts at a whole nanosecond');
  assert.equal(clock.nanosAt(last.cycles + 1000) - clock.nanosAt(last.cycles), 8000);
  assert.equal(clock.cyclesAt(clock.nanosAt(last.cycles + 12345)), last.cycles + 12345);
});

test('200 MHz at the reset voltage, 1.10 V, is outside the rating and ends the run; so does lowering the voltage under it', () => {
  const low = timed((t) => setClock(t, { fbdiv: 100, post1: 6, post2: 1, vreg: VREG_1_10 }));
  assert.throws(
    () => low.pico.run({ maxSeconds: 1 }),
    (error) => error instanceof RunError && /clk_sys at 200 MHz with the core at 1\.10 V: outside the RP2040's rating/.test(error.message),
  );
  const lowered = timed((t) => setClock(t, { fbdiv: 100, post1: 6, post2: 1, vreg: VREG_1_15 }).ldrConst(1, VREG).ldrConst(0, VREG_1_10).str(0, 1));
  assert.throws(() => lowered.pico.run({ maxSeconds: 1 }), /clk_sys at 200 MHz with the core at 1\.10 V/);
  assert.equal(ratedHz(1.1), 133e6);
  assert.equal(ratedHz(1.15), 200e6);
  assert.equal(ratedHz(1.3), 200e6, 'no rating above 200 MHz');
});

test('VREG: EN, VSEL from 0.80 V to 1.30 V in steps of 0.05 V, ROK; switching the regulator off is an error', () => {
  assert.deepEqual([0, 5, 6, 11, 12, 15].map(vselVolts).map((v) => +v.toFixed(2)), [0.8, 0.8, 0.85, 1.1, 1.15, 1.3]);
  const read = (setup) => {
    const image = flashImage({ programs: { [CORE0_CODE]: (t) => halt(setup(t).ldrConst(1, VREG).ldr(0, 1).inline(record, 0)) } });
    const run = machine(image);
    assert.equal(run.pico.run({ maxSeconds: 1 }), 'idle');
    return values(run.records, 0)[0];
  };
  assert.equal(read((t) => t), 0x10b1, 'reset: enabled, 1.10 V, regulating');
  assert.equal(read((t) => t.ldrConst(1, VREG).ldrConst(0, 0xd1).str(0, 1)), 0x10d1);
  const off = machine(flashImage({ programs: { [CORE0_CODE]: (t) => halt(t.ldrConst(1, VREG).movsImm(0, 0xb0).str(0, 1)) } }));
  assert.throws(() => off.pico.run({ maxSeconds: 1 }), /VREG 0xb0: the regulator off/);
});

test("an XIP miss is the line's serial clocks at clk_sys over the SSI's divider: 57 cycles at 125 and at 200 MHz", () => {
  for (const setup of [
    { fbdiv: 125, post1: 6, post2: 2, vreg: VREG_1_10 },
    { fbdiv: 100, post1: 6, post2: 1, vreg: VREG_1_15 },
  ]) {
    const { pico, records } = fromSram((t) => setClock(t, setup).ldrConst(1, 0x10006000).inline(record, 0).ldr(0, 1).inline(record, 0));
    assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
    const [before, after] = records[0];
    assert.equal(after.time - before.time - 3, 57, `at ${pico.systemClock.hz / 1e6} MHz`);
    assert.equal(pico.cacheStatistics().lineReadCycles, 57);
  }
});

test("the W25Q16JV's rating: Read Data (03h) up to 50 MHz, every other instruction and XIP's quad reads up to 133 MHz", () => {
  const chip = new W25Q16JV(new Uint8Array(1024), () => 0);
  const command = (opcode, hz) => {
    chip.serialClockHz = hz;
    chip.select();
    try {
      chip.exchange(opcode);
    } finally {
      chip.command = { opcode: null, bytes: [] };
      chip.deselect();
    }
  };
  command(0x03, 50e6);
  assert.throws(() => command(0x03, 62.5e6), /03h at a 62\.5 MHz serial clock: the chip is rated for 50 MHz/);
  command(0x05, 133e6);
  assert.throws(() => command(0x05, 140e6), /05h at a 140 MHz serial clock: the chip is rated for 133 MHz/);
  chip.serialClockHz = 140e6;
  assert.throws(
    () => chip.read({ instruction: 0xeb, transType: 1, lanes: 4, addressBits: 32, waitClocks: 4, mode: 0xa0 }),
    /ebh at a 140 MHz serial clock/,
  );
});
