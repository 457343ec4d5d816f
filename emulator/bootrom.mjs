// A stand-in for the RP2040's boot ROM: how it starts both cores, and the
// part of it an rp2040-hal firmware calls once it runs. The Raspberry Pi ROM
// image is not on any package registry, so this one is written here, in
// Thumb code the emulator runs (its cycles count like the firmware's own).
//
// Both cores enter at the reset vector and read SIO CPUID (datasheet 2.8.1):
//
// - Core 0 boots from flash as the real ROM does: it sets the SSI up for
//   standard 03h reads through XIP at clk_sys / 6, copies the 256 bytes of
//   boot2 to the top of SRAM (0x20041f00), flushes the XIP cache and enters
//   boot2 with lr = 0, so boot2 sets up its flash and vectors into the
//   firmware's table at 0x10000100. (The real ROM first checks boot2's CRC,
//   which the machine checks before it starts, `checkBoot2`; and it streams
//   boot2 with one 03h command where this one reads it line by line through
//   the cache.)
// - Core 1 waits for core 0 to launch it (2.8.2): it empties its RX FIFO,
//   sends 0, and sleeps in WFE until a word comes. A 0, or anything but 1
//   where the 1 is due, starts it over (empty, send 0); then each word is
//   echoed back: 1, the vector table (written to its VTOR), the stack
//   pointer (its MSP) and the entry point, to which it branches. A 0 in
//   their place starts it over too. It uses no stack; should the entry
//   return, it sleeps in WFE for good.
//
// rp2040-hal (by default, without its `disable-intrinsics` feature) routes
// these compiler intrinsics through the ROM: it reads the table-lookup
// function's address at 0x18 and the function table's at 0x14, looks a
// function up by its two-letter code, and calls it. This ROM answers those
// lookups with its own versions of exactly that family:
//
//   code  ROM function  what calls it
//   P3    popcount32    __popcountsi2 (u32::count_ones)
//   R3    reverse32     __rbit (u32::reverse_bits)
//   L3    clz32         __clzsi2 (u32::leading_zeros on Armv6-M)
//   T3    ctz32         __ctzsi2 (u32::trailing_zeros)
//   MS    memset        __aeabi_memset, __aeabi_memclr
//   S4    memset4       __aeabi_memset4/8, __aeabi_memclr4/8
//   MC    memcpy        __aeabi_memcpy
//   C4    memcpy44      __aeabi_memcpy4/8
//
// They cost what the real ROM's (its public source, B2) cost, written here
// anew: the table in the real one's order (the lookup walks it, 11 cycles
// a code; rp2040-hal looks a function up at every call unless its
// `rom-func-cache` feature keeps it, as octrace's Pico templates do); memset
// and memcpy reach a word boundary by a byte and a halfword, then fill or copy
// 16 bytes a turn with four registers (2 cycles a word filled, 3.25 a word
// copied) and finish with 8, 4, 2 and 1; memcpy of buffers whose
// alignments differ, and anything under 8 bytes, go a byte at a time; the
// bit functions in constant time: popcount and bit reversal by halving
// masks, clz by 16, 8 and 4 bits then a table, ctz by a de Bruijn multiply.
//
// Anything else (the flash-programming functions, the soft-float tables,
// reset to USB boot) is not here: looking it up stops the run with an error
// naming the code, never a silent zero.
//
// Invariants: the layout of the real ROM's header (initial stack pointer
// and reset vector at 0x00, magic at 0x10, version at 0x13, 16-bit pointers
// at 0x14, 0x16, 0x18); the launch protocol is the datasheet's; the
// functions' loops take the real ROM's cycles (their entries and short
// cases within a few cycles of them).

import { Thumb } from './thumb.mjs';

/** The breakpoint number the lookup stops at for a code this ROM lacks. */
export const MISSING_FUNCTION_BREAKPOINT = 0x52;

