// The wireframe view: an orbiting camera of its own over the scene's
// objects, lights, eye and view frustum where they are at the frame shown
// (`state.frame`), the paths their MOVEs take them on, and the mapping
// between canvas points and the scene that the tools place with.

import { objectCentre, placed, single } from './model.js';

export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const scale = (a, k) => [a[0] * k, a[1] * k, a[2] * k];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => scale(a, 1 / (Math.hypot(...a) || 1));

/** The view over `wire` (a canvas) of `state.model` at frame
 *  `state.frame`, seen by `state.camera`. */
export function createView(state, wire) {
  /** The model's one statement of a kind, where it is at the frame shown. */
  const at = (keyword, fallback) => single(state.model || [], keyword, fallback, state.frame);
  function basis() {
    const { yaw, pitch } = state.camera;
    const forward = [-Math.cos(pitch) * Math.sin(yaw), -Math.sin(pitch), -Math.cos(pitch) * Math.cos(yaw)];
    const right = normalize(cross(forward, [0, 1, 0]));
    const up = cross(right, forward);
    return { forward, right, up };
  }
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
    const model = (state.model || []).map((s) => placed(s, state.frame));
    drawPaths(line);
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

  /** The path each MOVE takes its statement on: the point it moves by
   *  (an object's centre, a light, the eye, the point looked at) through
   *  its keys, between which it moves in straight lines. */
  function drawPaths(line) {
    for (const s of state.model || []) {
      if (!s.moved) continue;
      const from = s.keyword === 'VIEWPOINT' || s.keyword === 'ORIGIN' ? s.args.slice(0, 3) : objectCentre(s);
      if (!from) continue;
      const points = s.moved.keys.map(([, ...d]) => add(from, d));
      for (let i = 0; i + 1 < points.length; i++) line(points[i], points[i + 1], '#ce93d8');
    }
  }

  /** The eye, the line of sight and the view frustum to the VIEWPORT at ORIGIN. */
  function drawEye(ctx, line) {
    const from = at('VIEWPOINT', [0, 0, 10]), to = at('ORIGIN', [0, 0, 0]), upv = at('UPVECTOR', [0, 1, 0]);
    const [rw, rh] = at('RASTER', [320, 240]);
    const forward = sub(to, from);
    const distance = Math.hypot(...forward);
    const f = normalize(forward), right = normalize(cross(f, upv)), up = cross(right, f);
    const viewport = at('VIEWPORT', null);
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

  return { basis, focal, project, onPlane, draw: drawWire };
}
