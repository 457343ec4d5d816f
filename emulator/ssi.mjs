// The RP2040's SSI (0x18000000, datasheet 4.10), the QSPI controller between
// the chip and its flash: the registers boot2s and the boot ROM program, the
// direct-mode transfers they make through DR0 (standard SPI frames in
// TX_AND_RX mode; enhanced-format EEPROM reads, as boot2's dummy quad read),
// each taking its serial clocks, and the XIP line reads the cache makes on a
// miss (timed by xip-timing.mjs, framed as the flash chip must take them).
//
// Direct mode: a frame written to DR0 starts when the one before it ends;
// chip select stays low while frames follow each other and goes high when
// the TX FIFO has run empty (the flash then ends its command); a received
// frame is in the RX FIFO once shifted in. SR's BUSY, TFE, TFNF, RFNE and
// TXFLR, RXFLR follow from those times. CTRLR0, CTRLR1, BAUDR, SPI_CTRLR0 and
// RX_SAMPLE_DLY are ignored while SSIENR is 1, as the SSI ignores them;
// writing SSIENR 0 empties the FIFOs and ends the transfer.
//
// The serial clock is clk_sys / SCKDV (BAUDR): the flash chip checks each
// transfer's against its rating, and an XIP miss lasts that clock's cycles
// (xip-timing.mjs), so a faster clk_sys at the same divider runs the flash
// faster and a miss costs the same cycles.
//
// Invariants: a transfer the model does not frame (no slave selected, a
// frame size not a whole number of bytes, RX FIFO overrun, reading an empty
// RX FIFO, an XIP read with the SSI off) is an error, never a made-up word;
// everything the flash sees goes through the W25Q16JV model, at the serial
// clock the SSI runs then.

import { BasePeripheral } from 'rp2040js';
import { RunError } from './errors.mjs';
import { lineTransferCycles, serialClockCycles, transferCycles, xipTransferFormat } from './xip-timing.mjs';

const CTRLR0 = 0x00;
const CTRLR1 = 0x04;
const SSIENR = 0x08;
const MWCR = 0x0c;
const SER = 0x10;
const BAUDR = 0x14;
const TXFTLR = 0x18;
const RXFTLR = 0x1c;
const TXFLR = 0x20;
const RXFLR = 0x24;
const SR = 0x28;
const IMR = 0x2c;
const ISR = 0x30;
const RISR = 0x34;
const TXOICR = 0x38;
const ICR = 0x48;
const DMACR = 0x4c;
const DMATDLR = 0x50;
const DMARDLR = 0x54;
const IDR = 0x58;
const SSI_VERSION_ID = 0x5c;
const DR0 = 0x60;
const DR_LAST = 0xec;
const RX_SAMPLE_DLY = 0xf0;
const SPI_CTRLR0 = 0xf4;
const TXD_DRIVE_EDGE = 0xf8;

const SR_BUSY = 1 << 0;
const SR_TFNF = 1 << 1;
const SR_TFE = 1 << 2;
const SR_RFNE = 1 << 3;
const SR_RFF = 1 << 4;
const FIFO_DEPTH = 16;
const TMOD_TX_AND_RX = 0;
const TMOD_EEPROM_READ = 3;

/** Registers the SSI ignores while enabled, and that shape a transfer. */
const CONFIGURATION = new Set([CTRLR0, CTRLR1, BAUDR, RX_SAMPLE_DLY, SPI_CTRLR0]);

export class Ssi extends BasePeripheral {
  /** `chip`: the flash (W25Q16JV). `now()`: the machine's time in cycles; `sysHz()`: clk_sys. */
  constructor(rp2040, chip, now, sysHz) {
    super(rp2040, 'SSI');
    Object.assign(this, { chip, now, sysHz });
    this.registers = new Map([
      [CTRLR0, 0],
      [CTRLR1, 0],
      [MWCR, 0],
      [SER, 0],
      [BAUDR, 0],
      [TXFTLR, 0],
      [RXFTLR, 0],
      [IMR, 0x3f],
      [DMACR, 0],
      [DMATDLR, 0],
      [DMARDLR, 0],
      [RX_SAMPLE_DLY, 0],
      [SPI_CTRLR0, 0x0300_0000], // XIP_CMD 03h
      [TXD_DRIVE_EDGE, 0],
    ]);
    this.enabled = false;
    this.clear();
    /** The cycles an XIP line read takes, valid while `xipReady`. */
    this.xipCycles = 0;
    this.xipReady = false;
  }

