// A Raspberry Pi Pico running a firmware ELF, with an ST7789 panel on SPI1
// wired as the Waveshare Pico-LCD-1.3 is: rp2040js's RP2040 with both of its
// Cortex-M0+ cores at 125 MHz (rp2040js runs one: core 1 is a second
// rp2040js core on the same bus), this folder's boot ROM stand-in, its
// corrections to rp2040js's instructions, and the flash as a real Pico has
// it (the W25Q16JV behind the SSI, the firmware's own boot2, the XIP cache).
//
// The cores run in lockstep by cycles: the next instruction is always the
// one of the core whose time (its cycle count) is lower, core 0 on a tie,
// and the shared clock (alarms: SPI, timer) follows the earlier of the
// running cores. A core asleep (WFE, WFI, or core 1 held in reset by the
// PSM) is carried along at the other's time, counted as waiting; woken by
// the other core (SEV, an interrupt it caused) or by an alarm, it starts at
// the end of the instruction or the clock step that woke it. When both
// sleep, the clock jumps to the next alarm; when none is left, `run`
// returns 'idle': the firmware waits for the outside world, which a runner
// may provide (a later serial link: it raises an IRQ line, then calls `run`
// again) or end the run on. `run({ until })` runs a slice and resumes
// exactly where it stopped.
//
// Between the cores: SEV (which rp2040js only logs) sets both cores' event
// registers and ends the other's WFE; every IRQ line reaches both NVICs;
// PSM FRCE_OFF.PROC1 holds core 1 in reset and, cleared, restarts it in the
// ROM. rp2040js's SysTick pends its exception without waking a sleeping
// core; here it wakes it, as any interrupt does. An interrupt's pending
// state follows the NVIC's rule: cleared on entry, kept only while its line
// is high (rp2040js keeps it until the line falls).
//
// Invariants: the ELF is loaded exactly as built and starts as on the chip
// (both cores from the ROM's reset vector; core 0 through the ELF's boot2);
// every cycle counted is one an emulated core spent (the ROM stand-in's,
// boot2's and flash stalls too); a firmware that faults, stops in an endless
// loop, touches what the emulator does not model, or outlives its cycle
// budget ends the run with a RunError naming the core and where it was; one
// whose watchdog runs out ends it with a WatchdogReset (a real Pico resets:
// the serial serve starts a new machine, see serial.mjs).

import { RP2040, GPIOPinState } from 'rp2040js';
import { buildBootrom, codeLetters, MISSING_FUNCTION_BREAKPOINT } from './bootrom.mjs';
import { functionAt, functionNameAt, parseElf } from './elf.mjs';
import { correctInstructions } from './armv6m.mjs';
import { ST7789 } from './st7789.mjs';
import { I2cController } from './i2c.mjs';
import { wireOled } from './oled.mjs';
import { RunError, WatchdogReset } from './errors.mjs';
import { installBus, machineMemory, peek16 } from './bus.mjs';
import { CoreSio, InterCoreFifos } from './sio.mjs';
import { CorePpb } from './ppb.mjs';
import { W25Q16JV } from './flash-chip.mjs';
import { Ssi } from './ssi.mjs';
import { XipCache, XipControl } from './xip.mjs';
import { BusCtrl, BusFabric } from './fabric.mjs';
import { completeRegisters } from './usb-serial.mjs';

export { RunError, WatchdogReset };

const FLASH_BASE = 0x10000000;
const SRAM_BASE = 0x20000000;
const BOOT2_BYTES = 256;
export const CLOCK_HZ = 125_000_000;
const NANOS_PER_CYCLE = 1e9 / CLOCK_HZ;
const EXC_HARDFAULT = 3;
/** The exception number of IRQ 0. */
const FIRST_IRQ = 16;
const ROM_END = 0x4000;
const BRANCH_TO_SELF = 0xe7fe;
const WFE = 0xbf20;
/** How often (in instructions) the run looks for endless loops, its budget, and reports progress. */
const CHECK_EVERY = 0xfffff;
/** How often (in instructions) a profiled run samples where the cores are. */
const SAMPLE_EVERY = 0xff;
/** Samples between a profiled run's other checks, less one: those stay at their usual pace. */
const SAMPLES_PER_CHECK = (CHECK_EVERY + 1) / (SAMPLE_EVERY + 1) - 1;
/** rp2040js's peripherals, by `(address >>> 14) << 2`. */
const XIP_CTRL_SLOT = 0x14000;
const BUSCTRL_SLOT = 0x40030;
const SSI_SLOT = 0x18000;
const PSM_SLOT = 0x40010;
const I2C_SLOTS = [0x40044, 0x40048];
const PSM_FRCE_OFF = 0x04;
const PSM_PROC1 = 1 << 16;
const WATCHDOG_SLOT = 0x40058;

