//! `sim.getLightParameters`, `sim.setLightParameters`: a light object's on/off state and
//! its diffuse and specular colours, as CoppeliaSim 4.1+ has them. The ambient part of
//! the older API is reserved: read as zero, ignored when set. A light's other
//! parameters (casting shadows, spot exponent and cutoff, attenuation) are object
//! parameters (`params.rs`). Gantry's renderers keep their own lighting, so these
//! values are kept and read back, and shine on nothing.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::scene::LightModel;
use crate::world::{Handle, ObjectKind, World};

/// The light functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getLightParameters",
        call: ApiFn::World(get_light_parameters),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setLightParameters",
        call: ApiFn::World(set_light_parameters),
        cost: Cost::Quick,
    },
];

/// The light of argument 0.
fn light_of(w: &World, a: &Args<'_>) -> Result<(Handle, LightModel), SimError> {
    let h = a.handle(0)?;
    match &w.object(h)?.kind {
        ObjectKind::Light(l) => Ok((h, *l)),
        other => Err(SimError::WrongKind {
            handle: h,
            expected: "light",
            actual: other.name(),
        }),
    }
}

/// `sim.getLightParameters(lightHandle)` → (state, zero, diffusePart, specularPart):
/// state 1 when the light is on, else 0; `zero` the reserved ambient part, `{0, 0, 0}`.
fn get_light_parameters(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (_, l) = light_of(w, a)?;
    Ok(vec![
        Value::Int(i64::from(l.on)),
        Value::floats(&[0.0; 3]),
        Value::floats(&l.diffuse),
        Value::floats(&l.specular),
    ])
}

/// `sim.setLightParameters(lightHandle, state, reserved, diffusePart, specularPart)`:
/// state bit 0 turns the light on (a boolean is accepted too); `reserved` (the old
/// ambient part) is ignored; a nil colour is left as it is. Colours are RGB in 0..1.
fn set_light_parameters(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (h, mut l) = light_of(w, a)?;
    l.on = match a.get(1) {
        Value::Bool(b) => *b,
        _ => a.int(1)? & 1 != 0,
    };
    for (i, part) in [(3, &mut l.diffuse), (4, &mut l.specular)] {
        if a.get(i) == &Value::Nil {
            continue;
        }
        let c = a.floats::<3>(i)?;
        if !c.iter().all(|v| (0.0..=1.0).contains(v)) {
            return Err(SimError::bad_argument(format!(
                "argument {}: colour components are from 0 to 1, got {c:?}",
                i + 1
            )));
        }
        *part = c;
    }
    w.set_light(h, l)?;
    Ok(Vec::new())
}
