//! Names from CoppeliaSim 4.0-4.5 that tutorials, course material and lab code still
//! call, with the semantics of the version that documented them.
//!
//! A rename with unchanged arguments and results is an alias ([`ALIASES`]): the
//! registry resolves it to the current function, so there is one implementation. What
//! behaves differently (lookup by name with `#` suffixes, the status bar, auxiliary
//! consoles, dialogs, millisecond time) is implemented here.

use crate::error::SimError;
use std::sync::OnceLock;
use std::time::Instant;

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::sim::{Advancing, Sim};
use crate::world::object_path::ObjectTree;
use crate::world::{Handle, World};

/// `(old name, current name)`: old names that are pure renames.
pub const ALIASES: &[(&str, &str)] = &[
    ("clearIntegerSignal", "clearInt32Signal"),
    ("getArrayParameter", "getArrayParam"),
    ("getBoolParameter", "getBoolParam"),
    ("getEngineFloatParameter", "getEngineFloatParam"),
    ("getFloatParameter", "getFloatParam"),
    ("getInt32Parameter", "getInt32Param"),
    ("getIntegerSignal", "getInt32Signal"),
    ("getStringParameter", "getStringParam"),
    // V-REP 3's name (`simGetInvertedMatrix`).
    ("getInvertedMatrix", "getMatrixInverse"),
    ("getObjectName", "getObjectAlias"),
    ("getObjectStringParameter", "getObjectStringParam"),
    // 4.0-4.2 customization scripts address the same user parameters by object.
    ("getUserParameter", "getScriptSimulationParameter"),
    ("getVelocity", "getObjectVelocity"),
    // 4.7's names for the custom data blocks.
    ("readCustomBufferData", "readCustomDataBlock"),
    ("readCustomDataTags", "readCustomDataBlockTags"),
    ("readCustomStringData", "readCustomDataBlock"),
    ("setArrayParameter", "setArrayParam"),
    ("setBoolParameter", "setBoolParam"),
    ("setEngineFloatParameter", "setEngineFloatParam"),
    ("setFloatParameter", "setFloatParam"),
    ("setInt32Parameter", "setInt32Param"),
    ("setIntegerSignal", "setInt32Signal"),
    ("setJointForce", "setJointMaxForce"),
    ("setObjectFloatParameter", "setObjectFloatParam"),
    ("setObjectInt32Parameter", "setObjectInt32Param"),
    ("setObjectName", "setObjectAlias"),
    ("setUserParameter", "setScriptSimulationParameter"),
    ("writeCustomBufferData", "writeCustomDataBlock"),
    ("writeCustomStringData", "writeCustomDataBlock"),
];

/// The old functions whose behaviour is their own, in alphabetical order.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "addObjectToSelection",
        call: ApiFn::World(add_object_to_selection),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "addStatusbarMessage",
        call: ApiFn::World(add_statusbar_message),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "announceSceneContentChange",
        call: ApiFn::World(announce_scene_content_change),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "auxiliaryConsoleClose",
        call: ApiFn::World(auxiliary_console_close),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "auxiliaryConsoleOpen",
        call: ApiFn::World(auxiliary_console_open),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "auxiliaryConsolePrint",
        call: ApiFn::World(auxiliary_console_print),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "auxiliaryConsoleShow",
        call: ApiFn::World(auxiliary_console_show),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "boolAnd32",
        call: ApiFn::World(|_, _, a| bool32(a, |x, y| x & y)),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "boolOr32",
        call: ApiFn::World(|_, _, a| bool32(a, |x, y| x | y)),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "boolXor32",
        call: ApiFn::World(|_, _, a| bool32(a, |x, y| x ^ y)),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "copyMatrix",
        call: ApiFn::World(copy_matrix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "displayDialog",
        call: ApiFn::World(display_dialog),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "endDialog",
        call: ApiFn::World(end_dialog),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getDialogResult",
        call: ApiFn::World(get_dialog_result),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getNameSuffix",
        call: ApiFn::World(get_name_suffix),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getNamedInt32Param",
        call: ApiFn::World(get_named_int32_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectAssociatedWithScript",
        call: ApiFn::World(get_object_associated_with_script),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectFloatParameter",
        call: ApiFn::World(get_object_float_parameter),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectHandle",
        call: ApiFn::World(get_object_handle),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectInt32Parameter",
        call: ApiFn::World(get_object_int32_parameter),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectSelection",
        call: ApiFn::World(get_object_selection),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectSizeFactor",
        call: ApiFn::World(get_object_size_factor),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getScriptHandle",
        call: ApiFn::World(get_script_handle),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getScriptSimulationParameter",
        call: ApiFn::World(get_script_simulation_parameter),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getShapeBB",
        call: ApiFn::World(get_shape_bb),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSimulationStopping",
        call: ApiFn::Sim(get_simulation_stopping),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSystemTimeInMs",
        call: ApiFn::World(get_system_time_in_ms),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "isDynamicallyEnabled",
        call: ApiFn::World(is_dynamically_enabled),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "isHandle",
        call: ApiFn::World(is_handle),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "isHandleValid",
        call: ApiFn::World(is_handle_valid),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "msgBox",
        call: ApiFn::World(msg_box),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "removeModel",
        call: ApiFn::Sim(remove_model),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "removeObjectFromSelection",
        call: ApiFn::World(remove_object_from_selection),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setScriptSimulationParameter",
        call: ApiFn::World(set_script_simulation_parameter),
        cost: Cost::Quick,
    },
];

