// Camera: orbit about a target point, Z up; or, when the user picks one in the HUD's
// viewpoint list, the view through one of the scene's cameras (CoppeliaSim's camera
// objects), following it as it moves.

import { S, changed } from './state.js';
import { canvas } from './gl.js';
import { $ } from './dom.js';
import { M4, add, scale3, rad } from './math.js';

// `through`: object index of the scene camera looked through, or null for the orbit.
export const cam = { target: [0, 0, 0.3], yaw: -2.2, pitch: 0.55, dist: 8, through: null };

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

// The scene camera looked through, if it still exists.
function throughCamera() {
  const o = cam.through == null ? null : S.objects[cam.through];
  return o && o.camera ? o : null;
}

export function eye() {
  const sc = throughCamera();
  if (sc) return [sc.world[12], sc.world[13], sc.world[14]];
  const c = Math.cos(cam.pitch);
  return add(cam.target, scale3([c * Math.cos(cam.yaw), c * Math.sin(cam.yaw), Math.sin(cam.pitch)], cam.dist));
}

export function viewProj() {
  const aspect = canvas.width / Math.max(1, canvas.height);
  const sc = throughCamera();
  if (sc) {
    // A CoppeliaSim camera looks along its +Z with +Y up (image right is its -X), and
    // its view angle spans the larger side of the view.
    const w = sc.world, e = eye();
    const z = [w[8], w[9], w[10]], y = [w[4], w[5], w[6]];
    const t = Math.tan(sc.camera.fov / 2);
    const fovy = aspect >= 1 ? 2 * Math.atan(t / aspect) : sc.camera.fov;
    return M4.multiply(M4.perspective(fovy, aspect, 0.01, 500), M4.lookAt(e, add(e, z), y));
  }
  const proj = M4.perspective(rad(45), aspect, Math.max(0.01, cam.dist * 0.01), cam.dist * 50 + 50);
  return M4.multiply(proj, M4.lookAt(eye(), cam.target, [0, 0, 1]));
}

// Back to the orbit (a drag or the wheel in the 3D view does this).
export function leaveCamera() {
  if (cam.through == null) return;
  cam.through = null;
  $('viewpoint').value = '';
  changed.view = true;
}

// The HUD's viewpoint list: the orbit, then the scene's cameras by path. Shown only
// when the scene has cameras.
export function buildViewpoints() {
  const select = $('viewpoint');
  const cameras = S.objects.filter((o) => o.camera);
  const kept = cameras.find((o) => o.handle === S.objects[cam.through]?.handle);
  cam.through = kept ? kept.index : null;
  select.replaceChildren(new Option('orbit view', ''));
  for (const o of cameras) select.append(new Option(`camera ${o.path || o.alias}`, String(o.index)));
  select.value = cam.through == null ? '' : String(cam.through);
  select.hidden = cameras.length === 0;
}

$('viewpoint').addEventListener('change', (e) => {
  cam.through = e.target.value === '' ? null : Number(e.target.value);
  changed.view = true;
});
