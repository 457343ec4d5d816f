// The RP2040's execute-in-place cache (datasheet 2.6.3), shared by both
// cores and by instruction fetches and data loads alike: 16 KiB, two-way set
// associative, 8-byte lines (1024 sets: address bits 12:3 pick the set,
// 23:13 are the tag), a hit costing nothing beyond the bus access the core
// makes anyway. The flash aliases:
//
//   0x10...  cached, allocating: a miss reads the line and keeps it
//   0x11...  cached, non-allocating: a miss reads the line, keeps nothing
//   0x12...  non-cached, allocating: always reads, and keeps the line
//   0x13...  non-cached, non-allocating: always reads, cache untouched
//
// With CTRL.EN clear (or POWER_DOWN set) every alias reads the flash and the
// cache's 16 KiB is SRAM at 0x15000000 (mirrored through 0x15ffffff); with
// it set, that alias is a bus error. A store to 0x10... removes the line if
// cached (the datasheet's invalidate by address) and changes no flash byte;
// a store to 0x11...-0x13... is a bus fault while CTRL.ERR_BADWRITE is set
// (its reset value), else ignored.
//
// Replacement: an empty way first, else a pseudo-random one. The RP2040
// datasheet states no policy; the RP2350's (the same XIP design, 4.4.1)
// states "cache eviction policy is random", so a fixed-seed xorshift picks
// the way: runs stay deterministic.
//
// Timing: a line read (a miss, or any non-cached access) stalls the reading
// core for the QSPI transfer xip-timing.mjs computes from the SSI. The QSPI
// serves one read at a time: a core missing while the other core's read is
// in flight waits for it to end first. A FLUSH (write 1) clears every tag
// and takes 1024 cycles (16 KiB / 8 bytes / 2 ways), during which flash
// reads wait; reading FLUSH waits for the flush to end.
//
// Each line read is 8 bytes, also for non-cached accesses. Accesses are
// counted as the emulated core makes them (a 16-bit instruction fetch each;
// the real M0+ fetches 32 bits at a time), so CTR_ACC and CTR_HIT count
// more accesses than the chip's would; misses and stalls are the chip's.
//
// Invariants: the cache holds tags only (the flash is never written during a
// run, so a line's data is the flash's); every core access to the four
// aliases is counted here (the bus looks up a 0x10 hit itself, with these
// tags and counts, and hands the rest to `read` and `miss`), so no flash
// read escapes the count; the streaming FIFO (STREAM_ADDR, STREAM_CTR,
// STREAM_FIFO) is not modelled and touching it is an error.

import { BasePeripheral } from 'rp2040js';
import { RunError } from './errors.mjs';

const SETS = 1024;
const WAYS = 2;
export const CACHE_BYTES = SETS * WAYS * 8;
const FLUSH_CYCLES = SETS;
const EMPTY = -1;

const CTRL_EN = 1 << 0;
const CTRL_ERR_BADWRITE = 1 << 1;
const CTRL_POWER_DOWN = 1 << 3;
const CTRL = 0x00;
const FLUSH = 0x04;
const STAT = 0x08;
const CTR_HIT = 0x0c;
const CTR_ACC = 0x10;
const STAT_FLUSH_READY = 1 << 0;
const STAT_FIFO_EMPTY = 1 << 1;
const SATURATED = 0xffffffff;

export const ALIAS_CACHED = 0x10;
const ALIAS_NONALLOCATING = 0x11;
const ALIAS_UNCACHED_ALLOCATING = 0x12;

export class XipCache {
  /** `ssi` times and frames the line reads; `cores` is the machine's pair of cores (each with `cycles`). */
  constructor(ssi, cores) {
    this.ssi = ssi;
    this.cores = cores;
    /** tags[2·set + way], EMPTY when invalid. */
    this.tags = new Int32Array(SETS * WAYS).fill(EMPTY);
    this.random = 0x2545f491;
    this.ctrl = CTRL_EN | CTRL_ERR_BADWRITE;
    this.cachingEnabled = true;
    this.sram = new Uint8Array(CACHE_BYTES);
    /** When the QSPI is next free, in machine cycles. */
    this.qspiFreeAt = 0;
    this.flushDoneAt = 0;
    // Per core: accesses, line reads (each access is a hit or a line read), cycles stalled on them.
    this.accesses = new Float64Array(2);
    this.lineReads = new Float64Array(2);
    this.stalls = new Float64Array(2);
    this.counterBase = { accesses: 0, hits: 0 };
  }

  /**
   * Core `k` reads the flash at `offset` through alias `alias` (0x10 to
   * 0x13, the address's top byte): counts it and stalls the core for a line
   * read if there is one. (The bus inlines the first case: a hit through
   * 0x10 with caching on.)
   */
  read(alias, offset, k) {
    this.accesses[k]++;
    const set = (offset >>> 2) & 0x7fe;
    const tag = offset >>> 13;
    const tags = this.tags;
    if (alias === ALIAS_CACHED && this.cachingEnabled) {
      if (tags[set] !== tag && tags[set + 1] !== tag) this.miss(set, tag, k);
      return;
    }
    if (this.cachingEnabled) {
      const way = tags[set] === tag ? set : tags[set + 1] === tag ? set + 1 : EMPTY;
      if (alias === ALIAS_NONALLOCATING && way !== EMPTY) {
        return;
      }
      if (alias === ALIAS_UNCACHED_ALLOCATING) {
        // "Don't check for hit, always update cache": the line is read and (re)filled.
        tags[way === EMPTY ? this.victim(set) : way] = tag;
      }
    }
    this.lineRead(k);
  }

