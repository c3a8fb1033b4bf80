// Graphs: one plot per graph object, every stream a coloured line; samples are kept up
// to MAX_POINTS per stream (the CSV link has all the server keeps).

import { S } from '../state.js';
import { $, el, fmt } from '../dom.js';

const MAX_POINTS = 20000;
const graphs = new Map();  // graph handle -> {canvas, legend, streams: Map(id -> {label, color, t[], v[]})}

export function addGraphSamples(updates) {
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

// A replay's cursor moved: draw every plot again with the cursor at the new time.
export function redrawGraphs() {
  for (const [h, g] of graphs) drawGraph(h, g);
}

// The value of a stream at time t: its last sample at or before t (binary search).
function valueAt(s, t) {
  let lo = 0, hi = s.t.length;
  while (lo < hi) { const mid = (lo + hi) >> 1; if (s.t[mid] <= t) lo = mid + 1; else hi = mid; }
  return lo > 0 ? s.v[lo - 1] : NaN;
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
  // In a replay the legend gives each stream's value at the cursor, and there is no
  // CSV of the simulation to download.
  const cursor = S.replay ? S.replay.time : null;
  const shown = (s) => (cursor === null ? s.v[s.v.length - 1] : valueAt(s, cursor));
  g.legend.replaceChildren(
    el('b', { text: g.alias || `graph ${handle}` }),
    ...[...g.streams.values()].map((s) => el('span', {}, el('span', { class: 'swatch', style: `background:${css(s.color)}` }),
      `${s.label}: ${fmt(shown(s))}`)),
    cursor === null ? el('a', { href: `/api/graph/${handle}.csv`, download: `${g.alias || 'graph'}.csv`, text: 'CSV' }) : null);
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
  if (cursor !== null) {
    // The replay's cursor: a vertical line at the time shown.
    const x = X(Math.min(Math.max(cursor, t0), t1));
    ctx.strokeStyle = '#e8e8e8';
    ctx.beginPath(); ctx.moveTo(x, 8); ctx.lineTo(x, H - 14); ctx.stroke();
    const values = {};
    for (const s of g.streams.values()) values[s.label] = valueAt(s, cursor);
    S.graphCursor[handle] = { time: cursor, x, left: pad, width: W - pad - 6, t0, t1, values };
  }
}
