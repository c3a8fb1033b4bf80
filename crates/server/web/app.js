// gantry viewer: a WebGL2 3D view of the simulation and its control panels.
//
// Plain JavaScript, no framework, no build step: gantry embeds this file in its binary.
// The server protocol (see crates/server/src/http/) over one WebSocket at /ws:
//   server -> page  text   {"t":"scene"}   object tree (paths included), visuals, joints, sensors (once)
//                          {"t":"tick"}    time, state, rates, joints, detections, picked object's Euler angles
//                          {"t":"panels"}  scripts, log, custom UIs, graph samples
//                          {"t":"reply"}   answer to a command (matched by id)
//                   binary u32 type 1: pose, drawing and point-cloud deltas, 2: vision image, 3: mesh
//   page -> server  text   {"id","op":"control"|"packet"|"ui"|"reload"|"debug"|"key"|"select",...}
// World frame: Z up, metres, radians; poses are [x, y, z, qx, qy, qz, qw].
'use strict';

// ---------------------------------------------------------------------------------------
// Small matrix library: 4x4 column-major Float32Arrays, as WebGL wants them.

const M4 = {
  identity() {
    const m = new Float32Array(16);
    m[0] = m[5] = m[10] = m[15] = 1;
    return m;
  },
  multiply(a, b) {
    const o = new Float32Array(16);
    for (let c = 0; c < 4; c++) {
      for (let r = 0; r < 4; r++) {
        let s = 0;
        for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
        o[c * 4 + r] = s;
      }
    }
    return o;
  },
  // Rigid transform from a pose [x, y, z, qx, qy, qz, qw].
  fromPose(p) {
    const [x, y, z, qx, qy, qz, qw] = p;
    const xx = qx * qx, yy = qy * qy, zz = qz * qz;
    const xy = qx * qy, xz = qx * qz, yz = qy * qz, wx = qw * qx, wy = qw * qy, wz = qw * qz;
    return new Float32Array([
      1 - 2 * (yy + zz), 2 * (xy + wz), 2 * (xz - wy), 0,
      2 * (xy - wz), 1 - 2 * (xx + zz), 2 * (yz + wx), 0,
      2 * (xz + wy), 2 * (yz - wx), 1 - 2 * (xx + yy), 0,
      x, y, z, 1,
    ]);
  },
  perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    const m = new Float32Array(16);
    m[0] = f / aspect; m[5] = f; m[10] = (far + near) * nf; m[11] = -1; m[14] = 2 * far * near * nf;
    return m;
  },
  lookAt(eye, target, up) {
    const z = norm(sub(eye, target));
    const x = norm(cross(up, z));
    const y = cross(z, x);
    return new Float32Array([
      x[0], y[0], z[0], 0,
      x[1], y[1], z[1], 0,
      x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1,
    ]);
  },
};
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale3 = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; };

const deg = (rad) => rad * 180 / Math.PI;
const rad = (d) => d * Math.PI / 180;
const fmt = (v, n = 3) => (Number.isFinite(v) ? v.toFixed(n) : '–');
const $ = (id) => document.getElementById(id);

// Creates an element with attributes/properties and children.
function el(tag, props = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else if (k.startsWith('data-') || k === 'title' || k === 'for') e.setAttribute(k, v);
    else e[k] = v;
  }
  for (const c of children) if (c != null) e.append(c);
  return e;
}

// ---------------------------------------------------------------------------------------
// Geometry: triangle lists with positions and normals, built at their real size (no
// scaling in the model matrix, so normals stay right under the rigid transforms).

