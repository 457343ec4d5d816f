// "Send to board": the studio's server sends the text to the board it was
// started with (--board PORT), as host-sim board --check does, and answers
// with the board's errors, listed with the page's own at their line and
// column, or its picture, shown beside the render with its verdict.

/** Wires the Send button of the page `app` (studio.js). The figure
 *  `#board` says where a send is in `data-state` (sending, done, rejected,
 *  error); its verdict, `#board-verdict`, in `data-verdict` (identical,
 *  differ, errors, error). */
export function createBoard(app) {
  const { $, editor, api, showBoardErrors, putRgb, setStatus } = app;
  const button = $('send-board'), figure = $('board'), verdict = $('board-verdict'), canvas = $('board-image');
  let port = null, sending = false;

  /** Asks the server for its board; without one the button stays disabled
   *  and its title says why. */
  async function connect() {
    const response = await api('/board');
    if (!response.ok) return;
    port = (await response.json()).port;
    if (port === null) return;
    button.disabled = false;
    button.title = `Send the scene to the board at ${port} (Ctrl+Shift+Enter)`;
  }

  function show(state, kind, message) {
    figure.hidden = false;
    figure.dataset.state = state;
    verdict.dataset.verdict = kind;
    verdict.textContent = message;
  }

  async function send() {
    if (!port || sending) return;
    sending = true;
    button.disabled = true;
    show('sending', '', `sending to ${port}…`);
    // The rows as they arrive (the answer comes when the board is done),
    // and the board's word that it is still working on a slow stretch: the
    // server waits as long as the board keeps drawing or says so, and
    // gives it up when it falls silent, as host-sim board does.
    const poll = setInterval(() => {
      api('/board').then((response) => (response.ok ? response.json() : {})).then((progress) => {
        if (!sending || !progress.height) return;
        const working = typeof progress.working === 'number'
          ? ` (still working: ${progress.working.toFixed(1)} s by its clock)` : '';
        verdict.textContent = `drawing: ${progress.rows} of ${progress.height} rows${working}`;
      }).catch(() => {});
    }, 250);
    try {
      const response = await api('/board', { method: 'POST', body: editor.text() });
      if (!response.ok) {
        const message = (await response.text()).trim();
        show('error', 'error', message);
        setStatus('board: ' + message);
        return;
      }
      const answer = await response.json();
      if (answer.answer === 'rejected') rejected(answer.errors); else drawn(answer);
    } catch (e) {
      show('error', 'error', String(e.message || e));
    } finally {
      clearInterval(poll);
      sending = false;
      button.disabled = false;
    }
  }

  /** The board's errors join the page's, listed and marked in the text
   *  (an error the page found too is listed once, as the board's); the
   *  cursor goes to the first. */
  function rejected(errors) {
    canvas.width = 0;
    canvas.height = 0;
    showBoardErrors(errors, `found by the board at ${port}`);
    const message = `the board found ${errors.length} error${errors.length === 1 ? '' : 's'}: nothing drawn`;
    show('rejected', 'errors', message);
    setStatus(message);
    const first = errors.find((e) => e.line);
    if (first) editor.goTo(first.line, first.column);
  }

  function drawn(answer) {
    const { width, height } = answer;
    const rgb = Uint8Array.from(atob(answer.rgb), (c) => c.charCodeAt(0));
    canvas.width = width;
    canvas.height = height;
    putRgb(canvas, rgb, width, height);
    const clock = answer.clock === 'board' ? 'by its clock' : 'here';
    const how = `${width}×${height} ${answer.format} in ${answer.seconds.toFixed(2)} s ${clock}`;
    if (answer.differ === null) show('done', 'error', `not compared: ${answer.problem}`);
    else if (answer.differ === 0) show('done', 'identical', 'identical');
    else show('done', 'differ', `${answer.differ} pixel${answer.differ === 1 ? ' differs' : 's differ'}`);
    verdict.title = `against host-sim's ${answer.format} render at ${width}×${height}`;
    setStatus(`the board drew ${how}: ${verdict.textContent}`);
  }

  button.onclick = send;
  return { connect, send };
}