  /** Empties the FIFOs and ends any transfer (chip select high). */
  clear() {
    if (this.selected) this.chip.deselect();
    this.selected = false;
    this.frameStarts = [];
    this.received = [];
    this.busyUntil = 0;
    this.eepromWords = [];
  }

  fail(message) {
    throw new RunError(`SSI: ${message}`);
  }

  /** clk_sys changed: the serial clock with it, which the next XIP read checks again. */
  clockChanged() {
    this.xipReady = false;
  }

  /** Tells the flash chip the serial clock of the transfer starting. */
  clockTheChip() {
    this.chip.serialClockHz = this.sysHz() / serialClockCycles(this.registers.get(BAUDR));
  }

  /** The flash's serial clock as BAUDR sets it now, in Hz (null while BAUDR stops it). */
  get serialClockHz() {
    const divider = this.registers.get(BAUDR) & 0xfffe;
    return divider === 0 ? null : this.sysHz() / divider;
  }

  get ctrlr0() {
    return this.registers.get(CTRLR0);
  }

  /** Drops what time has passed: started frames, and chip select after the last frame. */
  advance(now) {
    while (this.frameStarts.length > 0 && this.frameStarts[0] <= now) this.frameStarts.shift();
    if (this.selected && this.frameStarts.length === 0 && now >= this.busyUntil) {
      this.chip.deselect();
      this.selected = false;
    }
  }

  readUint32(offset) {
    const now = this.now();
    this.advance(now);
    switch (offset) {
      case SSIENR:
        return this.enabled ? 1 : 0;
      case TXFLR:
        return this.frameStarts.length;
      case RXFLR:
        return this.received.filter((frame) => frame.readyAt <= now).length;
      case SR: {
        const ready = this.received.length > 0 && this.received[0].readyAt <= now;
        return (
          (now < this.busyUntil ? SR_BUSY : 0) |
          (this.frameStarts.length < FIFO_DEPTH ? SR_TFNF : 0) |
          (this.frameStarts.length === 0 ? SR_TFE : 0) |
          (ready ? SR_RFNE : 0) |
          (this.received.length === FIFO_DEPTH ? SR_RFF : 0)
        );
      }
      case ISR:
      case RISR:
        return 0; // no SSI interrupt is modelled, so none is ever raised
      case IDR:
        return 0x51535049;
      case SSI_VERSION_ID:
        return 0x3430312a;
    }
    if (offset >= TXOICR && offset <= ICR) {
      return 0; // reading clears interrupts that were never raised
    }
    if (offset >= DR0 && offset <= DR_LAST) {
      const frame = this.received[0];
      if (!frame || frame.readyAt > now) {
        this.fail('DR0 read with the RX FIFO empty');
      }
      this.received.shift();
      return frame.value;
    }
    if (this.registers.has(offset)) {
      return this.registers.get(offset);
    }
    return super.readUint32(offset);
  }

  writeUint32(offset, value) {
    const now = this.now();
    this.advance(now);
    if (offset === SSIENR) {
      this.enabled = (value & 1) === 1;
      if (!this.enabled) this.clear();
      this.xipReady = false;
      return;
    }
    if (offset >= DR0 && offset <= DR_LAST) {
      this.transmit(value >>> 0, now);
      return;
    }
    if (CONFIGURATION.has(offset)) {
      if (!this.enabled) {
        this.registers.set(offset, value >>> 0);
        this.xipReady = false;
      }
      return;
    }
    if (this.registers.has(offset)) {
      this.registers.set(offset, value >>> 0);
      return;
    }
    super.writeUint32(offset, value);
  }

  /** A word written to DR0: a frame in TX_AND_RX mode, or part of an EEPROM read's instruction and address. */
  transmit(value, now) {
    if (!this.enabled) {
      this.fail('DR0 written with the SSI disabled (SSIENR 0)');
    }
    if (!(this.registers.get(SER) & 1)) {
      this.fail('a transfer with no slave selected (SER 0)');
    }
    const ctrlr0 = this.ctrlr0;
    const mode = (ctrlr0 >>> 8) & 3;
    const frameFormat = (ctrlr0 >>> 21) & 3;
    const frameBits = ((ctrlr0 >>> 16) & 0x1f) + 1;
    if (frameBits % 8 !== 0) {
      this.fail(`${frameBits}-bit frames (the flash takes whole bytes)`);
    }
    if (mode === TMOD_TX_AND_RX && frameFormat === 0) {
      this.exchangeFrame(value, frameBits, now);
    } else if (mode === TMOD_EEPROM_READ && frameFormat !== 0) {
      this.eepromWords.push(value);
      this.enhancedRead(frameBits, now);
    } else {
      this.fail(`direct transfers in CTRLR0 0x${ctrlr0.toString(16)} (TMOD ${mode}, SPI_FRF ${frameFormat}) are not modelled`);
    }
  }