function boxGeometry([hx, hy, hz]) {
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

function sphereGeometry(r, rings = 16) {
  const prof = [];
  for (let i = 0; i <= rings; i++) {
    const t = -Math.PI / 2 + (i / rings) * Math.PI;
    prof.push([r * Math.cos(t), r * Math.sin(t), Math.cos(t), Math.sin(t)]);
  }
  return lathe(prof);
}

function cylinderGeometry(r, len) {
  const h = len / 2;
  return lathe([[0, -h, 0, -1], [r, -h, 0, -1], [r, -h, 1, 0], [r, h, 1, 0], [r, h, 0, 1], [0, h, 0, 1]]);
}

// A capsule along Z: `len` is the distance between the cap centres.
function capsuleGeometry(r, len, rings = 8) {
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
function coneVolume(offset, range, halfAngle) {
  const t = Math.tan(Math.min(halfAngle, 1.5));
  const z0 = offset, z1 = offset + range;
  const n = [Math.cos(halfAngle), -Math.sin(halfAngle)];
  return lathe([[z0 * t, z0, n[0], n[1]], [z1 * t, z1, n[0], n[1]], [z1 * t, z1, 0, 1], [0, z1, 0, 1]], 24);
}

// Smooth normals for an indexed mesh (vertex normals averaged over faces).
function meshNormals(pos, idx) {
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

// ---------------------------------------------------------------------------------------
// Renderer.

// Whether WebGL renders on the CPU (no GPU: SwiftShader, llvmpipe), asked of a probe
// context, because antialiasing must be chosen when the real context is created: on
// the CPU, 4x multisampling quadruples the cost of every frame.
function softwareRenderer() {
  const probe = document.createElement('canvas').getContext('webgl2');
  if (!probe) return false;
  const info = probe.getExtension('WEBGL_debug_renderer_info');
  const renderer = String(info ? probe.getParameter(info.UNMASKED_RENDERER_WEBGL) : probe.getParameter(probe.RENDERER));
  probe.getExtension('WEBGL_lose_context')?.loseContext();
  return /swiftshader|llvmpipe|softpipe|software/i.test(renderer);
}
const SOFTWARE_GL = softwareRenderer();
const canvas = $('gl');
const gl = canvas.getContext('webgl2', { antialias: !SOFTWARE_GL });

const LIT_VS = `#version 300 es
layout(location=0) in vec3 aPos;
layout(location=1) in vec3 aNrm;
uniform mat4 uViewProj, uModel;
out vec3 vNrm; out vec3 vWorld;
void main() {
  vec4 w = uModel * vec4(aPos, 1.0);
  vWorld = w.xyz;
  vNrm = mat3(uModel) * aNrm;   // rigid transforms only: no inverse-transpose needed
  gl_Position = uViewProj * w;
}`;
const LIT_FS = `#version 300 es
precision highp float;
in vec3 vNrm; in vec3 vWorld;
uniform vec3 uColor, uEye; uniform float uAlpha, uHighlight; uniform int uFlat;
out vec4 outColor;
void main() {
  // Meshes from URDFs may share vertices across sharp edges: shade them per face.
  vec3 n = uFlat == 1 ? cross(dFdx(vWorld), dFdy(vWorld)) : vNrm;
  n = normalize(n);
  vec3 v = normalize(uEye - vWorld);
  if (dot(n, v) < 0.0) n = -n;     // two-sided
  vec3 key = normalize(vec3(0.4, 0.3, 1.0));
  float diffuse = 0.55 * max(dot(n, key), 0.0) + 0.3 * max(dot(n, v), 0.0);
  float sky = 0.25 + 0.1 * n.z;   // hemisphere ambient: a little brighter from above
  vec3 c = uColor * (sky + diffuse);
  c = mix(c, vec3(1.0, 0.75, 0.2), uHighlight * 0.45);
  outColor = vec4(c, uAlpha);
}`;
const FLAT_VS = `#version 300 es
layout(location=0) in vec3 aPos;
uniform mat4 uViewProj, uModel; uniform float uPointSize;
void main() { gl_Position = uViewProj * uModel * vec4(aPos, 1.0); gl_PointSize = uPointSize; }`;
const FLAT_FS = `#version 300 es
precision highp float;
uniform vec4 uColor;
out vec4 outColor;
void main() { outColor = uColor; }`;

// Point clouds: a colour per point (RGB bytes, normalised).
const CLOUD_VS = `#version 300 es
layout(location=0) in vec3 aPos;
layout(location=1) in vec3 aCol;
uniform mat4 uViewProj, uModel; uniform float uPointSize;
out vec3 vCol;
void main() { gl_Position = uViewProj * uModel * vec4(aPos, 1.0); gl_PointSize = uPointSize; vCol = aCol; }`;
const CLOUD_FS = `#version 300 es
precision highp float;
in vec3 vCol;
out vec4 outColor;
void main() { outColor = vec4(vCol, 1.0); }`;

function compile(vs, fs) {
  const prog = gl.createProgram();
  for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    gl.attachShader(prog, s);
  }
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  const uniforms = {};
  for (let i = 0; i < gl.getProgramParameter(prog, gl.ACTIVE_UNIFORMS); i++) {
    const name = gl.getActiveUniform(prog, i).name;
    uniforms[name] = gl.getUniformLocation(prog, name);
  }
  return { prog, u: uniforms };
}

// A drawable: a vertex array with positions (and normals), optionally indexed.
function makeDrawable(pos, nrm, idx, mode) {
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  const buf = (data, loc) => {
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, data instanceof Float32Array ? data : new Float32Array(data), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
    return b;
  };
  const buffers = [buf(pos, 0)];
  if (nrm) buffers.push(buf(nrm, 1));
  let count = pos.length / 3;
  if (idx) {
    const ib = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    buffers.push(ib);
    count = idx.length;
  }
  gl.bindVertexArray(null);
  return { vao, buffers, count, indexed: !!idx, mode: mode ?? gl.TRIANGLES };
}

// A point cloud's drawable: positions (cloud frame) and RGB bytes, one per point.
function makeCloudDrawable(pos, rgb) {
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  const pb = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, pb);
  gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW);
  gl.enableVertexAttribArray(0);
  gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
  const cb = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, cb);
  gl.bufferData(gl.ARRAY_BUFFER, rgb, gl.STATIC_DRAW);
  gl.enableVertexAttribArray(1);
  gl.vertexAttribPointer(1, 3, gl.UNSIGNED_BYTE, true, 0, 0);
  gl.bindVertexArray(null);
  return { vao, buffers: [pb, cb], count: pos.length / 3, indexed: false, mode: gl.POINTS };
}

function freeDrawable(d) {
  if (!d) return;
  gl.deleteVertexArray(d.vao);
  for (const b of d.buffers) gl.deleteBuffer(b);
}

let lit, flat, cloud;
const glError = gl ? null : 'WebGL2 is not available in this browser';
if (gl) {
  lit = compile(LIT_VS, LIT_FS);
  flat = compile(FLAT_VS, FLAT_FS);
  cloud = compile(CLOUD_VS, CLOUD_FS);
}

// The floor grid: 0.5 m lines over +-10 m, just above the floor's top face (z = 0).
function gridDrawable() {
  const p = [];
  for (let i = -20; i <= 20; i++) {
    const v = i * 0.5;
    p.push(v, -10, 0.001, v, 10, 0.001, -10, v, 0.001, 10, v, 0.001);
  }
  return makeDrawable(p, null, null, gl.LINES);
}
const AXES = gl && makeDrawable([0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1], null, null, gl.LINES);
const GRID = gl && gridDrawable();

