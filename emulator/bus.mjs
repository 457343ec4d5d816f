// Each core's view of memory: every load, store and instruction fetch
// rp2040js's core makes (it calls its own readUint32/16/8 and
// writeUint32/16/8 for all of them) goes through this core's bus, which
// sends the SIO (0xd0000000) and the PPB (0xe000e000) to the core's own, the
// flash aliases (0x10000000-0x13ffffff) through the shared XIP cache, the
// XIP cache's SRAM (0x15000000) to the cache, SRAM straight to memory
// (checked against the core's MPU when it restricts anything), peripheral
// loads straight to rp2040js's blocks; the rest (ROM, USB RAM, peripheral
// stores with their atomic aliases) is rp2040js's.
//
// Every load and store that reaches the crossbar (all but the SIO's and the
// PPB's) is arbitrated on the bus fabric (fabric.mjs) in its cycle: the
// instruction's first cycle plus the loads and stores it made before (the
// core's `slot`, which armv6m.mjs sets below zero for the reads that fetch
// the instruction itself: those it arbitrates as fetches). A stall delays
// the rest of the instruction.
//
// Invariants: no core access to flash bypasses the XIP cache (rp2040js's own
// shortcuts to the flash array are never taken for a core); a store to the
// flash changes no flash byte; a store to the ROM and an unaligned 32-bit
// access are errors (faults on the chip); `peek16` reads without counting
// or stalling anything (for the emulator's own look at an instruction);
// each load or store counts one slot, once (the narrow reads the bus
// widens count in the word read).

import { RunError } from './errors.mjs';
import { MPU_GRANULE_BITS, MPU_NO_ACCESS } from './ppb.mjs';
import { ALIAS_CACHED, CACHE_BYTES } from './xip.mjs';
import { DATA, NO_PORT, Port, portOf, sramPort } from './fabric.mjs';

const ROM_END = 0x4000;
const FLASH_BASE = 0x10000000;
const XIP_END = 0x14000000;
const XIP_SRAM = 0x15;
const SRAM_BASE = 0x20000000;
/** SRAM0 to SRAM3 unstriped, 64 KiB each (datasheet 2.6.2). */
const UNSTRIPED_BASE = 0x21000000;
const UNSTRIPED_END = 0x21040000;
const APB_BASE = 0x40000000;
const SIO_BASE = 0xd0000000;
const SIO_END = 0xe0000000;
const PPB_PAGE = 0xe000e;

/**
 * Routes core `index`'s accesses: rp2040 is rp2040js's chip, xip the
 * cache, sio and ppb this core's own, fabric the crossbar its loads and
 * stores are arbitrated on.
 */
