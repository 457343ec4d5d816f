// The second core against the RP2040 datasheet: the boot ROM's wait for
// launch (2.8.2) driven by rp2040-hal 0.12's spawn sequence and word by
// word, the inter-core FIFOs and their IRQ (2.3.1.5), the spinlocks, CPUID
// and the per-core divider (2.3.1), SEV and WFE/WFI between the cores, the
// lockstep by cycles, rp2040-hal's MPU stack guard, and a fault on core 1
// named as core 1's. Each program is Thumb, assembled here.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import {
  CORE0_CODE,
  FIFO_RD,
  FIFO_ST,
  FIFO_WR,
  FLASH,
  NVIC_ISER,
  RECORD,
  SIO,
  SPINLOCK0,
  SPINLOCK_ST,
  VECTOR_TABLE,
  VTOR,
  core1Started,
  delay,
  fifoPop,
  fifoPush,
  flashImage,
  dividerWait,
  halt,
  machine,
  spawnCore1,
  values,
} from './firmware.mjs';

const CORE1_CODE = FLASH + 0x1000;
const HANDLER = FLASH + 0x2000;
const CORE1_STACK = 0x20020000;
const SIO_IRQ_PROC0 = 15;
const record = (t, r) => t.bkpt(RECORD + r);
const VLD = 1;
const RDY = 2;
const WOF = 4;
const ROE = 8;

/** Core 0 launches core 1 at CORE1_CODE, then runs `after`; core 1 says it started, then runs `core1`. */
function launching({ after = halt, core1 = halt, vectors = {}, handlers = {}, sram = {}, inject } = {}) {
  const image = flashImage({
    programs: {
      [CORE0_CODE]: (t) => {
        spawnCore1(t, { entry: CORE1_CODE, stack: CORE1_STACK });
        record(t, 5); // wrong echoes
        after(t);
      },
      [CORE1_CODE]: (t) => {
        core1Started(t);
        core1(t);
      },
      ...handlers,
    },
    vectors,
  });
  const run = machine(image, { sram });
  if (inject) inject(run.pico);
  return run;
}

