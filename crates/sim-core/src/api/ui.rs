//! `simUI.*`: custom UIs (see [`crate::ui`] for the model and its rules).
//!
//! UI handles are integers here (older simUI versions counted integers from 1000; current
//! ones return opaque strings, which scripts only pass back). Number arguments for integer
//! values (slider positions) are rounded to the nearest integer, so a script computing
//! `100*(speed-min)/(max-min)` gets 50 even when the float is 49.999999.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;
use crate::ui::{UiError, Uis};

/// Verbosity of parser notes in the log (`sim.verbosity_scriptinfos`).
const INFO: i64 = 450;

/// Verbosity of parser warnings in the log (`sim.verbosity_warnings`).
const WARNING: i64 = 300;

/// The functions this file implements.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "create",
        call: ApiFn::Sim(create),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "destroy",
        call: ApiFn::Sim(destroy),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getCheckboxValue",
        call: ApiFn::Sim(get_checkbox_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getEditValue",
        call: ApiFn::Sim(get_edit_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getEnabled",
        call: ApiFn::Sim(get_enabled),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getKeyboardModifiers",
        call: ApiFn::Sim(get_keyboard_modifiers),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getLabelText",
        call: ApiFn::Sim(get_label_text),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPosition",
        call: ApiFn::Sim(get_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getRadiobuttonValue",
        call: ApiFn::Sim(get_radiobutton_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSliderValue",
        call: ApiFn::Sim(get_slider_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getSpinboxValue",
        call: ApiFn::Sim(get_spinbox_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getTitle",
        call: ApiFn::Sim(get_title),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getWidgetVisibility",
        call: ApiFn::Sim(get_widget_visibility),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "hide",
        call: ApiFn::Sim(hide),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "interact",
        call: ApiFn::Sim(interact),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "isVisible",
        call: ApiFn::Sim(is_visible),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "msgBox",
        call: ApiFn::World(super::legacy::msg_box),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setButtonText",
        call: ApiFn::Sim(set_button_text),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setCheckboxValue",
        call: ApiFn::Sim(set_checkbox_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setEditValue",
        call: ApiFn::Sim(set_edit_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setEnabled",
        call: ApiFn::Sim(set_enabled),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setLabelText",
        call: ApiFn::Sim(set_label_text),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setPosition",
        call: ApiFn::Sim(set_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setRadiobuttonValue",
        call: ApiFn::Sim(set_radiobutton_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setSliderValue",
        call: ApiFn::Sim(set_slider_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setSpinboxValue",
        call: ApiFn::Sim(set_spinbox_value),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setTitle",
        call: ApiFn::Sim(set_title),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setWidgetVisibility",
        call: ApiFn::Sim(set_widget_visibility),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "show",
        call: ApiFn::Sim(show),
        cost: Cost::Quick,
    },
];

/// The `simUI.*` constants: those of `simUI.msgBox`.
pub(super) const CONSTANTS: &[(&str, i64)] = super::legacy::UI_MSGBOX_CONSTANTS;

/// Runs `f` on the UIs, then moves any warnings it produced (unknown XML attributes,
/// a full event queue) to the world log under the caller's name.
fn with_uis<T>(
    sim: &mut Sim,
    ctx: &CallContext<'_>,
    f: impl FnOnce(&mut Uis) -> Result<T, UiError>,
) -> Result<T, SimError> {
    let result = f(&mut sim.uis);
    let t = sim.world.time();
    for msg in sim.uis.take_warnings() {
        sim.world.log.push(t, WARNING, ctx.source, &msg);
    }
    for msg in sim.uis.take_notes() {
        sim.world.log.push(t, INFO, ctx.source, &msg);
    }
    Ok(result?)
}

/// A number argument for an integer value, rounded (see the module doc).
fn rounded(a: &Args<'_>, i: usize) -> Result<i64, SimError> {
    // Finite, so the saturating cast only matters for absurd magnitudes, which the
    // widget then clamps anyway.
    Ok(a.finite(i)?.round() as i64)
}

/// `simUI.create(xml)` → ui handle.
fn create(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let xml = a.str(0)?;
    let owner = ctx.script_object;
    let ui = with_uis(sim, ctx, |u| u.create(xml, owner))?;
    Ok(vec![Value::Int(ui)])
}

/// `simUI.destroy(ui)`.
fn destroy(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let ui = a.handle(0)?;
    with_uis(sim, ctx, |u| u.destroy(ui))?;
    Ok(Vec::new())
}

/// `simUI.getSliderValue(ui, id)` → integer.
fn get_slider_value(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(sim.uis.slider_value(a.handle(0)?, a.int(1)?)?)])
}

/// `simUI.setSliderValue(ui, id, value, suppressEvents=true)`.
fn set_slider_value(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, value, suppress) = (a.handle(0)?, a.int(1)?, rounded(a, 2)?, a.opt_bool(3, true)?);
    with_uis(sim, ctx, |u| u.set_slider_value(ui, id, value, suppress))?;
    Ok(Vec::new())
}

/// `simUI.getLabelText(ui, id)` → text.
fn get_label_text(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::from(sim.uis.label_text(a.handle(0)?, a.int(1)?)?)])
}

/// `simUI.setLabelText(ui, id, text, suppressEvents=true)`; labels queue no event either way.
fn set_label_text(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, text) = (a.handle(0)?, a.int(1)?, a.str(2)?);
    // Checked for type only: simUI accepts the flag, and a label has no signal to suppress.
    a.opt_bool(3, true)?;
    with_uis(sim, ctx, |u| u.set_label_text(ui, id, text))?;
    Ok(Vec::new())
}

/// `simUI.getEditValue(ui, id)` → text.
fn get_edit_value(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::from(sim.uis.edit_value(a.handle(0)?, a.int(1)?)?)])
}

/// `simUI.setEditValue(ui, id, text, suppressEvents=true)`.
fn set_edit_value(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, text, suppress) = (a.handle(0)?, a.int(1)?, a.str(2)?, a.opt_bool(3, true)?);
    with_uis(sim, ctx, |u| u.set_edit_value(ui, id, text, suppress))?;
    Ok(Vec::new())
}

