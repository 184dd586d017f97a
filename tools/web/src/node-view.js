// The Node view: a node reached over Web Serial, a WebSocket or in the page; its live
// status and values, the event window with acknowledgement, the alarms'
// acknowledgement, and commissioning (unlock, staged configuration, scene upload,
// commit, revert, lock) by the same steps as tools/commission.py.
import { Client, Silent } from './modbus.js';
import { SerialTransport, WebSocketTransport, PageTransport } from './transport.js';
import { Node, Failed, SWITCHES, registerName, scan } from './commission.js';
import { registers } from './registers.js';
import { say, messageOf, fillTable, csvRows, STATE_COLOURS, STATE_NAMES } from './util.js';

/** The values shown live, and the counters, by their input register names. */
const VALUES = ['slip_ratio', 'axial_force', 'critical_angle', 'margin', 'load', 'misalignment', 'time_to_critical', 'friction'];
const COUNTERS = ['samples', 'events_dropped', 'event_seq_next', 'spikes', 'faults_non_finite', 'faults_out_of_range', 'faults_stuck', 'faults_gap', 'max_slip_ratio', 'min_margin'];
const COMMISSIONING = ['config_source', 'scene_active_crc', 'unlock', 'lockout', 'unlock_failures', 'staged', 'map_version', 'unit_id'];
/** The line settings in force and their supervision: [name, table]. */
const LINE = [
  ['active_unit_id', 'holding'], ['active_baud', 'holding'], ['active_parity', 'holding'],
  ['active_answer_delay', 'holding'], ['active_bus_timeout', 'holding'], ['line_confirm_window', 'holding'],
  ['line_status', 'input'], ['line_confirm_left', 'input'], ['line_reverts', 'input'],
];
/** A value's words in words a technician reads, where the number alone says little. */
const SPELLED = {
  active_parity: (v) => ['none, 8N2', 'odd, 8O1', 'even, 8E1'][v],
  line_status: (v) => [v & 1 ? 'master lost' : '', v & 2 ? 'a change waits for its confirmation' : ''].filter(Boolean).join(', ') || 'in order',
};

