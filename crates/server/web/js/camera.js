// Camera: orbit about a target point, Z up.

import { S } from './state.js';
import { canvas } from './gl.js';
import { M4, add, scale3, rad } from './math.js';

export const cam = { target: [0, 0, 0.3], yaw: -2.2, pitch: 0.55, dist: 8 };

export function fitCamera() {
  // Frame every shape except the floor.
  let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const o of S.objects) {
    if (!o.visuals || o.alias === 'Floor') continue;
    for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], o.pose[k]); hi[k] = Math.max(hi[k], o.pose[k]); }
  }
  if (!Number.isFinite(lo[0])) return;
  cam.target = scale3(add(lo, hi), 0.5);
  cam.dist = Math.max(1.5, 1.1 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
}

export function eye() {
  const c = Math.cos(cam.pitch);
  return add(cam.target, scale3([c * Math.cos(cam.yaw), c * Math.sin(cam.yaw), Math.sin(cam.pitch)], cam.dist));
}

export function viewProj() {
  const aspect = canvas.width / Math.max(1, canvas.height);
  const proj = M4.perspective(rad(45), aspect, Math.max(0.01, cam.dist * 0.01), cam.dist * 50 + 50);
  return M4.multiply(proj, M4.lookAt(eye(), cam.target, [0, 0, 1]));
}