/// Constants of the old functions, with CoppeliaSim's values.
pub const CONSTANTS: &[(&str, i64)] = &[
    ("dlgstyle_message", 0),
    ("dlgstyle_input", 1),
    ("dlgstyle_ok", 2),
    ("dlgstyle_ok_cancel", 3),
    ("dlgstyle_yes_no", 4),
    ("dlgret_still_open", 0),
    ("dlgret_ok", 1),
    ("dlgret_cancel", 2),
    ("dlgret_yes", 3),
    ("dlgret_no", 4),
    ("msgbox_type_info", MSGBOX_TYPE_INFO),
    ("msgbox_type_question", 1),
    ("msgbox_type_warning", MSGBOX_TYPE_WARNING),
    ("msgbox_type_critical", MSGBOX_TYPE_CRITICAL),
    ("msgbox_buttons_ok", MSGBOX_BUTTONS_OK),
    ("msgbox_buttons_yesno", MSGBOX_BUTTONS_YESNO),
    ("msgbox_buttons_yesnocancel", MSGBOX_BUTTONS_YESNOCANCEL),
    ("msgbox_buttons_okcancel", MSGBOX_BUTTONS_OKCANCEL),
    ("msgbox_return_cancel", 0),
    ("msgbox_return_no", 1),
    ("msgbox_return_yes", MSGBOX_RETURN_YES),
    ("msgbox_return_ok", MSGBOX_RETURN_OK),
    ("msgbox_return_error", 4),
];

// `sim.msgbox_*` and `simUI.msgbox_*` (the same numbers).
const MSGBOX_TYPE_INFO: i64 = 0;
const MSGBOX_TYPE_WARNING: i64 = 2;
const MSGBOX_TYPE_CRITICAL: i64 = 3;
const MSGBOX_BUTTONS_OK: i64 = 0;
const MSGBOX_BUTTONS_YESNO: i64 = 1;
const MSGBOX_BUTTONS_YESNOCANCEL: i64 = 2;
const MSGBOX_BUTTONS_OKCANCEL: i64 = 3;
const MSGBOX_RETURN_YES: i64 = 2;
const MSGBOX_RETURN_OK: i64 = 3;

