// Scene state, filled by the server's messages, and what changed since the page last
// drew.

export const S = {
  scene: null,          // the scene message
  objects: [],          // per object: {handle, alias, path, parent, kind, pose, world, visuals, ...}
  byHandle: new Map(),
  meshes: [],           // mesh id -> {pos, idx} until a visual uploads it
  textures: [],         // texture image index -> WebGL texture, once it has arrived
  jointIndex: [],       // joint k -> object index
  proxIndex: [],        // proximity sensor k -> object index
  joints: [],           // live joint positions (rad or m)
  jointVel: [],         // joint target velocities
  detections: [],
  drawings: new Map(),  // handle -> {kind, size, color, drawable}
  clouds: new Map(),    // point cloud object handle -> {size, count, drawable} (points in its frame)
  selected: -1,
  selectedOrientation: null,  // {handle, euler: [a, b, g] rad}: the server's, for the pick panel
  tick: null,
  framesRendered: 0,
  frameMessages: 0,
  images: 0,
  masks: 0,             // segmentation masks drawn in the vision panel
  replay: null,         // gantry replay: the timeline's last state (time, start, end, playing, speed, frame, frames)
  graphCursor: {},      // gantry replay: per graph handle, the cursor {time, x (canvas px), values {label: value}}
};
// For tests and the curious: `window.gantry` shows the page's live state.
window.gantry = S;

// What changed: the view (camera, selection, scene: redraw at once), the stream (poses,
// drawings, sensors: redraw at most STREAM_FPS, see main.js) and the panels' text
// (updated at most PANEL_FPS, see panels/simulation.js).
export const changed = { view: true, stream: false, panels: false };
