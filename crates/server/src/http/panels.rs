//! The page's slower panels: scripts, the log, custom UIs, graph streams and vision
//! sensor images. Each viewer session polls them a few times a second with a
//! [`PanelCursor`] saying what it already has, and gets only what is new, so the cost
//! is proportional to what changed, and bounded per poll.
//!
//! [`collect`] runs on the simulation thread (through `SimHandle::with`).

use std::collections::BTreeMap;

use std::path::PathBuf;

use gantry_lua::ScriptState;

use crate::sim_thread::SimView;
use gantry_sim_core::Handle;
use gantry_sim_core::Sim;
use gantry_sim_core::graph::GraphStream;
use gantry_sim_core::ui::{Container, Layout, Ui, Widget, WidgetKind};
use gantry_sim_core::world::ObjectKind;
use serde_json::{Value as Json, json};

/// Binary message type of a vision sensor image (the first little-endian `u32`).
pub const MSG_IMAGE: u32 = 2;
/// Binary message type of a vision sensor's depth image, one byte a pixel (see
/// [`depth_byte`]).
pub const MSG_DEPTH: u32 = 4;
/// Binary message type of a vision sensor's segmentation mask, one little-endian `i32`
/// handle a pixel (-1: nothing seen).
pub const MSG_MASK: u32 = 5;
/// The depth byte of a pixel that sees nothing (depth 1, at or past the far plane).
pub const DEPTH_NOTHING: u8 = 255;
/// Most log lines per poll; the rest follow in the next polls.
pub const MAX_LOG_LINES: usize = 500;
/// Most samples per graph stream per poll (the newest); a page that fell further behind
/// has a gap in its plot rather than an unbounded message.
pub const MAX_GRAPH_SAMPLES: usize = 5_000;
/// Most samples per poll, all streams together; streams past it wait for the next poll.
pub const MAX_POLL_SAMPLES: usize = 50_000;
/// Longest log message sent, in bytes; longer ones are cut (the page is not a file viewer).
pub const MAX_LOG_MESSAGE: usize = 4096;

/// What one session already has.
#[derive(Debug, Clone, Default)]
pub struct PanelCursor {
    /// Sequence number of the next log line wanted.
    log_seq: u64,
    /// `Uis::revision` last sent.
    ui_revision: Option<u64>,
    /// `FloatingViews::revision` last sent.
    view_revision: Option<u64>,
    /// `Selection::revision` last sent.
    selection_revision: Option<u64>,
    /// The scripts list last sent.
    scripts: Option<Json>,
    /// Per graph stream `(graph, id)`: time of the newest sample sent, s.
    graphs: BTreeMap<(Handle, i64), f64>,
    /// Per vision sensor: `(renders, simulation steps)` when its image was last sent.
    images: BTreeMap<Handle, (u64, u64)>,
    /// Simulation steps at the last poll: fewer now means a stop rebuilt the world,
    /// whose counters (UI revision, render counts) start over.
    steps: u64,
}

/// What is new since the cursor.
#[derive(Debug, Default)]
pub struct PanelUpdate {
    /// `{"t":"panels",...}` with only the parts that changed; `None` if nothing did.
    pub json: Option<Json>,
    /// `MSG_IMAGE`, `MSG_DEPTH` and `MSG_MASK` messages.
    pub images: Vec<Vec<u8>>,
}

/// Gathers what is new since `cursor` and advances it. Runs on the simulation thread.
/// Without the scripts (`view.scripts` is `None` while a script holds the step), the
/// script panel keeps what it showed.
pub fn collect(view: &SimView<'_>, cursor: &mut PanelCursor) -> PanelUpdate {
    let scripts = view.scripts.map(|s| scripts_json(view.sim, s));
    let core = view.sim;
    let world = &core.world;
    if world.steps() < cursor.steps {
        cursor.ui_revision = None;
        cursor.view_revision = None;
        cursor.selection_revision = None;
        cursor.images.clear();
    }
    cursor.steps = world.steps();
    let mut msg = serde_json::Map::new();
    if let Some(scripts) = scripts
        && cursor.scripts.as_ref() != Some(&scripts)
    {
        msg.insert("scripts".into(), scripts.clone());
        cursor.scripts = Some(scripts);
    }
    let log: Vec<Json> = world
        .log
        .since(cursor.log_seq)
        .take(MAX_LOG_LINES)
        .map(|l| {
            json!({
                "seq": l.seq,
                "time": l.sim_time,
                "verbosity": l.verbosity,
                "source": l.source,
                "message": truncate(&l.message, MAX_LOG_MESSAGE),
            })
        })
        .collect();
    if let Some(last) = log.last() {
        cursor.log_seq = last["seq"].as_u64().unwrap_or(cursor.log_seq) + 1;
        msg.insert("log".into(), Json::Array(log));
    }
    if cursor.ui_revision != Some(core.uis.revision()) {
        cursor.ui_revision = Some(core.uis.revision());
        msg.insert("uis".into(), Json::Array(core.uis.iter().map(ui_json).collect()));
    }
    if cursor.view_revision != Some(core.views.revision()) {
        cursor.view_revision = Some(core.views.revision());
        let views = core
            .views
            .iter()
            .map(|v| {
                json!({
                    "handle": v.handle,
                    "centre": v.centre,
                    "size": v.size,
                    "object": v.object,
                    "label": v.label,
                })
            })
            .collect();
        msg.insert("views".into(), Json::Array(views));
    }
    if cursor.selection_revision != Some(world.selection.revision()) {
        cursor.selection_revision = Some(world.selection.revision());
        msg.insert("selection".into(), json!(world.selection.handles()));
    }
    let graphs = graph_updates(core, &mut cursor.graphs);
    if !graphs.is_empty() {
        msg.insert("graphs".into(), Json::Array(graphs));
    }
    let images = image_updates(core, &mut cursor.images);
    let json = (!msg.is_empty()).then(|| {
        msg.insert("t".into(), json!("panels"));
        Json::Object(msg)
    });
    PanelUpdate { json, images }
}