/** The Pico-LCD-1.3's wiring: SPI1 on GP10 (clock) and GP11 (data); the panel's control lines. */
export const WIRING = { clock: 10, data: 11, chipSelect: 9, dataCommand: 8, reset: 12, backlight: 13 };
const GPIO_FUNCTION_SPI = 1;

export class Pico {
  /**
   * `segments` ({ loadAddress, data }, as an ELF's) are loaded as built;
   * `source` names them in messages, `functions` (an ELF's symbols) name
   * where a core is. `panel`: the ST7789's options (null: no panel);
   * `oled`: the SSD1306 module's on I2C0 (oled.mjs; null: none).
   * `onBreakpoint(core, code)`: returns true for a BKPT or UDF it handles
   * (tests); any other ends the run. `flashStatusRegister2`: the flash
   * chip's at power-on (QE set, as the Pico's). `contention`: whether
   * masters addressing one port of the bus fabric in one cycle wait for
   * each other (fabric.mjs; true, as on the chip).
   */
  constructor({
    segments,
    source,
    functions = [],
    panel = null,
    oled = null,
    onBreakpoint = () => false,
    flashStatusRegister2,
    contention = true,
  } = {}) {
    const rp2040 = new RP2040();
    this.rp2040 = rp2040;
    this.clock = rp2040.clock;
    this.functions = functions;
    this.onBreakpoint = onBreakpoint;
    // rp2040js's SEV only logs: each core's logger turns that into the event.
    rp2040.logger = strictLogger(() => this.sendEvent(0));
    this.rom = buildBootrom();
    rp2040.loadBootrom(this.rom.image); // also erases the flash and resets core 0 into the ROM: load the ELF after it
    loadSegments(rp2040, segments, source);
    checkBoot2(rp2040.flash, source);

    /** Machine time in cycles: the clock's, which follows the earlier running core. */
    this.time = 0;
    this.steps = 0;
    /** Instructions between the run's checks (a power of two, less one): fewer while profiling. */
    this.checkEvery = CHECK_EVERY;
    /** While profiling: cycles by function, and each core's time at its last sample. */
    this.profile = null;
    this.current = 0;
    this.cores = [rp2040.core, null];
    this.held = [false, false];
    this.waiting = [0, 0];
    this.instructions = [0, 0];
    this.core1Ran = false;
    /** Set when a sleeping core wakes or core 1 is reset: a core running alone must look again. */
    this.woke = false;
    /** Set by `stop`: the run returns once the running stretch ends. */
    this.stopping = false;
    this.irqLines = 0;
    this.fabric = new BusFabric(this.cores, { contention });

    // Core 1's rp2040js parts act on `rp2040.core`: give them a view of the chip whose core is core 1.
    const core1View = Object.create(rp2040, {
      core: { get: () => this.cores[1] },
      onBreak: { value: (code) => this.breakpoint(1, code) },
      logger: { value: strictLogger(() => this.sendEvent(1)) },
    });
    this.core1View = core1View;
    rp2040.onBreak = (code) => this.breakpoint(0, code);
    const ppb1 = new rp2040.ppb.constructor(core1View, 'PPB (core 1)');
    rp2040.addClockListener((hz) => (ppb1.systickTimer.frequency = hz));
    const sram = { base: SRAM_BASE, bytes: rp2040.sram.length };
    this.ppbs = [new CorePpb(0, rp2040.ppb, sram), new CorePpb(1, ppb1, sram)];
    this.fifos = new InterCoreFifos((irq, level) => rp2040.setInterrupt(irq, level));
    this.sios = [0, 1].map(
      (k) =>
        new CoreSio(k, this.fifos, rp2040.sio, k === 0 ? rp2040.sio : new rp2040.sio.constructor(core1View), () => this.cores[k].cycles),
    );
    // Every IRQ line reaches both cores' NVICs.
    rp2040.setInterrupt = (irq, level) => {
      this.irqLines = level ? this.irqLines | (1 << irq) : this.irqLines & ~(1 << irq);
      for (let k = 0; k < 2; k++) {
        const core = this.cores[k];
        if (this.held[k]) continue;
        const asleep = core.waiting;
        core.setInterrupt(irq, level);
        if (asleep && !core.waiting) this.woke = true;
      }
    };
    // rp2040js's SysTick pends its exception but wakes no sleeping core: wake it as an interrupt does.
    this.ppbs.forEach((ppb, k) => {
      const alarm = ppb.nvic.systickAlarm;
      const expire = alarm.callback;
      alarm.callback = () => {
        expire();
        const core = this.cores[k];
        if (core.waiting && !this.held[k] && core.checkForInterrupts()) {
          core.waiting = false;
          this.woke = true;
        }
      };
    });

    const now = () => this.clockCycles();
    this.flashChip = new W25Q16JV(rp2040.flash, () => this.clockCycles() / CLOCK_HZ, { statusRegister2: flashStatusRegister2 });
    this.ssi = new Ssi(rp2040, this.flashChip, now);
    rp2040.peripherals[SSI_SLOT] = this.ssi;
    this.xip = new XipCache(this.ssi, this.cores);
    this.memory = machineMemory(rp2040, this.xip);
    const stall = (cycles) => (this.cores[this.current].cycles += cycles);
    rp2040.peripherals[XIP_CTRL_SLOT] = new XipControl(rp2040, this.xip, now, stall);
    rp2040.peripherals[BUSCTRL_SLOT] = new BusCtrl(rp2040, this.fabric);
    this.watchPsm(rp2040.peripherals[PSM_SLOT]);
    completeRegisters(rp2040.usbCtrl);
    // rp2040js's DMA would copy outside the bus fabric (and around the XIP cache): not modelled.
    for (const channel of rp2040.dma.channels) {
      channel.start = () => {
        throw new RunError(`DMA channel ${channel.index} started: the emulator does not model the DMA on the bus fabric`);
      };
    }
    this.watchdog = rp2040.peripherals[WATCHDOG_SLOT];
    this.watchdog.onWatchdogTrigger = () => {
      const why = this.watchdog.reason & 2 ? 'was triggered' : 'ran out';
      throw new WatchdogReset(`the watchdog ${why} at ${(this.clockCycles() / CLOCK_HZ).toFixed(6)} s: the board resets`);
    };

    this.attach(0);
    this.startCore1(0);
    /** The ST7789 on SPI1 (null without one), and the times the run's phases are told by. */
    this.panel = panel ? new ST7789(panel) : null;
    this.events = this.panel ? this.wirePanel(this.panel) : null;
    // Both I2C controllers with what rp2040js's lack (i2c.mjs), and the SSD1306 module on I2C0.
    this.i2c = I2C_SLOTS.map((slot, k) => {
      const controller = new I2cController(rp2040, k, rp2040.i2c[k].irq, { nanosPerCycle: NANOS_PER_CYCLE });
      rp2040.i2c[k] = rp2040.peripherals[slot] = controller;
      return controller;
    });
    this.oled = oled ? wireOled(this.i2c[0], rp2040.gpio, now, oled) : null;
  }

