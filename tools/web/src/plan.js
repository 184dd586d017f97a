// The Plan view: a scene, a load range and the node's configuration in; the critical
// angle against load and where each state is raised and cleared (the monitor
// example's `--thresholds` table), the contact model section 9 chooses, and the
// scene, configuration and thresholds files tools/commission.py reads.
import uPlot from 'uplot';
import { registers, parseCsv } from './registers.js';
import { Client } from './modbus.js';
import { PageTransport } from './transport.js';
import { Node, Failed } from './commission.js';
import { download, say, messageOf, fillTable, csvRows } from './util.js';

/** The settings shown first; the rest sit under "Every setting". */
const MAIN = ['thresholds_on', 'warning', 'alarm', 'deadband', 'stop_load', 'load_max', 'on_delay', 'off_delay'];
const SCENE = ['R1', 'R2', 'G', 'nu', 'mu', 'length'];

/** A fresh node in the page and the protocol steps over it. */
function pageNode(wasm) {
  const node = new wasm.PageNode(false);
  return { node, steps: new Node(new Client(new PageTransport(node)), wasm) };
}

/** The monitor's configuration registers, by name (the Plan's form and file). */
const MONITOR = new Set(registers.monitorRegisters().map((e) => e.name));

/** The configuration file: the monitor's configuration the node runs (no line or
 * sensor settings, which are each node's own), `name,value`, as `cargo xtask modbus
 * --default-config` writes it. */
export function configFile(configuration) {
  const rows = configuration.filter((c) => MONITOR.has(c.entry.name));
  return `name,value\n${rows.map((c) => `${c.entry.name},${c.active.text}`).join('\n')}\n`;
}

