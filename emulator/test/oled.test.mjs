// The SSD1306 template's phases told from its bus and its LED: a still's,
// and an animation's, whose later frames light the LED and use the bus
// again but are not the first picture's.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { GPIOPinState } from 'rp2040js';
import { OLED_WIRING, wireOled } from '../oled.mjs';

/** The wiring with a clock the test sets, a bus it drives and an LED it switches. */
function wired() {
  let time = 0;
  const controller = { attach() {} };
  const listeners = [];
  const gpio = [];
  gpio[OLED_WIRING.led] = { addListener: (listener) => listeners.push(listener) };
  const { phases } = wireOled(controller, gpio, () => time);
  return {
    phases,
    at: (t) => {
      time = t;
    },
    transfer: (from, to) => {
      time = from;
      controller.onBusEvent('start');
      time = to;
      controller.onBusEvent('stop');
    },
    led: (t, state) => {
      time = t;
      for (const listener of listeners) listener(state);
    },
  };
}

test('a still: set-up, render while the LED is lit, then the picture over the bus', () => {
  const run = wired();
  run.transfer(10, 100);
  run.led(150, GPIOPinState.High);
  run.led(1_150, GPIOPinState.Low);
  run.transfer(1_200, 1_300);
  run.transfer(1_310, 1_500);
  assert.deepEqual(run.phases(), {
    startUp: 100,
    parseAndIndex: 50,
    render: 1_000,
    transfer: 300,
    firstFullPanel: 1_350,
  });
});

test("an animation's later frames leave the first picture's phases as they were", () => {
  const run = wired();
  run.transfer(10, 100);
  run.led(150, GPIOPinState.High);
  run.led(1_150, GPIOPinState.Low);
  run.transfer(1_200, 1_500);
  // Frame 1: lit again, its changes sent while lit and after.
  run.led(1_600, GPIOPinState.High);
  run.transfer(1_700, 1_800);
  run.led(1_900, GPIOPinState.Low);
  run.transfer(1_950, 2_400);
  const phases = run.phases();
  assert.equal(phases.render, 1_000);
  assert.equal(phases.transfer, 300);
  assert.equal(phases.firstFullPanel, 1_350);
});
