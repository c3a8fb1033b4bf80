// gantry viewer: a WebGL2 3D view of the simulation and its control panels.
//
// Plain JavaScript ES modules, no framework, no build step: gantry embeds every module in
// its binary (crates/server/src/http/assets.rs lists them). This one starts the page.
// The server protocol (see crates/server/src/http/) over one WebSocket at /ws:
//   server -> page  text   {"t":"scene"}   object tree (paths included), visuals, joints, sensors (once)
//                          {"t":"tick"}    time, state, rates, joints, detections, picked object's Euler angles
//                          {"t":"panels"}  scripts, log, custom UIs, graph samples
//                          {"t":"replay"}  gantry replay only: the timeline's time, end, playing, speed
//                          {"t":"reply"}   answer to a command (matched by id)
//                   binary u32 type 1: pose, drawing and point-cloud deltas, 2: vision image, 3: mesh,
//                   4: vision depth, 5: vision mask, 6: textured part, 7: texture image
//   page -> server  text   {"id","op":"control"|"packet"|"ui"|"reload"|"debug"|"key"|"select"|"replay",...}
// World frame: Z up, metres, radians; poses are [x, y, z, qx, qy, qz, qw].

import { S, changed } from './state.js';
import { showError } from './dom.js';
import { SOFTWARE_GL, gl, glError } from './gl.js';
import { connect } from './net.js';
import { onScene, onBinary } from './scene.js';
import { render } from './render.js';
import './input.js';
import { onTick, PANEL_FPS, lastPanels, updatePanels } from './panels/simulation.js';
import { onDebug } from './panels/debug.js';
import { select } from './panels/selection.js';
import { showScripts, appendLog, clearLog } from './panels/scripts.js';
import { showUis } from './panels/custom_ui.js';
import { showViews } from './panels/vision.js';
import { addGraphSamples } from './panels/graphs.js';
import { onReplay } from './panels/replay.js';
import { startRos2Panel } from './panels/ros2.js';

// Slower panels: scripts, log, custom UIs, floating views, the selection, graphs.
function onPanels(p) {
  if (p.scripts) showScripts(p.scripts);
  // A replay that went back in time starts its log over.
  if (p.log_reset) clearLog();
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

// Redraw only when something changed: an idle page costs nothing. Changes from the
// pose stream redraw at most STREAM_FPS (the stream is 20 Hz in real time, up to 60 Hz
// flat out). Without a GPU, WebGL renders on the CPU, often the one the simulator runs
// on (a headless lab server): there the stream redraws at 10 frames a second. Camera
// moves always redraw at the display rate.
const STREAM_FPS = SOFTWARE_GL ? 10 : 30;
S.softwareGl = SOFTWARE_GL;
let lastRender = -Infinity;
function loop(now) {
  if (changed.panels && now - lastPanels >= 1000 / PANEL_FPS - 2) updatePanels();
  if (gl && (changed.view || (changed.stream && now - lastRender >= 1000 / STREAM_FPS - 2))) {
    changed.view = changed.stream = false;
    lastRender = now;
    render();
  }
  requestAnimationFrame(loop);
}

if (glError) showError(glError);
window.addEventListener('resize', () => { changed.view = true; });
connect({ scene: onScene, tick: onTick, panels: onPanels, debug: onDebug, replay: onReplay, binary: onBinary });
startRos2Panel();
requestAnimationFrame(loop);
