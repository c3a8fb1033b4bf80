// The scene as the server describes it: the scene message (objects, visuals, joints,
// sensors) and the binary messages that follow it (the first little-endian u32 says
// which: 1 pose, drawing and point-cloud deltas, 2 a vision image, 3 a mesh, 6 a
// textured part, 7 a texture image).

import { S, changed } from './state.js';
import { M4 } from './math.js';
import { gl, makeDrawable, makeCloudDrawable, makeTexture, freeDrawable } from './gl.js';
import { boxGeometry, sphereGeometry, cylinderGeometry, capsuleGeometry, coneVolume, volumeEdges, meshNormals } from './geometry.js';
import { buildViewpoints, fitCamera } from './camera.js';
import { buildTree } from './panels/selection.js';
import { buildJointPanels } from './panels/joints.js';
import { buildVisionPanels, onDepth, onImage, onMask } from './panels/vision.js';

export function onScene(msg) {
  for (const o of S.objects) for (const v of o.visuals || []) { freeDrawable(v.drawable); freeDrawable(v.texDrawable); }
  for (const t of S.textures) if (t && gl) gl.deleteTexture(t);
  S.textures = new Array(msg.textures || 0).fill(null);
  for (const d of S.drawings.values()) freeDrawable(d.drawable);
  S.drawings.clear();
  // The server sends every point cloud again after a scene description.
  for (const c of S.clouds.values()) freeDrawable(c.drawable);
  S.clouds.clear();
  S.scene = msg;
  S.meshes = new Array(msg.meshes).fill(null);
  S.jointIndex = [];
  S.proxIndex = [];
  S.byHandle = new Map();
  S.objects = msg.objects.map((o, i) => {
    const obj = { ...o, index: i, pose: [0, 0, 0, 0, 0, 0, 1], world: M4.identity(), children: [] };
    S.byHandle.set(o.handle, obj);
    if (o.kind === 'joint') S.jointIndex.push(i);
    if (o.kind === 'proximity sensor') S.proxIndex.push(i);
    if (o.visuals) {
      obj.visuals = o.visuals.map((v) => ({ ...v, localM: M4.fromPose(v.local), drawable: null, texDrawable: null }));
      for (const v of obj.visuals) if (v.geom !== 'mesh' && gl) v.drawable = primitiveDrawable(v);
    }
    if (o.proximity && gl) {
      const p = o.proximity;
      if (p.shape === 'cone') {
        const g = coneVolume(p.offset, p.range, p.half_angle);
        obj.volume = makeDrawable(g.pos, g.nrm);
      } else if (p.shape === 'ray') {
        obj.volume = makeDrawable([0, 0, p.offset, 0, 0, p.offset + p.range], null, null, gl.LINES);
      } else {
        obj.volume = makeDrawable(volumeEdges(p), null, null, gl.LINES);
      }
    }
    return obj;
  });
  for (const o of S.objects) if (o.parent != null) S.objects[o.parent].children.push(o.index);
  S.selected = -1;
  buildTree();
  buildJointPanels();
  buildVisionPanels();
  buildViewpoints();
  const target = S.objects.find((o) => o.alias === 'target' && o.kind === 'dummy');
  S.ikTarget = target ? target.index : -1;
  S.ikPrefilled = false;
  S.needFit = true;  // once the first poses arrive
  changed.view = true;
}

function primitiveDrawable(v) {
  let g;
  switch (v.geom) {
    case 'box': g = boxGeometry(v.half_extents); break;
    case 'sphere': g = sphereGeometry(v.radius); break;
    case 'cylinder': g = cylinderGeometry(v.radius, v.length); break;
    case 'capsule': g = capsuleGeometry(v.radius, v.length); break;
    default: return null;
  }
  return makeDrawable(g.pos, g.nrm);
}

// Binary messages: the first little-endian u32 says which.
export function onBinary(buf) {
  const dv = new DataView(buf);
  const type = dv.getUint32(0, true);
  if (type === 1) onFrame(dv);
  else if (type === 2) onImage(dv, buf);
  else if (type === 3) onMesh(dv, buf);
  else if (type === 4) onDepth(dv, buf);
  else if (type === 5) onMask(dv, buf);
  else if (type === 6) onTexturedPart(dv, buf);
  else if (type === 7) onTexture(dv, buf);
}

