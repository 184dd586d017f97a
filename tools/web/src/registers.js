// The node's register map, read from docs/modbus/registers.csv when the page is built
// (the library writes that file from its map: `cargo xtask modbus --registers`), so
// that the page names, places and types every value exactly as the node does.
import text from '../../../docs/modbus/registers.csv?raw';

/** The CSV's rows (RFC 4180: quoted fields may hold commas and doubled quotes). */
export function parseCsv(csv) {
  const rows = [];
  let row = [], field = '', quoted = false;
  for (let i = 0; i < csv.length; i++) {
    const c = csv[i];
    if (quoted) {
      if (c === '"' && csv[i + 1] === '"') { field += '"'; i++; }
      else if (c === '"') quoted = false;
      else field += c;
    } else if (c === '"') quoted = true;
    else if (c === ',') { row.push(field); field = ''; }
    else if (c === '\n' || c === '\r') {
      if (c === '\r' && csv[i + 1] === '\n') i++;
      row.push(field); field = '';
      if (row.length > 1 || row[0] !== '') rows.push(row);
      row = [];
    } else field += c;
  }
  if (field !== '' || row.length) { row.push(field); rows.push(row); }
  return rows;
}

/** The map: `entry(table, name)` and every entry of a table, by address. */
export class RegisterMap {
  constructor(csv) {
    const [header, ...rows] = parseCsv(csv);
    const at = (name) => header.indexOf(name);
    this.entries = rows.map((r) => ({
      table: r[at('table')],
      address: Number(r[at('address')]),
      name: r[at('name')],
      type: r[at('type')],
      unit: r[at('unit')],
      access: r[at('access')],
      description: r[at('description')],
      // The values a writable register takes (empty: read only).
      min: at('min') >= 0 ? r[at('min')] : '',
      max: at('max') >= 0 ? r[at('max')] : '',
    }));
    this.byName = new Map(this.entries.map((e) => [`${e.table}:${e.name}`, e]));
  }

  /** The entry `name` of `table`, or an error naming it. */
  entry(name, table = 'holding') {
    const e = this.byName.get(`${table}:${name}`);
    if (!e) throw new Error(`the register map has no ${table} register ${name}`);
    return e;
  }

  has(name, table = 'holding') {
    return this.byName.has(`${table}:${name}`);
  }

  /** The staged configuration's registers (`config_*`, writable), in address order. */
  configRegisters() {
    return this.entries.filter((e) => e.table === 'holding' && e.name.startsWith('config_') && e.access === 'rw');
  }

  /** The monitor's configuration alone: the staged registers before the line
   * settings (the sensors' settings follow those). A file of line settings given to
   * every node would put them all at one unit id, so a plan leaves them to each
   * node's commissioning. */
  monitorRegisters() {
    const line = this.has('config_unit_id') ? this.entry('config_unit_id').address : Infinity;
    return this.configRegisters().filter((e) => e.address < line);
  }
}

/** Registers a value of `type` takes. */
export const wordsOf = (type) => (type === 'u16' ? 1 : 2);

/**
 * `value` (text as a person types it, or a number) as the words of `entry`'s
 * register, high word first; an Error naming the register for a value its type or its
 * domain (the map's `min` and `max`) does not hold, as tools/commission.py checks it.
 */
export function encode(entry, value) {
  const text = String(value).trim();
  const { name, min, max, unit } = entry;
  if (entry.access !== 'rw') throw new Error(`${name} is read only`);
  const within = `from ${min} to ${max}${unit ? ` ${unit}` : ''}`;
  if (entry.type === 'f32') {
    const x = Number(text);
    if (text === '' || Number.isNaN(x)) throw new Error(`${name} = ${text}: not a number`);
    const f = Math.fround(x);
    if (Number.isFinite(x) && !Number.isFinite(f)) throw new Error(`${name} = ${text}: beyond the largest f32 (${within})`);
    if (min !== '' && !Number.isFinite(f)) throw new Error(`${name} = ${text}: not a finite number (${within})`);
    if (min !== '' && !(Number(min) <= f && f <= Number(max))) throw new Error(`${name} = ${text}: outside its domain, ${within}`);
    const view = new DataView(new ArrayBuffer(4));
    view.setFloat32(0, f);
    return [view.getUint16(0), view.getUint16(2)];
  }
  if (entry.type !== 'u16' && entry.type !== 'u32') throw new Error(`${name}: a ${entry.type} register, which the console does not write`);
  if (!/^(\d+|0x[0-9a-f]+)$/i.test(text)) throw new Error(`${name} = ${text}: not a whole number (${within})`);
  const v = Number(text);
  if (!Number.isSafeInteger(v) || v < Number(min) || v > Number(max)) {
    throw new Error(`${name} = ${text}: outside its domain, a whole number ${within}`);
  }
  return entry.type === 'u16' ? [v] : [Math.floor(v / 0x10000), v % 0x10000];
}

/** A register's words as its value: a number (f32 as its bits too, for exact text). */
export function decode(entry, words) {
  if (entry.type === 'u16') return { value: words[0] };
  const u = words[0] * 0x10000 + words[1];
  if (entry.type === 'u32') return { value: u };
  if (entry.type === 'i32') return { value: u >= 0x80000000 ? u - 0x100000000 : u };
  const view = new DataView(new ArrayBuffer(4));
  view.setUint32(0, u);
  return { value: view.getFloat32(0), bits: u };
}

export const registers = new RegisterMap(text);