/// `s` cut to at most `max` bytes at a character boundary, marked with an ellipsis.
pub(super) fn truncate(s: &str, max: usize) -> String {
    if s.len() <= max {
        return s.to_owned();
    }
    let mut end = max;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}…", &s[..end])
}

fn scripts_json(sim: &Sim, scripts: &[(PathBuf, Handle, ScriptState)]) -> Json {
    let world = &sim.world;
    let list: Vec<Json> = scripts
        .iter()
        .enumerate()
        .map(|(i, (path, object, state))| {
            let alias = world.object(*object).map(|o| o.alias.clone()).unwrap_or_default();
            let (state, error) = match state {
                ScriptState::Running => ("running", None),
                ScriptState::Errored(e) => ("errored", Some(e)),
                ScriptState::Removed => ("removed", None),
            };
            json!({
                "index": i,
                "path": path.display().to_string(),
                "object": object,
                "alias": alias,
                "state": state,
                "error": error,
            })
        })
        .collect();
    Json::Array(list)
}

/// New samples of every graph stream since the cursor's times.
fn graph_updates(sim: &Sim, seen: &mut BTreeMap<(Handle, i64), f64>) -> Vec<Json> {
    let mut out = Vec::new();
    let mut budget = MAX_POLL_SAMPLES;
    for s in sim.graphs.streams() {
        if budget == 0 {
            break;
        }
        let key = (s.graph(), s.id());
        let newest = s.len().checked_sub(1).and_then(|i| s.samples().nth(i)).map(|(t, _)| t);
        let last = seen.get(&key).copied();
        // After a stop the stream restarts (or is emptied): its newest sample is older
        // than what the page has, so the page starts the plot over. A stream seen for
        // the first time is a reset too.
        let reset = match (last, newest) {
            (None, _) => true,
            (Some(l), Some(n)) => n < l,
            (Some(l), None) => l > f64::NEG_INFINITY,
        };
        let n = s.len();
        let first_new = match last {
            Some(l) if !reset => first_after(s, l),
            _ => 0,
        };
        let start = first_new.max(n.saturating_sub(MAX_GRAPH_SAMPLES.min(budget)));
        budget -= n - start;
        if start == n && !reset {
            continue;
        }
        let samples: Vec<[f64; 2]> = s.samples().skip(start).map(|(t, v)| [t, v]).collect();
        seen.insert(key, newest.unwrap_or(f64::NEG_INFINITY));
        let p = s.params();
        out.push(json!({
            "graph": s.graph(),
            "graph_alias": sim.world.object(s.graph()).map(|o| o.alias.clone()).unwrap_or_default(),
            "id": s.id(),
            "label": s.label(),
            "unit": p.unit,
            "color": p.color,
            "reset": reset,
            "samples": samples,
        }));
    }
    out
}

/// Index of the first sample newer than `t` (samples are in time order). A binary
/// search: `nth` on the stream's ring buffer is O(1), and streams hold up to 100 000
/// samples.
fn first_after(s: &GraphStream, t: f64) -> usize {
    let (mut lo, mut hi) = (0, s.len());
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        match s.samples().nth(mid) {
            Some((tm, _)) if tm <= t => lo = mid + 1,
            _ => hi = mid,
        }
    }
    lo
}