/// `simUI.getCheckboxValue(ui, id)` → 0 unchecked, 1 partial, 2 checked.
fn get_checkbox_value(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(sim.uis.checkbox_value(a.handle(0)?, a.int(1)?)?)])
}

/// `simUI.setCheckboxValue(ui, id, value, suppressEvents=true)` with value 0, 1 or 2.
fn set_checkbox_value(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, value, suppress) = (a.handle(0)?, a.int(1)?, a.int(2)?, a.opt_bool(3, true)?);
    with_uis(sim, ctx, |u| u.set_checkbox_value(ui, id, value, suppress))?;
    Ok(Vec::new())
}

/// `simUI.getRadiobuttonValue(ui, id)` → 1 checked, 0 not.
fn get_radiobutton_value(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let checked = sim.uis.radiobutton_value(a.handle(0)?, a.int(1)?)?;
    Ok(vec![Value::Int(i64::from(checked))])
}

/// `simUI.setRadiobuttonValue(ui, id, value, suppressEvents=true)`; value 1/true checks.
fn set_radiobutton_value(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, checked, suppress) = (a.handle(0)?, a.int(1)?, a.bool(2)?, a.opt_bool(3, true)?);
    with_uis(sim, ctx, |u| u.set_radiobutton_value(ui, id, checked, suppress))?;
    Ok(Vec::new())
}

/// `simUI.getSpinboxValue(ui, id)` → number.
fn get_spinbox_value(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(sim.uis.spinbox_value(a.handle(0)?, a.int(1)?)?)])
}

/// `simUI.setSpinboxValue(ui, id, value, suppressEvents=true)`.
fn set_spinbox_value(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, value, suppress) = (a.handle(0)?, a.int(1)?, a.finite(2)?, a.opt_bool(3, true)?);
    with_uis(sim, ctx, |u| u.set_spinbox_value(ui, id, value, suppress))?;
    Ok(Vec::new())
}

