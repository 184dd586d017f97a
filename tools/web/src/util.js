// Small helpers the views share.

/** Saves `data` (text or bytes) as a file named `name`. */
export function download(name, data, type = 'text/csv') {
  const url = URL.createObjectURL(new Blob([data], { type }));
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

/** Shows `text` in the message element `el`: kind `ok`, `error` or `` (progress). */
export function say(el, text, kind = '') {
  el.textContent = text;
  el.className = `message ${kind}`;
}

/** The text of a thrown value (wasm-bindgen's JsError, an Error, a string). */
export function messageOf(e) {
  return e instanceof Error ? e.message : String(e);
}

/** Fills `table` with a header and rows of cells (text). */
export function fillTable(table, header, rows, limit = Infinity) {
  const caption = table.querySelector('caption');
  table.replaceChildren(...(caption ? [caption] : []));
  const head = table.createTHead().insertRow();
  for (const h of header) {
    const th = document.createElement('th');
    th.scope = 'col';
    th.textContent = h;
    head.append(th);
  }
  const body = table.createTBody();
  for (const r of rows.slice(0, limit)) {
    const tr = body.insertRow();
    for (const c of r) {
      if (c instanceof Node) tr.insertCell().append(c);
      else tr.insertCell().textContent = c;
    }
  }
  return body;
}

/** A CSV file's lines split into cells (the tools' files have no quoted commas). */
export function csvRows(text) {
  return text.split('\n').filter((l) => l !== '').map((l) => l.split(','));
}

/** Reads a File as text. */
export const readText = (file) => file.text();

/** The risk states' colours, by `RiskState::index`. */
export const STATE_COLOURS = ['#c9ced6', '#bfe3c0', '#ffe08a', '#f4a6a6', '#c8b6ff'];
export const STATE_NAMES = ['stopped', 'normal', 'microslip', 'gross_slip', 'sensor_fault'];
