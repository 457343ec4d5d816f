// octrace studio: the page. The octrace module (octrace-core compiled to
// WebAssembly, octrace.js) does all parsing checks, rendering, palettes and
// image files; this module is the plumbing, and wires up the code editor
// (editor.js), the scene model (model.js), the wireframe view (view.js), the
// tools (tools.js), the panel (panel.js), the board (board.js), the full
// render and its image files (render.js) and the time controls of an
// animation (time.js). worker.js renders with its own octrace
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
import { createRender, putRgb } from './render.js';
import { workerPair } from './workers.js';

main();

function main() {
  const $ = (id) => document.getElementById(id);
  const editor = createEditor($('scene'), textChanged);
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

  const app = { state, $, editor, api, checkErrors, frameChanged, scheduleDraft, workerPair, sendDraft, draftDrawn,
    single, setSingle, replaceStatement, appendStatement, showBoardErrors, putRgb, setStatus };
  const { render, showFrame, saveImage } = createRender(app);
  app.showFrame = showFrame;
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
      // The core's default mode, host-sim's too: the page keeps no choice of its own.
      $('accel').value = String(state.octrace.defaultAccel());
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
