// Vision sensor images as canvases in the panel, side by side per sensor: RGB, depth in
// false colour (near warm, far cold, black where nothing is seen) and, once asked for,
// the segmentation mask (a colour per shape; hovering names the shape). The RGB image
// is mirrored by the floating views over the 3D view. Images arrive bottom row first.

import { S } from '../state.js';
import { $, el } from '../dom.js';
import { send } from '../net.js';

const visionCanvases = new Map();  // sensor handle -> RGB canvas
const depthCanvases = new Map();   // sensor handle -> depth canvas
const maskPanels = new Map();      // sensor handle -> {cv, button, caption, mask, w, h}
export function buildVisionPanels() {
  visionCanvases.clear();
  depthCanvases.clear();
  maskPanels.clear();
  const box = $('vision-images');
  const sensors = S.objects.filter((o) => o.vision);
  box.classList.toggle('muted', sensors.length === 0);
  if (!sensors.length) { box.textContent = 'No vision sensor.'; return; }
  box.replaceChildren(...sensors.map((o) => {
    const [w, h] = o.vision.resolution;
    const cv = el('canvas', { width: w, height: h, title: o.path, class: 'rgb' });
    const depth = el('canvas', { width: w, height: h, title: `${o.path}: depth`, class: 'depth' });
    const mask = el('canvas', { width: w, height: h, title: `${o.path}: mask`, class: 'mask', hidden: true });
    const caption = el('figcaption', { text: `${o.alias} ${w}×${h}` });
    const button = el('button', { type: 'button', class: 'mask-on', text: 'mask', title: 'draw this sensor\'s segmentation mask (sim.getVisionSensorMask)' });
    button.onclick = () => send({ op: 'mask', sensor: o.handle }, (r) => { if (!r.ok) caption.textContent = r.text; });
    const panel = { cv: mask, button, caption, mask: null, w, h, label: caption.textContent };
    mask.onmousemove = (ev) => {
      if (!panel.mask) return;
      const r = mask.getBoundingClientRect();
      const x = Math.floor((ev.clientX - r.left) / r.width * panel.w);
      const y = panel.h - 1 - Math.floor((ev.clientY - r.top) / r.height * panel.h);
      const id = panel.mask[y * panel.w + x];
      const obj = S.objects.find((q) => q.handle === id);
      mask.dataset.hover = `${x},${y},${id}`;  // column, row from the bottom, handle
      caption.textContent = id === -1 ? `${panel.label}: nothing` : `${panel.label}: ${obj ? obj.path : id}`;
    };
    mask.onmouseleave = () => { caption.textContent = panel.label; };
    visionCanvases.set(o.handle, cv);
    depthCanvases.set(o.handle, depth);
    maskPanels.set(o.handle, panel);
    return el('figure', { class: 'vision', 'data-sensor': String(o.handle) },
      el('div', { class: 'images' }, cv, depth, mask, button), caption);
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

// A canvas the size of an image message, and ImageData to fill (top row first).
function target(cv, w, h) {
  if (cv.width !== w || cv.height !== h) { cv.width = w; cv.height = h; }
  const ctx = cv.getContext('2d');
  return { ctx, img: ctx.createImageData(w, h) };
}

// False colour of a depth byte (0 near .. 254 far): red, yellow, green, cyan, blue.
const STOPS = [[220, 40, 30], [240, 200, 40], [60, 190, 80], [40, 170, 200], [40, 60, 170]];
const DEPTH_COLOURS = Array.from({ length: 256 }, (_, v) => {
  if (v === 255) return [0, 0, 0];  // nothing seen
  const t = v / 254 * (STOPS.length - 1), k = Math.min(Math.floor(t), STOPS.length - 2), f = t - k;
  return STOPS[k].map((c, i) => Math.round(c + (STOPS[k + 1][i] - c) * f));
});

export function onDepth(dv, buf) {
  const handle = dv.getUint32(4, true), w = dv.getUint32(8, true), h = dv.getUint32(12, true);
  const cv = depthCanvases.get(handle);
  if (!cv || w * h > buf.byteLength - 16) return;
  const bytes = new Uint8Array(buf, 16, w * h);
  const { ctx, img } = target(cv, w, h);
  for (let y = 0; y < h; y++) {
    const src = (h - 1 - y) * w, dst = y * w * 4;
    for (let x = 0; x < w; x++) {
      const c = DEPTH_COLOURS[bytes[src + x]];
      img.data.set(c, dst + 4 * x);
      img.data[dst + 4 * x + 3] = 255;
    }
  }
  ctx.putImageData(img, 0, 0);
}

// A shape's colour in the mask: its handle's hash as a hue, so neighbours differ.
function maskColour(id) {
  if (id === -1) return [0, 0, 0];
  const hue = ((id * 2654435761) >>> 0) / 4294967296 * 6, k = Math.floor(hue), f = hue - k;
  const rgb = [[1, f, 0], [1 - f, 1, 0], [0, 1, f], [0, 1 - f, 1], [f, 0, 1], [1, 0, 1 - f]][k % 6];
  return rgb.map((c) => Math.round(60 + 180 * c));
}

export function onMask(dv, buf) {
  const handle = dv.getUint32(4, true), w = dv.getUint32(8, true), h = dv.getUint32(12, true);
  const panel = maskPanels.get(handle);
  if (!panel || 4 * w * h > buf.byteLength - 16) return;
  panel.mask = new Int32Array(buf.slice(16, 16 + 4 * w * h));
  panel.w = w; panel.h = h;
  panel.cv.hidden = false;
  panel.button.hidden = true;
  const { ctx, img } = target(panel.cv, w, h);
  const colours = new Map();
  for (let y = 0; y < h; y++) {
    const src = (h - 1 - y) * w, dst = y * w * 4;
    for (let x = 0; x < w; x++) {
      const id = panel.mask[src + x];
      let c = colours.get(id);
      if (!c) { c = maskColour(id); colours.set(id, c); }
      img.data.set(c, dst + 4 * x);
      img.data[dst + 4 * x + 3] = 255;
    }
  }
  ctx.putImageData(img, 0, 0);
  S.masks++;
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
