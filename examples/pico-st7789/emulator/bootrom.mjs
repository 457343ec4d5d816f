// A stand-in for the RP2040's boot ROM: the part of it an rp2040-hal
// firmware calls once it runs. The Raspberry Pi ROM image is not on any
// package registry, so this one is written here, in Thumb code the emulator
// runs (its cycles count like the firmware's own).
//
// rp2040-hal (by default, without its `disable-intrinsics` feature) routes
// these compiler intrinsics through the ROM: it reads the table-lookup
// function's address at 0x18 and the function table's at 0x14, looks a
// function up by its two-letter code, and calls it. This ROM answers those
// lookups with its own versions of exactly that family:
//
//   code  ROM function  what calls it
//   MS    memset        __aeabi_memset, __aeabi_memclr
//   S4    memset4       __aeabi_memset4/8, __aeabi_memclr4/8
//   MC    memcpy        __aeabi_memcpy
//   C4    memcpy44      __aeabi_memcpy4/8
//   L3    clz32         __clzsi2 (u32::leading_zeros on Armv6-M)
//   T3    ctz32         __ctzsi2 (u32::trailing_zeros)
//   P3    popcount32    __popcountsi2 (u32::count_ones)
//   R3    reverse32     __rbit (u32::reverse_bits)
//
// Anything else (the flash-programming functions, the soft-float tables,
// reset to USB boot) is not here: looking it up stops the run with an error
// naming the code, never a silent zero.
//
// Invariants: the layout of the real ROM's header (magic at 0x10, version at
// 0x13, 16-bit pointers at 0x14, 0x16, 0x18); the copies are word-wise where
// the real ones are (memset4, memcpy44), byte-wise otherwise, so their costs
// are of the same order as the real ROM's, not equal to them.

import { Thumb } from './thumb.mjs';

/** The breakpoint number the lookup stops at for a code this ROM lacks. */
export const MISSING_FUNCTION_BREAKPOINT = 0x52;

const ROM_BYTES = 16 * 1024;
const CODE_START = 0x100;

/** The two letters of a table code, as the ROM's 16-bit key. */
function code(letters) {
  return letters.charCodeAt(0) | (letters.charCodeAt(1) << 8);
}

/** The two letters of a 16-bit key, for messages. */
export function codeLetters(key) {
  const printable = (c) => (c >= 0x20 && c < 0x7f ? String.fromCharCode(c) : '?');
  return `${printable(key & 0xff)}${printable((key >> 8) & 0xff)}`;
}

// Each function takes its arguments in r0..r2 (AAPCS) and returns in r0.
const FUNCTIONS = {
  // memset(ptr, c, n) -> ptr
  MS: (t) => storeBytes(t.movs(3, 0).cmpImm(2, 0).bcc('eq', 'ms.done'), 'ms').label('ms.done').bxLr(),
  // memset4(ptr, c, n) -> ptr, ptr word-aligned
  S4: (t) =>
    t.movsImm(3, 0xff)
      .alu('ands', 1, 3)
      .lslsImm(3, 1, 8)
      .alu('orrs', 1, 3)
      .lslsImm(3, 1, 16)
      .alu('orrs', 1, 3)
      .movs(3, 0)
      .subsImm(2, 4)
      .bcc('cc', 's4.tail')
      .label('s4.word')
      .str(1, 3)
      .addsImm(3, 4)
      .subsImm(2, 4)
      .bcc('cs', 's4.word')
      .label('s4.tail')
      .addsImm(2, 4)
      .bcc('eq', 's4.done')
      .inline(storeBytes, 's4')
      .label('s4.done')
      .bxLr(),
  // memcpy(dest, src, n) -> dest
  MC: (t) => copyBytes(t.mov(12, 0).cmpImm(2, 0).bcc('eq', 'mc.done'), 'mc').label('mc.done').mov(0, 12).bxLr(),
  // memcpy44(dest, src, n) -> dest, both word-aligned
  C4: (t) =>
    t.mov(12, 0)
      .subsImm(2, 4)
      .bcc('cc', 'c4.tail')
      .label('c4.word')
      .ldmia(1, [3])
      .stmia(0, [3])
      .subsImm(2, 4)
      .bcc('cs', 'c4.word')
      .label('c4.tail')
      .addsImm(2, 4)
      .bcc('eq', 'c4.done')
      .inline(copyBytes, 'c4')
      .label('c4.done')
      .mov(0, 12)
      .bxLr(),
  // clz32(x): halving steps; 32 for 0
  L3: (t) => leadingOrTrailing(t, 'l3', 'lsrsImm', 'lslsImm'),
  // ctz32(x): the same steps from the other end
  T3: (t) => leadingOrTrailing(t, 't3', 'lslsImm', 'lsrsImm'),
  // popcount32(x): each bit shifted out into the carry and added
  P3: (t) =>
    t.movsImm(1, 0)
      .movsImm(2, 0)
      .label('p3.bit')
      .lsrsImm(0, 0, 1)
      .alu('adcs', 1, 2)
      .cmpImm(0, 0)
      .bcc('ne', 'p3.bit')
      .movs(0, 1)
      .bxLr(),
  // reverse32(x): each bit shifted out of x into the bottom of the result
  R3: (t) =>
    t.movsImm(1, 0)
      .movsImm(2, 32)
      .label('r3.bit')
      .lsrsImm(0, 0, 1)
      .alu('adcs', 1, 1)
      .subsImm(2, 1)
      .bcc('ne', 'r3.bit')
      .movs(0, 1)
      .bxLr(),
};

