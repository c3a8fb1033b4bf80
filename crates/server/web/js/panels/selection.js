// The selection: the picked object's panel and the object tree, kept in step with the
// simulation's selection.

import { S, changed } from '../state.js';
import { send } from '../net.js';
import { $, el, fmt } from '../dom.js';
import { deg } from '../math.js';

// Selects object `idx` (-1: nothing) on the page and, unless the server asked for it,
// as the simulation's selection (sim.getObjectSel).
export function select(idx, fromServer = false) {
  if (!fromServer) send({ op: 'select', handles: idx >= 0 ? [S.objects[idx].handle] : [] });
  S.selected = idx;
  for (const s of document.querySelectorAll('#object-tree span.selected')) s.classList.remove('selected');
  if (idx >= 0) document.querySelector(`#object-tree span[data-index="${idx}"]`)?.classList.add('selected');
  showPick(idx);
  changed.view = true;
}

export function showPick(idx) {
  const box = $('pick-info');
  if (idx < 0) { box.textContent = 'Nothing selected.'; box.className = 'muted'; return; }
  const o = S.objects[idx];
  const p = o.pose;
  // The server's Euler angles (sim.getObjectOrientation's) follow the simulation's
  // selection, which this pick becomes one round trip later: '–' until then.
  const sel = S.selectedOrientation;
  const e = (sel && sel.handle === o.handle ? sel.euler : [NaN, NaN, NaN]).map((a) => fmt(deg(a), 2));
  const rows = [
    ['alias', o.alias], ['path', o.path], ['handle', String(o.handle)], ['type', o.kind],
    ['position', `${fmt(p[0])}, ${fmt(p[1])}, ${fmt(p[2])} m`],
    ['orientation', `α ${e[0]}°, β ${e[1]}°, γ ${e[2]}°`],
    ['quaternion', p.slice(3).map((q) => fmt(q, 4)).join(', ')],
  ];
  const ji = S.jointIndex.indexOf(idx);
  if (ji >= 0) rows.push(['joint', o.joint.type === 'prismatic' ? `${fmt(S.joints[ji], 4)} m` : `${fmt(deg(S.joints[ji]), 2)}°`]);
  const table = el('table', {}, ...rows.map(([k, v]) => el('tr', {}, el('td', { text: k }), el('td', { text: v }))));
  box.className = '';
  box.replaceChildren(table);
}

export function buildTree() {
  const make = (idx) => {
    const o = S.objects[idx];
    const label = el('span', { 'data-index': String(idx), text: `${o.alias} ` }, el('span', { class: 'kind', text: `${o.kind} #${o.handle}` }));
    label.addEventListener('click', () => select(idx));
    const li = el('li', {}, label);
    if (o.children.length) li.append(el('ul', {}, ...o.children.map(make)));
    return li;
  };
  $('object-tree').replaceChildren(...S.objects.filter((o) => o.parent == null).map((o) => make(o.index)));
}
