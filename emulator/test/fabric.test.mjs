// The bus fabric against the RP2040 datasheet's 2.1: the ports an address
// is on (the striped SRAM of 2.6.2, SRAM4 and SRAM5, the ROM, XIP, the APB
// bridge and the fast peripherals; the SIO on no port), one grant a port a
// cycle with the loser stalling, each master in turn and BUS_PRIORITY's
// high masters first (2.1.1.1), and BUSCTRL's counters (2.1.1.2); then on
// the machine: two cores reading one bank together wait for each other,
// reading two banks they do not, and the SIO never makes them wait.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { BusCtrl, BusFabric, DATA, FETCH, NO_PORT, Port, portOf } from '../fabric.mjs';
import { CORE0_CODE, FLASH, RECORD, SIO, core1Started, fifoPop, flashImage, halt, machine, spawnCore1 } from './firmware.mjs';

const record = (t, r) => t.bkpt(RECORD + r);

/** A fabric between two stand-in cores, each at `cycles`. */
function fabric(cycles = 100, options) {
  const cores = [{ cycles }, { cycles }];
  return { cores, fabric: new BusFabric(cores, options) };
}

test('the ports: SRAM striped by word across four banks, SRAM4 and SRAM5 apart; the SIO and the PPB on none', () => {
  const banks = [0, 4, 8, 12, 16, 0x1234].map((offset) => portOf(0x20000000 + offset));
  assert.deepEqual(banks, [Port.SRAM0, Port.SRAM1, Port.SRAM2, Port.SRAM3, Port.SRAM0, Port.SRAM1]);
  assert.equal(portOf(0x2003fffc), Port.SRAM3);
  assert.deepEqual([0x20040000, 0x20040ffc, 0x20041000, 0x20041ffc].map(portOf), [Port.SRAM4, Port.SRAM4, Port.SRAM5, Port.SRAM5]);
  assert.deepEqual([0x21000000, 0x21000004, 0x21010000, 0x2103fffc].map(portOf), [Port.SRAM0, Port.SRAM0, Port.SRAM1, Port.SRAM3], 'unstriped');
  assert.deepEqual([0x100, 0x10001000, 0x15000000, 0x40054028, 0x50100000].map(portOf), [Port.ROM, Port.XIP, Port.XIP, Port.APB, Port.FASTPERI]);
  assert.deepEqual([0xd0000000, 0xe000ed08].map(portOf), [NO_PORT, NO_PORT]);
});

test('one port, one cycle: one master is granted and the other waits a cycle; the next contest goes to the other', () => {
  const { cores, fabric: bus } = fabric();
  assert.equal(bus.access(0, Port.SRAM0, 100, DATA), 0, 'alone: granted at once');
  // Core 1 reaches the same cycle later in emulation order: it wins the first contest, core 0 waits after the fact.
  assert.equal(bus.access(1, Port.SRAM0, 100, FETCH), 0);
  assert.equal(cores[0].cycles, 101, 'core 0 stalled a cycle');
  assert.equal(bus.access(0, Port.SRAM0, 102, DATA), 0);
  assert.equal(bus.access(1, Port.SRAM0, 102, DATA), 1, 'in turn: now core 1 waits');
  assert.equal(bus.access(1, Port.SRAM1, 104, DATA), 0, 'another port: no wait');
  assert.equal(bus.access(0, Port.SRAM1, 105, DATA), 0, 'another cycle: no wait');
  assert.deepEqual([...bus.contested.slice(Port.SRAM1, Port.SRAM0 + 1)], [0, 2]);
  assert.deepEqual([...bus.stalls], [1, 1]);
  assert.deepEqual(bus.statistics().contests, { fetchFetch: 0, fetchData: 1, dataData: 1 });
});

test('a master that loses after the fact has its later accesses moved a cycle, and meets the winner again there', () => {
  const { cores, fabric: bus } = fabric(100);
  cores[0].cycles = 104;
  bus.access(0, Port.SRAM2, 101, DATA);
  bus.access(0, Port.SRAM2, 102, FETCH);
  bus.access(1, Port.SRAM2, 101, DATA); // core 0 loses 101: its accesses move to 102 and 103
  assert.equal(cores[0].cycles, 105);
  assert.equal(bus.access(1, Port.SRAM2, 103, DATA), 1, "core 0's fetch, now in 103, wins its turn: core 1 waits");
  assert.equal(cores[0].cycles, 105);
});

test('BUS_PRIORITY: a high-priority master wins every contest with a low one', () => {
  const { cores, fabric: bus } = fabric();
  bus.priority = 1 << 4; // PROC1 high
  for (let cycle = 100; cycle < 110; cycle += 2) {
    bus.access(1, Port.SRAM3, cycle, DATA);
    assert.equal(bus.access(0, Port.SRAM3, cycle, DATA), 1);
  }
  assert.equal(cores[1].cycles, 100, 'core 1 never waited');
});

test('contention off: every access is granted at once and counted, none contested', () => {
  const { fabric: bus } = fabric(100, { contention: false });
  bus.access(0, Port.SRAM0, 100, DATA);
  assert.equal(bus.access(1, Port.SRAM0, 100, DATA), 0);
  assert.deepEqual([bus.accesses[Port.SRAM0], bus.contested[Port.SRAM0]], [2, 0]);
});

