// The web console's browser tests (run by `cargo xtask web --test`, which builds and
// serves the page, writes the monitor example's files, boots a node in QEMU and the
// bridge): Debian's Chromium, headless, driven by playwright-core.
//
// Environment: MISALIGN_WEB_URL (the page), MISALIGN_WEB_WS (the bridge to the QEMU
// node), MISALIGN_WEB_FILES (the example's files), MISALIGN_WEB_SHOTS (screenshots),
// MISALIGN_CHROMIUM (the browser).
import fs from 'node:fs';
import path from 'node:path';
import { launch, open, heartbeat } from './browser-common.mjs';

const env = (k) => {
  const v = process.env[k];
  if (!v) throw new Error(`${k} is not set: run \`cargo xtask web --test\``);
  return v;
};
const FILES = env('MISALIGN_WEB_FILES');
const SHOTS = env('MISALIGN_WEB_SHOTS');
const WS = env('MISALIGN_WEB_WS');
const file = (n) => fs.readFileSync(path.join(FILES, n));
const text = (n) => file(n).toString('utf8');

let failed = 0;
async function check(name, fn) {
  const t = Date.now();
  try {
    await fn();
    console.log(`ok   ${name} (${Date.now() - t} ms)`);
  } catch (e) {
    failed++;
    console.log(`FAIL ${name}\n     ${String(e.message ?? e).split('\n').join('\n     ')}`);
  }
}
function same(got, want, what) {
  if (got === want) return;
  const a = got.split('\n'), b = want.split('\n');
  const i = a.findIndex((l, k) => l !== b[k]);
  throw new Error(`${what}: differs at line ${i + 1} of ${b.length}:\n page:    ${a[i]}\n example: ${b[i]}`);
}
function ok(cond, what) {
  if (!cond) throw new Error(what);
}

const browser = await launch();
const { context, page, errors } = await open(browser, env('MISALIGN_WEB_URL'));

/** Clicks `selector` and returns the download's text. */
async function downloaded(selector) {
  const [d] = await Promise.all([page.waitForEvent('download'), page.click(selector)]);
  return fs.readFileSync(await d.path()).toString('utf8');
}
/** Waits until `#id`'s message is final (ok or error) and returns it. */
async function message(id, timeout = 30_000) {
  await page.waitForFunction((i) => /\b(ok|error)\b/.test(document.getElementById(i).className), id, { timeout });
  return page.evaluate((i) => ({ text: document.getElementById(i).textContent, ok: document.getElementById(i).classList.contains('ok') }), id);
}

// --- the page itself ------------------------------------------------------------------
await check('every input, list and button has a name a screen reader says, and the tabs take the keyboard', async () => {
  const unnamed = await page.$$eval('input, select, button, textarea', (els) =>
    els.filter((el) => !(el.labels?.length || el.getAttribute('aria-label') || (el.tagName === 'BUTTON' && el.textContent.trim())))
      .map((el) => el.id || el.name || el.outerHTML.slice(0, 60)));
  ok(unnamed.length === 0, `without a label: ${unnamed.join(', ')}`);
  await page.focus('#tab-plan');
  await page.keyboard.press('ArrowRight');
  ok(await page.$eval('#tab-review', (t) => t.getAttribute('aria-selected') === 'true' && document.activeElement === t), 'ArrowRight moves to Review');
  await page.keyboard.press('ArrowLeft');
  ok(await page.$eval('#tab-plan', (t) => t.getAttribute('aria-selected') === 'true'), 'ArrowLeft back to Plan');
});