  /**
   * The panel the firmware drives, as run.mjs writes it: the ST7789 if it
   * took a command, else the SSD1306 if it took a transfer, else the first
   * wired (null: none is). Its name, size, picture (8-bit RGB), why it is
   * dark (or null), and how many writes it has taken.
   */
  get display() {
    if (!this.panel && !this.oled) return null;
    const st7789 = this.panel && { name: 'ST7789', panel: this.panel, writes: () => this.events.memoryWrites };
    const ssd1306 = this.oled && { name: 'SSD1306', panel: this.oled.panel, writes: () => this.oled.panel.dataBytes };
    const talkedTo = (st7789 && this.panel.counts.size > 0 && st7789) || (ssd1306 && this.oled.events.transfers > 0 && ssd1306);
    const { name, panel, writes } = talkedTo || st7789 || ssd1306;
    return { name, width: panel.width, height: panel.height, picture: () => panel.picture(), darkBecause: panel.darkBecause, writes };
  }

  /** A Pico running the ELF `bytes` read from `path`. */
  static fromElf(bytes, path, options) {
    const elf = parseElf(bytes, path);
    return new Pico({ ...options, segments: elf.segments, functions: elf.functions, source: path });
  }

  /** The clock's time in cycles. */
  clockCycles() {
    return this.clock.nanos / NANOS_PER_CYCLE;
  }