/// `simUI.getEnabled(ui, id)` → boolean (gantry; simUI has only the setter).
fn get_enabled(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Bool(sim.uis.enabled(a.handle(0)?, a.int(1)?)?)])
}

/// `simUI.setEnabled(ui, id, enabled)`.
fn set_enabled(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, enabled) = (a.handle(0)?, a.int(1)?, a.bool(2)?);
    with_uis(sim, ctx, |u| u.set_enabled(ui, id, enabled))?;
    Ok(Vec::new())
}

/// `simUI.show(ui)`.
fn show(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let ui = a.handle(0)?;
    with_uis(sim, ctx, |u| u.set_visible(ui, true))?;
    Ok(Vec::new())
}

/// `simUI.hide(ui)`.
fn hide(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let ui = a.handle(0)?;
    with_uis(sim, ctx, |u| u.set_visible(ui, false))?;
    Ok(Vec::new())
}

/// `simUI.isVisible(ui)` → boolean.
fn is_visible(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Bool(sim.uis.is_visible(a.handle(0)?)?)])
}

/// `simUI.interact(ui, id, value)` (gantry): acts as the user on widget `id` (0 = the
/// window's close button) and queues its callback; see [`Uis::interact`].
fn interact(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, value) = (a.handle(0)?, a.int(1)?, a.get(2));
    with_uis(sim, ctx, |u| u.interact(ui, id, value))?;
    Ok(Vec::new())
}

/// `simUI.getPosition(ui)` → `x, y` in pixels.
fn get_position(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let [x, y] = sim.uis.position(a.handle(0)?)?;
    Ok(vec![Value::Int(x), Value::Int(y)])
}

/// `simUI.setPosition(ui, x, y, suppressEvents=true)`: moves the window (pixels).
fn set_position(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, x, y) = (a.handle(0)?, a.int(1)?, a.int(2)?);
    // Checked for type only: gantry's windows have no move callback to suppress.
    a.opt_bool(3, true)?;
    with_uis(sim, ctx, |u| u.set_position(ui, [x, y]))?;
    Ok(Vec::new())
}

/// `simUI.getTitle(ui)` → text.
fn get_title(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::from(sim.uis.title(a.handle(0)?)?)])
}

/// `simUI.setTitle(ui, title, suppressEvents=true)`.
fn set_title(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, title) = (a.handle(0)?, a.str(1)?);
    // Checked for type only: a title change has no callback.
    a.opt_bool(2, true)?;
    with_uis(sim, ctx, |u| u.set_title(ui, title))?;
    Ok(Vec::new())
}

/// `simUI.getWidgetVisibility(ui, id)` → boolean.
fn get_widget_visibility(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Bool(sim.uis.widget_visible(a.handle(0)?, a.int(1)?)?)])
}

/// `simUI.setWidgetVisibility(ui, id, visible)`.
fn set_widget_visibility(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, visible) = (a.handle(0)?, a.int(1)?, a.bool(2)?);
    with_uis(sim, ctx, |u| u.set_widget_visible(ui, id, visible))?;
    Ok(Vec::new())
}

/// `simUI.setButtonText(ui, id, text)`.
fn set_button_text(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ui, id, text) = (a.handle(0)?, a.int(1)?, a.str(2)?);
    with_uis(sim, ctx, |u| u.set_button_text(ui, id, text))?;
    Ok(Vec::new())
}

/// `simUI.getKeyboardModifiers()` → `{control=bool, shift=bool, alt=bool}`: the modifier
/// keys held now. gantry has no keyboard of its own; a front end reports them
/// ([`crate::ui::SimulatorMessages::modifiers`]), and headless runs hold none.
fn get_keyboard_modifiers(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    if !a.is_empty() {
        return Err(SimError::bad_argument(format!(
            "expected no arguments, got {}",
            a.len()
        )));
    }
    let m = sim.messages.modifiers;
    Ok(vec![Value::Map(vec![
        (Value::Str("control".into()), Value::Bool(m.control)),
        (Value::Str("shift".into()), Value::Bool(m.shift)),
        (Value::Str("alt".into()), Value::Bool(m.alt)),
    ])])
}