  exchangeFrame(value, frameBits, now) {
    if (this.received.length === FIFO_DEPTH) {
      this.fail('RX FIFO overrun (16 frames unread)');
    }
    let start = now;
    if (this.selected) {
      start = Math.max(now, this.busyUntil);
    } else {
      this.chip.select();
      this.selected = true;
    }
    this.clockTheChip();
    let received = 0;
    for (let shift = frameBits - 8; shift >= 0; shift -= 8) {
      received = (received << 8) | this.chip.exchange((value >>> shift) & 0xff);
    }
    const end = start + frameBits * serialClockCycles(this.registers.get(BAUDR));
    if (start > now) this.frameStarts.push(start);
    this.received.push({ value: received >>> 0, readyAt: end });
    this.busyUntil = end;
  }

  /** Once the instruction (if INST_L asks for one) and the address are in, the read runs. */
  enhancedRead(frameBits, now) {
    const registers = this.configuration();
    const format = xipTransferFormat(registers);
    const words = format.instructionBits === 0 ? 1 : 2;
    if (this.eepromWords.length < words) {
      return;
    }
    const [first, address] = [this.eepromWords[0], this.eepromWords[words - 1]];
    this.eepromWords = [];
    const instruction = format.instructionBits === 0 ? null : first;
    this.flashRead(format, instruction, address);
    const frames = (registers.ctrlr1 & 0xffff) + 1;
    if (this.received.length + frames > FIFO_DEPTH) {
      this.fail('RX FIFO overrun (16 frames unread)');
    }
    const offset = format.addressBits === 32 ? address >>> 8 : address & 0xffffff;
    const end = now + transferCycles(registers, frames * frameBits);
    const bytes = frameBits / 8;
    for (let frame = 0; frame < frames; frame++) {
      let value = 0;
      for (let byte = 0; byte < bytes; byte++) {
        value = (value << 8) | this.chip.memory[(offset + frame * bytes + byte) % this.chip.memory.length];
      }
      this.received.push({ value: value >>> 0, readyAt: end });
    }
    this.busyUntil = end;
  }

  /** Has the flash take a read framed so; the mode bits are the address word's (direct) or XIP_CMD (XIP, no instruction). */
  flashRead(format, instruction, modeSource) {
    if (format.instructionBits !== 0 && format.instructionBits !== 8) {
      this.fail(`a ${format.instructionBits}-bit instruction (the flash takes 8-bit ones)`);
    }
    const mode = format.addressBits === 32 ? modeSource & 0xff : 0;
    this.clockTheChip();
    this.chip.read({
      instruction: instruction === null ? null : instruction & 0xff,
      transType: format.transType,
      lanes: format.lanes,
      addressBits: format.addressBits,
      waitClocks: format.waitClocks,
      mode,
    });
  }

  configuration() {
    return {
      ctrlr0: this.ctrlr0,
      ctrlr1: this.registers.get(CTRLR1),
      baudr: this.registers.get(BAUDR),
      spiCtrlr0: this.registers.get(SPI_CTRLR0),
      rxSampleDelay: this.registers.get(RX_SAMPLE_DLY),
    };
  }

  /**
   * The cycles one XIP line read takes (xip-timing.mjs), after checking
   * that the flash takes a read framed as SPI_CTRLR0 frames it. The check
   * is made again only when the set-up or the flash's mode changes.
   */
  xipTransfer() {
    if (this.xipReady) {
      return this.xipCycles;
    }
    if (!this.enabled) {
      this.fail('an XIP read with the SSI disabled (SSIENR 0)');
    }
    this.advance(this.now());
    if (this.selected) {
      this.fail('an XIP read during a direct-mode transfer');
    }
    const registers = this.configuration();
    const format = xipTransferFormat(registers);
    const modeBefore = this.chip.continuous;
    // With no instruction, XIP_CMD goes out as the mode bits after the address.
    const noInstruction = format.instructionBits === 0;
    this.flashRead(format, noInstruction ? null : format.command, noInstruction ? format.command : 0);
    this.xipCycles = lineTransferCycles(registers);
    this.xipReady = this.chip.continuous === modeBefore;
    return this.xipCycles;
  }
}
