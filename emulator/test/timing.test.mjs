// The Cortex-M0+'s and the RP2040's timings where rp2040js 1.4.1 counts
// others, each against its source: PUSH and POP with LR and PC (the M0+
// TRM, ARM DDI 0484C, 3.3 table 3-1), loads and stores on the APB
// (RP2040 datasheet 2.1.3), the divider's 8 cycles (2.3.1.5), and
// exception entry and return (TRM 3.6.1). Each program runs from SRAM4 on
// core 0 alone (core 1 sleeps in the boot ROM), so no fetch waits for
// flash or for the other core; BKPT #RECORD + n records the core's time
// at its own start, and costs 1 cycle.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { RunError } from '../errors.mjs';
import { CORE0_CODE, FLASH, RECORD, SIO, dividerWait, flashImage, halt, machine, values } from './firmware.mjs';

const record = (t, r) => t.bkpt(RECORD + r);
const CODE = 0x20040000;
const HANDLER = 0x20040800;

/** Core 0 runs `program` from SRAM4, with `handlers` (exception number → code writer) there too. */
function fromSram4(program, handlers = {}) {
  const vectors = {};
  const sram = { [CODE]: (t) => halt(program(t) ?? t) };
  Object.entries(handlers).forEach(([number, write], i) => {
    const at = HANDLER + 0x100 * i;
    vectors[number] = at;
    sram[at] = write;
  });
  const image = flashImage({ programs: { [CORE0_CODE]: (t) => t.ldrConst(0, CODE | 1).bx(0) }, vectors });
  return machine(image, { sram });
}

/** The cycles between consecutive records, less each record's own cycle. */
function gaps(records) {
  return records.slice(1).map((r, i) => r.time - records[i].time - 1);
}

test('PUSH and POP take 1 + N cycles, LR and PC counted in N; a POP that returns 3 + N (TRM table 3-1)', () => {
  const { pico, records } = fromSram4((t) =>
    t
      .inline(record, 0)
      .bl('callee')
      .inline(record, 0)
      .b('done')
      .label('callee')
      .inline(record, 0)
      .push([4, 5], true) // N = 3
      .inline(record, 0)
      .push([6]) // N = 1
      .inline(record, 0)
      .pop([6])
      .inline(record, 0)
      .pop([4, 5], true) // N = 3, and the return
      .label('done'),
  );
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  const [call, push3, push1, pop1] = gaps(records[0].slice(0, 5));
  assert.equal(call, 3, 'BL');
  assert.deepEqual([push3, push1, pop1], [1 + 3, 1 + 1, 1 + 1]);
  const returned = records[0][5].time - records[0][4].time - 1;
  assert.equal(returned, 3 + 3, 'POP {r4, r5, pc}');
});

test('a load from the APB takes 3 cycles and a store 4 (datasheet 2.1.3); the SIO 1, SRAM 2', () => {
  const timerRaw = 0x40054028; // TIMER TIMERAWL
  const scratch = 0x4005800c; // WATCHDOG SCRATCH0
  const { pico, records } = fromSram4((t) =>
    t
      .ldrConst(1, timerRaw)
      .ldrConst(2, scratch)
      .ldrConst(3, SIO)
      .ldrConst(4, 0x20030000)
      .inline(record, 0)
      .ldr(0, 1)
      .inline(record, 0)
      .str(0, 2)
      .inline(record, 0)
      .ldr(0, 3)
      .inline(record, 0)
      .str(0, 3, 0x10) // GPIO_OUT
      .inline(record, 0)
      .ldr(0, 4)
      .inline(record, 0)
      .str(0, 4)
      .inline(record, 0),
  );
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(gaps(records[0]), [3, 4, 1, 1, 2, 2]);
});

test("the divider: an operand costs its store's cycle, READY is clear for 8 cycles, then the result is valid (datasheet 2.3.1.5)", () => {
  const divide = (t) =>
    t
      .ldrConst(7, SIO)
      .movsImm(0, 100)
      .movsImm(1, 7)
      .inline(record, 0)
      .str(0, 7, 0x60) // UDIVIDEND
      .str(1, 7, 0x64) // UDIVISOR
      .inline(record, 0)
      .ldr(0, 7, 0x78) // CSR at once: not ready
      .inline(record, 0);
  const { pico, records } = fromSram4((t) =>
    dividerWait(divide(t))
      .ldr(0, 7, 0x78) // CSR: ready
      .inline(record, 0)
      .ldr(0, 7, 0x74) // REMAINDER
      .inline(record, 0)
      .ldr(0, 7, 0x70) // QUOTIENT
      .inline(record, 0),
  );
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.equal(gaps(records[0])[0], 2, 'two stores to the SIO, a cycle each: no wait for the divider');
  const [, , notReady, ready, remainder, quotient] = values(records, 0);
  assert.equal(notReady & 1, 0, 'READY clear right after the divisor');
  assert.equal(ready & 1, 1, 'READY set 8 cycles on');
  assert.deepEqual([quotient, remainder], [14, 2]);

  // Read too early, the result is undefined on the chip: the run ends.
  const early = fromSram4((t) => divide(t).ldr(0, 7, 0x70));
  assert.throws(() => early.pico.run({ maxSeconds: 1 }), (error) => error instanceof RunError && /QUOTIENT 3 cycles after its operand/.test(error.message));
});

test('exception entry takes 15 cycles to the handler, and the return the frame’s 8 loads beyond its BX (TRM 3.6.1)', () => {
  const irq = 25; // nothing drives it
  const { pico, records } = fromSram4(
    (t) =>
      t
        .ldrConst(1, 0xe000e100)
        .ldrConst(0, 1 << irq)
        .str(0, 1) // ISER: enabled
        .ldrConst(1, 0xe000e200)
        .ldrConst(2, FLASH + 0x100 + 4 * (16 + irq))
        .ldr(2, 2) // the vector, into the XIP cache: its read at the entry then waits for no flash
        .inline(record, 0)
        .str(0, 1) // ISPR: pending, taken after this store
        .inline(record, 0),
    { [16 + irq]: (t) => t.inline(record, 0).bxLr() },
  );
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  const [pend, entered, returned] = records[0].map((r) => r.time);
  assert.equal(entered - pend, 1 + 2 + 15, 'the store to the PPB (2), then the entry');
  assert.equal(returned - entered, 1 + 2 + 8, 'BX LR (2) and the frame unstacked');
});

test('a word of code is fetched once for the two 16-bit instructions in it, and again at a taken branch', () => {
  const { pico, records } = fromSram4((t) => {
    t.inline(record, 0);
    for (let i = 0; i < 32; i++) t.nop();
    t.inline(record, 0).b('there').nop().nop().label('there').inline(record, 0);
  });
  const counts = [];
  const onRecord = pico.onBreakpoint;
  pico.onBreakpoint = (k, code) => {
    counts.push(pico.fabric.accesses[3]); // SRAM4's
    return onRecord(k, code);
  };
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.equal(records[0].length, 3);
  // Between the records: the BKPT's word, then 32 NOPs in 16 words; then the branch, its target's word.
  const [straight, branch] = [counts[1] - counts[0], counts[2] - counts[1]];
  assert.equal(straight, 16, 'sixteen words for 32 NOPs and the record');
  assert.equal(branch, 2, "the branch's own word, then its target's");
  assert.equal(values(records, 0).length, 3);
});
