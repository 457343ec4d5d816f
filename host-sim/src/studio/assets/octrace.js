// The octrace module (octrace-core compiled to WebAssembly) behind a small
// JavaScript interface: scene text in, parse errors or pixels, palettes and
// image files out. The page and every render worker each load their own.

/** Instantiates the octrace module and wraps its byte-buffer interface. */
export async function loadOctrace() {
  // Beside this script, under the page's token (see studio.js).
  const response = await fetch(new URL('octrace_studio.wasm', import.meta.url));
  const { instance } = await WebAssembly.instantiateStreaming(response, {});
  const x = instance.exports;
  const encoder = new TextEncoder(), decoder = new TextDecoder();
  const put = (bytes) => {
    const at = x.studio_input(bytes.length);
    new Uint8Array(x.memory.buffer, at, bytes.length).set(bytes);
  };
  const output = () => new Uint8Array(x.memory.buffer, x.studio_output_ptr(), x.studio_output_len()).slice();
  const call = (f, ...args) => {
    const failed = f(...args);
    const out = output();
    if (failed) throw new Error(decoder.decode(out));
    return out;
  };
  return {
    /** Frame `frame` (0 for a still) of `text`: {width, height, objects,
     *  frames, rate} (frames 0 for a still) or {errors: ['line:col: message', …]} */
    load(text, frame = 0) {
      put(encoder.encode(text));
      const failed = x.studio_load(frame);
      const out = decoder.decode(output());
      if (failed) return { errors: out.split('\n').filter((l) => l) };
      const [width, height, objects, frames, rate] = out.split(' ').map(Number);
      return { width, height, objects, frames, rate };
    },
    /** The Process menu's code for the core's default mode (host-sim's). */
    defaultAccel: () => x.studio_default_accel(),
    prepare: (accel, w, h) => decoder.decode(call(x.studio_prepare, accel, w, h)),
    render: (x0, y0, w, h) => call(x.studio_render, x0, y0, w, h),
    /** The frame loaded, whole (after `prepare`): {traced, data}, the
     *  pixels traced (fewer for the next frame of an animation) and the
     *  frame as `render` gives it. */
    traceFrame() {
      const out = call(x.studio_trace_frame);
      return { traced: new DataView(out.buffer).getUint32(0, true), data: out.subarray(4) };
    },
    display(render, mode, dither, w, h) { put(render); return call(x.studio_display, mode, dither, w, h); },
    encode(render, mode, dither, format, w, h) { put(render); return call(x.studio_encode, mode, dither, format, w, h); },
    decode(bytes) {
      put(bytes);
      const out = call(x.studio_decode);
      const view = new DataView(out.buffer);
      return { width: view.getUint32(0, true), height: view.getUint32(4, true), rgb: out.subarray(8) };
    },
  };
}
