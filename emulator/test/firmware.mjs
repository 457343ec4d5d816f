// Small firmwares for the tests, written here in Thumb: a boot2 of our own
// for the Pico's W25Q16JV (the steps its datasheet asks for quad I/O XIP),
// flash images and ELFs around programs, rp2040-hal 0.12's core 1 launch
// sequence, and a machine that records what a program shows it.
//
// Invariant: nothing here is copied from a boot2 or a HAL; each routine
// follows the datasheet's protocol (or, for the launch, rp2040-hal's
// algorithm) step by step, so the tests check the emulator against those.

import { Thumb } from '../thumb.mjs';
import { Pico } from '../pico.mjs';
import { BOOT2_BASE } from '../bootrom.mjs';

export const FLASH = 0x10000000;
export const VECTOR_TABLE = FLASH + 0x100;
/** Core 0's program starts here (the reset vector), other programs where a test puts them. */
export const CORE0_CODE = FLASH + 0x400;
export const SIO = 0xd0000000;
export const FIFO_ST = 0x50;
export const FIFO_WR = 0x54;
export const FIFO_RD = 0x58;
export const SPINLOCK_ST = 0x5c;
export const SPINLOCK0 = 0x100;
export const VTOR = 0xe000ed08;
export const NVIC_ISER = 0xe000e100;
export const XIP_CTRL = 0x14000000;
/** A BKPT #RECORD + n makes the test machine record register n and the core's time. */
export const RECORD = 0x10;

const SSI = 0x18000000;
const CTRLR0 = 0x00;
const CTRLR1 = 0x04;
const SSIENR = 0x08;
const BAUDR = 0x14;
const SR = 0x28;
const DR0 = 0x60;
const RX_SAMPLE_DLY = 0xf0;
const SPI_CTRLR0 = 0xf4;
const PSM_FRCE_OFF = 0x40010004;

/** The boot ROM's check of boot2: CRC-32/MPEG-2 of its first 252 bytes. */
export function crc32Mpeg2(bytes) {
  let crc = 0xffffffff;
  for (const byte of bytes) {
    crc ^= byte << 24;
    for (let bit = 0; bit < 8; bit++) crc = crc & 0x80000000 ? (crc << 1) ^ 0x04c11db7 : crc << 1;
  }
  return crc >>> 0;
}

/**
 * A boot2 for a W25Q16JV, entered at the top of SRAM with lr = 0: it reads
 * status register 2 and, if QE is clear, sets it (write enable, write
 * status, wait while busy); makes one EBh read with mode bits A0h so the
 * flash stays in continuous read mode; sets XIP to send no instruction, the
 * address and the mode bits over 4 lanes, `waitClocks` wait clocks, at
 * clk_sys / `divider`; and vectors into the table at 0x10000100.
 */
export function boot2({ divider = 2, waitClocks = 4, sampleDelay = 1, badCrc = false } = {}) {
  const t = new Thumb(BOOT2_BASE);
  t.ldrConst(3, SSI)
    .movsImm(1, 0)
    .str(1, 3, SSIENR)
    .movsImm(1, divider)
    .str(1, 3, BAUDR)
    .movsImm(1, sampleDelay)
    .ldrConst(2, SSI + RX_SAMPLE_DLY)
    .str(1, 2)
    .ldrConst(1, 7 << 16) // standard SPI, 8-bit frames, transmit and receive
    .str(1, 3, CTRLR0)
    .movsImm(1, 1)
    .str(1, 3, SSIENR)
    .movsImm(0, 0x35)
    .bl('status')
    .cmpImm(0, 2)
    .bcc('eq', 'quad')
    .movsImm(1, 0x06)
    .str(1, 3, DR0)
    .bl('idle')
    .ldr(1, 3, DR0)
    .movsImm(1, 0x01)
    .str(1, 3, DR0)
    .movsImm(1, 0)
    .str(1, 3, DR0)
    .movsImm(1, 2)
    .str(1, 3, DR0)
    .bl('idle')
    .ldr(1, 3, DR0)
    .ldr(1, 3, DR0)
    .ldr(1, 3, DR0)
    .label('busy')
    .movsImm(0, 0x05)
    .bl('status')
    .movsImm(1, 1)
    .alu('tst', 0, 1)
    .bcc('ne', 'busy');
  // Quad I/O: a dummy EBh read with mode bits A0h, then XIP with no instruction.
  t.label('quad')
    .movsImm(1, 0)
    .str(1, 3, SSIENR)
    .ldrConst(1, (2 << 21) | (31 << 16) | (3 << 8)) // quad, 32-bit frames, EEPROM read
    .str(1, 3, CTRLR0)
    .movsImm(1, 0)
    .str(1, 3, CTRLR1)
    .ldrConst(2, SSI + SPI_CTRLR0)
    .ldrConst(1, (waitClocks << 11) | (2 << 8) | (8 << 2) | 1) // 8-bit instruction on 1 lane, 32 address-and-mode bits on 4
    .str(1, 2)
    .movsImm(1, 1)
    .str(1, 3, SSIENR)
    .movsImm(1, 0xeb)
    .str(1, 3, DR0)
    .movsImm(1, 0xa0)
    .str(1, 3, DR0)
    .bl('idle')
    .movsImm(1, 0)
    .str(1, 3, SSIENR)
    .ldrConst(1, (0xa0 << 24) | (waitClocks << 11) | (8 << 2) | 2) // no instruction, A0h as the mode bits
    .str(1, 2)
    .movsImm(1, 1)
    .str(1, 3, SSIENR)
    // Into the firmware's vector table.
    .ldrConst(0, VECTOR_TABLE)
    .ldrConst(1, VTOR)
    .str(0, 1)
    .ldmia(0, [0, 1])
    .msrMsp(0)
    .bx(1);
  // idle: until the TX FIFO is empty and the SSI not busy (r0, r1 spent).
  t.label('idle')
    .ldr(1, 3, SR)
    .movsImm(0, 4)
    .alu('tst', 1, 0)
    .bcc('eq', 'idle')
    .movsImm(0, 1)
    .alu('tst', 1, 0)
    .bcc('ne', 'idle')
    .bxLr();
  // status: the status register command r0 and a dummy byte out, the register's value back in r0.
  t.label('status')
    .mov(4, 14)
    .str(0, 3, DR0)
    .str(0, 3, DR0)
    .bl('idle')
    .ldr(0, 3, DR0)
    .ldr(0, 3, DR0)
    .bx(4)
    .pool();
  return boot2Image(t, { badCrc });
}

