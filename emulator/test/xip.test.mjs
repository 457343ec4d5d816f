// The flash as a real Pico has it: the miss cost's formula (xip-timing.mjs)
// against the SSI set-ups that make it, then on the machine: a miss stalls
// the core for exactly that, a hit for nothing; the four aliases, the two
// ways, the cache disabled (its SRAM at 0x15000000), FLUSH and the
// counters (the datasheet's own example), the QSPI serving one miss at a
// time, and boot2's dealings with the flash chip (QE, continuous read).

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { lineTransferCycles } from '../xip-timing.mjs';
import { RunError } from '../errors.mjs';
import { BOOT2_BASE } from '../bootrom.mjs';
import { Thumb } from '../thumb.mjs';
import {
  CORE0_CODE,
  FLASH,
  RECORD,
  XIP_CTRL,
  boot2,
  boot2Image,
  core1Started,
  fifoPop,
  fifoPush,
  flashImage,
  halt,
  machine,
  spawnCore1,
  values,
} from './firmware.mjs';

const record = (t, r) => t.bkpt(RECORD + r);
/** rp2040-boot2's W25Q080 set-up: quad, 32-bit frames, EEPROM read; no instruction, 32 address-and-mode bits, 4 wait clocks, 2C2A. */
const W25Q080 = {
  ctrlr0: (2 << 21) | (31 << 16) | (3 << 8),
  baudr: 2,
  spiCtrlr0: (0xa0 << 24) | (4 << 11) | (8 << 2) | 2,
  rxSampleDelay: 1,
};

test("a miss costs the line's serial clocks times the divider, plus the sample delay", () => {
  // (no instruction + 32/4 address and mode + 4 wait + 64/4 data) × 2 + 1
  assert.equal(lineTransferCycles(W25Q080), 57);
  assert.equal(lineTransferCycles({ ...W25Q080, baudr: 4 }), 28 * 4 + 1, 'the divider scales the clocks');
  assert.equal(lineTransferCycles({ ...W25Q080, baudr: 5 }), 28 * 4 + 1, "SCKDV's bit 0 is ignored");
  assert.equal(lineTransferCycles({ ...W25Q080, spiCtrlr0: (0xa0 << 24) | (6 << 11) | (8 << 2) | 2 }), 30 * 2 + 1, 'each wait clock');
  assert.equal(lineTransferCycles({ ...W25Q080, rxSampleDelay: 0 }), 56);
  // EBh every time: an 8-bit instruction on one lane (1C2A).
  assert.equal(lineTransferCycles({ ...W25Q080, spiCtrlr0: (0xeb << 24) | (4 << 11) | (2 << 8) | (8 << 2) | 1 }), 36 * 2 + 1);
  // The ROM's 03h reads: standard SPI, 8 + 24 + 64 clocks at clk_sys / 6.
  const standard = { ctrlr0: (31 << 16) | (3 << 8), baudr: 6, spiCtrlr0: (0x03 << 24) | (2 << 8) | (6 << 2), rxSampleDelay: 0 };
  assert.equal(lineTransferCycles(standard), 96 * 6);
  // Dual I/O: the address over two lanes, the data too.
  assert.equal(lineTransferCycles({ ...standard, ctrlr0: (1 << 21) | (31 << 16) | (3 << 8), spiCtrlr0: (0xbb << 24) | (2 << 8) | (8 << 2) | 1 }), (8 + 16 + 32) * 6);
  for (const bad of [{ ...W25Q080, baudr: 0 }, { ...W25Q080, ctrlr0: 3 << 21 }, { ...W25Q080, spiCtrlr0: W25Q080.spiCtrlr0 | (1 << 16) }]) {
    assert.throws(() => lineTransferCycles(bad), RunError);
  }
});

/** Core 0 runs `program` from SRAM (so its fetches leave the cache alone), after a boot2 made with `options`. */
function fromSram(program, { boot2Options = {}, ...options } = {}) {
  const code = 0x20010000;
  const image = flashImage({
    boot2: boot2(boot2Options),
    programs: { [CORE0_CODE]: (t) => t.ldrConst(0, code | 1).bx(0) },
  });
  for (let i = 0x4000; i < image.length; i += 4) new DataView(image.buffer).setUint32(i, 0xc0de0000 + i, true);
  return machine(image, { sram: { [code]: (t) => halt(program(t) ?? t) }, ...options });
}

