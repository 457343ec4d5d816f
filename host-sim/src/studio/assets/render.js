// octrace studio: the full render (on Web Workers, whole or in parallel
// tiles), the display modes it is shown in, and the image files saved from
// it or loaded into its canvas. studio.js makes it with createRender(app).

/** Puts `rgb` (3 bytes a pixel) of a `w` × `h` image on `canvas`. */
export function putRgb(canvas, rgb, w, h) {
  const ctx = canvas.getContext('2d');
  const image = ctx.createImageData(w, h);
  for (let i = 0, j = 0; i < w * h; i++, j += 3) {
    image.data[4 * i] = rgb[j]; image.data[4 * i + 1] = rgb[j + 1]; image.data[4 * i + 2] = rgb[j + 2];
    image.data[4 * i + 3] = 255;
  }
  ctx.putImageData(image, 0, 0);
}

/** The render: `render()` traces the text at the frame shown, `showFrame`
 *  shows a frame time.js's player traced, `saveImage(format)` saves the
 *  last render as the display shows it. */
export function createRender(app) {
  const { state, $, editor, setStatus } = app;
  const imageCanvas = $('image');

  function renderSize() {
    const mode = Number($('display').value);
    if (mode >= 5) {
      const m = /^(\d+)[xX](\d+)$/.exec($('panel-size').value.trim());
      if (m) return [Number(m[1]), Number(m[2])];
    }
    return null; // RASTER
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
    const loaded = app.checkErrors();
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

  return { render, showFrame, saveImage };
}
