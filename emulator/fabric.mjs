// The RP2040's bus fabric (datasheet 2.1): the main AHB-Lite crossbar's ten
// downstream ports, each with its arbiter, between the masters that share
// them, and BUSCTRL's priority and performance counters (2.1.1.1, 2.1.1.2).
//
// Ports, numbered as BUSCTRL's PERFSEL events number them (event 2p + 1
// counts port p's accesses, 2p its contested ones): APB (the bridge to every
// APB peripheral), the fast AHB-Lite peripherals (PIO, USB, the DMA's and
// XIP's registers), SRAM5, SRAM4, SRAM3 to SRAM0, flash XIP and ROM. The
// main SRAM (0x20000000-0x2003ffff) is striped (2.6.2): word address bits
// 3:2 pick SRAM0 to SRAM3, so consecutive words lie in different banks;
// 0x21000000 aliases the four banks unstriped. The SIO and each core's PPB
// are not on the crossbar (each core reaches its SIO through its own
// single-cycle IOPORT, 2.3.1): no port, never contested.
//
// Arbitration, per port and per cycle: a master addresses a port in one
// cycle (an AHB-Lite address phase); "the bus fabric does not add wait
// states to any AHB-Lite slave access" (2.1), so masters on different
// ports never wait, and of two masters addressing one port in the same
// cycle one is granted and the other stalls for that cycle and asks again
// in the next. Who is granted: a high-priority master before a low-priority
// one (BUS_PRIORITY); between masters of one level, "the arbiter grants
// access to each master in turn" (2.1.1.1): here, the master that lost the
// port's last contest wins its next one.
//
// Cores are emulated one instruction at a time, the one behind first, so a
// core's access in cycle c is checked against every access the other core
// made in cycle c, which the other (being ahead) has already recorded; an
// access the other core has not reached yet is checked when it makes it.
// Every pair of simultaneous accesses to a port is thus seen exactly once,
// by the later of the two in emulation order. When the core already ahead
// is the one to lose, it is stalled after the fact: its cycle count grows
// by one and its accesses from that cycle on move a cycle later (its
// instructions' results do not depend on when, within a few cycles, their
// accesses were granted).
//
// Invariants: each master makes at most one access a cycle (its records
// are indexed by cycle); records reach back RING cycles, more than two
// cores ever drift apart while both run; with contention off every access
// is granted at once and still counted (the counters' `access` events), and
// nothing is contested.

import { BasePeripheral } from 'rp2040js';
import { RunError } from './errors.mjs';

/** The crossbar's downstream ports, in BUSCTRL's event order. */
export const Port = Object.freeze({
  APB: 0,
  FASTPERI: 1,
  SRAM5: 2,
  SRAM4: 3,
  SRAM3: 4,
  SRAM2: 5,
  SRAM1: 6,
  SRAM0: 7,
  XIP: 8,
  ROM: 9,
});
export const PORT_NAMES = ['apb', 'fastperi', 'sram5', 'sram4', 'sram3', 'sram2', 'sram1', 'sram0', 'xip_main', 'rom'];
const PORTS = PORT_NAMES.length;
/** No port: the SIO (IOPORT) and the PPB, which never wait for another master. */
export const NO_PORT = -1;

const SRAM_BASE = 0x20000000;
const STRIPED_END = 0x20040000;
const SRAM5_BASE = 0x20041000;
const SRAM_END = 0x20042000;
const UNSTRIPED_BASE = 0x21000000;
const UNSTRIPED_END = 0x21040000;

/** The port a (32-bit, unsigned) address is on. */
export function portOf(address) {
  if (address >= SRAM_BASE && address < SRAM_END) return sramPort(address);
  if (address < 0x10000000) return Port.ROM;
  if (address < 0x20000000) return Port.XIP;
  if (address >= UNSTRIPED_BASE && address < UNSTRIPED_END) return Port.SRAM0 - ((address >>> 16) & 3);
  const top = address >>> 28;
  if (top === 4) return Port.APB;
  if (top === 5) return Port.FASTPERI;
  return NO_PORT;
}

