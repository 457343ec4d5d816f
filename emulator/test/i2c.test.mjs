// The I2C controller against the RP2040 datasheet (4.3): SCL's high and low
// times from the counts (4.3.14), the START, byte and STOP timing of a
// write, the registers rp2040js 1.4.1 gets wrong (IC_SDA_HOLD, IC_FS_SPKLEN,
// IC_CON.SPEED, the counts' minimums, FIRST_DATA_BYTE), the writes the
// chip takes only while disabled, the address not acknowledged when no
// device answers or the pins are not routed, and the RESTART before a
// change of direction. Each drives the registers as rp2040-hal 0.12 does.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { RP2040 } from 'rp2040js';
import { I2cController, i2cPinRole } from '../i2c.mjs';
import { RunError } from '../errors.mjs';

const NANOS_PER_CYCLE = 8; // 125 MHz
const IC_CON = 0x00;
const IC_TAR = 0x04;
const IC_DATA_CMD = 0x10;
const IC_FS_SCL_HCNT = 0x1c;
const IC_FS_SCL_LCNT = 0x20;
const IC_RAW_INTR_STAT = 0x34;
const IC_TX_TL = 0x3c;
const IC_CLR_STOP_DET = 0x60;
const IC_ENABLE = 0x6c;
const IC_STATUS = 0x70;
const IC_SDA_HOLD = 0x7c;
const IC_TX_ABRT_SOURCE = 0x80;
const IC_FS_SPKLEN = 0xa0;
const STOP = 1 << 9;
const CMD_READ = 1 << 8;
const R_TX_ABRT = 1 << 6;
const R_STOP_DET = 1 << 9;
const ABRT_7B_ADDR_NOACK = 1 << 0;

/** A device that records what it sees and answers reads with `answers`. */
function recorder(address, answers = []) {
  const seen = [];
  return {
    address,
    seen,
    start: ({ read }) => seen.push(read ? 'start read' : 'start write'),
    write: (byte) => (seen.push(byte), true),
    read: () => (seen.push('read'), answers.shift()),
    stop: () => seen.push('stop'),
  };
}

/**
 * An I2C0 with `device` on GP4 (SDA) and GP5 (SCL), set up as rp2040-hal's
 * `new_controller` sets it up at 125 MHz for `hz` (fast mode), its pins
 * given the I2C function unless `routed` is false.
 */
function controller({ device = recorder(0x3c), hz = 400_000, routed = true } = {}) {
  const rp2040 = new RP2040();
  rp2040.logger = { debug() {}, info() {}, warn: (c, m) => assert.fail(`${c}: ${m}`), error: (c, m) => assert.fail(`${c}: ${m}`) };
  const i2c = new I2cController(rp2040, 0, 23, { systemClock: { nanosPerCycle: NANOS_PER_CYCLE } });
  i2c.attach(device, { sda: 4, scl: 5 });
  if (routed) rp2040.gpio[4].ctrl = rp2040.gpio[5].ctrl = 3;
  const clock = 125_000_000;
  const period = Math.floor((clock + hz / 2) / hz);
  const lcnt = Math.floor((period * 3) / 5);
  const hcnt = period - lcnt;
  i2c.writeUint32(IC_ENABLE, 0);
  i2c.writeUint32(IC_CON, (i2c.readUint32(IC_CON) & ~0x6) | (2 << 1) | (1 << 8));
  i2c.writeUint32(IC_FS_SCL_HCNT, hcnt);
  i2c.writeUint32(IC_FS_SCL_LCNT, lcnt);
  i2c.writeUint32(IC_FS_SPKLEN, lcnt < 16 ? 1 : Math.floor(lcnt / 16));
  i2c.writeUint32(IC_SDA_HOLD, i2c.readUint32(IC_SDA_HOLD) & ~0xffff | (Math.floor((clock * 3) / 10_000_000) + 1));
  i2c.writeUint32(IC_TX_TL, 16);
  i2c.writeUint32(IC_ENABLE, 1);
  return { rp2040, i2c, device, hcnt, lcnt };
}

