// The emulated Pico as a serial device: the firmware's USB serial port
// (CDC ACM, served by usb-serial.mjs) bridged to a pseudo-terminal
// (pty-bridge.py), so that any serial program — `host-sim board`, the
// studio's "Send to board", picocom — talks to the emulated board as to a
// real one on a USB port.
//
// The machine runs in slices of SLICE_SECONDS of its time between the event loop's
// turns, so that bytes from the terminal reach it while it traces; when
// both cores sleep with nothing scheduled (the firmware waits for the
// host), it stops until bytes arrive. Its time is the emulated board's
// own: a scene takes the seconds it would take a real Pico (slower, here,
// in wall time), and nothing waits in between.
//
// Standard input carries commands, a line each, for tests that play a
// host the terminal cannot: `hold` (the host stops taking the board's
// bytes, as when no program reads the port), `release` (it takes them
// again), `times` (the board's clock in microseconds when the host last
// handed it bytes, when it last sent some, now, and how long its watchdog
// has left: `-` for never or stopped; then 1 if it waits for the host, both
// cores asleep, else 0), `panel PATH` (the panel's picture now, as a PNG
// file). Each is answered with a line on standard output (`ok`, or `times
// IN OUT NOW WATCHDOG IDLE`).
//
// A watchdog that runs out resets the board: the serve says so on
// standard error and starts a new machine from the ELF (its RAM cleared,
// as at power-on), which the host sees enumerate again; bytes in flight
// are lost, as on a real reset.
//
// Invariants: bytes pass unchanged and in order both ways (while the host
// takes them); the panel's picture is written (when asked) each time the
// firmware goes back to waiting after drawing; any other RunError (a
// fault, an endless loop) ends the serve with exit code 1, after the
// terminal is closed.

import { spawn } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { UsbSerialHost } from './usb-serial.mjs';
import { WatchdogReset } from './pico.mjs';

/** The board's time between the event loop's turns: a millisecond. */
const SLICE_SECONDS = 1e-3;

/**
 * Serves the machine `makePico()` makes on a new pseudo-terminal until
 * `input` (a readable stream: standard input, its lines commands) ends or
 * the process is signalled; `answer(line)` writes a command's answer.
 * `onPath(path)` gets the terminal's path once it is open; `onIdle(pico)`
 * runs each time the firmware waits for the host again; `writePanel(pico,
 * path)` writes the panel's picture. Resolves when the serve ends; rejects
 * with the machine's RunError.
 */
export function serveSerial(makePico, { input, answer, onPath, onIdle = () => {}, writePanel }) {
  return new Promise((resolve, reject) => {
    const bridge = spawn('python3', [fileURLToPath(new URL('./pty-bridge.py', import.meta.url))], {
      stdio: ['pipe', 'pipe', 'inherit'],
    });
    let pico;
    let host;
    const start = () => {
      pico = makePico();
      host = new UsbSerialHost(pico.rp2040, {
        onDeviceBytes: (bytes) => bridge.stdin.write(bytes),
        now: () => Math.floor(pico.clock.nanos / 1e3),
      });
    };
    start();
    let ended = false;
    let idle = false;
    let pathLine = '';
    const end = (error) => {
      if (ended) return;
      ended = true;
      bridge.stdin.end();
      bridge.kill();
      if (error) reject(error);
      else resolve();
    };
    const slice = () => {
      if (ended) return;
      let reason;
      try {
        reason = pico.run({ until: pico.time + Math.round(SLICE_SECONDS * pico.systemClock.hz) });
      } catch (error) {
        if (!(error instanceof WatchdogReset)) {
          end(error);
          return;
        }
        process.stderr.write(`octrace-pico-emulator: ${error.message}; it starts again\n`);
        start();
      }
      if (reason === 'idle') {
        idle = true;
        onIdle(pico);
      } else {
        setImmediate(slice);
      }
    };
    const wake = () => {
      if (idle && !ended) {
        idle = false;
        setImmediate(slice);
      }
    };
    const commands = {
      hold: () => (host.hold(), 'ok'),
      release: () => {
        host.release();
        wake();
        return 'ok';
      },
      times: () => {
        const left = pico.watchdogLeft();
        const time = (t) => (t === null ? '-' : String(t));
        return `times ${time(host.lastIn)} ${time(host.lastOut)} ${time(host.now())} ${time(left)} ${idle ? 1 : 0}`;
      },
      panel: (path) => {
        if (!path) return 'panel needs a path';
        writePanel(pico, path);
        return 'ok';
      },
    };
    let pending = '';
    input.on('data', (chunk) => {
      pending += chunk.toString('utf8');
      let newline;
      while ((newline = pending.indexOf('\n')) >= 0) {
        const [command, argument] = pending.slice(0, newline).trim().split(/\s+(.*)/);
        pending = pending.slice(newline + 1);
        if (command === '') continue;
        const run = Object.hasOwn(commands, command) ? commands[command] : null;
        answer(run ? run(argument) : `unknown command '${command}' (hold, release, times, panel PATH)`);
      }
    });
    bridge.stdout.on('data', (chunk) => {
      if (pathLine !== null) {
        // The bridge's first line is the terminal's path; bytes follow.
        pathLine += chunk.toString('latin1');
        const newline = pathLine.indexOf('\n');
        if (newline < 0) return;
        const rest = Buffer.from(pathLine.slice(newline + 1), 'latin1');
        onPath(pathLine.slice(0, newline));
        pathLine = null;
        chunk = rest;
      }
      host.write(chunk);
      wake();
    });
    bridge.on('exit', (code) => end(code === 0 || ended ? null : new Error(`the pseudo-terminal bridge ended (exit ${code})`)));
    bridge.on('error', (error) => end(new Error(`cannot start the pseudo-terminal bridge (python3): ${error.message}`)));
    input.on('end', () => end(null));
    for (const signal of ['SIGINT', 'SIGTERM']) {
      process.once(signal, () => end(null));
    }
    setImmediate(slice);
  });
}
