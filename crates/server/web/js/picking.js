// Picking: draw every pickable object with its index as colour, read one pixel. Also
// what tests and tools ask of the view: where an object appears, and a capture.

import { S } from './state.js';
import { canvas, gl, flat } from './gl.js';
import { drawWith, render } from './render.js';
import { viewProj } from './camera.js';
import { M4 } from './math.js';
import { select } from './panels/selection.js';

let pickFbo = null;
export function pickAt(clientX, clientY) {
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