const ROM_BYTES = 16 * 1024;
const CODE_START = 0x100;
const SRAM_END = 0x20042000;
/** Where the ROM copies boot2 and enters it: the last 256 bytes of SRAM. */
export const BOOT2_BASE = SRAM_END - 256;
const XIP_BASE = 0x10000000;
const XIP_CTRL_FLUSH = 0x14000004;
const SSI_BASE = 0x18000000;
const SSI_CTRLR0 = 0x00;
const SSI_SSIENR = 0x08;
const SSI_SER = 0x10;
const SSI_BAUDR = 0x14;
const SSI_SPI_CTRLR0 = 0xf4;
/** 03h reads through XIP: standard SPI, 32-bit frames, EEPROM read; 8-bit instruction 03h, 24-bit address. */
const CTRLR0_03H = (31 << 16) | (3 << 8);
const SPI_CTRLR0_03H = (0x03 << 24) | (2 << 8) | (6 << 2);
const ROM_FLASH_DIVIDER = 6;
const SIO_BASE = 0xd0000000;
const FIFO_ST = 0x50;
const FIFO_WR = 0x54;
const FIFO_RD = 0x58;
const FIFO_VLD = 1;
const FIFO_RDY = 2;
const VTOR = 0xe000ed08;

/** The two letters of a table code, as the ROM's 16-bit key. */
function code(letters) {
  return letters.charCodeAt(0) | (letters.charCodeAt(1) << 8);
}

/** The two letters of a 16-bit key, for messages. */
export function codeLetters(key) {
  const printable = (c) => (c >= 0x20 && c < 0x7f ? String.fromCharCode(c) : '?');
  return `${printable(key & 0xff)}${printable((key >> 8) & 0xff)}`;
}

// Each function takes its arguments in r0..r2 (AAPCS) and returns in r0;
// r0-r3 and r12 are the caller's to lose, the rest is pushed and popped.
// Listed in the real ROM's table order.
const FUNCTIONS = {
  // popcount32(x): bits counted in pairs, nibbles, then bytes summed by a multiply
  P3: (t) =>
    t.ldrConst(1, 0x55555555)
      .lsrsImm(2, 0, 1)
      .alu('ands', 2, 1)
      .subs(0, 0, 2)
      .ldrConst(1, 0x33333333)
      .lsrsImm(2, 0, 2)
      .alu('ands', 2, 1)
      .alu('ands', 0, 1)
      .adds(0, 0, 2)
      .lsrsImm(2, 0, 4)
      .adds(0, 0, 2)
      .ldrConst(1, 0x0f0f0f0f)
      .alu('ands', 0, 1)
      .ldrConst(1, 0x01010101)
      .alu('muls', 0, 1)
      .lsrsImm(0, 0, 24)
      .bxLr(),
  // reverse32(x): neighbouring bits, pairs and nibbles swapped, then the bytes by REV
  R3: (t) => {
    for (const [mask, shift] of [[0x55555555, 1], [0x33333333, 2], [0x0f0f0f0f, 4]]) {
      t.ldrConst(1, mask).lsrsImm(2, 0, shift).alu('ands', 2, 1).alu('ands', 0, 1).lslsImm(0, 0, shift).alu('orrs', 0, 2);
    }
    return t.rev(0, 0).bxLr();
  },
  // clz32(x): 16, 8 and 4 bits at a time from the top, the last nibble from a table; 32 for 0
  L3: (t) => {
    t.movsImm(1, 28);
    for (const bits of [16, 8, 4]) {
      t.lsrsImm(2, 0, bits).bcc('eq', `l3.${bits}`).movs(0, 2).subsImm(1, bits).label(`l3.${bits}`);
    }
    t.adr(2, 'l3.table').ldrbReg(0, 2, 0).adds(0, 0, 1).bxLr().align4().label('l3.table');
    for (const zeros of [4, 3, 2, 2, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0]) t.byte(zeros);
    return t;
  },
  // ctz32(x): the lowest set bit alone, times a de Bruijn word, its top 5 bits into a table; 32 for 0
  T3: (t) => {
    t.alu('rsbs', 1, 0).alu('ands', 1, 0).bcc('eq', 't3.zero').ldrConst(2, DE_BRUIJN).alu('muls', 1, 2).lsrsImm(1, 1, 27);
    t.adr(2, 't3.table').ldrbReg(0, 2, 1).bxLr().label('t3.zero').movsImm(0, 32).bxLr().align4().label('t3.table');
    for (const position of deBruijnPositions()) t.byte(position);
    return t;
  },
  // memset(ptr, c, n) -> ptr: bytes and a halfword up to a word boundary, then words
  MS: (t) => {
    t.mov(12, 0).inline(replicateByte).cmpImm(2, 8).bcc('cc', 'ms.short');
    t.lsrsImm(3, 0, 1).bcc('cc', 'ms.even').strb(1, 0).addsImm(0, 1).subsImm(2, 1).label('ms.even');
    t.lsrsImm(3, 0, 2).bcc('cc', 'ms.aligned').strh(1, 0).addsImm(0, 2).subsImm(2, 2).label('ms.aligned');
    return fillWords(t, 'ms').mov(0, 12).bxLr().label('ms.short').inline(storeBytes, 'ms').mov(0, 12).bxLr();
  },
  // memset4(ptr, c, n) -> ptr, ptr word-aligned
  S4: (t) => fillWords(t.mov(12, 0).inline(replicateByte), 's4').mov(0, 12).bxLr(),
  // memcpy(dest, src, n) -> dest: words when dest and src share their alignment, else bytes
  MC: (t) => {
    t.mov(12, 0).cmpImm(2, 8).bcc('cc', 'mc.short').subs(3, 0, 1).lslsImm(3, 3, 30).bcc('ne', 'mc.short');
    t.lsrsImm(3, 0, 1).bcc('cc', 'mc.even').ldrb(3, 1).strb(3, 0).addsImm(0, 1).addsImm(1, 1).subsImm(2, 1).label('mc.even');
    t.lsrsImm(3, 0, 2).bcc('cc', 'mc.aligned').ldrh(3, 1).strh(3, 0).addsImm(0, 2).addsImm(1, 2).subsImm(2, 2);
    return copyWords(t.label('mc.aligned'), 'mc').mov(0, 12).bxLr().label('mc.short').inline(copyBytes, 'mc').mov(0, 12).bxLr();
  },
  // memcpy44(dest, src, n) -> dest, both word-aligned
  C4: (t) => copyWords(t.mov(12, 0), 'c4').mov(0, 12).bxLr(),
};

