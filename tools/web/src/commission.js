// The node's protocol steps, as tools/commission.py takes them (docs/modbus.md,
// "Commissioning from the PC"): the status, the event window read page by page with
// `event_from` put back, acknowledgements, and the commissioning sequence: every value
// checked against its register first, the scene's length against `scene_bytes`,
// unlock, write and read back, the scene and its CRC, commit; on any failure the
// switches put back, revert and lock.
import { registers, encode, decode, wordsOf } from './registers.js';
import { Refused, Silent, crcOk } from './modbus.js';

/** Switches the node applies as written (behind the unlock), kept with a commit. */
export const SWITCHES = ['latching', 'external_mode'];

/** The risk states by code (`status` bits 0-7). */
export const STATES = ['stopped', 'normal', 'microslip', 'gross slip', 'sensor fault'];
/** NAMUR NE 107 categories (`status` bits 8-11). */
export const NE107 = ['good', 'maintenance required', 'out of specification', 'function check', 'failure'];
/** The four alarms, in the bit order of `acknowledge_alarms` and `alarms`. */
export const ALARMS = ['warning', 'alarm', 'sensor fault', 'approaching'];

/** The line settings a master must follow to reach the node after their commit. */
export const MOVES = ['unit_id', 'baud', 'parity'];
/** `config_parity`'s values as the letters of a frame (8E1). */
export const PARITY = ['N', 'O', 'E'];

/** A step that failed, with the reason a technician reads. */
export class Failed extends Error {}

/** A configuration register's name: `config_` added to a field's name. */
export function registerName(name) {
  name = name.trim();
  if (name === 'new_code' || SWITCHES.includes(name) || name.startsWith('config_')) return name;
  return `config_${name}`;
}

/** `name,value` lines (header `name,value`, blank lines and `#` comments allowed). */
export function parseSettings(text) {
  const out = [];
  text.split(/\r?\n/).forEach((line, i) => {
    if (!line.trim() || line.startsWith('#')) return;
    const cells = line.split(',');
    if (i === 0 && cells.map((c) => c.trim()).join(',') === 'name,value') return;
    if (cells.length !== 2) throw new Failed(`configuration line ${i + 1}: name,value`);
    out.push([registerName(cells[0]), cells[1].trim()]);
  });
  return out;
}

const u32 = (w) => w[0] * 0x10000 + w[1];
const same = (a, b) => a.length === b.length && a.every((x, i) => x === b[i]);

export class Node {
  /** `client`: a modbus.js Client; `wasm`: the page's WebAssembly (event decoding,
   * commit reasons, f32 text). */
  constructor(client, wasm, map = registers) {
    this.c = client;
    this.wasm = wasm;
    this.map = map;
  }

  async read(name, table = 'holding') {
    const e = this.map.entry(name, table);
    return this.c.readRegisters(table === 'input' ? 4 : 3, e.address, wordsOf(e.type), `read ${name}`);
  }

  /** The exception code of a write, or null. */
  async write(name, words) {
    const e = this.map.entry(name);
    try {
      await this.c.writeRegisters(e.address, words, `write ${name}`);
      return null;
    } catch (x) {
      if (x instanceof Refused) return x.code;
      throw x;
    }
  }

  /** Every value of `table` from `first` to `last` (addresses), decoded by the map:
   * name -> {value, bits, text}. Read in runs of registers the map holds without a
   * gap (a node refuses an address its map leaves out), at most 125 a request. */
  async block(table, first, last) {
    const fn = table === 'input' ? 4 : 3;
    const entries = this.map.entries
      .filter((e) => e.table === table && e.address >= first && e.address + wordsOf(e.type) <= last)
      .sort((a, b) => a.address - b.address);
    const runs = [];
    for (const e of entries) {
      const run = runs[runs.length - 1];
      const end = e.address + wordsOf(e.type);
      if (run && e.address <= run.end && end - run.start <= 125) run.end = Math.max(run.end, end);
      else runs.push({ start: e.address, end });
    }
    const out = new Map();
    for (const run of runs) {
      const words = await this.c.readRegisters(fn, run.start, run.end - run.start, `read ${table} ${run.start}-${run.end - 1}`);
      for (const e of entries) {
        if (e.address < run.start || e.address + wordsOf(e.type) > run.end) continue;
        const w = words.slice(e.address - run.start, e.address - run.start + wordsOf(e.type));
        const d = decode(e, w);
        d.text = this.text(e, d);
        d.words = w;
        out.set(e.name, d);
      }
    }
    return out;
  }