/// The `simUI.msgbox_*` constants.
pub(super) const UI_MSGBOX_CONSTANTS: &[(&str, i64)] = &[
    ("msgbox_type_info", MSGBOX_TYPE_INFO),
    ("msgbox_type_question", 1),
    ("msgbox_type_warning", MSGBOX_TYPE_WARNING),
    ("msgbox_type_critical", MSGBOX_TYPE_CRITICAL),
    ("msgbox_buttons_ok", MSGBOX_BUTTONS_OK),
    ("msgbox_buttons_yesno", MSGBOX_BUTTONS_YESNO),
    ("msgbox_buttons_yesnocancel", MSGBOX_BUTTONS_YESNOCANCEL),
    ("msgbox_buttons_okcancel", MSGBOX_BUTTONS_OKCANCEL),
    ("msgbox_result_cancel", 0),
    ("msgbox_result_no", 1),
    ("msgbox_result_yes", MSGBOX_RETURN_YES),
    ("msgbox_result_ok", MSGBOX_RETURN_OK),
];

/// `sim.msgBox(dlgType, buttons, title, message)` and `simUI.msgBox(...)` → the
/// button pressed. gantry has no modal windows (it runs headless, the viewer is a web
/// page that must not stop the simulation): the message is a log line at the
/// dialog's level (critical as an error, warning as a warning) and the box is answered
/// at once with its affirmative button, "OK" or "Yes", so a script that asks for
/// confirmation goes on.
pub(super) fn msg_box(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let kind = a.int(0)?;
    let buttons = a.int(1)?;
    let title = a.str(2)?;
    let text = a.str(3)?;
    if !(MSGBOX_TYPE_INFO..=MSGBOX_TYPE_CRITICAL).contains(&kind) {
        return Err(SimError::bad_argument(format!(
            "argument 1: invalid message box type {kind} (msgbox_type_info, _question, _warning or _critical)"
        )));
    }
    let answer = match buttons {
        MSGBOX_BUTTONS_OK | MSGBOX_BUTTONS_OKCANCEL => MSGBOX_RETURN_OK,
        MSGBOX_BUTTONS_YESNO | MSGBOX_BUTTONS_YESNOCANCEL => MSGBOX_RETURN_YES,
        _ => {
            return Err(SimError::bad_argument(format!(
                "argument 2: invalid buttons {buttons} (msgbox_buttons_ok, _yesno, _yesnocancel or _okcancel)"
            )));
        }
    };
    let level = match kind {
        MSGBOX_TYPE_CRITICAL => 100,
        MSGBOX_TYPE_WARNING => 300,
        _ => INFO,
    };
    let t = w.time();
    w.log.push(t, level, ctx.source, &format!("{title}: {text}"));
    Ok(vec![Value::Int(answer)])
}

/// CoppeliaSim's `sim.handle_self`.
const HANDLE_SELF: i64 = -4;

/// Verbosity of the lines the status bar and consoles write (`sim.verbosity_scriptinfos`).
const INFO: i64 = 450;

/// `sim.getObjectHandle(name)` (4.0-4.2): the object whose name is `name`. A suffix
/// `#k` names the (k+1)-th object of that name (CoppeliaSim names copies `name#0`,
/// `name#1`, ...), a bare `#` the original; `name@silentError` returns -1 instead of
/// failing when there is none. A path (`/a/b`, `./c`) is resolved as `sim.getObject` does.
fn get_object_handle(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    if let Some(h) = a.get(0).as_i64() {
        // `sim.getObjectHandle(sim.handle_self)` was accepted by old versions.
        if h == HANDLE_SELF {
            return Ok(vec![Value::Int(calling_object(ctx)?)]);
        }
    }
    let raw = a.str(0)?;
    let (name, silent) = match raw.strip_suffix("@silentError") {
        Some(n) => (n, true),
        None => (raw, false),
    };
    match find_by_name(w, ctx, name) {
        Some(h) => Ok(vec![Value::Int(h)]),
        None if silent => Ok(vec![Value::Int(-1)]),
        None => Err(SimError::no_such_item(format!("object does not exist: '{name}'"))),
    }
}

fn find_by_name(w: &World, ctx: &CallContext<'_>, name: &str) -> Option<Handle> {
    if name.starts_with(['/', '.', ':']) {
        return w.find(name, ctx.script_object, 0).ok();
    }
    let (base, index) = match name.rsplit_once('#') {
        Some((base, "")) => (base, 0),
        Some((base, k)) => match k.parse::<usize>() {
            Ok(k) => (base, k + 1),
            Err(_) => (name, 0),
        },
        None => (name, 0),
    };
    w.handles()
        .iter()
        .copied()
        .filter(|&h| w.object(h).is_ok_and(|o| o.alias == base))
        .nth(index)
}

