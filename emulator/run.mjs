#!/usr/bin/env node
// Runs a Pico firmware ELF on the emulated Pico with its ST7789 panel and
// writes the picture the panel shows as a PNG. As the template's cargo
// runner (see README.md):
//
//   CARGO_TARGET_THUMBV6M_NONE_EABI_RUNNER="node emulator/run.mjs" cargo run --release [-- OPTIONS]
//
// Options: --out FILE (default panel.png), --panel WxH (the panel's size,
// default 240x240, the Pico-LCD-1.3), --panel-offset X,Y (where it starts in
// the controller's 240x320 memory, default 0,0), --max-seconds S (emulated
// time before giving up, default 120), --contention on|off (whether two
// masters on one port of the bus fabric wait for each other, as on the
// chip: default on; off measures what the contention costs), --json (the
// report as JSON on standard output), --quiet.
//
// --serial: the board as a serial device (serial.mjs), for the live
// firmware: prints the path of a pseudo-terminal on its first line of
// standard output and serves the firmware's USB serial port there until
// standard input closes or the process is signalled (`host-sim board PATH
// scene.txt` then talks to it). With --out, the panel's picture is written
// each time the firmware waits for the host again; with --json, the report
// follows the path on standard output once the serve ends.
//
// Exit codes: 0 the run ended with both cores asleep and the picture written
// (or, with --serial, the serve ended); 1 the firmware or the ELF did
// something a real Pico would not survive, or the panel was sent what it
// does not take (the message says what); 2 bad arguments.

import { readFileSync } from 'node:fs';
import { parseArgs } from 'node:util';
import { CLOCK_HZ, Pico, RunError } from './pico.mjs';
import { ElfError } from './elf.mjs';
import { PanelError } from './st7789.mjs';
import { encodePng, writeAtomically } from './png.mjs';
import { serveSerial } from './serial.mjs';

const USAGE =
  'usage: node run.mjs ELF [--out FILE.png] [--panel WxH] [--panel-offset X,Y] [--max-seconds S] [--contention on|off] [--json] [--quiet]\n' +
  '       node run.mjs ELF --serial [--out FILE.png] [--panel WxH] [--panel-offset X,Y] [--contention on|off] [--json]';

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
      panel: { type: 'string', default: '240x240' },
      'panel-offset': { type: 'string', default: '0,0' },
      'max-seconds': { type: 'string', default: '120' },
      contention: { type: 'string', default: 'on' },
      json: { type: 'boolean', default: false },
      quiet: { type: 'boolean', default: false },
    },
  });
} catch (error) {
  usage(error.message);
}
const { values, positionals } = args;
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
const contention = values.contention === 'on';
if (values.out !== undefined && !values.out.toLowerCase().endsWith('.png')) {
  usage(`--out ${values.out}: the picture is written as PNG: name a .png file`);
}
if (values.serial) {
  await serve();
}
const out = values.out ?? 'panel.png';

const progress = !values.quiet && !values.json && process.stderr.isTTY;
const seconds = (cycles) => (cycles / CLOCK_HZ).toFixed(3);
let report;
try {
  const elf = readFileSync(elfPath);
  const pico = Pico.fromElf(elf, elfPath, { panel: { width, height, offsetX, offsetY }, contention });
  pico.run({
    maxCycles: maxSeconds * CLOCK_HZ,
    onProgress: progress
      ? (cycles, rows) => process.stderr.write(`\r${seconds(cycles)} s emulated, ${rows} panel writes`)
      : undefined,
  });
  if (progress) process.stderr.write('\r\x1b[K');
  writeAtomically(out, encodePng(width, height, pico.panel.picture()));
  report = runReport(pico, out);
} catch (error) {
  if (progress) process.stderr.write('\r\x1b[K');
  if (error instanceof RunError || error instanceof ElfError || error instanceof PanelError || error.code === 'ENOENT') {
    console.error(`octrace-pico-emulator: ${error.message}`);
    process.exit(1);
  }
  throw error;
}

if (values.json) {
  console.log(JSON.stringify(report, null, 2));
} else if (!values.quiet) {
  const count = (n) => n.toLocaleString('en');
  const row = (what, cycles) =>
    `  ${what.padEnd(44)} ${cycles === null ? 'never reached' : `${count(cycles).padStart(13)} cycles  ${seconds(cycles)} s`}`;
  const { startUp, parseAndIndex, render, firstFullPanel, total } = report.cycles;
  const cores = report.coreCycles.slice(0, report.cores);
  const cache = report.xipCache;
  const fabric = report.busFabric;
  const contested = Object.entries(fabric.ports)
    .filter(([, { contested }]) => contested > 0)
    .map(([port, { contested }]) => `${port} ${count(contested)}`);
  console.error(
    [
      `${elfPath} on an emulated Raspberry Pi Pico (${report.cores === 2 ? 'both Cortex-M0+ cores' : 'one Cortex-M0+ core'} at 125 MHz):`,
      row('start-up (clocks, panel set-up and clear)', startUp),
      row('parse and index the scene', parseAndIndex),
      row('render into the panel', render),
      row('first full panel (from the picture\'s start)', firstFullPanel),
      row('in all', total),
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
      report.dark ? `the panel is dark: ${report.dark}` : `the panel's ${report.panel} picture: ${out}`,
    ].join('\n'),
  );
}

/** What the run took and did: the report `--json` prints. */
function runReport(pico, out) {
  const coreCycles = pico.coreCycles();
  return {
    elf: elfPath,
    out,
    panel: `${width}x${height}`,
    dark: pico.panel.darkBecause,
    clockHz: CLOCK_HZ,
    cores: pico.coresUsed,
    instructions: coreCycles[0].instructions + coreCycles[1].instructions,
    cycles: pico.phases(),
    coreCycles,
    xipCache: pico.cacheStatistics(),
    busFabric: pico.fabric.statistics(),
  };
}

/** --serial: serves the board on a pseudo-terminal, then exits (with --json, printing the report). */
async function serve() {
  let pico;
  let drawn = -1;
  try {
    pico = Pico.fromElf(readFileSync(elfPath), elfPath, { panel: { width, height, offsetX, offsetY }, contention });
    await serveSerial(pico, {
      input: process.stdin,
      onPath: (path) => console.log(path),
      onIdle: () => {
        const writes = pico.events.memoryWrites;
        if (values.out !== undefined && writes !== drawn) {
          drawn = writes;
          writeAtomically(values.out, encodePng(width, height, pico.panel.picture()));
        }
      },
    });
  } catch (error) {
    if (error instanceof RunError || error instanceof ElfError || error instanceof PanelError || error.code === 'ENOENT') {
      console.error(`octrace-pico-emulator: ${error.message}`);
      process.exit(1);
    }
    throw error;
  }
  if (values.json) console.log(JSON.stringify(runReport(pico, values.out ?? null), null, 2));
  process.exit(0);
}
