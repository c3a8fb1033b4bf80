//! `sim.getEngineFloatParam`, `sim.setEngineFloatParam` (4.1: `...Parameter`): the
//! physics engine's per-body parameters that gantry's one engine has, a shape's friction
//! and restitution. CoppeliaSim keeps one set per engine (Bullet, ODE, Vortex, Newton);
//! gantry has one coefficient of each, so every engine's name for it reads and writes
//! that one. Any other parameter (the engines' own solver settings, global or per body)
//! is refused with its number rather than pretended.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The engine parameter functions, sorted by name.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getEngineFloatParam",
        call: ApiFn::World(get_engine_float_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setEngineFloatParam",
        call: ApiFn::World(set_engine_float_param),
        cost: Cost::Quick,
    },
];

const BULLET_BODY_RESTITUTION: i64 = 6001;
const BULLET_BODY_OLDFRICTION: i64 = 6002;
const BULLET_BODY_FRICTION: i64 = 6003;
const ODE_BODY_FRICTION: i64 = 15001;
const VORTEX_BODY_RESTITUTION: i64 = 24013;
const NEWTON_BODY_STATICFRICTION: i64 = 33001;
const NEWTON_BODY_KINETICFRICTION: i64 = 33002;
const NEWTON_BODY_RESTITUTION: i64 = 33003;

/// The parameters of this file, CoppeliaSim's values.
pub const CONSTANTS: &[(&str, i64)] = &[
    ("bullet_body_restitution", BULLET_BODY_RESTITUTION),
    ("bullet_body_oldfriction", BULLET_BODY_OLDFRICTION),
    ("bullet_body_friction", BULLET_BODY_FRICTION),
    ("ode_body_friction", ODE_BODY_FRICTION),
    ("vortex_body_restitution", VORTEX_BODY_RESTITUTION),
    ("newton_body_staticfriction", NEWTON_BODY_STATICFRICTION),
    ("newton_body_kineticfriction", NEWTON_BODY_KINETICFRICTION),
    ("newton_body_restitution", NEWTON_BODY_RESTITUTION),
];

/// What a parameter number means in gantry's engine.
enum Param {
    Friction,
    Restitution,
}

fn param(id: i64) -> Result<Param, SimError> {
    match id {
        BULLET_BODY_FRICTION
        | BULLET_BODY_OLDFRICTION
        | ODE_BODY_FRICTION
        | NEWTON_BODY_STATICFRICTION
        | NEWTON_BODY_KINETICFRICTION => Ok(Param::Friction),
        BULLET_BODY_RESTITUTION | VORTEX_BODY_RESTITUTION | NEWTON_BODY_RESTITUTION => Ok(Param::Restitution),
        other => Err(SimError::refused(format!(
            "engine parameter {other} is not one gantry's physics has: it has a shape's friction (sim.bullet_body_friction, sim.ode_body_friction, sim.newton_body_staticfriction/kineticfriction) and restitution (sim.bullet_body_restitution, sim.vortex_body_restitution, sim.newton_body_restitution)"
        ))),
    }
}

/// `sim.getEngineFloatParam(paramId, objectHandle)` → the shape's friction or
/// restitution.
fn get_engine_float_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = param(a.int(0)?)?;
    let h = a.handle(1)?;
    let v = match p {
        Param::Friction => w.shape_friction(h)?,
        Param::Restitution => w.shape_restitution(h)?,
    };
    Ok(vec![Value::Float(v)])
}

/// `sim.setEngineFloatParam(paramId, objectHandle, value)`: the shape's friction (>= 0)
/// or restitution (0..1), in effect from the next contact.
fn set_engine_float_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = param(a.int(0)?)?;
    let h = a.handle(1)?;
    let v = a.finite(2)?;
    match p {
        Param::Friction => w.set_shape_friction(h, v)?,
        Param::Restitution => w.set_shape_restitution(h, v)?,
    }
    Ok(Vec::new())
}