  /** A value as the PC tools print it (f32 as Rust does; NaN: none). */
  text(e, d) {
    if (e.type !== 'f32') return String(d.value);
    return Number.isNaN(d.value) ? '-' : this.wasm.f32Text(d.bits);
  }

  /** The status and values (input registers up to the event window), the
   * commissioning registers (holding up to the staged configuration). */
  async status() {
    const window = this.map.entry('event_first', 'input').address;
    const input = await this.block('input', 0, window);
    const firstConfig = this.map.configRegisters()[0].address;
    const holding = await this.block('holding', 0, firstConfig);
    // The line settings in force and their supervision, where the map has them.
    const after = (table, first, last) => {
      const [a, b] = [first, last].map((n) => this.map.has(n, table) && this.map.entry(n, table));
      return a && b ? this.block(table, a.address, b.address + wordsOf(b.type)) : new Map();
    };
    for (const [k, v] of await after('holding', 'active_unit_id', 'line_confirm_window')) holding.set(k, v);
    for (const [k, v] of await after('input', 'line_reverts', 'line_confirm_left')) input.set(k, v);
    const s = input.get('status').value;
    return {
      input,
      holding,
      state: STATES[s & 0xff] ?? `code ${s & 0xff}`,
      ne107: NE107[(s >> 8) & 0xf] ?? `code ${(s >> 8) & 0xf}`,
      unacknowledged: ALARMS.filter((_, i) => (s >> (12 + i)) & 1),
    };
  }

  /** The staged and the active configuration: name (without `config_`) -> {staged,
   * active} decoded values. */
  async configuration() {
    const regs = this.map.configRegisters();
    const first = regs[0].address;
    const last = Math.max(...regs.map((e) => e.address + wordsOf(e.type)));
    const staged = await this.block('holding', first, last);
    const activeEntries = regs.map((e) => this.map.entry(`active_${e.name.slice(7)}`));
    const a0 = Math.min(...activeEntries.map((e) => e.address));
    const a1 = Math.max(...activeEntries.map((e) => e.address + wordsOf(e.type)));
    const active = await this.block('holding', a0, a1);
    return regs.map((e) => ({
      entry: e,
      field: e.name.slice(7),
      staged: staged.get(e.name),
      active: active.get(`active_${e.name.slice(7)}`),
    }));
  }

  /** Every event the node holds from sequence number `start` (null: from its own
   * `event_from`), read through the window, as the monitor example's `--events` rows;
   * `event_from` is put back as it was (reading acknowledges nothing). */
  async heldEvents(start = null) {
    const eventFrom = await this.read('event_from');
    const firstAt = this.map.entry('event_first', 'input').address;
    const countAt = this.map.entry('event_count', 'input').address;
    const slot0 = this.map.entry('event_0_seq', 'input').address;
    const stride = this.map.entry('event_1_seq', 'input').address - slot0;
    let slots = 0;
    while (this.map.has(`event_${slots}_seq`, 'input')) slots++;
    const writeFrom = async (n) => {
      const x = await this.write('event_from', [Math.floor(n / 0x10000), n % 0x10000]);
      if (x !== null) throw new Failed(`write event_from: exception ${x}`);
    };
    if (start !== null) await writeFrom(start);
    const rows = [];
    try {
      for (;;) {
        const w = await this.c.readRegisters(4, firstAt, slot0 + slots * stride - firstAt, 'read the event window');
        const count = w[countAt - firstAt];
        for (let k = 0; k < count; k++) {
          const at = slot0 - firstAt + k * stride;
          rows.push(this.wasm.eventRow(Uint16Array.from(w.slice(at, at + stride))));
        }
        if (count < slots) return rows;
        await writeFrom((u32(w) + count) % 0x100000000);
      }
    } finally {
      await this.write('event_from', eventFrom);
    }
  }

