// The frames a firmware draws, as the emulator tells them: a Pico template
// lights the Pico's LED (GP25) while it works on a frame (loading it,
// tracing it, sending it to the panel) and puts it out once the frame is
// whole on the panel, as a user sees it do on the board. Each time the LED
// goes out, the panel shows a finished frame: `watchFrames` records when,
// what the frame cost each core, and hands over the panel's picture; after
// the frames asked for, it stops the run.
//
// Invariants: frame n ends at the n-th falling edge of GP25, at the time of
// the core whose store to the SIO put it out; a frame's cycles run from the
// end of the frame before (the first frame's from the LED's first rising
// edge), so they add up to the time from the first frame's start to the
// last one's end; its lit cycles are those the LED was on; each core's busy
// cycles in a frame are its cycles not asleep between the two ends (to
// within the instruction the other core was in).

import { GPIOPinState } from 'rp2040js';

/** The Pico's LED. */
export const LED_PIN = 25;

/**
 * Watches `pico`'s LED for `count` frames: `onFrame(frame)` is called as
 * each ends, with `{ index, cycles, lit, busy: [core 0, core 1], start, end }`
 * (cycles of clk_sys; start and end from the machine's start), and the run
 * is stopped (`pico.stop()`) when the last has. Returns the list of frames
 * seen so far (it grows as they end).
 */
export function watchFrames(pico, { count, onFrame = () => {} }) {
  const frames = [];
  let litAt = null;
  let previousEnd = null;
  let busyBefore = null;
  const now = () => pico.cores[pico.current].cycles;
  const busy = () => pico.coreCycles().map(({ busy }) => busy);
  pico.rp2040.gpio[LED_PIN].addListener((state) => {
    if (frames.length >= count) return;
    if (state === GPIOPinState.High && litAt === null) {
      litAt = now();
      if (previousEnd === null) {
        previousEnd = litAt;
        busyBefore = busy();
      }
    } else if (state === GPIOPinState.Low && litAt !== null) {
      const end = now();
      const busyNow = busy();
      const frame = {
        index: frames.length,
        cycles: end - previousEnd,
        lit: end - litAt,
        busy: busyNow.map((b, k) => b - busyBefore[k]),
        start: litAt,
        end,
      };
      frames.push(frame);
      [litAt, previousEnd, busyBefore] = [null, end, busyNow];
      onFrame(frame);
      if (frames.length >= count) pico.stop();
    }
  });
  return frames;
}

/**
 * A file name pattern with one frame number: `%d`, or `%0Nd` for N digits
 * (`%%` is a `%`), as host-sim's frame files. Returns `index => name`, or
 * throws an Error saying why `pattern` is none.
 */
export function framePattern(pattern) {
  const refuse = () => new Error(`${pattern}: a frame pattern holds one %d or %0Nd (and %% for a %)`);
  let found = null;
  const parts = [''];
  for (let at = 0; at < pattern.length; at++) {
    if (pattern[at] !== '%') {
      parts[parts.length - 1] += pattern[at];
      continue;
    }
    if (pattern[at + 1] === '%') {
      parts[parts.length - 1] += '%';
      at++;
      continue;
    }
    const spec = /^%(0\d*)?d/.exec(pattern.slice(at));
    if (!spec || found !== null) throw refuse();
    found = spec[1] ? Number(spec[1]) : 0;
    parts.push('');
    at += spec[0].length - 1;
  }
  if (found === null) throw refuse();
  const [before, after] = parts;
  return (index) => `${before}${String(index).padStart(found, '0')}${after}`;
}
