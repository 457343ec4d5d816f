// The SSD1306 model against its datasheet (Rev 1.1): the command table
// (chapter 9) code by code with its parameter counts, the parameters'
// fixed and invalid values, the I2C control bytes (8.1.5), the three
// addressing modes (10.1.3 to 10.1.5), and what the panel shows for the
// hardware configuration commands.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import { PanelError, SSD1306 } from '../ssd1306.mjs';

const COMMANDS = 0x00; // control byte: Co = 0, D/C# = 0: a stream of command bytes
const DATA = 0x40; // Co = 0, D/C# = 1: a stream of RAM bytes

/** One I2C write transfer to the panel: a control byte, then `bytes`. */
function transfer(panel, control, ...bytes) {
  panel.start({ read: false });
  for (const byte of [control, ...bytes]) assert.equal(panel.write(byte), true);
  panel.stop();
}

const send = (panel, ...commands) => transfer(panel, COMMANDS, ...commands);

/** The ssd1306 crate's (0.10) init for a 128×64 panel in its buffered graphics mode, byte for byte. */
const CRATE_INIT = [
  [0xae],
  [0xd5, 0x80],
  [0xa8, 0x3f],
  [0xd3, 0x00],
  [0x40],
  [0x8d, 0x14],
  [0x20, 0x00],
  [0xda, 0x12],
  [0xa1],
  [0xc8],
  [0xd9, 0x21],
  [0x81, 0x5f],
  [0xdb, 0x40],
  [0xa4],
  [0xa6],
  [0x2e],
  [0xaf],
];

function initialised() {
  const panel = new SSD1306();
  for (const command of CRATE_INIT) send(panel, ...command);
  return panel;
}

/** Writes the whole RAM through `fill(page, column)` in horizontal mode, as the crate's flush does. */
function writeAll(panel, fill) {
  send(panel, 0x21, 0, 127);
  send(panel, 0x22, 0, 7);
  const bytes = [];
  for (let page = 0; page < 8; page++) for (let column = 0; column < 128; column++) bytes.push(fill(page, column));
  for (let k = 0; k < bytes.length; k += 16) transfer(panel, DATA, ...bytes.slice(k, k + 16));
}

/** The panel's lit pixels as rows of '#' and '.', for the rows and columns asked. */
function shown(panel, xs, ys) {
  return ys.map((y) => xs.map((x) => (panel.lit(x, y) ? '#' : '.')).join(''));
}

/**
 * The datasheet's command table (9, and 2.1 for the charge pump; Rev 1.2's
 * 23h and D6h): each code, with a valid parameter list.
 */
const TABLE = [
  [0x81, [0x7f]],
  [0xa4, []],
  [0xa5, []],
  [0xa6, []],
  [0xa7, []],
  [0xae, []],
  [0xaf, []],
  [0x26, [0x00, 0x00, 0x07, 0x07, 0x00, 0xff]],
  [0x27, [0x00, 0x01, 0x00, 0x02, 0x00, 0xff]],
  [0x29, [0x00, 0x00, 0x00, 0x07, 0x01]],
  [0x2a, [0x00, 0x00, 0x00, 0x07, 0x3f]],
  [0x2e, []],
  [0xa3, [0x00, 0x40]],
  ...Array.from({ length: 16 }, (_, k) => [k, []]),
  ...Array.from({ length: 8 }, (_, k) => [0x10 + k, []]),
  [0x20, [0x02]],
  [0x21, [0x00, 0x7f]],
  ...Array.from({ length: 8 }, (_, k) => [0xb0 + k, []]),
  ...Array.from({ length: 64 }, (_, k) => [0x40 + k, []]),
  [0xa0, []],
  [0xa1, []],
  [0xa8, [0x0f]],
  [0xa8, [0x3f]],
  [0xc0, []],
  [0xc8, []],
  [0xd3, [0x3f]],
  [0xda, [0x02]],
  [0xda, [0x32]],
  [0xd5, [0xf0]],
  [0xd9, [0xf1]],
  [0xdb, [0x00]],
  [0xdb, [0x20]],
  [0xdb, [0x30]],
  [0xe3, []],
  [0x8d, [0x10]],
  [0x8d, [0x14]],
  [0x23, [0x00]],
  [0xd6, [0x00]],
];

test('every command of the datasheet table is taken with exactly its parameters, in page addressing mode as at power-on', () => {
  for (const [code, params] of TABLE) {
    const panel = new SSD1306();
    send(panel, code, ...params);
    assert.equal(panel.command, null, `${code.toString(16)} waits for no more`);
    if (params.length > 0) {
      const short = new SSD1306();
      send(short, code, ...params.slice(0, -1));
      assert.throws(() => transfer(short, DATA, 0), /waits for 1 more parameter/, `${code.toString(16)} one short`);
    }
  }
  // 22h is for the horizontal and vertical modes.
  const horizontal = new SSD1306();
  send(horizontal, 0x20, 0x00, 0x22, 0x00, 0x07);
  assert.deepEqual(horizontal.pages, [0, 7]);
});