  /** Acknowledges every event through `seq` (`event_ack`: the node frees them on
   * flash and moves `event_from` past them). */
  async acknowledgeEvents(seq) {
    const x = await this.write('event_ack', [Math.floor(seq / 0x10000), seq % 0x10000]);
    if (x === 3) throw new Failed(`event ${seq}: the node has not given it yet (exception 3)`);
    if (x !== null) throw new Failed(`acknowledging events through ${seq}: exception ${x}`);
  }

  /** Acknowledges the alarms of `bits` (ISA-18.2; bit 0 warning, 1 alarm, 2 sensor
   * fault, 3 approaching). */
  async acknowledgeAlarms(bits = 0xf) {
    const x = await this.write('acknowledge_alarms', [bits]);
    if (x !== null) throw new Failed(`acknowledging the alarms: exception ${x}`);
  }

  /** The site's code written to `unlock`. */
  async unlock(code) {
    const entry = this.map.entry('unlock');
    let words;
    try {
      words = encode(entry, code);
    } catch {
      throw new Failed(`the code ${code}: a whole number from 0 to 65535`);
    }
    const x = await this.write('unlock', words);
    if (x === 3) throw new Failed('wrong code: refused by the node (counted; a few in a row lock it out)');
    if (x === 1) {
      const left = (await this.read('lockout'))[0];
      throw new Failed(`locked out for ${left} s after wrong codes: wait, then use the right code`);
    }
    if (x !== null) throw new Failed(`unlock: exception ${x}`);
  }

  /** `command`: 1 commit, 2 revert, 3 lock, 4 reset the statistics. */
  async command(n) {
    return this.write('command', [n]);
  }

  /** Where the node answers after a commit of what is staged: {unit, baud, parity}
   * when the staged line settings move it (a new unit id, baud rate or parity), null
   * when they do not. */
  async lineMove() {
    if (!((await this.read('staged'))[0] & 8)) return null;
    const value = async (name) => {
      const w = await this.read(name);
      return w.length === 2 ? u32(w) : w[0];
    };
    const to = {}, from = {};
    for (const f of MOVES) {
      to[f] = await value(`config_${f}`);
      from[f] = await value(`active_${f}`);
    }
    if (MOVES.every((f) => to[f] === from[f])) return null;
    return { unit: to.unit_id, baud: to.baud, parity: PARITY[to.parity] ?? `code ${to.parity}` };
  }

  /** Asks the node at the line settings `to` from now on: the unit id, and a serial
   * port reopened at the baud rate and parity (a WebSocket's bridge carries the bytes
   * whatever the node's UART runs). */
  async move(to) {
    this.c.unit = to.unit;
    await this.c.t.reconfigure?.(to.baud, to.parity);
  }

  /** After a commit that moved the node: a request at its new settings confirms them
   * (`line_status` bit 1 clears); without one the node goes back to the old ones
   * within `line_confirm_window`. The page asks there, up to three times. */
  async confirmLine(to, from) {
    await this.move(to);
    for (let i = 0; i < 3; i++) {
      try {
        if (!((await this.read('line_status', 'input'))[0] & 2)) return;
      } catch (e) {
        if (!(e instanceof Silent)) throw e;
      }
    }
    await this.move(from).catch(() => {});
    throw new Failed(
      `the node did not confirm its new line settings (unit ${to.unit}, ${to.baud} baud, parity ${to.parity}): ` +
        'it goes back to the old ones within line_confirm_window',
    );
  }