/** A de Bruijn sequence of 32: its top 5 bits, shifted by k, differ for every k. */
const DE_BRUIJN = 0x077cb531;

/** The table of ctz32: the bit's position for each top 5 bits of DE_BRUIJN << position. */
function deBruijnPositions() {
  const positions = new Array(32);
  for (let bit = 0; bit < 32; bit++) positions[((DE_BRUIJN << bit) >>> 27) & 31] = bit;
  return positions;
}

// r1's low byte in all four bytes of r1 (r3 spent).
function replicateByte(t) {
  return t.uxtb(1, 1).lslsImm(3, 1, 8).alu('orrs', 1, 3).lslsImm(3, 1, 16).alu('orrs', 1, 3);
}

// Stores the pattern r1 from r0 (word-aligned) on, r2 bytes (any number):
// 16 bytes a turn of four registers (8 cycles: 2 a word), then 8, 4, 2, 1;
// ends at `${prefix}.done`, r0 past the end.
function fillWords(t, prefix) {
  t.movs(3, 1).subsImm(2, 16).bcc('cc', `${prefix}.tail`).push([4, 5]).movs(4, 1).movs(5, 1);
  t.label(`${prefix}.words`).stmia(0, [1, 3, 4, 5]).subsImm(2, 16).bcc('cs', `${prefix}.words`).pop([4, 5]);
  t.label(`${prefix}.tail`).lslsImm(2, 2, 29).bcc('cc', `${prefix}.4`).stmia(0, [1, 3]);
  t.label(`${prefix}.4`).lslsImm(2, 2, 1).bcc('cc', `${prefix}.2`).stmia(0, [1]);
  t.label(`${prefix}.2`).lslsImm(2, 2, 1).bcc('cc', `${prefix}.1`).strh(1, 0).addsImm(0, 2);
  return t.label(`${prefix}.1`).lslsImm(2, 2, 1).bcc('cc', `${prefix}.done`).strb(1, 0).label(`${prefix}.done`);
}

