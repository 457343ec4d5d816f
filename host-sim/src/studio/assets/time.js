// The time controls of an animation (a scene with FRAMES): the frame shown,
// which the wireframe, the errors, the draft and the render follow (a
// slider), and play, every frame in turn at the animation's rate at most. A
// still scene hides them.
//
// Two workers are the players: the draft's (studio.js's `sendDraft`, which
// also draws the text's drafts) and the render's when one is shown. Each
// keeps its last frame and the core's coherence, so the next frame forward
// re-traces only what moved, and a frame is the frame traced whole, bit for
// bit (host-sim --frame K). A frame asked for while another is traced stops
// that one at once (its worker terminated, a spare takes over, tracing the
// next frame whole): no frame runs on after a newer one is asked for.

const DRAFT = [160, 120];

/** The time controls of the page `app` (studio.js). They set `state.frame`
 *  and `state.playing`; `state.played` holds, for each frame played since
 *  play began, its number, when it was shown (ms), the milliseconds from
 *  asking for it to its draft and render shown, and the share of the
 *  draft's pixels traced (%). */
export function createTime(app) {
  const { state, $ } = app;
  const box = $('time'), slider = $('frame'), button = $('play'), label = $('frame-label');
  let frames = null; // {count, rate}, or null for a still
  /** Playing: the timer of the next frame, and when it is due (on a clock
   *  of its own, so that the rate holds; a late frame moves it on). */
  let timer = 0, due = 0;
  /** The number of the last frame asked for: an answer to an earlier one
   *  is not shown. */
  let asked = 0;
  const renderPlayer = app.workerPair();

  /** Frame `frame` of the text at `width`×`height`, traced by `send` (a
   *  worker pair's). */
  function trace(send, frame, [width, height]) {
    return new Promise((resolve, reject) => {
      send({ type: 'frame', text: app.editor.text(), frame, width, height }, (m) => {
        if (m.type === 'frame') resolve(m); else reject(new Error(m.message));
        return true;
      });
    });
  }

  function showLabel() {
    label.textContent = frames ? `frame ${state.frame} / ${frames.count - 1} · ${frames.rate} fps` : '';
  }

  /** The text, loaded at the frame shown (octrace.load's answer): shows the
   *  controls for an animation, hides them for a still; a scene with errors
   *  leaves them as they were. */
  function scene(loaded) {
    if (loaded.errors) return;
    frames = loaded.frames ? { count: loaded.frames, rate: loaded.rate } : null;
    box.hidden = !frames;
    if (!frames) {
      stop();
      state.frame = 0;
      return;
    }
    slider.max = String(frames.count - 1);
    // FRAMES made fewer: the last frame (as the loader read it already).
    state.frame = Math.min(state.frame, frames.count - 1);
    slider.value = String(state.frame);
    showLabel();
  }

  /** Shows frame `frame`: its wireframe and errors at once, then its draft
   *  and, if one is shown, its render, once traced; then, playing, the next
   *  when its time comes. A frame with errors stops there. */
  async function go(frame) {
    const mine = ++asked;
    state.frame = frame;
    slider.value = String(frame);
    showLabel();
    if (app.frameChanged().errors) {
      stop();
      renderPlayer.stop();
      $('draft-status').textContent = `frame ${frame} has errors`;
      return;
    }
    const started = performance.now(), playing = state.playing;
    const render = state.lastRender;
    app.draftDrawn();
    if (!render) renderPlayer.stop();
    try {
      const [draft, image] = await Promise.all([
        trace(app.sendDraft, frame, DRAFT),
        render ? trace(renderPlayer.send, frame, [render.width, render.height]) : null,
      ]);
      // A newer frame was asked for (then this one was stopped, and does not
      // come here) or only its render was still traced.
      if (mine !== asked) return;
      const ms = performance.now() - started;
      const canvas = $('draft');
      canvas.width = draft.width; canvas.height = draft.height;
      app.putRgb(canvas, draft.data, draft.width, draft.height);
      Object.assign(canvas.dataset, { state: 'done', frame: String(frame) });
      const share = (100 * draft.traced) / (draft.width * draft.height);
      $('draft-status').textContent = `frame ${frame}: ${share.toFixed(0)} % of the pixels traced, ${ms.toFixed(0)} ms`;
      if (image) {
        app.showFrame(frame, image.width, image.height, image.data);
        const imageShare = (100 * image.traced) / (image.width * image.height);
        app.setStatus(`frame ${frame}: ${image.width}×${image.height}, ${imageShare.toFixed(0)} % of the pixels traced`);
      }
      if (playing) state.played.push({ frame, at: performance.now(), ms, share });
      if (state.playing) {
        const now = performance.now();
        due = Math.max(due + 1000 / frames.rate, now);
        timer = setTimeout(() => go((frame + 1) % frames.count), due - now);
      }
    } catch (e) {
      if (mine !== asked) return;
      stop();
      $('draft-status').textContent = `frame ${frame}: ${e.message}`;
    }
  }

  function play() {
    if (!frames || state.playing) return;
    state.playing = true;
    state.played = [];
    due = performance.now();
    button.textContent = '❚❚';
    button.title = 'Pause (Space)';
    go((state.frame + 1) % frames.count);
  }

  /** Stops playing: the frame being traced is the last shown. */
  function stop() {
    if (!state.playing) return;
    state.playing = false;
    clearTimeout(timer);
    button.textContent = '▶';
    button.title = 'Play (Space)';
  }

  /** The text changed while paused, or a render was asked for: the frame
   *  being traced, if any, is not shown (the text's draft takes the draft's
   *  worker over; a render its canvas). */
  function superseded() {
    stop();
    asked += 1;
    renderPlayer.stop();
  }

  const toggle = () => (state.playing ? stop() : play());
  button.onclick = toggle;
  slider.addEventListener('input', () => { stop(); go(Number(slider.value)); });
  return { scene, stop, toggle, superseded };
}
