//! What the user interface shows: floating views over the viewer's 3D view
//! (`sim.floatingViewAdd`, `sim.adjustView`, `sim.floatingViewRemove`; see
//! [`crate::ui::FloatingViews`]) and the object selection (`sim.getObjectSel`,
//! `sim.setObjectSel`; see [`crate::world::Selection`]).

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;
use crate::world::ObjectKind;

/// The functions of this file.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "adjustView",
        call: ApiFn::Sim(adjust_view),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "floatingViewAdd",
        call: ApiFn::Sim(floating_view_add),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "floatingViewRemove",
        call: ApiFn::Sim(floating_view_remove),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectSel",
        call: ApiFn::Sim(get_object_sel),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectSel",
        call: ApiFn::Sim(set_object_sel),
        cost: Cost::Quick,
    },
];

/// `sim.getObjectSel()` → the selected objects' handles, in selection order (the
/// viewer's click selects one).
fn get_object_sel(sim: &mut Sim, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Array(
        sim.world.selection.handles().iter().map(|&h| Value::Int(h)).collect(),
    )])
}

/// `sim.setObjectSel(handles)`: replaces the selection (the viewer shows its first
/// object); every handle must name an object; an empty table clears it.
fn set_object_sel(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let handles = match a.get(0) {
        Value::Array(items) => items
            .iter()
            .map(|v| {
                v.as_i64().ok_or_else(|| {
                    SimError::bad_argument(format!("argument 1: expected object handles, got {}", v.type_name()))
                })
            })
            .collect::<Result<Vec<_>, _>>()?,
        // An empty Lua table converts to an empty map.
        Value::Map(pairs) if pairs.is_empty() => Vec::new(),
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 1: expected a table of object handles, got {}",
                other.type_name()
            )));
        }
    };
    if handles.len() > crate::world::MAX_SELECTION {
        return Err(SimError::bad_argument(format!(
            "argument 1: at most {} objects can be selected",
            crate::world::MAX_SELECTION
        )));
    }
    for &h in &handles {
        sim.world.object(h)?;
    }
    sim.world.selection.set(&handles);
    Ok(Vec::new())
}

/// `sim.floatingViewAdd(posX, posY, sizeX, sizeY, options)` → the view's handle. The
/// position is the view's centre and the size its extent, both relative to the main
/// view (0..1, from the bottom left).
fn floating_view_add(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let centre = [a.finite(0)?, a.finite(1)?];
    let size = [a.finite(2)?, a.finite(3)?];
    let options = a.opt_int(4, 0)?;
    let h = sim
        .views
        .add(centre, size, options)
        .map_err(|e| SimError::refused(e.to_string()))?;
    Ok(vec![Value::Int(h)])
}

/// `sim.adjustView(viewHandle, objectHandle, options, viewLabel=nil)` → 1: the view
/// shows what `objectHandle` sees (a vision sensor's image in gantry's viewer; -1 for
/// nothing), captioned `viewLabel` or the object's alias. `options` are accepted and
/// ignored.
fn adjust_view(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let view = a.int(0)?;
    let object = match a.int(1)? {
        -1 => None,
        h => {
            let o = sim.world.object(h)?;
            if !matches!(o.kind, ObjectKind::VisionSensor(_)) {
                return Err(SimError::bad_argument(format!(
                    "argument 2: object {h} is not a vision sensor: gantry's floating views show vision sensors"
                )));
            }
            Some(h)
        }
    };
    a.opt_int(2, 0)?;
    let label = match a.get(3) {
        Value::Nil => match object {
            Some(h) => sim.world.object(h)?.alias.clone(),
            None => String::new(),
        },
        _ => a.str(3)?.to_owned(),
    };
    sim.views
        .adjust(view, object, &label)
        .map_err(|e| SimError::bad_argument(format!("argument 1: {e}")))?;
    Ok(vec![Value::Int(1)])
}

/// `sim.floatingViewRemove(viewHandle)` → 1 when removed, 0 when there was no such
/// view (CoppeliaSim's result, not an error).
fn floating_view_remove(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let view = a.int(0)?;
    Ok(vec![Value::Int(i64::from(sim.views.remove(view)))])
}
