// octrace studio: the page. The octrace module (octrace-core compiled to
// WebAssembly) does all parsing checks, rendering, palettes and image files;
// this script is the editor, the wireframe view and the plumbing. It is also
// loaded by worker.js, which uses only loadOctrace().
'use strict';

// ---------------------------------------------------------------- module --

/** Instantiates the octrace module and wraps its byte-buffer interface. */
async function loadOctrace() {
  const response = await fetch('/octrace_studio.wasm');
  const { instance } = await WebAssembly.instantiateStreaming(response, {});
  const x = instance.exports;
  const encoder = new TextEncoder(), decoder = new TextDecoder();
  const put = (bytes) => {
    const at = x.studio_input(bytes.length);
    new Uint8Array(x.memory.buffer, at, bytes.length).set(bytes);
  };
  const output = () => new Uint8Array(x.memory.buffer, x.studio_output_ptr(), x.studio_output_len()).slice();
  const call = (f, ...args) => {
    const failed = f(...args);
    const out = output();
    if (failed) throw new Error(decoder.decode(out));
    return out;
  };
  return {
    /** {width, height, objects} or {errors: ['line:col: message', …]} */
    load(text) {
      put(encoder.encode(text));
      const failed = x.studio_load();
      const out = decoder.decode(output());
      if (failed) return { errors: out.split('\n').filter((l) => l) };
      const [width, height, objects] = out.split(' ').map(Number);
      return { width, height, objects };
    },
    prepare: (accel, w, h) => decoder.decode(call(x.studio_prepare, accel, w, h)),
    render: (x0, y0, w, h) => call(x.studio_render, x0, y0, w, h),
    display(render, mode, w, h) { put(render); return call(x.studio_display, mode, w, h); },
    encode(render, mode, format, w, h) { put(render); return call(x.studio_encode, mode, format, w, h); },
    decode(bytes) {
      put(bytes);
      const out = call(x.studio_decode);
      const view = new DataView(out.buffer);
      return { width: view.getUint32(0, true), height: view.getUint32(4, true), rgb: out.subarray(8) };
    },
  };
}

if (typeof document !== 'undefined') {
  main();
}

