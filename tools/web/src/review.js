// The Review view: a trace (opened or dropped, any size) and the monitor over it in
// a worker, with progress; the interactive plot, the summary, the events table, and
// the events as the monitor example's `--events` file, byte for byte.
import { TracePlot } from './plot.js';
import { download, say, fillTable, csvRows, STATE_COLOURS, STATE_NAMES } from './util.js';

/** Rows of the events table shown (the download holds every one). */
const SHOWN = 2000;

export function setupReview() {
  const form = document.getElementById('review-form');
  const traceInput = document.getElementById('review-trace');
  const sceneInput = document.getElementById('review-scene');
  const model = document.getElementById('review-model');
  const run = document.getElementById('review-run');
  const builtin = document.getElementById('review-builtin');
  const cancel = document.getElementById('review-cancel');
  const bar = document.getElementById('review-progress');
  const barLabel = document.getElementById('review-progress-label');
  const message = document.getElementById('review-message');
  const result = document.getElementById('review-result');
  const drop = document.getElementById('drop');
  let worker = null;
  let dropped = null;
  let plot = null;
  let events = '';

  document.getElementById('review-states').replaceChildren(
    ...STATE_NAMES.map((s, i) => {
      const span = document.createElement('span');
      span.innerHTML = `<i style="background:${STATE_COLOURS[i]}"></i>${s}`;
      return span;
    }),
    Object.assign(document.createElement('span'), { innerHTML: '<b>│</b> state change <b class="dashed">┆</b> approaching, friction' }),
  );

  const busy = (on) => {
    run.disabled = builtin.disabled = on;
    cancel.disabled = !on;
  };

  // One worker, started with the page so that its library is ready; a new one after
  // a cancel.
  const fresh = () => new Worker(new URL('./review-worker.js', import.meta.url), { type: 'module' });
  worker = fresh();

  function start(file, name) {
    result.hidden = true;
    busy(true);
    bar.value = 0;
    barLabel.textContent = 'Starting…';
    say(message, `Replaying ${name}…`);
    const sceneFile = sceneInput.files[0];
    const began = performance.now();
    const go = async () => {
      const scene = sceneFile ? await sceneFile.text() : null;
      worker.postMessage({ file, scene, model: model.value, planner: false });
    };
    worker.onmessage = ({ data }) => {
      if (data.type !== 'progress') document.body.dataset.replayEnded = String(performance.now());
      if (data.type === 'progress') {
        bar.value = data.pass === 1 ? data.fraction * 0.3 : 0.3 + 0.7 * data.fraction;
        barLabel.textContent = data.pass === 1 ? `Reading the trace ${Math.round(100 * data.fraction)} %` : `Replaying ${Math.round(100 * data.fraction)} %`;
        return;
      }
      busy(false);
      if (data.type === 'error') {
        // The library's state after a failure is not trusted: a fresh worker.
        worker.terminate();
        worker = fresh();
        bar.value = 0;
        barLabel.textContent = 'Stopped';
        say(message, `${name}: ${data.message}`, 'error');
        return;
      }
      bar.value = 1;
      const rate = data.summary.samples / data.seconds;
      barLabel.textContent = `Done: ${data.summary.samples} samples in ${data.seconds.toFixed(2)} s`;
      document.body.dataset.replayRate = String(rate);
      show(data, name);
      say(message, `${name}: ${data.summary.samples} samples, ${csvRows(data.events).length - 1} events (${Math.round(rate).toLocaleString('en')} samples a second; ${((performance.now() - began) / 1e3).toFixed(2)} s in all).`, 'ok');
    };
    worker.onerror = (e) => {
      busy(false);
      worker.terminate();
      worker = fresh();
      say(message, `${name}: the worker stopped (${e.message})`, 'error');
    };
    go();
  }

  function show(data, name) {
    events = data.events;
    const s = data.summary;
    const dl = document.getElementById('review-summary');
    const item = (k, v) => {
      const dt = document.createElement('dt');
      dt.textContent = k;
      const dd = document.createElement('dd');
      dd.textContent = v;
      dl.append(dt, dd);
    };
    dl.replaceChildren();
    item('trace', name);
    item('samples', s.samples.toLocaleString('en'));
    item('final state', s.final_state);
    for (const st of s.states) item(`time ${st.state}`, `${(st.time_s / 3600).toFixed(2)} h, ${st.energy_J.toFixed(1)} J`);
    const faults = Object.entries(s.faults).filter(([, n]) => n > 0).map(([k, n]) => `${k} ${n}`).join(', ');
    item('faults', faults || 'none');
    item('max d/b', s.max_slip_ratio.toFixed(3));
    item('max |F|', `${s.max_axial_force_N.toFixed(1)} N`);
    item('min margin', s.min_margin_rad === null ? '-' : `${(s.min_margin_rad * 1e3).toFixed(3)} mrad`);
    if (s.friction !== null) item('friction mu', `${s.friction.toFixed(4)} (baseline ${s.friction_baseline === null ? '-' : s.friction_baseline.toFixed(4)})`);
    item('time to critical', s.time_to_critical_s === null ? '-' : `${(s.time_to_critical_s / 60).toFixed(0)} min`);
    if (s.skipped !== undefined) {
      item('rows skipped (no usable time)', s.skipped);
      item('rows with a cell not a number (sensor faults)', s.unreadable);
    }
    result.hidden = false;
    const rows = csvRows(events);
    const [header, ...body] = rows;
    plot = new TracePlot(document.getElementById('review-plots'), data.plot, body);
    const tbody = fillTable(document.getElementById('review-events'), header, body, SHOWN);
    [...tbody.rows].forEach((tr, i) => {
      const state = STATE_NAMES.indexOf(body[i][2]);
      if (state >= 0) tr.style.background = STATE_COLOURS[state];
      tr.tabIndex = 0;
      tr.title = 'Enter or click: show it on the plot';
      const focus = () => plot.focus(Number(body[i][0]));
      tr.addEventListener('click', focus);
      tr.addEventListener('keydown', (e) => { if (e.key === 'Enter') focus(); });
    });
    if (body.length > SHOWN) {
      const caption = document.querySelector('#review-events caption');
      caption.textContent = `Events: the first ${SHOWN} of ${body.length} (the download holds every one)`;
    }
  }

  form.addEventListener('submit', (e) => {
    e.preventDefault();
    const file = dropped ?? traceInput.files[0];
    if (!file) {
      say(message, 'Choose or drop a trace file first (or replay the built-in shift).', 'error');
      traceInput.focus();
      return;
    }
    start(file, file.name);
  });
  traceInput.addEventListener('change', () => { dropped = null; });
  builtin.addEventListener('click', () => start(null, 'the built-in shift'));
  cancel.addEventListener('click', () => {
    worker.terminate();
    worker = fresh();
    busy(false);
    barLabel.textContent = 'Cancelled';
    say(message, 'Cancelled.', '');
  });
  for (const [ev, on] of [['dragover', true], ['dragenter', true], ['dragleave', false]]) {
    drop.addEventListener(ev, (e) => { e.preventDefault(); drop.classList.toggle('over', on); });
  }
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    const file = e.dataTransfer.files[0];
    if (file) { dropped = file; start(file, file.name); }
  });
  document.querySelector('.plot-toolbar').addEventListener('click', (e) => {
    const b = e.target.closest('button');
    if (!b || !plot) return;
    if (b.dataset.zoom === 'in') plot.zoom(0.5);
    else if (b.dataset.zoom === 'out') plot.zoom(2);
    else if (b.dataset.zoom === 'reset') plot.reset();
    else if (b.dataset.pan) plot.pan(Number(b.dataset.pan));
  });
  document.getElementById('review-download').addEventListener('click', () => download('events.csv', events));
  window.addEventListener('resize', () => plot?.resize());
}
