// An SSD1306 OLED controller (Solomon Systech SSD1306 datasheet, Rev 1.1)
// on the I2C bus, and the 128×64 panel of the common 0.96-inch module it
// drives: every command of the datasheet's command table (chapter 9) with
// its parameters checked bit by bit, the I2C protocol of 8.1.5 (the slave
// address, then control bytes: Co and D/C#, six zeros), the graphic display
// data RAM (8 pages of 128 columns, a byte a column of 8 rows, bit 0 on
// top) written in page, horizontal or vertical addressing mode within the
// column and page ranges (10.1.3 to 10.1.5), and the picture the panel
// shows from it: segment re-map, COM scan direction, COM pins
// configuration, multiplex ratio, display offset and start line, inverse
// and entire-display-on, display on and the charge pump.
//
// The module: its 64 rows are wired to the controller's COM pads
// alternately from the left and right side (which is why it wants the
// alternative COM pin configuration, DAh 12h), and it is mounted so that the
// set-up every driver sends (segment re-map A1h, COM scan remapped C8h,
// DAh 12h) shows RAM column 0, row 0 at its top left. Any other set-up
// shows what that module shows: mirrored, upside down, rows interleaved.
// Its panel has no supply but the charge pump (8Dh 14h). A lit pixel is
// written white, an unlit one black: the module's colour (white, blue, or
// yellow over the top 16 rows on two-colour ones) and the contrast (81h)
// change how bright "on" is, not which pixels are.
//
// Invariants: a command outside the table, a parameter whose fixed bits are
// not the datasheet's or whose value it calls invalid, data while a
// command waits for its parameters, a control byte with its low six bits
// set, or a read is an error (PanelError), never ignored; so is what the
// model does not animate (scrolling, fading, zoom) when it is switched on.
// The RAM's content at power-on is undefined in the datasheet: the model
// fills it with a fixed pseudo-random pattern, as a real panel shows noise.

export class PanelError extends Error {}

const COLUMNS = 128;
const PAGES = 8;
const ROWS = 64;
/** The module's I2C address with SA0 low; 0x3D with it high. */
export const SSD1306_ADDRESS = 0x3c;
/** The fastest SCL its I2C interface takes (the datasheet's I2C timing table: a clock cycle of 2.5 µs or more). */
const MAX_SCL_HZ = 400_000;

/** The addressing modes of 20h. */
const MODE_HORIZONTAL = 0;
const MODE_VERTICAL = 1;
const MODE_PAGE = 2;
const MODE_NAMES = ['horizontal', 'vertical', 'page'];

const hex = (byte) => `${byte.toString(16).padStart(2, '0').toUpperCase()}h`;

/**
 * A parameter byte: `value` is the mask of the bits it carries, `fixed`
 * the bits the datasheet fixes (with their values in `fixedValue`); the
 * rest are don't-care. `check(value)` returns why a value is invalid, or
 * null.
 */
const param = (name, value, { fixed = 0, fixedValue = 0, check = () => null } = {}) => ({ name, value, fixed, fixedValue, check });
const range = (low, high) => (v) => (v < low || v > high ? `${v} is outside ${low}..${high}` : null);

/**
 * The command table, a line a command (or a run of codes): its codes, name
 * and parameters. `run(controller, code, params)` acts on it.
 */
