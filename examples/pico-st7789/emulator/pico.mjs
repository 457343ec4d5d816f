// A Raspberry Pi Pico running a firmware ELF, with an ST7789 panel on SPI1
// wired as the Waveshare Pico-LCD-1.3 is: rp2040js (one Cortex-M0+ core at
// 125 MHz, counting its cycles) with this folder's boot ROM stand-in and its
// corrections to rp2040js's instructions.
//
// Invariants: the ELF is loaded exactly as built, and started the way the
// real boot2 starts it (vector table at 0x10000100); every cycle counted is
// one the emulated core spent (the ROM stand-in's too); a firmware that
// faults, stops in an endless loop, touches what the emulator does not
// model, or outlives its cycle budget ends the run with an error.

import { RP2040, GPIOPinState } from 'rp2040js';
import { buildBootrom, codeLetters, MISSING_FUNCTION_BREAKPOINT } from './bootrom.mjs';
import { functionAt, parseElf } from './elf.mjs';
import { correctInstructions } from './armv6m.mjs';
import { ST7789 } from './st7789.mjs';

export class RunError extends Error {}

const FLASH_BASE = 0x10000000;
const SRAM_BASE = 0x20000000;
/** boot2, the first 256 bytes of flash, hands over to the vector table right after it. */
const VECTOR_TABLE = FLASH_BASE + 0x100;
const BOOT2_BYTES = 256;
export const CLOCK_HZ = 125_000_000;
const NANOS_PER_CYCLE = 1e9 / CLOCK_HZ;
const EXC_HARDFAULT = 3;

/** The Pico-LCD-1.3's wiring: SPI1 on GP10 (clock) and GP11 (data); the panel's control lines. */
export const WIRING = { clock: 10, data: 11, chipSelect: 9, dataCommand: 8, reset: 12, backlight: 13 };
const GPIO_FUNCTION_SPI = 1;

/**
 * Runs `elfBytes` (read from `elfPath`) until the core sleeps with nothing
 * left to wake it. Returns the panel and the cycle counts of the run's
 * phases; throws RunError for anything a real Pico would not have done the
 * same way.
 */
export function runPico(elfBytes, elfPath, { panel: panelSize, maxCycles, onProgress = () => {} }) {
  const elf = parseElf(elfBytes, elfPath);
  const rp2040 = new RP2040();
  const fail = (message) => {
    throw new RunError(message);
  };
  rp2040.logger = strictLogger(fail);
  const core = rp2040.core;
  correctInstructions(core);

  const rom = buildBootrom();
  rp2040.loadBootrom(rom.image); // also erases the flash: load the ELF after it
  loadSegments(rp2040, elf, elfPath, fail);
  checkBoot2(rp2040.flash, elfPath, fail);

  const pc = () => core.PC >>> 0;
  rp2040.onBreak = (code) => {
    if (code === MISSING_FUNCTION_BREAKPOINT) {
      const table = core.registers[0] >>> 0 < rom.dataTable ? 'function' : 'data';
      fail(
        `the firmware looked up the boot ROM ${table} '${codeLetters(core.registers[1])}', which the runner's ROM ` +
          `does not stand in for (called from ${functionAt(elf.functions, core.LR & ~1)})`,
      );
    }
    fail(`a breakpoint or undefined instruction (#${code}) at ${functionAt(elf.functions, pc() - 2)}`);
  };

  const panel = new ST7789(panelSize);
  const events = wirePanel(rp2040, panel, fail);

  core.VTOR = VECTOR_TABLE;
  core.SP = rp2040.readUint32(VECTOR_TABLE);
  core.PC = rp2040.readUint32(VECTOR_TABLE + 4) & ~1;

  const clock = rp2040.clock;
  let instructions = 0;
  for (;;) {
    if (core.waiting) {
      const nanos = clock.nanosToNextAlarm;
      if (nanos <= 0 && !clock.nextAlarm) {
        break; // asleep, and nothing is left to wake the core
      }
      clock.tick(nanos);
      continue;
    }
    if (core.IPSR === EXC_HARDFAULT) {
      fail(`HardFault at ${functionAt(elf.functions, pc())}`);
    }
    const cycles = core.executeInstruction();
    clock.tick(cycles * NANOS_PER_CYCLE);
    instructions++;
    if ((instructions & 0xfffff) === 0) {
      // A branch to itself (`b .`, as panic-halt's loop) never ends.
      if (rp2040.readUint16(pc()) === 0xe7fe) {
        fail(`the firmware stopped in an endless loop in ${functionAt(elf.functions, pc())} (a panic?)`);
      }
      if (core.cycles > maxCycles) {
        fail(`still running after ${maxCycles} cycles (${maxCycles / CLOCK_HZ} s at 125 MHz), in ${functionAt(elf.functions, pc())}`);
      }
      onProgress(core.cycles, events.memoryWrites);
    }
  }
  return { panel, phases: phases(events, core.cycles), cycles: core.cycles, instructions };
}

