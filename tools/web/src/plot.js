// The Review view's plot: four panels over the monitor's time (d/b, the margin, F,
// the load and the angle), each drawn from the replay's bins (plot.rs in the
// WebAssembly) as the lowest and highest value per pixel column of the visible range,
// so that zooming shows detail and a one-sample spike stays visible; the states as
// coloured bands, the events as lines, units on every axis, a legend.
import uPlot from 'uplot';
import { STATE_COLOURS, STATE_NAMES } from './util.js';

const PANELS = [
  { title: 'slip ratio d/b', axis: 'd/b (-)', curves: [[0, 'd/b (-)', '#1f5fa8']] },
  { title: 'margin to the critical angle', axis: 'margin (mrad)', curves: [[1, 'margin phi0 - |phi| (mrad)', '#2e7d32']] },
  { title: 'axial force', axis: 'F (N)', curves: [[2, 'axial force F (N)', '#6a1b9a']] },
  {
    title: 'load and misalignment',
    axis: 'P (kN), phi (mrad)',
    curves: [
      [3, 'load P (kN)', '#444'],
      [4, 'misalignment phi (mrad)', '#c75b00'],
    ],
  },
];

/** `s` seconds as h:mm:ss (tenths below a minute of span). */
function clock(s, fine) {
  const sign = s < 0 ? '-' : '';
  s = Math.abs(s);
  const h = Math.floor(s / 3600);
  const m = Math.floor((s % 3600) / 60);
  const sec = s % 60;
  const ss = fine ? sec.toFixed(1).padStart(4, '0') : String(Math.floor(sec)).padStart(2, '0');
  return `${sign}${h}:${String(m).padStart(2, '0')}:${ss}`;
}

export class TracePlot {
  /** `data`: the worker's plot bins; `events`: the `--events` rows (cells). */
  constructor(container, data, events) {
    this.el = container;
    this.d = data;
    this.n = data.states.length;
    this.end = this.n * data.binS;
    this.events = events
      .map((r) => ({ t: Number(r[0]), kind: r[4], state: r[2] }))
      .filter((e) => Number.isFinite(e.t));
    this.view = [0, Math.max(this.end, data.binS)];
    this.plots = [];
    container.replaceChildren();
    for (const p of PANELS) this.plots.push(this.panel(p));
    this.draw();
  }

  panel(p) {
    const box = document.createElement('div');
    box.className = 'panel';
    box.tabIndex = 0;
    box.setAttribute('role', 'img');
    box.setAttribute('aria-label', `${p.title} against time; + and − zoom, ← and → pan, 0 the whole trace`);
    this.el.append(box);
    box.addEventListener('keydown', (e) => {
      const act = { '+': () => this.zoom(0.5), '=': () => this.zoom(0.5), '-': () => this.zoom(2), ArrowLeft: () => this.pan(-1), ArrowRight: () => this.pan(1), 0: () => this.reset(), Home: () => this.reset() }[e.key];
      if (act) { e.preventDefault(); act(); }
    });
    const self = this;
    const opts = {
      title: p.title,
      width: Math.max(320, this.el.clientWidth || 900),
      height: 170,
      cursor: { sync: { key: 'misalign-review' }, drag: { x: true, y: false, setScale: false } },
      scales: { x: { time: false, range: () => this.view } },
      legend: { live: true },
      axes: [
        {
          label: 't since the first sample (h:mm:ss)',
          values: (u, ticks) => ticks.map((t) => clock(t, this.view[1] - this.view[0] < 120)),
          space: 80,
        },
        { label: p.axis, size: 70 },
      ],
      series: [{ label: 't', value: (u, v) => (v == null ? '-' : clock(v, true)) }, ...p.curves.map(([, label, stroke]) => ({ label, stroke, width: 1.25 }))],
      hooks: {
        drawClear: [(u) => self.bands(u)],
        draw: [(u) => self.marks(u)],
        setSelect: [
          (u) => {
            if (u.select.width > 4) {
              const a = u.posToVal(u.select.left, 'x');
              const b = u.posToVal(u.select.left + u.select.width, 'x');
              self.setView(a, b);
            }
            u.setSelect({ left: 0, width: 0, top: 0, height: 0 }, false);
          },
        ],
      },
    };
    const u = new uPlot(opts, [[0], ...p.curves.map(() => [null])], box);
    u.curves = p.curves.map(([k]) => k);
    // The wheel zooms about the pointer; Shift+drag pans.
    u.over.addEventListener('wheel', (e) => {
      e.preventDefault();
      const at = u.posToVal(e.offsetX, 'x');
      this.zoom(e.deltaY < 0 ? 0.8 : 1.25, at);
    }, { passive: false });
    u.over.addEventListener('mousedown', (e) => {
      if (!e.shiftKey) return;
      e.stopPropagation();
      e.preventDefault();
      const x0 = e.clientX;
      const [a, b] = this.view;
      const per = (b - a) / u.over.clientWidth;
      const move = (m) => this.setView(a - (m.clientX - x0) * per, b - (m.clientX - x0) * per, true);
      const up = () => { window.removeEventListener('mousemove', move); window.removeEventListener('mouseup', up); };
      window.addEventListener('mousemove', move);
      window.addEventListener('mouseup', up);
    }, true);
    return u;
  }

