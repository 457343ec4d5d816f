// The machine's run loop: a run in slices ends exactly as a run in one go
// (what a later serial link will drive it by), 'idle' when both cores sleep
// with nothing scheduled, a sleeping core woken by its SysTick (which
// rp2040js pends without waking anyone), and each core's own interpolators.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { CORE0_CODE, FLASH, RECORD, SIO, core1Started, delay, fifoPop, fifoPush, flashImage, halt, machine, spawnCore1, values } from './firmware.mjs';

const record = (t, r) => t.bkpt(RECORD + r);

test('a run in slices ends as a run in one go, and returns idle when both cores sleep with nothing scheduled', () => {
  const image = flashImage({ programs: { [CORE0_CODE]: (t) => halt(record(delay(t, 20000), 0)) } });
  const whole = machine(image);
  assert.equal(whole.pico.run(), 'idle');
  const sliced = machine(image);
  let slices = 0;
  while (sliced.pico.run({ until: sliced.pico.time + 1000 }) === 'until') slices++;
  assert.ok(slices > 50, `${slices} slices`);
  assert.equal(sliced.pico.time, whole.pico.time);
  assert.deepEqual(sliced.records, whole.records);
  assert.deepEqual(sliced.pico.coreCycles(), whole.pico.coreCycles());
  assert.deepEqual(sliced.pico.cacheStatistics(), whole.pico.cacheStatistics());
});

test('SysTick wakes a core sleeping in WFI and takes its exception', () => {
  const handler = FLASH + 0x2000;
  const image = flashImage({
    vectors: { 15: handler },
    programs: {
      [CORE0_CODE]: (t) => {
        t.ldrConst(1, 0xe000e010)
          .ldrConst(0, 1000)
          .str(0, 1, 4) // RVR; the counter starts from its reset value, 0xffffff
          .movsImm(0, 7)
          .str(0, 1) // CSR: enabled, interrupting, on the processor clock
          .wfi();
        halt(record(t, 0));
      },
      [handler]: (t) => t.movsImm(0, 0x5c).inline(record, 0).ldrConst(1, 0xe000e010).movsImm(0, 0).str(0, 1).bxLr(),
    },
  });
  const { pico, records } = machine(image);
  assert.equal(pico.run({ maxSeconds: 20 }), 'idle');
  assert.equal(values(records, 0)[0], 0x5c, 'the handler ran');
  assert.ok(records[0][0].time > 0xffffff, 'when the counter ran out, the core asleep');
  assert.equal(records[0].length, 2, 'then the core went on after its WFI');
});

test('each core has its own interpolators', () => {
  const accum0 = 0x80;
  const image = flashImage({
    programs: {
      [CORE0_CODE]: (t) => {
        spawnCore1(t, { entry: FLASH + 0x1000, stack: 0x20020000 });
        t.ldrConst(6, SIO + accum0).movsImm(0, 5).str(0, 6);
        fifoPush(t, 0);
        fifoPop(t, 0);
        halt(t.ldr(0, 6).inline(record, 0));
      },
      [FLASH + 0x1000]: (t) => {
        core1Started(t);
        fifoPop(t, 0);
        t.ldrConst(6, SIO + accum0).movsImm(0, 7).str(0, 6);
        fifoPush(t, 0);
        halt(t.ldr(0, 6).inline(record, 0));
      },
    },
  });
  const { pico, records } = machine(image);
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual([values(records, 0).at(-1), values(records, 1)[0]], [5, 7]);
});

test('a core asleep with PRIMASK set wakes on a pending interrupt, which is taken only once PRIMASK clears', () => {
  const handler = FLASH + 0x2000;
  const image = flashImage({
    vectors: { 15: handler },
    programs: {
      [CORE0_CODE]: (t) => {
        t.cpsid()
          .ldrConst(1, 0xe000e010)
          .ldrConst(0, 1000)
          .str(0, 1, 4) // RVR
          .movsImm(0, 7)
          .str(0, 1) // CSR: enabled, interrupting, on the processor clock
          .wfi()
          .movsImm(0, 1)
          .inline(record, 0) // awake, the handler not yet run
          .cpsie()
          .movsImm(0, 3)
          .inline(record, 0); // after the handler
        halt(t);
      },
      [handler]: (t) => t.movsImm(0, 2).inline(record, 0).ldrConst(1, 0xe000e010).movsImm(0, 0).str(0, 1).bxLr(),
    },
  });
  const { pico, records } = machine(image);
  assert.equal(pico.run({ maxSeconds: 20 }), 'idle');
  assert.deepEqual(values(records, 0), [1, 2, 3], 'woken inside the mask, the handler ran at CPSIE');
});