  /** Commit, refused with the node's reason (`commit_error`) spelled out. When the
   * commit moves the node (its unit id, baud rate or parity), the page follows it
   * and confirms the new settings; returns where it answers then, or null. */
  async commit() {
    const { to, from } = await this.commitStaged();
    if (to) await this.confirmLine(to, from);
    return to;
  }

  /** The commit alone: where the node answers after it (`to`, null: where it did)
   * and before it (`from`). */
  async commitStaged() {
    const to = await this.lineMove();
    const from = { unit: this.c.unit, ...this.c.t.line?.() };
    const x = await this.command(1);
    if (x === 1) throw new Failed('commit refused: locked (unlock first)');
    if (x !== null) {
      const why = (await this.read('commit_error'))[0];
      throw new Failed(`commit refused: ${this.wasm.commitReason(why)} (commit_error 0x${why.toString(16)})`);
    }
    return { to, from };
  }

  /** Every setting as its register's words, checked before anything is written. */
  checked(settings) {
    return settings.map(([name, value]) => {
      if (!(name.startsWith('config_') || name === 'new_code' || SWITCHES.includes(name))) {
        throw new Failed(`${name} is not a configuration register (config_*, new_code, ${SWITCHES.join(', ')})`);
      }
      let entry;
      try {
        entry = this.map.entry(name);
      } catch (e) {
        throw new Failed(e.message);
      }
      try {
        return [name, encode(entry, value), value];
      } catch (e) {
        throw new Failed(e.message);
      }
    });
  }

  /** The scene's words for the scene block (two bytes a register, high byte first,
   * an odd last byte padded). */
  static sceneWords(scene) {
    const words = [];
    for (let i = 0; i < scene.length; i += 2) words.push((scene[i] << 8) | (scene[i + 1] ?? 0));
    return words;
  }

  /** Stages `settings` ([name, value]) and `scene` (prepared bytes), each read back,
   * after the unlock. */
  async stage(checked, scene) {
    for (const [name, words, value] of checked) {
      const x = await this.write(name, words);
      if (x !== null) throw new Failed(`${name} = ${value}: refused with exception ${x}`);
      if (name !== 'new_code') {
        const back = await this.read(name);
        if (!same(back, words)) throw new Failed(`${name} reads back ${back}, not ${words}`);
      }
    }
    if (scene) {
      const words = Node.sceneWords(scene);
      const at = this.map.entry('scene_0_word').address;
      for (let i = 0; i < words.length; i += 120) {
        try {
          await this.c.writeRegisters(at + i, words.slice(i, i + 120), `scene block at ${at + i}`);
        } catch (e) {
          throw new Failed(e.message);
        }
      }
      const crc = new DataView(scene.buffer, scene.byteOffset).getUint32(scene.length - 4, true);
      if (u32(await this.read('scene_staged_crc')) !== crc) {
        throw new Failed("the staged scene's CRC differs from the file's: bytes lost on the way");
      }
    }
  }

  /** One line on the node (as tools/commission.py's --scan prints it): its unit id,
   * map version, state, NAMUR NE 107 category and line settings in force. */
  async describe(mapVersion) {
    const s = (await this.read('status', 'input'))[0];
    let line = '';
    if (mapVersion >= 3 && this.map.has('active_baud')) {
      const baud = u32(await this.read('active_baud'));
      const parity = PARITY[(await this.read('active_parity'))[0]] ?? '?';
      const delay = (await this.read('active_answer_delay'))[0];
      const timeout = (await this.read('active_bus_timeout'))[0];
      line = `, ${baud} baud 8${parity}${parity === 'N' ? 2 : 1}, answer delay ${delay} ms, bus timeout ${timeout} s`;
    }
    return `unit ${this.c.unit}: map_version ${mapVersion}, state ${STATES[s & 0xff] ?? s & 0xff}, NE 107 ${NE107[(s >> 8) & 0xf] ?? (s >> 8) & 0xf}${line}`;
  }