/** The port of an address in 0x20000000-0x20041fff: a striped bank by word, or SRAM4, SRAM5. */
export function sramPort(address) {
  if (address < STRIPED_END) return Port.SRAM0 - ((address >>> 2) & 3);
  return address < SRAM5_BASE ? Port.SRAM4 : Port.SRAM5;
}

/** What an access is: a load or store, or an instruction fetch (for the report's kinds of contest). */
export const DATA = 0;
export const FETCH = 16;

/** Each master's records reach back RING cycles (a power of two). */
const RING_BITS = 10;
const RING = 1 << RING_BITS;
const MASK = RING - 1;
/** A record's key: its cycle times KEY_SCALE plus its port, plus FETCH_KEY for a fetch. */
const KEY_SCALE = 32;
const FETCH_KEY = FETCH;
const EMPTY = -1;
/** Bus masters: the two cores. */
const MASTERS = 2;
/** BUS_PRIORITY's bits for PROC0 and PROC1 (DMA_R and DMA_W are bits 8 and 12). */
const PRIORITY_BITS = [1 << 0, 1 << 4];

export class BusFabric {
  /** `cores`: the machine's pair of cores (each with `cycles`), read through the array as core 1 is replaced. */
  constructor(cores, { contention = true } = {}) {
    this.cores = cores;
    this.contention = contention;
    /** Master k's access in cycle c, if any: keys[k·RING + c mod RING] = c·KEY_SCALE + port (+ FETCH_KEY). */
    this.keys = new Float64Array(MASTERS * RING).fill(EMPTY);
    /** Per port: accesses, and accesses that waited for another master (BUSCTRL's two events). */
    this.accesses = new Float64Array(PORTS);
    this.contested = new Float64Array(PORTS);
    /** Per port: the master granted in its last contest (EMPTY before any). */
    this.lastWinner = new Int8Array(PORTS).fill(EMPTY);
    this.priority = 0;
    /** Per core: cycles stalled waiting for the other. */
    this.stalls = new Float64Array(MASTERS);
    /** Contests by kind: fetch against fetch, fetch against data, data against data. */
    this.kinds = { fetchFetch: 0, fetchData: 0, dataData: 0 };
  }

  /** Core k was reset: it has made no access. */
  forget(k) {
    this.keys.fill(EMPTY, k * RING, (k + 1) * RING);
  }

  /**
   * Master k addresses `port` in cycle `cycle` (`kind`: FETCH or DATA):
   * the access is counted and arbitrated. Returns the cycles k waits
   * before it is granted (0 when uncontested); the other master, if it
   * loses, is delayed here.
   */
  access(k, port, cycle, kind) {
    this.accesses[port]++;
    const key = cycle * KEY_SCALE + port;
    const keys = this.keys;
    const theirs = keys[((1 - k) << RING_BITS) | (cycle & MASK)];
    if ((theirs === key || theirs === key + FETCH_KEY) && this.contention) return this.contest(k, port, cycle, kind);
    keys[(k << RING_BITS) | (cycle & MASK)] = key + kind;
    return 0;
  }

  /** k's access meets the other master's in `cycle`: one waits, in turn, until k is granted. */
  contest(k, port, cycle, kind) {
    const j = 1 - k;
    const keys = this.keys;
    const other = j << RING_BITS;
    let at = cycle;
    for (;;) {
      const theirs = keys[other | (at & MASK)] - at * KEY_SCALE;
      if (theirs !== port && theirs !== port + FETCH_KEY) break;
      this.countKind(kind, theirs & FETCH_KEY);
      if (this.loses(k, j, port)) {
        this.lastWinner[port] = j;
        at++;
        continue;
      }
      this.lastWinner[port] = k;
      this.contested[port]++;
      this.delay(j, at);
      break;
    }
    this.record(k, at, port, kind);
    const waited = at - cycle;
    if (waited > 0) {
      this.contested[port]++;
      this.stalls[k] += waited;
    }
    return waited;
  }

  /** Whether k loses a contest with j for `port`: priority first, then each in turn. */
  loses(k, j, port) {
    const high = this.priority;
    if (high !== 0) {
      const kHigh = (high & PRIORITY_BITS[k]) !== 0;
      if (kHigh !== ((high & PRIORITY_BITS[j]) !== 0)) return !kHigh;
    }
    return this.lastWinner[port] === k;
  }