  /** Routes core k's accesses through its own bus and puts the instruction corrections in front of it. */
  attach(k) {
    const core = this.cores[k];
    installBus(core, k, { rp2040: this.rp2040, xip: this.xip, sio: this.sios[k], ppb: this.ppbs[k], fabric: this.fabric });
    correctInstructions(core, peek16, this.memory, { fabric: this.fabric, busIndex: k });
    // An interrupt's pending state clears as its handler is entered, and
    // stays only while its line is still high (the NVIC's rule; rp2040js
    // keeps a pending bit until the line falls, so an interrupt pended by
    // software, NVIC ISPR, with its line low was taken for ever).
    const enter = core.exceptionEntry;
    core.exceptionEntry = (exception) => {
      enter.call(core, exception);
      const irq = exception - FIRST_IRQ;
      if (irq >= 0 && !(this.irqLines & (1 << irq))) core.pendingInterrupts &= ~(1 << irq);
    };
  }

  /** Core 1 out of reset at time `at`: a new core at the ROM's reset vector, its NVIC seeing the IRQ lines as they are. */
  startCore1(at) {
    const previous = this.cores[1];
    if (previous) this.waiting[1] += at - previous.cycles;
    const core = new this.rp2040.core.constructor(this.core1View);
    core.cycles = at;
    core.SP = this.rp2040.bootrom[0];
    core.PC = this.rp2040.bootrom[1] & ~1;
    core.pendingInterrupts = this.irqLines;
    core.interruptsUpdated = true;
    this.cores[1] = core;
    this.fabric.forget(1);
    this.held[1] = false;
    this.woke = true;
    this.ppbs[1].reset();
    this.attach(1);
  }

  /** PSM FRCE_OFF.PROC1 set holds core 1 in reset; cleared, core 1 starts again from the ROM. */
  watchPsm(psm) {
    const write = psm.writeUint32.bind(psm);
    psm.writeUint32 = (offset, value) => {
      const before = psm.frceOff;
      write(offset, value);
      if (offset !== PSM_FRCE_OFF) return;
      if (psm.frceOff & ~PSM_PROC1) {
        throw new RunError(`PSM FRCE_OFF 0x${psm.frceOff.toString(16)}: forcing off anything but core 1 is not modelled`);
      }
      const at = this.cores[this.current].cycles;
      if (psm.frceOff & ~before & PSM_PROC1) {
        this.settle(1, at);
        this.held[1] = true;
        this.cores[1].waiting = true;
        this.woke = true;
      } else if (before & ~psm.frceOff & PSM_PROC1) {
        this.startCore1(at);
      }
    };
  }

  /**
   * SEV on core k (the manual's B1.5.18): its own event register is set,
   * and the other core's TXEV-RXEV wire sets the other's, or ends its WFE
   * (not a WFI: only an interrupt ends that), consuming the event.
   */
  sendEvent(k) {
    this.cores[k].eventRegistered = true;
    const j = 1 - k;
    if (this.held[j]) return;
    const other = this.cores[j];
    // A sleeping core's PC is past the WFE or WFI it sleeps in.
    if (other.waiting && peek16(this.memory, other.PC - 2) === WFE) {
      other.waiting = false;
      this.woke = true;
    } else {
      other.eventRegistered = true;
    }
  }

  /** Brings an asleep core's time up to `at` (at least), counting the gap as waiting. */
  settle(j, at) {
    const core = this.cores[j];
    if (at > core.cycles) {
      this.waiting[j] += at - core.cycles;
      core.cycles = at;
    }
  }

