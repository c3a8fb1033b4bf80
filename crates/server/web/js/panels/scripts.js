// The scripts panel (each script's state, error and a reload button) and the log.

import { $, el, fmt, showError } from '../dom.js';
import { send } from '../net.js';

export function showScripts(list) {
  const rows = list.map((s) => {
    const file = s.path.split(/[\\/]/).pop();
    const state = el('span', { class: `badge ${s.state === 'running' ? 'ok' : 'bad'}`, text: s.state });
    const reload = el('button', { text: 'Reload', title: `reload ${s.path} from disk` });
    reload.addEventListener('click', () => send({ op: 'reload', script: s.index }, (r) => { if (!r.ok) showError(r.text); }));
    const info = el('td', {}, el('div', { text: `${file} on ${s.alias}`, title: s.path }));
    if (s.error) info.append(el('div', { class: 'error', text: s.error }));
    return el('tr', { 'data-script': file }, info, el('td', {}, state), el('td', {}, reload));
  });
  $('script-table').tBodies[0].replaceChildren(...rows);
}

const MAX_LOG = 500;
export function clearLog() { $('log').replaceChildren(); }

export function appendLog(lines) {
  const log = $('log');
  const atBottom = log.scrollTop + log.clientHeight >= log.scrollHeight - 4;
  for (const l of lines) {
    const cls = l.verbosity <= 200 ? 'v200' : l.verbosity <= 300 ? 'v300' : '';
    log.append(el('div', { class: cls, text: `[${fmt(l.time, 2)} ${l.source}] ${l.message}` }));
  }
  while (log.childElementCount > MAX_LOG) log.firstElementChild.remove();
  if (atBottom) log.scrollTop = log.scrollHeight;
}
