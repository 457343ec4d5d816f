// The panel beside the view: the selected statement's fields, a surface
// editor (the thesis's 16 colours, sliders), the next object's settings, or
// the scene's own settings. Every change is an edit of the text.

import { FIELDS, SHAPES, fieldNames } from './model.js';

/** The panel of the page `app` (studio.js). */
export function createPanel(app) {
  const { state, $, single, setSingle, replaceStatement, appendStatement } = app;
  const options = app.tools.options;

  // The thesis's tool offers 16 predefined colours.
  const COLOURS = ['#000000', '#ffffff', '#ff0000', '#00ff00', '#0000ff', '#ffff00', '#00ffff', '#ff00ff',
    '#808080', '#c0c0c0', '#800000', '#008000', '#000080', '#808000', '#008080', '#ff8000'];

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
      const surfaceNumber = SHAPES.includes(s.keyword) ? s.args[0] : null;
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
      // Lights numbered as the file has them, first to last (i is the
      // statement's place among all statements).
      let light = 0;
      model.forEach((l, i) => {
        if (l.keyword === 'LIGHT') panel.append(numberInput(`light ${++light} brightness`, l.args[0], (v) => { const a = l.args.slice(); a[0] = v; replaceStatement(i, 'LIGHT', a); }));
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

  return { show: showPanel };
}