  /**
   * Runs until both cores sleep with nothing scheduled ('idle'), the
   * machine's time reaches `until` ('until') or `stop` is called
   * ('stopped'). Throws RunError for what a
   * real Pico would not have done the same way, or after `maxCycles`.
   * `onProgress(cycles, panelWrites)` is called now and then.
   */
  run({ maxCycles = Infinity, until = Infinity, onProgress = () => {} } = {}) {
    try {
      return this.loop(maxCycles, until, onProgress);
    } catch (error) {
      if (error instanceof RunError && !error.located) {
        // The same class (a WatchdogReset stays one), located.
        throw new error.constructor(`${error.message} (${this.whereAll()})`, { located: true });
      }
      throw error;
    } finally {
      for (let j = 0; j < 2; j++) {
        if (this.cores[j].waiting) this.settle(j, this.time);
      }
    }
  }

  loop(maxCycles, until, onProgress) {
    const cores = this.cores;
    for (;;) {
      const awake0 = !cores[0].waiting;
      const awake1 = !cores[1].waiting;
      let reason;
      if (awake0 && awake1) {
        reason = this.runBoth(until, maxCycles, onProgress);
      } else if (awake0 || awake1) {
        reason = this.runAlone(awake0 ? 0 : 1, until, maxCycles, onProgress);
      } else {
        if (!this.sleepUntilAlarm()) return 'idle';
        if (this.time >= until) return 'until';
        if (this.time > maxCycles) this.check(maxCycles, onProgress);
        continue;
      }
      if (reason) return reason;
      if (this.stopping) {
        this.stopping = false;
        return 'stopped';
      }
    }
  }

  /**
   * Ends the run (`run` returns 'stopped') after the instruction now
   * executing: for a watcher that has seen what it waited for (frames.mjs).
   */
  stop() {
    this.stopping = true;
    this.woke = true;
  }

  /**
   * Both cores run: each step is the next instruction of the core that is
   * behind (core 0 on a tie), and the clock follows the earlier. Returns a
   * reason to end the run, or null when a core sleeps or core 1 is reset.
   */
  runBoth(until, maxCycles, onProgress) {
    const c0 = this.cores[0];
    const c1 = this.cores[1];
    const clock = this.clock;
    let time = this.time;
    let steps0 = 0;
    let steps1 = 0;
    let countdown = this.checkEvery + 1 - (this.steps & this.checkEvery);
    let reason = null;
    this.woke = false;
    for (;;) {
      if (c1.cycles < c0.cycles) {
        this.current = 1;
        c1.executeInstruction();
        steps1++;
        if (!this.core1Ran && c1.PC >= ROM_END) this.core1Ran = true;
      } else {
        this.current = 0;
        c0.executeInstruction();
        steps0++;
      }
      if (c0.waiting || c1.waiting || this.woke) break;
      const target = c0.cycles < c1.cycles ? c0.cycles : c1.cycles;
      if (target > time) {
        clock.tick((target - time) * NANOS_PER_CYCLE);
        time = target;
      }
      if (time >= until) {
        reason = 'until';
        break;
      }
      if (--countdown === 0) {
        this.time = time;
        this.count(0, steps0);
        this.count(1, steps1);
        steps0 = steps1 = 0;
        this.check(maxCycles, onProgress);
        countdown = this.checkEvery + 1;
      }
    }
    this.time = time;
    this.count(0, steps0);
    this.count(1, steps1);
    if (reason === null) this.follow(this.current);
    return reason;
  }

  /**
   * After core k's instruction that ended a stretch: the clock follows the
   * earlier running core (or core k, if both now sleep), and a core woken
   * on the way starts then.
   */
  follow(k) {
    const cores = this.cores;
    const core = cores[k];
    let target = core.waiting ? Infinity : core.cycles;
    const other = cores[1 - k];
    if (!other.waiting && other.cycles < target) target = other.cycles;
    if (target === Infinity) target = core.cycles;
    if (target > this.time) {
      const asleep0 = cores[0].waiting;
      const asleep1 = cores[1].waiting;
      this.clock.tick((target - this.time) * NANOS_PER_CYCLE);
      this.time = target;
      if (asleep0 && !cores[0].waiting) this.settle(0, target);
      if (asleep1 && !cores[1].waiting) this.settle(1, target);
    }
  }

