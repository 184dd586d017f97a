// The web console's measurement (run by `cargo xtask web --measure`): the time to a
// usable page (median of 5 loads, each in a fresh profile) and a trace replayed in
// the Review view's worker (the better of two runs), with the page's longest pause
// meanwhile, and idle for as long. Prints `name value` lines. Environment: MISALIGN_WEB_URL,
// MISALIGN_WEB_TRACE (the trace file), MISALIGN_CHROMIUM.
import { launch, open, heartbeat } from './browser-common.mjs';

const url = process.env.MISALIGN_WEB_URL;
const trace = process.env.MISALIGN_WEB_TRACE;
const browser = await launch();
const ready = [];
for (let i = 0; i < 5; i++) {
  const { context, page } = await open(browser, url);
  ready.push(await page.evaluate(() => performance.getEntriesByName('misalign-ready')[0].startTime));
  await context.close();
}
ready.sort((a, b) => a - b);
console.log(`ready_ms ${ready[2].toFixed(1)}`);

const { context, page, errors } = await open(browser, url);
await page.click('#tab-review');
await page.setInputFiles('#review-trace', trace);
let best = Infinity, longest = 0, samples = 0;
for (let run = 0; run < 2; run++) {
  const beat = await heartbeat(page);
  const t0 = await page.evaluate(() => performance.now());
  await page.click('#review-run');
  await page.waitForFunction(() => /\b(ok|error)\b/.test(document.getElementById('review-message').className), null, { timeout: 600_000 });
  const t1 = await page.evaluate(() => performance.now());
  const message = await page.textContent('#review-message');
  if (!(await page.evaluate(() => document.getElementById('review-message').classList.contains('ok')))) throw new Error(message);
  const b = await beat.stop();
  best = Math.min(best, (t1 - t0) / 1e3);
  longest = Math.max(longest, b.longest);
  samples = Number(message.match(/(\d+) samples/)[1]);
  console.error(`measure: ${message}`);
}
// The same page idle for as long: its pauses that are the machine's, not the replay's.
const idle = await heartbeat(page);
await page.waitForTimeout(best * 1000);
const quiet = await idle.stop();
console.log(`replay_s ${best.toFixed(3)}`);
console.log(`idle_longest_pause_ms ${quiet.longest.toFixed(1)}`);
console.log(`longest_pause_ms ${longest.toFixed(1)}`);
console.log(`samples ${samples}`);
if (errors.length) throw new Error(errors.join('\n'));
await context.close();
await browser.close();