// A textured visual's triangles with u, v per corner (the server's, as vision sensors
// draw them), shaded per face.
function onTexturedPart(dv, buf) {
  const id = dv.getUint32(4, true), n = dv.getUint32(8, true);
  const pos = new Float32Array(buf.slice(12, 12 + n * 12));
  const uv = new Float32Array(buf.slice(12 + n * 12, 12 + n * 20));
  const d = gl && makeDrawable(pos, null, null, gl.TRIANGLES, uv);
  if (d) d.flat = true;
  for (const o of S.objects) for (const v of o.visuals || []) if (v.texture && v.texture.part === id) v.texDrawable = d;
  changed.view = true;
}

// A texture image: RGBA, rows from the bottom.
function onTexture(dv, buf) {
  const i = dv.getUint32(4, true), w = dv.getUint32(8, true), h = dv.getUint32(12, true);
  if (!gl || i >= S.textures.length) return;
  S.textures[i] = makeTexture(w, h, new Uint8Array(buf, 16, w * h * 4));
  changed.view = true;
}

function onMesh(dv, buf) {
  const id = dv.getUint32(4, true), nv = dv.getUint32(8, true), nt = dv.getUint32(12, true);
  const pos = new Float32Array(buf.slice(16, 16 + nv * 12));
  const idx = new Uint32Array(buf.slice(16 + nv * 12, 16 + nv * 12 + nt * 12));
  const d = gl && makeDrawable(pos, meshNormals(pos, idx), idx);
  if (d) d.flat = true;
  // Visuals share one upload per mesh.
  for (const o of S.objects) for (const v of o.visuals || []) if (v.geom === 'mesh' && v.mesh === id) v.drawable = d;
  changed.view = true;
}

function onFrame(dv) {
  const nPoses = dv.getUint32(4, true), nDrawings = dv.getUint32(8, true), nClouds = dv.getUint32(12, true);
  let off = 16;
  for (let i = 0; i < nPoses; i++) {
    const idx = dv.getUint32(off, true);
    const p = [];
    for (let k = 0; k < 7; k++) p.push(dv.getFloat32(off + 4 + 4 * k, true));
    off += 32;
    const o = S.objects[idx];
    if (o) { o.pose = p; o.world = M4.fromPose(p); }
  }
  for (let i = 0; i < nDrawings; i++) {
    const handle = dv.getUint32(off, true), kind = dv.getUint32(off + 4, true);
    const size = dv.getFloat32(off + 8, true);
    const color = [dv.getFloat32(off + 12, true), dv.getFloat32(off + 16, true), dv.getFloat32(off + 20, true)];
    const n = dv.getUint32(off + 24, true);
    const verts = new Float32Array(dv.buffer.slice(off + 28, off + 28 + n * 12));
    off += 28 + n * 12;
    const old = S.drawings.get(handle);
    if (old) freeDrawable(old.drawable);
    if (kind === 255) { S.drawings.delete(handle); continue; }
    const mode = { 1: gl.LINES, 2: gl.TRIANGLES, 8: gl.LINE_STRIP }[kind] ?? gl.POINTS;
    S.drawings.set(handle, { kind, size, color, drawable: n ? makeDrawable(verts, null, null, mode) : null });
  }
  for (let i = 0; i < nClouds; i++) {
    const handle = dv.getUint32(off, true), flag = dv.getUint32(off + 4, true);
    const size = dv.getFloat32(off + 8, true), n = dv.getUint32(off + 12, true);
    const pos = new Float32Array(dv.buffer.slice(off + 16, off + 16 + n * 12));
    const rgb = new Uint8Array(dv.buffer.slice(off + 16 + n * 12, off + 16 + n * 15));
    off += 16 + n * 12 + Math.ceil((n * 3) / 4) * 4;
    const old = S.clouds.get(handle);
    if (old) freeDrawable(old.drawable);
    if (flag === 255) { S.clouds.delete(handle); continue; }
    S.clouds.set(handle, { size, count: n, drawable: n && gl ? makeCloudDrawable(pos, rgb) : null });
  }
  S.frameMessages++;
  if (S.needFit && nPoses) { S.needFit = false; fitCamera(); changed.view = true; }
  changed.panels = true;  // the selection's live pose
  changed.stream = true;
}