// Copies r2 bytes (any number) from r1 to r0, both word-aligned: 16 bytes
// a turn of four registers (13 cycles: 3.25 a word), then 8, 4, 2, 1.
function copyWords(t, prefix) {
  t.push([4, 5, 6]).subsImm(2, 16).bcc('cc', `${prefix}.tail`);
  t.label(`${prefix}.words`).ldmia(1, [3, 4, 5, 6]).stmia(0, [3, 4, 5, 6]).subsImm(2, 16).bcc('cs', `${prefix}.words`);
  t.label(`${prefix}.tail`).lslsImm(2, 2, 29).bcc('cc', `${prefix}.4`).ldmia(1, [3, 4]).stmia(0, [3, 4]);
  t.label(`${prefix}.4`).lslsImm(2, 2, 1).bcc('cc', `${prefix}.2`).ldmia(1, [3]).stmia(0, [3]);
  t.label(`${prefix}.2`).lslsImm(2, 2, 1).bcc('cc', `${prefix}.1`).ldrh(3, 1).strh(3, 0).addsImm(1, 2).addsImm(0, 2);
  t.label(`${prefix}.1`).lslsImm(2, 2, 1).bcc('cc', `${prefix}.done`).ldrb(3, 1).strb(3, 0);
  return t.label(`${prefix}.done`).pop([4, 5, 6]);
}

// Stores the byte r1 at r0 onwards, r2 times (any number, r3 spent).
function storeBytes(t, prefix) {
  return t
    .cmpImm(2, 0)
    .bcc('eq', `${prefix}.bytes.done`)
    .label(`${prefix}.byte`)
    .subsImm(2, 1)
    .strbReg(1, 0, 2)
    .bcc('ne', `${prefix}.byte`)
    .label(`${prefix}.bytes.done`);
}

// Copies r2 bytes (any number) from r1 onwards to r0 onwards, the last first (r3 spent).
function copyBytes(t, prefix) {
  return t
    .cmpImm(2, 0)
    .bcc('eq', `${prefix}.bytes.done`)
    .label(`${prefix}.byte`)
    .subsImm(2, 1)
    .ldrbReg(3, 1, 2)
    .strbReg(3, 0, 2)
    .bcc('ne', `${prefix}.byte`)
    .label(`${prefix}.bytes.done`);
}

// Both cores' reset: core 0 boots from flash, core 1 waits to be launched.
function start(t) {
  t.label('start').ldrConst(0, SIO_BASE).ldr(1, 0, 0).cmpImm(1, 0).bcc('ne', 'core1.wait');
  // Core 0: 03h reads through XIP, at the ROM's pace.
  t.ldrConst(3, SSI_BASE)
    .movsImm(1, 0)
    .str(1, 3, SSI_SSIENR)
    .movsImm(1, ROM_FLASH_DIVIDER)
    .str(1, 3, SSI_BAUDR)
    .ldrConst(1, CTRLR0_03H)
    .str(1, 3, SSI_CTRLR0)
    .ldrConst(1, SPI_CTRLR0_03H)
    .ldrConst(2, SSI_BASE + SSI_SPI_CTRLR0)
    .str(1, 2)
    .movsImm(1, 1)
    .str(1, 3, SSI_SER)
    .str(1, 3, SSI_SSIENR);
  // boot2 to the top of SRAM, a word at a time.
  t.ldrConst(0, XIP_BASE)
    .ldrConst(1, BOOT2_BASE)
    .movsImm(2, 64)
    .label('boot2.copy')
    .ldmia(0, [3])
    .stmia(1, [3])
    .subsImm(2, 1)
    .bcc('ne', 'boot2.copy');
  // Flush the cache (reading FLUSH waits for it), then boot2 with lr = 0.
  return t
    .ldrConst(0, XIP_CTRL_FLUSH)
    .movsImm(1, 1)
    .str(1, 0)
    .ldr(1, 0)
    .movsImm(1, 0)
    .mov(14, 1)
    .ldrConst(0, BOOT2_BASE | 1)
    .bx(0);
}

// Core 1's wait for launch (r4 the SIO, r7 VTOR's address; no stack).
function core1Wait(t) {
  t.label('core1.wait').ldrConst(4, SIO_BASE).ldrConst(7, VTOR);
  t.label('core1.handshake')
    .ldr(1, 4, FIFO_ST)
    .movsImm(2, FIFO_VLD)
    .alu('tst', 1, 2)
    .bcc('eq', 'core1.empty')
    .ldr(1, 4, FIFO_RD)
    .b('core1.handshake')
    .label('core1.empty')
    .movsImm(0, 0)
    .bl('core1.send')
    .bl('core1.receive')
    .cmpImm(0, 1)
    .bcc('ne', 'core1.handshake')
    .bl('core1.send');
  // The vector table, the stack pointer, the entry: each taken, then echoed.
  const take = (use) => {
    t.bl('core1.receive').cmpImm(0, 0).bcc('eq', 'core1.handshake');
    use();
    t.bl('core1.send');
  };
  take(() => t.str(0, 7));
  take(() => t.msrMsp(0));
  take(() => {});
  t.blx(0).label('core1.done').wfe().b('core1.done');
  // send: r0 into the TX FIFO once it has room, then SEV; r0 kept.
  sleepUntilFifo(t, 'core1.send', FIFO_RDY).str(0, 4, FIFO_WR).sev().bxLr();
  // receive: r0 from the RX FIFO, sleeping until there is a word.
  return sleepUntilFifo(t, 'core1.receive', FIFO_VLD).ldr(0, 4, FIFO_RD).bxLr();
}