// ---------------------------------------------------------------------------------------
// Scene state, filled by the server's messages.

const S = {
  scene: null,          // the scene message
  objects: [],          // per object: {handle, alias, path, parent, kind, pose, world, visuals, ...}
  byHandle: new Map(),
  meshes: [],           // mesh id -> {pos, idx} until a visual uploads it
  jointIndex: [],       // joint k -> object index
  proxIndex: [],        // proximity sensor k -> object index
  joints: [],           // live joint positions (rad or m)
  jointVel: [],         // joint target velocities
  detections: [],
  drawings: new Map(),  // handle -> {kind, size, color, drawable}
  clouds: new Map(),    // point cloud object handle -> {size, count, drawable} (points in its frame)
  selected: -1,
  selectedOrientation: null,  // {handle, euler: [a, b, g] rad}: the server's, for the pick panel
  tick: null,
  framesRendered: 0,
  frameMessages: 0,
  images: 0,
};
// For tests and the curious: `window.gantry` shows the page's live state.
window.gantry = S;

function onScene(msg) {
  for (const o of S.objects) for (const v of o.visuals || []) freeDrawable(v.drawable);
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
      obj.visuals = o.visuals.map((v) => ({ ...v, localM: M4.fromPose(v.local), drawable: null }));
      for (const v of obj.visuals) if (v.geom !== 'mesh' && gl) v.drawable = primitiveDrawable(v);
    }
    if (o.proximity && gl) {
      const p = o.proximity;
      obj.volume = p.shape === 'cone'
        ? (() => { const g = coneVolume(p.offset, p.range, p.half_angle); return makeDrawable(g.pos, g.nrm); })()
        : makeDrawable([0, 0, p.offset, 0, 0, p.offset + p.range], null, null, gl.LINES);
    }
    return obj;
  });
  for (const o of S.objects) if (o.parent != null) S.objects[o.parent].children.push(o.index);
  S.selected = -1;
  buildTree();
  buildJointPanels();
  buildVisionPanels();
  const target = S.objects.find((o) => o.alias === 'target' && o.kind === 'dummy');
  S.ikTarget = target ? target.index : -1;
  S.ikPrefilled = false;
  S.needFit = true;  // once the first poses arrive
  dirty = true;
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
function onBinary(buf) {
  const dv = new DataView(buf);
  const type = dv.getUint32(0, true);
  if (type === 1) onFrame(dv);
  else if (type === 2) onImage(dv, buf);
  else if (type === 3) onMesh(dv, buf);
}

function onMesh(dv, buf) {
  const id = dv.getUint32(4, true), nv = dv.getUint32(8, true), nt = dv.getUint32(12, true);
  const pos = new Float32Array(buf.slice(16, 16 + nv * 12));
  const idx = new Uint32Array(buf.slice(16 + nv * 12, 16 + nv * 12 + nt * 12));
  const d = gl && makeDrawable(pos, meshNormals(pos, idx), idx);
  if (d) d.flat = true;
  // Visuals share one upload per mesh.
  for (const o of S.objects) for (const v of o.visuals || []) if (v.geom === 'mesh' && v.mesh === id) v.drawable = d;
  dirty = true;
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
  if (S.needFit && nPoses) { S.needFit = false; fitCamera(); dirty = true; }
  panelDirty = true;  // the selection's live pose
  streamDirty = true;
}

// ---------------------------------------------------------------------------------------
// Camera: orbit about a target point, Z up.

const cam = { target: [0, 0, 0.3], yaw: -2.2, pitch: 0.55, dist: 8 };
let dirty = true;        // camera or selection changed: redraw at once
let streamDirty = false; // poses, drawings or sensors changed: redraw at most STREAM_FPS

function fitCamera() {
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

function eye() {
  const c = Math.cos(cam.pitch);
  return add(cam.target, scale3([c * Math.cos(cam.yaw), c * Math.sin(cam.yaw), Math.sin(cam.pitch)], cam.dist));
}

function viewProj() {
  const aspect = canvas.width / Math.max(1, canvas.height);
  const proj = M4.perspective(rad(45), aspect, Math.max(0.01, cam.dist * 0.01), cam.dist * 50 + 50);
  return M4.multiply(proj, M4.lookAt(eye(), cam.target, [0, 0, 1]));
}

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
  dirty = true;
});
canvas.addEventListener('pointerup', (e) => {
  if (drag && drag.moved < 4) pickAt(e.clientX, e.clientY);
  drag = null;
});
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  cam.dist = Math.max(0.05, Math.min(500, cam.dist * Math.exp(e.deltaY * 0.0012)));
  dirty = true;
}, { passive: false });
canvas.addEventListener('dblclick', () => {
  if (S.selected >= 0) { cam.target = S.objects[S.selected].pose.slice(0, 3); dirty = true; }
});

// ---------------------------------------------------------------------------------------
// Drawing.

function resize() {
  const dpr = Math.min(window.devicePixelRatio || 1, 2);
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; dirty = true; }
}

function drawWith(prog, d, model) {
  gl.uniformMatrix4fv(prog.u.uModel, false, model);
  gl.bindVertexArray(d.vao);
  if (d.indexed) gl.drawElements(d.mode, d.count, gl.UNSIGNED_INT, 0);
  else gl.drawArrays(d.mode, 0, d.count);
}

