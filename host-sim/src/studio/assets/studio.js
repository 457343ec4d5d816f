// octrace studio: the page. The octrace module (octrace-core compiled to
// WebAssembly, octrace.js) does all parsing checks, rendering, palettes and
// image files; this module is the editor and the plumbing, and wires up the
// scene model (model.js), the wireframe view (view.js), the tools (tools.js),
// the panel (panel.js) and the board (board.js). worker.js renders with its
// own octrace module: the page's thread never traces, so that a scene of
// hours a pixel cannot freeze it, and a render or draft is stopped at once,
// inside its pixel, by terminating its workers when the next one starts.

import { loadOctrace } from './octrace.js';
import { objectCentre, parseModel, single as singleIn, statementText } from './model.js';
import { createView } from './view.js';
import { createTools } from './tools.js';
import { createPanel } from './panel.js';
import { createBoard } from './board.js';

main();

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

  // The server's rules: the page and its assets are loaded under /TOKEN/
  // (so relative addresses carry it), and every other request names the
  // token in a header, never in a cookie, which a browser would also send
  // to every other server on this machine.
  const token = decodeURIComponent(location.pathname.split('/')[1] || '');
  /** fetch() of the server's `path` (/scene, /board), with the token. */
  const api = (path, init = {}) => fetch(path, { ...init, headers: { ...init.headers, 'X-Studio-Token': token } });

  // ----------------------------------------------------------- scene file --

  async function loadScene(preferStored) {
    const response = await api('/scene');
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
    const response = await api('/scene', {
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
      const [line, column] = e.split(':').map(Number);
      list.append(errorItem(e, line, column));
    }
    return loaded;
  }

  /** An error of the list: `message` (`line:col: …`); a click goes to
   *  its line and column (line 0: an error of the whole scene). */
  function errorItem(message, line, column) {
    const li = document.createElement('li');
    li.textContent = message;
    li.dataset.line = String(line);
    li.dataset.column = String(column);
    if (line > 0) li.onclick = () => goTo(line, column);
    return li;
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

  // The draft worker, and a spare already loading: a draft still running
  // when the next is asked for is stopped at once (its worker terminated,
  // the spare takes over), so a scene of hours a pixel never holds the
  // drafts up.
  const newDraftWorker = () => {
    const worker = new Worker('worker.js', { type: 'module' });
    worker.onmessage = (event) => draftMessage(event.data);
    return worker;
  };
  let draftWorker = newDraftWorker();
  let spareDraftWorker = newDraftWorker();
  let draftBusy = false;
  function sendDraft(message) {
    if (draftBusy) {
      draftWorker.terminate();
      draftWorker = spareDraftWorker;
      spareDraftWorker = newDraftWorker();
    }
    draftBusy = true;
    draftWorker.postMessage(message);
  }
  function draftMessage(m) {
    if (m.seq !== state.draftSeq) return; // superseded
    if (m.type === 'draft-errors') { draftBusy = false; $('draft-status').textContent = 'scene has errors'; return; }
    if (m.type !== 'draft') return;
    const canvas = $('draft');
    canvas.width = m.width; canvas.height = m.height;
    putRgb(canvas, m.data.subarray(0, 3 * m.width * m.height), m.width, m.height);
    if (m.final) {
      draftBusy = false;
      const latency = performance.now() - state.draftSent;
      state.draftLatency = latency;
      canvas.dataset.state = 'done';
      canvas.dataset.seq = String(m.seq);
      $('draft-status').textContent = `${m.width}×${m.height}, ${latency.toFixed(0)} ms after the last change`;
    }
  }
  function scheduleDraft() {
    clearTimeout(state.draftTimer);
    const changedAt = performance.now();
    $('draft').dataset.state = 'pending';
    // A short pause, so a burst of keys renders once.
    state.draftTimer = setTimeout(() => {
      state.draftSeq += 1;
      state.draftSent = changedAt;
      sendDraft({ type: 'draft', seq: state.draftSeq, text: text.value, width: 160, height: 120, progressive: true });
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
      used = await renderOnWorkers(text.value, accel, width, height, place, () => job === renderJob);
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
    const how = $('parallel').checked ? `, ${workers.length} workers, ${$('partition').value}` : ', one worker';
    setStatus(`done: ${width}×${height} in ${seconds.toFixed(2)} s (${used}${how})`);
    state.lastSeconds = seconds;
    imageCanvas.dataset.state = 'done';
  }

  /** Renders on Web Workers: 32×32 tiles handed out as workers become free,
   *  or the thesis's four equal rectangles (quarter i to worker i mod n);
   *  without "parallel", one worker renders bands of 8 rows in order. A
   *  render started next terminates them (`render`): they stop at once,
   *  inside the pixel they trace. */
  function renderOnWorkers(source, accel, width, height, place, current) {
    const parallel = $('parallel').checked;
    const count = parallel ? Math.max(1, Math.min(16, Number($('workers').value) || 4)) : 1;
    const pieces = [];
    if (!parallel) {
      for (let y = 0; y < height; y += 8) pieces.push({ x: 0, y, width, height: Math.min(8, height - y) });
    } else if ($('partition').value === 'equal4') {
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
      const equal4 = parallel && $('partition').value === 'equal4';
      const queues = Array.from({ length: count }, (_, i) => pieces.filter((_, j) => j % count === i));
      const give = (worker, index) => {
        const piece = equal4 ? queues[index].shift() : pieces[next++];
        if (piece) worker.postMessage({ type: 'tile', ...piece });
      };
      for (let i = 0; i < count; i++) {
        const worker = new Worker('worker.js', { type: 'module' });
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
    const mode = Number($('display').value), dither = Number($('dither').value);
    const rgb = state.octrace.display(r.data, mode, dither, r.width, r.height);
    imageCanvas.width = r.width; imageCanvas.height = r.height;
    putRgb(imageCanvas, rgb, r.width, r.height);
    imageCanvas.dataset.display = String(mode);
    imageCanvas.dataset.dither = String(dither);
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
  // The method changes the look of the same render.
  $('dither').addEventListener('change', showDisplay);

  // ---------------------------------------------------------------- image --

  function saveImage(format) {
    const r = state.lastRender;
    if (!r) { setStatus('render first'); return; }
    const mode = Number($('display').value), dither = Number($('dither').value);
    const bytes = state.octrace.encode(r.data, mode, dither, format, r.width, r.height);
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

  // ------------------------------------------------- statements in text --

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

  const single = (keyword, fallback) => singleIn(state.model || [], keyword, fallback);

  // ----------------------------------------------- view, tools and panel --

  const app = { state, $, text, api, textChanged, scheduleDraft, single, setSingle, replaceStatement, appendStatement,
    errorItem, goTo, putRgb, setStatus };
  app.view = createView(state, $('wire'), single);
  app.tools = createTools(app);
  app.panel = createPanel(app);
  app.board = createBoard(app);
  const drawWire = app.view.draw, showPanel = app.panel.show, setTool = app.tools.setTool, project = app.view.project;

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
    if ((e.ctrlKey || e.metaKey) && e.shiftKey && key === 'enter') { e.preventDefault(); app.board.send(); return; }
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
    imageBytes: (mode, format) => state.octrace.encode(state.lastRender.data, mode, Number($('dither').value), format, state.lastRender.width, state.lastRender.height) });

  (async () => {
    try {
      state.octrace = await loadOctrace();
      await loadScene(true);
      await app.board.connect();
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
