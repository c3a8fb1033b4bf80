// The WebGL2 context, its three shader programs (lit shapes, textured or not, flat
// lines and points, coloured point clouds), drawables (vertex arrays uploaded once and
// freed with their scene) and textures. `gl` is null when the browser has no WebGL2 (then `glError` says so).

import { $ } from './dom.js';

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
export const SOFTWARE_GL = softwareRenderer();
export const canvas = $('gl');
export const gl = canvas.getContext('webgl2', { antialias: !SOFTWARE_GL });

const LIT_VS = `#version 300 es
layout(location=0) in vec3 aPos;
layout(location=1) in vec3 aNrm;
layout(location=2) in vec2 aUv;
uniform mat4 uViewProj, uModel;
out vec3 vNrm; out vec3 vWorld; out vec2 vUv;
void main() {
  vec4 w = uModel * vec4(aPos, 1.0);
  vWorld = w.xyz;
  vUv = aUv;
  vNrm = mat3(uModel) * aNrm;   // rigid transforms only: no inverse-transpose needed
  gl_Position = uViewProj * w;
}`;
const LIT_FS = `#version 300 es
precision highp float;
in vec3 vNrm; in vec3 vWorld; in vec2 vUv;
uniform vec3 uColor, uEye; uniform float uAlpha, uHighlight; uniform int uFlat;
// A texture replaces the colour (decal) or multiplies it, as in vision sensors.
uniform sampler2D uTex; uniform int uTextured, uDecal;
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
  vec3 base = uColor;
  if (uTextured == 1) base = texture(uTex, vUv).rgb * (uDecal == 1 ? vec3(1.0) : uColor);
  vec3 c = base * (sky + diffuse);
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

// A drawable: a vertex array with positions (and normals, and texture coordinates),
// optionally indexed.
export function makeDrawable(pos, nrm, idx, mode, uv) {
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  const buf = (data, loc, size = 3) => {
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, data instanceof Float32Array ? data : new Float32Array(data), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0);
    return b;
  };
  const buffers = [buf(pos, 0)];
  if (nrm) buffers.push(buf(nrm, 1));
  if (uv) buffers.push(buf(uv, 2, 2));
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
export function makeCloudDrawable(pos, rgb) {
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

// A texture from RGBA bytes, rows from the bottom (v = 0), with mipmaps; how it is
// sampled is set per draw (`bindTexture`), since shapes may wear one image differently.
export function makeTexture(w, h, rgba) {
  const t = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, t);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, w, h, 0, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
  gl.generateMipmap(gl.TEXTURE_2D);
  gl.bindTexture(gl.TEXTURE_2D, null);
  return t;
}

// Binds texture `t` to unit 0, sampled as a visual's `texture` says (repeat or clamp
// along u and v, bilinear or nearest).
export function bindTexture(t, how) {
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, t);
  const wrap = (r) => (r ? gl.REPEAT : gl.CLAMP_TO_EDGE);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, wrap(how.repeat[0]));
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, wrap(how.repeat[1]));
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, how.interpolate ? gl.LINEAR_MIPMAP_LINEAR : gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, how.interpolate ? gl.LINEAR : gl.NEAREST);
}

export function freeDrawable(d) {
  if (!d) return;
  gl.deleteVertexArray(d.vao);
  for (const b of d.buffers) gl.deleteBuffer(b);
}

export let lit, flat, cloud;
export const glError = gl ? null : 'WebGL2 is not available in this browser';
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
export const AXES = gl && makeDrawable([0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1], null, null, gl.LINES);
export const GRID = gl && gridDrawable();
