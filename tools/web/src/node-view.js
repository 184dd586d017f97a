// The Node view: a node reached over Web Serial, a WebSocket or in the page; its live
// status and values, the event window with acknowledgement, the alarms'
// acknowledgement, and commissioning (unlock, staged configuration, scene upload,
// commit, revert, lock) by the same steps as tools/commission.py.
import { Client, Silent } from './modbus.js';
import { SerialTransport, WebSocketTransport, PageTransport } from './transport.js';
import { Node, Failed, SWITCHES, registerName } from './commission.js';
import { registers } from './registers.js';
import { say, messageOf, fillTable, csvRows, STATE_COLOURS, STATE_NAMES } from './util.js';

/** The values shown live, and the counters, by their input register names. */
const VALUES = ['slip_ratio', 'axial_force', 'critical_angle', 'margin', 'load', 'misalignment', 'time_to_critical', 'friction'];
const COUNTERS = ['samples', 'events_dropped', 'event_seq_next', 'spikes', 'faults_non_finite', 'faults_out_of_range', 'faults_stuck', 'faults_gap', 'max_slip_ratio', 'min_margin'];
const COMMISSIONING = ['config_source', 'scene_active_crc', 'unlock', 'lockout', 'unlock_failures', 'staged', 'map_version', 'unit_id'];