  /** The visible range, kept within the trace (at least a few bins wide). */
  setView(a, b, keepWidth = false) {
    const min = 4 * this.d.binS;
    if (b - a < min) { const c = (a + b) / 2; a = c - min / 2; b = c + min / 2; }
    const w = b - a;
    const total = Math.max(this.end, min);
    if (w >= total) { a = 0; b = total; }
    else if (a < 0) { a = 0; b = keepWidth ? w : b; }
    else if (b > total) { b = total; a = keepWidth ? total - w : a; }
    this.view = [a, b];
    this.draw();
  }

  zoom(factor, at) {
    const [a, b] = this.view;
    const c = at ?? (a + b) / 2;
    this.setView(c - (c - a) * factor, c + (b - c) * factor);
  }

  pan(direction) {
    const [a, b] = this.view;
    const step = (b - a) * 0.5 * direction;
    this.setView(a + step, b + step, true);
  }

  reset() {
    this.setView(0, this.end);
  }

  /** The bins of the view grouped per pixel column: [t, value] pairs (the lowest then
   * the highest) for each of the panel's curves. */
  columns(u) {
    const { binS, low, high } = this.d;
    const [a, b] = this.view;
    const i0 = Math.max(0, Math.floor(a / binS));
    const i1 = Math.min(this.n, Math.ceil(b / binS));
    const width = Math.max(50, Math.round(u.bbox.width / devicePixelRatio) || 800);
    const k = Math.max(1, Math.ceil((i1 - i0) / width));
    const xs = [];
    const ys = u.curves.map(() => []);
    for (let i = i0; i < i1; i += k) {
      const j1 = Math.min(i1, i + k);
      xs.push(i * binS, (i + (j1 - i) / 2) * binS);
      u.curves.forEach((c, m) => {
        let lo = Infinity, hi = -Infinity;
        for (let j = i; j < j1; j++) {
          if (low[c][j] < lo) lo = low[c][j];
          if (high[c][j] > hi) hi = high[c][j];
        }
        if (lo === Infinity) ys[m].push(null, null);
        else ys[m].push(lo, hi);
      });
    }
    return [xs, ...ys];
  }

  draw() {
    for (const u of this.plots) u.setData(this.columns(u), true);
    this.el.dataset.view = this.view.join(',');
  }

  /** The states as bands behind the curves. */
  bands(u) {
    const { ctx } = u;
    const { binS, states } = this.d;
    const [a, b] = this.view;
    const i0 = Math.max(0, Math.floor(a / binS));
    const i1 = Math.min(this.n, Math.ceil(b / binS));
    const k = Math.max(1, Math.ceil((i1 - i0) / Math.max(1, u.bbox.width)));
    ctx.save();
    ctx.globalAlpha = 0.55;
    let run = null;
    const flush = (end) => {
      if (run && run.s !== 255) {
        const x0 = u.valToPos(run.t, 'x', true);
        const x1 = u.valToPos(end, 'x', true);
        ctx.fillStyle = STATE_COLOURS[run.s] ?? '#eee';
        ctx.fillRect(x0, u.bbox.top, Math.max(1, x1 - x0), u.bbox.height);
      }
    };
    for (let i = i0; i < i1; i += k) {
      let s = 255;
      for (let j = i; j < Math.min(i1, i + k); j++) {
        const x = states[j];
        if (x !== 255 && (s === 255 || x > s)) s = x;
      }
      if (!run || run.s !== s) { flush(i * binS); run = { s, t: i * binS }; }
    }
    flush(i1 * binS);
    ctx.restore();
  }

  /** The events as vertical lines: solid for a state change, dashed otherwise. */
  marks(u) {
    const { ctx } = u;
    const [a, b] = this.view;
    ctx.save();
    for (const e of this.events) {
      if (e.t < a || e.t > b) continue;
      const x = Math.round(u.valToPos(e.t, 'x', true)) + 0.5;
      const index = STATE_NAMES.indexOf(e.state);
      ctx.strokeStyle = e.kind === 'state' ? '#333' : '#777';
      ctx.setLineDash(e.kind === 'state' ? [] : [4, 3]);
      ctx.lineWidth = e.kind === 'state' && index >= 3 ? 1.5 : 1;
      ctx.beginPath();
      ctx.moveTo(x, u.bbox.top);
      ctx.lineTo(x, u.bbox.top + u.bbox.height);
      ctx.stroke();
    }
    ctx.restore();
  }

  /** Zooms to show `t` (s) with some context. */
  focus(t) {
    const w = Math.max(60, (this.view[1] - this.view[0]) / 10);
    this.setView(t - w / 2, t + w / 2, true);
  }

  resize() {
    for (const u of this.plots) u.setSize({ width: Math.max(320, this.el.clientWidth), height: 170 });
    this.draw();
  }
}
