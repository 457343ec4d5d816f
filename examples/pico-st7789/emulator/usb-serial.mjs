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
// Invariants: bytes reach the firmware in the order `write` was given
// them, at most one OUT transfer is held at a time, and a held transfer is
// answered as soon as bytes arrive.

import { USBCDC } from 'rp2040js';

export class UsbSerialHost {
  /**
   * Attaches to `rp2040`'s USB controller. `onDeviceBytes(Uint8Array)`
   * receives what the firmware sends; `onConnected()` fires once the
   * device is configured and its control lines are up.
   */
  constructor(rp2040, { onDeviceBytes = () => {}, onConnected = () => {} } = {}) {
    const usb = rp2040.usbCtrl;
    this.usb = usb;
    this.cdc = new USBCDC(usb);
    this.queue = []; // Uint8Arrays from the host, oldest first
    this.queued = 0; // bytes in `queue`
    this.heldRead = 0; // size of the OUT transfer the firmware armed and waits on, or 0
    this.connected = false;
    this.cdc.onSerialData = (bytes) => onDeviceBytes(bytes);
    this.cdc.onDeviceConnected = () => {
      this.connected = true;
      onConnected();
    };
    // Replaces USBCDC's answer to an armed OUT transfer (see above).
    usb.onEndpointRead = (endpoint, size) => {
      if (endpoint !== this.cdc.outEndpoint) {
        return;
      }
      this.heldRead = size;
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

  /** How many bytes wait for the firmware to take them. */
  get pending() {
    return this.queued;
  }

  answerHeldRead() {
    if (this.heldRead === 0 || this.queued === 0) {
      return;
    }
    const packet = new Uint8Array(Math.min(this.heldRead, this.queued));
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
    this.heldRead = 0;
    this.usb.endpointReadDone(this.cdc.outEndpoint, packet);
  }
}
