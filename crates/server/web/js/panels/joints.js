// Joint panel: per robot (the model that holds the joints) a slider and a box per joint,
// in degrees (mm for prismatic joints) within the limits. Moving one sends the FK packet
// a TCP client would send, with every joint of that robot; the rows follow the live values.

import { S } from '../state.js';
import { $, el, fmt, setReply } from '../dom.js';
import { deg, rad } from '../math.js';
import { send } from '../net.js';

const jointRows = [];  // {k (joint index), robot, slider, box, busy}

function robotOf(idx) {
  for (let o = S.objects[idx]; o; o = o.parent != null ? S.objects[o.parent] : null) {
    if (o.model_base) return o.index;
  }
  return -1;
}

export function buildJointPanels() {
  jointRows.length = 0;
  const robots = new Map();
  S.jointIndex.forEach((oi, k) => {
    const o = S.objects[oi];
    if (o.joint.type === 'fixed') return;
    const r = robotOf(oi);
    if (!robots.has(r)) robots.set(r, []);
    robots.get(r).push(k);
  });
  const panels = [];
  for (const [r, ks] of robots) {
    const name = r >= 0 ? S.objects[r].alias : 'scene';
    const box = el('div', { class: 'robot', 'data-robot': name }, el('h3', { text: name }));
    const settable = ks.some((k) => S.objects[S.jointIndex[k]].joint.mode !== 'velocity');
    ks.forEach((k, n) => {
      const o = S.objects[S.jointIndex[k]];
      const prismatic = o.joint.type === 'prismatic';
      const toUi = prismatic ? (v) => v * 1000 : deg, fromUi = prismatic ? (v) => v / 1000 : rad;
      const lim = o.joint.limits && !o.joint.cyclic ? o.joint.limits.map(toUi) : prismatic ? [-1000, 1000] : [-180, 180];
      const readOnly = o.joint.mode === 'velocity';
      const slider = el('input', { type: 'range', min: lim[0], max: lim[1], step: prismatic ? 1 : 0.1, disabled: readOnly, title: `${o.path} (J${n + 1})` });
      const num = el('input', { type: 'number', min: lim[0], max: lim[1], step: prismatic ? 1 : 0.1, disabled: readOnly });
      const row = { k, n, robot: ks, slider, box: num, toUi, fromUi, busy: false, readOnly };
      const rowEl = el('div', { class: 'joint-row', 'data-joint': o.path, 'data-fk': `J${n + 1}` },
        el('span', { class: 'name', text: `J${n + 1} ${o.alias}`, title: o.path }), slider, num);
      if (readOnly) {
        row.info = el('span', { class: 'unit', text: '' });
        rowEl.append(row.info);
      }
      // While the user drags or types, live values do not fight the input.
      slider.addEventListener('pointerdown', () => { row.busy = true; });
      slider.addEventListener('pointerup', () => { row.busy = false; });
      slider.addEventListener('input', () => { num.value = slider.value; sendFk(row, false); });
      slider.addEventListener('change', () => { num.value = slider.value; row.busy = false; sendFk(row, true); });
      num.addEventListener('focus', () => { row.busy = true; });
      num.addEventListener('blur', () => { row.busy = false; });
      num.addEventListener('change', () => { slider.value = num.value; sendFk(row, true); });
      jointRows.push(row);
      box.append(rowEl);
    });
    if (!settable) box.append(el('div', { class: 'muted', text: 'velocity-controlled: shown live, set by its script' }));
    panels.push(box);
  }
  $('joint-panels').replaceChildren(...(panels.length ? panels : [el('div', { class: 'muted', text: 'No joints.' })]));
  updateJointPanels();
}

// How long a row keeps the user's value after the server acknowledged it, so a tick
// sent before the packet took effect cannot snap the slider back.
const HOLD_MS = 400;

export function updateJointPanels() {
  const now = performance.now();
  for (const row of jointRows) {
    const v = S.joints[row.k];
    if (v == null) continue;
    const held = row.inFlight || row.wanted || now - (row.ackAt || 0) < HOLD_MS;
    if (!row.busy && !held && document.activeElement !== row.box) {
      const shown = row.toUi(v);
      row.slider.value = shown;
      row.box.value = shown.toFixed(1);
    }
    if (row.info) row.info.textContent = `target speed ${fmt(deg(S.jointVel[row.k] ?? NaN), 1)}°/s`;
  }
}

// Sends <FK#J1=..,...> for the row's robot, in radians (metres for prismatic joints).
// While dragging, at most one packet is in flight; the last position always goes out.
function sendFk(row, final) {
  row.wanted = true;
  if (row.inFlight) return;
  const values = jointRows.filter((r) => r.robot === row.robot).map((r) => {
    // The moved row, and any other the user holds, send what the user chose.
    const own = r === row || r.busy || r.inFlight || r.wanted || performance.now() - (r.ackAt || 0) < HOLD_MS;
    const v = own ? r.fromUi(parseFloat(r.slider.value)) : S.joints[r.k] ?? 0;
    return `J${r.n + 1}=${v.toFixed(6)}`;
  });
  const packet = `<FK#${values.join(',')}>`;
  row.wanted = false;
  row.inFlight = true;
  send({ op: 'packet', text: packet }, (r) => {
    row.inFlight = false;
    row.ackAt = performance.now();
    setReply($('fk-reply'), r);
    if (row.wanted) sendFk(row, final);
  });
}
