#!/usr/bin/env node
// Runs a Pico firmware ELF on the emulated Pico with its panel (an ST7789 on
// SPI1 as examples/pico-st7789 wires it, an SSD1306 module on I2C0 as
// examples/pico-ssd1306 does) and writes the picture the panel shows as a
// PNG. As a template's cargo runner (see README.md):
//
//   CARGO_TARGET_THUMBV6M_NONE_EABI_RUNNER="node emulator/run.mjs" cargo run --release [-- OPTIONS]
//
// Options: --out FILE (default panel.png), --display auto|st7789|ssd1306
// (which panel is wired; auto, the default, wires both and writes the one
// the firmware talks to), --panel WxH (the ST7789 panel's size, default
// 240x240, the Pico-LCD-1.3), --panel-offset X,Y (where it starts in the
// controller's 240x320 memory, default 0,0), --max-seconds S (emulated time
// before giving up, default 120), --contention on|off (whether two masters
// on one port of the bus fabric wait for each other, as on the chip:
// default on; off measures what the contention costs), --json (the report
// as JSON on standard output), --quiet.
//
// --profile N: where the cycles went, by function: each running core's
// place sampled every 256 instructions, the cycles since charged to the
// function it is in (the ELF's symbols; inlined code counts as its
// caller), and the N functions charged most listed after the report (in
// it, with --json). Not with --serial. With --frames, --profile-from K
// charges only frames K on (1: the frames an animation draws after its
// first, which loads the scene and traces everything).
//
// --frames N: for a firmware that draws frames (an animation), runs until
// N frames are on the panel and writes each as it was then: --out is then
// a pattern with one %d or %0Nd (default panel%03d.png), the frames
// numbered from 0 in the order drawn. A frame is drawn when the Pico's LED
// (GP25) goes out, the templates lighting it while they work on a frame
// (frames.mjs); the report lists each frame's cycles.
//
// --serial: the board as a serial device (serial.mjs), for the live
// firmware: prints the path of a pseudo-terminal on its first line of
// standard output and serves the firmware's USB serial port there until
// standard input closes or the process is signalled (`host-sim board PATH
// scene.txt` then talks to it). With --out, the panel's picture is written
// each time the firmware waits for the host again; with --json, the report
// follows the path on standard output once the serve ends. Its standard
// input's lines are commands for tests (hold, release, times: see
// serial.mjs); a watchdog that runs out resets the board, which starts
// again.
//
// Exit codes: 0 the run ended with both cores asleep and the picture written
// (with --frames, N frames drawn and written; with --serial, the serve
// ended); 1 the firmware or the ELF did
// something a real Pico would not survive, or the panel was sent what it
// does not take (the message says what); 2 bad arguments.

import { readFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { Pico, RunError } from './pico.mjs';
import { ElfError } from './elf.mjs';
import { PanelError } from './st7789.mjs';
import { PanelError as OledError } from './ssd1306.mjs';
import { encodePng, writeAtomically } from './png.mjs';
import { serveSerial } from './serial.mjs';
import { framePattern, watchFrames } from './frames.mjs';

const USAGE =
  'usage: node run.mjs ELF [--out FILE.png] [--display auto|st7789|ssd1306] [--panel WxH] [--panel-offset X,Y] [--max-seconds S] [--contention on|off] [--json] [--quiet]\n' +
  '       node run.mjs ELF --frames N [--out \'DIR/f%03d.png\'] [the options above]\n' +
  '       node run.mjs ELF --profile N [the options above, or --frames N [--profile-from K]]: also where the cycles went, by function (from frame K on)\n' +
  '       node run.mjs ELF --serial [--out FILE.png] [--display auto|st7789|ssd1306] [--panel WxH] [--panel-offset X,Y] [--contention on|off] [--json]\n' +
  '       node run.mjs --help';

function usage(message) {
  console.error(`octrace-pico-emulator: ${message}\n${USAGE}`);
  process.exit(2);
}

function numbers(text, separator, option) {
  const parts = text.split(separator).map(Number);
  if (parts.length !== 2 || !parts.every((n) => Number.isInteger(n) && n >= 0)) {
    usage(`${option} ${text}: expected two whole numbers separated by '${separator}'`);
  }
  return parts;
}

let args;
try {
  args = parseArgs({
    allowPositionals: true,
    options: {
      out: { type: 'string' },
      serial: { type: 'boolean', default: false },
      display: { type: 'string', default: 'auto' },
      panel: { type: 'string', default: '240x240' },
      'panel-offset': { type: 'string', default: '0,0' },
      'max-seconds': { type: 'string', default: '120' },
      frames: { type: 'string' },
      contention: { type: 'string', default: 'on' },
      profile: { type: 'string' },
      'profile-from': { type: 'string' },
      json: { type: 'boolean', default: false },
      quiet: { type: 'boolean', default: false },
      help: { type: 'boolean', short: 'h', default: false },
    },
  });
} catch (error) {
  usage(error.message);
}
const { values, positionals } = args;
if (values.help) {
  console.log(`${USAGE}\nWhat each option does, and what the emulator models: README.md beside this file.`);
  process.exit(0);
}
if (positionals.length !== 1) {
  usage(positionals.length === 0 ? 'no ELF given' : `one ELF, not ${positionals.length} arguments`);
}
const [elfPath] = positionals;
const [width, height] = numbers(values.panel, 'x', '--panel');
const [offsetX, offsetY] = numbers(values['panel-offset'], ',', '--panel-offset');
const maxSeconds = Number(values['max-seconds']);
if (!(maxSeconds > 0)) {
  usage(`--max-seconds ${values['max-seconds']}: expected a positive number`);
}
if (values.contention !== 'on' && values.contention !== 'off') {
  usage(`--contention ${values.contention}: expected on or off`);
}
const DISPLAYS = ['auto', 'st7789', 'ssd1306'];
if (!DISPLAYS.includes(values.display)) {
  usage(`--display ${values.display}: expected one of ${DISPLAYS.join(', ')}`);
}
/** The machine's options: the panels wired (the ST7789 with its size and place, the SSD1306 module, as --display asks) and the contention. */
const wired = {
  panel: values.display === 'ssd1306' ? null : { width, height, offsetX, offsetY },
  oled: values.display === 'st7789' ? null : {},
  contention: values.contention === 'on',
};
if (values.out !== undefined && !values.out.toLowerCase().endsWith('.png')) {
  usage(`--out ${values.out}: the picture is written as PNG: name a .png file`);
}
const profileTop = values.profile === undefined ? null : Number(values.profile);
if (profileTop !== null && !(Number.isInteger(profileTop) && profileTop > 0)) {
  usage(`--profile ${values.profile}: expected how many functions to list, at least 1`);
}
if (values.serial) {
  if (profileTop !== null) usage('--profile: not with --serial');
  await serve();
}
const frameCount = values.frames === undefined ? null : Number(values.frames);
if (frameCount !== null && !(Number.isInteger(frameCount) && frameCount > 0)) {
  usage(`--frames ${values.frames}: expected a whole number of frames, at least 1`);
}
const profileFrom = values['profile-from'] === undefined ? 0 : Number(values['profile-from']);
if (values['profile-from'] !== undefined) {
  if (profileTop === null || frameCount === null) usage('--profile-from: with --profile and --frames');
  if (!(Number.isInteger(profileFrom) && profileFrom >= 0 && profileFrom < frameCount)) {
    usage(`--profile-from ${values['profile-from']}: expected a frame from 0 to ${frameCount - 1}`);
  }
}
const out = values.out ?? (frameCount === null ? 'panel.png' : 'panel%03d.png');
let frameName = null;
if (frameCount !== null) {
  try {
    frameName = framePattern(out);
  } catch (error) {
    usage(`--out ${error.message}, with --frames`);
  }
}

const progress = !values.quiet && !values.json && process.stderr.isTTY;
let report;
try {
  const elf = readFileSync(elfPath);
  const pico = Pico.fromElf(elf, elfPath, wired);
  // Each frame's picture as it was when drawn, written once the run has succeeded.
  const pictures = [];
  const picture = () => encodePng(pico.display.width, pico.display.height, pico.display.picture());
  // The profile starts with the run, or once frame profileFrom - 1 is drawn.
  const profileFromHere = () => {
    if (profileTop !== null && pictures.length === profileFrom) pico.startProfile();
  };
  const onFrame = () => {
    pictures.push(picture());
    profileFromHere();
  };
  const frames = frameCount === null ? null : watchFrames(pico, { count: frameCount, onFrame });
  profileFromHere();
  const ended = pico.run({
    maxSeconds,
    onProgress: progress
      ? (_, rows) =>
          process.stderr.write(
            `\r${(pico.clock.nanos / 1e9).toFixed(3)} s emulated, ${rows} panel writes` +
              (frames ? `, ${frames.length} of ${frameCount} frames` : ''),
          )
      : undefined,
  });
  if (progress) process.stderr.write('\r\x1b[K');
  const display = pico.display;
  if (frames && ended !== 'stopped') {
    throw new RunError(
      `the firmware went to sleep after drawing ${frames.length} of ${frameCount} frames ` +
        '(a frame is drawn when the Pico\'s LED, GP25, goes out)',
    );
  }
  if (frames) {
    pictures.forEach((png, index) => writeAtomically(frameName(index), png));
  } else {
    writeAtomically(out, picture());
  }
  report = runReport(
    pico,
    out,
    frames &&
      frames.map(({ index, cycles, lit, busy, start, end }) => {
        const seconds = pico.systemClock.secondsBetween(end - cycles, end);
        return { index, out: frameName(index), cycles, seconds, lit, busy, start, end };
      }),
  );
  if (profileTop !== null) {
    report.profile = pico.profileReport(profileTop);
    report.profileFrom = profileFrom;
  }
} catch (error) {
  if (progress) process.stderr.write('\r\x1b[K');
  if (expected(error)) {
    console.error(`octrace-pico-emulator: ${error.message}`);
    process.exit(1);
  }
  throw error;
}

if (values.json) {
  console.log(JSON.stringify(report, null, 2));
} else if (!values.quiet) {
  const count = (n) => n.toLocaleString('en');
  const row = (what, key) => {
    const cycles = report.cycles[key];
    const time = cycles === null ? 'never reached' : `${count(cycles).padStart(13)} cycles  ${report.seconds[key].toFixed(3)} s`;
    return `  ${what.padEnd(44)} ${time}`;
  };
  const { transfer } = report.cycles;
  const clock = report.clock;
  const cores = report.coreCycles.slice(0, report.cores);
  const cache = report.xipCache;
  const fabric = report.busFabric;
  const contested = Object.entries(fabric.ports)
    .filter(([, { contested }]) => contested > 0)
    .map(([port, { contested }]) => `${port} ${count(contested)}`);
  console.error(
    [
      `${elfPath} on an emulated Raspberry Pi Pico (${report.cores === 2 ? 'both Cortex-M0+ cores' : 'one Cortex-M0+ core'} ` +
        `at ${mhz(clock.sysHz)}, the clock it set; the flash at ${clock.flashHz === null ? '-' : mhz(clock.flashHz)}, ` +
        `the core at ${clock.coreVolts.toFixed(2)} V):`,
      row('start-up (clocks, panel set-up and clear)', 'startUp'),
      row('parse and index the scene', 'parseAndIndex'),
      row(transfer === undefined ? 'render into the panel' : 'render (the LED lit)', 'render'),
      ...(transfer === undefined ? [] : [row('the picture to the panel over I2C', 'transfer')]),
      row('first full panel (from the picture\'s start)', 'firstFullPanel'),
      row('in all', 'total'),
      ...cores.map(
        ({ core, busy, waiting, flashStall, busStall }) =>
          `  core ${core}: ${count(busy)} cycles busy (${count(flashStall)} of them stalled on flash, ` +
          `${count(busStall)} on the other core at the bus), ${count(waiting)} waiting`,
      ),
      fabric.contention
        ? `  bus fabric: contested accesses ${contested.length > 0 ? contested.join(', ') : 'none'}`
        : '  bus fabric: contention off (no master waits for another)',
      `  XIP cache: ${count(cache.accesses)} flash reads, ${count(cache.misses)} misses` +
        (cache.lineReadCycles === null ? '' : ` (${cache.lineReadCycles} cycles a line read)`) +
        `, ${count(cache.stallCycles)} cycles stalled`,
      ...(report.frames ?? []).map(
        ({ index, out: file, cycles, seconds, lit, busy }) =>
          `  frame ${String(index).padStart(3)}: ${count(cycles).padStart(13)} cycles  ${seconds.toFixed(3)} s ` +
          `(LED lit ${count(lit)}; busy: core 0 ${count(busy[0])}, core 1 ${count(busy[1])}): ${file}`,
      ),
      ...(report.frames?.length > 1 ? [framesPerSecond(report.frames)] : []),
      report.dark
        ? `the ${report.display} panel is dark: ${report.dark}`
        : `the ${report.display} panel's ${report.panel} ${report.frames ? 'frames' : 'picture'}: ${out}`,
      ...(report.profile
        ? [
            `where the cycles went${profileFrom > 0 ? ` from frame ${profileFrom} on` : ''} ` +
              '(sampled every 256 instructions, by function; inlined code counts as its caller):',
            ...report.profile.map(
              ({ name, cycles, share }) => `  ${(100 * share).toFixed(1).padStart(5)} %  ${count(cycles).padStart(13)} cycles  ${name}`,
            ),
          ]
        : []),
    ].join('\n'),
  );
}

/** The frames a second after the first frame (which loads, and traces everything). */
function framesPerSecond(frames) {
  const after = frames.slice(1).reduce((sum, { seconds }) => sum + seconds, 0);
  return `  after the first: ${((frames.length - 1) / after).toFixed(2)} frames a second`;
}

function mhz(hz) {
  return `${+(hz / 1e6).toFixed(3)} MHz`;
}

/**
 * What the run took and did: the report `--json` prints. `clockHz` is
 * clk_sys as the firmware left it (`clock` has its changes, clk_peri, the
 * flash's serial clock and the core voltage); `seconds` are the phases'
 * lengths in the Pico's time, each cycle as long as clk_sys made it then.
 */
function runReport(pico, out, frames) {
  const display = pico.display;
  const coreCycles = pico.coreCycles();
  const cycles = pico.phases();
  return {
    elf: elfPath,
    out,
    ...(frames && { frames }),
    display: display.name,
    panel: `${display.width}x${display.height}`,
    dark: display.darkBecause,
    clockHz: pico.systemClock.hz,
    clock: pico.clockReport(),
    cores: pico.coresUsed,
    instructions: coreCycles[0].instructions + coreCycles[1].instructions,
    cycles,
    seconds: phaseSeconds(pico, cycles),
    coreCycles,
    xipCache: pico.cacheStatistics(),
    busFabric: pico.fabric.statistics(),
  };
}

/**
 * Each phase's length in seconds. The phases follow each other (start-up
 * from the machine's start, then parse and index, render, the transfer);
 * the first full panel starts with the render, the total at 0.
 */
function phaseSeconds(pico, cycles) {
  const clock = pico.systemClock;
  const seconds = {};
  let at = 0;
  for (const key of ['startUp', 'parseAndIndex', 'render', 'transfer']) {
    if (!(key in cycles)) continue;
    seconds[key] = cycles[key] === null ? null : clock.secondsBetween(at, at + cycles[key]);
    at += cycles[key] ?? 0;
  }
  const renderStart = (cycles.startUp ?? 0) + (cycles.parseAndIndex ?? 0);
  seconds.firstFullPanel = cycles.firstFullPanel === null ? null : clock.secondsBetween(renderStart, renderStart + cycles.firstFullPanel);
  seconds.total = clock.secondsBetween(0, cycles.total);
  return seconds;
}

/** --serial: serves the board on a pseudo-terminal, then exits (with --json, printing the report). */
async function serve() {
  let pico; // the board serving now (a new one after each watchdog reset)
  let drawn = -1;
  try {
    const elf = readFileSync(elfPath);
    await serveSerial(() => (pico = Pico.fromElf(elf, elfPath, wired)), {
      input: process.stdin,
      answer: (line) => console.log(line),
      onPath: (path) => console.log(path),
      writePanel: (pico, path) => {
        const display = pico.display;
        writeAtomically(path, encodePng(display.width, display.height, display.picture()));
      },
      onIdle: (pico) => {
        const display = pico.display;
        const writes = display.writes();
        if (values.out !== undefined && writes !== drawn) {
          drawn = writes;
          writeAtomically(values.out, encodePng(display.width, display.height, display.picture()));
        }
      },
    });
  } catch (error) {
    if (expected(error)) {
      console.error(`octrace-pico-emulator: ${error.message}`);
      process.exit(1);
    }
    throw error;
  }
  if (values.json) console.log(JSON.stringify(runReport(pico, values.out ?? null), null, 2));
  process.exit(0);
}

/** What a run ends with for the firmware's or the ELF's doing (exit 1), not the emulator's own failure. */
function expected(error) {
  return [RunError, ElfError, PanelError, OledError].some((kind) => error instanceof kind) || error.code === 'ENOENT';
}
