// The scene text as the page sees it: the statements the wireframe draws
// and the tools edit, with where each is in the text, and where a MOVE puts
// them at a frame. The octrace module stays the judge of validity; nothing
// here touches the page.

// How many arguments follow each keyword: the core's list, as host-sim
// serves it (keywords.js).
import { ARITY } from './keywords.js';

export { ARITY };
export const SHAPES = ['SPHERE', 'BOX', 'SUPERQUADRIC', 'TRIANGLE', 'RECTANGLE', 'BSPLINE'];
/** What a MOVE after it displaces (the format's rule). */
const MOVABLE = new Set([...SHAPES, 'LIGHT', 'VIEWPOINT', 'ORIGIN']);
/** A number as the format writes one. */
export const NUMBER = /^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$/;

/** The statements of `source`: each {keyword, args, start, end}; an object,
 *  LIGHT, VIEWPOINT or ORIGIN followed by a MOVE has `moved`: {keys:
 *  [[frame, dx, dy, dz], …], start, end} (the MOVE's place in the text). */
export function parseModel(source) {
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
    // The numbers after the fewest are the statement's too: FRAMES's rate,
    // a MOVE's further keys.
    let after = i + 1 + arity;
    while (after < tokens.length && NUMBER.test(tokens[after].text)) after++;
    const args = tokens.slice(i + 1, after);
    const end = args.length ? args[args.length - 1].end : tokens[i].end;
    const statement = { keyword, args: args.map((t) => (keyword === 'IMAGEFILE' ? t.text : Number(t.text))), start: tokens[i].start, end };
    const before = statements[statements.length - 1];
    if (keyword === 'MOVE' && before && MOVABLE.has(before.keyword)) {
      const keys = [];
      for (let k = 0; k + 4 <= statement.args.length; k += 4) keys.push(statement.args.slice(k, k + 4));
      before.moved = { keys, start: statement.start, end };
    }
    statements.push(statement);
    i = after;
  }
  return statements;
}

/** The displacement a MOVE's `keys` give at `frame`: linear between two
 *  keys, the first key's before it, the last's after it (the core's rule,
 *  here in floating point: the wireframe's places, not the render's). */
export function displacementAt(keys, frame) {
  let before = null;
  for (const [at, ...value] of keys) {
    if (at >= frame) {
      if (!before || at === frame) return value;
      const t = (frame - before[0]) / (at - before[0]);
      return value.map((v, a) => before[1][a] + (v - before[1][a]) * t);
    }
    before = [at, value];
  }
  return before ? before[1] : [0, 0, 0];
}

/** Statement `s` where its MOVE puts it at `frame` (itself if none). */
export function placed(s, frame) {
  if (!s.moved) return s;
  const d = displacementAt(s.moved.keys, frame);
  const args = s.args.slice();
  for (const i of pointArgs(s)) for (let k = 0; k < 3; k++) args[i + k] += d[k];
  return { ...s, args };
}

const fmt = (v) => String(Math.round(v * 1000) / 1000);

export function statementText(keyword, args) {
  if (keyword === 'BSPLINE') {
    const head = args.slice(0, 6).map(fmt).join(' ');
    const points = [];
    for (let i = 6; i < args.length; i += 3) points.push('  ' + args.slice(i, i + 3).map(fmt).join(' '));
    return `BSPLINE ${head}\n${points.join('\n')}`;
  }
  return `${keyword} ${args.map((a) => (typeof a === 'number' ? fmt(a) : a)).join(' ')}`;
}

/** The arguments of the one statement of a kind in `model` as written
 *  (or where its MOVE puts it at `frame`, if given), or `fallback`. */
export function single(model, keyword, fallback, frame) {
  const s = model.find((x) => x.keyword === keyword);
  if (!s || s.args.length !== ARITY[keyword]) return fallback;
  return frame === undefined ? s.args : placed(s, frame).args;
}

export const objectCentre = (s) => {
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
export const pointArgs = (s) => {
  switch (s.keyword) {
    case 'SPHERE': case 'SUPERQUADRIC': return [2];
    case 'BOX': case 'LIGHT': return [1];
    case 'VIEWPOINT': case 'ORIGIN': return [0];
    case 'TRIANGLE': return [1, 4, 7];
    case 'RECTANGLE': return [1, 4, 7, 10];
    case 'BSPLINE': return Array.from({ length: (s.args.length - 6) / 3 }, (_, i) => 6 + 3 * i);
    default: return [];
  }
};


export const FIELDS = {
  SPHERE: ['surface', 'radius', 'x', 'y', 'z'],
  BOX: ['surface', 'x', 'y', 'z', 'half x', 'half y', 'half z'],
  SUPERQUADRIC: ['surface', 'power', 'x', 'y', 'z', 'size x', 'size y', 'size z'],
  LIGHT: ['brightness', 'x', 'y', 'z'],
  SURFACE: ['number', 'ambient r', 'ambient g', 'ambient b', 'diffuse r', 'diffuse g', 'diffuse b', 'specular r', 'specular g', 'specular b', 'coefficient', 'reflection', 'transparency'],
};
export function fieldNames(s) {
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