/** Unit ids as a person writes them: `1-247`, `1,5,7`, `3`. */
export function unitIds(text) {
  const units = [];
  for (const part of text.split(',')) {
    const m = /^\s*(\d+)\s*(?:-\s*(\d+)\s*)?$/.exec(part);
    const [a, b] = m ? [Number(m[1]), Number(m[2] ?? m[1])] : [NaN, NaN];
    if (!(a >= 1 && b <= 247 && a <= b)) throw new Failed(`unit ids ${text.trim()}: a range (1-247) or a list (1,5,7) of ids from 1 to 247`);
    for (let u = a; u <= b; u++) units.push(u);
  }
  return units;
}

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

  /** A client on a new transport as the connection form says (the old one closed). */
  async function open(unit) {
    await disconnect();
    const t = kind.value === 'serial'
      ? new SerialTransport(Number($('node-baud').value), $('node-parity').value)
      : kind.value === 'websocket' ? new WebSocketTransport($('node-url').value.trim()) : new PageTransport(new wasm.PageNode(true));
    const client = new Client(t, { unit, timeoutMs: 1000 });
    await t.open();
    transport = t;
    $('node-disconnect').disabled = false;
    return client;
  }

  /** The node at `client`'s unit id: its status, configuration and events shown. */
  async function attach(client) {
    steps = new Node(client, wasm);
    try {
      await readStatus();
    } catch (err) {
      await disconnect();
      throw err;
    }
    live.hidden = false;
    await readConfig();
    await readEvents(null);
    return `Connected through ${transport.name}, unit ${client.unit}.`;
  }

  $('node-connect').addEventListener('submit', (e) => {
    e.preventDefault();
    step('Connecting', async () => attach(await open(Number($('node-unit').value))));
  });

  /** The connection form shows where the node answers after a commit moved it. */
  function moved(to) {
    if (!to) return '';
    $('node-unit').value = String(to.unit);
    if (transport instanceof SerialTransport) {
      $('node-baud').value = String(to.baud);
      $('node-parity').value = to.parity;
    }
    return ` The node answers at unit ${to.unit}, ${to.baud} baud, parity ${to.parity} now, confirmed (the connection follows it).`;
  }

  let scanning = null;
  $('node-scan-form').addEventListener('submit', (e) => {
    e.preventDefault();
    const list = $('node-scan-found');
    step('Finding nodes', async () => {
      const units = unitIds($('node-scan-units').value);
      const wait = Number($('node-scan-timeout').value);
      if (!(Number.isInteger(wait) && wait >= 10 && wait <= 5000)) throw new Failed(`wait ${$('node-scan-timeout').value}: whole ms from 10 to 5000`);
      list.replaceChildren();
      clearInterval(timer);
      $('node-poll').checked = false;
      const client = steps?.c ?? (await open(1));
      const stop = { stopped: false };
      scanning = stop;
      $('node-scan').disabled = true;
      $('node-scan-stop').disabled = false;
      let result;
      try {
        result = await scan(client, wasm, units, wait, (u) => {
          if (stop.stopped) throw new Failed(`stopped at unit ${u}`);
          say(message, `Finding nodes: unit ${u} of ${units.at(-1)}…`);
        });
      } finally {
        scanning = null;
        $('node-scan').disabled = false;
        $('node-scan-stop').disabled = true;
      }
      for (const f of result.found) {
        const li = document.createElement('li');
        const text = document.createElement('span');
        text.textContent = f.text;
        const b = document.createElement('button');
        b.type = 'button';
        b.textContent = `Connect to unit ${f.unit}`;
        b.addEventListener('click', () => step('Connecting', async () => {
          $('node-unit').value = String(f.unit);
          client.unit = f.unit;
          return attach(client);
        }));
        li.append(text, b);
        list.append(li);
      }
      for (const c of result.clashes) {
        const li = document.createElement('li');
        li.className = 'clash';
        li.textContent = c;
        list.append(li);
      }
      const n = result.found.length;
      const text = `${n} node${n === 1 ? '' : 's'} found among ${units.length} unit ids${result.clashes.length ? `, ${result.clashes.length} clash${result.clashes.length === 1 ? '' : 'es'}` : ''}.`;
      if (result.clashes.length) throw new Failed(`${text} ${result.clashes.join('; ')}`);
      return text;
    });
  });
  $('node-scan-stop').addEventListener('click', () => { if (scanning) scanning.stopped = true; });

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
      for (const item of names) {
        const [name, t] = table ? [item, table] : item;
        const e = registers.entry(name, t);
        const d = (t === 'input' ? s.input : s.holding).get(name);
        const dt = document.createElement('dt');
        dt.textContent = name;
        dt.title = e.description;
        const dd = document.createElement('dd');
        dd.dataset.register = name;
        const hex = name.endsWith('_crc') ? `0x${d.value.toString(16).padStart(8, '0')}` : d.text;
        const spelled = SPELLED[name]?.(d.value);
        dd.textContent = `${hex}${e.unit && d.text !== '-' ? ` ${e.unit}` : ''}${spelled ? ` (${spelled})` : ''}`;
        dl.append(dt, dd);
      }
      section.append(h, dl);
      box.append(section);
    };
    list('Values', VALUES, 'input');
    list('Counters', COUNTERS, 'input');
    list('Commissioning', COMMISSIONING, 'holding');
    list('Line', LINE.filter(([n, t]) => (t === 'input' ? s.input : s.holding).has(n)), null);
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
      const { source, moved: to } = await steps.commission(code(), s, sc);
      return `Commissioned: ${s.length} registers${sc ? ' and the scene' : ''} committed and read back; config_source ${source}.${moved(to)}`;
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
      const to = await steps.commit();
      return `Committed: the node runs the staged copy.${moved(to)}`;
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