export function setupNode(wasm, plan) {
  const $ = (id) => document.getElementById(id);
  const message = $('node-message');
  const live = $('node-live');
  const kind = $('node-transport');
  let transport = null;
  let steps = null;
  let timer = null;

  const showFor = () => {
    for (const el of document.querySelectorAll('#node-connect [data-for]')) el.hidden = el.dataset.for !== kind.value;
  };
  kind.addEventListener('change', showFor);
  showFor();

  /** Runs a step with its outcome in the message line; the error's text on failure. */
  async function step(what, fn) {
    say(message, `${what}…`);
    try {
      const done = await fn();
      if (done) say(message, done, 'ok');
      return true;
    } catch (e) {
      const text = messageOf(e);
      say(message, e instanceof Silent || e instanceof Failed ? text : `${what}: ${text}`, 'error');
      return false;
    }
  }

  $('node-connect').addEventListener('submit', (e) => {
    e.preventDefault();
    step('Connecting', async () => {
      await disconnect();
      const unit = Number($('node-unit').value);
      if (kind.value === 'serial') transport = new SerialTransport(Number($('node-baud').value), $('node-parity').value);
      else if (kind.value === 'websocket') transport = new WebSocketTransport($('node-url').value.trim());
      else transport = new PageTransport(new wasm.PageNode(true));
      const client = new Client(transport, { unit, timeoutMs: 1000 });
      await transport.open();
      steps = new Node(client, wasm);
      try {
        await readStatus();
      } catch (err) {
        await disconnect();
        throw err;
      }
      live.hidden = false;
      $('node-disconnect').disabled = false;
      await readConfig();
      await readEvents(null);
      return `Connected through ${transport.name}, unit ${unit}.`;
    });
  });

  async function disconnect() {
    clearInterval(timer);
    timer = null;
    $('node-poll').checked = false;
    const t = transport;
    transport = null;
    steps = null;
    live.hidden = true;
    $('node-disconnect').disabled = true;
    await t?.close();
  }
  $('node-disconnect').addEventListener('click', () => step('Disconnecting', async () => { await disconnect(); return 'Disconnected.'; }));

  async function readStatus() {
    const s = await steps.status();
    const box = $('node-status');
    box.replaceChildren();
    const state = document.createElement('p');
    state.className = 'state';
    state.dataset.state = s.state;
    state.style.background = STATE_COLOURS[STATE_NAMES.indexOf(s.state.replace(' ', '_'))] ?? '#eee';
    state.textContent = `${s.state} · NE 107: ${s.ne107} · unacknowledged: ${s.unacknowledged.join(', ') || 'none'}`;
    box.append(state);
    const list = (title, names, table) => {
      const section = document.createElement('div');
      const h = document.createElement('h3');
      h.textContent = title;
      const dl = document.createElement('dl');
      for (const name of names) {
        const e = registers.entry(name, table);
        const d = (table === 'input' ? s.input : s.holding).get(name);
        const dt = document.createElement('dt');
        dt.textContent = name;
        dt.title = e.description;
        const dd = document.createElement('dd');
        dd.dataset.register = name;
        const hex = name.endsWith('_crc') ? `0x${d.value.toString(16).padStart(8, '0')}` : d.text;
        dd.textContent = `${hex}${e.unit && d.text !== '-' ? ` ${e.unit}` : ''}`;
        dl.append(dt, dd);
      }
      section.append(h, dl);
      box.append(section);
    };
    list('Values', VALUES, 'input');
    list('Counters', COUNTERS, 'input');
    list('Commissioning', COMMISSIONING, 'holding');
    return s;
  }

  async function readConfig() {
    const config = await steps.configuration();
    const rows = config.map((c) => {
      const input = document.createElement('input');
      input.name = c.entry.name;
      input.setAttribute('aria-label', `stage ${c.field}`);
      input.inputMode = c.entry.type === 'f32' ? 'decimal' : 'numeric';
      return [c.field, c.entry.unit, c.active.text, c.staged.text, input];
    });
    for (const name of SWITCHES) {
      const input = document.createElement('input');
      input.name = name;
      input.setAttribute('aria-label', `switch ${name}`);
      input.inputMode = 'numeric';
      const now = (await steps.read(name))[0];
      rows.push([`${name} (switch)`, '', String(now), String(now), input]);
    }
    const body = fillTable($('node-config'), ['setting', 'unit', 'active', 'staged', 'stage'], rows);
    [...body.rows].forEach((tr, i) => { if (rows[i][2] !== rows[i][3]) tr.classList.add('staged'); });
  }

  async function readEvents(from) {
    const rows = (await steps.heldEvents(from)).filter((r) => r !== '');
    const header = csvRows('t,seq,state,from,kind,fault,P,phi,s,F,phi0,margin,time_to_critical,time_ms')[0];
    const cells = rows.map((r) => {
      const c = r.split(',');
      const b = document.createElement('button');
      b.type = 'button';
      b.textContent = `Acknowledge through #${c[1]}`;
      b.addEventListener('click', () => step(`Acknowledging events through ${c[1]}`, async () => {
        await steps.acknowledgeEvents(Number(c[1]));
        await readEvents(null);
        return `Events through #${c[1]} acknowledged: the node frees them and shows the later ones.`;
      }));
      return [...c, b];
    });
    fillTable($('node-events-table'), [...header, ''], cells);
    $('node-events-table').querySelector('caption').textContent = `Events the node holds (${rows.length})`;
    return rows;
  }

  $('node-read').addEventListener('click', () => step('Reading the status', async () => { const s = await readStatus(); return `State ${s.state}.`; }));
  $('node-poll').addEventListener('change', (e) => {
    clearInterval(timer);
    timer = e.target.checked ? setInterval(() => readStatus().catch((err) => say(message, messageOf(err), 'error')), 1000) : null;
  });
  $('node-ack-alarms').addEventListener('click', () => step('Acknowledging the alarms', async () => {
    await steps.acknowledgeAlarms(0xf);
    const s = await readStatus();
    return `Alarms acknowledged; unacknowledged now: ${s.unacknowledged.join(', ') || 'none'}.`;
  }));
  $('node-events').addEventListener('click', () => step('Reading the events', async () => `${(await readEvents(null)).length} events in the window.`));
  $('node-events-all').addEventListener('click', () => step('Reading the events', async () => `${(await readEvents(0)).length} events held from #0.`));

  /** The values typed into the "stage" column: [register, value]. */
  const settings = () =>
    [...document.querySelectorAll('#node-config input')]
      .filter((i) => i.value.trim() !== '')
      .map((i) => [registerName(i.name), i.value.trim()]);

  /** The scene to upload: prepared for the node's core (by `scene_bytes`) from a
   * scene file or the Plan view's scene, or a prepared file as it is; null: none. */
  async function scene() {
    const file = $('node-scene').files[0];
    let text = null;
    if ($('node-scene-plan').checked) text = plan.sceneText();
    else if (file && !file.name.endsWith('.bin')) text = await file.text();
    else if (file) return new Uint8Array(await file.arrayBuffer());
    else return null;
    const want = (await steps.read('scene_bytes'))[0];
    if (want === 0) throw new Failed('this node takes no scene over the bus');
    for (const fpu of [true, false]) {
      const bytes = wasm.prepareScene(text, fpu);
      if (bytes.length === want) return bytes;
    }
    throw new Failed(`the node takes ${want} bytes of prepared scene, which neither core's scene has`);
  }

  const code = () => $('node-code').value.trim();
  $('node-commissioning').addEventListener('submit', (e) => e.preventDefault());
  const after = async () => { await readStatus(); await readConfig(); };

  $('node-commission').addEventListener('click', () => step('Commissioning', async () => {
    if (code() === '') throw new Failed('the site code is needed to write');
    const s = settings();
    const sc = await scene();
    if (!s.length && !sc) throw new Failed('nothing to write: stage a value or choose a scene');
    try {
      const source = await steps.commission(code(), s, sc);
      return `Commissioned: ${s.length} registers${sc ? ' and the scene' : ''} committed and read back; config_source ${source}.`;
    } finally {
      await after().catch(() => {});
    }
  }));
  $('node-unlock').addEventListener('click', () => step('Unlocking', async () => {
    try {
      await steps.unlock(code());
      return `Unlocked for ${(await steps.read('unlock'))[0]} s.`;
    } finally {
      await readStatus().catch(() => {});
    }
  }));
  $('node-stage').addEventListener('click', () => step('Staging', async () => {
    const s = steps.checked(settings());
    const sc = await scene();
    await steps.stage(s, sc);
    await after();
    return `Staged ${s.length} values${sc ? ' and the scene' : ''}; commit to apply them.`;
  }));
  $('node-commit').addEventListener('click', () => step('Committing', async () => {
    try {
      await steps.commit();
      return 'Committed: the node runs the staged copy.';
    } finally {
      await after().catch(() => {});
    }
  }));
  $('node-revert').addEventListener('click', () => step('Reverting', async () => {
    const x = await steps.command(2);
    if (x !== null) throw new Failed(x === 1 ? 'revert refused: locked (unlock first)' : `revert: exception ${x}`);
    await after();
    return 'Reverted: the staged copy is the active one again.';
  }));
  $('node-lock').addEventListener('click', () => step('Locking', async () => {
    const x = await steps.command(3);
    if (x !== null) throw new Failed(x === 1 ? 'already locked' : `lock: exception ${x}`);
    await readStatus();
    return 'Locked.';
  }));
}