  countKind(a, b) {
    const kinds = this.kinds;
    if (a && b) kinds.fetchFetch++;
    else if (a || b) kinds.fetchData++;
    else kinds.dataData++;
  }

  record(k, at, port, kind) {
    this.keys[(k << RING_BITS) | (at & MASK)] = at * KEY_SCALE + port + kind;
  }

  /** Master j, already past cycle `at`, lost it: it waits a cycle, and its accesses from `at` on move one later. */
  delay(j, at) {
    const keys = this.keys;
    const base = j << RING_BITS;
    const core = this.cores[j];
    // Its records are all before its time.
    for (let t = core.cycles - 1; t >= at; t--) {
      const i = base | (t & MASK);
      const key = keys[i];
      if (key < t * KEY_SCALE || key >= (t + 1) * KEY_SCALE) continue;
      keys[base | ((t + 1) & MASK)] = key + KEY_SCALE;
      keys[i] = EMPTY;
    }
    core.cycles++;
    this.stalls[j]++;
  }

  /** The count of BUSCTRL event `event` (0 to 19) so far. */
  eventCount(event) {
    const port = event >>> 1;
    return event & 1 ? this.accesses[port] : this.contested[port];
  }

  /** Totals for the report: each port's accesses and contested accesses, each core's stalls, the kinds of contest. */
  statistics() {
    const ports = {};
    PORT_NAMES.forEach((name, p) => {
      if (this.accesses[p] > 0) ports[name] = { accesses: this.accesses[p], contested: this.contested[p] };
    });
    return { contention: this.contention, ports, stallCycles: [...this.stalls], contests: { ...this.kinds } };
  }
}

const BUS_PRIORITY = 0x00;
const BUS_PRIORITY_ACK = 0x04;
const PERFCTR0 = 0x08;
const PERFSEL_LAST = 0x24;
const COUNTER_MAX = 0xffffff;
const EVENTS = 2 * PORTS;
/** PERFSEL's reset value: an event number no port has, so the counter stays at 0. */
const NO_EVENT = 0x1f;

/**
 * BUSCTRL (0x40030000): BUS_PRIORITY, its ACK, and the four performance
 * counters: PERFSELn picks an event (0x1f at reset: none), PERFCTRn counts
 * it in 24 bits, saturating, and any write clears it (2.1.1.2).
 */
export class BusCtrl extends BasePeripheral {
  constructor(rp2040, fabric) {
    super(rp2040, 'BUSCTRL');
    this.fabric = fabric;
    this.select = [NO_EVENT, NO_EVENT, NO_EVENT, NO_EVENT];
    /** The event's count when the counter last read 0. */
    this.base = [0, 0, 0, 0];
  }

  total(n) {
    const event = this.select[n];
    return event < EVENTS ? this.fabric.eventCount(event) : 0;
  }

  value(n) {
    return Math.min(this.total(n) - this.base[n], COUNTER_MAX);
  }

  readUint32(offset) {
    if (offset === BUS_PRIORITY) return this.fabric.priority;
    if (offset === BUS_PRIORITY_ACK) return 1;
    if (offset >= PERFCTR0 && offset <= PERFSEL_LAST) {
      const n = (offset - PERFCTR0) >>> 3;
      return offset & 4 ? this.select[n] : this.value(n);
    }
    return this.unmodelled(offset);
  }

  writeUint32(offset, value) {
    if (offset === BUS_PRIORITY) {
      this.fabric.priority = value & 0x1111;
      return;
    }
    if (offset === BUS_PRIORITY_ACK) return;
    if (offset >= PERFCTR0 && offset <= PERFSEL_LAST) {
      const n = (offset - PERFCTR0) >>> 3;
      if (offset & 4) {
        // The counter keeps its count and goes on with the new event.
        const kept = this.value(n);
        this.select[n] = value & 0x1f;
        this.base[n] = this.total(n) - kept;
      } else {
        this.base[n] = this.total(n);
      }
      return;
    }
    this.unmodelled(offset);
  }

  unmodelled(offset) {
    throw new RunError(`BUSCTRL 0x${(0x40030000 + offset).toString(16)}: no such register`);
  }
}
