// The WebSocket at /ws and commands over it: each command carries an id, and the
// server's reply with that id goes to the command's callback. Reconnects every second.

import { $, setBadge, showError } from './dom.js';

let ws = null;
let nextId = 1;
const pending = new Map();  // command id -> callback(reply)

export function send(cmd, onReply) {
  if (!ws || ws.readyState !== WebSocket.OPEN) { onReply?.({ ok: false, text: 'not connected' }); return; }
  const id = nextId++;
  if (onReply) pending.set(id, onReply);
  ws.send(JSON.stringify({ id, ...cmd }));
}

// `on` handles the server's messages: scene, tick, panels, debug and replay (text, by `t`) and
// binary (an ArrayBuffer).
export function connect(on) {
  ws = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => setBadge($('conn'), 'connected', 'ok');
  ws.onclose = () => {
    setBadge($('conn'), 'disconnected: retrying', 'bad');
    for (const cb of pending.values()) cb({ ok: false, text: 'disconnected' });
    pending.clear();
    setTimeout(() => connect(on), 1000);
  };
  ws.onmessage = (ev) => {
    if (typeof ev.data !== 'string') { on.binary(ev.data); return; }
    const msg = JSON.parse(ev.data);
    switch (msg.t) {
      case 'scene': on.scene(msg); break;
      case 'tick': on.tick(msg); break;
      case 'panels': on.panels(msg); break;
      case 'reply': {
        const cb = pending.get(msg.id);
        pending.delete(msg.id);
        if (cb) cb(msg); else if (!msg.ok) showError(msg.text);
        break;
      }
      case 'error': showError(msg.text); break;
      case 'debug': on.debug(msg.paused); break;
      case 'replay': on.replay(msg); break;
    }
  };
}