// Stores the byte r1 at r3 onwards, r2 times (r2 > 0).
function storeBytes(t, prefix) {
  return t.label(`${prefix}.byte`).strb(1, 3).addsImm(3, 1).subsImm(2, 1).bcc('ne', `${prefix}.byte`);
}

// Copies r2 bytes (r2 > 0) from r1 onwards to r0 onwards.
function copyBytes(t, prefix) {
  return t
    .label(`${prefix}.byte`)
    .ldrb(3, 1)
    .strb(3, 0)
    .addsImm(1, 1)
    .addsImm(0, 1)
    .subsImm(2, 1)
    .bcc('ne', `${prefix}.byte`);
}

// Counts the zero bits at one end of r0 by halving steps: `test` shifts the
// end's 16, 8, 4, 2, 1 bits down to see whether they are all zero; if so they
// are counted and `move` shifts them out.
function leadingOrTrailing(t, prefix, test, move) {
  t.movsImm(1, 0);
  for (const bits of [16, 8, 4, 2, 1]) {
    t[test](2, 0, 32 - bits)
      .bcc('ne', `${prefix}.${bits}`)
      .addsImm(1, bits)
      [move](0, 0, bits)
      .label(`${prefix}.${bits}`);
  }
  // One bit left to test at the end: a zero input counts 32.
  return t[test](2, 0, 31).bcc('ne', `${prefix}.done`).addsImm(1, 1).label(`${prefix}.done`).movs(0, 1).bxLr();
}

/** The ROM image (4096 words) and where each function is. */
export function buildBootrom() {
  const t = new Thumb(CODE_START);
  // rom_table_lookup(table, code): walks (code, address) pairs up to a zero code.
  const lookup = t.here;
  t.label('lookup')
    .ldrh(2, 0)
    .cmpImm(2, 0)
    .bcc('eq', 'lookup.missing')
    .alu('cmp', 2, 1)
    .bcc('eq', 'lookup.found')
    .addsImm(0, 4)
    .b('lookup')
    .label('lookup.found')
    .ldrh(0, 0, 2)
    .bxLr()
    .label('lookup.missing')
    .bkpt(MISSING_FUNCTION_BREAKPOINT)
    .bxLr();
  const addresses = {};
  for (const [letters, write] of Object.entries(FUNCTIONS)) {
    addresses[letters] = t.here;
    write(t);
  }
  const code_ = t.bytes();
  const functionTable = align4(CODE_START + code_.length);
  const dataTable = functionTable + 4 * (Object.keys(FUNCTIONS).length + 1);

  const rom = new Uint8Array(ROM_BYTES);
  const view = new DataView(rom.buffer);
  // Never run: the runner starts the firmware at its own vector table.
  view.setUint32(0x00, 0x20042000, true);
  view.setUint32(0x04, lookup | 1, true);
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
