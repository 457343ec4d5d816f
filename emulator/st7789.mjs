// An ST7789 display controller on a 4-wire SPI bus (a data/command line
// beside clock, data and chip select) and the panel that shows part of its
// 240×320 frame memory: the commands mipidsi sends, each with its
// parameters checked.
//
// Invariants: a command the model does not know, a parameter too many or
// too few, or pixels in a format it does not model is an error (thrown as
// PanelError), never ignored; the picture is what the panel shows: black
// until the controller is out of sleep with its display on. Coverage, once
// started, counts each of the panel's pixels the first time it is written.

export class PanelError extends Error {}

const MEMORY_COLUMNS = 240;
const MEMORY_ROWS = 320;

// MADCTL bits: row order (MY), column order (MX), row/column exchange (MV),
// and blue-green-red order; the two refresh-order bits change no picture.
const MADCTL_MY = 0x80;
const MADCTL_MX = 0x40;
const MADCTL_MV = 0x20;
const MADCTL_BGR = 0x08;

/** Every command the model knows: its name and how many parameter bytes it takes (null: a stream). */
const COMMANDS = new Map([
  [0x00, { name: 'NOP', params: 0 }],
  [0x01, { name: 'SWRESET', params: 0 }],
  [0x10, { name: 'SLPIN', params: 0 }],
  [0x11, { name: 'SLPOUT', params: 0 }],
  [0x13, { name: 'NORON', params: 0 }],
  [0x20, { name: 'INVOFF', params: 0 }],
  [0x21, { name: 'INVON', params: 0 }],
  [0x28, { name: 'DISPOFF', params: 0 }],
  [0x29, { name: 'DISPON', params: 0 }],
  [0x2a, { name: 'CASET', params: 4 }],
  [0x2b, { name: 'RASET', params: 4 }],
  [0x2c, { name: 'RAMWR', params: null }],
  [0x36, { name: 'MADCTL', params: 1 }],
  [0x3a, { name: 'COLMOD', params: 1 }],
]);

const hex = (byte) => `0x${byte.toString(16).padStart(2, '0')}`;

export class ST7789 {
  /**
   * `panel`: the width and height the panel shows and where they start in
   * the frame memory. `invertedPanel`: an IPS panel that shows true colours
   * only with the controller's inversion on (INVON), as the Pico-LCD-1.3's.
   */
  constructor({ width, height, offsetX = 0, offsetY = 0, invertedPanel = true }) {
    if (width < 1 || height < 1 || offsetX + width > MEMORY_COLUMNS || offsetY + height > MEMORY_ROWS) {
      throw new PanelError(`a ${width}x${height} panel at (${offsetX}, ${offsetY}) does not fit the 240x320 frame memory`);
    }
    Object.assign(this, { width, height, offsetX, offsetY, invertedPanel });
    this.memory = new Uint16Array(MEMORY_COLUMNS * MEMORY_ROWS);
    /** Memory cells written since `startCoverage` (null: not counting), and how many of them the panel shows. */
    this.written = null;
    this.covered = 0;
    /** How many times each command was received, by name. */
    this.counts = new Map();
    this.reset();
  }

  /** The controller's state after power-on, a reset pulse or SWRESET (the frame memory is kept). */
  reset() {
    this.sleeping = true;
    this.displayOn = false;
    this.inverted = false;
    this.madctl = 0;
    this.colmod = 0x66;
    this.columns = [0, MEMORY_COLUMNS - 1];
    this.rows = [0, MEMORY_ROWS - 1];
    this.command = null;
    this.params = [];
    this.pixelBytes = [];
  }

  /** A byte on the bus while chip select is low: a command if `dataCommand` is low, else data. */
  receive(byte, dataCommand) {
    if (!dataCommand) {
      this.finishCommand();
      const command = COMMANDS.get(byte);
      if (!command) {
        throw new PanelError(`ST7789: command ${hex(byte)} is not modelled`);
      }
      this.counts.set(command.name, (this.counts.get(command.name) ?? 0) + 1);
      this.command = { code: byte, ...command };
      this.params = [];
      if (command.params === 0) {
        this.execute();
      } else if (command.name === 'RAMWR') {
        this.startMemoryWrite();
      }
      return;
    }
    if (!this.command) {
      throw new PanelError(`ST7789: data byte ${hex(byte)} with no command before it`);
    }
    if (this.command.params === null) {
      this.pixelByte(byte);
      return;
    }
    if (this.params.length === this.command.params) {
      throw new PanelError(`ST7789: ${this.command.name} takes ${this.command.params} parameter bytes; a further one came (${hex(byte)})`);
    }
    this.params.push(byte);
    if (this.params.length === this.command.params) {
      this.execute();
    }
  }

  /** A new command ends the one before: one short of its parameters is an error. */
  finishCommand() {
    const command = this.command;
    if (command && command.params !== null && command.params > 0 && this.params.length < command.params) {
      throw new PanelError(
        `ST7789: ${command.name} takes ${command.params} parameter bytes; it ended after ${this.params.length}`,
      );
    }
    if (command && command.params === null && this.pixelBytes.length > 0) {
      throw new PanelError(`ST7789: RAMWR ended in the middle of a pixel (${this.pixelBytes.length} of its bytes)`);
    }
    this.command = null;
  }

