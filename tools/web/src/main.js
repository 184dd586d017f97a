// The console's entry: loads the library (WebAssembly), exposes it to scripts as
// `window.misalign`, and wires the three views.
import init, * as wasm from '@pkg/misalign_web.js';
import './style.css';
import { api } from './api.js';
import { setupPlan } from './plan.js';
import { setupReview } from './review.js';
import { setupNode } from './node-view.js';

/** ARIA tabs: click, arrow keys, Home/End; the address's #plan, #review, #node. */
function setupTabs() {
  const tabs = [...document.querySelectorAll('[role=tab]')];
  const show = (tab, focus) => {
    for (const t of tabs) {
      const on = t === tab;
      t.setAttribute('aria-selected', on);
      t.tabIndex = on ? 0 : -1;
      document.getElementById(t.getAttribute('aria-controls')).hidden = !on;
    }
    if (focus) tab.focus();
    history.replaceState(null, '', `#${tab.getAttribute('aria-controls')}`);
    window.dispatchEvent(new Event('resize'));
  };
  tabs.forEach((t, i) => {
    t.addEventListener('click', () => show(t, false));
    t.addEventListener('keydown', (e) => {
      const to = { ArrowRight: i + 1, ArrowLeft: i - 1, Home: 0, End: tabs.length - 1 }[e.key];
      if (to === undefined) return;
      e.preventDefault();
      show(tabs[(to + tabs.length) % tabs.length], true);
    });
  });
  const wanted = tabs.find((t) => `#${t.getAttribute('aria-controls')}` === location.hash);
  show(wanted ?? tabs[0], false);
}

async function main() {
  const loading = document.getElementById('loading');
  try {
    await init();
  } catch (e) {
    loading.textContent = `The library did not load (${e.message}): serve this folder over http(s), not as a file.`;
    loading.className = 'message error';
    return;
  }
  window.misalign = api(wasm);
  setupTabs();
  const plan = setupPlan(wasm);
  setupReview(wasm);
  setupNode(wasm, plan);
  loading.remove();
  document.body.dataset.ready = 'true';
  performance.mark('misalign-ready');
  window.dispatchEvent(new Event('misalign-ready'));
}

main();