fn calling_object(ctx: &CallContext<'_>) -> Result<Handle, SimError> {
    ctx.script_object
        .ok_or_else(|| SimError::refused("sim.handle_self names the calling script, and a remote client has none"))
}

/// `sim.getObjectAssociatedWithScript(scriptHandle)`: the object a script is attached
/// to. In gantry a script's handle is its object's handle.
fn get_object_associated_with_script(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(script_object(w, ctx, a)?)])
}

/// `sim.getScriptHandle(name = sim.handle_self)`: the calling script's handle, or the
/// handle of the script attached to the object named `name`.
fn get_script_handle(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    match a.get(0) {
        Value::Nil => Ok(vec![Value::Int(calling_object(ctx)?)]),
        Value::Str(_) => get_object_handle(w, ctx, a),
        v if v.as_i64() == Some(HANDLE_SELF) => Ok(vec![Value::Int(calling_object(ctx)?)]),
        _ => Err(SimError::bad_argument(
            "argument 1: expected a script name or sim.handle_self",
        )),
    }
}

/// `sim.getObjectSizeFactor(h)`: 1, as objects are never scaled in gantry.
fn get_object_size_factor(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    w.object(a.handle(0)?)?;
    Ok(vec![Value::Float(1.0)])
}

/// `sim.isHandle(h)`: whether an object with that handle exists.
fn is_handle(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.int(0)?;
    Ok(vec![Value::Bool(w.object(h).is_ok())])
}

/// `sim.isHandleValid(handle [, type])` (V-REP 3): 1 when `handle` names an object,
/// else 0. The type is V-REP's general object type; -1 (any) and 109
/// (`sim_appobj_object_type`) ask about scene objects, the only ones gantry's handles
/// name, so other types are never valid here.
fn is_handle_valid(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    /// V-REP's `sim_appobj_object_type`.
    const OBJECT_TYPE: i64 = 109;
    let h = a.int(0)?;
    let ty = a.opt_int(1, -1)?;
    let valid = (ty == -1 || ty == OBJECT_TYPE) && w.object(h).is_ok();
    Ok(vec![Value::Int(i64::from(valid))])
}

/// `sim.getSimulationStopping()` (V-REP 3): whether this is the simulation's last pass,
/// the one a stop request ends it with.
fn get_simulation_stopping(sim: &mut Sim, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Bool(sim.advancing == Advancing::AboutToStop)])
}

/// `sim.removeModel(objectHandle)`: removes a model, its base and every object below
/// it; the number of objects removed. The handle must be a model base (an object
/// marked `model_base`, or a loaded model's root), as in CoppeliaSim.
fn remove_model(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let base = a.handle(0)?;
    if !sim.world.object(base)?.model_base {
        return Err(SimError::bad_argument(format!(
            "argument 1: object {base} is not a model base; remove plain objects with sim.removeObjects"
        )));
    }
    let tree = tree_from(&sim.world, &[base]);
    sim.remove_objects(&tree)?;
    Ok(vec![Value::Int(i64::try_from(tree.len()).unwrap_or(i64::MAX))])
}

/// `bases` and every object below them, each base before its descendants.
fn tree_from(w: &World, bases: &[Handle]) -> Vec<Handle> {
    let mut tree = bases.to_vec();
    let mut i = 0;
    while i < tree.len() {
        tree.extend(w.children(tree[i]).iter().copied());
        i += 1;
    }
    tree
}