test('an interrupt pended by software (NVIC ISPR) with its line low is taken once', () => {
  const handler = FLASH + 0x2000;
  const irq = 25; // nothing drives it
  const image = flashImage({
    vectors: { [16 + irq]: handler },
    programs: {
      [CORE0_CODE]: (t) => {
        t.ldrConst(1, 0xe000e100)
          .ldrConst(0, 1 << irq)
          .str(0, 1) // ISER: enabled
          .ldrConst(1, 0xe000e200)
          .str(0, 1) // ISPR: pending
          .movsImm(0, 2)
          .inline(record, 0);
        halt(t);
      },
      [handler]: (t) => t.movsImm(0, 1).inline(record, 0).bxLr(),
    },
  });
  const { pico, records } = machine(image);
  assert.equal(pico.run({ maxSeconds: 2 }), 'idle');
  assert.deepEqual(values(records, 0), [1, 2], 'the handler once, then the program');
});

test('a profile charges each function the cycles spent in it', () => {
  // Core 0 spins 20,000 times in one function, then 60,000 in another.
  const second = CORE0_CODE + 0x200;
  const image = flashImage({
    programs: {
      [CORE0_CODE]: (t) => delay(t, 20000).ldrConst(1, second | 1).blx(1),
      [second]: (t) => halt(delay(t, 60000)),
    },
  });
  const functions = [
    { name: '_ZN4demo5first17h0123456789abcdefE', address: CORE0_CODE, size: 0x100 },
    { name: '_ZN4demo6second17h0123456789abcdefE', address: second, size: 0x100 },
  ];
  const { pico } = machine(image, { functions });
  pico.startProfile();
  assert.equal(pico.run(), 'idle');
  const [most, next] = pico.profileReport(2);
  assert.deepEqual([most.name, next.name], ['demo::second', 'demo::first']);
  // A pass of the loop is SUBS and a taken branch, 3 cycles; a sample
  // charges the cycles since the one before, so the first function also
  // takes the boot's last stretch (256 instructions, some from flash).
  assert.ok(Math.abs(most.cycles - 3 * 60000) < 1000, `${most.cycles}`);
  assert.ok(next.cycles >= 3 * 20000 && next.cycles < 3 * 20000 + 8000, `${next.cycles}`);
});

test('a profile charges no function the cycles a core slept', () => {
  // Core 0 sleeps in WFI until SysTick's count from 0xffffff runs out
  // (16.8 M cycles), then spins 60,000 times in another function.
  const second = CORE0_CODE + 0x200;
  const handler = FLASH + 0x2000;
  const image = flashImage({
    vectors: { 15: handler },
    programs: {
      [CORE0_CODE]: (t) => {
        t.ldrConst(1, 0xe000e010).ldrConst(0, 1000).str(0, 1, 4).movsImm(0, 7).str(0, 1).wfi();
        t.ldrConst(1, second | 1).blx(1);
      },
      [second]: (t) => halt(delay(t, 60000)),
      [handler]: (t) => t.ldrConst(1, 0xe000e010).movsImm(0, 0).str(0, 1).bxLr(),
    },
  });
  const functions = [
    { name: '_ZN4demo5first17h0123456789abcdefE', address: CORE0_CODE, size: 0x100 },
    { name: '_ZN4demo6second17h0123456789abcdefE', address: second, size: 0x100 },
  ];
  const { pico } = machine(image, { functions });
  pico.startProfile();
  assert.equal(pico.run({ maxSeconds: 20 }), 'idle');
  assert.ok(pico.coreCycles()[0].waiting > 0xffffff - 1000, 'core 0 slept');
  const charged = new Map(pico.profileReport(4).map(({ name, cycles }) => [name, cycles]));
  // As above, a sample's stretch may reach back over the call.
  const spun = charged.get('demo::second');
  assert.ok(spun >= 3 * 60000 && spun < 3 * 60000 + 8000, `${spun}`);
  assert.ok((charged.get('demo::first') ?? 0) < 8000, `the sleep charged to demo::first: ${charged.get('demo::first')}`);
});