export function installBus(core, index, { rp2040, xip, sio, ppb, fabric }) {
  const sram = rp2040.sram;
  const sramView = rp2040.sramView;
  const sramEnd = SRAM_BASE + sram.length;
  const flash = rp2040.flash;
  const flashView = rp2040.flashView;
  const peripherals = rp2040.peripherals;
  const xipSramView = new DataView(xip.sram.buffer);
  const tags = xip.tags;
  const accesses = xip.accesses;
  // A load or store on `port` in its slot of the instruction (a fetch's read, below slot 0, is not one).
  const arbitrate = (port) => {
    const slot = core.slot++;
    if (slot < 0 || port === NO_PORT) return;
    const waited = fabric.access(index, port, core.cycles + slot, DATA);
    if (waited !== 0) core.cycles += waited;
  };
  // An instruction fetch or load from flash: a hit through 0x10 costs a lookup; the rest is the cache's.
  const flashRead = (address) => {
    const offset = address & 0xffffff;
    if (address >>> 24 === ALIAS_CACHED && xip.cachingEnabled) {
      accesses[index]++;
      const set = (offset >>> 2) & 0x7fe;
      const tag = offset >>> 13;
      if (tags[set] !== tag && tags[set + 1] !== tag) xip.miss(set, tag, index);
    } else {
      xip.read(address >>> 24, offset, index);
    }
    return offset;
  };
  const unaligned = (address, store) => {
    const access = store ? 'store to' : 'load from';
    throw new RunError(`core ${index}: a 32-bit ${access} 0x${address.toString(16)}, not word-aligned (a HardFault on the M0+)`);
  };

  const mpuFault = (address, store) => {
    const [start, end] = ppb.restrictedSpan(address);
    const noAccess = ppb.mpuMap[(address - SRAM_BASE) >>> MPU_GRANULE_BITS] === MPU_NO_ACCESS;
    const range = `0x${start.toString(16)}-0x${end.toString(16)}`;
    const at = `0x${address.toString(16)}`;
    if (store && noAccess) {
      throw new RunError(`core ${index} overflowed its stack: a store to ${at} hit its MPU guard (${range}, no access)`);
    }
    const access = store ? 'store to' : 'load from';
    throw new RunError(`core ${index}: a ${access} ${at} is a fault in MPU region ${range} (${noAccess ? 'no access' : 'read-only'})`);
  };
  // An SRAM address the MPU forbids: a load from a no-access granule, a store to any restricted one.
  const checkLoad = (address) => {
    if (loadForbidden(ppb, address)) mpuFault(address, false);
  };
  const checkStore = (address) => {
    const map = ppb.mpuMap;
    if (map !== null && map[(address - SRAM_BASE) >>> MPU_GRANULE_BITS] !== 0) mpuFault(address, true);
  };

  const readUint32 = (address) => {
    address >>>= 0;
    if (address & 3) unaligned(address, false);
    if (address >= SRAM_BASE && address < sramEnd) {
      checkLoad(address);
      arbitrate(sramPort(address));
      return sramView.getUint32(address - SRAM_BASE, true);
    }
    if (address >= UNSTRIPED_BASE && address < UNSTRIPED_END) return readUint32(striped(address));
    arbitrate(portOf(address));
    if (address >= FLASH_BASE && address < XIP_END) return flashView.getUint32(flashRead(address), true);
    if (address >= SIO_BASE && address < SIO_END) return sio.readUint32(address - SIO_BASE);
    if (address >>> 12 === PPB_PAGE) return ppb.readUint32(address & 0xfff);
    if (address >>> 24 === XIP_SRAM) return xipSramView.getUint32(xip.sramAt(address, index), true);
    if (address >= APB_BASE && address < SIO_BASE) {
      const peripheral = peripherals[(address >>> 14) << 2];
      if (peripheral) return peripheral.readUint32(address & 0x3fff);
    }
    return rp2040.readUint32(address);
  };

  const readUint16 = (address) => {
    address >>>= 0;
    if (address >= FLASH_BASE && address < XIP_END) {
      arbitrate(Port.XIP);
      return flashView.getUint16(flashRead(address), true);
    }
    if (address >= SRAM_BASE && address < sramEnd) {
      checkLoad(address);
      arbitrate(sramPort(address));
      return sramView.getUint16(address - SRAM_BASE, true);
    }
    const word = readUint32(address & ~3);
    return address & 2 ? word >>> 16 : word & 0xffff;
  };

  const readUint8 = (address) => {
    address >>>= 0;
    if (address >= SRAM_BASE && address < sramEnd) {
      checkLoad(address);
      arbitrate(sramPort(address));
      return sram[address - SRAM_BASE];
    }
    if (address >= FLASH_BASE && address < XIP_END) {
      arbitrate(Port.XIP);
      return flash[flashRead(address)];
    }
    return (readUint32(address & ~3) >>> ((address & 3) * 8)) & 0xff;
  };

  /** A store outside SRAM, of `bits` bits: true when handled here, false for rp2040js to take. */
  const storeElsewhere = (address, value, bits) => {
    arbitrate(portOf(address));
    if (address >= FLASH_BASE && address < XIP_END) {
      xip.write(address >>> 24, address & 0xffffff, index);
      return true;
    }
    if (address < ROM_END) {
      throw new RunError(`core ${index}: a store to the boot ROM at 0x${address.toString(16)} (a bus fault on the chip)`);
    }
    if (address >= SIO_BASE && address < SIO_END) {
      if (bits !== 32) sio.narrowWrite(address - SIO_BASE, bits);
      sio.writeUint32(address - SIO_BASE, value);
      return true;
    }
    if (address >>> 12 === PPB_PAGE) {
      // A narrower store to the PPB merges into its word, as rp2040js does for core 0.
      const aligned = address & 0xffc;
      const shift = (address & 3) * 8;
      const mask = bits === 32 ? 0xffffffff : ((1 << bits) - 1) << shift;
      const merged = bits === 32 ? value : (ppb.readUint32(aligned) & ~mask) | ((value << shift) & mask);
      ppb.writeUint32(aligned, merged >>> 0);
      return true;
    }
    if (address >>> 24 === XIP_SRAM) {
      const at = xip.sramAt(address, index);
      if (bits === 32) xipSramView.setUint32(at, value, true);
      else if (bits === 16) xipSramView.setUint16(at, value, true);
      else xipSramView.setUint8(at, value);
      return true;
    }
    return false;
  };

  core.sramFetch = { end: sramEnd, ppb };
  core.readUint32 = readUint32;
  core.readUint16 = readUint16;
  core.readUint8 = readUint8;
  core.writeUint32 = (address, value) => {
    address >>>= 0;
    if (address & 3) unaligned(address, true);
    if (address >= SRAM_BASE && address < sramEnd) {
      checkStore(address);
      arbitrate(sramPort(address));
      sramView.setUint32(address - SRAM_BASE, value, true);
    } else if (address >= UNSTRIPED_BASE && address < UNSTRIPED_END) {
      core.writeUint32(striped(address), value);
    } else if (!storeElsewhere(address, value, 32)) {
      rp2040.writeUint32(address, value);
    }
  };
  core.writeUint16 = (address, value) => {
    address >>>= 0;
    if (address >= SRAM_BASE && address < sramEnd) {
      checkStore(address);
      arbitrate(sramPort(address));
      sramView.setUint16(address - SRAM_BASE, value, true);
    } else if (address >= UNSTRIPED_BASE && address < UNSTRIPED_END) {
      core.writeUint16(striped(address), value);
    } else if (!storeElsewhere(address, value & 0xffff, 16)) {
      rp2040.writeUint16(address, value);
    }
  };
  core.writeUint8 = (address, value) => {
    address >>>= 0;
    if (address >= SRAM_BASE && address < sramEnd) {
      checkStore(address);
      arbitrate(sramPort(address));
      sram[address - SRAM_BASE] = value;
    } else if (address >= UNSTRIPED_BASE && address < UNSTRIPED_END) {
      core.writeUint8(striped(address), value);
    } else if (!storeElsewhere(address, value & 0xff, 8)) {
      rp2040.writeUint8(address, value);
    }
  };
}