const TABLE = [
  // 1. Fundamental
  { codes: [0x81], name: 'Set Contrast Control', params: [param('contrast', 0xff)], run: (c, _, [v]) => (c.contrast = v) },
  { codes: [0xa4, 0xa5], name: 'Entire Display ON', params: [], run: (c, code) => (c.entireDisplayOn = code === 0xa5) },
  { codes: [0xa6, 0xa7], name: 'Set Normal/Inverse Display', params: [], run: (c, code) => (c.inverse = code === 0xa7) },
  { codes: [0xae, 0xaf], name: 'Set Display ON/OFF', params: [], run: (c, code) => (c.displayOn = code === 0xaf) },
  // 2. Scrolling
  {
    codes: [0x26, 0x27],
    name: 'Continuous Horizontal Scroll Setup',
    params: [
      param('dummy', 0, { fixed: 0xff, fixedValue: 0x00 }),
      param('start page', 0x07),
      param('interval', 0x07),
      param('end page', 0x07),
      param('dummy', 0, { fixed: 0xff, fixedValue: 0x00 }),
      param('dummy', 0, { fixed: 0xff, fixedValue: 0xff }),
    ],
    run: (c, code, p) => c.scrollSetup(code, p),
  },
  {
    codes: [0x29, 0x2a],
    name: 'Continuous Vertical and Horizontal Scroll Setup',
    params: [
      param('dummy', 0, { fixed: 0xff, fixedValue: 0x00 }),
      param('start page', 0x07),
      param('interval', 0x07),
      param('end page', 0x07),
      param('vertical offset', 0x3f),
    ],
    run: (c, code, p) => c.scrollSetup(code, p),
  },
  { codes: [0x2e], name: 'Deactivate Scroll', params: [], run: (c) => (c.scrolling = false) },
  {
    codes: [0x2f],
    name: 'Activate Scroll',
    params: [],
    run: () => {
      throw new PanelError('SSD1306: 2Fh (Activate Scroll): scrolling is not modelled (the picture would move)');
    },
  },
  {
    codes: [0xa3],
    name: 'Set Vertical Scroll Area',
    params: [param('fixed rows', 0x3f), param('scroll rows', 0x7f, { check: range(0, 64) })],
    run: (c, _, p) => (c.verticalScrollArea = p),
  },
  // 3. Addressing
  { codes: range16(0x00), name: 'Set Lower Column Start Address for Page Addressing Mode', params: [], run: (c, code) => c.pageModeColumn(code, false) },
  { codes: range16(0x10), name: 'Set Higher Column Start Address for Page Addressing Mode', params: [], run: (c, code) => c.pageModeColumn(code, true) },
  {
    codes: [0x20],
    name: 'Set Memory Addressing Mode',
    params: [param('mode', 0x03, { check: (v) => (v === 3 ? '11b is invalid' : null) })],
    run: (c, _, [mode]) => (c.mode = mode),
  },
  {
    codes: [0x21],
    name: 'Set Column Address',
    params: [param('start', 0x7f), param('end', 0x7f)],
    run: (c, _, [start, end]) => c.columnRange(start, end),
  },
  {
    codes: [0x22],
    name: 'Set Page Address',
    params: [param('start', 0x07), param('end', 0x07)],
    run: (c, _, [start, end]) => c.pageRange(start, end),
  },
  { codes: range8(0xb0), name: 'Set Page Start Address for Page Addressing Mode', params: [], run: (c, code) => c.pageModePage(code & 7) },
  // 4. Hardware configuration
  { codes: Array.from({ length: 64 }, (_, k) => 0x40 + k), name: 'Set Display Start Line', params: [], run: (c, code) => (c.startLine = code & 0x3f) },
  { codes: [0xa0, 0xa1], name: 'Set Segment Re-map', params: [], run: (c, code) => (c.segmentRemap = code === 0xa1) },
  {
    codes: [0xa8],
    name: 'Set Multiplex Ratio',
    params: [param('ratio', 0x3f, { check: (v) => (v < 15 ? `${v} is invalid (0 to 14 are)` : null) })],
    run: (c, _, [ratio]) => (c.multiplex = ratio + 1),
  },
  { codes: [0xc0, 0xc8], name: 'Set COM Output Scan Direction', params: [], run: (c, code) => (c.comRemap = code === 0xc8) },
  { codes: [0xd3], name: 'Set Display Offset', params: [param('offset', 0x3f)], run: (c, _, [offset]) => (c.displayOffset = offset) },
  {
    codes: [0xda],
    name: 'Set COM Pins Hardware Configuration',
    params: [param('configuration', 0x30, { fixed: 0xcf, fixedValue: 0x02 })],
    run: (c, _, [v]) => {
      c.alternativeComPins = (v & 0x10) !== 0;
      c.comLeftRightRemap = (v & 0x20) !== 0;
    },
  },
  // 5. Timing and driving scheme
  {
    codes: [0xd5],
    name: 'Set Display Clock Divide Ratio/Oscillator Frequency',
    params: [param('divide ratio and frequency', 0xff)],
    run: (c, _, [v]) => (c.clockDivide = v),
  },
  {
    codes: [0xd9],
    name: 'Set Pre-charge Period',
    params: [param('phases', 0xff, { check: (v) => ((v & 0x0f) === 0 || (v & 0xf0) === 0 ? 'a phase of 0 DCLKs is invalid' : null) })],
    run: (c, _, [v]) => (c.precharge = v),
  },
  {
    codes: [0xdb],
    name: 'Set VCOMH Deselect Level',
    // 000b, 010b and 011b are the datasheet's levels; 100b is the one
    // Adafruit's driver and the ssd1306 crate (VcomhLevel::Auto) send,
    // which panels take (the SSD1306's successors document it).
    params: [
      param('level', 0x70, {
        fixed: 0x8f,
        fixedValue: 0x00,
        check: (v) => ([0x00, 0x20, 0x30, 0x40].includes(v & 0x70) ? null : `A[6:4] = ${((v >> 4) & 7).toString(2).padStart(3, '0')}b is not a level`),
      }),
    ],
    run: (c, _, [v]) => (c.vcomh = v),
  },
  { codes: [0xe3], name: 'NOP', params: [], run: () => {} },
  // Charge pump (the datasheet's charge pump command table, 2.1).
  {
    codes: [0x8d],
    name: 'Charge Pump Setting',
    params: [param('enable', 0x04, { fixed: 0x3b, fixedValue: 0x10 })],
    run: (c, _, [v]) => (c.chargePump = (v & 0x04) !== 0),
  },
  // Rev 1.2's graphic acceleration commands: taken while off, not animated.
  {
    codes: [0x23],
    name: 'Set Fade Out and Blinking',
    params: [param('mode and interval', 0x3f, { fixed: 0xc0, fixedValue: 0x00, check: (v) => ((v & 0x30) === 0x10 ? 'A[5:4] = 01b is invalid' : null) })],
    run: (_, __, [v]) => notAnimated(v & 0x30, '23h (fade out or blinking)'),
  },
  {
    codes: [0xd6],
    name: 'Set Zoom In',
    params: [param('zoom', 0x01, { fixed: 0xfe, fixedValue: 0x00 })],
    run: (_, __, [v]) => notAnimated(v & 0x01, 'D6h (zoom in)'),
  },
];