/** rp2040-hal's write: set the target while disabled, queue the bytes (STOP on the last), wait for STOP_DET. */
function write(rp2040, i2c, address, bytes) {
  i2c.writeUint32(IC_ENABLE, 0);
  i2c.writeUint32(IC_TAR, address);
  i2c.writeUint32(IC_ENABLE, 1);
  const started = rp2040.clock.nanos;
  bytes.forEach((byte, k) => {
    while (!(i2c.readUint32(IC_STATUS) & 0x2)) rp2040.clock.tick(NANOS_PER_CYCLE); // TFNF
    i2c.writeUint32(IC_DATA_CMD, byte | (k === bytes.length - 1 ? STOP : 0));
  });
  while (!(i2c.readUint32(IC_RAW_INTR_STAT) & R_STOP_DET)) rp2040.clock.tick(NANOS_PER_CYCLE);
  i2c.readUint32(IC_CLR_STOP_DET);
  return (rp2040.clock.nanos - started) / NANOS_PER_CYCLE;
}

test("SCL's period is HCNT + SPKLEN + 7 high and LCNT + 1 low; a write takes its START, 9 clocks a byte, and its STOP", () => {
  const { rp2040, i2c, device, hcnt, lcnt } = controller();
  // rp2040-hal at 400 kHz: period 313, LCNT 187, HCNT 126, SPKLEN 11.
  assert.deepEqual([hcnt, lcnt, i2c.spikelen], [126, 187, 11]);
  const bit = 126 + 11 + 7 + 187 + 1;
  assert.equal(i2c.bitCycles, bit);
  assert.ok(Math.abs(i2c.sclHz(125e6) - 376_506) < 1);
  const cycles = write(rp2040, i2c, 0x3c, [0x00, 0xaf]);
  // START hold (HCNT), address and two bytes, then SCL low and the STOP's set-up (HCNT); within a cycle of polling.
  const expected = hcnt + 3 * 9 * bit + lcnt + 1 + hcnt;
  assert.ok(cycles >= expected && cycles <= expected + 1, `${cycles} cycles, expected ${expected}`);
  assert.deepEqual(device.seen, ['start write', 0x00, 0xaf, 'stop']);
  // The next START, asked for at once, first waits for the bus-free time (tBUF, LCNT) after the STOP.
  const next = write(rp2040, i2c, 0x3c, [0x40]);
  const expectedNext = lcnt + hcnt + 2 * 9 * bit + lcnt + 1 + hcnt;
  assert.ok(next >= expectedNext && next <= expectedNext + 1, `${next} cycles, expected ${expectedNext}`);
});

test('a device that is not there, or pins without the I2C function, leave the address unacknowledged: TX_ABRT, ABRT_7B_ADDR_NOACK, then STOP', () => {
  for (const options of [{}, { routed: false }]) {
    const { rp2040, i2c, device } = controller(options);
    const address = options.routed === false ? 0x3c : 0x3d;
    write(rp2040, i2c, address, [0x00]);
    assert.ok(i2c.readUint32(IC_RAW_INTR_STAT) & R_TX_ABRT);
    assert.equal(i2c.readUint32(IC_TX_ABRT_SOURCE) & ABRT_7B_ADDR_NOACK, ABRT_7B_ADDR_NOACK);
    assert.deepEqual(device.seen, []);
  }
});

