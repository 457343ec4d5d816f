// The host's side of the firmware's USB serial port (CDC ACM), as a PC's
// USB stack would be: rp2040js's USBCDC enumerates the device (address,
// configuration, control line state), and this file carries bytes both
// ways, with a host's flow control.
//
// rp2040js's USBCDC answers every OUT transfer the firmware arms at once,
// with a zero-length packet when it has nothing to send, and drops what
// does not fit its 512-byte FIFO; a real host instead holds the transfer
// until it has data (NAK) and never loses a byte. This class does what the
// real host does: a scene of any length arrives whole, and a firmware that
// waits for input sleeps instead of spinning on empty packets.
//
// rp2040js leaves some of the controller's registers out, and rp2040-hal
// touches them: `UsbBus::new` writes 0 to every register after the
// controller's reset, and sets USB_MUXING by read-modify-write. Here the
// read-only ones (SOF_RD, BUFF_CPU_SHOULD_HANDLE, INTR, INTS) ignore writes
// as on the chip, and USB_MUXING and the PHY's direct-drive and trim
// controls keep what is written (from their reset values) and read it
// back; what they control is not modelled (the bytes the host exchanges
// do not depend on it).
//
// A host program may also stop reading the port (or close it): a real
// host's USB stack then stops taking IN transfers, and the device's data
// waits in its endpoint. `hold()` does that: each IN transfer the firmware
// arms on the data endpoint waits, unanswered, until `release()`.
//
// Invariants: bytes reach the firmware in the order `write` was given
// them, at most one OUT transfer is held at a time on an endpoint, and a held transfer is
// answered as soon as bytes arrive; while held, no byte of the firmware's
// reaches the host, and released, they come in the order it sent them.

import { USBCDC } from 'rp2040js';

/** USBCTRL_REGS offsets rp2040js leaves out (see above). */
const READ_ONLY = new Set([0x48, 0x5c, 0x8c, 0x98]); // SOF_RD, BUFF_CPU_SHOULD_HANDLE, INTR, INTS
const USB_MUXING = 0x74;
/** DPRAM: EP0_IN_BUFFER_CONTROL, the first of the endpoints' buffer controls (IN, then OUT, 8 bytes an endpoint). */
const BUFFER_CONTROLS = 0x80;
const BUFFER_AVAILABLE = 1 << 10;
/** Registers kept here, with their values after reset: USB_MUXING, USBPHY_DIRECT, _OVERRIDE, _TRIM, LINESTATE_TUNING. */
const KEPT_AT_RESET = [
  [USB_MUXING, 0],
  [0x7c, 0],
  [0x80, 0],
  [0x84, 0x1f1f],
  [0x88, 0xf8],
];

/**
 * Completes rp2040js's USB controller with the registers it leaves out:
 * once, when the machine is made (a firmware touches them with or without
 * a host on the bus).
 */
export function completeRegisters(usb) {
  const kept = new Map(KEPT_AT_RESET);
  const read = usb.readUint32.bind(usb);
  const write = usb.writeUint32.bind(usb);
  usb.readUint32 = (offset) => (kept.has(offset) ? kept.get(offset) : read(offset));
  usb.writeUint32 = (offset, value) => {
    if (READ_ONLY.has(offset)) return;
    if (kept.has(offset)) {
      kept.set(offset, value >>> 0);
      // rp2040js acts on USB_MUXING writes (its pads' state) without keeping them.
      if (offset === USB_MUXING) write(offset, value);
      return;
    }
    write(offset, value);
  };
}

export class UsbSerialHost {
  /**
   * Attaches to `rp2040`'s USB controller. `onDeviceBytes(Uint8Array)`
   * receives what the firmware sends; `onConnected()` fires once the
   * device is configured and its control lines are up. `now()` is the
   * board's clock in microseconds, for `lastIn` and `lastOut`.
   */
  constructor(rp2040, { onDeviceBytes = () => {}, onConnected = () => {}, now = () => 0 } = {}) {
    const usb = rp2040.usbCtrl;
    this.usb = usb;
    this.now = now;
    this.cdc = new USBCDC(usb);
    /** The board's time when the host last handed it bytes, and when it last sent some (null: never). */
    this.lastIn = null;
    this.lastOut = null;
    /** IN transfers armed on the data endpoint while held: [offset, value] of their buffer control, oldest first. */
    this.heldWrites = null;
    const armed = usb.DPRAMUpdated.bind(usb);
    this.armWrite = armed;
    usb.DPRAMUpdated = (offset, value) => {
      const inControl = BUFFER_CONTROLS + 8 * this.cdc.inEndpoint;
      if (this.heldWrites && this.cdc.inEndpoint > 0 && offset === inControl && value & BUFFER_AVAILABLE) {
        this.heldWrites.push([offset, value]);
        return;
      }
      armed(offset, value);
    };
    this.queue = []; // Uint8Arrays from the host, oldest first
    this.queued = 0; // bytes in `queue`
    // The OUT transfers the firmware armed and waits on: size by endpoint.
    // Kept for every endpoint, since the firmware may arm its data
    // endpoint before enumeration tells which one it is.
    this.heldReads = new Map();
    this.connected = false;
    this.cdc.onSerialData = (bytes) => {
      this.lastOut = now();
      onDeviceBytes(bytes);
    };
    this.cdc.onDeviceConnected = () => {
      this.connected = true;
      onConnected();
      // Bytes the host wrote before enumeration told which endpoint is the
      // data endpoint go now.
      this.answerHeldRead();
    };
    // Replaces USBCDC's answer to an armed OUT transfer (see above).
    usb.onEndpointRead = (endpoint, size) => {
      if (endpoint === 0) {
        return;
      }
      this.heldReads.set(endpoint, size);
      this.answerHeldRead();
    };
  }

  /** Bytes from the host to the firmware. */
  write(bytes) {
    if (bytes.length === 0) {
      return;
    }
    this.queue.push(Uint8Array.from(bytes));
    this.queued += bytes.length;
    this.answerHeldRead();
  }

  /** The host stops taking what the firmware sends (a program that stops reading the port, or closes it). */
  hold() {
    this.heldWrites ??= [];
  }

  /** The host takes what the firmware sends again, what waited first. */
  release() {
    const held = this.heldWrites ?? [];
    this.heldWrites = null;
    for (const [offset, value] of held) this.armWrite(offset, value);
  }

  /** How many bytes wait for the firmware to take them. */
  get pending() {
    return this.queued;
  }

  answerHeldRead() {
    const endpoint = this.cdc.outEndpoint;
    const size = this.heldReads.get(endpoint);
    if (size === undefined || this.queued === 0) {
      return;
    }
    const packet = new Uint8Array(Math.min(size, this.queued));
    let filled = 0;
    while (filled < packet.length) {
      const head = this.queue[0];
      const take = Math.min(head.length, packet.length - filled);
      packet.set(head.subarray(0, take), filled);
      filled += take;
      if (take === head.length) {
        this.queue.shift();
      } else {
        this.queue[0] = head.subarray(take);
      }
    }
    this.queued -= packet.length;
    this.heldReads.delete(endpoint);
    this.lastIn = this.now();
    this.usb.endpointReadDone(endpoint, packet);
  }
}