test('BUSCTRL: PERFSEL picks an event (none at reset), PERFCTR counts it in 24 bits, saturating, and a write clears it', () => {
  const { fabric: bus } = fabric();
  const ctrl = new BusCtrl({ clock: null }, bus);
  const [perfctr, perfsel] = [(n) => 0x08 + 8 * n, (n) => 0x0c + 8 * n];
  assert.equal(ctrl.readUint32(perfsel(0)), 0x1f);
  bus.access(0, Port.SRAM0, 100, DATA);
  bus.access(1, Port.SRAM0, 100, DATA);
  assert.equal(ctrl.readUint32(perfctr(0)), 0, 'no event selected');
  ctrl.writeUint32(perfsel(0), 14); // sram0 contested
  ctrl.writeUint32(perfsel(1), 15); // sram0 accesses
  ctrl.writeUint32(perfsel(2), 18); // rom contested
  bus.access(0, Port.SRAM0, 102, DATA);
  bus.access(1, Port.SRAM0, 102, DATA);
  assert.deepEqual([0, 1, 2].map((n) => ctrl.readUint32(perfctr(n))), [1, 2, 0], 'counted from the selection on');
  ctrl.writeUint32(perfctr(1), 0);
  assert.equal(ctrl.readUint32(perfctr(1)), 0, 'cleared by a write');
  bus.accesses[Port.SRAM0] += 0x1000000;
  assert.equal(ctrl.readUint32(perfctr(1)), 0xffffff, 'saturated');
  ctrl.writeUint32(0x00, 0x1111);
  assert.equal(bus.priority, 0x1111);
  assert.equal(ctrl.readUint32(0x04), 1, 'BUS_PRIORITY_ACK');
});

const CORE1_CODE = FLASH + 0x1000;
/** Each core's loop: SRAM4 for core 0, SRAM5 for core 1, so that their fetches never meet. */
const LOOPS = [0x20040000, 0x20041000];
const PERFCTR0 = 0x40030008;
const ITERATIONS = 200;

/**
 * Both cores (or core 0 alone) load 7 words from `addresses[k]` in one LDM,
 * ITERATIONS times, after a word through the FIFO lines them up; core 0
 * counts BUSCTRL event `event` meanwhile. Records: core 0's time before
 * and after, the counter; core 1's times.
 */
function loads(addresses, { both = true, event = 14 } = {}) {
  const loop = (t, k, address) => {
    t.ldrConst(1, address).ldrConst(3, ITERATIONS).inline(record, 0).label(`loop${k}`);
    t.mov(2, 1).ldmia(2, [0, 4, 5]).ldmia(2, [0, 4, 5]).ldmia(2, [0]).subsImm(3, 1).bcc('ne', `loop${k}`);
    return t.inline(record, 0);
  };
  const image = flashImage({
    programs: {
      [CORE0_CODE]: (t) => {
        spawnCore1(t, { entry: CORE1_CODE, stack: 0x20020000 });
        t.ldrConst(6, PERFCTR0).ldrConst(0, event).str(0, 6, 4).str(0, 6); // PERFSEL0, PERFCTR0 cleared
        if (both) fifoPop(t, 1); // core 1's word: it starts now too
        t.ldrConst(0, LOOPS[0] | 1).bx(0);
      },
      [CORE1_CODE]: (t) => core1Started(t).ldrConst(0, LOOPS[1] | 1).bx(0),
    },
  });
  const sram = {
    [LOOPS[0]]: (t) => halt(loop(t, 0, addresses[0]).ldr(0, 6).inline(record, 0)),
    [LOOPS[1]]: (t) => {
      if (both) t.ldrConst(7, SIO).movsImm(0, 1).str(0, 7, 0x54).sev(); // FIFO_WR: go
      return halt(both ? loop(t, 1, addresses[1]) : t);
    },
  };
  const run = machine(image, { sram });
  assert.equal(run.pico.run({ maxSeconds: 2 }), 'idle');
  const [before, after, counted] = run.records[0];
  return { cycles: after.time - before.time, contested: counted.value, pico: run.pico, core1: run.records[1] };
}

test('on the machine: two cores loading from one bank wait for each other, the counter says how often; two banks, no wait', () => {
  const sram0 = 0x21000000; // unstriped: seven words in one bank
  const alone = loads([sram0, sram0], { both: false });
  // The record (1), then MOV, LDMs of 3, 3 and 1, SUBS and BNE, the last not taken (-1).
  assert.equal(alone.cycles, 1 + ITERATIONS * (1 + 4 + 4 + 2 + 1 + 2) - 1);
  assert.equal(alone.contested, 0);

  const together = loads([sram0, sram0 + 0x100]);
  assert.ok(together.cycles > alone.cycles + ITERATIONS, `${together.cycles} cycles against ${alone.cycles} alone`);
  assert.ok(together.contested > ITERATIONS, `${together.contested} contested accesses`);
  assert.equal(together.core1.length, 2, 'core 1 ran its loop too');

  const apart = loads([sram0, 0x21010000]); // SRAM1
  assert.equal(apart.cycles, alone.cycles, 'different banks: nobody waits');
  assert.equal(apart.contested, 0);
});

test('on the machine: the SIO is no port of the crossbar, both cores read it in the same cycles and never wait', () => {
  const gpio = SIO + 0x10; // GPIO_OUT and the six registers after it
  const both = loads([gpio, gpio]);
  const alone = loads([gpio, gpio], { both: false });
  assert.equal(both.cycles, alone.cycles);
  assert.equal(both.core1.length, 2, 'core 1 ran its loop too');
});