test('IC_SDA_HOLD holds its 24 bits, IC_FS_SPKLEN an odd value, and both read back as written (rp2040js dropped them)', () => {
  const { i2c } = controller();
  assert.equal(i2c.readUint32(IC_SDA_HOLD), 38); // 125 MHz × 300 ns + 1
  assert.equal(i2c.readUint32(IC_FS_SPKLEN), 11);
  i2c.writeUint32(IC_ENABLE, 0);
  i2c.writeUint32(IC_FS_SPKLEN, 0);
  assert.equal(i2c.readUint32(IC_FS_SPKLEN), 1, 'the minimum is 1');
  i2c.writeUint32(IC_FS_SCL_HCNT, 2);
  i2c.writeUint32(IC_FS_SCL_LCNT, 3);
  assert.deepEqual([i2c.readUint32(IC_FS_SCL_HCNT), i2c.readUint32(IC_FS_SCL_LCNT)], [6, 8], 'the minimums are 6 and 8');
  i2c.writeUint32(IC_CON, 0x61); // SPEED 0: becomes fast, the RP2040's fastest
  assert.equal((i2c.readUint32(IC_CON) >> 1) & 3, 2);
  i2c.writeUint32(IC_CON, 0x67); // SPEED 3 likewise
  assert.equal((i2c.readUint32(IC_CON) >> 1) & 3, 2);
});

test('IC_CON, the counts, IC_FS_SPKLEN and IC_SDA_HOLD written while enabled are errors: the chip ignores such writes', () => {
  const { i2c } = controller();
  for (const offset of [IC_CON, IC_FS_SCL_HCNT, IC_FS_SCL_LCNT, IC_FS_SPKLEN, IC_SDA_HOLD]) {
    assert.throws(() => i2c.writeUint32(offset, 0x10), (e) => e instanceof RunError && /while the controller is enabled/.test(e.message));
  }
});

test('counts the datasheet forbids (LCNT ≤ SPKLEN + 7) are an error when a transfer starts', () => {
  const { rp2040, i2c } = controller();
  i2c.writeUint32(IC_ENABLE, 0);
  i2c.writeUint32(IC_FS_SPKLEN, 4);
  i2c.writeUint32(IC_FS_SCL_LCNT, 11);
  i2c.writeUint32(IC_ENABLE, 1);
  assert.throws(() => write(rp2040, i2c, 0x3c, [0x00]), /LCNT > SPKLEN \+ 7/);
});

test('a read after a write gets a RESTART, and its first byte carries FIRST_DATA_BYTE in bit 11', () => {
  const device = recorder(0x3c, [0x5a]);
  const { rp2040, i2c } = controller({ device });
  i2c.writeUint32(IC_ENABLE, 0);
  i2c.writeUint32(IC_TAR, 0x3c);
  i2c.writeUint32(IC_ENABLE, 1);
  i2c.writeUint32(IC_DATA_CMD, 0x01);
  i2c.writeUint32(IC_DATA_CMD, CMD_READ | STOP);
  while (!(i2c.readUint32(IC_RAW_INTR_STAT) & R_STOP_DET)) rp2040.clock.tick(NANOS_PER_CYCLE);
  assert.deepEqual(device.seen, ['start write', 0x01, 'start read', 'read', 'stop']);
  assert.equal(i2c.readUint32(IC_DATA_CMD), (1 << 11) | 0x5a);
});

test('GPIO pins carry the controller and line the datasheet gives (I2C0 SDA on GP0, 4, …; I2C1 SCL on GP3, 7, …)', () => {
  assert.deepEqual(i2cPinRole(4), { controller: 0, line: 'SDA' });
  assert.deepEqual(i2cPinRole(5), { controller: 0, line: 'SCL' });
  assert.deepEqual(i2cPinRole(26), { controller: 1, line: 'SDA' });
  assert.deepEqual(i2cPinRole(7), { controller: 1, line: 'SCL' });
  const rp2040 = new RP2040();
  const i2c = new I2cController(rp2040, 0, 23, { systemClock: { nanosPerCycle: NANOS_PER_CYCLE } });
  assert.throws(() => i2c.attach(recorder(0x3c), { sda: 6, scl: 7 }), /GPIO 6 is not I2C0's SDA/);
});