test('a code outside the table is an error, never ignored', () => {
  // 18h–1Fh are in the table, but put the column pointer past column 127 (below).
  const known = new Set(TABLE.map(([code]) => code).concat([0x22, 0x2f], [0x18, 0x19, 0x1a, 0x1b, 0x1c, 0x1d, 0x1e, 0x1f]));
  for (let code = 0; code < 256; code++) {
    if (known.has(code)) continue;
    assert.throws(() => send(new SSD1306(), code), /not in the datasheet's command table/, `0x${code.toString(16)}`);
  }
});

test("parameters: the datasheet's fixed bits and invalid values are errors", () => {
  const cases = [
    [[0xda, 0x10], /bits CFh must be 02h/], // A[1] must be 1
    [[0xda, 0x13], /bits CFh must be 02h/],
    [[0xa8, 0x0e], /0 to 14 are/],
    [[0x20, 0x03], /11b is invalid/],
    [[0xd9, 0x20], /phase of 0 DCLKs/],
    [[0xd9, 0x02], /phase of 0 DCLKs/],
    [[0x8d, 0x15], /bits 3Bh must be 10h/],
    [[0x8d, 0x04], /bits 3Bh must be 10h/],
    [[0xdb, 0x50], /101b is not a level/],
    [[0xdb, 0x41], /bits 8Fh must be 00h/],
    [[0x26, 0x01, 0, 0, 0, 0, 0xff], /dummy byte 01h/],
    [[0x26, 0x00, 0, 0, 0, 0, 0xfe], /dummy byte FEh/],
    [[0x26, 0x00, 3, 0, 2, 0, 0xff], /end page 2 before start page 3/],
    [[0xa3, 0x00, 0x41], /65 is outside 0..64/],
    [[0x21, 0x10, 0x0f], /end column 15 before start column 16/],
    [[0x2f], /scrolling is not modelled/],
    [[0x18], /column pointer at 128, past column 127/],
    [[0x23, 0x20], /fade out or blinking/],
    [[0xd6, 0x01], /zoom in/],
  ];
  for (const [bytes, message] of cases) {
    assert.throws(() => send(new SSD1306(), ...bytes), message, bytes.map((b) => b.toString(16)).join(' '));
  }
  // The crate's VCOMH level 100b is taken, and don't-care bits are.
  send(new SSD1306(), 0xdb, 0x40);
  send(new SSD1306(), 0x20, 0xfe); // A[7:2] are don't-care: page mode
});

test('I2C: a control byte with Co set takes one byte, then another control byte; one with its six low bits set is an error; reads are errors', () => {
  const panel = new SSD1306();
  // Co = 1, D/C# = 0: a command; Co = 1, D/C# = 1: a RAM byte; then a stream of commands.
  transfer(panel, 0x80, 0xaf, 0xc0, 0xa5, 0x00, 0x8d, 0x14);
  assert.equal(panel.displayOn, true);
  assert.equal(panel.ram[0], 0xa5);
  assert.equal(panel.chargePump, true);
  assert.throws(() => transfer(new SSD1306(), 0x01), /six bits must be 0/);
  assert.throws(() => new SSD1306().start({ read: true }), /writes only/);
  assert.throws(() => new SSD1306().start({ read: false, sclHz: 1e6 }), /SCL at 1000 kHz, faster than the datasheet's 400 kHz/);
  // A command's parameters may come in the next transfer.
  const split = new SSD1306();
  send(split, 0x81);
  send(split, 0x10);
  assert.equal(split.contrast, 0x10);
});

test("the crate's set-up and a frame in horizontal mode show RAM column 0, row 0 at the top left, lit where a bit is 1", () => {
  const panel = initialised();
  assert.equal(panel.darkBecause, null);
  // Page 0, column 0: only its top row; the last page's last column: only its bottom row.
  writeAll(panel, (page, column) => (page === 0 && column === 0 ? 0x01 : page === 7 && column === 127 ? 0x80 : 0));
  assert.deepEqual(shown(panel, [0, 1, 126, 127], [0, 1, 62, 63]), ['#...', '....', '....', '...#']);
  let lit = 0;
  for (let y = 0; y < 64; y++) for (let x = 0; x < 128; x++) lit += panel.lit(x, y);
  assert.equal(lit, 2);
  const rgb = panel.picture();
  assert.deepEqual([...rgb.subarray(0, 6)], [255, 255, 255, 0, 0, 0]);
});

test('horizontal and vertical addressing wrap within the column and page ranges', () => {
  const panel = initialised();
  writeAll(panel, () => 0);
  // Horizontal: columns 2..3 of pages 1..2, then back to (2, 1).
  send(panel, 0x21, 2, 3, 0x22, 1, 2);
  transfer(panel, DATA, 1, 2, 3, 4, 5);
  assert.deepEqual([...panel.ram.subarray(128 + 2, 128 + 4)], [5, 2]);
  assert.deepEqual([...panel.ram.subarray(256 + 2, 256 + 4)], [3, 4]);
  // Vertical: down pages 1..2 first, then the next column.
  send(panel, 0x20, 0x01, 0x21, 10, 11, 0x22, 1, 2);
  transfer(panel, DATA, 1, 2, 3, 4);
  assert.deepEqual([panel.ram[128 + 10], panel.ram[256 + 10], panel.ram[128 + 11], panel.ram[256 + 11]], [1, 2, 3, 4]);
});

test('page addressing: B0h–B7h and 00h–1Fh set the pointer, which wraps within the column range on its page; they are errors in the other modes', () => {
  const panel = new SSD1306();
  send(panel, 0xb3, 0x0e, 0x17); // page 3, column 0x7e
  transfer(panel, DATA, 0xaa, 0xbb, 0xcc);
  assert.deepEqual([panel.ram[3 * 128 + 126], panel.ram[3 * 128 + 127], panel.ram[3 * 128]], [0xaa, 0xbb, 0xcc]);
  // The crate's set_draw_area sends 21h in page mode too: the wrap follows its range.
  send(panel, 0x21, 4, 5, 0xb1);
  transfer(panel, DATA, 1, 2, 3);
  assert.deepEqual([panel.ram[128 + 4], panel.ram[128 + 5]], [3, 2]);
  const horizontal = initialised();
  assert.throws(() => send(horizontal, 0xb0), /page addressing mode only/);
  assert.throws(() => send(horizontal, 0x10), /page addressing mode only/);
  assert.throws(() => send(new SSD1306(), 0x22, 0, 7), /horizontal and vertical addressing modes/);
});

test('segment re-map, COM scan direction and the COM pins configuration move, mirror and interleave the picture', () => {
  // The RAM: a bit only at column 0 of rows 0 and 1.
  const fill = (page, column) => (page === 0 && column === 0 ? 0x03 : 0);
  const panel = initialised();
  writeAll(panel, fill);
  assert.deepEqual(shown(panel, [0, 127], [0, 1, 2, 32, 62, 63]), ['#.', '#.', '..', '..', '..', '..']);
  send(panel, 0xa0); // SEG0 is column 0 again: the picture mirrored
  assert.deepEqual(shown(panel, [0, 127], [0, 1]), ['.#', '.#']);
  send(panel, 0xa1, 0xc0); // scanning COM0 to COM63: upside down
  assert.deepEqual(shown(panel, [0], [0, 62, 63]), ['.', '#', '#']);
  send(panel, 0xc8, 0xda, 0x02); // sequential COM pins on this module: rows 0 and 1 land half a panel apart
  assert.deepEqual(shown(panel, [0], [0, 1, 32, 33]), ['#', '.', '#', '.']);
  send(panel, 0xda, 0x32); // left/right remap swaps the halves
  assert.deepEqual(shown(panel, [0], [0, 1, 32, 33]), ['.', '.', '#', '#']);
});

test('start line, display offset and the multiplex ratio pick which RAM rows the panel shows, and where', () => {
  const panel = initialised();
  writeAll(panel, (page, column) => (page === 1 && column === 0 ? 0x01 : 0)); // RAM row 8
  send(panel, 0x48); // start line 8: RAM row 8 on top
  assert.deepEqual(shown(panel, [0], [0, 8]), ['#', '.']);
  send(panel, 0x40, 0xd3, 0x04); // offset 4 moves the picture up four rows
  assert.deepEqual(shown(panel, [0], [4, 8]), ['#', '.']);
  send(panel, 0xd3, 0x00, 0xa8, 0x1f); // 32 rows multiplexed: half the panel is dark
  let lit = 0;
  send(panel, 0xa5);
  for (let y = 0; y < 64; y++) lit += panel.lit(0, y);
  assert.equal(lit, 64, 'entire display on lights every pixel');
  send(panel, 0xa4, 0xa7);
  for (let y = 0, dark = 0; y < 64; y++) {
    if (panel.ramRowShownAt(y) === null) dark++;
    if (y === 63) assert.equal(dark, 32);
  }
  assert.equal(panel.lit(1, 0) || panel.lit(1, 63), true, 'inverse lights the zero bits of the rows shown');
});

test('inverse, entire display on, and a dark panel when the display or the charge pump is off', () => {
  const panel = initialised();
  writeAll(panel, () => 0);
  assert.equal(panel.lit(5, 5), false);
  send(panel, 0xa7);
  assert.equal(panel.lit(5, 5), true);
  send(panel, 0xa6, 0xa5);
  assert.equal(panel.lit(5, 5), true);
  send(panel, 0xa4, 0x8d, 0x10);
  assert.match(panel.darkBecause, /charge pump/);
  send(panel, 0x8d, 0x14, 0xae);
  assert.match(panel.darkBecause, /display is off/);
  assert.ok(panel.picture().every((v) => v === 0));
  assert.throws(() => new SSD1306({ address: 0x3e }), PanelError);
});