  execute() {
    const p = this.params;
    switch (this.command.name) {
      case 'NOP':
      case 'NORON':
        break;
      case 'SWRESET':
        this.reset();
        return;
      case 'SLPIN':
        this.sleeping = true;
        break;
      case 'SLPOUT':
        this.sleeping = false;
        break;
      case 'INVOFF':
        this.inverted = false;
        break;
      case 'INVON':
        this.inverted = true;
        break;
      case 'DISPOFF':
        this.displayOn = false;
        break;
      case 'DISPON':
        this.displayOn = true;
        break;
      case 'CASET':
        this.columns = this.range('CASET', (p[0] << 8) | p[1], (p[2] << 8) | p[3]);
        break;
      case 'RASET':
        this.rows = this.range('RASET', (p[0] << 8) | p[1], (p[2] << 8) | p[3]);
        break;
      case 'MADCTL':
        this.madctl = p[0];
        break;
      case 'COLMOD':
        this.colmod = p[0];
        break;
      default:
        throw new PanelError(`ST7789: ${this.command.name} has no action`);
    }
  }

  /** The window's columns are the memory's rows when MV exchanges them. */
  range(name, start, end) {
    const exchanged = (this.madctl & MADCTL_MV) !== 0;
    const limit = (name === 'CASET') !== exchanged ? MEMORY_COLUMNS : MEMORY_ROWS;
    if (start > end || end >= limit) {
      throw new PanelError(`ST7789: ${name} ${start}..${end} is not a range within 0..${limit - 1}`);
    }
    return [start, end];
  }

  startMemoryWrite() {
    if ((this.colmod & 0x7) !== 0x5) {
      throw new PanelError(`ST7789: RAMWR with COLMOD ${hex(this.colmod)}: only 16-bit pixels (COLMOD 0x55) are modelled`);
    }
    this.column = this.columns[0];
    this.row = this.rows[0];
    this.pixelBytes = [];
  }

  pixelByte(byte) {
    this.pixelBytes.push(byte);
    if (this.pixelBytes.length < 2) {
      return;
    }
    const pixel = (this.pixelBytes[0] << 8) | this.pixelBytes[1];
    this.pixelBytes = [];
    const index = this.memoryIndex(this.column, this.row);
    this.memory[index] = pixel;
    if (this.written !== null && this.written[index] === 0) {
      this.written[index] = 1;
      if (this.shows(index)) this.covered++;
    }
    // Along the window's row, then down to the next; past its end, back to its start.
    if (this.column < this.columns[1]) {
      this.column++;
    } else {
      this.column = this.columns[0];
      this.row = this.row < this.rows[1] ? this.row + 1 : this.rows[0];
    }
  }

  /** Where the window's (column, row) lands in memory: MV exchanges, then MX and MY reverse the memory's columns and rows. */
  memoryIndex(column, row) {
    let [x, y] = this.madctl & MADCTL_MV ? [row, column] : [column, row];
    if (this.madctl & MADCTL_MX) x = MEMORY_COLUMNS - 1 - x;
    if (this.madctl & MADCTL_MY) y = MEMORY_ROWS - 1 - y;
    return y * MEMORY_COLUMNS + x;
  }

  /** Counts from now on how many of the panel's pixels have been written at least once. */
  startCoverage() {
    this.written = new Uint8Array(MEMORY_COLUMNS * MEMORY_ROWS);
    this.covered = 0;
  }

  /** Every pixel the panel shows has been written since `startCoverage`. */
  get fullyCovered() {
    return this.covered === this.width * this.height;
  }

  /** Whether memory cell `index` is one the panel shows. */
  shows(index) {
    const x = index % MEMORY_COLUMNS - this.offsetX;
    const y = Math.floor(index / MEMORY_COLUMNS) - this.offsetY;
    return x >= 0 && x < this.width && y >= 0 && y < this.height;
  }

  /** Why the panel is dark, or null when it shows its memory. */
  get darkBecause() {
    if (this.sleeping) return 'the controller is asleep (no SLPOUT)';
    if (!this.displayOn) return 'the display is off (no DISPON)';
    return null;
  }

  /**
   * The picture the panel shows as 8-bit RGB, row by row: each RGB565 pixel
   * widened as embedded-graphics' `Rgb888::from(Rgb565)` does (host-sim's
   * rgb565 preview), after the inversion and colour order the panel applies.
   */
  picture() {
    const rgb = new Uint8Array(this.width * this.height * 3);
    if (this.darkBecause) {
      return rgb;
    }
    // An IPS panel inverts what the controller sends unless INVON inverts it back.
    const invert = this.invertedPanel !== this.inverted ? 0xffff : 0;
    const bgr = (this.madctl & MADCTL_BGR) !== 0;
    let at = 0;
    for (let y = 0; y < this.height; y++) {
      for (let x = 0; x < this.width; x++) {
        const pixel = this.memory[(y + this.offsetY) * MEMORY_COLUMNS + x + this.offsetX] ^ invert;
        let [r, g, b] = [pixel >> 11, (pixel >> 5) & 0x3f, pixel & 0x1f];
        if (bgr) [r, b] = [b, r];
        rgb[at++] = widen(r, 31);
        rgb[at++] = widen(g, 63);
        rgb[at++] = widen(b, 31);
      }
    }
    return rgb;
  }
}

/** A channel of `max` steps to 0..255, rounded to nearest. */
function widen(value, max) {
  return Math.floor((value * 255 + (max >> 1)) / max);
}
