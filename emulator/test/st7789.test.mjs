// The ST7789 model: what it shows for the commands mipidsi sends, and the
// errors for what it does not take.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { PanelError, ST7789 } from '../st7789.mjs';

const COMMAND = false;
const DATA = true;

function send(panel, command, ...params) {
  panel.receive(command, COMMAND);
  for (const byte of params) panel.receive(byte, DATA);
}

/** mipidsi's ST7789 set-up: sleep out, MADCTL, inversion on, 16-bit pixels, normal mode, display on. */
function setUp(panel, madctl = 0) {
  send(panel, 0x11);
  send(panel, 0x36, madctl);
  send(panel, 0x21);
  send(panel, 0x3a, 0x55);
  send(panel, 0x13);
  send(panel, 0x29);
}

function fill(panel, [x0, x1], [y0, y1], pixels) {
  send(panel, 0x2a, x0 >> 8, x0 & 0xff, x1 >> 8, x1 & 0xff);
  send(panel, 0x2b, y0 >> 8, y0 & 0xff, y1 >> 8, y1 & 0xff);
  send(panel, 0x2c, ...pixels.flatMap((p) => [p >> 8, p & 0xff]));
}

const pixelAt = (picture, width, x, y) => [...picture.subarray(3 * (y * width + x), 3 * (y * width + x) + 3)];

test('a window fills row by row and shows in RGB565 widened as embedded-graphics widens it', () => {
  const panel = new ST7789({ width: 4, height: 2 });
  setUp(panel);
  // Red, green, blue, white, then a pixel with every channel at its midpoint.
  fill(panel, [1, 3], [0, 1], [0xf800, 0x07e0, 0x001f, 0xffff, 0x8410]);
  const picture = panel.picture();
  assert.deepEqual(pixelAt(picture, 4, 0, 0), [0, 0, 0]);
  assert.deepEqual(pixelAt(picture, 4, 1, 0), [255, 0, 0]);
  assert.deepEqual(pixelAt(picture, 4, 2, 0), [0, 255, 0]);
  assert.deepEqual(pixelAt(picture, 4, 3, 0), [0, 0, 255]);
  assert.deepEqual(pixelAt(picture, 4, 1, 1), [255, 255, 255]);
  // (16·255 + 15) / 31 = 132, (32·255 + 31) / 63 = 130.
  assert.deepEqual(pixelAt(picture, 4, 2, 1), [132, 130, 132]);
});

test('the IPS panel shows the negative without INVON, and nothing asleep or off', () => {
  const panel = new ST7789({ width: 1, height: 1 });
  assert.match(panel.darkBecause, /asleep/);
  setUp(panel);
  fill(panel, [0, 0], [0, 0], [0xf800]);
  assert.deepEqual(pixelAt(panel.picture(), 1, 0, 0), [255, 0, 0]);
  send(panel, 0x20);
  assert.deepEqual(pixelAt(panel.picture(), 1, 0, 0), [0, 255, 255]);
  send(panel, 0x28);
  assert.match(panel.darkBecause, /display is off/);
  assert.deepEqual(pixelAt(panel.picture(), 1, 0, 0), [0, 0, 0]);
});

test('MADCTL: BGR swaps red and blue; a 90° turn (MV and MX, as mipidsi sets it) turns the picture clockwise', () => {
  const bgr = new ST7789({ width: 1, height: 1 });
  setUp(bgr, 0x08);
  fill(bgr, [0, 0], [0, 0], [0xf800]);
  assert.deepEqual(pixelAt(bgr.picture(), 1, 0, 0), [0, 0, 255]);

  const turned = new ST7789({ width: 240, height: 2 });
  setUp(turned, 0x60);
  // The window's top-left pixel lands top right; its second column, one row down.
  fill(turned, [0, 1], [0, 0], [0xf800, 0x07e0]);
  const picture = turned.picture();
  assert.deepEqual(pixelAt(picture, 240, 239, 0), [255, 0, 0]);
  assert.deepEqual(pixelAt(picture, 240, 239, 1), [0, 255, 0]);
});

test('a reset pulse or SWRESET puts the controller back to sleep and keeps its memory', () => {
  const panel = new ST7789({ width: 1, height: 1 });
  setUp(panel);
  fill(panel, [0, 0], [0, 0], [0x07e0]);
  send(panel, 0x01);
  assert.match(panel.darkBecause, /asleep/);
  setUp(panel);
  assert.deepEqual(pixelAt(panel.picture(), 1, 0, 0), [0, 255, 0]);
});

test('what the model does not take is an error, never ignored', () => {
  const errors = [
    [(p) => send(p, 0xb2, 1, 2, 3, 4, 5), /command 0xb2 is not modelled/],
    [(p) => p.receive(0x12, DATA), /data byte 0x12 with no command/],
    [(p) => send(p, 0x36, 0, 0), /MADCTL takes 1 parameter bytes; a further one/],
    [(p) => send(p, 0x2a, 0, 0) || send(p, 0x29), /CASET takes 4 parameter bytes; it ended after 2/],
    [(p) => send(p, 0x2a, 0, 10, 0, 5), /CASET 10..5 is not a range/],
    [(p) => send(p, 0x2b, 0, 0, 1, 0x40), /RASET 0..320 is not a range within 0..319/],
    [(p) => send(p, 0x2c, 0), /RAMWR with COLMOD 0x66/],
    [(p) => send(p, 0x3a, 0x55) || send(p, 0x2c, 0xff) || send(p, 0x00), /RAMWR ended in the middle of a pixel/],
  ];
  for (const [action, message] of errors) {
    assert.throws(() => action(new ST7789({ width: 240, height: 240 })), (e) => e instanceof PanelError && message.test(e.message));
  }
  assert.throws(() => new ST7789({ width: 240, height: 321 }), PanelError);
});

test("coverage counts each of the panel's pixels once, from when it starts, inside the panel's window only", () => {
  const panel = new ST7789({ width: 2, height: 2, offsetX: 1, offsetY: 1 });
  setUp(panel);
  fill(panel, [0, 2], [0, 2], Array(9).fill(0xffff)); // before coverage starts: not counted
  panel.startCoverage();
  assert.equal(panel.covered, 0);
  fill(panel, [0, 2], [0, 1], Array(6).fill(0x1234)); // rows 0 and 1: the panel's top row (memory row 1) only
  assert.equal(panel.covered, 2);
  fill(panel, [1, 1], [1, 1], [0x1234]); // written again: no new pixel
  assert.equal(panel.covered, 2);
  assert.ok(!panel.fullyCovered);
  fill(panel, [1, 2], [2, 2], [1, 2]);
  assert.ok(panel.fullyCovered);
});
