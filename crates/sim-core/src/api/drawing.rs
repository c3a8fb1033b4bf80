//! Drawing objects and graph streams: `sim.addDrawingObject`, `addDrawingObjectItem`,
//! `removeDrawingObject`, `addGraphStream`, `setGraphStreamValue`, and gantry's read
//! and export extensions (`getDrawingObjectItems`, `getGraphStreamValues`,
//! `exportGraphStreams`). The models live in `world::drawing` and `world::graph`.

use crate::error::SimError;
use crate::sim::Sim;
use std::path::Path;

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::drawing::{DrawingKind, DrawingParams, HANDLEFLAG_ADD_MULTIPLE, MAX_DRAWING_ITEMS};
use crate::graph::StreamParams;
use crate::world::{Handle, ObjectKind, World};

/// The functions this file implements.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "addDrawingObject",
        call: ApiFn::Sim(add_drawing_object),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "addDrawingObjectItem",
        call: ApiFn::Sim(add_drawing_object_item),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "addGraphStream",
        call: ApiFn::Sim(add_graph_stream),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "exportGraphStreams",
        call: ApiFn::Sim(export_graph_streams),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getDrawingObjectItems",
        call: ApiFn::Sim(get_drawing_object_items),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getGraphStreamValues",
        call: ApiFn::Sim(get_graph_stream_values),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "removeDrawingObject",
        call: ApiFn::Sim(remove_drawing_object),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setGraphStreamValue",
        call: ApiFn::Sim(set_graph_stream_value),
        cost: Cost::Quick,
    },
];

/// `sim.handle_all`.
const HANDLE_ALL: Handle = -2;
/// `sim.handle_world`: a drawing object without parent.
const HANDLE_WORLD: Handle = -1;
/// Verbosity of the warnings logged here (`sim.verbosity_scriptwarnings`).
const WARNING: i64 = 420;
/// CoppeliaSim's default drawing colour when none is given (its default material).
const DEFAULT_DRAWING_COLOR: [f64; 3] = [0.5, 0.5, 0.5];

/// An optional RGB argument: `default` when nil, else 3 finite numbers (extra ones are
/// ignored), clamped to [0, 1].
pub(super) fn opt_color(a: &Args<'_>, i: usize, default: [f64; 3]) -> Result<[f64; 3], SimError> {
    match a.get(i) {
        Value::Nil => Ok(default),
        _ => Ok(a.floats::<3>(i)?.map(|c| c.clamp(0.0, 1.0))),
    }
}

/// `sim.addDrawingObject(objectType, size, duplicateTolerance, parentHandle,
/// maxItemCount, color)` → handle.
///
/// Accepts both CoppeliaSim forms: 4.6's `color` as the 6th argument, and 4.1's
/// `ambient_diffuse, nil, specular, emission` from the 6th on (ambient/diffuse is the
/// colour, emission is kept for the viewer, specular is checked and ignored).
/// `parentHandle` -1 draws in the world frame. `maxItemCount` 0 means 1000; above
/// 100,000 it is capped with a warning in the log. Unknown type codes are drawn as
/// points, with a warning.
fn add_drawing_object(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let object_type = a.int(0)?;
    let size = a.finite(1)?;
    let duplicate_tolerance = a.finite(2)?;
    let parent = match a.handle(3)? {
        HANDLE_WORLD => None,
        h => {
            sim.world.object(h)?;
            Some(h)
        }
    };
    let max_items = a.int(4)?;
    let max_items = usize::try_from(max_items).map_err(|_| {
        SimError::bad_argument(format!("argument 5: max item count must be 0 or more, got {max_items}"))
    })?;
    let color = opt_color(a, 5, DEFAULT_DRAWING_COLOR)?;
    // 4.1 form (1-based): argument 7 is a reserved nil, 8 specular (not rendered),
    // 9 emission.
    opt_color(a, 7, [0.0; 3])?;
    let emission = match a.get(8) {
        Value::Nil => None,
        _ => Some(opt_color(a, 8, [0.0; 3])?),
    };
    let h = sim.drawings.create(DrawingParams {
        object_type,
        size,
        duplicate_tolerance,
        parent,
        max_items,
        color,
        emission,
    })?;
    // Warn only once the object exists, so a refused call logs nothing.
    let (_, known) = DrawingKind::from_type(object_type);
    let time = sim.world.time();
    if !known {
        sim.world.log.push(
            time,
            WARNING,
            ctx.source,
            &format!(
                "sim.addDrawingObject: type {} is drawn as points by gantry",
                object_type & 0x1f
            ),
        );
    }
    if max_items > MAX_DRAWING_ITEMS {
        sim.world.log.push(
            time,
            WARNING,
            ctx.source,
            &format!("sim.addDrawingObject: max item count {max_items} capped at {MAX_DRAWING_ITEMS}"),
        );
    }
    Ok(vec![Value::Int(h)])
}

/// `sim.addDrawingObjectItem(handle, itemData)` → 1 if the item was added, else 0.
///
/// `itemData` holds 3 numbers per vertex (points 3, lines 6, triangles 9, line strip 3
/// for the next vertex); extra numbers are ignored, as CoppeliaSim reads only what the
/// type needs (the 7-number `distData` of `sim.checkDistance` draws its segment).
/// Coordinates are world-frame, or parent-frame with `sim.drawing_local`. `nil` clears
/// the object and returns 0. With `sim.handleflag_addmultiple` OR-ed on the handle the
/// data is packed items; the result is 1 if any was added.
fn add_drawing_object_item(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let raw = a.handle(0)?;
    let multiple = raw > 0 && raw & HANDLEFLAG_ADD_MULTIPLE != 0;
    let h = if multiple { raw & !HANDLEFLAG_ADD_MULTIPLE } else { raw };
    let data = a.opt_numbers(1)?;
    let frame = sim.drawings.object(h)?.frame(&sim.world);
    let object = sim.drawings.object_mut(h)?;
    let added = match data {
        None => {
            object.clear();
            false
        }
        Some(data) if multiple => object.add_items(&data, &frame)? > 0,
        Some(data) => object.add_item(&data, &frame)?,
    };
    Ok(vec![Value::Int(i64::from(added))])
}

