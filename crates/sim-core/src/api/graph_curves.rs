//! Graph curves and graph handling: `sim.addGraphCurve`, `sim.handleGraph`,
//! `sim.resetGraph`. Curves live with the streams in `world::graph`.

use super::drawing::{graph, opt_color};
use super::scene::handle_list;
use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::graph::CurveParams;
use crate::sim::Sim;
use crate::world::Handle;

/// The functions this file implements.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "addGraphCurve",
        call: ApiFn::Sim(add_graph_curve),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "handleGraph",
        call: ApiFn::Sim(handle_graph),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "resetGraph",
        call: ApiFn::Sim(reset_graph),
        cost: Cost::Quick,
    },
];

/// `sim.handle_all`.
const HANDLE_ALL: Handle = -2;

/// `sim.addGraphCurve(graphHandle, curveName, dim, streamIds, defaultValues, unitStr,
/// options=0, color={1,1,0}, curveWidth=2)` → curve id: draws `dim` (2 or 3) streams of
/// the graph against each other; a stream without a value at a time gives its default
/// value. A curve of the same name on the same graph is updated and keeps its id.
fn add_graph_curve(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let g = graph(&sim.world, a.handle(0)?)?;
    let name = a.str(1)?;
    if name.is_empty() {
        return Err(SimError::bad_argument("argument 2: curve name must not be empty"));
    }
    let dim = a.int(2)?;
    let dim = match usize::try_from(dim) {
        Ok(d @ 2..=3) => d,
        _ => {
            return Err(SimError::bad_argument(format!(
                "argument 3: dim must be 2 (x/y) or 3 (x/y/z), got {dim}"
            )));
        }
    };
    let streams = handle_list(a, 3)?;
    if streams.len() < dim {
        return Err(SimError::bad_argument(format!(
            "argument 4: expected {dim} stream ids, got {}",
            streams.len()
        )));
    }
    let defaults = match a.get(4) {
        Value::Nil => vec![0.0; dim],
        Value::Array(items) if items.len() >= dim => items[..dim]
            .iter()
            .map(|v| v.as_f64().filter(|f| f.is_finite()))
            .collect::<Option<Vec<f64>>>()
            .ok_or_else(|| SimError::bad_argument("argument 5: default values must be finite numbers"))?,
        _ => {
            return Err(SimError::bad_argument(format!(
                "argument 5: expected a table of {dim} default values"
            )));
        }
    };
    let unit = match a.get(5) {
        Value::Nil => "",
        _ => a.str(5)?,
    };
    let params = CurveParams {
        name: name.to_owned(),
        streams: streams[..dim].to_vec(),
        defaults,
        unit: unit.to_owned(),
        options: a.opt_int(6, 0)?,
        color: opt_color(a, 7, [1.0, 1.0, 0.0])?,
        width: a.opt_int(8, 2)?,
    };
    Ok(vec![Value::Int(sim.graphs.add_curve(g, params)?)])
}

/// The graph objects `h` names: one graph, or every graph for `sim.handle_all`.
fn graphs(sim: &Sim, h: Handle) -> Result<Vec<Handle>, SimError> {
    if h == HANDLE_ALL {
        return Ok(sim.graphs.graphs());
    }
    Ok(vec![graph(&sim.world, h)?])
}

/// `sim.handleGraph(graphHandle, simulationTime)`: in CoppeliaSim it records the values
/// set since the last call, stamped with `simulationTime`. gantry records each value
/// when `sim.setGraphStreamValue` sets it, stamped with the step's end time (the time
/// the main script passes), so this only checks its arguments.
fn handle_graph(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    graphs(sim, a.handle(0)?)?;
    if !matches!(a.get(1), Value::Nil) {
        a.finite(1)?;
    }
    Ok(Vec::new())
}

/// `sim.resetGraph(graphHandle)`: drops the recorded values of the graph's streams (or
/// of every graph's with `sim.handle_all`); the streams and curves stay.
fn reset_graph(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    for g in graphs(sim, a.handle(0)?)? {
        sim.graphs.clear_graph_samples(g);
    }
    Ok(Vec::new())
}
