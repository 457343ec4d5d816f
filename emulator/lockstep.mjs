// The run loop of the emulated Pico's two Cortex-M0+ cores (pico.mjs
// builds the machine around it).
//
// The cores run in lockstep by cycles: the next instruction is always the
// one of the core whose time (its cycle count) is lower, core 0 on a tie,
// and the machine's clock (alarms: SPI, I2C, timer, USB) follows the
// earlier of the running cores, each cycle lasting what clk_sys makes it
// then (clocks.mjs). A core asleep (WFE, WFI, or core 1 held in reset by
// the PSM) is carried along at the other's time, counted as waiting; woken
// by the other core (SEV, an interrupt it caused) or by an alarm, it starts
// at the end of the instruction or the clock step that woke it. When both
// sleep, the clock jumps to the next alarm; when none is left, `run`
// returns 'idle': the firmware waits for the outside world, which a runner
// may provide (a later serial link: it raises an IRQ line, then calls `run`
// again) or end the run on. `run({ until })` runs a slice and resumes
// exactly where it stopped.
//
// Invariants: a stretch of instructions ends (`woke`) whenever what it
// assumed changes (a core sleeps or wakes, core 1 is reset, clk_sys
// changes), so each stretch ticks the clock at one rate; the machine's
// time never runs ahead of a running core.

import { RunError } from './errors.mjs';
import { peek16 } from './bus.mjs';
import { Profiler, SAMPLE_EVERY } from './profile.mjs';

/** How often (in instructions, less one) the run looks for endless loops, its budget, and reports progress. */
const CHECK_EVERY = 0xfffff;
/** Samples between a profiled run's other checks, less one: those stay at their usual pace. */
const SAMPLES_PER_CHECK = (CHECK_EVERY + 1) / (SAMPLE_EVERY + 1) - 1;
const EXC_HARDFAULT = 3;
const ROM_END = 0x4000;
const BRANCH_TO_SELF = 0xe7fe;

/**
 * Two cores' run loop. The machine that extends it sets `cores`, `clock`
 * (rp2040js's, in nanoseconds), `systemClock` (clocks.mjs), `memory`, and
 * provides `whereAll()` and `display`.
 */
export class Lockstep {
  constructor() {
    /** Machine time in cycles: the clock's, which follows the earlier running core. */
    this.time = 0;
    this.steps = 0;
    /** Instructions between the run's checks (a power of two, less one): fewer while profiling. */
    this.checkEvery = CHECK_EVERY;
    /** While profiling: the Profiler. */
    this.profile = null;
    this.current = 0;
    this.held = [false, false];
    this.waiting = [0, 0];
    this.instructions = [0, 0];
    this.core1Ran = false;
    /** Set when a sleeping core wakes, core 1 is reset or clk_sys changes: a running stretch must look again. */
    this.woke = false;
    /** Set by `stop`: the run returns once the running stretch ends. */
    this.stopping = false;
  }

  /** Brings an asleep core's time up to `at` (at least), counting the gap as waiting. */
  settle(j, at) {
    const core = this.cores[j];
    if (at > core.cycles) {
      this.waiting[j] += at - core.cycles;
      core.cycles = at;
    }
  }

  /** Moves the machine's clock to the start of cycle `target`, across any change of clk_sys on the way. */
  tickTo(target) {
    this.clock.tick(this.systemClock.nanosAt(target) - this.clock.nanos);
  }

  /**
   * Runs until both cores sleep with nothing scheduled ('idle'), the
   * machine's time reaches cycle `until` ('until') or `stop` is called
   * ('stopped'). Throws RunError for what a real Pico would not have done
   * the same way, or once the Pico's time passes `maxSeconds`.
   * `onProgress(cycles, panelWrites)` is called now and then.
   */
  run({ maxSeconds = Infinity, until = Infinity, onProgress = () => {} } = {}) {
    try {
      return this.loop(maxSeconds * 1e9, until, onProgress);
    } catch (error) {
      if (error instanceof RunError && !error.located) {
        // The same class (a WatchdogReset stays one), located.
        throw new error.constructor(`${error.message} (${this.whereAll()})`, { located: true });
      }
      throw error;
    } finally {
      for (let j = 0; j < 2; j++) {
        if (this.cores[j].waiting) this.settle(j, this.time);
      }
    }
  }

