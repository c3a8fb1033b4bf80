// Geometry: triangle lists with positions and normals, built at their real size (no
// scaling in the model matrix, so normals stay right under the rigid transforms).

import { add, scale3, cross, sub } from './math.js';

export function boxGeometry([hx, hy, hz]) {
  const pos = [], nrm = [];
  const faces = [
    [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [[-1, 0, 0], [0, 0, 1], [0, 1, 0]],
    [[0, 1, 0], [0, 0, 1], [1, 0, 0]], [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
    [[0, 0, 1], [1, 0, 0], [0, 1, 0]], [[0, 0, -1], [0, 1, 0], [1, 0, 0]],
  ];
  const h = [hx, hy, hz];
  for (const [n, u, v] of faces) {
    const c = n.map((k, i) => k * h[i]);
    const U = u.map((k, i) => k * h[i]), V = v.map((k, i) => k * h[i]);
    const corner = (a, b) => add(c, add(scale3(U, a), scale3(V, b)));
    for (const [a, b] of [[-1, -1], [1, -1], [1, 1], [-1, -1], [1, 1], [-1, 1]]) {
      pos.push(...corner(a, b));
      nrm.push(...n);
    }
  }
  return { pos, nrm };
}

// A surface of revolution about Z: `profile` is a list of [radius, z, normalR, normalZ].
function lathe(profile, segments = 32) {
  const pos = [], nrm = [];
  for (let i = 0; i < segments; i++) {
    const a0 = (i / segments) * 2 * Math.PI, a1 = ((i + 1) / segments) * 2 * Math.PI;
    const c0 = Math.cos(a0), s0 = Math.sin(a0), c1 = Math.cos(a1), s1 = Math.sin(a1);
    for (let j = 0; j + 1 < profile.length; j++) {
      const [r0, z0, nr0, nz0] = profile[j], [r1, z1, nr1, nz1] = profile[j + 1];
      const p = (r, z, c, s) => [r * c, r * s, z];
      const q = [
        [p(r0, z0, c0, s0), [nr0 * c0, nr0 * s0, nz0]], [p(r0, z0, c1, s1), [nr0 * c1, nr0 * s1, nz0]],
        [p(r1, z1, c1, s1), [nr1 * c1, nr1 * s1, nz1]], [p(r1, z1, c0, s0), [nr1 * c0, nr1 * s0, nz1]],
      ];
      for (const k of [0, 1, 2, 0, 2, 3]) { pos.push(...q[k][0]); nrm.push(...q[k][1]); }
    }
  }
  return { pos, nrm };
}

export function sphereGeometry(r, rings = 16) {
  const prof = [];
  for (let i = 0; i <= rings; i++) {
    const t = -Math.PI / 2 + (i / rings) * Math.PI;
    prof.push([r * Math.cos(t), r * Math.sin(t), Math.cos(t), Math.sin(t)]);
  }
  return lathe(prof);
}

export function cylinderGeometry(r, len) {
  const h = len / 2;
  return lathe([[0, -h, 0, -1], [r, -h, 0, -1], [r, -h, 1, 0], [r, h, 1, 0], [r, h, 0, 1], [0, h, 0, 1]]);
}

// A capsule along Z: `len` is the distance between the cap centres.
export function capsuleGeometry(r, len, rings = 8) {
  const h = len / 2, prof = [];
  for (let i = 0; i <= rings; i++) {
    const t = -Math.PI / 2 + (i / rings) * (Math.PI / 2);
    prof.push([r * Math.cos(t), -h + r * Math.sin(t), Math.cos(t), Math.sin(t)]);
  }
  for (let i = 0; i <= rings; i++) {
    const t = (i / rings) * (Math.PI / 2);
    prof.push([r * Math.cos(t), h + r * Math.sin(t), Math.cos(t), Math.sin(t)]);
  }
  return lathe(prof);
}

// A proximity sensor's cone (apex at the sensor, along +Z) between `offset` and
// `offset + range`, as CoppeliaSim draws it.
export function coneVolume(offset, range, halfAngle) {
  const t = Math.tan(Math.min(halfAngle, 1.5));
  const z0 = offset, z1 = offset + range;
  const n = [Math.cos(halfAngle), -Math.sin(halfAngle)];
  return lathe([[z0 * t, z0, n[0], n[1]], [z1 * t, z1, n[0], n[1]], [z1 * t, z1, 0, 1], [0, z1, 0, 1]], 24);
}

// Edges (pairs of points, for gl.LINES) of a pyramid, cylinder or disc proximity volume,
// the sensor frame's +Z ahead: the shapes `sensor/proximity_volume/polytope.rs` detects in.
export function volumeEdges(p) {
  const out = [];
  const seg = (a, b) => out.push(...a, ...b);
  const ring = (pt, n, closed) => {
    for (let i = 0; i < n - (closed ? 0 : 1); i++) seg(pt(i), pt((i + 1) % n));
  };
  if (p.shape === 'pyramid') {
    const z0 = p.offset, z1 = p.offset + p.range;
    const c = [[-1, -1], [1, -1], [1, 1], [-1, 1]];
    const near = (i) => [c[i][0] * p.near_size[0] / 2, c[i][1] * p.near_size[1] / 2, z0];
    const far = (i) => [c[i][0] * p.far_size[0] / 2, c[i][1] * p.far_size[1] / 2, z1];
    ring(near, 4, true); ring(far, 4, true);
    for (let i = 0; i < 4; i++) seg(near(i), far(i));
  } else if (p.shape === 'cylinder') {
    const n = 32, z0 = p.offset, z1 = p.offset + p.range;
    const at = (r, z) => (i) => [r * Math.cos(2 * Math.PI * i / n), r * Math.sin(2 * Math.PI * i / n), z];
    ring(at(p.radius, z0), n, true); ring(at(p.radius_far, z1), n, true);
    for (let i = 0; i < n; i += 8) seg(at(p.radius, z0)(i), at(p.radius_far, z1)(i));
  } else if (p.shape === 'disc') {
    const n = 33, a = p.half_angle, r0 = p.offset, r1 = p.offset + p.range;
    for (const y of [-p.thickness / 2, p.thickness / 2]) {
      const at = (r) => (i) => { const t = -a + 2 * a * i / (n - 1); return [r * Math.sin(t), y, r * Math.cos(t)]; };
      ring(at(r0), n, false); ring(at(r1), n, false);
      seg(at(r0)(0), at(r1)(0)); seg(at(r0)(n - 1), at(r1)(n - 1));
    }
  }
  return out;
}

// Smooth normals for an indexed mesh (vertex normals averaged over faces).
export function meshNormals(pos, idx) {
  const nrm = new Float32Array(pos.length);
  for (let i = 0; i < idx.length; i += 3) {
    const [a, b, c] = [idx[i] * 3, idx[i + 1] * 3, idx[i + 2] * 3];
    const pa = [pos[a], pos[a + 1], pos[a + 2]];
    const n = cross(sub([pos[b], pos[b + 1], pos[b + 2]], pa), sub([pos[c], pos[c + 1], pos[c + 2]], pa));
    for (const v of [a, b, c]) { nrm[v] += n[0]; nrm[v + 1] += n[1]; nrm[v + 2] += n[2]; }
  }
  for (let i = 0; i < nrm.length; i += 3) {
    const l = Math.hypot(nrm[i], nrm[i + 1], nrm[i + 2]) || 1;
    nrm[i] /= l; nrm[i + 1] /= l; nrm[i + 2] /= l;
  }
  return nrm;
}
