// The one error a run ends with when the firmware, its ELF or the machine's
// set-up does what a real Pico would not survive or what the emulator does
// not model: its message says what, and where when the machine knows.
//
// Invariant: every model of the machine (SIO, PPB, SSI, flash chip, XIP
// cache, bus) reports through this class, so the runner tells a firmware's
// mistake from a bug of the emulator (any other exception).

export class RunError extends Error {
  /** `located`: the message already names the core and the function. */
  constructor(message, { located = false } = {}) {
    super(message);
    this.located = located;
  }
}

/**
 * The firmware let its watchdog run out (or triggered it): a real Pico
 * resets. A run ends with it; a serial serve starts the board again.
 */
export class WatchdogReset extends RunError {}