// --- window.misalign: the example's files, byte for byte ---------------------------
const bad = file('bad-rows.csv').toString('base64');
const scene = text('scene.csv');
for (const model of ['f32', 'fixed', 'reference']) {
  await check(`window.misalign.replay: the built-in shift, ${model}, is the example's --events`, async () => {
    same(await page.evaluate((m) => window.misalign.replay(null, null, { model: m }), model), text(`builtin-${model}.csv`), 'events');
  });
  await check(`window.misalign.replay: a trace with bad rows and a scene, ${model}, is the example's --events`, async () => {
    const got = await page.evaluate(([t, s, m]) => window.misalign.replay(Uint8Array.from(atob(t), (c) => c.charCodeAt(0)), s, { model: m }), [bad, scene, model]);
    same(got, text(`bad-rows-${model}.csv`), 'events');
  });
  await check(`window.misalign.thresholds: the built-in shift and the bad rows' trace, ${model}, are the example's --thresholds`, async () => {
    same(await page.evaluate((m) => window.misalign.thresholds(null, { model: m }), model), text(`thresholds-builtin-${model}.csv`), 'built-in');
    const got = await page.evaluate(([t, s, m]) => window.misalign.thresholds(s, { model: m, trace: Uint8Array.from(atob(t), (c) => c.charCodeAt(0)) }), [bad, scene, model]);
    same(got, text(`thresholds-bad-rows-${model}.csv`), 'bad rows');
  });
}
await check('window.misalign: a bad file is refused with its reason', async () => {
  const e = await page.evaluate(() => { try { window.misalign.replay('time,P\n1,2\n', null); return ''; } catch (x) { return x.message; } });
  ok(e.startsWith('trace: ') && e.includes('phi'), e);
});
await check('window.misalign.estimate and its inverse: the CSV estimator', async () => {
  const out = await page.evaluate(() => window.misalign.estimate('R1,R2,G,nu,mu,P,phi\n0.05,0.05,79.3e9,0.3,0.3,2000,2e-4\n', { args: ['--model', 'reference'] }));
  ok(out.startsWith('theta,m,n,a,b,p0,s,F,phi0,regime,error'), out);
  const F = out.split('\n')[1].split(',')[7];
  const mu = await page.evaluate((f) => window.misalign.estimate(`R1,R2,G,nu,P,phi,F\n0.05,0.05,79.3e9,0.3,2000,2e-4,${f}\n`, { args: ['--solve', 'mu'] }), F);
  ok(Math.abs(Number(mu.split('\n')[1].split(',')[0]) / 0.3 - 1) < 1e-9, mu);
});

// --- Plan ----------------------------------------------------------------------------
await check('Plan: the defaults over the example\'s load range give its --thresholds file', async () => {
  await page.click('#tab-plan');
  const want = text('thresholds-builtin-f32.csv');
  const top = want.trim().split('\n').at(-1).split(',')[0];
  await page.fill('input[name=load_max]', top);
  await page.click('#plan-run');
  const m = await message('plan-message');
  ok(m.ok, m.text);
  same(await downloaded('#plan-download-thresholds'), want, 'thresholds.csv');
  same(await downloaded('#plan-download-config'), text('default-config.csv'), 'config.csv');
  const sceneCsv = await downloaded('#plan-download-scene');
  ok(sceneCsv === 'R1,R2,G,nu,mu\n0.05,0.05,79.3e9,0.3,0.3\n', sceneCsv);
  ok((await page.textContent('#plan-model')).includes('ellipse'), 'the model chosen');
});
await check('Plan: a configuration the node would refuse is refused with its reason', async () => {
  await page.fill('input[name=config_warning]', '1.5');
  await page.click('#plan-run');
  const m = await message('plan-message');
  ok(!m.ok && m.text.includes('the warning threshold must come before the alarm'), m.text);
  await page.fill('input[name=config_warning]', '0.8');
  await page.fill('input[name=load_max]', '5000');
  await page.click('#plan-run');
  ok((await message('plan-message')).ok, 'planned again');
  await page.screenshot({ path: path.join(SHOTS, 'plan.png'), fullPage: true });
});