/// The objects `sim.addObjectToSelection` and `sim.removeObjectFromSelection` (V-REP
/// 3 to CoppeliaSim 4.4) name: `(what, objectHandle)` with `what` one of
/// `sim.handle_single` (the object), `sim.handle_tree` (it and everything below),
/// `sim.handle_chain` (it and its ancestors) or `sim.handle_all` (every object); or a
/// table of handles.
fn selection_targets(w: &World, a: &Args<'_>) -> Result<Vec<Handle>, SimError> {
    const HANDLE_ALL: i64 = -2;
    const HANDLE_TREE: i64 = -6;
    const HANDLE_CHAIN: i64 = -7;
    const HANDLE_SINGLE: i64 = -8;
    if let Value::Array(items) = a.get(0) {
        let mut out = Vec::with_capacity(items.len());
        for v in items {
            let h = v
                .as_i64()
                .ok_or_else(|| SimError::bad_argument("argument 1: expected a table of handles"))?;
            w.object(h)?;
            out.push(h);
        }
        return Ok(out);
    }
    let what = a.int(0)?;
    if what == HANDLE_ALL {
        return Ok(tree_from(w, w.roots()));
    }
    let h = a.handle(1)?;
    w.object(h)?;
    Ok(match what {
        HANDLE_SINGLE => vec![h],
        HANDLE_TREE => tree_from(w, &[h]),
        HANDLE_CHAIN => {
            let mut chain = vec![h];
            while let Some(p) = w.object(*chain.last().unwrap_or(&h))?.parent {
                chain.push(p);
            }
            chain
        }
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 1: {other} is not sim.handle_single, sim.handle_tree, sim.handle_chain or sim.handle_all"
            )));
        }
    })
}

/// `sim.addObjectToSelection(what, objectHandle)`: adds objects to the selection, after
/// those already selected.
fn add_object_to_selection(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let mut handles = w.selection.handles().to_vec();
    handles.extend(selection_targets(w, a)?);
    w.selection.set(&handles);
    Ok(Vec::new())
}

/// `sim.removeObjectFromSelection(what, objectHandle)`: takes objects out of the
/// selection (`sim.handle_all` clears it).
fn remove_object_from_selection(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let gone = selection_targets(w, a)?;
    let kept: Vec<Handle> = w
        .selection
        .handles()
        .iter()
        .copied()
        .filter(|h| !gone.contains(h))
        .collect();
    w.selection.set(&kept);
    Ok(Vec::new())
}

/// `sim.boolAnd32`, `sim.boolOr32`, `sim.boolXor32` (V-REP 3): `op` on the two values'
/// low 32 bits, the result as an unsigned 32-bit number (Lua 5.1 had no bit operators).
fn bool32(a: &Args<'_>, op: fn(u32, u32) -> u32) -> Result<Ret, SimError> {
    // Truncation to the low 32 bits is the documented behaviour.
    #[expect(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "the low 32 bits, as V-REP"
    )]
    let low = |v: i64| v as u32;
    Ok(vec![Value::Int(i64::from(op(low(a.int(0)?), low(a.int(1)?))))])
}

/// `sim.copyMatrix(matrix)` (V-REP 3): a copy of a 12-number transformation matrix (a
/// new table, so that changing one does not change the other).
fn copy_matrix(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let m: [f64; 12] = a.floats(0)?;
    Ok(vec![Value::Array(m.iter().map(|&x| Value::Float(x)).collect())])
}

/// `sim.isDynamicallyEnabled(h)`: whether the physics engine simulates the object: a
/// dynamic shape, or a joint in a dynamic mode. `sim.moveToConfig` uses it to choose
/// between driving a joint's target and setting its position.
fn is_dynamically_enabled(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    use crate::world::ObjectKind;
    let enabled = match &w.object(a.handle(0)?)?.kind {
        ObjectKind::Shape(s) => s.dynamic,
        ObjectKind::Joint(j) => j.mode.is_dynamic(),
        _ => false,
    };
    Ok(vec![Value::Bool(enabled)])
}

/// `sim.getObjectSelection()` (4.1, now `sim.getObjectSel`): the selected objects'
/// handles in selection order, or `nil` when nothing is selected, as 4.1 returned.
fn get_object_selection(w: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    let handles = w.selection.handles();
    Ok(vec![if handles.is_empty() {
        Value::Nil
    } else {
        Value::Array(handles.iter().map(|&h| Value::Int(h)).collect())
    }])
}