function range16(first) {
  return Array.from({ length: 16 }, (_, k) => first + k);
}

function range8(first) {
  return Array.from({ length: 8 }, (_, k) => first + k);
}

function notAnimated(on, what) {
  if (on) throw new PanelError(`SSD1306: ${what} switched on: not modelled`);
}

/** Every command by its code. */
const COMMANDS = new Map(TABLE.flatMap((command) => command.codes.map((code) => [code, command])));

export class SSD1306 {
  /** `address`: 0x3C (SA0 low, the usual module) or 0x3D. */
  constructor({ address = SSD1306_ADDRESS } = {}) {
    if (address !== 0x3c && address !== 0x3d) {
      throw new PanelError(`an SSD1306 answers at 0x3C or 0x3D (its SA0 pin), not 0x${address.toString(16)}`);
    }
    this.address = address;
    this.width = COLUMNS;
    this.height = ROWS;
    /** The RAM: a byte a column of each page, bit 0 the page's top row. */
    this.ram = new Uint8Array(COLUMNS * PAGES);
    let state = 0x2545f491;
    for (let i = 0; i < this.ram.length; i++) {
      state ^= state << 13;
      state ^= state >>> 17;
      state ^= state << 5;
      this.ram[i] = state & 0xff;
    }
    /** How many times each command was received, by name; RAM bytes written. */
    this.counts = new Map();
    this.dataBytes = 0;
    this.powerOn();
  }

  /** The controller's state at power-on (its RES# pulse: most modules tie it to an RC). */
  powerOn() {
    Object.assign(this, {
      contrast: 0x7f,
      entireDisplayOn: false,
      inverse: false,
      displayOn: false,
      scrolling: false,
      verticalScrollArea: [0, 64],
      mode: MODE_PAGE,
      columns: [0, COLUMNS - 1],
      pages: [0, PAGES - 1],
      column: 0,
      page: 0,
      startLine: 0,
      segmentRemap: false,
      multiplex: ROWS,
      comRemap: false,
      displayOffset: 0,
      alternativeComPins: true,
      comLeftRightRemap: false,
      clockDivide: 0x80,
      precharge: 0x22,
      vcomh: 0x20,
      chargePump: false,
    });
    this.command = null;
    this.params = [];
    this.inTransfer = false;
    this.awaitingControl = false;
    this.dataNext = false;
    this.singleByte = false;
  }

  // --- I2C (datasheet 8.1.5) --------------------------------------------