function render() {
  resize();
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(0.16, 0.18, 0.21, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  const vp = viewProj();
  const e = eye();

  // Opaque shapes.
  gl.useProgram(lit.prog);
  gl.uniformMatrix4fv(lit.u.uViewProj, false, vp);
  gl.uniform3fv(lit.u.uEye, e);
  gl.uniform1f(lit.u.uAlpha, 1);
  gl.disable(gl.BLEND);
  for (const o of S.objects) {
    if (!o.visuals) continue;
    gl.uniform1f(lit.u.uHighlight, o.index === S.selected ? 1 : 0);
    for (const v of o.visuals) {
      if (!v.drawable) continue;
      gl.uniform3fv(lit.u.uColor, v.color);
      gl.uniform1i(lit.u.uFlat, v.drawable.flat ? 1 : 0);
      drawWith(lit, v.drawable, M4.multiply(o.world, v.localM));
    }
  }

  // Lines and points: grid, drawing objects, selected frame.
  gl.useProgram(flat.prog);
  gl.uniformMatrix4fv(flat.u.uViewProj, false, vp);
  gl.uniform1f(flat.u.uPointSize, 1);
  gl.uniform4f(flat.u.uColor, 0.45, 0.5, 0.55, 1);
  drawWith(flat, GRID, M4.identity());
  const id = M4.identity();
  for (const d of S.drawings.values()) {
    if (!d.drawable) continue;
    // Sphere points have a size in metres: approximate them by a few pixels.
    gl.uniform1f(flat.u.uPointSize, d.kind === 7 ? 6 : Math.max(1, Math.min(32, d.size)));
    gl.uniform4f(flat.u.uColor, d.color[0], d.color[1], d.color[2], 1);
    drawWith(flat, d.drawable, id);
  }
  if (S.selected >= 0) {
    const o = S.objects[S.selected];
    const k = Math.max(0.05, cam.dist * 0.04);
    const m = M4.multiply(o.world, new Float32Array([k, 0, 0, 0, 0, k, 0, 0, 0, 0, k, 0, 0, 0, 0, 1]));
    gl.disable(gl.DEPTH_TEST);
    gl.uniformMatrix4fv(flat.u.uModel, false, m);
    gl.bindVertexArray(AXES.vao);
    for (const [i, c] of [[0, [1, 0.3, 0.3, 1]], [2, [0.3, 1, 0.3, 1]], [4, [0.4, 0.6, 1, 1]]]) {
      gl.uniform4fv(flat.u.uColor, c);
      gl.drawArrays(gl.LINES, i, 2);
    }
    gl.enable(gl.DEPTH_TEST);
  }

  // Point clouds, placed by their object's pose.
  gl.useProgram(cloud.prog);
  gl.uniformMatrix4fv(cloud.u.uViewProj, false, vp);
  for (const [handle, c] of S.clouds) {
    const o = S.byHandle.get(handle);
    if (!o || !c.drawable) continue;
    gl.uniform1f(cloud.u.uPointSize, Math.max(1, Math.min(32, c.size)));
    drawWith(cloud, c.drawable, o.world);
  }

  // Translucent sensor volumes last: red while detecting.
  gl.enable(gl.BLEND);
  gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
  gl.depthMask(false);
  S.proxIndex.forEach((oi, k) => {
    const o = S.objects[oi];
    if (!o.volume) return;
    const hit = S.detections[k] >= 0;
    const c = hit ? [1, 0.2, 0.15] : [0.3, 0.7, 1];
    if (o.volume.mode === gl.LINES) {
      gl.useProgram(flat.prog);
      gl.uniform4f(flat.u.uColor, c[0], c[1], c[2], 1);
      drawWith(flat, o.volume, o.world);
    } else {
      gl.useProgram(lit.prog);
      gl.uniform3fv(lit.u.uColor, c);
      gl.uniform1f(lit.u.uAlpha, hit ? 0.55 : 0.25);
      gl.uniform1f(lit.u.uHighlight, oi === S.selected ? 1 : 0);
      gl.uniform1i(lit.u.uFlat, 0);
      drawWith(lit, o.volume, o.world);
    }
  });
  gl.depthMask(true);
  gl.disable(gl.BLEND);
  gl.bindVertexArray(null);
  S.framesRendered++;
}

// Redraw only when something changed: an idle page costs nothing. Changes from the
// pose stream redraw at most STREAM_FPS (the stream is 20 Hz in real time, up to 60 Hz
// flat out). Without a GPU, WebGL renders on the CPU, often the one the simulator runs
// on (a headless lab server): there the stream redraws at 10 frames a second. Camera
// moves always redraw at the display rate.
const STREAM_FPS = SOFTWARE_GL ? 10 : 30;
S.softwareGl = SOFTWARE_GL;
let lastRender = -Infinity;
function loop(now) {
  if (panelDirty && now - lastPanels >= 1000 / PANEL_FPS - 2) updatePanels();
  if (gl && (dirty || (streamDirty && now - lastRender >= 1000 / STREAM_FPS - 2))) {
    dirty = streamDirty = false;
    lastRender = now;
    render();
  }
  requestAnimationFrame(loop);
}

// ---------------------------------------------------------------------------------------
// Picking: draw every pickable object with its index as colour, read one pixel.

let pickFbo = null;
function pickAt(clientX, clientY) {
  if (!gl) return;
  const r = canvas.getBoundingClientRect();
  const x = Math.floor(((clientX - r.left) / r.width) * canvas.width);
  const y = Math.floor((1 - (clientY - r.top) / r.height) * canvas.height);
  const w = canvas.width, h = canvas.height;
  if (!pickFbo || pickFbo.w !== w || pickFbo.h !== h) {
    if (pickFbo) { gl.deleteFramebuffer(pickFbo.fb); gl.deleteTexture(pickFbo.tex); gl.deleteRenderbuffer(pickFbo.depth); }
    const fb = gl.createFramebuffer(), tex = gl.createTexture(), depth = gl.createRenderbuffer();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, null);
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, w, h);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
    pickFbo = { fb, tex, depth, w, h };
  }
  gl.bindFramebuffer(gl.FRAMEBUFFER, pickFbo.fb);
  gl.viewport(0, 0, w, h);
  gl.clearColor(0, 0, 0, 0);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  gl.disable(gl.BLEND);
  gl.useProgram(flat.prog);
  gl.uniformMatrix4fv(flat.u.uViewProj, false, viewProj());
  const idColor = (i) => [((i + 1) & 255) / 255, (((i + 1) >> 8) & 255) / 255, (((i + 1) >> 16) & 255) / 255, 1];
  for (const o of S.objects) {
    gl.uniform4fv(flat.u.uColor, idColor(o.index));
    for (const v of o.visuals || []) if (v.drawable) drawWith(flat, v.drawable, M4.multiply(o.world, v.localM));
    if (o.volume && o.volume.mode !== gl.LINES) drawWith(flat, o.volume, o.world);
  }
  const px = new Uint8Array(4);
  gl.readPixels(x, y, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  const idx = px[0] + (px[1] << 8) + (px[2] << 16) - 1;
  select(idx >= 0 && idx < S.objects.length ? idx : -1);
}