/// `sim.addStatusbarMessage(text)`: a line in the log (the viewer shows it); `nil`
/// clears CoppeliaSim's status bar and does nothing here.
fn add_statusbar_message(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    if let Value::Nil = a.get(0) {
        return Ok(Vec::new());
    }
    let text = a.str(0)?;
    let t = w.time();
    w.log.push(t, INFO, ctx.source, text);
    Ok(Vec::new())
}

/// `sim.auxiliaryConsoleOpen(title, maxLines, mode, ...)` → handle. The console is a
/// source in the log, named after its title; position, size and colours are ignored.
fn auxiliary_console_open(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let title = a.str(0)?;
    Ok(vec![Value::Int(w.log.open_console(title))])
}

/// `sim.auxiliaryConsolePrint(handle, text)` → 1, or 0 for a closed console; one log
/// line per line of `text` (`nil` clears the console and logs nothing).
fn auxiliary_console_print(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.int(0)?;
    let Some(title) = w.log.console(h).map(|t| format!("console: {t}")) else {
        return Ok(vec![Value::Int(0)]);
    };
    if let Value::Nil = a.get(1) {
        return Ok(vec![Value::Int(1)]);
    }
    let text = a.str(1)?;
    let t = w.time();
    for line in text.trim_end_matches('\n').split('\n') {
        w.log.push(t, INFO, &title, line);
    }
    Ok(vec![Value::Int(1)])
}

/// `sim.auxiliaryConsoleClose(handle)` → 1, or 0 when it was not open.
fn auxiliary_console_close(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(i64::from(w.log.close_console(a.int(0)?)))])
}

/// `sim.auxiliaryConsoleShow(handle, show)` → 1, or 0 for a closed console.
fn auxiliary_console_show(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(i64::from(w.log.console(a.int(0)?).is_some()))])
}

/// `sim.displayDialog(title, text, style, modal, ...)` → dialog handle. gantry has no
/// modal windows: the dialog is a log line and is answered "OK" at once
/// (`sim.getDialogResult` returns `sim.dlgret_ok`).
fn display_dialog(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let title = a.str(0)?;
    let text = a.str(1)?;
    let t = w.time();
    w.log.push(t, INFO, ctx.source, &format!("{title}: {text}"));
    Ok(vec![Value::Int(w.log.open_console(title))])
}

/// `sim.getDialogResult(handle)` → `sim.dlgret_ok` (1), or -1 for an unknown dialog.
fn get_dialog_result(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let known = w.log.console(a.int(0)?).is_some();
    Ok(vec![Value::Int(if known { 1 } else { -1 })])
}

/// `sim.endDialog(handle)` → 1, or -1 for an unknown dialog.
fn end_dialog(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(if w.log.close_console(a.int(0)?) { 1 } else { -1 })])
}

/// `sim.getSystemTimeInMs(previous)`: with -1, milliseconds since an arbitrary start
/// (here the first call in the process); otherwise the milliseconds elapsed since
/// `previous`, a value it returned before.
fn get_system_time_in_ms(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    static START: OnceLock<Instant> = OnceLock::new();
    let now = i64::try_from(START.get_or_init(Instant::now).elapsed().as_millis()).unwrap_or(i64::MAX);
    let previous = a.opt_int(0, -1)?;
    Ok(vec![Value::Int(if previous < 0 { now } else { now - previous })])
}

/// `sim.getObjectInt32Parameter(h, id)` (4.0-4.2) → result, value: the current
/// `sim.getObjectInt32Param` with the old leading result (1, or 0 when the parameter
/// does not apply to the object).
fn get_object_int32_parameter(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    with_result(super::params::get_object_int32_param(w, ctx, a)?)
}

/// `sim.getObjectFloatParameter(h, id)` (4.0-4.2) → result, value (see
/// [`get_object_int32_parameter`]).
fn get_object_float_parameter(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    with_result(super::params::get_object_float_param(w, ctx, a)?)
}

/// The current getter's result with the old leading result code.
fn with_result(current: Ret) -> Result<Ret, SimError> {
    let value = current.into_iter().next().unwrap_or(Value::Nil);
    let found = i64::from(value != Value::Nil);
    Ok(vec![Value::Int(found), value])
}

