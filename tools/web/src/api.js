// `window.misalign`: the console's functions for scripts (the browser's console, a
// test): the monitor example's files, the planner, the estimator, scenes for a node.
// Each call runs the library on this page's thread (the Review view runs its replay
// in a worker instead).

const bytes = (x) => {
  if (x === undefined || x === null || x === '') return undefined;
  if (typeof x === 'string') return new TextEncoder().encode(x);
  if (x instanceof Uint8Array) return x;
  if (x instanceof ArrayBuffer) return new Uint8Array(x);
  throw new TypeError('a trace: its text, a Uint8Array or an ArrayBuffer');
};
const text = (x) => (x === undefined || x === null || x === '' ? undefined : String(x));

export function api(wasm) {
  return Object.freeze({
    /** The models: the f32 core, the fixed-point core, the f64 reference. */
    models: Object.freeze(['f32', 'fixed', 'reference']),

    /**
     * The monitor example's `--events` file for a trace (its text; none: the
     * built-in shift) and a scene file's text (none: the demo rollers);
     * `options.model`: "f32" (default), "fixed" or "reference".
     */
    replay(traceText, sceneText, options = {}) {
      return wasm.events(bytes(traceText), text(sceneText), options.model ?? 'f32');
    },

    /**
     * The monitor example's `--thresholds` file for a scene (none: the demo rollers):
     * over the loads of `options.trace` (its text; none: the built-in shift), as
     * `--trace T --plot P --thresholds H` plans; or with `options.loadMax` (N) over
     * loads up to it under the default configuration. `options.model` as in replay.
     */
    thresholds(sceneText, options = {}) {
      const model = options.model ?? 'f32';
      if (options.loadMax !== undefined) return wasm.plan(text(sceneText), model, Number(options.loadMax));
      return wasm.thresholds(bytes(options.trace), text(sceneText), model);
    },

    /**
     * The CSV estimator (`cargo run --example estimate -- ARGS < CSV`): its output
     * text; `options.args` its arguments (e.g. ["--model", "f32"], ["--solve", "mu"]).
     * Throws with its message on a non-zero exit status.
     */
    estimate(csvText, options = {}) {
      const r = wasm.estimate(String(csvText), options.args ?? []);
      if (r.code !== 0) throw new Error(r.err.trim());
      return r.out;
    },

    /** A scene file's scene prepared for a node (`options.core`: "f32", "fixed"), as
     * tools/commission.py prepares it: the bytes for the scene block. */
    prepare(sceneText, options = {}) {
      return wasm.prepareScene(String(sceneText), (options.core ?? 'f32') === 'f32');
    },

    /** Section 9's contact model for a scene over loads up to `loadMax` (N). */
    contactModel(sceneText, loadMax) {
      return wasm.contactModel(text(sceneText), Number(loadMax));
    },
  });
}