/// Images of vision sensors that changed since the cursor, three messages each with the
/// header `u32` type, `u32` handle, `u32` width, `u32` height, bottom row first:
/// [`MSG_IMAGE`] with RGB bytes, [`MSG_DEPTH`] with [`depth_byte`]s, and, when the
/// sensor draws one (after `sim.getVisionSensorMask` or the viewer's mask button),
/// [`MSG_MASK`] with its handles.
fn image_updates(sim: &Sim, seen: &mut BTreeMap<Handle, (u64, u64)>) -> Vec<Vec<u8>> {
    let world = &sim.world;
    let mut out = Vec::new();
    for &h in world.handles() {
        let Ok(o) = world.object(h) else { continue };
        if !matches!(o.kind, ObjectKind::VisionSensor(_)) {
            continue;
        }
        let Some(img) = sim.vision.image(h) else { continue };
        // Scripts may rewrite the image without rendering (simVision filters), so a
        // new step counts as a change too.
        let stamp = (img.renders(), world.steps());
        if seen.get(&h) == Some(&stamp) {
            continue;
        }
        seen.insert(h, stamp);
        let [w, hgt] = img.resolution();
        let message = |kind: u32, len: usize| {
            let mut b = Vec::with_capacity(16 + len);
            for v in [kind, h as u32, w, hgt] {
                b.extend(v.to_le_bytes());
            }
            b
        };
        let mut b = message(MSG_IMAGE, img.rgb().len());
        b.extend_from_slice(img.rgb());
        out.push(b);
        let mut b = message(MSG_DEPTH, img.depth().len());
        b.extend(img.depth().iter().map(|&d| depth_byte(d)));
        out.push(b);
        if let Some(mask) = img.mask() {
            let mut b = message(MSG_MASK, 4 * mask.len());
            for id in mask {
                b.extend(id.to_le_bytes());
            }
            out.push(b);
        }
    }
    out
}

/// A normalised depth (0 at the near plane, 1 at the far one) as the byte the page's
/// false-colour panel shows: 0..=254 for what is seen, [`DEPTH_NOTHING`] where nothing
/// is. A byte is plenty for a picture, and a quarter of the floats' bandwidth.
pub fn depth_byte(d: f32) -> u8 {
    if d >= 1.0 || d.is_nan() {
        DEPTH_NOTHING
    } else {
        // d in [0, 1): at most 254.
        (d.max(0.0) * 254.0).round() as u8
    }
}

/// A custom UI as the page draws it.
fn ui_json(ui: &Ui) -> Json {
    json!({
        "handle": ui.handle,
        "title": ui.title,
        "closeable": ui.closeable,
        "enabled": ui.enabled,
        "visible": ui.visible,
        "content": container_json(&ui.content),
    })
}

fn container_json(c: &Container) -> Json {
    let layout = match c.layout {
        Layout::VBox => "vbox",
        Layout::HBox => "hbox",
        Layout::Grid => "grid",
        Layout::Form => "form",
        Layout::None => "none",
    };
    let rows: Vec<Json> = c
        .rows
        .iter()
        .map(|row| Json::Array(row.iter().map(widget_json).collect()))
        .collect();
    json!({"layout": layout, "rows": rows})
}

fn widget_json(w: &Widget) -> Json {
    let mut j = json!({
        "id": w.id,
        "type": w.kind.name(),
        "enabled": w.enabled,
        "visible": w.visible,
    });
    let extra = match &w.kind {
        WidgetKind::Slider(s) => json!({
            "minimum": s.minimum, "maximum": s.maximum, "value": s.value, "inverted": s.inverted,
        }),
        WidgetKind::Button(b) => json!({"text": b.text, "checkable": b.checkable, "checked": b.checked}),
        WidgetKind::Label(l) => json!({"text": l.text, "word_wrap": l.word_wrap}),
        WidgetKind::Edit(e) => json!({"value": e.value}),
        WidgetKind::Checkbox(c) => json!({"text": c.text, "value": c.value}),
        WidgetKind::Radiobutton(r) => json!({"text": r.text, "checked": r.checked}),
        WidgetKind::Spinbox(s) => json!({
            "value": s.value, "minimum": s.minimum, "maximum": s.maximum, "step": s.step,
            "float": s.float, "decimals": s.decimals, "prefix": s.prefix, "suffix": s.suffix,
        }),
        WidgetKind::Group(g) => json!({"text": g.text, "flat": g.flat, "content": container_json(&g.content)}),
        WidgetKind::Stretch(s) => json!({"factor": s.factor}),
    };
    if let (Json::Object(j), Json::Object(extra)) = (&mut j, extra) {
        j.extend(extra);
    }
    j
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_messages_are_cut_at_a_character_boundary() {
        assert_eq!(truncate("abc", 3), "abc");
        assert_eq!(truncate("abcd", 3), "abc…");
        // 'é' is two bytes: a cut inside it backs off to before it.
        assert_eq!(truncate("aé", 2), "a…");
    }

    #[test]
    fn depth_bytes_keep_nothing_seen_apart() {
        assert_eq!(depth_byte(0.0), 0);
        assert_eq!(depth_byte(0.5), 127);
        // The farthest surface short of the far plane is still a surface.
        assert_eq!(depth_byte(0.999_999), 254);
        for nothing in [1.0, 1.5, f32::NAN, f32::INFINITY] {
            assert_eq!(depth_byte(nothing), DEPTH_NOTHING, "{nothing}");
        }
        assert_eq!(depth_byte(-0.1), 0);
    }
}