/** The 256 bytes of a boot2 assembled by `t` (at BOOT2_BASE), with its CRC (wrong if `badCrc`). */
export function boot2Image(t, { badCrc = false } = {}) {
  const code = t.bytes();
  if (code.length > 252) throw new Error(`the test boot2 is ${code.length} bytes; 252 fit`);
  const image = new Uint8Array(256);
  image.set(code);
  new DataView(image.buffer).setUint32(252, crc32Mpeg2(image.subarray(0, 252)) ^ (badCrc ? 1 : 0), true);
  return image;
}

/**
 * A flash image: `boot2`, the vector table (initial stack pointer `stack`,
 * reset at CORE0_CODE, and `vectors`: exception number → address), and
 * `programs`: flash address → a function writing Thumb code there.
 */
export function flashImage({ programs, vectors = {}, stack = 0x20040000, boot2: loader = boot2(), size = 0x8000 }) {
  const image = new Uint8Array(size);
  const view = new DataView(image.buffer);
  image.set(loader, 0);
  view.setUint32(0x100, stack, true);
  view.setUint32(0x104, CORE0_CODE | 1, true);
  for (const [number, address] of Object.entries(vectors)) view.setUint32(0x100 + 4 * Number(number), address | 1, true);
  for (const [address, write] of Object.entries(programs)) {
    image.set(assemble(Number(address), write), Number(address) - FLASH);
  }
  return image;
}

/** Thumb code at `base`. */
export function assemble(base, write) {
  const t = new Thumb(base);
  write(t);
  return t.bytes();
}

/** An ELF32 for ARM with one loadable segment: `image` at `address`. */
export function elf(image, address = FLASH) {
  const out = Buffer.alloc(52 + 32 + image.length);
  out.set([0x7f, 0x45, 0x4c, 0x46, 1, 1, 1], 0);
  out.writeUInt16LE(2, 16); // executable
  out.writeUInt16LE(40, 18); // ARM
  out.writeUInt32LE(1, 20);
  out.writeUInt32LE(CORE0_CODE | 1, 24);
  out.writeUInt32LE(52, 28); // program headers
  out.writeUInt16LE(52, 40);
  out.writeUInt16LE(32, 42);
  out.writeUInt16LE(1, 44);
  out.writeUInt16LE(40, 46);
  out.writeUInt32LE(1, 52); // PT_LOAD
  out.writeUInt32LE(84, 56);
  out.writeUInt32LE(address, 60);
  out.writeUInt32LE(address, 64);
  out.writeUInt32LE(image.length, 68);
  out.writeUInt32LE(image.length, 72);
  out.set(image, 84);
  return out;
}

/**
 * A Pico with `image` in flash (and `sram`: { address → code writer }) whose
 * BKPT #RECORD + n records { value: rn, time } per core in `records`.
 */
export function machine(image, { sram = {}, ...options } = {}) {
  const records = [[], []];
  const segments = [{ loadAddress: FLASH, data: image }];
  for (const [address, write] of Object.entries(sram)) {
    segments.push({ loadAddress: Number(address), data: assemble(Number(address), write) });
  }
  const pico = new Pico({
    ...options,
    segments,
    source: 'test firmware',
    onBreakpoint: (k, code) => {
      if (code < RECORD || code >= RECORD + 8) return false;
      const [core, other] = [pico.cores[k], pico.cores[1 - k]];
      records[k].push({
        value: core.registers[code - RECORD] >>> 0,
        time: core.cycles,
        other: other.waiting ? null : other.cycles, // the other core's time, if it runs
      });
      return true;
    },
  });
  return { pico, records };
}