export function setupPlan(wasm) {
  const form = document.getElementById('plan-form');
  const message = document.getElementById('plan-message');
  const result = document.getElementById('plan-result');
  let defaults = new Map();
  let last = null;

  // The configuration's inputs, from the register map, with the node's defaults.
  (async () => {
    const { steps } = pageNode(wasm);
    for (const c of (await steps.configuration()).filter((c) => MONITOR.has(c.entry.name))) {
      defaults.set(c.entry.name, c.staged.text);
      const label = document.createElement('label');
      label.title = c.entry.description;
      label.append(`${c.field}${c.entry.unit ? ` (${c.entry.unit})` : ''} `);
      const input = document.createElement('input');
      input.name = c.entry.name;
      input.value = c.staged.text;
      input.inputMode = c.entry.type === 'f32' ? 'decimal' : 'numeric';
      label.append(input);
      document.getElementById(MAIN.includes(c.field) ? 'plan-config-main' : 'plan-config-more').append(label);
    }
  })().catch((e) => say(message, `the register map: ${messageOf(e)}`, 'error'));

  const sceneText = () => {
    // namedItem: `form.elements.length` is the collection's own count.
    const v = (n) => form.elements.namedItem(n).value.trim();
    const cols = SCENE.filter((n) => n !== 'length' || v('length') !== '');
    return `${cols.join(',')}\n${cols.map(v).join(',')}\n`;
  };

  document.getElementById('plan-scene-file').addEventListener('change', async (e) => {
    const file = e.target.files[0];
    if (!file) return;
    try {
      const text = await file.text();
      const sep = text.split('\n')[0].includes(';') ? ';' : ',';
      const rows = parseCsv(sep === ',' ? text : text.replaceAll(';', ','));
      if (rows.length < 2) throw new Error('a header and one row R1,R2,G,nu,mu[,length]');
      const [header, row] = rows;
      for (const n of SCENE) {
        const i = header.findIndex((h) => h.trim() === n);
        if (i < 0 && n !== 'length') throw new Error(`no column ${n}`);
        form.elements.namedItem(n).value = i < 0 ? '' : row[i].trim();
      }
      say(message, `${file.name}: the scene is in the form; Plan to compute.`, 'ok');
    } catch (err) {
      say(message, `${file.name}: ${messageOf(err)}`, 'error');
    }
  });

  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    result.hidden = true;
    say(message, 'Planning…');
    try {
      const scene = sceneText();
      const model = form.elements.model.value;
      const loadMax = Number(form.elements.load_max.value);
      if (!(loadMax > 0 && Number.isFinite(loadMax))) throw new Error(`highest load ${form.elements.load_max.value}: a load in N above 0`);
      // The scene first: its own message if it is refused.
      wasm.prepareScene(scene, true);
      const changed = registers
        .monitorRegisters()
        .map((e) => [e.name, form.elements.namedItem(e.name)?.value ?? defaults.get(e.name)])
        .filter(([n, v]) => v !== undefined && v.trim() !== defaults.get(n));
      const { node, steps } = pageNode(wasm);
      if (changed.length) {
        try {
          await steps.commission(wasm.defaultCode(), changed);
        } catch (err) {
          if (err instanceof Failed) throw new Error(`the node would refuse this configuration: ${err.message}`);
          throw err;
        }
      }
      const table = node.thresholds(scene, model, loadMax);
      const config = configFile(await steps.configuration());
      last = { scene, config, table };
      show(wasm, scene, model, loadMax, table);
      say(message, `Planned ${csvRows(table).length - 1} loads${changed.length ? `, ${changed.length} settings changed from the defaults` : ''}.`, 'ok');
    } catch (err) {
      say(message, messageOf(err), 'error');
    }
  });

  document.getElementById('plan-download-scene').onclick = () => download('scene.csv', last.scene);
  document.getElementById('plan-download-config').onclick = () => download('config.csv', last.config);
  document.getElementById('plan-download-thresholds').onclick = () => download('thresholds.csv', last.table);

  let chart = null;
  function show(wasm, scene, model, loadMax, table) {
    const rows = csvRows(table);
    const [header, ...data] = rows;
    const contact = wasm.contactModel(scene, loadMax);
    document.getElementById('plan-model').textContent =
      `Section 9 chooses ${contact === 'line' ? 'line contact (section 8)' : 'the contact ellipse (sections 5-7)'} for loads up to ${loadMax} N; core: ${model}.`;
    fillTable(document.getElementById('plan-table'), header.map((h) => (h === 'P' ? 'P (N)' : `${h} (rad)`)), data);
    result.hidden = false;
    const num = (c) => (c === '' ? null : Number(c));
    const cols = header.map((_, k) => data.map((r) => (k === 0 ? num(r[k]) : num(r[k]) === null ? null : num(r[k]) * 1e3)));
    const colours = ['#222', '#c98a00', '#e8c15a', '#c62828', '#ef8a8a'];
    const names = {
      phi0: 'critical angle phi0',
      phi_warning: 'warning raised',
      phi_warning_clear: 'warning cleared',
      phi_alarm: 'alarm raised',
      phi_alarm_clear: 'alarm cleared',
    };
    const el = document.getElementById('plan-chart');
    chart?.destroy();
    chart = new uPlot(
      {
        width: Math.max(320, el.clientWidth || 800),
        height: 320,
        scales: { x: { time: false } },
        axes: [
          { label: 'load P (N)' },
          { label: 'misalignment (mrad)', size: 70 },
        ],
        series: [
          { label: 'P (N)' },
          ...header.slice(1).map((h, i) => ({
            label: `${names[h] ?? h} (mrad)`,
            stroke: colours[i],
            width: i === 0 ? 2.5 : 1.5,
            dash: h.endsWith('_clear') ? [6, 4] : undefined,
          })),
        ],
      },
      cols,
      el,
    );
  }
  window.addEventListener('resize', () => {
    const el = document.getElementById('plan-chart');
    if (chart && el.clientWidth) chart.setSize({ width: el.clientWidth, height: 320 });
  });

  return { sceneText };
}
