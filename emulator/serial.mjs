// The emulated Pico as a serial device: the firmware's USB serial port
// (CDC ACM, served by usb-serial.mjs) bridged to a pseudo-terminal
// (pty-bridge.py), so that any serial program — `host-sim board`, the
// studio's "Send to board", picocom — talks to the emulated board as to a
// real one on a USB port.
//
// The machine runs in slices of SLICE_CYCLES between the event loop's
// turns, so that bytes from the terminal reach it while it traces; when
// both cores sleep with nothing scheduled (the firmware waits for the
// host), it stops until bytes arrive. Its time is the emulated board's
// own: a scene takes the seconds it would take a real Pico (slower, here,
// in wall time), and nothing waits in between.
//
// Invariants: bytes pass unchanged and in order both ways; the panel's
// picture is written (when asked) each time the firmware goes back to
// waiting after drawing; a RunError (a fault, an endless loop) ends the
// serve with exit code 1, after the terminal is closed.

import { spawn } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { UsbSerialHost } from './usb-serial.mjs';

/** A millisecond of the board's time between the event loop's turns. */
const SLICE_CYCLES = 125_000;

/**
 * Serves `pico` on a new pseudo-terminal until `input` (a readable stream:
 * standard input) ends or the process is signalled. `onPath(path)` gets the
 * terminal's path once it is open; `onIdle()` runs each time the firmware
 * waits for the host again. Resolves when the serve ends; rejects with the
 * machine's RunError.
 */
export function serveSerial(pico, { input, onPath, onIdle = () => {} }) {
  return new Promise((resolve, reject) => {
    const bridge = spawn('python3', [fileURLToPath(new URL('./pty-bridge.py', import.meta.url))], {
      stdio: ['pipe', 'pipe', 'inherit'],
    });
    const host = new UsbSerialHost(pico.rp2040, { onDeviceBytes: (bytes) => bridge.stdin.write(bytes) });
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
        reason = pico.run({ until: pico.time + SLICE_CYCLES });
      } catch (error) {
        end(error);
        return;
      }
      if (reason === 'idle') {
        idle = true;
        onIdle();
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
    input.resume();
    for (const signal of ['SIGINT', 'SIGTERM']) {
      process.once(signal, () => end(null));
    }
    setImmediate(slice);
  });
}