  /**
   * Core k runs while the other sleeps: the same steps as `loop`'s, with
   * nothing to choose. Returns a reason to end the run, or null when the
   * other core woke, core 1 was reset, or this one sleeps.
   */
  runAlone(k, until, maxCycles, onProgress) {
    const core = this.cores[k];
    const clock = this.clock;
    let time = this.time;
    let steps = 0;
    let countdown = this.checkEvery + 1 - (this.steps & this.checkEvery);
    let reason = null;
    let watchLaunch = k === 1 && !this.core1Ran;
    this.current = k;
    this.woke = false;
    for (;;) {
      core.executeInstruction();
      steps++;
      if (watchLaunch && core.PC >= ROM_END) {
        // Core 1 runs outside the ROM: the firmware launched it.
        this.core1Ran = true;
        watchLaunch = false;
      }
      const t = core.cycles;
      clock.tick((t - time) * NANOS_PER_CYCLE);
      time = t;
      if (core.waiting || this.woke) break;
      if (time >= until) {
        reason = 'until';
        break;
      }
      if (--countdown === 0) {
        this.time = time;
        this.count(k, steps);
        steps = 0;
        this.check(maxCycles, onProgress);
        countdown = this.checkEvery + 1;
      }
    }
    this.time = time;
    this.count(k, steps);
    const j = 1 - k;
    if (!this.cores[j].waiting) this.settle(j, time);
    return reason;
  }

  count(k, steps) {
    this.steps += steps;
    this.instructions[k] += steps;
  }

  /** Both cores asleep: the clock jumps to the next alarm (false when there is none). */
  sleepUntilAlarm() {
    const clock = this.clock;
    if (!clock.nextAlarm) return false;
    clock.tick(Math.max(0, clock.nextAlarm.nanos - clock.nanos));
    const time = Math.ceil(clock.nanos / NANOS_PER_CYCLE);
    if (time * NANOS_PER_CYCLE > clock.nanos) clock.tick(time * NANOS_PER_CYCLE - clock.nanos);
    this.time = time;
    for (let j = 0; j < 2; j++) {
      if (!this.cores[j].waiting) this.settle(j, time);
    }
    return true;
  }

  /**
   * From now on, samples where each running core is every 256
   * instructions and charges the cycles since its last sample to the
   * function it is in (`profileReport`): a statistical profile, as a
   * sampling profiler takes on a board, a little slower to run.
   */
  startProfile() {
    this.profile = { cycles: new Map(), last: this.cores.map((core) => core?.cycles ?? 0), checks: 0 };
    this.checkEvery = SAMPLE_EVERY;
  }

  sample() {
    const { cycles, last } = this.profile;
    for (let k = 0; k < 2; k++) {
      const core = this.cores[k];
      if (!core) continue;
      const spent = core.cycles - last[k];
      last[k] = core.cycles;
      if (core.waiting || spent <= 0) continue;
      const name = functionNameAt(this.functions, core.PC >>> 0);
      cycles.set(name, (cycles.get(name) ?? 0) + spent);
    }
  }

  /** The `top` functions the profile charged most, with their cycles and share of all it charged. */
  profileReport(top) {
    const entries = [...(this.profile?.cycles ?? [])];
    const all = entries.reduce((sum, [, cycles]) => sum + cycles, 0);
    return entries
      .sort((a, b) => b[1] - a[1])
      .slice(0, top)
      .map(([name, cycles]) => ({ name, cycles, share: all ? cycles / all : 0 }));
  }

