// What the browser tests and the measurement share: Debian's Chromium through
// playwright-core (never a downloaded browser), the page opened and ready, and a
// heartbeat on the page's own thread.
import { chromium } from 'playwright-core';

/** Chromium, headless, each run in a fresh profile. */
export function launch() {
  return chromium.launch({
    executablePath: process.env.MISALIGN_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
}

/** A fresh context on `url`, once the library has loaded; the page's errors. */
export async function open(browser, url) {
  const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(url);
  await page.waitForFunction(() => document.body.dataset.ready === 'true', null, { timeout: 30_000 });
  return { context, page, errors };
}

/** Starts a timer on the page's thread that notes its pauses; `stop()` gives the
 * longest (ms) before the replay's result arrived (`body[data-replay-ended]`, set
 * before the page draws it), and the time watched. */
export async function heartbeat(page) {
  await page.evaluate(() => {
    delete document.body.dataset.replayEnded;
    const beat = { last: performance.now(), pauses: [], start: performance.now() };
    beat.timer = setInterval(() => {
      const now = performance.now();
      beat.pauses.push([beat.last, now - beat.last]);
      beat.last = now;
    }, 10);
    window.__beat = beat;
  });
  return {
    stop: () => page.evaluate(() => {
      const b = window.__beat;
      clearInterval(b.timer);
      const end = Number(document.body.dataset.replayEnded ?? Infinity);
      // Each pause's part before the result arrived (the page then draws it).
      const during = b.pauses.filter(([t]) => t < end).map(([t, p]) => Math.min(t + p, end) - t);
      return { longest: Math.max(0, ...during), span: Math.min(end, performance.now()) - b.start };
    }),
  };
}
