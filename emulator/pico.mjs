// A Raspberry Pi Pico running a firmware ELF, with an ST7789 panel on SPI1
// wired as the Waveshare Pico-LCD-1.3 is (lcd.mjs) and an SSD1306 module on
// I2C0 (oled.mjs): rp2040js's RP2040 with both of its Cortex-M0+ cores
// (rp2040js runs one: core 1 is a second rp2040js core on the same bus),
// run in lockstep by cycles (lockstep.mjs) at the clock the firmware sets
// (clocks.mjs, with the regulator it needs, vreg.mjs), this folder's boot
// ROM stand-in, its corrections to rp2040js's instructions, and the flash
// as a real Pico has it (the W25Q16JV behind the SSI, the firmware's own
// boot2, the XIP cache).
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
// loop, touches what the emulator does not model, runs the chip outside its
// rating, or outlives its time budget ends the run with a RunError naming
// the core and where it was; one whose watchdog runs out ends it with a
// WatchdogReset (a real Pico resets: the serial serve starts a new machine,
// see serial.mjs).

import { RP2040 } from 'rp2040js';
import { buildBootrom, checkBoot2, codeLetters, MISSING_FUNCTION_BREAKPOINT } from './bootrom.mjs';
import { functionAt, parseElf } from './elf.mjs';
import { correctInstructions } from './armv6m.mjs';
import { wireLcd } from './lcd.mjs';
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
import { Lockstep } from './lockstep.mjs';
import { SystemClock } from './clocks.mjs';
import { Vreg } from './vreg.mjs';

export { RunError, WatchdogReset };
export { WIRING } from './lcd.mjs';

const FLASH_BASE = 0x10000000;
const SRAM_BASE = 0x20000000;
/** The exception number of IRQ 0. */
const FIRST_IRQ = 16;
const WFE = 0xbf20;
/** rp2040js's peripherals, by `(address >>> 14) << 2`. */
const XIP_CTRL_SLOT = 0x14000;
const BUSCTRL_SLOT = 0x40030;
const SSI_SLOT = 0x18000;
const PSM_SLOT = 0x40010;
const I2C_SLOTS = [0x40044, 0x40048];
const VREG_SLOT = 0x40064;
const PSM_FRCE_OFF = 0x04;
const PSM_PROC1 = 1 << 16;
const WATCHDOG_SLOT = 0x40058;

export class Pico extends Lockstep {
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
    super();
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
    checkBoot2(rp2040.flash, (message) => new RunError(`${source}: ${message}`));

    this.cores = [rp2040.core, null];
    this.irqLines = 0;
    this.fabric = new BusFabric(this.cores, { contention });
    // The core voltage and clk_sys, from their registers: from reset on, the ring oscillator.
    this.vreg = new Vreg(rp2040, { onVoltage: (volts) => this.systemClock.voltageChanged(volts) });
    rp2040.peripherals[VREG_SLOT] = this.vreg;
    this.systemClock = new SystemClock(rp2040, {
      now: () => this.cores[this.current].cycles,
      volts: () => this.vreg.volts,
      onChange: () => {
        // The running stretch ticked at the old rate; the flash's serial clock changed with clk_sys.
        this.woke = true;
        this.ssi.clockChanged();
      },
    });

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
    this.flashChip = new W25Q16JV(rp2040.flash, () => this.clock.nanos / 1e9, { statusRegister2: flashStatusRegister2 });
    this.ssi = new Ssi(rp2040, this.flashChip, now, () => this.systemClock.hz);
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
      throw new WatchdogReset(`the watchdog ${why} at ${(this.clock.nanos / 1e9).toFixed(6)} s: the board resets`);
    };

    this.attach(0);
    this.startCore1(0);
    /** The ST7789 on SPI1 (null without one): the panel, and the times the run's phases are told by. */
    this.lcd = panel ? wireLcd(rp2040, now, panel) : null;
    this.panel = this.lcd?.panel ?? null;
    this.events = this.lcd?.events ?? null;
    // Both I2C controllers with what rp2040js's lack (i2c.mjs), and the SSD1306 module on I2C0.
    this.i2c = I2C_SLOTS.map((slot, k) => {
      const controller = new I2cController(rp2040, k, rp2040.i2c[k].irq, { systemClock: this.systemClock });
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

  /** The machine clock's time in cycles. */
  clockCycles() {
    return this.systemClock.cyclesAt(this.clock.nanos);
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
   * The clocks the firmware set, as the report gives them: clk_sys now and
   * each change of it (the cycle it took effect at), clk_peri, the flash's
   * serial clock (clk_sys / the SSI's divider) and the core voltage.
   */
  clockReport() {
    return {
      ...this.systemClock.report(),
      periHz: this.rp2040.clkPeri,
      flashHz: this.ssi.serialClockHz,
      coreVolts: this.vreg.volts,
    };
  }

  /**
   * The run's phases in cycles, as the panel the firmware drives tells them
   * (lcd.mjs, oled.mjs; null where the run never got there), and the whole
   * run's.
   */
  phases() {
    const none = { startUp: null, parseAndIndex: null, render: null, firstFullPanel: null };
    const phases = this.display?.name === 'SSD1306' ? this.oled.phases() : (this.lcd?.phases() ?? none);
    return { ...phases, total: this.time };
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
