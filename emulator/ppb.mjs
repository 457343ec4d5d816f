// Each core's private peripheral bus (0xe000e000, Cortex-M0+ System Control
// Space): rp2040js's NVIC, SysTick and SCB (VTOR, ICSR, SHPR) acting on this
// core, plus what rp2040js lacks: the SCR and the MPU (8 regions), which
// rp2040-hal's core 1 start-up programs as a stack guard.
//
// The MPU is enforced on SRAM, for privileged accesses (the firmware's
// thread and handler modes), per 32-byte subregion: a region with AP 000
// (no access) faults any load, store or fetch in it, AP 101-111 (read-only)
// faults stores; a higher-numbered region wins where regions overlap, and
// PRIVDEFENA's default map allows the rest. A fault ends the run (a real
// Pico takes a HardFault): a store into a no-access region is reported as
// the stack overflow rp2040-hal's guard is there to catch.
//
// Invariants: core 0's NVIC, SysTick and SCB are rp2040js's own (`rp2040.ppb`),
// so a one-core firmware sees today's PPB; an MPU or SCR set-up the model
// cannot enforce (no PRIVDEFENA, a restricting region outside SRAM, a
// reserved AP, SLEEPONEXIT, SEVONPEND) is an error, never ignored.

import { RunError } from './errors.mjs';

const SCR = 0xd10;
const SCR_SLEEPONEXIT = 1 << 1;
const SCR_SLEEPDEEP = 1 << 2;
const SCR_SEVONPEND = 1 << 4;
const MPU_TYPE = 0xd90;
const MPU_CTRL = 0xd94;
const MPU_RNR = 0xd98;
const MPU_RBAR = 0xd9c;
const MPU_RASR = 0xda0;
const MPU_REGIONS = 8;
const CTRL_ENABLE = 1 << 0;
const CTRL_PRIVDEFENA = 1 << 2;
const RBAR_VALID = 1 << 4;

/** What a 32-byte granule of SRAM allows: every access, loads only, nothing. */
const MPU_ALLOWED = 0;
const MPU_READ_ONLY = 1;
export const MPU_NO_ACCESS = 2;
export const MPU_GRANULE_BITS = 5;

export class CorePpb {
  /** `nvic`: rp2040js's PPB block acting on this core. `sram`: { base, bytes }. */
  constructor(index, nvic, sram) {
    Object.assign(this, { index, nvic, sram });
    this.reset();
  }

  /** The core's reset: SCR and MPU cleared, SysTick stopped. */
  reset() {
    this.scr = 0;
    this.mpuCtrl = 0;
    this.mpuRegion = 0;
    this.rbar = new Uint32Array(MPU_REGIONS);
    this.rasr = new Uint32Array(MPU_REGIONS);
    /** Per 32-byte granule of SRAM, MPU_ALLOWED, _READ_ONLY or _NO_ACCESS; null when nothing is restricted. */
    this.mpuMap = null;
    this.nvic.reset();
  }

  readUint32(offset) {
    switch (offset) {
      case SCR:
        return this.scr;
      case MPU_TYPE:
        return MPU_REGIONS << 8;
      case MPU_CTRL:
        return this.mpuCtrl;
      case MPU_RNR:
        return this.mpuRegion;
      case MPU_RBAR:
        return (this.rbar[this.mpuRegion] | this.mpuRegion) >>> 0;
      case MPU_RASR:
        return this.rasr[this.mpuRegion];
    }
    return this.nvic.readUint32(offset);
  }

  writeUint32(offset, value) {
    switch (offset) {
      case SCR:
        if (value & (SCR_SLEEPONEXIT | SCR_SEVONPEND)) {
          throw new RunError(`core ${this.index}: SCR 0x${value.toString(16)}: SLEEPONEXIT and SEVONPEND are not modelled`);
        }
        this.scr = value & SCR_SLEEPDEEP;
        return;
      case MPU_CTRL:
        this.mpuCtrl = value & 7;
        break;
      case MPU_RNR:
        this.mpuRegion = value & (MPU_REGIONS - 1);
        return;
      case MPU_RBAR:
        if (value & RBAR_VALID) this.mpuRegion = value & (MPU_REGIONS - 1);
        this.rbar[this.mpuRegion] = value & ~0xff;
        break;
      case MPU_RASR:
        this.rasr[this.mpuRegion] = value;
        break;
      default:
        this.nvic.writeUint32(offset, value);
        return;
    }
    this.mpuMap = this.mapSram();
  }

  /** What the MPU allows in SRAM, granule by granule (null: everything). */
  mapSram() {
    if (!(this.mpuCtrl & CTRL_ENABLE)) {
      return null;
    }
    if (!(this.mpuCtrl & CTRL_PRIVDEFENA)) {
      throw new RunError(`core ${this.index}: MPU enabled without PRIVDEFENA (no default memory map) is not modelled`);
    }
    const { base: sramBase, bytes: sramBytes } = this.sram;
    const map = new Uint8Array(sramBytes >>> MPU_GRANULE_BITS);
    let restricted = false;
    for (let region = 0; region < MPU_REGIONS; region++) {
      const rasr = this.rasr[region];
      if (!(rasr & 1)) continue;
      const sizeField = (rasr >>> 1) & 0x1f;
      const ap = (rasr >>> 24) & 7;
      if (sizeField < 7 || ap === 4) {
        throw new RunError(
          `core ${this.index}: MPU region ${region}: RASR 0x${rasr.toString(16)} is unpredictable on the Cortex-M0+ (SIZE < 7 or AP 100)`,
        );
      }
      const size = 2 ** (sizeField + 1);
      const base = this.rbar[region] - (this.rbar[region] % size);
      const access = ap === 0 ? MPU_NO_ACCESS : ap >= 5 ? MPU_READ_ONLY : MPU_ALLOWED;
      for (let subregion = 0; subregion < 8; subregion++) {
        if ((rasr >>> (8 + subregion)) & 1) continue; // SRD: this eighth falls through
        const start = base + (subregion * size) / 8;
        const end = start + size / 8;
        if (access !== MPU_ALLOWED && (start < sramBase || end > sramBase + sramBytes)) {
          throw new RunError(
            `core ${this.index}: MPU region ${region} restricts 0x${start.toString(16)}..0x${end.toString(16)}: the emulator enforces the MPU in SRAM only`,
          );
        }
        const first = Math.max(start, sramBase) - sramBase;
        const last = Math.min(end, sramBase + sramBytes) - sramBase;
        if (last > first) {
          map.fill(access, first >>> MPU_GRANULE_BITS, last >>> MPU_GRANULE_BITS);
          restricted ||= access !== MPU_ALLOWED;
        }
      }
    }
    return restricted ? map : null;
  }

  /** The span of SRAM around `address` the MPU restricts the same way: [start, end). */
  restrictedSpan(address) {
    const { base } = this.sram;
    const map = this.mpuMap;
    let first = (address - base) >>> MPU_GRANULE_BITS;
    let last = first;
    while (first > 0 && map[first - 1] === map[last]) first--;
    while (last + 1 < map.length && map[last + 1] === map[first]) last++;
    return [base + (first << MPU_GRANULE_BITS), base + ((last + 1) << MPU_GRANULE_BITS)];
  }
}
