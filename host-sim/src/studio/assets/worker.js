// The studio's render worker: its own instance of the octrace module, the
// scene (a frame of it, for an animation) loaded once, then rectangles
// rendered on request. Also the draft renderer (a smaller image first, then
// the draft size), and an animation's player: a frame whole, re-tracing
// only what moved since the frame it traced before (time.js). The page
// stops a worker by terminating it, even inside a pixel: a worker never
// queues work of its own.

import { loadOctrace } from './octrace.js';

let octrace = null;
const ready = loadOctrace().then((o) => { octrace = o; });

self.onmessage = async (event) => {
  await ready;
  const m = event.data;
  try {
    if (m.type === 'init') {
      const loaded = octrace.load(m.text, m.frame);
      if (loaded.errors) throw new Error(loaded.errors.join('\n'));
      const accel = octrace.prepare(m.accel, m.width, m.height);
      self.postMessage({ type: 'ready', accel });
    } else if (m.type === 'tile') {
      const data = octrace.render(m.x, m.y, m.width, m.height);
      self.postMessage({ type: 'tile', x: m.x, y: m.y, width: m.width, height: m.height, data }, [data.buffer]);
    } else if (m.type === 'frame') {
      const loaded = octrace.load(m.text, m.frame);
      if (loaded.errors) throw new Error(loaded.errors.join('\n'));
      octrace.prepare(0, m.width, m.height);
      const { traced, data } = octrace.traceFrame();
      self.postMessage({ type: 'frame', seq: m.seq, frame: m.frame, width: m.width, height: m.height, traced, data }, [data.buffer]);
    } else if (m.type === 'draft') {
      draft(m);
    }
  } catch (e) {
    self.postMessage({ type: 'error', message: String(e.message || e) });
  }
};

function draft(m) {
  const loaded = octrace.load(m.text, m.frame);
  if (loaded.errors) {
    self.postMessage({ type: 'draft-errors', seq: m.seq, errors: loaded.errors });
    return;
  }
  // A quarter-size pass first, so something shows at once on big scenes.
  for (const scale of m.progressive ? [4, 1] : [1]) {
    const w = Math.max(1, Math.floor(m.width / scale)), h = Math.max(1, Math.floor(m.height / scale));
    try {
      octrace.prepare(0, w, h);
      const data = octrace.render(0, 0, w, h);
      self.postMessage({ type: 'draft', seq: m.seq, frame: m.frame, width: w, height: h, final: scale === 1, data }, [data.buffer]);
    } catch (e) {
      self.postMessage({ type: 'draft-errors', seq: m.seq, errors: [String(e.message || e)] });
      return;
    }
  }
}
