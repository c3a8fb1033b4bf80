// The replay timeline (`gantry replay FILE`): play/pause, speed, a slider to scrub to
// any time, one snapshot back or forward, and the time shown / the recording's end.
// It replaces the simulation controls; the 3D view, graphs and log are the live
// viewer's, fed from the recording. Times are the recording's, in seconds.

import { S, changed } from '../state.js';
import { $, fmt, showError } from '../dom.js';
import { send } from '../net.js';
import { redrawGraphs } from './graphs.js';

// Seeks while the slider is dragged: one in flight at a time, and the newest position
// goes next, so a fast drag never queues a backlog on the server.
let seekBusy = false;
let seekNext = null;
function seek(time) {
  if (seekBusy) { seekNext = time; return; }
  seekBusy = true;
  send({ op: 'replay', action: 'seek', time }, (r) => {
    seekBusy = false;
    if (!r.ok) showError(r.text);
    if (seekNext !== null) { const t = seekNext; seekNext = null; seek(t); }
  });
}

function command(cmd) {
  send({ op: 'replay', ...cmd }, (r) => { if (!r.ok) showError(r.text); });
}

let dragging = false;
const slider = $('replay-slider');
slider.addEventListener('pointerdown', () => { dragging = true; });
slider.addEventListener('pointerup', () => { dragging = false; });
slider.addEventListener('input', () => seek(Number(slider.value)));
slider.addEventListener('change', () => { dragging = false; seek(Number(slider.value)); });
$('replay-play').addEventListener('click', () => command({ action: S.replay?.playing ? 'pause' : 'play' }));
$('replay-back').addEventListener('click', () => command({ action: 'step', frames: -1 }));
$('replay-forward').addEventListener('click', () => command({ action: 'step', frames: 1 }));
$('replay-speed').addEventListener('change', (e) => command({ action: 'speed', speed: Number(e.target.value) }));

// `{"t":"replay", time, start, end, playing, speed, frame, frames}`; the first one also
// names the file and what was wrong with it.
export function onReplay(r) {
  const first = !S.replay;
  S.replay = { ...S.replay, ...r };
  if (first) {
    document.body.classList.add('replay');
    $('replay').hidden = false;
    $('controls').hidden = true;
    $('replay-file').textContent = (r.file || '').split(/[\\/]/).pop();
    $('replay-file').title = r.file || '';
    const w = $('replay-warnings');
    w.textContent = (r.warnings || []).join('\n');
    w.hidden = !(r.warnings || []).length;
  }
  slider.min = r.start;
  slider.max = r.end;
  // While the user drags, the thumb is theirs.
  if (!dragging) slider.value = r.time;
  $('replay-time').textContent = `${fmt(r.time)} / ${fmt(r.end)} s`;
  $('replay-frame').textContent = `snapshot ${r.frame + 1} of ${r.frames}`;
  $('replay-play').textContent = r.playing ? 'Pause' : 'Play';
  $('replay-speed').value = String(r.speed);
  redrawGraphs();
  changed.panels = true;
}
