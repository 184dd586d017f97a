// The Review view's worker: the monitor's replay of a trace (two passes over the file,
// read in 8 MiB pieces with FileReaderSync, never whole), off the page's thread so
// that the page answers meanwhile. In: {file (a Blob, or null for the built-in
// shift), scene (text or null), model, planner}. Out: progress, then the result.
import init, { review_trace } from '@pkg/misalign_web.js';

const ready = init();

self.onmessage = async ({ data }) => {
  await ready;
  const { file, scene, model, planner } = data;
  const started = performance.now();
  try {
    let read = null;
    if (file) {
      const reader = new FileReaderSync();
      read = (offset, length) => new Uint8Array(reader.readAsArrayBuffer(file.slice(offset, offset + length)));
    }
    const progress = (pass, fraction) => self.postMessage({ type: 'progress', pass, fraction });
    const out = review_trace(read, file ? file.size : 0, scene ?? undefined, model, planner, progress);
    const curves = [0, 1, 2, 3, 4];
    const plot = {
      binS: out.bin_s,
      states: out.states(),
      low: curves.map((k) => out.low(k)),
      high: curves.map((k) => out.high(k)),
    };
    const result = {
      type: 'done',
      events: out.events,
      thresholds: out.thresholds,
      summary: JSON.parse(out.summary),
      seconds: (performance.now() - started) / 1e3,
      plot,
    };
    out.free();
    self.postMessage(result, [plot.states.buffer, ...plot.low.map((a) => a.buffer), ...plot.high.map((a) => a.buffer)]);
  } catch (e) {
    self.postMessage({ type: 'error', message: e instanceof Error ? e.message : String(e) });
  }
};
