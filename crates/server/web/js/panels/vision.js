// Vision sensor images (RGB, bottom row first) as canvases in the panel, mirrored by
// the floating views over the 3D view.

import { S } from '../state.js';
import { $, el } from '../dom.js';

const visionCanvases = new Map();
export function buildVisionPanels() {
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
export function showViews(views) {
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

export function onImage(dv, buf) {
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
