// gantry run --debug: a script stopped at a breakpoint holds the whole simulation; the
// banner says where and sends the debugger's step commands.

import { $, showError } from '../dom.js';
import { send } from '../net.js';

export function onDebug(paused) {
  const banner = $('debug-banner');
  banner.hidden = !paused;
  if (paused) $('debug-where').textContent = `paused in ${paused.script}:${paused.line} (${paused.reason})`;
}

for (const b of document.querySelectorAll('#debug-banner button')) {
  b.addEventListener('click', () => send({ op: 'debug', action: b.dataset.debug }, (r) => { if (!r.ok) showError(r.text); }));
}