/// `sim.removeDrawingObject(handle)`; `sim.handle_all` removes every drawing object.
fn remove_drawing_object(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    match a.handle(0)? {
        HANDLE_ALL => sim.drawings.clear(),
        h => sim.drawings.remove(h)?,
    }
    Ok(Vec::new())
}

/// gantry extension: `sim.getDrawingObjectItems(handle)` → `objectType, size, color,
/// vertices`: the type as created (kind in the low 5 bits, flags above), the size
/// (pixels, or m for spheres), `{r, g, b}`, and every stored vertex oldest first as a
/// flat list `{x1, y1, z1, x2, ...}` in the world frame (m).
fn get_drawing_object_items(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let object = sim.drawings.object(a.handle(0)?)?;
    let frame = object.frame(&sim.world);
    let flat: Vec<f64> = object.world_vertices(&frame).flat_map(|v| [v.x, v.y, v.z]).collect();
    Ok(vec![
        Value::Int(object.object_type()),
        Value::Float(object.size()),
        Value::floats(&object.color()),
        Value::floats(&flat),
    ])
}

/// Checks that `h` is a graph object.
pub(super) fn graph(w: &World, h: Handle) -> Result<Handle, SimError> {
    match &w.object(h)?.kind {
        ObjectKind::Graph => Ok(h),
        other => Err(SimError::WrongKind {
            handle: h,
            expected: "graph",
            actual: other.name(),
        }),
    }
}

/// `sim.addGraphStream(graphHandle, name, unit='', options=0, color={1,0,0},
/// cyclicRange=0)` → stream id. A stream of the same name on the same graph is updated
/// (unit, options, colour) and keeps its id and values.
fn add_graph_stream(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let g = graph(&sim.world, a.handle(0)?)?;
    let name = a.str(1)?;
    if name.is_empty() {
        return Err(SimError::bad_argument("argument 2: stream name must not be empty"));
    }
    let unit = match a.get(2) {
        Value::Nil => "",
        _ => a.str(2)?,
    };
    let params = StreamParams {
        name: name.to_owned(),
        unit: unit.to_owned(),
        options: a.opt_int(3, 0)?,
        color: opt_color(a, 4, [1.0, 0.0, 0.0])?,
        cyclic_range: match a.get(5) {
            Value::Nil => 0.0,
            _ => a.finite(5)?,
        },
    };
    Ok(vec![Value::Int(sim.graphs.add_stream(g, params)?)])
}

/// `sim.setGraphStreamValue(graphHandle, streamId, value)`. The value is stamped with
/// the current step's end time `sim.getSimulationTime() + dt`, the time CoppeliaSim's
/// `sim.handleGraph` records it with; a second value in the same step replaces the
/// first.
fn set_graph_stream_value(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let g = graph(&sim.world, a.handle(0)?)?;
    let id = a.int(1)?;
    let value = a.finite(2)?;
    let t = sim.world.time() + sim.world.settings().dt;
    sim.graphs.record(g, id, t, value)?;
    Ok(Vec::new())
}

/// gantry extension: `sim.getGraphStreamValues(graphHandle, streamId)` → `times,
/// values`: the kept samples, oldest first, times in s.
fn get_graph_stream_values(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let g = graph(&sim.world, a.handle(0)?)?;
    let s = sim.graphs.stream(g, a.int(1)?)?;
    let (times, values): (Vec<f64>, Vec<f64>) = s.samples().unzip();
    Ok(vec![Value::floats(&times), Value::floats(&values)])
}

/// gantry extension: `sim.exportGraphStreams(dir)` → list of written file paths: one CSV
/// per graph with streams, named after the graph's alias (`time` column, then
/// `name [unit]` per stream, one row per sample time). The directory is created if
/// needed; files are replaced atomically.
///
/// Scripts and remote clients both reach this function, so the directory must lie
/// inside the simulation's [`ExportScope`] (in gantry: the scene's folder, against which a
/// relative `dir` resolves); anything else is refused before touching the disk.
///
/// [`ExportScope`]: crate::graph::ExportScope
fn export_graph_streams(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let dir = a.str(0)?;
    if dir.is_empty() {
        return Err(SimError::bad_argument("argument 1: directory must not be empty"));
    }
    let target = sim
        .graphs
        .export_scope()
        .resolve(Path::new(dir))
        .map_err(|e| SimError::refused(format!("cannot export graph streams to '{dir}': {e}")))?;
    let names = |h: Handle| {
        sim.world
            .object(h)
            .map_or_else(|_| format!("graph{h}"), |o| o.alias.clone())
    };
    let paths = sim
        .graphs
        .export_csv(&target, names)
        .map_err(|e| SimError::refused(format!("cannot export graph streams to '{dir}': {e}")))?;
    Ok(vec![Value::Array(
        paths
            .into_iter()
            .map(|p| Value::Str(p.to_string_lossy().into_owned()))
            .collect(),
    )])
}