/** Loads the word at `address` into r0, recording the time before and the value after. */
const timedLoad = (t, address) => t.ldrConst(1, address).inline(record, 0).ldr(0, 1).inline(record, 0);

/** The cycles each timed load took beyond the bkpt (1) and the load (2), and the values loaded. */
function stalls(records) {
  const out = [];
  for (let i = 0; i + 1 < records.length; i += 2) out.push(records[i + 1].time - records[i].time - 3);
  return out;
}

test('on the machine: a miss stalls the core for the line read, a hit and the rest of the line cost nothing', () => {
  for (const [boot2Options, miss] of [[{}, 57], [{ divider: 4 }, 113]]) {
    const { pico, records } = fromSram((t) => timedLoad(timedLoad(timedLoad(t, FLASH + 0x4000), FLASH + 0x4004), FLASH + 0x4008), { boot2Options });
    assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
    assert.deepEqual(stalls(records[0]), [miss, 0, miss], `boot2 ${JSON.stringify(boot2Options)}`);
    assert.equal(records[0][1].value, 0xc0de4000);
  }
});

test('the aliases: 0x11 does not allocate, 0x12 always reads and allocates, 0x13 always reads; a store to 0x10 invalidates', () => {
  const line = 0x4040;
  const { pico, records } = fromSram((t) => {
    for (const alias of [0x13, 0x13, 0x11, 0x10, 0x11, 0x12, 0x10]) timedLoad(t, (alias << 24) + line);
    t.ldrConst(1, FLASH + line).movsImm(0, 0).str(0, 1); // deallocates; writes nothing
    timedLoad(t, FLASH + line);
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(stalls(records[0]), [57, 57, 57, 57, 0, 57, 0, 57]);
  assert.ok(values(records, 0).every((v, i) => i % 2 === 0 || v === 0xc0de0000 + line), 'the flash kept its word');
});

test('a store to the non-allocating aliases is a bus fault while ERR_BADWRITE is set', () => {
  const { pico } = fromSram((t) => t.ldrConst(1, 0x11004000).str(0, 1));
  assert.throws(() => pico.run({ maxSeconds: 1 }), /store to the flash alias 0x11004000 is a bus fault \(XIP_CTRL.ERR_BADWRITE\)/);
});

test('two ways: two lines of one set stay cached together; a third replaces one of them', () => {
  const [a, b, c] = [0x4000, 0x6000, 0x8000].map((offset) => FLASH + offset); // 8 KiB apart: one set
  const { pico, records } = fromSram((t) => {
    for (const address of [a, b, a, b, c, c]) timedLoad(t, address);
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(stalls(records[0]), [57, 57, 0, 0, 57, 0]);
  const set = (0x4000 >>> 3) & 1023;
  const tags = [...pico.xip.tags.subarray(2 * set, 2 * set + 2)].sort();
  assert.ok(tags.includes(0x8000 >>> 13) && (tags.includes(0x4000 >>> 13) !== tags.includes(0x6000 >>> 13)), `set ${set} holds ${tags}`);
});

test("CTRL.EN clear: every read goes to the flash, and the cache's 16 KiB are SRAM at 0x15000000", () => {
  const { pico, records } = fromSram((t) => {
    t.ldrConst(2, XIP_CTRL).movsImm(0, 2).str(0, 2); // EN clear, ERR_BADWRITE kept
    timedLoad(timedLoad(t, FLASH + 0x4000), FLASH + 0x4000);
    t.ldrConst(1, 0x15003ffc).ldrConst(0, 0x5a5a1234).str(0, 1).movsImm(0, 0).ldr(0, 1).inline(record, 0);
    t.ldrConst(1, 0x15ff3ffc).ldr(0, 1).inline(record, 0); // mirrored through the segment
    t.movsImm(0, 3).str(0, 2); // enabled again: the SRAM alias is a bus error
    t.ldrConst(1, 0x15000000).ldr(0, 1);
  });
  assert.throws(() => pico.run({ maxSeconds: 1 }), /0x15000000 \(the XIP cache as SRAM\) is a bus error while the cache is enabled/);
  assert.deepEqual(stalls(records[0].slice(0, 4)), [57, 57]);
  assert.deepEqual(values(records, 0).slice(4), [0x5a5a1234, 0x5a5a1234]);
});

test("FLUSH clears every line and takes 1024 cycles; the counters as in the datasheet's example", () => {
  const { pico, records } = fromSram((t) => {
    t.ldrConst(2, XIP_CTRL);
    timedLoad(t, FLASH + 0x4000);
    // Flush, and wait for it by reading FLUSH.
    t.movsImm(0, 1).str(0, 2, 4).inline(record, 0).ldr(0, 2, 4).inline(record, 0);
    t.ldr(0, 2, 8).inline(record, 0); // STAT: FLUSH_READY, FIFO_EMPTY
    t.movsImm(0, 1).str(0, 2, 0x10).str(0, 2, 0x0c); // clear CTR_ACC and CTR_HIT
    timedLoad(t, FLASH + 0x4000);
    t.ldr(0, 2, 0x0c).inline(record, 0).ldr(0, 2, 0x10).inline(record, 0);
    timedLoad(t, FLASH + 0x4000);
    t.ldr(0, 2, 0x0c).inline(record, 0).ldr(0, 2, 0x10).inline(record, 0);
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  const r = records[0];
  // The store (2 cycles) started the flush; the read of FLUSH ends (2 cycles) as the flush does, 1024 cycles on.
  assert.equal(r[3].time - 2 - (r[2].time - 2), 1024, 'the read of FLUSH waited for the flush');
  assert.equal(r[4].value, 3);
  assert.equal(r[6].time - r[5].time - 3, 57, 'the line was gone');
  assert.deepEqual([r[7].value, r[8].value], [0, 1], 'first access: a miss');
  assert.deepEqual([r[11].value, r[12].value], [1, 2], 'second access: a hit');
});

test('the QSPI serves one miss at a time: a core missing while the other core waits for its line waits for it too', () => {
  // Each core's code in a bank of its own (SRAM4, SRAM5): their fetches never meet on the bus fabric.
  const image = flashImage({
    programs: {
      [CORE0_CODE]: (t) => {
        spawnCore1(t, { entry: 0x20041000, stack: 0x20020000 });
        t.ldrConst(0, 0x20040001).bx(0);
      },
    },
  });
  const { pico, records } = machine(image, {
    sram: {
      0x20040000: (t) => halt(timedLoad(fifoPush(t.ldrConst(7, 0xd0000000), 0), 0x13004000)),
      0x20041000: (t) => halt(timedLoad(fifoPop(core1Started(t), 0), 0x13005000)),
    },
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  const [before0, after0] = records[0];
  const [before1, after1] = records[1];
  assert.ok(before1.time > before0.time && before1.time - before0.time < 57, 'core 1 misses while core 0 waits');
  assert.equal(after0.time - before0.time, 3 + 57);
  assert.equal(after1.time - after0.time, 57, "core 1's line comes right after core 0's");
  assert.equal(pico.xip.stalls[1], after1.time - before1.time - 3);
});

test('boot2 with a flash whose QE is clear: it writes the status register and waits out tW (10 ms) before quad reads', () => {
  const { pico, records } = machine(flashImage({ programs: { [CORE0_CODE]: (t) => halt(record(t, 0)) } }), { flashStatusRegister2: 0 });
  assert.equal(pico.run({ maxSeconds: 2 }), 'idle');
  const started = pico.systemClock.nanosAt(records[0][0].time) / 1e9;
  assert.ok(started > 0.01, `the firmware started after ${started} s`);
  assert.equal(pico.flashChip.statusRegister(2), 2, 'QE set');
});

test('the flash chip refuses what it does not take: wrong wait clocks, XIP with the SSI off', () => {
  const wrongWait = machine(flashImage({ boot2: boot2({ waitClocks: 6 }), programs: { [CORE0_CODE]: halt } }));
  assert.throws(() => wrongWait.pico.run({ maxSeconds: 1 }), /EBh takes the address and mode on 4 lanes \(32 bits\) and 4 wait clocks; the SSI sent 4-lane data, 32 address bits, 6 wait clocks/);
  const ssiOff = boot2Image(new Thumb(BOOT2_BASE).ldrConst(3, 0x18000000).movsImm(1, 0).str(1, 3, 8).ldrConst(0, FLASH + 0x100).ldr(1, 0, 4).bx(1));
  const off = machine(flashImage({ boot2: ssiOff, programs: { [CORE0_CODE]: halt } }));
  assert.throws(() => off.pico.run({ maxSeconds: 1 }), /an XIP read with the SSI disabled \(SSIENR 0\)/);
});