// --- Review --------------------------------------------------------------------------
await check('Review: the built-in shift replayed in the worker; its download is the example\'s --events', async () => {
  await page.click('#tab-review');
  await page.selectOption('#review-model', 'f32');
  await page.click('#review-builtin');
  const m = await message('review-message', 60_000);
  ok(m.ok, m.text);
  same(await downloaded('#review-download'), text('builtin-f32.csv'), 'events.csv');
  const rows = await page.$$eval('#review-events tbody tr', (r) => r.length);
  ok(rows === text('builtin-f32.csv').trim().split('\n').length - 1, `${rows} rows in the table`);
  ok((await page.$$('#review-plots canvas')).length >= 4, 'four plot panels');
});
await check('Review: the plot zooms and pans from the keyboard and the toolbar', async () => {
  const view = () => page.$eval('#review-plots', (el) => el.dataset.view.split(',').map(Number));
  const [a, b] = await view();
  await page.focus('#review-plots .panel');
  await page.keyboard.press('+');
  await page.keyboard.press('ArrowRight');
  const [c, d] = await view();
  ok(Math.abs((d - c) - (b - a) / 2) < 1e-6 * b && c > a, `view ${a}-${b} then ${c}-${d}`);
  await page.click('button[data-zoom=out]');
  await page.click('button[data-pan="-1"]');
  await page.click('button[data-zoom=reset]');
  const [e, f] = await view();
  ok(e === a && f === b, `the whole trace again: ${e}-${f}`);
});
await check('Review: a trace with bad rows through the file input, fixed point: its download is the example\'s, the bad rows counted', async () => {
  await page.setInputFiles('#review-trace', path.join(FILES, 'bad-rows.csv'));
  await page.setInputFiles('#review-scene', path.join(FILES, 'scene.csv'));
  await page.selectOption('#review-model', 'fixed');
  await page.click('#review-run');
  const m = await message('review-message', 60_000);
  ok(m.ok, m.text);
  same(await downloaded('#review-download'), text('bad-rows-fixed.csv'), 'events.csv');
  const summary = await page.textContent('#review-summary');
  ok(/rows skipped \(no usable time\)\s*\d+ \(row/.test(summary), summary);
});
await check('Review: a bad trace is refused with its reason', async () => {
  await page.setInputFiles('#review-trace', { name: 'bad.csv', mimeType: 'text/csv', buffer: Buffer.from('time,P\n1,2\n') });
  await page.click('#review-run');
  const m = await message('review-message');
  ok(!m.ok && m.text.includes('bad.csv') && m.text.includes('phi'), m.text);
});
await check('Review: a 600 000-row trace replays in the worker while the page answers', async () => {
  await page.setInputFiles('#review-scene', []);
  await page.selectOption('#review-model', 'f32');
  await page.setInputFiles('#review-trace', path.join(FILES, 'trace-short.csv'));
  const beat = await heartbeat(page);
  await page.click('#review-run');
  const m = await message('review-message', 120_000);
  const { longest, span } = await beat.stop();
  ok(m.ok, m.text);
  ok(m.text.includes('600000 samples'), m.text);
  console.log(`     ${m.text}; the page's longest pause ${longest.toFixed(0)} ms over the ${span.toFixed(0)} ms of the replay`);
  // On the page's thread the replay would be one pause as long as itself; in the
  // worker the page's timer runs on throughout (its pauses are the machine's
  // scheduling, hundreds of ms on a loaded one).
  ok(longest < span / 3, `the page paused ${longest.toFixed(0)} ms of ${span.toFixed(0)} ms`);
  // The built-in shift again, for the screenshot.
  await page.click('#review-builtin');
  ok((await message('review-message', 60_000)).ok, 'the built-in shift');
  await page.screenshot({ path: path.join(SHOTS, 'review.png'), fullPage: true });
});

// --- Node ----------------------------------------------------------------------------
const reg = (name) => page.textContent(`#node-status dd[data-register=${name}]`);
const configTable = () => page.$$eval('#node-config tbody tr', (rows) => rows.map((r) => [...r.cells].slice(0, 4).map((c) => c.textContent).join(',')));
await check('Node: connects through the bridge to the node in QEMU and reads its status', async () => {
  await page.click('#tab-node');
  await page.selectOption('#node-transport', 'websocket');
  await page.fill('#node-url', WS);
  await page.click('#node-connect-button');
  const m = await message('node-message', 30_000);
  ok(m.ok, m.text);
  ok((await reg('samples')).trim() === '28620', `samples ${await reg('samples')}`);
  ok((await page.textContent('#node-status .state')).includes('NE 107'), 'the state');
  ok(!(await page.isVisible('#node-baud')) && (await page.isVisible('#node-url')), 'a WebSocket shows its address, not the serial settings');
});
await check('Node: a unit id nobody answers is said so, with what to check', async () => {
  await page.fill('#node-unit', '9');
  await page.click('#node-connect-button');
  const m = await message('node-message', 30_000);
  ok(!m.ok && m.text.includes('the node did not answer within 1000 ms (its unit id 9, the line settings, the cable or the bridge?)'), m.text);
  ok(!(await page.isVisible('#node-live')), 'the status is hidden');
  await page.fill('#node-unit', '1');
  await page.click('#node-connect-button');
  ok((await message('node-message', 30_000)).ok, 'connected again at unit 1');
});
await check('Node: the event window is the example\'s events, decoded by the library', async () => {
  const rows = await page.$$eval('#node-events-table tbody tr', (r) => r.map((tr) => [...tr.cells].slice(0, 14).map((c) => c.textContent).join(',')));
  ok(rows.length > 0, 'no events');
  const example = text('builtin-f32.csv').trim().split('\n');
  for (const r of rows) same(r, example[Number(r.split(',')[1]) + 1], `event ${r.split(',')[1]}`);
});
await check('Node: a wrong code is refused with a clear message and changes nothing', async () => {
  const before = await configTable();
  const failures = Number(await reg('unlock_failures'));
  await page.fill('#node-code', '4321');
  await page.fill('#node-config input[name=config_warning]', '0.7');
  await page.click('#node-commission');
  const m = await message('node-message');
  ok(!m.ok && m.text.startsWith('wrong code'), m.text);
  ok((await configTable()).join('|') === before.join('|'), 'the configuration changed');
  ok((await reg('unlock')).trim() === '0 s', `unlock ${await reg('unlock')}`);
  ok((await reg('staged')).trim() === '0', `staged ${await reg('staged')}`);
  ok(Number(await reg('unlock_failures')) === failures + 1, 'the wrong code was not counted');
});
await check('Node: commissions a scene and a threshold; the node runs the bytes examples/prepare.rs writes', async () => {
  await page.fill('#node-code', '1234');
  await page.fill('#node-config input[name=config_warning]', '0.75');
  await page.setInputFiles('#node-scene', path.join(FILES, 'commission-scene.csv'));
  await page.click('#node-commission');
  const m = await message('node-message');
  ok(m.ok && m.text.startsWith('Commissioned: 1 registers and the scene'), m.text);
  const bin = file('commission-scene.bin');
  const crc = `0x${bin.readUInt32LE(bin.length - 4).toString(16).padStart(8, '0')}`;
  ok((await reg('scene_active_crc')).trim() === crc, `scene_active_crc ${await reg('scene_active_crc')}, the file's ${crc}`);
  ok((await configTable()).includes('warning,,0.75,0.75'), (await configTable()).join('\n'));
});
await check('Node: a commit the node refuses says why, and the node keeps what it ran', async () => {
  await page.setInputFiles('#node-scene', []);
  await page.fill('#node-code', '1234');
  await page.fill('#node-config input[name=config_warning]', '2');
  await page.click('#node-commission');
  const m = await message('node-message');
  ok(!m.ok && m.text.includes('commit refused: the configuration: the warning threshold must come before the alarm (commit_error 0x11)'), m.text);
  ok((await configTable()).includes('warning,,0.75,0.75'), (await configTable()).join('\n'));
  ok((await reg('unlock')).trim() === '0 s', 'locked again');
});
await check('Node: acknowledges the alarms and an event', async () => {
  await page.click('#node-ack-alarms');
  const m = await message('node-message');
  ok(m.ok && m.text.endsWith('unacknowledged now: none.'), m.text);
  const first = await page.$eval('#node-events-table tbody tr', (tr) => Number(tr.cells[1].textContent));
  await page.click('#node-events-table tbody tr button');
  const a = await message('node-message');
  ok(a.ok && a.text.startsWith(`Events through #${first} acknowledged`), a.text);
  const now = await page.$$eval('#node-events-table tbody tr', (r) => r.map((tr) => Number(tr.cells[1].textContent)));
  ok(now.length > 0 && now.every((s) => s > first), `the window shows ${now}`);
});
const found = () => page.$$eval('#node-scan-found li', (li) => li.map((l) => `${l.className}|${l.querySelector('span')?.textContent ?? l.textContent}`));
await check('Node: Find nodes lists the node at unit 1 with its line settings in force', async () => {
  await page.fill('#node-scan-units', '1-3');
  await page.click('#node-scan');
  const m = await message('node-message');
  ok(m.ok && m.text === '1 node found among 3 unit ids.', m.text);
  const f = await found();
  ok(f.length === 1 && /^\|unit 1: map_version \d+, state \S+/.test(f[0]) && f[0].includes(', 19200 baud 8E1, answer delay 0 ms'), f.join('\n'));
  ok((await reg('active_baud')).trim() === '19200 bit/s' && (await reg('active_parity')).trim() === '2 (even, 8E1)', 'the line in the status');
});
await check('Node: a new unit id commissioned from the page: the page follows the node there and confirms it', async () => {
  await page.fill('#node-code', '1234');
  await page.fill('#node-config input[name=config_unit_id]', '7');
  await page.click('#node-commission');
  const m = await message('node-message');
  ok(m.ok && m.text.includes('The node answers at unit 7, 19200 baud, parity E now, confirmed'), m.text);
  ok((await page.inputValue('#node-unit')) === '7', 'the connection form shows unit 7');
  ok((await reg('unit_id')).trim() === '7' && (await reg('active_unit_id')).trim() === '7', `unit_id ${await reg('unit_id')}`);
  ok((await reg('line_status')).includes('in order') && (await reg('line_confirm_left')).trim() === '0 s', `line_status ${await reg('line_status')}, ${await reg('line_confirm_left')}`);
  await page.fill('#node-scan-units', '1-8');
  await page.click('#node-scan');
  const s = await message('node-message');
  ok(s.ok && s.text === '1 node found among 8 unit ids.', s.text);
  const f = await found();
  ok(f.length === 1 && f[0].startsWith('|unit 7: '), f.join('\n'));
  await page.click('#node-scan-found button');
  const c = await message('node-message');
  ok(c.ok && c.text.endsWith('unit 7.'), c.text);
  await page.click('#node-read');
  await message('node-message');
  // The tables from their first row and column, as a person opening the view sees them.
  await page.$$eval('.table-wrap', (wraps) => wraps.forEach((w) => w.scrollTo(0, 0)));
  await page.screenshot({ path: path.join(SHOTS, 'node.png'), fullPage: true });
});
await check('Node: over Web Serial, a new baud rate and parity committed: the page reopens the port at them and the node confirms', async () => {
  // A stand-in for the browser's Web Serial: the port the person would pick, its
  // bytes carried to the node in QEMU through the bridge, each open's settings noted.
  await page.evaluate((ws) => {
    window.__opened = [];
    class Port {
      async open(settings) {
        const socket = new WebSocket(ws);
        socket.binaryType = 'arraybuffer';
        await new Promise((resolve, reject) => { socket.onopen = resolve; socket.onerror = () => reject(new Error('bridge')); });
        window.__opened.push(`${settings.baudRate} ${settings.dataBits}${settings.parity[0].toUpperCase()}${settings.stopBits}`);
        this.socket = socket;
        this.readable = new ReadableStream({ start(c) { socket.onmessage = (m) => c.enqueue(new Uint8Array(m.data)); } });
        this.writable = new WritableStream({ write(chunk) { socket.send(chunk); } });
      }
      async close() { this.socket.close(); this.readable = null; this.writable = null; }
    }
    Object.defineProperty(navigator, 'serial', { configurable: true, value: { requestPort: async () => new Port() } });
  }, WS);
  await page.click('#node-disconnect');
  await message('node-message');
  await page.selectOption('#node-transport', 'serial');
  await page.fill('#node-unit', '7');
  await page.click('#node-connect-button');
  const c = await message('node-message', 30_000);
  ok(c.ok && c.text === 'Connected through serial 19200 baud, 8E1, unit 7.', c.text);
  await page.fill('#node-code', '1234');
  await page.fill('#node-config input[name=config_baud]', '38400');
  await page.fill('#node-config input[name=config_parity]', '0');
  await page.click('#node-commission');
  const m = await message('node-message');
  ok(m.ok && m.text.includes('The node answers at unit 7, 38400 baud, parity N now, confirmed'), m.text);
  const opened = await page.evaluate(() => window.__opened);
  ok(opened.join('|') === '19200 8E1|38400 8N2', `the port opened at ${opened.join(', then ')}`);
  ok((await page.inputValue('#node-baud')) === '38400' && (await page.inputValue('#node-parity')) === 'N', 'the connection form shows 38400 8N2');
  ok((await reg('active_baud')).trim() === '38400 bit/s' && (await reg('active_parity')).trim() === '0 (none, 8N2)', `active_baud ${await reg('active_baud')}`);
  ok((await reg('line_status')).includes('in order'), `line_status ${await reg('line_status')}`);
});
await check('the page raised no error', async () => {
  ok(errors.length === 0, errors.join('\n'));
});

await context.close();
await browser.close();
console.log(failed ? `${failed} browser tests failed` : 'every browser test passed');
process.exit(failed ? 1 : 0);
