// The 3D view's mouse and the page's keys.

import { S, changed } from './state.js';
import { canvas } from './gl.js';
import { cam, eye, leaveCamera } from './camera.js';
import { add, cross, norm, rad, scale3, sub } from './math.js';
import { send } from './net.js';
import { pickAt } from './picking.js';

// Mouse: left drag orbits, right or shift drag pans, wheel zooms, a click picks.
let drag = null;
canvas.addEventListener('contextmenu', (e) => e.preventDefault());

// Keys pressed while nothing editable has the focus (click the 3D view first) go to the
// scripts as CoppeliaSim's key-press messages (sim.getSimulatorMessage), with its codes:
// a character's own code, the arrows 2007-2010; modifiers bit 0 ctrl, bit 1 shift.
const SPECIAL_KEYS = {
  ArrowUp: 2007, ArrowDown: 2008, ArrowLeft: 2009, ArrowRight: 2010,
  Enter: 13, Escape: 27, Backspace: 8, Tab: 9, Delete: 127,
};
document.addEventListener('keydown', (e) => {
  const t = e.target;
  const editable = t instanceof HTMLElement
    && (t.isContentEditable || ['INPUT', 'TEXTAREA', 'SELECT', 'BUTTON'].includes(t.tagName));
  if (editable || e.altKey || e.metaKey) return;
  const key = SPECIAL_KEYS[e.key] ?? ([...e.key].length === 1 ? e.key.codePointAt(0) : null);
  if (!key) return;
  // The page would scroll on arrows and the space bar.
  if (e.key.startsWith('Arrow') || e.key === ' ') e.preventDefault();
  send({ op: 'key', key, mods: (e.ctrlKey ? 1 : 0) | (e.shiftKey ? 2 : 0) });
});
canvas.addEventListener('pointerdown', (e) => {
  canvas.setPointerCapture(e.pointerId);
  drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey, moved: 0 };
});
canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  drag.moved += Math.abs(dx) + Math.abs(dy);
  // Orbiting or panning leaves a scene camera's view (a click still picks).
  if (drag.moved >= 4) leaveCamera();
  if (drag.pan) {
    // Move the target in the view plane, scaled so the point under the cursor follows.
    const f = norm(sub(cam.target, eye()));
    const right = norm(cross(f, [0, 0, 1]));
    const up = cross(right, f);
    const k = (2 * cam.dist * Math.tan(rad(22.5))) / canvas.clientHeight;
    cam.target = add(cam.target, add(scale3(right, -dx * k), scale3(up, dy * k)));
  } else {
    cam.yaw -= dx * 0.008;
    cam.pitch = Math.max(-1.55, Math.min(1.55, cam.pitch + dy * 0.008));
  }
  changed.view = true;
});
canvas.addEventListener('pointerup', (e) => {
  if (drag && drag.moved < 4) pickAt(e.clientX, e.clientY);
  drag = null;
});
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  leaveCamera();
  cam.dist = Math.max(0.05, Math.min(500, cam.dist * Math.exp(e.deltaY * 0.0012)));
  changed.view = true;
}, { passive: false });
canvas.addEventListener('dblclick', () => {
  if (S.selected >= 0) { leaveCamera(); cam.target = S.objects[S.selected].pose.slice(0, 3); changed.view = true; }
});