/** The striped address of a byte of SRAM0-3's unstriped alias: bank b's word n is the striped word 4n + b. */
function striped(address) {
  const offset = address - UNSTRIPED_BASE;
  const bank = offset >>> 16;
  const word = (offset & 0xffff) >>> 2;
  return SRAM_BASE + ((word * 4 + bank) << 2) + (address & 3);
}

/**
 * Whether core `core`'s fetch of the instruction at `pc`, of `halfwords`
 * halfwords, is a plain read of SRAM that the MPU allows: then the read
 * itself tells nothing (`peek16` has the opcode) and only its slot is
 * counted, which a fetch's read takes below slot 0 without arbitrating
 * (the fabric arbitrates the fetch's word, armv6m.mjs); else (flash, the
 * ROM, a fault to raise, or a core without this bus) the fetch is the
 * bus's own read. Half of all reads are fetches: made through the bus,
 * they took about a tenth of the emulator's time.
 */
export function plainSramFetch(core, pc, halfwords) {
  const sram = core.sramFetch;
  if (sram === undefined || pc < SRAM_BASE || pc + 2 * halfwords > sram.end) return false;
  // Each halfword as the bus's read would check it.
  return !loadForbidden(sram.ppb, pc) && (halfwords === 1 || !loadForbidden(sram.ppb, pc + 2));
}

/** Whether the MPU of `ppb` forbids a load from the SRAM address `address` (a no-access granule). */
function loadForbidden(ppb, address) {
  const map = ppb.mpuMap;
  return map !== null && map[(address - SRAM_BASE) >>> MPU_GRANULE_BITS] === MPU_NO_ACCESS;
}

/**
 * The halfword at `address` of `memory` (the machine's: rp2040js's flash,
 * SRAM and ROM, the XIP cache's SRAM), read without counting, stalling or
 * side effects: the emulator's own look at an instruction, the same for
 * every core.
 */
export function peek16(memory, address) {
  address >>>= 0;
  if (address >= FLASH_BASE && address < XIP_END) return memory.flashView.getUint16(address & 0xffffff, true);
  if (address >= SRAM_BASE && address < memory.sramEnd) return memory.sramView.getUint16(address - SRAM_BASE, true);
  if (address < ROM_END) return memory.rom.getUint16(address, true);
  if (address >>> 24 === XIP_SRAM) return memory.xipSramView.getUint16(address & (CACHE_BYTES - 2), true);
  throw new RunError(`executing from 0x${address.toString(16)}, where the emulator runs no code`);
}

/** The machine's memories, as `peek16` reads them. */
export function machineMemory(rp2040, xip) {
  return {
    flashView: rp2040.flashView,
    sramView: rp2040.sramView,
    sramEnd: SRAM_BASE + rp2040.sram.length,
    rom: new DataView(rp2040.bootrom.buffer),
    xipSramView: new DataView(xip.sram.buffer),
  };
}