  check(maxCycles, onProgress) {
    if (this.profile) {
      this.sample();
      if (++this.profile.checks & SAMPLES_PER_CHECK) return;
    }
    for (let k = 0; k < 2; k++) {
      const core = this.cores[k];
      if (core.waiting) continue;
      if (core.IPSR === EXC_HARDFAULT) {
        throw new RunError(`HardFault at ${this.where(k)}`, { located: true });
      }
      // A branch to itself (`b .`, as panic-halt's loop) never ends.
      if (peek16(this.memory, core.PC & ~1) === BRANCH_TO_SELF) {
        throw new RunError(`the firmware stopped in an endless loop in ${this.where(k)} (a panic?)`, { located: true });
      }
    }
    if (this.time > maxCycles) {
      throw new RunError(`still running after ${maxCycles} cycles (${maxCycles / CLOCK_HZ} s at 125 MHz), in ${this.whereAll()}`, {
        located: true,
      });
    }
    onProgress(this.time, this.display?.writes() ?? 0);
  }

  breakpoint(k, code) {
    if (this.onBreakpoint(k, code)) {
      return;
    }
    const core = this.cores[k];
    if (code === MISSING_FUNCTION_BREAKPOINT) {
      const table = core.registers[0] >>> 0 < this.rom.dataTable ? 'function' : 'data';
      throw new RunError(
        `the firmware looked up the boot ROM ${table} '${codeLetters(core.registers[1])}', which the runner's ROM ` +
          `does not stand in for (called from ${functionAt(this.functions, core.LR & ~1)} on core ${k})`,
        { located: true },
      );
    }
    throw new RunError(
      `a breakpoint or undefined instruction (#${code}) at ${functionAt(this.functions, (core.PC - 2) >>> 0)} on core ${k}`,
      { located: true },
    );
  }

  /** Where core k is: its function and core. */
  where(k) {
    return `${functionAt(this.functions, this.cores[k].PC >>> 0)} on core ${k}`;
  }

  /** Where the running cores are. */
  whereAll() {
    const running = [0, 1].filter((k) => !this.held[k] && (k === 0 || this.core1Ran));
    return running.map((k) => this.where(k)).join(' and ');
  }

  /**
   * The watchdog: null while it is stopped, else the microseconds left
   * before it resets the board (RP2040-E1: its counter runs at twice the
   * tick, as rp2040js models).
   */
  watchdogLeft() {
    const timer = this.watchdog.timer;
    return this.watchdog.enable ? Math.floor(timer.counter / 2) : null;
  }

  /** How many cores ran firmware: 2 once core 1 left the boot ROM. */
  get coresUsed() {
    return this.core1Ran ? 2 : 1;
  }

  /** Each core's busy and waiting cycles, and its stalls on flash and on the other core at the bus fabric (part of busy). */
  coreCycles() {
    return [0, 1].map((k) => ({
      core: k,
      busy: this.cores[k].cycles - this.waiting[k],
      waiting: this.waiting[k],
      flashStall: this.xip.stalls[k],
      busStall: this.fabric.stalls[k],
      instructions: this.instructions[k],
    }));
  }

  /** The XIP cache's counts, with the cycles a line read costs as the SSI is set up now. */
  cacheStatistics() {
    return this.xip.statistics(this.ssi.xipReady ? this.ssi.xipCycles : null);
  }

  /**
   * The run's phases in cycles: start-up (clocks, the panel's set-up and
   * clear, up to the backlight), parse and index (up to the picture's first
   * command), render (to its last pixel), first full panel (from the
   * picture's first command until every pixel of the panel has been written
   * once: the render's length for a top-to-bottom render). Null where the
   * run never got there.
   */
  phases() {
    if (this.display?.name === 'SSD1306') return { ...this.oled.phases(), total: this.time };
    const { backlightOn, pictureStart, lastPixel, fullPanel } = this.events ?? {};
    const picture = backlightOn != null && pictureStart != null && lastPixel > pictureStart;
    return {
      startUp: backlightOn ?? null,
      parseAndIndex: picture ? pictureStart - backlightOn : null,
      render: picture ? lastPixel - pictureStart : null,
      firstFullPanel: picture && fullPanel != null ? fullPanel - pictureStart : null,
      total: this.time,
    };
  }