  /** A miss through the allocating alias: the line is read and replaces a way of `set`. */
  miss(set, tag, k) {
    this.tags[this.victim(set)] = tag;
    this.lineRead(k);
  }

  /** The way of set `set` (its first tag's index) a new line replaces. */
  victim(set) {
    if (this.tags[set] === EMPTY) return set;
    if (this.tags[set + 1] === EMPTY) return set + 1;
    let x = this.random;
    x ^= x << 13;
    x ^= x >>> 17;
    x ^= x << 5;
    this.random = x;
    return set + (x & 1);
  }

  /** Core k waits for the QSPI, then for its line. */
  lineRead(k) {
    const core = this.cores[k];
    const now = core.cycles;
    const end = Math.max(now, this.qspiFreeAt) + this.ssi.xipTransfer();
    this.qspiFreeAt = end;
    this.lineReads[k]++;
    this.stalls[k] += end - now;
    core.cycles = end;
  }

  /** A store to the flash aliases: invalidates by address (0x10), or faults or is ignored (0x11-0x13). */
  write(alias, offset, k) {
    if (alias === ALIAS_CACHED) {
      if (this.cachingEnabled) {
        const set = (offset >>> 2) & 0x7fe;
        const tag = offset >>> 13;
        if (this.tags[set] === tag) this.tags[set] = EMPTY;
        if (this.tags[set + 1] === tag) this.tags[set + 1] = EMPTY;
      }
    } else if (this.ctrl & CTRL_ERR_BADWRITE) {
      throw new RunError(
        `core ${k}: a store to the flash alias 0x${((alias << 24) | offset).toString(16)} is a bus fault (XIP_CTRL.ERR_BADWRITE)`,
      );
    }
  }

  /** The cache's memory as SRAM (0x15...): only while caching is off. */
  sramAt(address, k) {
    if (this.cachingEnabled || this.ctrl & CTRL_POWER_DOWN) {
      throw new RunError(
        `core ${k}: 0x${address.toString(16)} (the XIP cache as SRAM) is a bus error ` +
          `while the cache is ${this.cachingEnabled ? 'enabled' : 'powered down'}`,
      );
    }
    return address & (CACHE_BYTES - 1);
  }

  /** Starts a flush at time `now`: every tag cleared, flash reads held off for its duration. */
  flush(now) {
    this.tags.fill(EMPTY);
    this.flushDoneAt = Math.max(now, this.flushDoneAt) + FLUSH_CYCLES;
    this.qspiFreeAt = Math.max(this.qspiFreeAt, this.flushDoneAt);
  }

  setCtrl(value) {
    this.ctrl = value & (CTRL_EN | CTRL_ERR_BADWRITE | CTRL_POWER_DOWN);
    if (this.ctrl & CTRL_POWER_DOWN) this.ctrl &= ~CTRL_EN;
    this.cachingEnabled = (this.ctrl & CTRL_EN) !== 0;
  }

  /** All cores' accesses, or hits (accesses that read no line). */
  total(name) {
    const accesses = this.accesses[0] + this.accesses[1];
    return name === 'accesses' ? accesses : accesses - this.lineReads[0] - this.lineReads[1];
  }

  /** CTR_ACC or CTR_HIT: counts since they were last cleared, saturating at 2³² - 1. */
  counter(name) {
    return Math.min(this.total(name) - this.counterBase[name], SATURATED);
  }

  clearCounter(name) {
    this.counterBase[name] = this.total(name);
  }

  /** Totals and per-core figures for the report. */
  statistics(lineCycles) {
    const perCore = [0, 1].map((k) => ({
      accesses: this.accesses[k],
      hits: this.accesses[k] - this.lineReads[k],
      misses: this.lineReads[k],
      stallCycles: this.stalls[k],
    }));
    const sum = (key) => perCore[0][key] + perCore[1][key];
    return {
      lineReadCycles: lineCycles,
      accesses: sum('accesses'),
      hits: sum('hits'),
      misses: sum('misses'),
      stallCycles: sum('stallCycles'),
      byCore: perCore,
    };
  }
}

/** XIP_CTRL (0x14000000): the cache's control, flush, status and counters. */
export class XipControl extends BasePeripheral {
  /** `now()`: the machine's time; `stall(cycles)` holds the accessing core. */
  constructor(rp2040, cache, now, stall) {
    super(rp2040, 'XIP_CTRL');
    Object.assign(this, { cache, now, stall });
  }

  readUint32(offset) {
    const cache = this.cache;
    switch (offset) {
      case CTRL:
        return cache.ctrl;
      case FLUSH: {
        const wait = cache.flushDoneAt - this.now();
        if (wait > 0) this.stall(wait);
        return 0;
      }
      case STAT:
        return (this.now() >= cache.flushDoneAt ? STAT_FLUSH_READY : 0) | STAT_FIFO_EMPTY;
      case CTR_HIT:
        return cache.counter('hits');
      case CTR_ACC:
        return cache.counter('accesses');
    }
    return this.unmodelled(offset);
  }

  writeUint32(offset, value) {
    const cache = this.cache;
    switch (offset) {
      case CTRL:
        cache.setCtrl(value);
        return;
      case FLUSH:
        if (value & 1) cache.flush(this.now());
        return;
      case STAT:
        return; // read-only
      case CTR_HIT:
        cache.clearCounter('hits');
        return;
      case CTR_ACC:
        cache.clearCounter('accesses');
        return;
    }
    this.unmodelled(offset);
  }

  unmodelled(offset) {
    throw new RunError(`XIP_CTRL 0x${(0x14000000 + offset).toString(16)}: the streaming FIFO is not modelled`);
  }
}