/** The values core k recorded. */
export const values = (records, k) => records[k].map((r) => r.value);

/**
 * rp2040-hal 0.12's `Core::spawn` for core 1, step by step: FRCE_OFF.PROC1
 * set (read-modify-write), waited for, cleared; then the command sequence 0,
 * 0, 1, vector table (core 0's VTOR), stack pointer, entry, each preceded
 * when 0 by draining the RX FIFO and SEV, pushed with `write_blocking` and
 * its echo read with `read_blocking`; a wrong echo starts the sequence
 * over; after 16 wrong echoes it gives up (BKPT #0x7f). Last, it reads core
 * 1's word saying it has taken its entry. Leaves the number of wrong echoes
 * in r5 and the SIO's address in r7. The command table goes to SRAM at
 * `table`.
 */
export function spawnCore1(t, { entry, stack, table = 0x20030000 }) {
  t.ldrConst(0, PSM_FRCE_OFF)
    .ldr(1, 0)
    .ldrConst(2, 1 << 16)
    .alu('orrs', 1, 2)
    .str(1, 0)
    .label('spawn.off')
    .ldr(1, 0)
    .alu('tst', 1, 2)
    .bcc('eq', 'spawn.off')
    .ldr(1, 0)
    .alu('bics', 1, 2)
    .str(1, 0);
  // The command sequence, in SRAM.
  t.ldrConst(6, table).movsImm(0, 0).str(0, 6, 0).str(0, 6, 4).movsImm(0, 1).str(0, 6, 8);
  t.ldrConst(1, VTOR).ldr(0, 1).str(0, 6, 12);
  t.ldrConst(0, stack).str(0, 6, 16).ldrConst(0, entry | 1).str(0, 6, 20);
  t.ldrConst(7, SIO).movsImm(4, 0).movsImm(5, 0);
  t.label('spawn.next')
    .lslsImm(0, 4, 2)
    .ldrReg(0, 6, 0)
    .cmpImm(0, 0)
    .bcc('ne', 'spawn.write')
    .label('spawn.drain')
    .ldr(1, 7, FIFO_ST)
    .movsImm(2, 1)
    .alu('tst', 1, 2)
    .bcc('eq', 'spawn.drained')
    .ldr(1, 7, FIFO_RD)
    .b('spawn.drain')
    .label('spawn.drained')
    .sev()
    .label('spawn.write');
  fifoPush(t, 0);
  fifoPop(t, 1);
  t.alu('cmp', 0, 1)
    .bcc('ne', 'spawn.wrong')
    .addsImm(4, 1)
    .b('spawn.more')
    .label('spawn.wrong')
    .movsImm(4, 0)
    .addsImm(5, 1)
    .cmpImm(5, 16)
    .bcc('ls', 'spawn.more')
    .bkpt(0x7f)
    .label('spawn.more')
    .cmpImm(4, 6)
    .bcc('cc', 'spawn.next');
  fifoPop(t, 1);
}

/** rp2040-hal's core1_startup, as far as the tests need it: tell core 0 the entry is taken (1, write_blocking). */
export function core1Started(t) {
  return fifoPush(t.ldrConst(7, SIO).movsImm(0, 1), 0);
}

let unique = 0;

/**
 * rp2040-hal's `write_blocking`: register `r` into the TX FIFO once it has
 * room (NOP while full), with `write`'s SEV and its own (r7 holds the SIO;
 * r1, r2 spent).
 */
export function fifoPush(t, r) {
  const [wait, room] = [`push.${unique}`, `push.${unique++}.room`];
  return t
    .label(wait)
    .ldr(1, 7, FIFO_ST)
    .movsImm(2, 2)
    .alu('tst', 1, 2)
    .bcc('ne', room)
    .nop()
    .b(wait)
    .label(room)
    .str(r, 7, FIFO_WR)
    .sev()
    .sev();
}

/** rp2040-hal's `read_blocking`: the next word of the RX FIFO into register `r`, WFE while it is empty (r7 the SIO; r1, r2 spent). */
export function fifoPop(t, r) {
  const [wait, word] = [`pop.${unique}`, `pop.${unique++}.word`];
  return t.label(wait).ldr(1, 7, FIFO_ST).movsImm(2, 1).alu('tst', 1, 2).bcc('ne', word).wfe().b(wait).label(word).ldr(r, 7, FIFO_RD);
}

/** A loop of `n` iterations (subs, bne: 3n - 1 cycles) in r0. */
export function delay(t, n) {
  const loop = `delay.${unique++}`;
  return t.ldrConst(0, n).label(loop).subsImm(0, 1).bcc('ne', loop);
}

/** rp2040-hal's wait for the divider's result: four branches to the next instruction, 8 cycles. */
export function dividerWait(t) {
  for (let i = 0; i < 4; i++) {
    const next = `divider.${unique++}`;
    t.b(next).label(next);
  }
  return t;
}

/** Sleeps for good: WFI with nothing to wake it. */
export const halt = (t) => t.label('halt').wfi().b('halt');
