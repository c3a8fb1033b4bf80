// Drawing the 3D view: shapes, lines and points, point clouds, then translucent sensor
// volumes.

import { S, changed } from './state.js';
import { canvas, gl, lit, flat, cloud, bindTexture, AXES, GRID } from './gl.js';
import { cam, eye, viewProj } from './camera.js';
import { M4 } from './math.js';

function resize() {
  const dpr = Math.min(window.devicePixelRatio || 1, 2);
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; changed.view = true; }
}

export function drawWith(prog, d, model) {
  gl.uniformMatrix4fv(prog.u.uModel, false, model);
  gl.bindVertexArray(d.vao);
  if (d.indexed) gl.drawElements(d.mode, d.count, gl.UNSIGNED_INT, 0);
  else gl.drawArrays(d.mode, 0, d.count);
}

export function render() {
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
      // Textured once both its part and its image have arrived; plain until then.
      const image = v.texture && v.texDrawable ? S.textures[v.texture.image] : null;
      const d = image ? v.texDrawable : v.drawable;
      if (!d) continue;
      gl.uniform3fv(lit.u.uColor, v.color);
      gl.uniform1i(lit.u.uFlat, d.flat ? 1 : 0);
      gl.uniform1i(lit.u.uTextured, image ? 1 : 0);
      if (image) {
        bindTexture(image, v.texture);
        gl.uniform1i(lit.u.uDecal, v.texture.decal ? 1 : 0);
      }
      drawWith(lit, d, M4.multiply(o.world, v.localM));
    }
  }
  gl.uniform1i(lit.u.uTextured, 0);

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
