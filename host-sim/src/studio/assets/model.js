// The scene text as the page sees it: the statements the wireframe draws
// and the tools edit, with where each is in the text. The octrace module
// stays the judge of validity; nothing here touches the page.

// How many arguments follow each keyword (BSPLINE: before its 3 × rows ×
// cols control point coordinates). tests/tests/studio.rs checks this table
// against the core's grammar (octrace_core::parse::statement_arity).
export const ARITY = {
  VIEWPOINT: 3, ORIGIN: 3, UPVECTOR: 3, RASTER: 2, VIEWPORT: 2, RDEPTH: 1, IMAGEFILE: 1, LIGHT: 4,
  BACKGROUND: 3, GAMMA: 1, ATTENUATION: 1, SAMPLES: 1, SPHERE: 5, BOX: 7, SUPERQUADRIC: 8, TRIANGLE: 10,
  RECTANGLE: 13, BSPLINE: 6, SURFACE: 13, FRAMES: 1, MOVE: 4,
};
export const SHAPES = ['SPHERE', 'BOX', 'SUPERQUADRIC', 'TRIANGLE', 'RECTANGLE', 'BSPLINE'];

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
    const args = tokens.slice(i + 1, i + 1 + arity);
    const end = args.length ? args[args.length - 1].end : tokens[i].end;
    statements.push({ keyword, args: args.map((t) => (keyword === 'IMAGEFILE' ? t.text : Number(t.text))), start: tokens[i].start, end });
    i += 1 + arity;
  }
  return statements;
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

/** The arguments of the one statement of a kind in `model`, or `fallback`. */
export function single(model, keyword, fallback) {
  const s = model.find((x) => x.keyword === keyword);
  return s && s.args.length === ARITY[keyword] ? s.args : fallback;
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