// At `label`: WFE until FIFO_ST (r4 the SIO) has `bit` set (r1, r2 spent).
function sleepUntilFifo(t, label, bit) {
  return t
    .label(label)
    .ldr(1, 4, FIFO_ST)
    .movsImm(2, bit)
    .alu('tst', 1, 2)
    .bcc('ne', `${label}.ready`)
    .wfe()
    .b(label)
    .label(`${label}.ready`);
}

/** The ROM image (4096 words) and where each function is. */
export function buildBootrom() {
  const t = new Thumb(CODE_START);
  // rom_table_lookup(table, code): walks (code, address) pairs up to a zero
  // code, 11 cycles a pair, as the real ROM's loop.
  const lookup = t.here;
  t.label('lookup')
    .movsImm(3, 0)
    .ldrh(2, 0)
    .alu('cmp', 2, 3)
    .bcc('eq', 'lookup.missing')
    .ldrh(3, 0, 2)
    .addsImm(0, 4)
    .alu('cmp', 2, 1)
    .bcc('ne', 'lookup')
    .movs(0, 3)
    .bxLr()
    .label('lookup.missing')
    .bkpt(MISSING_FUNCTION_BREAKPOINT)
    .bxLr();
  const addresses = {};
  for (const [letters, write] of Object.entries(FUNCTIONS)) {
    addresses[letters] = t.here;
    write(t);
  }
  const reset = t.here;
  start(t);
  core1Wait(t);
  const code_ = t.bytes();
  const functionTable = align4(CODE_START + code_.length);
  const dataTable = functionTable + 4 * (Object.keys(FUNCTIONS).length + 1);

  const rom = new Uint8Array(ROM_BYTES);
  const view = new DataView(rom.buffer);
  view.setUint32(0x00, BOOT2_BASE, true); // the stack below boot2's copy, as the real ROM's
  view.setUint32(0x04, reset | 1, true);
  rom.set([0x4d, 0x75, 0x01, 0x02], 0x10); // 'M', 'u', 1, version 2 (RP2040 B1 and later)
  view.setUint16(0x14, functionTable, true);
  view.setUint16(0x16, dataTable, true);
  view.setUint16(0x18, lookup | 1, true);
  rom.set(code_, CODE_START);
  let at = functionTable;
  for (const [letters, address] of Object.entries(addresses)) {
    view.setUint16(at, code(letters), true);
    view.setUint16(at + 2, address | 1, true);
    at += 4;
  }
  // Both tables end with a zero code; the data table holds nothing else.
  return { image: new Uint32Array(rom.buffer), functionTable, dataTable, addresses };
}

function align4(n) {
  return (n + 3) & ~3;
}

const BOOT2_BYTES = 256;

/**
 * The real ROM's check before it runs boot2: the last 4 bytes of flash's
 * first 256 are the CRC-32 (MPEG-2: MSB first, no reflection, no final
 * xor) of the 252 before them. An image without a valid boot2 would not
 * start on a real Pico, so it does not start here: throws `error(message)`.
 */
export function checkBoot2(flash, error) {
  let crc = 0xffffffff;
  for (let i = 0; i < BOOT2_BYTES - 4; i++) {
    crc ^= flash[i] << 24;
    for (let bit = 0; bit < 8; bit++) {
      crc = crc & 0x80000000 ? (crc << 1) ^ 0x04c11db7 : crc << 1;
    }
  }
  const stored = new DataView(flash.buffer).getUint32(BOOT2_BYTES - 4, true);
  if (crc >>> 0 !== stored) throw error('no valid boot2 in the first 256 bytes of flash (a real Pico would not start it); see memory.x');
}
