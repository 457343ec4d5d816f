// octrace studio: a worker for requests of which only the newest matters.
// The draft and time.js's players each hold one; studio.js makes them.

/** A worker for requests of which only the newest matters, and a spare
 *  already loading: a request still running when the next is sent is
 *  stopped at once (its worker terminated, the spare takes over), so a
 *  scene of hours a pixel never holds the next up. `send(message,
 *  answer)` hands the worker's messages to `answer` till it returns true
 *  (the request is finished); `stop()` ends the request running, if any.
 *  A worker that finished keeps its state: time.js's players keep the
 *  frame they traced last. */
export function workerPair() {
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
