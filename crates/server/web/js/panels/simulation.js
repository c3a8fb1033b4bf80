// The simulation panel and the status bar: start/pause/stop/step, and the live state,
// time and rates from each tick.

import { S, changed } from '../state.js';
import { $, fmt, setBadge, showError } from '../dom.js';
import { send } from '../net.js';
import { updateJointPanels } from './joints.js';
import { showPick } from './selection.js';
import { prefillIk } from './ik.js';

for (const b of document.querySelectorAll('#controls button')) {
  b.addEventListener('click', () => send({ op: 'control', action: b.dataset.action }, (r) => { if (!r.ok) showError(r.text); }));
}

const STATES = { 0: ['stopped', 'bad'], 8: ['paused', 'warn'], 17: ['running', 'ok'] };
export function onTick(t) {
  const stateChanged = !S.tick || S.tick.state !== t.state;
  S.tick = t;
  if ('selected' in t) S.selectedOrientation = t.selected;
  if (t.joints) { S.joints = t.joints; S.jointVel = t.joint_target_velocities; }
  if (t.detections) { S.detections = t.detections; changed.stream = true; }
  // Text and inputs change at most PANEL_FPS: every DOM change repaints the page, which
  // without a GPU costs as much as a 3D frame. A new state shows at once.
  changed.panels = true;
  if (stateChanged) updatePanels();
}

export const PANEL_FPS = 10;
export let lastPanels = -Infinity;
export function updatePanels() {
  changed.panels = false;
  lastPanels = performance.now();
  const t = S.tick;
  if (!t) return;
  const [name, cls] = STATES[t.state] || [`state ${t.state}`, ''];
  setBadge($('state'), name, cls);
  $('simtime').textContent = fmt(t.time);
  $('rtf').textContent = t.state === 17 ? fmt(t.rtf, 2) : '–';
  $('sps').textContent = t.state === 17 ? fmt(t.steps_per_s, 0) : '–';
  updateJointPanels();
  if (S.selected >= 0) showPick(S.selected);
  if (S.ikTarget >= 0 && !S.ikPrefilled && S.objects[S.ikTarget].pose[6] !== 1) prefillIk();
}