  /**
   * Connects the panel to SPI1 and its control pins. Returns the times the
   * run's phases are told by: when the backlight came on (the template turns
   * it on once the panel is cleared, before it loads the scene), the first
   * command after that (the picture's first row), the last pixel, when the
   * whole panel had been written, and how many rows (RAMWRs) the panel has
   * taken.
   */
  wirePanel(panel) {
    const rp2040 = this.rp2040;
    const gpio = rp2040.gpio;
    const spi = rp2040.spi[1];
    const events = { backlightOn: null, pictureStart: null, lastPixel: null, fullPanel: null, memoryWrites: 0 };
    let chipSelected = false;
    const level = (pin) => gpio[pin].value === GPIOPinState.High;
    const now = () => this.clockCycles();

    // Chip select frames bytes; the controller keeps its command across frames.
    gpio[WIRING.chipSelect].addListener((state) => {
      chipSelected = state === GPIOPinState.Low;
    });
    gpio[WIRING.reset].addListener((state) => {
      if (state === GPIOPinState.Low) {
        panel.reset();
      }
    });
    gpio[WIRING.backlight].addListener((state) => {
      if (state === GPIOPinState.High && events.backlightOn === null) {
        events.backlightOn = now();
      }
    });

    // A byte takes 8 clocks of the bus; the next starts when it is out.
    const done = rp2040.clock.createAlarm(() => spi.completeTransmit(0));
    spi.onTransmit = (byte) => {
      const routed = [WIRING.clock, WIRING.data].every((pin) => gpio[pin].functionSelect === GPIO_FUNCTION_SPI);
      if (routed && chipSelected) {
        const dataCommand = level(WIRING.dataCommand);
        panelReceive(panel, byte, dataCommand);
        if (!dataCommand && events.backlightOn !== null && events.pictureStart === null) {
          events.pictureStart = now();
          panel.startCoverage();
        }
        if (panel.command?.name === 'RAMWR') {
          if (dataCommand) {
            events.lastPixel = now();
            if (events.fullPanel === null && events.pictureStart !== null && panel.fullyCovered) events.fullPanel = now();
          } else {
            events.memoryWrites++;
          }
        }
      }
      const hz = spi.clockFrequency;
      if (!hz) {
        throw new RunError('SPI1 transmits with no clock (SSPCPSR is 0)');
      }
      done.schedule((spi.dataBits * 1e9) / hz);
    };
    return events;
  }
}

function panelReceive(panel, byte, dataCommand) {
  try {
    panel.receive(byte, dataCommand);
  } catch (error) {
    throw new RunError(error.message);
  }
}

/** Warnings and errors end the run; of the rest, only a core's SEV (`sendEvent`) matters. */
function strictLogger(sendEvent) {
  const fail = (component, message) => {
    throw new RunError(`emulator (${component}): ${message}`);
  };
  const info = (component, message) => {
    if (component === 'CortexM0Core' && message === 'SEV') sendEvent();
  };
  return { debug: () => {}, info, warn: fail, error: fail };
}

function loadSegments(rp2040, segments, source) {
  for (const { loadAddress, data } of segments) {
    const end = loadAddress + data.length;
    if (loadAddress >= FLASH_BASE && end <= FLASH_BASE + rp2040.flash.length) {
      rp2040.flash.set(data, loadAddress - FLASH_BASE);
    } else if (loadAddress >= SRAM_BASE && end <= SRAM_BASE + rp2040.sram.length) {
      rp2040.sram.set(data, loadAddress - SRAM_BASE);
    } else {
      throw new RunError(`${source}: a segment at 0x${loadAddress.toString(16)} (${data.length} bytes) is in neither flash nor RAM`);
    }
  }
}

/**
 * The boot ROM runs boot2 only if its last 4 bytes are the CRC-32 (MPEG-2:
 * MSB first, no reflection, no final xor) of its first 252: an ELF without
 * a valid boot2 would not start on a real Pico, so it does not start here.
 */
function checkBoot2(flash, source) {
  let crc = 0xffffffff;
  for (let i = 0; i < BOOT2_BYTES - 4; i++) {
    crc ^= flash[i] << 24;
    for (let bit = 0; bit < 8; bit++) {
      crc = crc & 0x80000000 ? (crc << 1) ^ 0x04c11db7 : crc << 1;
    }
  }
  const stored = new DataView(flash.buffer).getUint32(BOOT2_BYTES - 4, true);
  if (crc >>> 0 !== stored) {
    throw new RunError(`${source}: no valid boot2 in the first 256 bytes of flash (a real Pico would not start it); see memory.x`);
  }
}