test("rp2040-hal's spawn launches core 1 through the boot ROM: its VTOR, stack pointer, entry and CPUID", () => {
  const { pico, records } = launching({
    after: (t) => halt(t.ldrConst(7, SIO).ldr(0, 7).inline(record, 0)),
    core1: (t) => halt(t.ldr(0, 7).inline(record, 0).ldrConst(1, VTOR).ldr(0, 1).inline(record, 0).mov(0, 13).inline(record, 0)),
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(values(records, 0), [0, 0], 'no wrong echo; core 0 reads CPUID 0');
  assert.deepEqual(values(records, 1), [1, VECTOR_TABLE, CORE1_STACK], 'core 1: CPUID 1, VTOR and SP as sent');
  assert.equal(pico.coresUsed, 2);
});

test('a wrong echo: the sequence starts over, core 1 goes back to its handshake, and the launch completes', () => {
  // A stale word in core 0's RX FIFO, there just before core 0 sends the 1.
  const inject = (pico) => {
    const fifos = pico.fifos;
    const write = fifos.write.bind(fifos);
    let injected = false;
    fifos.write = (k, value) => {
      if (k === 0 && value === 1 && !injected) {
        injected = true;
        write(1, 0xbad);
      }
      write(k, value);
    };
  };
  const { pico, records } = launching({ inject, core1: (t) => halt(t.mov(0, 13).inline(record, 0)) });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(values(records, 0), [1], 'one wrong echo, then a whole sequence');
  assert.deepEqual(values(records, 1), [CORE1_STACK]);
});

test("the boot ROM's wait routine, word by word: each word echoed, a 0 or a wrong word starts it over", () => {
  const entry = CORE1_CODE;
  const { pico, records } = machine(
    flashImage({
      programs: {
        [CORE0_CODE]: halt,
        [CORE1_CODE]: (t) => halt(t.ldrConst(1, VTOR).ldr(0, 1).inline(record, 0).mov(0, 13).inline(record, 0)),
      },
    }),
  );
  const fifos = pico.fifos;
  const answers = () => {
    assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
    const words = [];
    while (fifos.status(0) & VLD) words.push(fifos.read(0));
    return words;
  };
  const send = (word) => {
    fifos.write(0, word);
    pico.sendEvent(0); // core 0's SEV
    return answers();
  };
  assert.deepEqual(answers(), [0], 'at power-on core 1 sends 0 unasked');
  assert.deepEqual(send(0), [0]);
  assert.deepEqual(send(0), [0]);
  assert.deepEqual(send(5), [0], 'a word other than 1: core 1 starts over and sends 0');
  assert.deepEqual(send(1), [1]);
  assert.deepEqual(send(0), [0], 'a 0 in place of the vector table: over again');
  assert.deepEqual(send(VECTOR_TABLE), [0], 'the vector table where the 1 is due: over again');
  assert.deepEqual(send(1), [1]);
  assert.deepEqual(send(VECTOR_TABLE), [VECTOR_TABLE]);
  assert.deepEqual(send(CORE1_STACK), [CORE1_STACK]);
  assert.deepEqual(values(records, 1), [], 'not launched before its entry');
  assert.deepEqual(send(entry | 1), [entry | 1]);
  assert.deepEqual(values(records, 1), [VECTOR_TABLE, CORE1_STACK]);
  assert.equal(pico.coresUsed, 2);
});

test('the FIFOs: VLD, RDY, a read when empty (ROE), a write when full (WOF, the word dropped), and clearing them', () => {
  const status = (t) => t.ldr(0, 7, FIFO_ST).inline(record, 0);
  const { pico, records } = machine(
    flashImage({
      programs: {
        [CORE0_CODE]: (t) => {
          t.ldrConst(7, SIO);
          status(t); // core 1's 0 from power-on
          t.ldr(0, 7, FIFO_RD).inline(record, 0);
          status(t);
          t.ldr(0, 7, FIFO_RD).inline(record, 0); // empty
          status(t);
          t.movsImm(0, 0).str(0, 7, FIFO_ST); // a 0 clears nothing
          status(t);
          t.movsImm(0, ROE).str(0, 7, FIFO_ST);
          status(t);
          for (let word = 1; word <= 9; word++) {
            t.movsImm(0, word).str(0, 7, FIFO_WR);
            if (word >= 7) status(t);
          }
          t.movsImm(0, WOF).str(0, 7, FIFO_ST);
          status(t);
          halt(t);
        },
      },
    }),
  );
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(values(records, 0), [VLD | RDY, 0, RDY, 0, RDY | ROE, RDY | ROE, RDY, RDY, 0, WOF, 0]);
  // Core 1 (asleep in the ROM: no SEV came) sees the first eight words, in order, then nothing.
  const sio1 = pico.sios[1];
  assert.equal(sio1.readUint32(FIFO_ST), VLD | RDY, 'core 1: data in, room out');
  const words = Array.from({ length: 8 }, () => sio1.readUint32(FIFO_RD));
  assert.deepEqual(words, [1, 2, 3, 4, 5, 6, 7, 8]);
  assert.equal(sio1.readUint32(FIFO_RD), 0);
  assert.equal(sio1.readUint32(FIFO_ST), RDY | ROE);
});

test("the FIFO IRQ (SIO_IRQ_PROC0): data from core 1, and core 0's own read when empty", () => {
  const handler = (t) => {
    t.ldrConst(1, SIO)
      .ldr(0, 1, FIFO_ST)
      .inline(record, 0)
      .movsImm(2, VLD)
      .alu('tst', 0, 2)
      .bcc('eq', 'irq.errors')
      .ldr(0, 1, FIFO_RD)
      .inline(record, 0)
      .bxLr()
      .label('irq.errors')
      .movsImm(2, WOF | ROE)
      .str(2, 1, FIFO_ST)
      .bxLr();
  };
  const { pico, records } = launching({
    handlers: { [HANDLER]: handler },
    vectors: { [16 + SIO_IRQ_PROC0]: HANDLER },
    after: (t) => {
      t.ldrConst(1, NVIC_ISER).ldrConst(0, 1 << SIO_IRQ_PROC0).str(0, 1).cpsie().wfi();
      t.ldr(0, 7, FIFO_RD); // empty: ROE, and the IRQ again
      t.ldr(0, 7, FIFO_ST).inline(record, 0);
      halt(t);
    },
    core1: (t) => {
      delay(t, 1000);
      t.ldrConst(0, 0x1234);
      fifoPush(t, 0);
      halt(t);
    },
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(values(records, 0), [0, VLD | RDY, 0x1234, RDY | ROE, RDY]);
});

test('the spinlocks: a read claims (nonzero), a second claim fails (0), a write releases, SPINLOCK_ST shows them', () => {
  const lock5 = SIO + SPINLOCK0 + 5 * 4;
  const { pico, records } = launching({
    after: (t) => {
      t.ldrConst(6, lock5).ldr(0, 6).inline(record, 0).ldr(0, 7, SPINLOCK_ST).inline(record, 0);
      t.movsImm(0, 1);
      fifoPush(t, 0);
      fifoPop(t, 0);
      record(t, 0); // core 1's claim
      t.str(0, 6).ldr(0, 7, SPINLOCK_ST).inline(record, 0);
      fifoPush(t, 0);
      fifoPop(t, 0);
      record(t, 0); // core 1's second claim
      t.ldr(0, 7, SPINLOCK_ST).inline(record, 0);
      halt(t);
    },
    core1: (t) => {
      t.ldrConst(6, 0xd0000114);
      fifoPop(t, 0);
      t.ldr(0, 6);
      fifoPush(t, 0);
      fifoPop(t, 0);
      t.ldr(0, 6);
      fifoPush(t, 0);
      halt(t);
    },
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(values(records, 0), [0, 1 << 5, 1 << 5, 0, 0, 1 << 5, 1 << 5]);
});

test("each core has its own hardware divider: core 1's division does not touch core 0's", () => {
  const { pico, records } = launching({
    after: (t) => {
      t.movsImm(0, 100).str(0, 7, 0x60).movsImm(0, 7).str(0, 7, 0x64); // unsigned 100 / 7
      fifoPush(t, 0);
      fifoPop(t, 0); // core 1 has divided meanwhile
      t.ldr(0, 7, 0x74).inline(record, 0).ldr(0, 7, 0x70).inline(record, 0);
      halt(t);
    },
    core1: (t) => {
      fifoPop(t, 0);
      t.ldrConst(0, -50 >>> 0).str(0, 7, 0x68).movsImm(0, 3).str(0, 7, 0x6c); // signed -50 / 3
      dividerWait(t);
      t.ldr(0, 7, 0x74).inline(record, 0).ldr(0, 7, 0x70).inline(record, 0);
      fifoPush(t, 0);
      halt(t);
    },
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(values(records, 0), [0, 2, 14]);
  assert.deepEqual(values(records, 1), [-2 >>> 0, -16 >>> 0]);
});

test("SEV on one core ends the other's WFE, at once; it does not end a WFI", () => {
  const flag = 0x20030100;
  // Both from SRAM: no flash miss in the way.
  const [signalling, waiting] = [0x20011000, 0x20012000];
  const wfe = launching({
    after: (t) => t.ldrConst(0, signalling | 1).bx(0),
    core1: (t) => t.ldrConst(0, waiting | 1).bx(0),
    sram: {
      [signalling]: (t) => {
        delay(t, 2000);
        t.ldrConst(1, flag).movsImm(0, 1).str(0, 1);
        record(t, 0);
        t.sev();
        halt(t);
      },
      [waiting]: (t) => {
        t.ldrConst(1, flag).label('wait').ldr(0, 1).cmpImm(0, 0).bcc('ne', 'woke').wfe().b('wait').label('woke');
        record(t, 0);
        halt(t);
      },
    },
  });
  assert.equal(wfe.pico.run({ maxSeconds: 1 }), 'idle');
  const sev = wfe.records[0][1].time; // core 0's SEV starts here
  const woke = wfe.records[1][0].time;
  // bkpt and SEV (2 cycles), then core 1's way back to its check: branch, load, compare, branch (7).
  assert.equal(woke - sev, 9, 'core 1 woke as the SEV ended');
  assert.ok(wfe.pico.coreCycles()[1].waiting > 5000, 'core 1 slept through the delay');

  const wfi = launching({
    after: (t) => halt(delay(t, 100).sev()),
    core1: (t) => halt(t.wfi().inline(record, 0)),
  });
  assert.equal(wfi.pico.run({ maxSeconds: 1 }), 'idle');
  assert.deepEqual(values(wfi.records, 1), [], 'still in its WFI');
  assert.ok(wfi.pico.cores[1].waiting);
});

test('lockstep by cycles: two cores counting the same loop take the same cycles, side by side; the clock is the later one', () => {
  const n = 5000;
  const loop = (t) => halt(delay(record(t, 0), n).inline(record, 0));
  const core0Loop = 0x20010000;
  const core1Loop = 0x20011000;
  const { pico, records } = launching({
    sram: { [core0Loop]: loop, [core1Loop]: loop },
    after: (t) => {
      fifoPush(t, 0);
      t.ldrConst(0, core0Loop | 1).bx(0);
    },
    core1: (t) => {
      fifoPop(t, 0);
      t.ldrConst(0, core1Loop | 1).bx(0);
    },
  });
  assert.equal(pico.run({ maxSeconds: 1 }), 'idle');
  const [start0, end0] = records[0].slice(1);
  const [start1, end1] = records[1];
  // bkpt 1, ldr (literal, SRAM) 2, n iterations of subs and bne: 3n - 1.
  assert.equal(end0.time - start0.time, 3 * n + 2);
  assert.equal(end1.time - start1.time, 3 * n + 2);
  // Where both count in SRAM (no flash stall makes an instruction long), neither is more than an instruction ahead.
  for (const r of [start1, end0]) {
    assert.ok(r.other !== null, 'the other core was counting');
    assert.ok(Math.abs(r.time - r.other) <= 3, `a core ${r.time - r.other} cycles ahead of the other`);
  }
  assert.equal(pico.time, Math.max(...pico.cores.map((core) => core.cycles)));
  for (const core of pico.coreCycles()) assert.equal(core.busy + core.waiting, pico.time);
});

/** As rp2040-hal's install_stack_guard: trap if the MPU is set up already, then CTRL, RBAR, RASR (32 bytes at `guard`, no access). */
function installStackGuard(t, guard) {
  t.ldrConst(1, 0xe000ed94)
    .ldr(0, 1)
    .cmpImm(0, 0)
    .bcc('eq', 'mpu.free')
    .udf(0)
    .label('mpu.free')
    .movsImm(0, 5)
    .str(0, 1)
    .ldrConst(0, guard | 0x10)
    .str(0, 1, 8)
    .ldrConst(0, 1 | (7 << 1) | ((0xff ^ 1) << 8) | 0x10000000)
    .str(0, 1, 12);
}

test("rp2040-hal's MPU stack guard on core 1: a store into it ends the run as the stack overflow it is", () => {
  const guard = 0x20018000;
  const { pico, records } = launching({
    core1: (t) => {
      installStackGuard(t, guard);
      t.ldrConst(1, guard + 0x20).str(0, 1).inline(record, 0); // just above the guard: fine
      t.ldrConst(1, guard + 0x1c).str(0, 1); // into it
      halt(t);
    },
  });
  assert.throws(
    () => pico.run({ maxSeconds: 1 }),
    /core 1 overflowed its stack: a store to 0x2001801c hit its MPU guard \(0x20018000-0x20018020, no access\)/,
  );
  assert.equal(values(records, 1).length, 1);
});

test('code in SRAM runs beside the MPU guard, and a fetch from inside the guard is a fault', () => {
  const guard = 0x20018000;
  const { pico, records } = launching({
    core1: (t) => {
      installStackGuard(t, guard);
      t.ldrConst(2, (guard + 0x20) | 1).blx(2).inline(record, 0); // code just above the guard: runs
      t.ldrConst(2, (guard + 0x1c) | 1).blx(2); // code inside it
      halt(t);
    },
    sram: { [guard + 0x1c]: (t) => t.movsImm(0, 7).bxLr(), [guard + 0x20]: (t) => t.movsImm(0, 9).bxLr() },
  });
  assert.throws(() => pico.run({ maxSeconds: 1 }), /core 1: a load from 0x2001801c is a fault in MPU region 0x20018000-0x20018020 \(no access\)/);
  assert.deepEqual(values(records, 1), [9]);
});

test('a fault, an endless loop or a breakpoint on core 1 ends the run naming core 1', () => {
  const udf = launching({ core1: (t) => t.udf(3) });
  assert.throws(() => udf.pico.run({ maxSeconds: 1 }), /undefined instruction \(#3\) at 0x100010.. on core 1/);
  const loop = launching({ core1: (t) => t.label('here').b('here') });
  assert.throws(() => loop.pico.run({ maxSeconds: 20 }), /endless loop in 0x100010.. on core 1/);
});