  loop(maxNanos, until, onProgress) {
    const cores = this.cores;
    for (;;) {
      const awake0 = !cores[0].waiting;
      const awake1 = !cores[1].waiting;
      let reason;
      if (awake0 && awake1) {
        reason = this.runBoth(until, maxNanos, onProgress);
      } else if (awake0 || awake1) {
        reason = this.runAlone(awake0 ? 0 : 1, until, maxNanos, onProgress);
      } else {
        if (!this.sleepUntilAlarm()) return 'idle';
        if (this.time >= until) return 'until';
        if (this.clock.nanos > maxNanos) this.check(maxNanos, onProgress);
        continue;
      }
      if (reason) return reason;
      if (this.stopping) {
        this.stopping = false;
        return 'stopped';
      }
    }
  }

  /**
   * Ends the run (`run` returns 'stopped') after the instruction now
   * executing: for a watcher that has seen what it waited for (frames.mjs).
   */
  stop() {
    this.stopping = true;
    this.woke = true;
  }

  /**
   * Both cores run: each step is the next instruction of the core that is
   * behind (core 0 on a tie), and the clock follows the earlier. Returns a
   * reason to end the run, or null when a core sleeps, core 1 is reset or
   * the clock changes.
   */
  runBoth(until, maxNanos, onProgress) {
    const c0 = this.cores[0];
    const c1 = this.cores[1];
    const clock = this.clock;
    const { cycles: epochCycles, nanos: epochNanos, nanosPerCycle } = this.systemClock.epoch;
    let time = this.time;
    let steps0 = 0;
    let steps1 = 0;
    let countdown = this.checkEvery + 1 - (this.steps & this.checkEvery);
    let reason = null;
    this.woke = false;
    for (;;) {
      if (c1.cycles < c0.cycles) {
        this.current = 1;
        c1.executeInstruction();
        steps1++;
        if (!this.core1Ran && c1.PC >= ROM_END) this.core1Ran = true;
      } else {
        this.current = 0;
        c0.executeInstruction();
        steps0++;
      }
      if (c0.waiting || c1.waiting || this.woke) break;
      const target = c0.cycles < c1.cycles ? c0.cycles : c1.cycles;
      if (target > time) {
        if (target >= epochCycles) clock.tick(epochNanos + (target - epochCycles) * nanosPerCycle - clock.nanos);
        else this.tickTo(target);
        time = target;
      }
      if (time >= until) {
        reason = 'until';
        break;
      }
      if (--countdown === 0) {
        this.time = time;
        this.count(0, steps0);
        this.count(1, steps1);
        steps0 = steps1 = 0;
        this.check(maxNanos, onProgress);
        countdown = this.checkEvery + 1;
      }
    }
    this.time = time;
    this.count(0, steps0);
    this.count(1, steps1);
    if (reason === null) this.follow(this.current);
    return reason;
  }

  /**
   * After core k's instruction that ended a stretch: the clock follows the
   * earlier running core (or core k, if both now sleep), and a core woken
   * on the way starts then.
   */
  follow(k) {
    const cores = this.cores;
    const core = cores[k];
    let target = core.waiting ? Infinity : core.cycles;
    const other = cores[1 - k];
    if (!other.waiting && other.cycles < target) target = other.cycles;
    if (target === Infinity) target = core.cycles;
    if (target > this.time) {
      const asleep0 = cores[0].waiting;
      const asleep1 = cores[1].waiting;
      this.tickTo(target);
      this.time = target;
      if (asleep0 && !cores[0].waiting) this.settle(0, target);
      if (asleep1 && !cores[1].waiting) this.settle(1, target);
    }
  }