/// `sim.getNamedInt32Param(name)` → nil: gantry has no named parameters (CoppeliaSim
/// sets them from its command line), so every name is unset, which scripts check for.
fn get_named_int32_param(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    a.str(0)?;
    Ok(vec![Value::Nil])
}

/// The object a script handle or `sim.handle_self` names.
fn script_object(w: &World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Handle, SimError> {
    let h = a.int(0)?;
    let object = if h == HANDLE_SELF { calling_object(ctx)? } else { h };
    w.object(object)?;
    Ok(object)
}

/// `sim.getScriptSimulationParameter(scriptHandle, name, forceStringReturn=false)` → the
/// value of an object's user parameter, or nil when unset. Scene files keep the values as
/// text (`[[user_parameter]]`, CoppeliaSim files' `Lsp`); as in CoppeliaSim, text that
/// reads as a number comes back as a number, and `true`/`false` as a boolean, unless
/// `forceStringReturn` asks for the text. Scripts set values with
/// `sim.setScriptSimulationParameter`.
fn get_script_simulation_parameter(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let object = script_object(w, ctx, a)?;
    let name = a.str(1)?;
    let force_string = a.opt_bool(2, false)?;
    let value = w.custom.get(object, name).cloned().unwrap_or(Value::Nil);
    Ok(vec![match value {
        Value::Str(text) if !force_string => user_parameter_value(text),
        Value::Int(i) if force_string => Value::Str(i.to_string()),
        Value::Float(f) if force_string => Value::Str(f.to_string()),
        Value::Bool(b) if force_string => Value::Str(b.to_string()),
        other => other,
    }])
}

/// A user parameter's text as CoppeliaSim returns it: an integer, a number, a boolean,
/// or the text itself.
fn user_parameter_value(text: String) -> Value {
    let t = text.trim();
    if let Ok(i) = t.parse::<i64>() {
        Value::Int(i)
    } else if let Some(f) = t.parse::<f64>().ok().filter(|f| f.is_finite()) {
        Value::Float(f)
    } else if t == "true" || t == "false" {
        Value::Bool(t == "true")
    } else {
        Value::Str(text)
    }
}

/// `sim.setScriptSimulationParameter(scriptHandle, name, value)` → 1.
fn set_script_simulation_parameter(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let object = script_object(w, ctx, a)?;
    let name = a.str(1)?.to_owned();
    w.custom.set(object, &name, a.get(2).clone());
    Ok(vec![Value::Int(1)])
}

/// `sim.getShapeBB(shapeHandle)` → the size of the shape's bounding box in its own
/// frame (x, y, z extents, m).
fn get_shape_bb(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    if !matches!(w.object(h)?.kind, crate::world::ObjectKind::Shape(_)) {
        return Err(SimError::bad_argument("object is not a shape."));
    }
    let (lo, hi) = w.bounding_box(h)?;
    Ok(vec![Value::Array(
        (0..3).map(|k| Value::Float(hi[k] - lo[k])).collect(),
    )])
}

/// `sim.announceSceneContentChange()` → 1: in CoppeliaSim it records an undo point for
/// the editor; gantry has no scene editor, so there is nothing to record.
fn announce_scene_content_change(_: &mut World, _: &CallContext<'_>, _: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(1)])
}

/// `sim.getNameSuffix(nameWithSuffix)` (4.0-4.2) → suffix, name: `"arm#2"` gives 2 and
/// "arm", a name without `#` -1 and itself. With nil, the suffix of the calling script's
/// copy: gantry never numbers copies that way, so -1.
fn get_name_suffix(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    if let Value::Nil = a.get(0) {
        return Ok(vec![Value::Int(-1), Value::Str(String::new())]);
    }
    let name = a.str(0)?;
    Ok(match name.rsplit_once('#').map(|(base, k)| (base, k.parse::<i64>())) {
        Some((base, Ok(k))) if k >= 0 => vec![Value::Int(k), Value::Str(base.to_owned())],
        _ => vec![Value::Int(-1), Value::Str(name.to_owned())],
    })
}