  /**
   * The slave address matched, SCL at `sclHz`: a write transfer starts with
   * a control byte.
   */
  start({ read, sclHz = MAX_SCL_HZ }) {
    if (sclHz > MAX_SCL_HZ) {
      throw new PanelError(
        `SSD1306: SCL at ${(sclHz / 1000).toFixed(0)} kHz, faster than the datasheet's 400 kHz (its I2C timing table: a clock cycle of at least 2.5 µs)`,
      );
    }
    if (read) {
      throw new PanelError('SSD1306: a read transfer: the model takes writes only (reading its status byte is not modelled)');
    }
    this.inTransfer = true;
    this.awaitingControl = true;
  }

  /** A byte of the transfer; returns the acknowledge. */
  write(byte) {
    if (!this.inTransfer) throw new PanelError(`SSD1306: byte ${hex(byte)} outside a transfer`);
    if (this.awaitingControl) {
      if (byte & 0x3f) {
        throw new PanelError(`SSD1306: control byte ${hex(byte)}: after Co and D/C# its six bits must be 0`);
      }
      this.singleByte = (byte & 0x80) !== 0;
      this.dataNext = (byte & 0x40) !== 0;
      this.awaitingControl = false;
      return true;
    }
    if (this.dataNext) {
      this.dataByte(byte);
    } else {
      this.commandByte(byte);
    }
    // Co set: one byte, then another control byte.
    if (this.singleByte) this.awaitingControl = true;
    return true;
  }

  /** The STOP: the next transfer starts with a control byte again; a command may take its parameters from it. */
  stop() {
    this.inTransfer = false;
  }

  // --- commands ---------------------------------------------------------

  commandByte(byte) {
    if (this.command) {
      this.params.push(byte);
    } else {
      const command = COMMANDS.get(byte);
      if (!command) throw new PanelError(`SSD1306: command ${hex(byte)} is not in the datasheet's command table`);
      this.command = { code: byte, ...command };
      this.params = [];
    }
    const { code, name, params, run } = this.command;
    if (this.params.length < params.length) return;
    this.params.forEach((value, k) => {
      const spec = params[k];
      const where = `SSD1306: ${hex(code)} (${name}), its ${spec.name} byte ${hex(value)}`;
      if ((value & spec.fixed) !== spec.fixedValue) {
        throw new PanelError(`${where}: bits ${hex(spec.fixed)} must be ${hex(spec.fixedValue)}`);
      }
      const invalid = spec.check(value & (spec.value | spec.fixed));
      if (invalid) throw new PanelError(`${where}: ${invalid}`);
    });
    const values = this.params.map((value, k) => value & params[k].value);
    this.command = null;
    this.counts.set(name, (this.counts.get(name) ?? 0) + 1);
    run(this, code, values);
  }

  scrollSetup(code, [, startPage, interval, endPage]) {
    if (endPage < startPage) {
      throw new PanelError(`SSD1306: ${hex(code)}: end page ${endPage} before start page ${startPage}`);
    }
    this.scroll = { code, startPage, interval, endPage };
  }

  /** 00h–1Fh: a nibble of the column pointer, in page addressing mode only. */
  pageModeColumn(code, high) {
    this.onlyInPageMode(code);
    const nibble = code & 0x0f;
    this.column = high ? (nibble << 4) | (this.column & 0x0f) : (this.column & 0xf0) | nibble;
    if (this.column >= COLUMNS) {
      throw new PanelError(`SSD1306: ${hex(code)} puts the column pointer at ${this.column}, past column ${COLUMNS - 1}`);
    }
  }

  /** B0h–B7h: the page pointer, in page addressing mode only. */
  pageModePage(page) {
    this.onlyInPageMode(0xb0 | page);
    this.page = page;
  }

  onlyInPageMode(code) {
    if (this.mode !== MODE_PAGE) {
      throw new PanelError(`SSD1306: ${hex(code)} is for page addressing mode only; the mode is ${MODE_NAMES[this.mode]} (20h)`);
    }
  }

  /**
   * 21h: the column range and pointer. The datasheet gives it for the
   * horizontal and vertical modes; the ssd1306 crate also sends it in page
   * mode (`set_draw_area`), where the range is the one the page mode's
   * pointer wraps in (10.1.3).
   */
  columnRange(start, end) {
    if (end < start) throw new PanelError(`SSD1306: 21h: end column ${end} before start column ${start}`);
    this.columns = [start, end];
    this.column = start;
  }