function main() {
  const $ = (id) => document.getElementById(id);
  const text = $('scene');
  const imageCanvas = $('image');
  const state = {
    octrace: null,
    version: null, // the ETag of the file as loaded, for conflict checks
    sceneName: '',
    writable: false,
    lastRender: null, // {width, height, data: colours then objects}
    undoStack: [], redoStack: [],
    tool: 'select', selection: -1, placing: null,
    camera: { yaw: 0.7, pitch: 0.45, distance: 30, target: [0, 0, 0] },
    draftSeq: 0, draftSent: 0, draftTimer: 0,
  };
  // Exposed for scripts and the browser tests.
  window.studio = state;
  // Script errors are kept for the tests' failure messages.
  window.addEventListener('error', (e) => (state.log = state.log || []).push(['error', e.message, e.lineno]));

  const storageKey = () => 'octrace-studio:' + state.sceneName;

  // ----------------------------------------------------------- scene file --

  async function loadScene(preferStored) {
    const response = await fetch('/scene');
    if (!response.ok) throw new Error(await response.text());
    const body = await response.text();
    state.version = (response.headers.get('ETag') || '').replaceAll('"', '');
    state.sceneName = response.headers.get('X-Scene-Name') || 'scene';
    state.writable = response.headers.get('X-Scene-Writable') === 'true';
    $('scene-name').textContent = state.sceneName + (state.writable ? '' : ' (example, not saved)');
    const stored = preferStored ? localStorage.getItem(storageKey()) : null;
    setText(stored !== null && stored !== body ? stored : body, false);
    if (stored !== null && stored !== body) setStatus('unsaved changes restored from this browser');
  }

  async function saveScene(force) {
    if (!state.writable) { alert('The studio was started without a scene file: nothing to save to.'); return false; }
    const response = await fetch('/scene', {
      method: 'PUT', body: text.value, headers: { 'If-Match': force ? '*' : '"' + state.version + '"' },
    });
    if (response.status === 409) {
      if (confirm('The scene file changed on disk since it was loaded. Overwrite it with this text?')) {
        return saveScene(true);
      }
      setStatus('not saved: the file changed on disk (Reload loads it)');
      return false;
    }
    if (!response.ok) { setStatus('not saved: ' + (await response.text())); return false; }
    state.version = (response.headers.get('ETag') || '').replaceAll('"', '');
    localStorage.removeItem(storageKey());
    setStatus('saved ' + state.sceneName);
    document.body.dataset.saved = state.version;
    return true;
  }

  // ------------------------------------------------------ text and errors --

  /** Replaces the text (a tool or the panel changed the scene). */
  function setText(value, remember = true) {
    if (remember && value !== text.value) { state.undoStack.push(text.value); state.redoStack = []; }
    text.value = value;
    textChanged();
  }

  let lastKnown = '';
  function textChanged() {
    if (text.value !== lastKnown) {
      lastKnown = text.value;
      localStorage.setItem(storageKey(), text.value);
    }
    state.model = parseModel(text.value);
    checkErrors();
    drawWire();
    showPanel();
    scheduleDraft();
  }

  function checkErrors() {
    if (!state.octrace) return;
    const loaded = state.octrace.load(text.value);
    const list = $('errors');
    list.replaceChildren();
    for (const e of loaded.errors || []) {
      const li = document.createElement('li');
      li.textContent = e;
      const [line, column] = e.split(':').map(Number);
      li.onclick = () => goTo(line, column);
      list.append(li);
    }
    return loaded;
  }

  function goTo(line, column) {
    const lines = text.value.split('\n');
    let at = 0;
    for (let i = 0; i < line - 1 && i < lines.length; i++) at += lines[i].length + 1;
    text.focus();
    text.setSelectionRange(at + column - 1, at + column);
  }

  let typingUndoTimer = 0, typingBase = null;
  text.addEventListener('input', () => {
    // A burst of typing is one undo step.
    if (typingBase === null) typingBase = lastKnown;
    clearTimeout(typingUndoTimer);
    typingUndoTimer = setTimeout(() => {
      if (typingBase !== text.value) { state.undoStack.push(typingBase); state.redoStack = []; }
      typingBase = null;
    }, 600);
    textChanged();
  });

  // ---------------------------------------------------------------- draft --

  const draftWorker = new Worker('/worker.js');
  draftWorker.onmessage = (event) => {
    const m = event.data;
    if (m.seq !== state.draftSeq) return; // superseded
    if (m.type === 'draft-errors') { $('draft-status').textContent = 'scene has errors'; return; }
    if (m.type !== 'draft') return;
    const canvas = $('draft');
    canvas.width = m.width; canvas.height = m.height;
    putRgb(canvas, m.data.subarray(0, 3 * m.width * m.height), m.width, m.height);
    if (m.final) {
      const latency = performance.now() - state.draftSent;
      state.draftLatency = latency;
      canvas.dataset.state = 'done';
      canvas.dataset.seq = String(m.seq);
      $('draft-status').textContent = `${m.width}×${m.height}, ${latency.toFixed(0)} ms after the last change`;
    }
  };
  function scheduleDraft() {
    clearTimeout(state.draftTimer);
    const changedAt = performance.now();
    $('draft').dataset.state = 'pending';
    // A short pause, so a burst of keys renders once.
    state.draftTimer = setTimeout(() => {
      state.draftSeq += 1;
      state.draftSent = changedAt;
      draftWorker.postMessage({ type: 'draft', seq: state.draftSeq, text: text.value, width: 160, height: 120, progressive: true });
    }, 25);
  }

  // ---------------------------------------------------------- full render --

  function renderSize() {
    const mode = Number($('display').value);
    if (mode >= 5) {
      const m = /^(\d+)[xX](\d+)$/.exec($('panel-size').value.trim());
      if (m) return [Number(m[1]), Number(m[2])];
    }
    return null; // RASTER
  }

  function putRgb(canvas, rgb, w, h) {
    const ctx = canvas.getContext('2d');
    const image = ctx.createImageData(w, h);
    for (let i = 0, j = 0; i < w * h; i++, j += 3) {
      image.data[4 * i] = rgb[j]; image.data[4 * i + 1] = rgb[j + 1]; image.data[4 * i + 2] = rgb[j + 2];
      image.data[4 * i + 3] = 255;
    }
    ctx.putImageData(image, 0, 0);
  }

  let renderJob = 0;
  let workers = [];
  async function render() {
    const job = ++renderJob;
    for (const w of workers) w.terminate();
    workers = [];
    const loaded = checkErrors();
    if (loaded.errors) { setStatus('the scene has errors: nothing rendered'); return; }
    const [width, height] = renderSize() || [loaded.width, loaded.height];
    const accel = Number($('accel').value);
    imageCanvas.dataset.state = 'rendering';
    imageCanvas.width = width; imageCanvas.height = height;
    const data = new Uint8Array(7 * width * height);
    const started = performance.now();
    let done = 0;
    const progress = (pixels) => {
      done += pixels;
      $('progress').value = done / (width * height);
      setStatus(`rendering ${(100 * done / (width * height)).toFixed(0)} %, ${((performance.now() - started) / 1000).toFixed(2)} s`);
    };
    const place = (x, y, w, h, tile) => {
      for (let row = 0; row < h; row++) {
        data.set(tile.subarray(3 * row * w, 3 * (row + 1) * w), 3 * ((y + row) * width + x));
        data.set(tile.subarray(3 * w * h + 4 * row * w, 3 * w * h + 4 * (row + 1) * w), 3 * width * height + 4 * ((y + row) * width + x));
      }
      const ctx = imageCanvas.getContext('2d');
      const part = ctx.createImageData(w, h);
      for (let i = 0; i < w * h; i++) {
        part.data.set([tile[3 * i], tile[3 * i + 1], tile[3 * i + 2], 255], 4 * i);
      }
      ctx.putImageData(part, x, y);
      progress(w * h);
    };
    let used;
    try {
      if ($('parallel').checked) {
        used = await renderParallel(text.value, accel, width, height, place, () => job === renderJob);
      } else {
        used = state.octrace.prepare(accel, width, height);
        // Bands of rows, yielding between them so progress shows.
        for (let y = 0; y < height && job === renderJob; y += 8) {
          const h = Math.min(8, height - y);
          place(0, y, width, h, state.octrace.render(0, y, width, h));
          await new Promise((r) => setTimeout(r, 0));
        }
      }
    } catch (e) {
      for (const w of workers) w.terminate();
      imageCanvas.dataset.state = 'error';
      setStatus('render failed: ' + e.message);
      return;
    }
    if (job !== renderJob) return;
    const seconds = (performance.now() - started) / 1000;
    state.lastRender = { width, height, data };
    showDisplay();
    const how = $('parallel').checked ? `, ${workers.length} workers, ${$('partition').value}` : '';
    setStatus(`done: ${width}×${height} in ${seconds.toFixed(2)} s (${used}${how})`);
    state.lastSeconds = seconds;
    imageCanvas.dataset.state = 'done';
  }

  /** Renders on Web Workers: 32×32 tiles handed out as workers become free,
   *  or the thesis's four equal rectangles (quarter i to worker i mod n). */
  function renderParallel(source, accel, width, height, place, current) {
    const count = Math.max(1, Math.min(16, Number($('workers').value) || 4));
    const pieces = [];
    if ($('partition').value === 'equal4') {
      const left = width >> 1, top = height >> 1;
      for (const [x, y, w, h] of [[0, 0, left, top], [left, 0, width - left, top], [0, top, left, height - top], [left, top, width - left, height - top]]) {
        if (w > 0 && h > 0) pieces.push({ x, y, width: w, height: h });
      }
    } else {
      for (let y = 0; y < height; y += 32) for (let x = 0; x < width; x += 32) {
        pieces.push({ x, y, width: Math.min(32, width - x), height: Math.min(32, height - y) });
      }
    }
    return new Promise((resolve, reject) => {
      let next = 0, finished = 0, used = '';
      const equal4 = $('partition').value === 'equal4';
      const queues = Array.from({ length: count }, (_, i) => pieces.filter((_, j) => j % count === i));
      const give = (worker, index) => {
        const piece = equal4 ? queues[index].shift() : pieces[next++];
        if (piece) worker.postMessage({ type: 'tile', ...piece });
      };
      for (let i = 0; i < count; i++) {
        const worker = new Worker('/worker.js');
        workers.push(worker);
        worker.onmessage = (event) => {
          const m = event.data;
          if (!current()) return;
          if (m.type === 'error') { reject(new Error(m.message)); return; }
          if (m.type === 'ready') { used = m.accel; give(worker, i); return; }
          place(m.x, m.y, m.width, m.height, m.data);
          finished += 1;
          if (finished === pieces.length) {
            for (const w of workers) w.terminate();
            resolve(used);
          } else give(worker, i);
        };
        worker.postMessage({ type: 'init', text: source, accel, width, height });
      }
    });
  }

  /** Shows the last render in the chosen display mode. */
  function showDisplay() {
    const r = state.lastRender;
    if (!r) return;
    const mode = Number($('display').value);
    const rgb = state.octrace.display(r.data, mode, r.width, r.height);
    imageCanvas.width = r.width; imageCanvas.height = r.height;
    putRgb(imageCanvas, rgb, r.width, r.height);
    imageCanvas.dataset.display = String(mode);
  }

  $('display').addEventListener('change', () => {
    const size = renderSize();
    const r = state.lastRender;
    if (r && (!size || (size[0] === r.width && size[1] === r.height))) {
      const loaded = state.octrace.load(text.value);
      const raster = loaded.errors ? null : [loaded.width, loaded.height];
      const wanted = size || raster;
      if (wanted && wanted[0] === r.width && wanted[1] === r.height) { showDisplay(); return; }
    }
    render();
  });

  // ---------------------------------------------------------------- image --

  function saveImage(format) {
    const r = state.lastRender;
    if (!r) { setStatus('render first'); return; }
    const mode = Number($('display').value);
    const bytes = state.octrace.encode(r.data, mode, format, r.width, r.height);
    const name = (state.sceneName.replace(/.*[\\/]/, '').replace(/\.[^.]*$/, '') || 'image') + ['.png', '.tga', '.ras'][format];
    const link = document.createElement('a');
    link.href = URL.createObjectURL(new Blob([bytes], { type: 'application/octet-stream' }));
    link.download = name;
    link.click();
    setTimeout(() => URL.revokeObjectURL(link.href), 10000);
  }
  $('save-png').onclick = () => saveImage(0);
  $('save-tga').onclick = () => saveImage(1);
  $('save-ras').onclick = () => saveImage(2);
  $('load-image').addEventListener('change', async (event) => {
    const file = event.target.files[0];
    if (!file) return;
    try {
      const image = state.octrace.decode(new Uint8Array(await file.arrayBuffer()));
      imageCanvas.width = image.width; imageCanvas.height = image.height;
      putRgb(imageCanvas, image.rgb, image.width, image.height);
      state.lastRender = null;
      imageCanvas.dataset.state = 'loaded';
      setStatus(`loaded ${file.name}: ${image.width}×${image.height}`);
    } catch (e) {
      setStatus(`cannot load ${file.name}: ${e.message}`);
    }
    event.target.value = '';
  });
  $('clear').onclick = () => {
    imageCanvas.getContext('2d').clearRect(0, 0, imageCanvas.width, imageCanvas.height);
    state.lastRender = null;
    imageCanvas.dataset.state = 'clear';
    $('progress').value = 0;
    setStatus('cleared');
  };

  function setStatus(message) { $('status').textContent = message; }

  // ------------------------------------------------------------ the model --

  // The statements the wireframe draws and the tools edit, with where each
  // is in the text; the octrace module stays the judge of validity.
  const ARITY = {
    VIEWPOINT: 3, ORIGIN: 3, UPVECTOR: 3, RASTER: 2, VIEWPORT: 2, RDEPTH: 1, IMAGEFILE: 1, LIGHT: 4,
    BACKGROUND: 3, GAMMA: 1, ATTENUATION: 1, SAMPLES: 1, SPHERE: 5, BOX: 7, SUPERQUADRIC: 8, TRIANGLE: 10,
    RECTANGLE: 13, BSPLINE: 6, SURFACE: 13,
  };
  const SHAPES = ['SPHERE', 'BOX', 'SUPERQUADRIC', 'TRIANGLE', 'RECTANGLE', 'BSPLINE'];

  function parseModel(source) {
    const tokens = [];
    const re = /\/\*[\s\S]*?(\*\/|$)|\/\/[^\n]*|[^\s]+/g;
    let m;
    while ((m = re.exec(source))) {
      if (m[0].startsWith('/*') || m[0].startsWith('//')) continue;
      tokens.push({ text: m[0], start: m.index, end: m.index + m[0].length });
    }
    const statements = [];
    for (let i = 0; i < tokens.length;) {
      const keyword = tokens[i].text.toUpperCase();
      let arity = ARITY[keyword];
      if (arity === undefined) { i++; continue; }
      if (keyword === 'BSPLINE' && i + 4 < tokens.length) {
        arity += 3 * Number(tokens[i + 3].text) * Number(tokens[i + 4].text) || 0;
      }
      const args = tokens.slice(i + 1, i + 1 + arity);
      const end = args.length ? args[args.length - 1].end : tokens[i].end;
      statements.push({ keyword, args: args.map((t) => (keyword === 'IMAGEFILE' ? t.text : Number(t.text))), start: tokens[i].start, end });
      i += 1 + arity;
    }
    return statements;
  }

  const fmt = (v) => String(Math.round(v * 1000) / 1000);

  function statementText(keyword, args) {
    if (keyword === 'BSPLINE') {
      const head = args.slice(0, 6).map(fmt).join(' ');
      const points = [];
      for (let i = 6; i < args.length; i += 3) points.push('  ' + args.slice(i, i + 3).map(fmt).join(' '));
      return `BSPLINE ${head}\n${points.join('\n')}`;
    }
    return `${keyword} ${args.map((a) => (typeof a === 'number' ? fmt(a) : a)).join(' ')}`;
  }

  function replaceStatement(index, keyword, args) {
    const s = state.model[index];
    setText(text.value.slice(0, s.start) + statementText(keyword, args) + text.value.slice(s.end));
  }

  function appendStatement(keyword, args) {
    const sep = text.value.endsWith('\n') || text.value === '' ? '' : '\n';
    setText(text.value + sep + statementText(keyword, args) + '\n');
    return state.model.length - 1;
  }

  /** The one statement of a kind (VIEWPOINT, RDEPTH, …): replaced or added. */
  function setSingle(keyword, args) {
    const index = state.model.findIndex((s) => s.keyword === keyword);
    if (index >= 0) replaceStatement(index, keyword, args); else appendStatement(keyword, args);
  }

  function deleteStatement(index) {
    const s = state.model[index];
    let end = s.end;
    if (text.value[end] === '\n') end += 1;
    setText(text.value.slice(0, s.start) + text.value.slice(end));
    state.selection = -1;
    textChanged();
  }

  const single = (keyword, fallback) => {
    const s = state.model.find((x) => x.keyword === keyword);
    return s && s.args.length === ARITY[keyword] ? s.args : fallback;
  };

  // ------------------------------------------------------------- the view --

  const wire = $('wire');

  function basis() {
    const { yaw, pitch } = state.camera;
    const forward = [-Math.cos(pitch) * Math.sin(yaw), -Math.sin(pitch), -Math.cos(pitch) * Math.cos(yaw)];
    const right = normalize(cross(forward, [0, 1, 0]));
    const up = cross(right, forward);
    return { forward, right, up };
  }
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const scale = (a, k) => [a[0] * k, a[1] * k, a[2] * k];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const normalize = (a) => scale(a, 1 / (Math.hypot(...a) || 1));
  const focal = () => wire.height * 1.2;

  function eye() {
    const b = basis();
    return sub(state.camera.target, scale(b.forward, state.camera.distance));
  }

  function project(p) {
    const b = basis();
    const d = sub(p, eye());
    const z = dot(d, b.forward);
    if (z <= 0.01) return null;
    return [wire.width / 2 + (focal() * dot(d, b.right)) / z, wire.height / 2 - (focal() * dot(d, b.up)) / z];
  }

  /** The ray through canvas point (x, y). */
  function ray(x, y) {
    const b = basis();
    const dir = normalize(add(b.forward, add(scale(b.right, (x - wire.width / 2) / focal()), scale(b.up, -(y - wire.height / 2) / focal()))));
    return { origin: eye(), dir };
  }

  /** Where the ray through (x, y) meets the plane y = height. */
  function onPlane(x, y, height = 0) {
    const r = ray(x, y);
    if (Math.abs(r.dir[1]) < 1e-6) return null;
    const t = (height - r.origin[1]) / r.dir[1];
    return t > 0 ? add(r.origin, scale(r.dir, t)) : null;
  }

  function drawWire() {
    const ctx = wire.getContext('2d');
    ctx.clearRect(0, 0, wire.width, wire.height);
    const line = (a, b, colour) => {
      const p = project(a), q = project(b);
      if (!p || !q) return;
      ctx.strokeStyle = colour; ctx.beginPath(); ctx.moveTo(...p); ctx.lineTo(...q); ctx.stroke();
    };
    const poly = (points, colour) => points.forEach((p, i) => line(p, points[(i + 1) % points.length], colour));
    // The y–z reference plane (x = 0), a grid, and the axes.
    const extent = 10;
    for (let v = -extent; v <= extent; v += 2) {
      line([0, v, -extent], [0, v, extent], '#2c3440');
      line([0, -extent, v], [0, extent, v], '#2c3440');
    }
    line([0, 0, 0], [extent, 0, 0], '#e05555');
    line([0, 0, 0], [0, extent, 0], '#55c055');
    line([0, 0, 0], [0, 0, extent], '#5577ee');
    const model = state.model || [];
    model.forEach((s, index) => {
      const colour = index === state.selection ? '#ffd54f' : '#b0bec5';
      const a = s.args;
      switch (s.keyword) {
        case 'SPHERE': {
          const [, r, x, y, z] = a;
          for (const axes of [[[1, 0, 0], [0, 1, 0]], [[1, 0, 0], [0, 0, 1]], [[0, 1, 0], [0, 0, 1]]]) {
            const pts = [];
            for (let k = 0; k < 24; k++) {
              const t = (k / 24) * 2 * Math.PI;
              pts.push(add([x, y, z], add(scale(axes[0], r * Math.cos(t)), scale(axes[1], r * Math.sin(t)))));
            }
            poly(pts, colour);
          }
          break;
        }
        case 'BOX': case 'SUPERQUADRIC': {
          const o = s.keyword === 'BOX' ? 1 : 2;
          const c = a.slice(o, o + 3), h = a.slice(o + 3, o + 6);
          const corner = (i) => [c[0] + (i & 1 ? h[0] : -h[0]), c[1] + (i & 2 ? h[1] : -h[1]), c[2] + (i & 4 ? h[2] : -h[2])];
          for (let i = 0; i < 8; i++) for (const bit of [1, 2, 4]) if (!(i & bit)) line(corner(i), corner(i | bit), colour);
          break;
        }
        case 'TRIANGLE': poly([a.slice(1, 4), a.slice(4, 7), a.slice(7, 10)], colour); break;
        case 'RECTANGLE': poly([a.slice(1, 4), a.slice(4, 7), a.slice(7, 10), a.slice(10, 13)], colour); break;
        case 'BSPLINE': {
          const rows = a[2], cols = a[3];
          const p = (r, c) => a.slice(6 + 3 * (r * cols + c), 9 + 3 * (r * cols + c));
          for (let r = 0; r < rows; r++) for (let c = 0; c < cols; c++) {
            if (c + 1 < cols) line(p(r, c), p(r, c + 1), colour);
            if (r + 1 < rows) line(p(r, c), p(r + 1, c), colour);
          }
          break;
        }
        case 'LIGHT': {
          const q = project(a.slice(1, 4));
          if (q) { ctx.fillStyle = index === state.selection ? '#ffd54f' : '#fff176'; ctx.beginPath(); ctx.arc(...q, 5, 0, 7); ctx.fill(); }
          break;
        }
      }
    });
    drawEye(ctx, line);
    if (state.placing) drawPlacing(ctx, line);
  }

  /** The eye, the line of sight and the view frustum to the VIEWPORT at ORIGIN. */
  function drawEye(ctx, line) {
    const from = single('VIEWPOINT', [0, 0, 10]), to = single('ORIGIN', [0, 0, 0]), upv = single('UPVECTOR', [0, 1, 0]);
    const [rw, rh] = single('RASTER', [320, 240]);
    const forward = sub(to, from);
    const distance = Math.hypot(...forward);
    const f = normalize(forward), right = normalize(cross(f, upv)), up = cross(right, f);
    const viewport = single('VIEWPORT', null);
    const halfW = viewport ? viewport[0] / 2 : distance * Math.tan(Math.PI / 6);
    const halfH = viewport ? viewport[1] / 2 : (halfW * rh) / rw;
    const corners = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([i, j]) => add(to, add(scale(right, i * halfW), scale(up, j * halfH))));
    corners.forEach((c, i) => { line(from, c, '#4db6ac'); line(c, corners[(i + 1) % 4], '#4db6ac'); });
    line(from, to, '#80cbc4');
    const q = project(from);
    if (q) { ctx.fillStyle = '#4db6ac'; ctx.fillRect(q[0] - 4, q[1] - 4, 8, 8); }
  }

  function drawPlacing(ctx, line) {
    const p = state.placing;
    for (const point of p.points) {
      const q = project(point);
      if (q) { ctx.fillStyle = '#ff8a65'; ctx.fillRect(q[0] - 3, q[1] - 3, 6, 6); }
    }
    if (p.current) {
      line([p.current[0], 0, p.current[2]], p.current, '#ff8a65');
      const q = project(p.current);
      if (q) { ctx.strokeStyle = '#ff8a65'; ctx.strokeRect(q[0] - 4, q[1] - 4, 8, 8); }
    }
  }

  // ---------------------------------------------------- tools and mouse --

  const HINTS = {
    select: 'click an object to select it; drag to move it (Shift: up/down); drag empty space to orbit',
    sphere: 'press on the x–z plane, drag up/down for y; then drag for the radius',
    box: 'press on the x–z plane, drag up/down for y; then drag for the size',
    superquadric: 'press on the x–z plane, drag up/down for y; then drag for the size',
    triangle: 'three points: press on the x–z plane, drag up/down for y',
    rectangle: 'two opposite corners at the first one’s height',
    bspline: 'control points row by row (order and grid in the panel)',
    viewpoint: 'press on the x–z plane, drag up/down for y: the eye',
    light: 'press on the x–z plane, drag up/down for y: a light',
  };

  function setTool(tool) {
    state.tool = tool;
    state.placing = null;
    // A placing tool's panel shows its settings, not an old selection.
    if (tool !== 'select') state.selection = -1;
    for (const b of document.querySelectorAll('#toolbar button')) b.classList.toggle('active', b.dataset.tool === tool);
    $('tool-hint').textContent = HINTS[tool];
    showPanel();
    drawWire();
  }
  for (const b of document.querySelectorAll('#toolbar button')) b.onclick = () => setTool(b.dataset.tool);

  const options = { surface: 1, order: 3, rows: 4, cols: 4, samples: 16, brightness: 10 };
  const objectCentre = (s) => {
    const a = s.args;
    switch (s.keyword) {
      case 'SPHERE': return a.slice(2, 5);
      case 'BOX': return a.slice(1, 4);
      case 'SUPERQUADRIC': return a.slice(2, 5);
      case 'LIGHT': return a.slice(1, 4);
      case 'TRIANGLE': case 'RECTANGLE': {
        const n = (a.length - 1) / 3;
        const c = [0, 0, 0];
        for (let i = 0; i < n; i++) for (let k = 0; k < 3; k++) c[k] += a[1 + 3 * i + k] / n;
        return c;
      }
      case 'BSPLINE': {
        const n = (a.length - 6) / 3;
        const c = [0, 0, 0];
        for (let i = 0; i < n; i++) for (let k = 0; k < 3; k++) c[k] += a[6 + 3 * i + k] / n;
        return c;
      }
      default: return null;
    }
  };
  /** The indices of the arguments that are x coordinates of points. */
  const pointArgs = (s) => {
    switch (s.keyword) {
      case 'SPHERE': case 'SUPERQUADRIC': return [2];
      case 'BOX': case 'LIGHT': return [1];
      case 'TRIANGLE': return [1, 4, 7];
      case 'RECTANGLE': return [1, 4, 7, 10];
      case 'BSPLINE': return Array.from({ length: (s.args.length - 6) / 3 }, (_, i) => 6 + 3 * i);
      default: return [];
    }
  };

  let drag = null;
  wire.addEventListener('contextmenu', (e) => e.preventDefault());
  wire.addEventListener('pointerdown', (e) => {
    wire.setPointerCapture(e.pointerId);
    const x = e.offsetX, y = e.offsetY;
    if (state.tool === 'select' || e.button !== 0) {
      let best = -1, bestDistance = 12;
      if (e.button === 0) {
        (state.model || []).forEach((s, i) => {
          const c = objectCentre(s);
          const q = c && project(c);
          if (q && Math.hypot(q[0] - x, q[1] - y) < bestDistance) { best = i; bestDistance = Math.hypot(q[0] - x, q[1] - y); }
        });
      }
      if (best >= 0) {
        state.selection = best;
        const s = state.model[best];
        drag = { kind: 'move', x, y, start: objectCentre(s), args: s.args.slice(), base: text.value, shift: e.shiftKey };
        showPanel();
      } else {
        if (e.button === 0 && state.tool === 'select') state.selection = -1;
        drag = { kind: e.shiftKey || e.button === 1 ? 'pan' : 'orbit', x, y };
        showPanel();
      }
      drawWire();
      return;
    }
    // Placing: the first press of a point picks it on the x–z plane; a press
    // in the size phase starts the size drag.
    const p = state.placing || (state.placing = { tool: state.tool, points: [], phase: 'point' });
    if (p.phase === 'size') { drag = { kind: 'size', x, y }; return; }
    const ground = onPlane(x, y, p.tool === 'rectangle' && p.points.length ? p.points[0][1] : 0);
    if (!ground) return;
    p.current = ground;
    drag = { kind: p.tool === 'rectangle' && p.points.length ? 'flat' : 'height', x, y, ground };
    drawWire();
  });
  wire.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const x = e.offsetX, y = e.offsetY;
    const dx = x - drag.x, dy = y - drag.y;
    const unit = state.camera.distance / focal();
    if (drag.kind === 'orbit') {
      state.camera.yaw -= dx * 0.01;
      state.camera.pitch = Math.max(-1.5, Math.min(1.5, state.camera.pitch + dy * 0.01));
      drag.x = x; drag.y = y;
    } else if (drag.kind === 'pan') {
      const b = basis();
      state.camera.target = add(state.camera.target, add(scale(b.right, -dx * unit), scale(b.up, dy * unit)));
      drag.x = x; drag.y = y;
    } else if (drag.kind === 'height') {
      state.placing.current = [drag.ground[0], -dy * unit, drag.ground[2]];
    } else if (drag.kind === 'flat') {
      const p = onPlane(x, y, state.placing.points[0][1]);
      if (p) state.placing.current = p;
    } else if (drag.kind === 'size') {
      state.placing.size = Math.max(0.05, Math.hypot(dx, dy) * unit);
      previewSize();
    } else if (drag.kind === 'move') {
      const s = state.model[state.selection];
      let delta;
      if (drag.shift) delta = [0, -dy * unit, 0];
      else {
        const a = onPlane(drag.x, drag.y, drag.start[1]), b = onPlane(x, y, drag.start[1]);
        delta = a && b ? sub(b, a) : [0, 0, 0];
      }
      const args = drag.args.slice();
      for (const i of pointArgs(s)) for (let k = 0; k < 3; k++) args[i + k] = drag.args[i + k] + delta[k];
      const before = text.value;
      const t = drag.base;
      text.value = t.slice(0, s.start) + statementText(s.keyword, args) + t.slice(s.end);
      state.model = parseModel(text.value);
      if (before !== text.value) { drag.moved = true; scheduleDraft(); }
    }
    drawWire();
  });
  wire.addEventListener('pointerup', () => {
    if (!drag) return;
    const d = drag;
    drag = null;
    if (d.kind === 'move' && d.moved) {
      state.undoStack.push(d.base); state.redoStack = [];
      textChanged();
      return;
    }
    if (d.kind === 'height' || d.kind === 'flat') pointPlaced();
    else if (d.kind === 'size') sizeChosen();
  });
  wire.addEventListener('wheel', (e) => {
    e.preventDefault();
    state.camera.distance = Math.max(1, Math.min(1e4, state.camera.distance * Math.exp(e.deltaY * 0.001)));
    drawWire();
  }, { passive: false });

  function pointPlaced() {
    const p = state.placing;
    p.points.push(p.current);
    p.current = null;
    const n = p.points.length;
    const [c] = p.points;
    switch (p.tool) {
      case 'sphere': case 'box': case 'superquadric':
        p.phase = 'size'; p.size = 1;
        $('tool-hint').textContent = 'now drag for the size';
        break;
      case 'viewpoint': finishPlacing(() => setSingle('VIEWPOINT', c)); break;
      case 'light': finishPlacing(() => appendStatement('LIGHT', [options.brightness, ...c])); break;
      case 'triangle':
        if (n === 3) finishPlacing(() => appendStatement('TRIANGLE', [options.surface, ...p.points.flat()]));
        break;
      case 'rectangle':
        if (n === 2) {
          const [a, b] = p.points;
          finishPlacing(() => appendStatement('RECTANGLE', [options.surface, ...a, b[0], a[1], a[2], ...b, a[0], a[1], b[2]]));
        }
        break;
      case 'bspline':
        if (n === options.rows * options.cols) {
          finishPlacing(() => appendStatement('BSPLINE', [options.surface, options.order, options.rows, options.cols, options.samples, options.samples, ...p.points.flat()]));
        }
        break;
    }
    drawWire();
  }

  function sizedArgs() {
    const p = state.placing, [c] = p.points, r = p.size;
    switch (p.tool) {
      case 'sphere': return ['SPHERE', [options.surface, r, ...c]];
      case 'box': return ['BOX', [options.surface, ...c, r, r, r]];
      default: return ['SUPERQUADRIC', [options.surface, 4, ...c, r, r, r]];
    }
  }
  function previewSize() {
    const [keyword, args] = sizedArgs();
    state.model = parseModel(text.value);
    state.model.push({ keyword, args, start: 0, end: 0 });
  }
  function sizeChosen() {
    const [keyword, args] = sizedArgs();
    finishPlacing(() => appendStatement(keyword, args));
  }
  function finishPlacing(edit) {
    state.placing = null;
    edit();
    state.selection = state.model.length - 1;
    $('tool-hint').textContent = HINTS[state.tool];
    ensureSurface(options.surface);
    showPanel();
    drawWire();
  }

  /** A placed object's surface must exist: add a grey one if not. */
  function ensureSurface(number) {
    if (!state.model.some((s) => s.keyword === 'SURFACE' && s.args[0] === number)) {
      const selection = state.selection;
      appendStatement('SURFACE', [number, 0.1, 0.1, 0.1, 0.6, 0.6, 0.6, 0.3, 0.3, 0.3, 20, 0, 0]);
      state.selection = selection;
    }
  }

  // ------------------------------------------------------------ the panel --

  const FIELDS = {
    SPHERE: ['surface', 'radius', 'x', 'y', 'z'],
    BOX: ['surface', 'x', 'y', 'z', 'half x', 'half y', 'half z'],
    SUPERQUADRIC: ['surface', 'power', 'x', 'y', 'z', 'size x', 'size y', 'size z'],
    LIGHT: ['brightness', 'x', 'y', 'z'],
    SURFACE: ['number', 'ambient r', 'ambient g', 'ambient b', 'diffuse r', 'diffuse g', 'diffuse b', 'specular r', 'specular g', 'specular b', 'coefficient', 'reflection', 'transparency'],
  };
  // The thesis's tool offers 16 predefined colours.
  const COLOURS = ['#000000', '#ffffff', '#ff0000', '#00ff00', '#0000ff', '#ffff00', '#00ffff', '#ff00ff',
    '#808080', '#c0c0c0', '#800000', '#008000', '#000080', '#808000', '#008080', '#ff8000'];

  function fieldNames(s) {
    if (FIELDS[s.keyword]) return FIELDS[s.keyword];
    if (s.keyword === 'TRIANGLE' || s.keyword === 'RECTANGLE') {
      const names = ['surface'];
      for (let i = 1; i <= (s.args.length - 1) / 3; i++) names.push(`x${i}`, `y${i}`, `z${i}`);
      return names;
    }
    if (s.keyword === 'BSPLINE') {
      const names = ['surface', 'order', 'rows', 'cols', 'samples u', 'samples v'];
      for (let i = 0; i < (s.args.length - 6) / 3; i++) names.push(`x${i}`, `y${i}`, `z${i}`);
      return names;
    }
    return s.args.map((_, i) => `#${i + 1}`);
  }

  function numberInput(label, value, onChange, step = 0.1) {
    const wrap = document.createElement('label');
    wrap.textContent = label + ' ';
    const input = document.createElement('input');
    input.type = 'number'; input.step = String(step); input.value = String(value);
    input.dataset.field = label;
    input.addEventListener('change', () => onChange(Number(input.value)));
    wrap.append(input);
    return wrap;
  }

  function showPanel() {
    const panel = $('panel');
    // Not while a number is being typed into it (its change rebuilds it).
    const focused = document.activeElement;
    if (panel.contains(focused) && focused.tagName === 'INPUT' && focused.type === 'number') return;
    panel.replaceChildren();
    const heading = (t) => { const h = document.createElement('b'); h.textContent = t; h.style.gridColumn = '1 / -1'; panel.append(h); };
    const model = state.model || [];
    const s = model[state.selection];
    if (s && s.start !== s.end) {
      heading(s.keyword.toLowerCase());
      fieldNames(s).forEach((name, i) => {
        panel.append(numberInput(name, s.args[i], (v) => {
          // The model as it is now: other fields may have changed since.
          const now = state.model[state.selection];
          if (!now || now.keyword !== s.keyword) return;
          const args = now.args.slice(); args[i] = v;
          replaceStatement(state.selection, s.keyword, args);
        }));
      });
      const surfaceNumber = ['SPHERE', 'BOX', 'SUPERQUADRIC', 'TRIANGLE', 'RECTANGLE', 'BSPLINE'].includes(s.keyword) ? s.args[0] : null;
      if (surfaceNumber !== null) surfaceEditor(panel, surfaceNumber, heading);
    } else if (state.tool === 'bspline') {
      heading('new B-spline');
      for (const k of ['order', 'rows', 'cols', 'samples']) panel.append(numberInput(k, options[k], (v) => { options[k] = Math.max(2, Math.round(v)); }, 1));
    } else if (state.tool !== 'select') {
      heading('new ' + state.tool);
      panel.append(numberInput('surface', options.surface, (v) => { options.surface = Math.max(1, Math.round(v)); }, 1));
      if (state.tool === 'light') panel.append(numberInput('brightness', options.brightness, (v) => { options.brightness = v; }));
    } else {
      heading('scene');
      const bg = single('BACKGROUND', [0, 0, 0]);
      ['background r', 'background g', 'background b'].forEach((n, i) => panel.append(numberInput(n, bg[i], (v) => {
        const next = single('BACKGROUND', [0, 0, 0]).slice(); next[i] = v; setSingle('BACKGROUND', next);
      }, 0.05)));
      panel.append(numberInput('RDEPTH', single('RDEPTH', [3])[0], (v) => setSingle('RDEPTH', [Math.round(v)]), 1));
      const raster = single('RASTER', [320, 240]);
      panel.append(numberInput('RASTER w', raster[0], (v) => setSingle('RASTER', [Math.round(v), single('RASTER', [320, 240])[1]]), 1));
      panel.append(numberInput('RASTER h', raster[1], (v) => setSingle('RASTER', [single('RASTER', [320, 240])[0], Math.round(v)]), 1));
      model.forEach((l, i) => {
        if (l.keyword === 'LIGHT') panel.append(numberInput(`light ${i} brightness`, l.args[0], (v) => { const a = l.args.slice(); a[0] = v; replaceStatement(i, 'LIGHT', a); }));
      });
    }
  }

  /** Edits SURFACE `number`: 16 colours into ambient, diffuse or specular,
   *  RGB sliders, coefficient, reflection and transparency. */
  function surfaceEditor(panel, number, heading) {
    heading(`surface ${number}`);
    const index = () => state.model.findIndex((x) => x.keyword === 'SURFACE' && x.args[0] === number);
    const current = () => { const i = index(); return i >= 0 ? state.model[i].args.slice() : [number, 0.1, 0.1, 0.1, 0.6, 0.6, 0.6, 0.3, 0.3, 0.3, 20, 0, 0]; };
    const write = (args) => { const i = index(); if (i >= 0) replaceStatement(i, 'SURFACE', args); else appendStatement('SURFACE', args); };
    const target = document.createElement('select');
    target.id = 'surface-target';
    for (const [v, label] of [[1, 'ambient'], [4, 'diffuse'], [7, 'specular']]) target.append(new Option(label, String(v)));
    target.value = String(panel.dataset.target || 4);
    target.onchange = () => { panel.dataset.target = target.value; };
    panel.append(target);
    const swatches = document.createElement('div');
    swatches.className = 'swatches';
    COLOURS.forEach((c, i) => {
      const b = document.createElement('button');
      b.style.background = c; b.title = c; b.dataset.colour = String(i);
      b.onclick = () => {
        const args = current(); const at = Number(target.value);
        const rgb = [1, 3, 5].map((k) => parseInt(c.slice(k, k + 2), 16) / 255);
        // Ambient is a dim version of the colour, as the thesis's editor did.
        const k = at === 1 ? 0.1 : 1;
        for (let j = 0; j < 3; j++) args[at + j] = Math.round(rgb[j] * k * 1000) / 1000;
        write(args);
      };
      swatches.append(b);
    });
    panel.append(swatches);
    const args = current();
    const names = FIELDS.SURFACE;
    for (let i = 1; i < 13; i++) {
      const wrap = document.createElement('label');
      wrap.textContent = names[i] + ' ';
      const slider = document.createElement('input');
      slider.type = 'range'; slider.min = '0'; slider.max = i === 10 ? '200' : '1'; slider.step = i === 10 ? '1' : '0.01';
      slider.value = String(args[i]); slider.dataset.field = names[i];
      slider.addEventListener('change', () => { const a = current(); a[i] = Number(slider.value); write(a); });
      wrap.append(slider);
      panel.append(wrap);
    }
  }

  // -------------------------------------------------------- undo, keys --

  function undo() {
    if (!state.undoStack.length) return;
    state.redoStack.push(text.value);
    text.value = state.undoStack.pop();
    textChanged();
  }
  function redo() {
    if (!state.redoStack.length) return;
    state.undoStack.push(text.value);
    text.value = state.redoStack.pop();
    textChanged();
  }
  $('undo').onclick = undo;
  $('redo').onclick = redo;

  document.addEventListener('keydown', (e) => {
    const inText = e.target === text || e.target.tagName === 'INPUT';
    const key = e.key.toLowerCase();
    if ((e.ctrlKey || e.metaKey) && key === 'enter') { e.preventDefault(); render(); return; }
    if ((e.ctrlKey || e.metaKey) && key === 's') { e.preventDefault(); saveScene(false); return; }
    if (e.key === 'F1') { e.preventDefault(); $('help').showModal(); return; }
    if (inText) return;
    if ((e.ctrlKey || e.metaKey) && key === 'z') { e.preventDefault(); if (e.shiftKey) redo(); else undo(); return; }
    if ((e.ctrlKey || e.metaKey) && key === 'y') { e.preventDefault(); redo(); return; }
    if ((e.key === 'Delete' || e.key === 'Backspace') && state.selection >= 0) { e.preventDefault(); deleteStatement(state.selection); return; }
    if (e.key === 'Escape') { setTool('select'); return; }
    const tools = ['sphere', 'box', 'superquadric', 'triangle', 'rectangle', 'bspline', 'viewpoint', 'light'];
    if (key >= '1' && key <= '8') setTool(tools[Number(key) - 1]);
    if (key === 's') setTool('select');
  });

  $('render').onclick = render;
  $('save-scene').onclick = () => saveScene(false);
  $('reload-scene').onclick = () => loadScene(false);
  $('help-button').onclick = () => $('help').showModal();
  $('help-close').onclick = () => $('help').close();

  // Exposed for scripts and the browser tests.
  Object.assign(state, { render, saveScene, setText, setTool, saveImage, undo, redo, project,
    imageBytes: (mode, format) => state.octrace.encode(state.lastRender.data, mode, format, state.lastRender.width, state.lastRender.height) });

  (async () => {
    try {
      state.octrace = await loadOctrace();
      await loadScene(true);
      setTool('select');
      fitView();
      setStatus('ready: Render (Ctrl+Enter) traces the full image');
      document.body.dataset.ready = 'true';
    } catch (e) {
      setStatus('cannot start: ' + e.message);
    }
  })();

  /** Frames the eye and the objects. */
  function fitView() {
    const points = (state.model || []).map(objectCentre).filter(Boolean);
    points.push(single('VIEWPOINT', [0, 0, 10]));
    const extent = Math.max(5, ...points.map((p) => Math.hypot(...p)));
    state.camera.distance = extent * 2.5;
    drawWire();
  }
}
