// Where the cycles went, by function: a sampling profiler, as one on a
// board takes. Every SAMPLE_EVERY + 1 instructions of the machine it looks
// where each running core is and charges the cycles since its last look to
// the function there (the ELF's symbols, demangled; code the compiler
// inlined counts as its caller). A core asleep is charged nothing, nor
// is the sleep it woke from (the cycles its wake-up carried it over).
//
// Invariant: the samples come between the run's usual checks, which keep
// their pace (lockstep.mjs), so a profiled run is the same run, a little
// slower.

import { functionNameAt } from './elf.mjs';

/** How often (in instructions, less one) a profiled run samples where the cores are. */
export const SAMPLE_EVERY = 0xff;

export class Profiler {
  /**
   * Starts charging `cores`' cycles (null for a core not yet made) to
   * `functions` from now; `waiting[k]`, core k's cycles asleep so far.
   */
  constructor(cores, functions, waiting) {
    this.functions = functions;
    this.cycles = new Map();
    this.last = cores.map((core) => core?.cycles ?? 0);
    this.lastWaiting = [...waiting];
    this.samples = 0;
  }

  /** Charges each running core's cycles awake since its last sample to the function it is in. */
  sample(cores, waiting) {
    this.samples++;
    for (let k = 0; k < 2; k++) {
      const core = cores[k];
      if (!core) continue;
      const spent = core.cycles - this.last[k] - (waiting[k] - this.lastWaiting[k]);
      this.last[k] = core.cycles;
      this.lastWaiting[k] = waiting[k];
      if (core.waiting || spent <= 0) continue;
      const name = functionNameAt(this.functions, core.PC >>> 0);
      this.cycles.set(name, (this.cycles.get(name) ?? 0) + spent);
    }
  }

  /** The `top` functions charged most, with their cycles and share of all charged. */
  report(top) {
    const entries = [...this.cycles];
    const all = entries.reduce((sum, [, cycles]) => sum + cycles, 0);
    return entries
      .sort((a, b) => b[1] - a[1])
      .slice(0, top)
      .map(([name, cycles]) => ({ name, cycles, share: all ? cycles / all : 0 }));
  }
}
