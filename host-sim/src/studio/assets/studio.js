// octrace studio: the page. The octrace module (octrace-core compiled to
// WebAssembly, octrace.js) does all parsing checks, rendering, palettes and
// image files; this module is the plumbing, and wires up the code editor
// (editor.js), the scene model (model.js), the wireframe view (view.js), the
// tools (tools.js), the panel (panel.js), the board (board.js) and the time
// controls of an animation (time.js). worker.js renders with its own octrace
// module: the page's thread never traces, so that a scene of hours a pixel
// cannot freeze it, and a render or draft is stopped at once, inside its
// pixel, by terminating its workers when the next one starts.

import { loadOctrace } from './octrace.js';
import { createEditor } from './editor.js';
import { objectCentre, parseModel, single as singleIn, statementText } from './model.js';
import { createTime } from './time.js';
import { createView } from './view.js';
import { createTools } from './tools.js';
import { createPanel } from './panel.js';
import { createBoard } from './board.js';

main();

function main() {
  const $ = (id) => document.getElementById(id);
  const editor = createEditor($('scene'), textChanged);
  const imageCanvas = $('image');
  const state = {
    octrace: null,
    version: null, // the ETag of the file as loaded, for conflict checks
    sceneName: '',
    writable: false,
    lastRender: null, // {width, height, data: colours then objects}
    frame: 0, // the frame of an animation shown (time.js)
    boardErrors: [], // the board's, till the text changes
    tool: 'select', selection: -1, placing: null,
    camera: { yaw: 0.7, pitch: 0.45, distance: 30, target: [0, 0, 0] },
    draftSeq: 0, draftSent: 0, draftTimer: 0,
  };
  // Exposed for scripts and the browser tests.
  window.studio = state;
  // Script errors, and whatever the Content-Security-Policy refuses, are
  // kept for the tests.
  window.addEventListener('error', (e) => (state.log = state.log || []).push(['error', e.message, e.lineno]));
  document.addEventListener('securitypolicyviolation',
    (e) => (state.log = state.log || []).push(['refused', e.effectiveDirective, e.blockedURI]));

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
    editor.load(stored !== null && stored !== body ? stored : body);
    if (stored !== null && stored !== body) setStatus('unsaved changes restored from this browser');
  }

  async function saveScene(force) {
    if (!state.writable) { alert('The studio was started without a scene file: nothing to save to.'); return false; }
    const response = await api('/scene', {
      method: 'PUT', body: editor.text(), headers: { 'If-Match': force ? '*' : '"' + state.version + '"' },
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

  /** Replaces the text: a tool's or the panel's edit, one step of undo. */
  function setText(value) {
    editor.edit(value);
  }

  let lastKnown = '';
  /** After every change of the text (the editor calls it). */
  function textChanged() {
    if (editor.text() !== lastKnown) {
      lastKnown = editor.text();
      localStorage.setItem(storageKey(), lastKnown);
      state.boardErrors = [];
    }
    state.model = parseModel(lastKnown);
    checkErrors();
    drawWire();
    showPanel();
    scheduleDraft();
  }

  /** Another frame is shown (time.js): its errors, its wireframe; returns
   *  the frame's load (octrace.load's answer). */
  function frameChanged() {
    const loaded = checkErrors();
    drawWire();
    return loaded;
  }

  /** Loads the text at the frame shown and lists its errors, and the
   *  board's, under the editor and at their places in it. */
  function checkErrors() {
    if (!state.octrace) return;
    const loaded = state.octrace.load(editor.text(), state.frame);
    app.time.scene(loaded);
    const board = new Set(state.boardErrors.map((e) => e.text));
    const errors = (loaded.errors || []).filter((e) => !board.has(e)).map((e) => {
      const [, line, column, message] = /^(\d+):(\d+): ([\s\S]*)$/.exec(e) || [, 0, 0, e];
      return { text: e, line: Number(line), column: Number(column), message };
    });
    errors.push(...state.boardErrors);
    $('errors').replaceChildren(...errors.map((e) => errorItem(e)));
    editor.setErrors(errors);
    return loaded;
  }

  /** An error of the list (`text`, `line:col: …`; `board` says which
   *  board found it, if one did); a click goes to its line and column
   *  (line 0: the whole scene's). */
  function errorItem({ text, line, column, board }) {
    const li = document.createElement('li');
    li.textContent = text;
    li.dataset.line = String(line);
    li.dataset.column = String(column);
    if (board) { li.classList.add('board'); li.title = board; }
    if (line > 0) li.onclick = () => editor.goTo(line, column);
    return li;
  }

  /** The errors ({line, column, message}) the board `board` found, listed
   *  and marked with the page's own till the text changes; an error the
   *  page found too is listed once, as the board's. */
  function showBoardErrors(errors, board) {
    state.boardErrors = errors.map((e) => ({ ...e, text: (e.line ? `${e.line}:${e.column}: ` : '') + e.message, board }));
    checkErrors();
  }

  // ---------------------------------------------------------------- draft --

  /** A worker for requests of which only the newest matters, and a spare
   *  already loading: a request still running when the next is sent is
   *  stopped at once (its worker terminated, the spare takes over), so a
   *  scene of hours a pixel never holds the next up. `send(message,
   *  answer)` hands the worker's messages to `answer` till it returns true
   *  (the request is finished); `stop()` ends the request running, if any.
   *  A worker that finished keeps its state: time.js's players keep the
   *  frame they traced last. */
  function workerPair() {
    const start = () => {
      const worker = new Worker('worker.js', { type: 'module' });
      worker.onmessage = (event) => { if (worker === current && answer(event.data)) busy = false; };
      return worker;
    };
    let current = start(), spare = start(), busy = false, answer = () => true;
    const stop = () => {
      if (!busy) return;
      current.terminate();
      current = spare;
      spare = start();
      busy = false;
    };
    const send = (message, answerWith) => {
      stop();
      busy = true;
      answer = answerWith;
      current.postMessage(message);
    };
    return { send, stop };
  }

  // The draft's worker: the text's drafts and, for an animation, the
  // frames time.js's player draws at the draft's size, one history of
  // requests, so that no draft runs on after a newer one is asked for.
  const drafts = workerPair();
  const sendDraft = drafts.send;
  /** A text draft's message; true once it is finished. */
  function draftMessage(m) {
    if (m.type === 'draft-errors' || m.type === 'error') {
      if (m.seq === state.draftSeq) $('draft-status').textContent = 'scene has errors';
      return true;
    }
    if (m.type !== 'draft') return false;
    if (m.seq !== state.draftSeq) return m.final; // superseded
    const canvas = $('draft');
    canvas.width = m.width; canvas.height = m.height;
    putRgb(canvas, m.data.subarray(0, 3 * m.width * m.height), m.width, m.height);
    if (m.final) {
      const latency = performance.now() - state.draftSent;
      state.draftLatency = latency;
      canvas.dataset.state = 'done';
      canvas.dataset.seq = String(m.seq);
      canvas.dataset.frame = String(m.frame);
      $('draft-status').textContent = `${m.width}×${m.height}, ${latency.toFixed(0)} ms after the last change`;
    }
    return m.final;
  }
  function scheduleDraft() {
    // Playing, the next frame's draft is of the text as it is then.
    if (state.playing) return;
    app.time.superseded();
    clearTimeout(state.draftTimer);
    const changedAt = performance.now();
    $('draft').dataset.state = 'pending';
    // A short pause, so a burst of keys renders once.
    state.draftTimer = setTimeout(() => {
      state.draftSeq += 1;
      state.draftSent = changedAt;
      sendDraft({ type: 'draft', seq: state.draftSeq, text: editor.text(), frame: state.frame, width: 160, height: 120, progressive: true }, draftMessage);
    }, 25);
  }
  /** The draft is time.js's player's from now on (it sends its frame
   *  with `sendDraft`): a text draft asked for or running is not to
   *  replace it. */
  function draftDrawn() {
    clearTimeout(state.draftTimer);
    state.draftSeq += 1;
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
  /** Stops the render under way, if any. */
  function stopRender() {
    renderJob += 1;
    for (const w of workers) w.terminate();
    workers = [];
  }
  async function render() {
    // A frame the player still traces would replace this render.
    app.time.superseded();
    stopRender();
    const job = renderJob;
    // The frame shown now (an animation's; 0 for a still).
    const frame = state.frame;
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
      used = await renderOnWorkers(editor.text(), frame, accel, width, height, place, () => job === renderJob);
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
    const which = loaded.frames ? `frame ${frame}: ` : '';
    setStatus(`done: ${which}${width}×${height} in ${seconds.toFixed(2)} s (${used}${how})`);
    state.lastSeconds = seconds;
    imageCanvas.dataset.frame = String(frame);
    imageCanvas.dataset.state = 'done';
  }

  /** Renders frame `frame` of `source` on Web Workers: 32×32 tiles handed
   *  out as workers become free, or the thesis's four equal rectangles
   *  (quarter i to worker i mod n); without "parallel", one worker renders
   *  bands of 8 rows in order. A render started next terminates them
   *  (`render`): they stop at once, inside the pixel they trace. */
  function renderOnWorkers(source, frame, accel, width, height, place, current) {
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
        worker.postMessage({ type: 'init', text: source, frame, accel, width, height });
      }
    });
  }

  /** Frame `frame` of the text, whole, as the render (time.js's player
   *  traced it): shown in the chosen display mode. */
  function showFrame(frame, width, height, data) {
    stopRender();
    state.lastRender = { width, height, data };
    showDisplay();
    imageCanvas.dataset.frame = String(frame);
    imageCanvas.dataset.state = 'done';
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
      const loaded = state.octrace.load(editor.text(), state.frame);
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
    const s = state.model[index], text = editor.text();
    setText(text.slice(0, s.start) + statementText(keyword, args) + text.slice(s.end));
  }

  function appendStatement(keyword, args) {
    const text = editor.text();
    const sep = text.endsWith('\n') || text === '' ? '' : '\n';
    setText(text + sep + statementText(keyword, args) + '\n');
    return state.model.length - 1;
  }

  /** The one statement of a kind (VIEWPOINT, RDEPTH, …): replaced or added. */
  function setSingle(keyword, args) {
    const index = state.model.findIndex((s) => s.keyword === keyword);
    if (index >= 0) replaceStatement(index, keyword, args); else appendStatement(keyword, args);
  }

  /** Removes statement `index`, and the MOVE that moves it. */
  function deleteStatement(index) {
    const s = state.model[index], text = editor.text();
    let end = s.moved ? s.moved.end : s.end;
    if (text[end] === '\n') end += 1;
    state.selection = -1;
    setText(text.slice(0, s.start) + text.slice(end));
  }

  const single = (keyword, fallback) => singleIn(state.model || [], keyword, fallback);

  // ----------------------------------------------- view, tools and panel --

  const app = { state, $, editor, api, frameChanged, scheduleDraft, workerPair, sendDraft, draftDrawn, showFrame,
    single, setSingle, replaceStatement, appendStatement, showBoardErrors, putRgb, setStatus };
  app.view = createView(state, $('wire'));
  app.tools = createTools(app);
  app.panel = createPanel(app);
  app.board = createBoard(app);
  app.time = createTime(app);
  const drawWire = app.view.draw, showPanel = app.panel.show, setTool = app.tools.setTool, project = app.view.project;

  // -------------------------------------------------------- undo, keys --

  // One history, the editor's: typing, the tools' and the panel's edits.
  const undo = () => editor.undo(), redo = () => editor.redo();
  $('undo').onclick = undo;
  $('redo').onclick = redo;

  // The page's keys, wherever the focus is: caught before the editor sees
  // them (its Ctrl+Enter would insert a line).
  document.addEventListener('keydown', (e) => {
    const key = e.key.toLowerCase();
    const action = !(e.ctrlKey || e.metaKey) ? (e.key === 'F1' ? () => $('help').showModal() : null)
      : key === 'enter' ? (e.shiftKey ? app.board.send : render)
        : key === 's' ? () => saveScene(false) : null;
    if (!action) return;
    e.preventDefault();
    e.stopPropagation();
    action();
  }, { capture: true });
  // The view's keys, except in the editor (whose own undo and redo are of
  // the same history) and in the panel's fields.
  document.addEventListener('keydown', (e) => {
    const key = e.key.toLowerCase();
    if (e.defaultPrevented || e.target === $('scene') || e.target.tagName === 'INPUT') return;
    if ((e.ctrlKey || e.metaKey) && key === 'z') { e.preventDefault(); if (e.shiftKey) redo(); else undo(); return; }
    if ((e.ctrlKey || e.metaKey) && key === 'y') { e.preventDefault(); redo(); return; }
    if ((e.key === 'Delete' || e.key === 'Backspace') && state.selection >= 0) { e.preventDefault(); deleteStatement(state.selection); return; }
    if (e.key === 'Escape') { setTool('select'); return; }
    if (e.key === ' ' && !['BUTTON', 'SELECT'].includes(e.target.tagName)) { e.preventDefault(); app.time.toggle(); return; }
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
  Object.assign(state, { render, saveScene, setText, setTool, saveImage, undo, redo, project, editor,
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
