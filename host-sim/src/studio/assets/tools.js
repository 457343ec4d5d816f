// The tools: select and move objects, orbit and pan the view, and place
// new objects, lights and the eye with the mouse, each an edit of the text.

import { objectCentre, parseModel, placed, pointArgs, statementText } from './model.js';
import { add, scale, sub } from './view.js';

/** Installs the tools on `app.view`'s canvas; `app` is the page (studio.js). */
export function createTools(app) {
  const { state, $, editor } = app;
  const wire = $('wire');
  const { basis, focal, project, onPlane } = app.view;
  const drawWire = () => app.view.draw();
  const showPanel = () => app.panel.show();
  const { scheduleDraft, setSingle, appendStatement } = app;

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
  let drag = null;
  wire.addEventListener('contextmenu', (e) => e.preventDefault());
  wire.addEventListener('pointerdown', (e) => {
    wire.setPointerCapture(e.pointerId);
    const x = e.offsetX, y = e.offsetY;
    if (state.tool === 'select' || e.button !== 0) {
      let best = -1, bestDistance = 12;
      if (e.button === 0) {
        (state.model || []).forEach((s, i) => {
          // Where it is seen: at the frame shown.
          const c = objectCentre(placed(s, state.frame));
          const q = c && project(c);
          if (q && Math.hypot(q[0] - x, q[1] - y) < bestDistance) { best = i; bestDistance = Math.hypot(q[0] - x, q[1] - y); }
        });
      }
      if (best >= 0) {
        state.selection = best;
        const s = state.model[best];
        drag = { kind: 'move', x, y, start: objectCentre(placed(s, state.frame)), statement: s, base: editor.text(), shift: e.shiftKey };
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
      // The statement as it was when the drag began, in the text then.
      const s = drag.statement;
      let delta;
      if (drag.shift) delta = [0, -dy * unit, 0];
      else {
        const a = onPlane(drag.x, drag.y, drag.start[1]), b = onPlane(x, y, drag.start[1]);
        delta = a && b ? sub(b, a) : [0, 0, 0];
      }
      const args = s.args.slice();
      for (const i of pointArgs(s)) for (let k = 0; k < 3; k++) args[i + k] += delta[k];
      const before = editor.text();
      const t = drag.base;
      // A preview, outside the history (the drag's end is one step of it);
      // not moved, the text as written (a click only selects).
      const moved = delta.some((d) => d !== 0);
      editor.edit(moved ? t.slice(0, s.start) + statementText(s.keyword, args) + t.slice(s.end) : t, true);
      state.model = parseModel(editor.text());
      if (before !== editor.text()) { drag.moved = true; scheduleDraft(); }
    }
    drawWire();
  });
  wire.addEventListener('pointerup', () => {
    if (!drag) return;
    const d = drag;
    drag = null;
    if (d.kind === 'move' && d.moved) {
      editor.commit(d.base, editor.text());
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
    state.model = parseModel(editor.text());
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

  return { setTool, options };
}