  /** The whole commissioning, as tools/commission.py runs it: what the node runs
   * afterwards is checked (at its new line settings, which the page follows and
   * confirms, when the commit moved it); on any failure before the commit the switches
   * are put back, the staged copy reverted and the node locked. Returns
   * `config_source` and where the node answers when the commit moved it (else null). */
  async commission(code, settings, scene = null) {
    const checked = this.checked(settings);
    if (scene) {
      const want = (await this.read('scene_bytes'))[0];
      if (want === 0) throw new Failed('this node takes no scene over the bus');
      if (scene.length !== want) {
        throw new Failed(`the node takes ${want} bytes of prepared scene, the file has ${scene.length} (another core?)`);
      }
    }
    await this.unlock(code);
    const switched = new Map();
    let line = { to: null };
    try {
      for (const [name] of checked) if (SWITCHES.includes(name)) switched.set(name, await this.read(name));
      await this.stage(checked, scene);
      if (checked.some(([n]) => !SWITCHES.includes(n)) || scene) line = await this.commitStaged();
      else await this.command(3);
    } catch (e) {
      for (const [name, words] of switched) await this.write(name, words).catch(() => {});
      await this.command(2).catch(() => {});
      await this.command(3).catch(() => {});
      throw e;
    }
    if (line.to) await this.confirmLine(line.to, line.from);
    for (const [name, words] of checked) {
      if (SWITCHES.includes(name) && !same(await this.read(name), words)) {
        throw new Failed(`${name} reads ${await this.read(name)} after the commit`);
      }
      if (name.startsWith('config_')) {
        const active = `active_${name.slice(7)}`;
        if (!same(await this.read(active), words)) throw new Failed(`${active} reads ${await this.read(active)} after the commit`);
      }
    }
    if (scene) {
      const crc = new DataView(scene.buffer, scene.byteOffset).getUint32(scene.length - 4, true);
      if (u32(await this.read('scene_active_crc')) !== crc) throw new Failed('the node does not run the scene after the commit');
    }
    return { source: (await this.read('config_source'))[0], moved: line.to };
  }
}

const hex = (bytes) => [...bytes].map((b) => b.toString(16).padStart(2, '0')).join('');

/** Each unit id of `units` asked once for `unit_id` and `map_version` (a read every
 * node of this map answers), as tools/commission.py's --scan: the nodes found, each
 * described in a line, and the clashes (bytes that are not one valid answer, as two
 * nodes answering at once make, or an answer naming another unit id). `progress(unit)`
 * is called before each. */
export async function scan(client, wasm, units, timeoutMs, progress = () => {}, map = registers) {
  const at = map.entry('unit_id').address;
  const found = [], clashes = [];
  const was = client.unit;
  try {
    for (const unit of units) {
      progress(unit);
      const got = await client.probe(unit, at, 2, timeoutMs);
      if (!got.length) continue;
      if (!(got.length === 9 && got[0] === unit && got[1] === 3 && got[2] === 4 && crcOk(got))) {
        if (got.length === 5 && got[0] === unit && got[1] === 0x83 && crcOk(got)) {
          clashes.push(`unit ${unit}: exception ${got[2]} to a read every node answers: not this map's node`);
        } else {
          clashes.push(`unit ${unit}: clash: ${got.length} bytes that are not one valid answer (two nodes at one unit id?): ${hex(got.subarray(0, 12))}`);
        }
        continue;
      }
      const id = (got[3] << 8) | got[4];
      if (id !== unit) {
        clashes.push(`unit ${unit}: answered with unit_id ${id} (a clash)`);
        continue;
      }
      client.unit = unit;
      try {
        found.push({ unit, text: await new Node(client, wasm, map).describe((got[5] << 8) | got[6]) });
      } catch (e) {
        clashes.push(`unit ${unit}: clash while reading it: ${e.message}`);
      }
    }
  } finally {
    client.unit = was;
  }
  return { found, clashes };
}