  /**
   * Core k runs while the other sleeps: the same steps as `loop`'s, with
   * nothing to choose. Returns a reason to end the run, or null when the
   * other core woke, core 1 was reset, the clock changed, or this one
   * sleeps.
   */
  runAlone(k, until, maxNanos, onProgress) {
    const core = this.cores[k];
    const clock = this.clock;
    const { cycles: epochCycles, nanos: epochNanos, nanosPerCycle } = this.systemClock.epoch;
    let time = this.time;
    let steps = 0;
    let countdown = this.checkEvery + 1 - (this.steps & this.checkEvery);
    let reason = null;
    let watchLaunch = k === 1 && !this.core1Ran;
    this.current = k;
    this.woke = false;
    for (;;) {
      core.executeInstruction();
      steps++;
      if (watchLaunch && core.PC >= ROM_END) {
        // Core 1 runs outside the ROM: the firmware launched it.
        this.core1Ran = true;
        watchLaunch = false;
      }
      const t = core.cycles;
      // After a clock change (which sets `woke`), the epochs say where the rate changed.
      if (t >= epochCycles && !this.woke) clock.tick(epochNanos + (t - epochCycles) * nanosPerCycle - clock.nanos);
      else this.tickTo(t);
      time = t;
      if (core.waiting || this.woke) break;
      if (time >= until) {
        reason = 'until';
        break;
      }
      if (--countdown === 0) {
        this.time = time;
        this.count(k, steps);
        steps = 0;
        this.check(maxNanos, onProgress);
        countdown = this.checkEvery + 1;
      }
    }
    this.time = time;
    this.count(k, steps);
    const j = 1 - k;
    if (!this.cores[j].waiting) this.settle(j, time);
    return reason;
  }

  count(k, steps) {
    this.steps += steps;
    this.instructions[k] += steps;
  }

  /** Both cores asleep: the clock jumps to the next alarm, then to the cycle it falls in (false when there is none). */
  sleepUntilAlarm() {
    const clock = this.clock;
    if (!clock.nextAlarm) return false;
    clock.tick(Math.max(0, clock.nextAlarm.nanos - clock.nanos));
    const time = this.systemClock.cycleAtOrAfter(clock.nanos);
    const nanos = this.systemClock.nanosAt(time);
    if (nanos > clock.nanos) clock.tick(nanos - clock.nanos);
    this.time = time;
    for (let j = 0; j < 2; j++) {
      if (!this.cores[j].waiting) this.settle(j, time);
    }
    return true;
  }

  /**
   * From now on, samples where each running core is every 256
   * instructions (profile.mjs): a statistical profile, as a sampling
   * profiler takes on a board, a little slower to run.
   */
  startProfile() {
    this.profile = new Profiler(this.cores, this.functions, this.waiting);
    this.checkEvery = SAMPLE_EVERY;
    // Started mid-run (from a frame's end): the running stretch ends after
    // this instruction, so the next one counts to its checks at the new pace.
    this.woke = true;
  }

  /** The `top` functions the profile charged most, with their cycles and share of all it charged. */
  profileReport(top) {
    return this.profile ? this.profile.report(top) : [];
  }

  check(maxNanos, onProgress) {
    if (this.profile) {
      this.profile.sample(this.cores, this.waiting);
      if (this.profile.samples & SAMPLES_PER_CHECK) return;
    }
    for (let k = 0; k < 2; k++) {
      const core = this.cores[k];
      if (core.waiting) continue;
      if (core.IPSR === EXC_HARDFAULT) {
        throw new RunError(`HardFault at ${this.where(k)}`, { located: true });
      }
      // A branch to itself (`b .`, as panic-halt's loop) never ends.
      if (peek16(this.memory, core.PC & ~1) === BRANCH_TO_SELF) {
        throw new RunError(`the firmware stopped in an endless loop in ${this.where(k)} (a panic?)`, { located: true });
      }
    }
    if (this.clock.nanos > maxNanos) {
      const seconds = (nanos) => +(nanos / 1e9).toFixed(6);
      throw new RunError(
        `still running after ${seconds(this.clock.nanos)} s of the Pico's time (${this.time} cycles, clk_sys ` +
          `${this.systemClock.hz / 1e6} MHz now), past its budget of ${seconds(maxNanos)} s, in ${this.whereAll()}`,
        { located: true },
      );
    }
    onProgress(this.time, this.display?.writes() ?? 0);
  }
}
