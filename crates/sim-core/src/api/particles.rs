//! `sim.addParticleObject`, `sim.addParticleObjectItem`, `sim.removeParticleObject`:
//! V-REP's particle jets and sprays. The particles are rapier bodies of the running
//! simulation ([`crate::world::Particles`] has the model and what is not simulated);
//! the viewer shows them through drawing objects ([`Sim::draw_particles`]).

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::{Sim, SimulationState};
use crate::world::{Handle, ParticleMaterial, ParticleParams};

/// The particle functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "addParticleObject",
        call: ApiFn::Sim(add_particle_object),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "addParticleObjectItem",
        call: ApiFn::Sim(add_particle_object_item),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "removeParticleObject",
        call: ApiFn::Sim(remove_particle_object),
        cost: Cost::Quick,
    },
];

/// The `sim.particle_*` constants, CoppeliaSim's values.
pub const CONSTANTS: &[(&str, i64)] = &[
    ("particle_points1", crate::world::PARTICLE_POINTS1),
    ("particle_points2", crate::world::PARTICLE_POINTS2),
    ("particle_points4", crate::world::PARTICLE_POINTS4),
    ("particle_roughspheres", crate::world::PARTICLE_ROUGHSPHERES),
    ("particle_spheres", crate::world::PARTICLE_SPHERES),
    ("particle_respondable1to4", crate::world::PARTICLE_RESPONDABLE1TO4),
    ("particle_respondable5to8", crate::world::PARTICLE_RESPONDABLE5TO8),
    (
        "particle_particlerespondable",
        crate::world::PARTICLE_PARTICLERESPONDABLE,
    ),
    ("particle_ignoresgravity", crate::world::PARTICLE_IGNORESGRAVITY),
    ("particle_invisible", crate::world::PARTICLE_INVISIBLE),
    ("particle_itemsizes", crate::world::PARTICLE_ITEMSIZES),
    ("particle_itemdensities", crate::world::PARTICLE_ITEMDENSITIES),
    ("particle_itemcolors", crate::world::PARTICLE_ITEMCOLORS),
    ("particle_cyclic", crate::world::PARTICLE_CYCLIC),
    ("particle_emissioncolor", crate::world::PARTICLE_EMISSIONCOLOR),
    ("particle_water", crate::world::PARTICLE_WATER),
    ("particle_painttag", crate::world::PARTICLE_PAINTTAG),
];

/// `sim.handle_all`.
const HANDLE_ALL: Handle = -2;
/// CoppeliaSim's default particle colour when none is given.
const DEFAULT_COLOR: [f64; 3] = [0.5, 0.5, 0.5];

/// `sim.addParticleObject(objectType, size, density, params, lifeTime, maxItemCount,
/// color)` → particle object handle.
///
/// `objectType`: `sim.particle_points1/2/4`, `roughspheres` or `spheres`, plus
/// `sim.particle_*` flags. `size`: diameter (m, at most 100). `density`: kg/m³.
/// `params`: nil or `{n, id1, value1, ...}`: id 0 friction, 1 restitution, 5/6 linear
/// and quadratic drag (N per m/s, N per (m/s)²; in the water for water particles), 7/8
/// the same in the air for water particles; the other engines' ids are ignored.
/// `lifeTime`: s, 0 for forever. `maxItemCount`: particles alive at once (at least 1, at
/// most 10,000). `color`: RGB, or 4.1's `ambient_diffuse, nil, specular, emission`
/// (specular and emission are checked and ignored). Only while the simulation runs:
/// particle objects go with it at stop.
fn add_particle_object(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    if sim.state == SimulationState::Stopped {
        return Err(SimError::refused(
            "particle objects exist only while the simulation runs (simulation is not running)",
        ));
    }
    let object_type = a.int(0)?;
    let size = a.finite(1)?;
    let density = a.finite(2)?;
    let material = match a.opt_numbers(3)? {
        None => ParticleMaterial::default(),
        Some(p) => ParticleMaterial::from_params(&p).map_err(|e| e.prefixed("argument 4: "))?,
    };
    let life_time = a.finite(4)?;
    let max_items = a.int(5)?;
    let color = match a.get(6) {
        Value::Nil => DEFAULT_COLOR,
        _ => a.floats::<3>(6)?.map(|c| c.clamp(0.0, 1.0)),
    };
    for i in [8, 9] {
        if !matches!(a.get(i), Value::Nil) {
            a.floats::<3>(i)?;
        }
    }
    let h = sim.particles.create(ParticleParams {
        object_type,
        size,
        density,
        material,
        life_time,
        // CoppeliaSim raises anything below 1 to 1.
        max_items: usize::try_from(max_items).unwrap_or(1),
        color,
    })?;
    sim.draw_particles();
    Ok(vec![Value::Int(h)])
}

/// `sim.addParticleObjectItem(objectHandle, itemData)`: emits one particle.
///
/// `itemData` is `{p1x, p1y, p1z, p2x, p2y, p2z}` in the world frame (m): the particle
/// starts at p1 with velocity p2 - p1 (m/s); the object's `itemsizes`, `itemdensities`
/// and `itemcolors` flags each add values after them (diameter, density, r, g, b; the
/// colour is not drawn). A full object replaces its oldest particle when cyclic and
/// ignores the item otherwise. `nil` removes every particle of the object. The particle
/// is drawn from the next step on.
fn add_particle_object_item(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    match a.opt_numbers(1)? {
        None => sim.particles.clear(&mut sim.world, h)?,
        Some(data) => {
            sim.particles.add_item(&mut sim.world, h, &data)?;
        }
    }
    Ok(Vec::new())
}

/// `sim.removeParticleObject(objectHandle)`: removes the object and its particles;
/// `sim.handle_all` removes every particle object.
fn remove_particle_object(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    match a.handle(0)? {
        HANDLE_ALL => sim.particles.remove_all(&mut sim.world),
        h => sim.particles.remove(&mut sim.world, h)?,
    }
    sim.draw_particles();
    Ok(Vec::new())
}
