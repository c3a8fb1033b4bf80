// The ROS 2 panel: every topic gantry publishes or subscribes to on the ROS 2 graph
// (gantry run --ros2, or a script's simROS2), with its type and its rate, from
// GET /api/ros2 once a second. Hidden while gantry has no ROS 2 endpoint.

import { $, el, fmt } from '../dom.js';

const POLL_MS = 1000;
// The last reading of each endpoint: {messages, at (ms)}, for the rates.
let previous = new Map();

function show(topics) {
  const now = performance.now();
  const seen = new Map();
  const rows = topics.map((t) => {
    const before = previous.get(t.id);
    const rate = before && now > before.at ? (t.messages - before.messages) * 1000 / (now - before.at) : NaN;
    seen.set(t.id, { messages: t.messages, at: now });
    const dir = t.direction === 'publish' ? 'out' : 'in';
    return el('tr', { 'data-topic': t.topic },
      el('td', { text: t.topic, title: t.type }),
      el('td', { class: 'muted', text: t.type }),
      el('td', { text: dir }),
      el('td', { class: 'num', text: Number.isFinite(rate) ? `${fmt(rate, 1)} Hz` : '…' }),
      el('td', { class: 'num muted', text: t.dropped ? `${t.dropped} dropped` : '' }));
  });
  previous = seen;
  $('ros2-table').tBodies[0].replaceChildren(...rows);
  $('ros2').hidden = topics.length === 0;
}

async function poll() {
  try {
    const r = await fetch('api/ros2', { cache: 'no-store' });
    if (r.ok) show((await r.json()).topics);
  } catch (_) {
    // The server is gone: the connection badge says so already.
  }
}

export function startRos2Panel() {
  poll();
  setInterval(poll, POLL_MS);
}
