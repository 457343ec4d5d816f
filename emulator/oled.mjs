// The SSD1306 module wired to a Pico as examples/pico-ssd1306 wires it: SDA
// on GP4 and SCL on GP5 (I2C0; the module's own pull-ups hold the lines
// high), the module answering at its address (0x3C), and the Pico's LED on
// GP25, which the template lights while it traces the picture; and the
// run's phases told from them.
//
// Invariants: the module sees exactly the transfers the I2C controller puts
// on the wires, timed as the controller times them; a phase is null until
// the run has got there.

import { GPIOPinState } from 'rp2040js';
import { SSD1306 } from './ssd1306.mjs';

/** The template's wiring: I2C0's SDA and SCL, and the Pico's LED. */
export const OLED_WIRING = { sda: 4, scl: 5, led: 25 };

/**
 * Puts an SSD1306 (`options`: its address) on `controller`'s bus at the
 * template's pins, and watches the LED on `gpio`. `now()` is the machine's
 * time in cycles.
 */
export function wireOled(controller, gpio, now, options = {}) {
  const panel = new SSD1306(options);
  controller.attach(panel, OLED_WIRING);
  const events = {
    /** The last STOP on the bus, and the last one before the LED first lit (the set-up's end). */
    lastStop: null,
    setUpEnd: null,
    ledOn: null,
    ledOff: null,
    /**
     * The picture's transfer: its first START and last STOP after the LED
     * went out, before it lit again (an animation's next frame).
     */
    transferStart: null,
    transferEnd: null,
    relit: false,
    transfers: 0,
  };
  controller.onBusEvent = (event) => {
    const time = now();
    if (event === 'start') {
      events.transfers++;
      if (events.ledOff !== null && events.transferStart === null) events.transferStart = time;
    } else {
      events.lastStop = time;
      if (events.ledOff !== null && !events.relit) events.transferEnd = time;
    }
  };
  gpio[OLED_WIRING.led].addListener((state) => {
    if (state === GPIOPinState.High && events.ledOn === null) {
      events.ledOn = now();
      events.setUpEnd = events.lastStop;
    } else if (state === GPIOPinState.High && events.ledOff !== null) {
      events.relit = true;
    } else if (state === GPIOPinState.Low && events.ledOn !== null && events.ledOff === null) {
      events.ledOff = now();
    }
  });
  return { panel, events, phases: () => phases(events) };
}

/**
 * The run's phases in cycles: start-up (up to the end of the panel's
 * set-up and clearing, the last transfer before the LED lit), parse and
 * index (up to the LED: the template lights it as it starts tracing),
 * render (while it is lit), the picture's transfer (its first START to its
 * last STOP after the LED went out, before an animation's next frame lit
 * it again), and the first full panel (render and
 * transfer: the picture whole on the panel, from the picture's start).
 */
function phases(events) {
  const { setUpEnd, ledOn, ledOff, transferStart, transferEnd } = events;
  const rendered = setUpEnd !== null && ledOn !== null && ledOff !== null;
  const sent = rendered && transferStart !== null && transferEnd !== null;
  return {
    startUp: setUpEnd,
    parseAndIndex: rendered ? ledOn - setUpEnd : null,
    render: rendered ? ledOff - ledOn : null,
    transfer: sent ? transferEnd - transferStart : null,
    firstFullPanel: sent ? transferEnd - ledOn : null,
  };
}