/**
 * The run's phases in cycles: start-up (clocks, the panel's set-up and
 * clear, up to the backlight), parse and index (up to the picture's first
 * command), render (to its last pixel). Null where the run never got there.
 */
function phases(events, total) {
  const { backlightOn, pictureStart, lastPixel } = events;
  const picture = backlightOn !== null && pictureStart !== null && lastPixel > pictureStart;
  return {
    startUp: backlightOn,
    parseAndIndex: picture ? pictureStart - backlightOn : null,
    render: picture ? lastPixel - pictureStart : null,
    total,
  };
}

function strictLogger(fail) {
  const quiet = () => {};
  return {
    debug: quiet,
    info: quiet,
    warn: (component, message) => fail(`emulator (${component}): ${message}`),
    error: (component, message) => fail(`emulator (${component}): ${message}`),
  };
}

function loadSegments(rp2040, elf, elfPath, fail) {
  for (const { loadAddress, data } of elf.segments) {
    const end = loadAddress + data.length;
    if (loadAddress >= FLASH_BASE && end <= FLASH_BASE + rp2040.flash.length) {
      rp2040.flash.set(data, loadAddress - FLASH_BASE);
    } else if (loadAddress >= SRAM_BASE && end <= SRAM_BASE + rp2040.sram.length) {
      rp2040.sram.set(data, loadAddress - SRAM_BASE);
    } else {
      fail(`${elfPath}: a segment at 0x${loadAddress.toString(16)} (${data.length} bytes) is in neither flash nor RAM`);
    }
  }
}

/**
 * The boot ROM runs boot2 only if its last 4 bytes are the CRC-32 (MPEG-2:
 * MSB first, no reflection, no final xor) of its first 252: an ELF without
 * a valid boot2 would not start on a real Pico, so it does not start here.
 */
function checkBoot2(flash, elfPath, fail) {
  let crc = 0xffffffff;
  for (let i = 0; i < BOOT2_BYTES - 4; i++) {
    crc ^= flash[i] << 24;
    for (let bit = 0; bit < 8; bit++) {
      crc = crc & 0x80000000 ? (crc << 1) ^ 0x04c11db7 : crc << 1;
    }
  }
  const stored = new DataView(flash.buffer).getUint32(BOOT2_BYTES - 4, true);
  if (crc >>> 0 !== stored) {
    fail(`${elfPath}: no valid boot2 in the first 256 bytes of flash (a real Pico would not start it); see memory.x`);
  }
}

/**
 * Connects the panel to SPI1 and its control pins. Returns the cycle counts
 * the run's phases are told by: when the backlight came on (the template
 * turns it on once the panel is cleared, before it loads the scene), the
 * first command after that (the picture's first row), the last pixel, and
 * how many rows (RAMWRs) the panel has taken.
 */
function wirePanel(rp2040, panel, fail) {
  const gpio = rp2040.gpio;
  const spi = rp2040.spi[1];
  const core = rp2040.core;
  const events = { backlightOn: null, pictureStart: null, lastPixel: null, memoryWrites: 0 };
  let chipSelected = false;
  const level = (pin) => gpio[pin].value === GPIOPinState.High;

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
      events.backlightOn = core.cycles;
    }
  });

  // A byte takes 8 clocks of the bus; the next starts when it is out.
  const done = rp2040.clock.createAlarm(() => spi.completeTransmit(0));
  spi.onTransmit = (byte) => {
    const routed = [WIRING.clock, WIRING.data].every((pin) => gpio[pin].functionSelect === GPIO_FUNCTION_SPI);
    if (routed && chipSelected) {
      const dataCommand = level(WIRING.dataCommand);
      guard(fail, () => panel.receive(byte, dataCommand));
      if (!dataCommand && events.backlightOn !== null && events.pictureStart === null) {
        events.pictureStart = core.cycles;
      }
      if (panel.command?.name === 'RAMWR') {
        if (dataCommand) events.lastPixel = core.cycles;
        else events.memoryWrites++;
      }
    }
    const hz = spi.clockFrequency;
    if (!hz) {
      fail('SPI1 transmits with no clock (SSPCPSR is 0)');
    }
    done.schedule((spi.dataBits * 1e9) / hz);
  };
  return events;
}

function guard(fail, action) {
  try {
    action();
  } catch (error) {
    fail(error.message);
  }
}