// Where object `idx`'s origin (or the point `local`, m, in its frame) appears on the page
// (CSS pixels), or null when behind the camera: for tests and tools that want to click
// an object or look at it.
S.screenPosition = (idx, local = [0, 0, 0]) => {
  const w = S.objects[idx].world;
  const p = [0, 1, 2].map((r) => w[r] * local[0] + w[4 + r] * local[1] + w[8 + r] * local[2] + w[12 + r]);
  const m = viewProj();
  const c = [0, 1, 2, 3].map((r) => m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
  if (c[3] <= 0) return null;
  const r = canvas.getBoundingClientRect();
  return { x: r.left + ((c[0] / c[3] + 1) / 2) * r.width, y: r.top + ((1 - c[1] / c[3]) / 2) * r.height };
};

// The 3D view as a PNG data URL, drawn in the same task (the drawing buffer is not
// preserved between frames, which saves a copy per frame).
S.capture = () => { render(); return canvas.toDataURL('image/png'); };

// Selects object `idx` (-1: nothing) on the page and, unless the server asked for it,
// as the simulation's selection (sim.getObjectSel).
function select(idx, fromServer = false) {
  if (!fromServer) send({ op: 'select', handles: idx >= 0 ? [S.objects[idx].handle] : [] });
  S.selected = idx;
  for (const s of document.querySelectorAll('#object-tree span.selected')) s.classList.remove('selected');
  if (idx >= 0) document.querySelector(`#object-tree span[data-index="${idx}"]`)?.classList.add('selected');
  showPick(idx);
  dirty = true;
}

function showPick(idx) {
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

function buildTree() {
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

// ---------------------------------------------------------------------------------------
// WebSocket and commands.

let ws = null;
let nextId = 1;
const pending = new Map();  // command id -> callback(reply)

function send(cmd, onReply) {
  if (!ws || ws.readyState !== WebSocket.OPEN) { onReply?.({ ok: false, text: 'not connected' }); return; }
  const id = nextId++;
  if (onReply) pending.set(id, onReply);
  ws.send(JSON.stringify({ id, ...cmd }));
}

function connect() {
  ws = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => setBadge($('conn'), 'connected', 'ok');
  ws.onclose = () => {
    setBadge($('conn'), 'disconnected: retrying', 'bad');
    for (const cb of pending.values()) cb({ ok: false, text: 'disconnected' });
    pending.clear();
    setTimeout(connect, 1000);
  };
  ws.onmessage = (ev) => {
    if (typeof ev.data !== 'string') { onBinary(ev.data); return; }
    const msg = JSON.parse(ev.data);
    switch (msg.t) {
      case 'scene': onScene(msg); break;
      case 'tick': onTick(msg); break;
      case 'panels': onPanels(msg); break;
      case 'reply': {
        const cb = pending.get(msg.id);
        pending.delete(msg.id);
        if (cb) cb(msg); else if (!msg.ok) showError(msg.text);
        break;
      }
      case 'error': showError(msg.text); break;
      case 'debug': onDebug(msg.paused); break;
    }
  };
}

// gantry run --debug: a script stopped at a breakpoint holds the whole simulation.
function onDebug(paused) {
  const banner = $('debug-banner');
  banner.hidden = !paused;
  if (paused) $('debug-where').textContent = `paused in ${paused.script}:${paused.line} (${paused.reason})`;
}

for (const b of document.querySelectorAll('#debug-banner button')) {
  b.addEventListener('click', () => send({ op: 'debug', action: b.dataset.debug }, (r) => { if (!r.ok) showError(r.text); }));
}

function setBadge(e, text, cls) { e.textContent = text; e.className = `badge ${cls || ''}`; }

function showError(text) {
  const e = $('error');
  e.textContent = text;
  e.hidden = false;
  clearTimeout(showError.timer);
  showError.timer = setTimeout(() => { e.hidden = true; }, 6000);
}

for (const b of document.querySelectorAll('#controls button')) {
  b.addEventListener('click', () => send({ op: 'control', action: b.dataset.action }, (r) => { if (!r.ok) showError(r.text); }));
}

const STATES = { 0: ['stopped', 'bad'], 8: ['paused', 'warn'], 17: ['running', 'ok'] };
function onTick(t) {
  const stateChanged = !S.tick || S.tick.state !== t.state;
  S.tick = t;
  if ('selected' in t) S.selectedOrientation = t.selected;
  if (t.joints) { S.joints = t.joints; S.jointVel = t.joint_target_velocities; }
  if (t.detections) { S.detections = t.detections; streamDirty = true; }
  // Text and inputs change at most PANEL_FPS: every DOM change repaints the page, which
  // without a GPU costs as much as a 3D frame. A new state shows at once.
  panelDirty = true;
  if (stateChanged) updatePanels();
}

const PANEL_FPS = 10;
let panelDirty = false;
let lastPanels = -Infinity;
function updatePanels() {
  panelDirty = false;
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

// ---------------------------------------------------------------------------------------
// Joint panel: per robot (the model that holds the joints) a slider and a box per joint,
// in degrees (mm for prismatic joints) within the limits. Moving one sends the FK packet
// a TCP client would send, with every joint of that robot; the rows follow the live values.

const jointRows = [];  // {k (joint index), robot, slider, box, busy}

function robotOf(idx) {
  for (let o = S.objects[idx]; o; o = o.parent != null ? S.objects[o.parent] : null) {
    if (o.model_base) return o.index;
  }
  return -1;
}

function buildJointPanels() {
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

function updateJointPanels() {
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

function setReply(e, r) {
  e.textContent = r.text;
  e.className = `reply ${r.ok ? '' : 'bad'}`;
}

// IK panel: the target's position comes from the scene's `target` dummy.
function prefillIk() {
  const p = S.objects[S.ikTarget].pose;
  $('ik-tx').value = p[0].toFixed(3);
  $('ik-ty').value = p[1].toFixed(3);
  $('ik-tz').value = p[2].toFixed(3);
  S.ikPrefilled = true;
}
$('ik-form').addEventListener('submit', (e) => {
  e.preventDefault();
  const v = ['ik-tx', 'ik-ty', 'ik-tz'].map((id) => parseFloat($(id).value));
  if (v.some((x) => !Number.isFinite(x))) return;
  send({ op: 'packet', text: `<IK#TX=${v[0]},TY=${v[1]},TZ=${v[2]}>` }, (r) => setReply($('ik-reply'), r));
});

// ---------------------------------------------------------------------------------------
// Slower panels: scripts, log, custom UIs, graphs, vision images.

function onPanels(p) {
  if (p.scripts) showScripts(p.scripts);
  if (p.log) appendLog(p.log);
  if (p.uis) showUis(p.uis);
  if (p.views) showViews(p.views);
  if (p.selection) {
    // A script or client set the selection (sim.setObjectSel): show its first object.
    const idx = p.selection.length ? S.objects.findIndex((o) => o.handle === p.selection[0]) : -1;
    if (idx !== S.selected) select(idx, true);
  }
  if (p.graphs) addGraphSamples(p.graphs);
}

function showScripts(list) {
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
function appendLog(lines) {
  const log = $('log');
  const atBottom = log.scrollTop + log.clientHeight >= log.scrollHeight - 4;
  for (const l of lines) {
    const cls = l.verbosity <= 200 ? 'v200' : l.verbosity <= 300 ? 'v300' : '';
    log.append(el('div', { class: cls, text: `[${fmt(l.time, 2)} ${l.source}] ${l.message}` }));
  }
  while (log.childElementCount > MAX_LOG) log.firstElementChild.remove();
  if (atBottom) log.scrollTop = log.scrollHeight;
}

// Custom UIs (simUI) as HTML. A user action calls simUI.interact(ui, id, value) on the
// server, which queues the widget's callback for its script, as a click in CoppeliaSim.
const uiState = new Map();  // ui handle -> {sig, root, inputs: Map(id -> update fn)}

function showUis(uis) {
  const box = $('ui-windows');
  const seen = new Set();
  for (const ui of uis) {
    seen.add(ui.handle);
    // Rebuild only when the structure changed; otherwise update values in place so a
    // slider being dragged is not replaced under the pointer.
    const sig = JSON.stringify(ui, (k, v) => (k === 'value' || k === 'checked' ? undefined : v));
    let st = uiState.get(ui.handle);
    if (!st || st.sig !== sig) {
      st?.root.remove();
      st = { sig, inputs: new Map() };
      st.root = el('div', { class: 'ui-window', 'data-ui': String(ui.handle) },
        el('div', { class: 'title', text: ui.title }), buildContainer(ui, ui.content, st));
      uiState.set(ui.handle, st);
      box.append(st.root);
    }
    st.root.hidden = !ui.visible;
    for (const w of walkWidgets(ui.content)) st.inputs.get(w.id)?.(w);
  }
  for (const [h, st] of uiState) if (!seen.has(h)) { st.root.remove(); uiState.delete(h); }
  box.classList.toggle('muted', uiState.size === 0);
  if (uiState.size === 0) box.textContent = 'No custom UI yet.';
  else for (const n of [...box.childNodes]) if (n.nodeType === Node.TEXT_NODE) n.remove();
}

function* walkWidgets(c) {
  for (const row of c.rows) for (const w of row) {
    yield w;
    if (w.content) yield* walkWidgets(w.content);
  }
}

function buildContainer(ui, c, st) {
  const box = el('div', { class: `ui-box ${c.layout}` });
  if (c.layout === 'grid' || c.layout === 'form') {
    const cols = Math.max(1, ...c.rows.map((r) => r.length));
    box.style.gridTemplateColumns = `repeat(${cols}, auto)`;
  }
  for (const row of c.rows) for (const w of row) box.append(buildWidget(ui, w, st));
  return box;
}

function buildWidget(ui, w, st) {
  const act = (value) => send({ op: 'ui', ui: ui.handle, widget: w.id, value }, (r) => { if (!r.ok) showError(r.text); });
  const attrs = { 'data-ui-widget': String(w.id), 'data-type': w.type };
  let e;
  switch (w.type) {
    case 'hslider':
    case 'vslider': {
      e = el('input', { ...attrs, type: 'range', min: w.minimum, max: w.maximum, step: 1 });
      let busy = false;
      e.addEventListener('pointerdown', () => { busy = true; });
      e.addEventListener('pointerup', () => { busy = false; });
      // simUI reports every position while dragging; coalesce to what the server takes.
      let last = null;
      e.addEventListener('input', () => { const v = parseInt(e.value, 10); if (v !== last) { last = v; act(v); } });
      e.addEventListener('change', () => { busy = false; const v = parseInt(e.value, 10); if (v !== last) { last = v; act(v); } });
      st.inputs.set(w.id, (nw) => { if (!busy && document.activeElement !== e) { e.value = nw.value; last = nw.value; } });
      break;
    }
    case 'button':
      e = el('button', { ...attrs, text: w.text, type: 'button' });
      e.addEventListener('click', () => act(null));
      break;
    case 'label':
      // Qt rich text is shown as plain text: never as HTML from a script.
      e = el('span', { ...attrs, text: w.text.replace(/<[^>]*>/g, '') });
      st.inputs.set(w.id, (nw) => { e.textContent = nw.text.replace(/<[^>]*>/g, ''); });
      break;
    case 'edit':
      e = el('input', { ...attrs, type: 'text' });
      e.addEventListener('keydown', (ev) => { if (ev.key === 'Enter') act(e.value); });
      st.inputs.set(w.id, (nw) => { if (document.activeElement !== e) e.value = nw.value; });
      break;
    case 'checkbox': {
      const input = el('input', { type: 'checkbox' });
      e = el('label', attrs, input, ` ${w.text}`);
      input.addEventListener('change', () => act(input.checked ? 2 : 0));
      st.inputs.set(w.id, (nw) => { input.checked = nw.value === 2; input.indeterminate = nw.value === 1; });
      break;
    }
    case 'radiobutton': {
      const input = el('input', { type: 'radio', name: `ui${ui.handle}` });
      e = el('label', attrs, input, ` ${w.text}`);
      input.addEventListener('click', () => act(null));
      st.inputs.set(w.id, (nw) => { input.checked = nw.checked; });
      break;
    }
    case 'spinbox':
      e = el('input', { ...attrs, type: 'number', min: w.minimum, max: w.maximum, step: w.float ? w.step : Math.max(1, Math.round(w.step)) });
      e.addEventListener('change', () => act(w.float ? parseFloat(e.value) : parseInt(e.value, 10)));
      st.inputs.set(w.id, (nw) => { if (document.activeElement !== e) e.value = nw.value; });
      break;
    case 'group':
      e = el('fieldset', attrs, w.flat ? null : el('legend', { text: w.text }), buildContainer(ui, w.content, st));
      break;
    case 'stretch':
      e = el('div', { ...attrs, class: 'stretch' });
      break;
    default:
      e = el('span', { ...attrs, class: 'muted', text: `(${w.type})` });
  }
  if (!w.enabled) { e.classList.add('disabled'); if ('disabled' in e) e.disabled = true; }
  if (!w.visible) e.hidden = true;
  return e;
}

// Graphs: one plot per graph object, every stream a coloured line; samples are kept up
// to MAX_POINTS per stream (the CSV link has all the server keeps).
const MAX_POINTS = 20000;
const graphs = new Map();  // graph handle -> {canvas, legend, streams: Map(id -> {label, color, t[], v[]})}

function addGraphSamples(updates) {
  const box = $('graph-plots');
  for (const u of updates) {
    let g = graphs.get(u.graph);
    if (!g) {
      if (graphs.size === 0) { box.textContent = ''; box.classList.remove('muted'); }
      const cv = el('canvas', { width: 340, height: 140 });
      const legend = el('div', { class: 'legend' });
      g = { canvas: cv, legend, streams: new Map() };
      box.append(el('div', { class: 'graph', 'data-graph': String(u.graph) }, legend, cv));
      graphs.set(u.graph, g);
    }
    let s = g.streams.get(u.id);
    if (!s || u.reset) { s = { t: [], v: [] }; g.streams.set(u.id, s); }
    Object.assign(s, { label: u.label, unit: u.unit, color: u.color });
    for (const [t, v] of u.samples) { s.t.push(t); s.v.push(v); }
    if (s.t.length > MAX_POINTS) { s.t.splice(0, s.t.length - MAX_POINTS); s.v.splice(0, s.v.length - MAX_POINTS); }
    g.alias = u.graph_alias;
    g.stale = true;
  }
  for (const [h, g] of graphs) if (g.stale) { g.stale = false; drawGraph(h, g); }
}

function drawGraph(handle, g) {
  const ctx = g.canvas.getContext('2d');
  const W = g.canvas.width, H = g.canvas.height, pad = 28;
  ctx.clearRect(0, 0, W, H);
  let t0 = Infinity, t1 = -Infinity, v0 = Infinity, v1 = -Infinity;
  for (const s of g.streams.values()) {
    if (!s.t.length) continue;
    t0 = Math.min(t0, s.t[0]); t1 = Math.max(t1, s.t[s.t.length - 1]);
    for (const v of s.v) { if (v < v0) v0 = v; if (v > v1) v1 = v; }
  }
  const css = (c) => `rgb(${c.map((x) => Math.round(x * 255)).join(',')})`;
  g.legend.replaceChildren(
    el('b', { text: g.alias || `graph ${handle}` }),
    ...[...g.streams.values()].map((s) => el('span', {}, el('span', { class: 'swatch', style: `background:${css(s.color)}` }),
      `${s.label}: ${fmt(s.v[s.v.length - 1])}`)),
    el('a', { href: `/api/graph/${handle}.csv`, download: `${g.alias || 'graph'}.csv`, text: 'CSV' }));
  if (!Number.isFinite(t0)) return;
  if (t1 - t0 < 1e-9) t1 = t0 + 1;
  if (v1 - v0 < 1e-9) { v0 -= 0.5; v1 += 0.5; }
  const X = (t) => pad + ((t - t0) / (t1 - t0)) * (W - pad - 6);
  const Y = (v) => H - 14 - ((v - v0) / (v1 - v0)) * (H - 22);
  ctx.strokeStyle = '#3a4047'; ctx.fillStyle = '#8b96a3'; ctx.font = '10px sans-serif';
  ctx.strokeRect(pad, 8, W - pad - 6, H - 22);
  ctx.fillText(fmt(v1, 2), 2, 14); ctx.fillText(fmt(v0, 2), 2, H - 14);
  ctx.fillText(`${fmt(t0, 1)} s`, pad, H - 2); ctx.fillText(`${fmt(t1, 1)} s`, W - 50, H - 2);
  for (const s of g.streams.values()) {
    ctx.strokeStyle = css(s.color);
    ctx.beginPath();
    // At most ~2 points per pixel column: long streams stay cheap to draw.
    const stride = Math.max(1, Math.floor(s.t.length / (2 * W)));
    for (let i = 0; i < s.t.length; i += stride) {
      if (i === 0) ctx.moveTo(X(s.t[i]), Y(s.v[i])); else ctx.lineTo(X(s.t[i]), Y(s.v[i]));
    }
    ctx.stroke();
  }
}

// Vision sensor images (RGB, bottom row first) as canvases.
const visionCanvases = new Map();
function buildVisionPanels() {
  visionCanvases.clear();
  const box = $('vision-images');
  const sensors = S.objects.filter((o) => o.vision);
  box.classList.toggle('muted', sensors.length === 0);
  if (!sensors.length) { box.textContent = 'No vision sensor.'; return; }
  box.replaceChildren(...sensors.map((o) => {
    const [w, h] = o.vision.resolution;
    const cv = el('canvas', { width: w, height: h, title: o.path });
    visionCanvases.set(o.handle, cv);
    return el('figure', { class: 'vision', 'data-sensor': String(o.handle) }, cv, el('figcaption', { text: `${o.alias} ${w}×${h}` }));
  }));
}

// Floating views (sim.floatingViewAdd / adjustView): overlays on the 3D view that mirror
// a vision sensor's image. Centre and size are relative to the view, from the bottom left.
const viewCanvases = new Map();  // sensor handle -> overlay canvases
function showViews(views) {
  viewCanvases.clear();
  $('views').replaceChildren(...views.map((v) => {
    const cv = el('canvas', { width: 1, height: 1 });
    const fig = el('figure', { class: 'fview', 'data-view': String(v.handle) }, cv,
      el('figcaption', { text: v.label || (v.object === null ? 'no view' : `object ${v.object}`) }));
    Object.assign(fig.style, {
      left: `${(v.centre[0] - v.size[0] / 2) * 100}%`, bottom: `${(v.centre[1] - v.size[1] / 2) * 100}%`,
      width: `${v.size[0] * 100}%`, height: `${v.size[1] * 100}%`,
    });
    if (v.object !== null) {
      if (!viewCanvases.has(v.object)) viewCanvases.set(v.object, []);
      viewCanvases.get(v.object).push(cv);
      mirror(v.object);
    }
    return fig;
  }));
}

// Copies a sensor's panel image into the floating views that show it.
function mirror(handle) {
  const src = visionCanvases.get(handle);
  for (const cv of viewCanvases.get(handle) ?? []) {
    if (!src) continue;
    if (cv.width !== src.width || cv.height !== src.height) { cv.width = src.width; cv.height = src.height; }
    cv.getContext('2d').drawImage(src, 0, 0);
  }
}

function onImage(dv, buf) {
  const handle = dv.getUint32(4, true), w = dv.getUint32(8, true), h = dv.getUint32(12, true);
  const cv = visionCanvases.get(handle);
  if (!cv || w * h * 3 > buf.byteLength - 16) return;
  if (cv.width !== w || cv.height !== h) { cv.width = w; cv.height = h; }
  const rgb = new Uint8Array(buf, 16);
  const ctx = cv.getContext('2d');
  const img = ctx.createImageData(w, h);
  for (let y = 0; y < h; y++) {
    const src = (h - 1 - y) * w * 3, dst = y * w * 4;  // flip: the sensor sends the bottom row first
    for (let x = 0; x < w; x++) {
      img.data[dst + 4 * x] = rgb[src + 3 * x];
      img.data[dst + 4 * x + 1] = rgb[src + 3 * x + 1];
      img.data[dst + 4 * x + 2] = rgb[src + 3 * x + 2];
      img.data[dst + 4 * x + 3] = 255;
    }
  }
  ctx.putImageData(img, 0, 0);
  mirror(handle);
  S.images++;
}

// ---------------------------------------------------------------------------------------

if (glError) showError(glError);
window.addEventListener('resize', () => { dirty = true; });
connect();
requestAnimationFrame(loop);