  /** 22h: the page range and pointer, for the horizontal and vertical modes. */
  pageRange(start, end) {
    if (this.mode === MODE_PAGE) {
      throw new PanelError('SSD1306: 22h (Set Page Address) is for horizontal and vertical addressing modes; the mode is page (20h)');
    }
    if (end < start) throw new PanelError(`SSD1306: 22h: end page ${end} before start page ${start}`);
    this.pages = [start, end];
    this.page = start;
  }

  // --- the RAM ------------------------------------------------------------

  dataByte(byte) {
    if (this.command) {
      throw new PanelError(
        `SSD1306: a data byte while ${hex(this.command.code)} (${this.command.name}) waits for ` +
          `${this.command.params.length - this.params.length} more parameter byte(s)`,
      );
    }
    this.ram[this.page * COLUMNS + this.column] = byte;
    this.dataBytes++;
    const [firstColumn, lastColumn] = this.columns;
    const [firstPage, lastPage] = this.pages;
    switch (this.mode) {
      case MODE_PAGE:
        // Along the page; past the column range's end, back to its start, same page.
        this.column = this.column === lastColumn ? firstColumn : this.column + 1;
        break;
      case MODE_HORIZONTAL:
        if (this.column < lastColumn) {
          this.column++;
        } else {
          this.column = firstColumn;
          this.page = this.page < lastPage ? this.page + 1 : firstPage;
        }
        break;
      case MODE_VERTICAL:
        if (this.page < lastPage) {
          this.page++;
        } else {
          this.page = firstPage;
          this.column = this.column < lastColumn ? this.column + 1 : firstColumn;
        }
        break;
    }
  }

  /** RAM bit of `row` (0..63) in `column`. */
  ramBit(column, row) {
    return (this.ram[(row >> 3) * COLUMNS + column] >> (row & 7)) & 1;
  }

  // --- the panel -----------------------------------------------------------

  /** Why the panel is dark, or null when it shows. */
  get darkBecause() {
    if (!this.displayOn) return 'the display is off (no AFh)';
    if (!this.chargePump) return "the charge pump is off (8Dh 14h): the module's panel has no other supply";
    return null;
  }

  /**
   * The RAM row the panel's row `y` (0 on top) shows, or null when no
   * active COM drives it: the module's wiring to a COM pad, the COM pins
   * configuration (DAh), the scan direction (C0h/C8h) against the
   * multiplex ratio, the display offset (D3h) and the start line (40h–7Fh).
   */
  ramRowShownAt(y) {
    const half = ROWS / 2;
    // The module: its rows take the pads alternately from each side.
    const pad = y < half ? ROWS - 1 - 2 * y : 2 * (ROWS - 1) - 2 * y;
    let com;
    if (this.alternativeComPins) {
      com = pad % 2 === 0 ? pad / 2 : half + (pad - 1) / 2;
    } else {
      com = pad;
    }
    if (this.comLeftRightRemap) com = (com + half) % ROWS;
    const n = this.multiplex;
    const scanned = this.comRemap ? (((n - 1 - com) % ROWS) + ROWS) % ROWS : com;
    const rowCounter = (scanned + this.displayOffset) % ROWS;
    if (rowCounter >= n) return null;
    return (rowCounter + this.startLine) % ROWS;
  }

  /** The RAM column the panel's column `x` (0 on the left) shows: SEG0 is on the right. */
  ramColumnShownAt(x) {
    return this.segmentRemap ? x : COLUMNS - 1 - x;
  }

  /** Whether the panel's pixel (x, y) is lit. */
  lit(x, y) {
    if (this.darkBecause) return false;
    if (this.entireDisplayOn) return true;
    const row = this.ramRowShownAt(y);
    if (row === null) return false;
    return (this.ramBit(this.ramColumnShownAt(x), row) === 1) !== this.inverse;
  }

  /** The picture as 8-bit RGB, row by row: lit pixels white, the rest black. */
  picture() {
    const rgb = new Uint8Array(COLUMNS * ROWS * 3);
    for (let y = 0; y < ROWS; y++) {
      for (let x = 0; x < COLUMNS; x++) {
        if (this.lit(x, y)) rgb.fill(255, 3 * (y * COLUMNS + x), 3 * (y * COLUMNS + x) + 3);
      }
    }
    return rgb;
  }
}
