//! Particle objects (`sim.addParticleObject`): streams of small spheres that V-REP
//! demos emit for jets, sprays and propeller down-wash. Each particle is a dynamic
//! rapier body (a ball of the object's diameter and density) that lives until its
//! object's lifetime runs out, the object is emptied or removed, or the simulation
//! stops (the whole [`crate::sim::Sim`] is rebuilt then, so nothing outlives a run).
//!
//! The model follows CoppeliaSim's dynamics plugin:
//! - an item is `{p1x, p1y, p1z, p2x, p2y, p2z}` in the world frame (m): the particle
//!   starts at `p1` with velocity `p2 - p1` (m/s). With `sim.particle_itemsizes`,
//!   `sim.particle_itemdensities` and `sim.particle_itemcolors` a diameter, a density and
//!   an RGB colour follow, in that order;
//! - a full object (its `maxItemCount` particles alive) replaces its oldest particle with
//!   [`PARTICLE_CYCLIC`] and ignores the new one otherwise;
//! - `params` is CoppeliaSim's list `{n, id1, value1, ..., idn, valuen}` (see
//!   [`ParticleMaterial::from_params`]);
//! - respondable particles (`respondable1to4`/`respondable5to8`) collide with every
//!   shape that collides with anything: gantry's shapes carry no CoppeliaSim respondable
//!   mask (scenes map it onto all-colliding rapier groups), so the two halves of the mask
//!   are not told apart. Particles are in rapier group 32 (`PARTICLE_GROUP`), so a shape
//!   whose collision mask leaves out that bit never meets them;
//!   `particlerespondable` particles also collide with each other (and with those of
//!   other particle-respondable objects). Other particles pass through everything and
//!   move ballistically (gravity and drag only);
//! - `ignoresgravity` particles float; `water` particles float below z = 0 and fall
//!   above it, with the drag of water below and of air above.
//!
//! Bounded: at most [`MAX_PARTICLE_OBJECTS`] objects, [`MAX_PARTICLE_ITEMS`] particles
//! an object and [`MAX_LIVE_PARTICLES`] in the whole world (a full world treats every
//! object as full). Non-goals: the painttag flag (vision sensors do not see particles),
//! and the engine-specific contact parameters other than Bullet's friction and
//! restitution.

use std::collections::{BTreeMap, VecDeque};

use rapier3d::prelude::*;

use super::object::Handle;
use super::world::World;
use crate::error::SimError;
use crate::math::{self, Vec3};

/// The first particle object handle. Particle objects have their own handles, above the
/// drawing objects' and below IK objects', so one passed where another kind is expected
/// names nothing and fails clearly.
pub const FIRST_PARTICLE_HANDLE: Handle = 4_000_000;

/// Cap on live particle objects; creating more fails.
pub const MAX_PARTICLE_OBJECTS: usize = 1_000;

/// Cap on one object's particles, whatever `maxItemCount` asks for (CoppeliaSim allows
/// ten million; each particle here is a rapier body).
pub const MAX_PARTICLE_ITEMS: usize = 10_000;

/// Cap on the particles alive in the world, all objects together. When it is reached
/// every object behaves as if full.
pub const MAX_LIVE_PARTICLES: usize = 20_000;

/// Largest diameter, m (CoppeliaSim clamps larger ones to it).
pub const MAX_PARTICLE_SIZE: f64 = 100.0;

/// `sim.particle_points1`: drawn as 1-pixel points.
pub const PARTICLE_POINTS1: i64 = 0;
/// `sim.particle_points2`: drawn as 2-pixel points.
pub const PARTICLE_POINTS2: i64 = 1;
/// `sim.particle_points4`: drawn as 4-pixel points.
pub const PARTICLE_POINTS4: i64 = 2;
/// `sim.particle_roughspheres`: drawn as spheres.
pub const PARTICLE_ROUGHSPHERES: i64 = 3;
/// `sim.particle_spheres`: drawn as spheres.
pub const PARTICLE_SPHERES: i64 = 4;
/// `sim.particle_respondable1to4`: collides with shapes.
pub const PARTICLE_RESPONDABLE1TO4: i64 = 0x20;
/// `sim.particle_respondable5to8`: collides with shapes (not told apart from 1to4).
pub const PARTICLE_RESPONDABLE5TO8: i64 = 0x40;
/// `sim.particle_particlerespondable`: collides with other particles.
pub const PARTICLE_PARTICLERESPONDABLE: i64 = 0x80;
/// `sim.particle_ignoresgravity`.
pub const PARTICLE_IGNORESGRAVITY: i64 = 0x100;
/// `sim.particle_invisible`: not drawn.
pub const PARTICLE_INVISIBLE: i64 = 0x200;
/// `sim.particle_itemsizes`: each item gives its diameter (m).
pub const PARTICLE_ITEMSIZES: i64 = 0x400;
/// `sim.particle_itemdensities`: each item gives its density (kg/m³).
pub const PARTICLE_ITEMDENSITIES: i64 = 0x800;
/// `sim.particle_itemcolors`: each item gives its RGB colour.
pub const PARTICLE_ITEMCOLORS: i64 = 0x1000;
/// `sim.particle_cyclic`: a full object replaces its oldest particle.
pub const PARTICLE_CYCLIC: i64 = 0x2000;
/// `sim.particle_emissioncolor`: item colours are emissive (the viewer ignores it).
pub const PARTICLE_EMISSIONCOLOR: i64 = 0x4000;
/// `sim.particle_water`: no weight below z = 0 (in the water), water drag there and
/// air drag above.
pub const PARTICLE_WATER: i64 = 0x8000;
/// `sim.particle_painttag`: seen by vision sensors (not in gantry).
pub const PARTICLE_PAINTTAG: i64 = 0x1_0000;

/// The type codes (low bits); the flags start at [`PARTICLE_RESPONDABLE1TO4`].
const TYPE_MASK: i64 = 0x1f;
/// Every flag CoppeliaSim defines.
const FLAGS: i64 = 0x1_ffe0;
/// The rapier collision group of every particle (shapes are in all groups by default).
const PARTICLE_GROUP: Group = Group::GROUP_32;

/// What the particles of an object are made of, from `params`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParticleMaterial {
    /// Coulomb friction with what they touch (param 0, Bullet's friction; default 0).
    pub friction: f64,
    /// Restitution (param 1, Bullet's restitution; default 0).
    pub restitution: f64,
    /// Linear drag, N per m/s (param 5; in the water for water particles).
    pub linear_drag: f64,
    /// Quadratic drag, N per (m/s)² (param 6; in the water for water particles).
    pub quadratic_drag: f64,
    /// Linear drag in the air of water particles, N per m/s (param 7).
    pub air_linear_drag: f64,
    /// Quadratic drag in the air of water particles, N per (m/s)² (param 8).
    pub air_quadratic_drag: f64,
}

impl Default for ParticleMaterial {
    fn default() -> Self {
        Self {
            friction: 0.0,
            restitution: 0.0,
            linear_drag: 0.0,
            quadratic_drag: 0.0,
            air_linear_drag: 0.0,
            air_quadratic_drag: 0.0,
        }
    }
}

impl ParticleMaterial {
    /// Reads CoppeliaSim's `params` list: a count `n`, then `n` pairs of a parameter id
    /// and its value. Ids 0 (friction), 1 (restitution) and 5-8 (drag) are used; the
    /// other engine-specific ids below 18 (ODE, Vortex and Newton contact parameters)
    /// are accepted and ignored, as are ids CoppeliaSim does not know.
    ///
    /// # Errors
    /// A count that is not a whole number, fewer values than it announces, an id that
    /// is not a whole number, a non-finite value, or a negative friction or drag.
    pub fn from_params(params: &[f64]) -> Result<Self, SimError> {
        let mut m = Self::default();
        let Some(&count) = params.first() else {
            return Ok(m);
        };
        let whole = |v: f64| v.is_finite() && v.fract() == 0.0;
        if !whole(count) || count < 0.0 {
            return Err(SimError::bad_argument(format!(
                "params: the first value is the number of (id, value) pairs, got {count}"
            )));
        }
        let pairs = count as usize;
        if params.len() < 1 + 2 * pairs {
            return Err(SimError::bad_argument(format!(
                "params: {pairs} (id, value) pairs announced but {} values follow",
                params.len() - 1
            )));
        }
        for pair in params[1..1 + 2 * pairs].chunks_exact(2) {
            let (id, value) = (pair[0], pair[1]);
            if !whole(id) {
                return Err(SimError::bad_argument(format!(
                    "params: parameter id {id} is not a whole number"
                )));
            }
            if !value.is_finite() {
                return Err(SimError::bad_argument(format!(
                    "params: parameter {id} must be a finite number, got {value}"
                )));
            }
            let id = id as i64;
            if matches!(id, 0 | 5..=8) && value < 0.0 {
                return Err(SimError::bad_argument(format!(
                    "params: parameter {id} (friction or drag) must be 0 or more, got {value}"
                )));
            }
            match id {
                0 => m.friction = value,
                1 => m.restitution = value.clamp(0.0, 1.0),
                5 => m.linear_drag = value,
                6 => m.quadratic_drag = value,
                7 => m.air_linear_drag = value,
                8 => m.air_quadratic_drag = value,
                // Other engines' parameters (ids 2-4, 9-17), and ids CoppeliaSim skips.
                _ => {}
            }
        }
        Ok(m)
    }
}

/// What `sim.addParticleObject` asks for, checked by the API.
#[derive(Debug, Clone, PartialEq)]
pub struct ParticleParams {
    /// Type code (0-4) OR-ed with `sim.particle_*` flags.
    pub object_type: i64,
    /// Diameter, m (positive; clamped to [`MAX_PARTICLE_SIZE`]).
    pub size: f64,
    /// Density, kg/m³ (positive).
    pub density: f64,
    /// Contact and drag parameters.
    pub material: ParticleMaterial,
    /// Lifetime of each particle, s; 0 means until removed.
    pub life_time: f64,
    /// Most particles alive at once (at least 1; capped at [`MAX_PARTICLE_ITEMS`]).
    pub max_items: usize,
    /// RGB in [0, 1].
    pub color: [f64; 3],
}

/// One particle: its rapier body and what it was given.
#[derive(Debug, Clone)]
struct Particle {
    body: RigidBodyHandle,
    /// Simulation time after which it goes, s (infinite without a lifetime).
    kill_time: f64,
}

/// A particle object and its live particles.
#[derive(Debug, Clone)]
pub struct ParticleObject {
    object_type: i64,
    size: f64,
    density: f64,
    material: ParticleMaterial,
    life_time: f64,
    max_items: usize,
    color: [f64; 3],
    /// Oldest first. Every particle of an object has the same lifetime, so they also
    /// expire in this order.
    items: VecDeque<Particle>,
}

impl ParticleObject {
    /// Type code and flags as created.
    pub fn object_type(&self) -> i64 {
        self.object_type
    }

    /// The type code alone (0-4: points1, points2, points4, roughspheres, spheres).
    pub fn kind(&self) -> i64 {
        self.object_type & TYPE_MASK
    }

    /// Whether flag `flag` (a `PARTICLE_*` constant) is set.
    pub fn has(&self, flag: i64) -> bool {
        self.object_type & flag != 0
    }

    /// Diameter, m.
    pub fn size(&self) -> f64 {
        self.size
    }

    /// Density, kg/m³.
    pub fn density(&self) -> f64 {
        self.density
    }

    /// Contact and drag parameters.
    pub fn material(&self) -> &ParticleMaterial {
        &self.material
    }

    /// Lifetime of each particle, s (0: until removed).
    pub fn life_time(&self) -> f64 {
        self.life_time
    }

    /// Most particles alive at once.
    pub fn max_items(&self) -> usize {
        self.max_items
    }

    /// RGB colour.
    pub fn color(&self) -> [f64; 3] {
        self.color
    }

    /// Live particles.
    pub fn item_count(&self) -> usize {
        self.items.len()
    }

    /// Numbers one item takes: 6, plus the per-item values the flags ask for.
    pub fn floats_per_item(&self) -> usize {
        6 + usize::from(self.has(PARTICLE_ITEMSIZES))
            + usize::from(self.has(PARTICLE_ITEMDENSITIES))
            + 3 * usize::from(self.has(PARTICLE_ITEMCOLORS))
    }

    /// The rapier interaction groups of this object's particles.
    fn groups(&self) -> InteractionGroups {
        let mut filter = Group::NONE;
        if self.has(PARTICLE_RESPONDABLE1TO4 | PARTICLE_RESPONDABLE5TO8) {
            filter |= !PARTICLE_GROUP;
        }
        if self.has(PARTICLE_PARTICLERESPONDABLE) {
            filter |= PARTICLE_GROUP;
        }
        InteractionGroups::new(PARTICLE_GROUP, filter, InteractionTestMode::And)
    }
}

/// Every particle object of the running simulation, by handle.
#[derive(Debug, Clone)]
pub struct Particles {
    objects: BTreeMap<Handle, ParticleObject>,
    next_handle: Handle,
    /// Particles alive, all objects together.
    live: usize,
}

impl Default for Particles {
    fn default() -> Self {
        Self {
            objects: BTreeMap::new(),
            next_handle: FIRST_PARTICLE_HANDLE,
            live: 0,
        }
    }
}

fn no_such(h: Handle) -> SimError {
    SimError::no_such_item(format!("particle object does not exist (handle {h})"))
}

impl Particles {
    /// Creates a particle object, empty, and returns its handle.
    ///
    /// # Errors
    /// An unknown type code or flag, a size or density that is not a positive number, a
    /// negative or non-finite lifetime, or [`MAX_PARTICLE_OBJECTS`] objects alive.
    pub fn create(&mut self, p: ParticleParams) -> Result<Handle, SimError> {
        let code = p.object_type & TYPE_MASK;
        if !(PARTICLE_POINTS1..=PARTICLE_SPHERES).contains(&code) || p.object_type & !(TYPE_MASK | FLAGS) != 0 {
            return Err(SimError::bad_argument(format!(
                "argument 1: unknown particle object type {} (a sim.particle_points1..spheres type plus sim.particle_* flags)",
                p.object_type
            )));
        }
        if !(p.size.is_finite() && p.size > 0.0) {
            return Err(SimError::bad_argument(format!(
                "argument 2: particle size must be a positive number of metres, got {}",
                p.size
            )));
        }
        if !(p.density.is_finite() && p.density > 0.0) {
            return Err(SimError::bad_argument(format!(
                "argument 3: particle density must be a positive number of kg/m³, got {}",
                p.density
            )));
        }
        if !(p.life_time.is_finite() && p.life_time >= 0.0) {
            return Err(SimError::bad_argument(format!(
                "argument 5: lifetime must be 0 (forever) or a positive number of seconds, got {}",
                p.life_time
            )));
        }
        if self.objects.len() >= MAX_PARTICLE_OBJECTS {
            return Err(SimError::refused(format!(
                "too many particle objects ({MAX_PARTICLE_OBJECTS}); remove some with sim.removeParticleObject"
            )));
        }
        let h = self.next_handle;
        self.next_handle += 1;
        self.objects.insert(
            h,
            ParticleObject {
                object_type: p.object_type,
                size: p.size.min(MAX_PARTICLE_SIZE),
                density: p.density,
                material: p.material,
                life_time: p.life_time,
                max_items: p.max_items.clamp(1, MAX_PARTICLE_ITEMS),
                color: p.color,
                items: VecDeque::new(),
            },
        );
        Ok(h)
    }

    /// The particle object behind a handle.
    ///
    /// # Errors
    /// No particle object has this handle.
    pub fn object(&self, h: Handle) -> Result<&ParticleObject, SimError> {
        self.objects.get(&h).ok_or_else(|| no_such(h))
    }

    /// Every particle object with its handle, in creation order.
    pub fn iter(&self) -> impl Iterator<Item = (Handle, &ParticleObject)> {
        self.objects.iter().map(|(&h, o)| (h, o))
    }

    /// Number of particle objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether there is no particle object.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Particles alive, all objects together.
    pub fn live(&self) -> usize {
        self.live
    }

    /// Emits one particle (`sim.addParticleObjectItem`); see the module docs for the
    /// item layout. Returns whether it was added: `false` when the object (or the world,
    /// at [`MAX_LIVE_PARTICLES`]) is full and not cyclic.
    ///
    /// # Errors
    /// No such object, too few numbers for the object's item layout, a non-finite
    /// number, or a per-item size or density that is not positive.
    pub fn add_item(&mut self, world: &mut World, h: Handle, data: &[f64]) -> Result<bool, SimError> {
        let o = self.objects.get(&h).ok_or_else(|| no_such(h))?;
        let need = o.floats_per_item();
        if data.len() < need {
            return Err(SimError::bad_argument(format!(
                "argument 2: this particle object's items take {need} numbers (start point, end point{}), got {}",
                extras(o),
                data.len()
            )));
        }
        if let Some(i) = data[..need].iter().position(|v| !v.is_finite()) {
            return Err(SimError::bad_argument(format!(
                "argument 2: element {} must be a finite number, got {}",
                i + 1,
                data[i]
            )));
        }
        let mut next = 6;
        let mut take = || {
            next += 1;
            data[next - 1]
        };
        let size = if o.has(PARTICLE_ITEMSIZES) { take() } else { o.size };
        let density = if o.has(PARTICLE_ITEMDENSITIES) {
            take()
        } else {
            o.density
        };
        if size <= 0.0 || density <= 0.0 {
            return Err(SimError::bad_argument(format!(
                "argument 2: an item's size and density must be positive, got {size} m and {density} kg/m³"
            )));
        }
        let full = o.items.len() >= o.max_items || self.live >= MAX_LIVE_PARTICLES;
        if full {
            if !o.has(PARTICLE_CYCLIC) || o.items.is_empty() {
                return Ok(false);
            }
            self.drop_oldest(world, h);
        }
        let o = &self.objects[&h];
        let start = Vec3::new(data[0], data[1], data[2]);
        let velocity = Vec3::new(data[3], data[4], data[5]) - start;
        let respondable = o.has(PARTICLE_RESPONDABLE1TO4 | PARTICLE_RESPONDABLE5TO8 | PARTICLE_PARTICLERESPONDABLE);
        let body = RigidBodyBuilder::dynamic()
            .translation(math::vec_to_physics(&start))
            .linvel(math::vec_to_physics(&velocity))
            .gravity_scale(gravity_scale(o, start.z))
            // Fast and small: without continuous collision detection a jet tunnels
            // through thin walls.
            .ccd_enabled(respondable);
        let collider = ColliderBuilder::ball((size.min(MAX_PARTICLE_SIZE) / 2.0) as f32)
            .density(density as f32)
            .friction(o.material.friction as f32)
            .restitution(o.material.restitution as f32)
            .collision_groups(o.groups())
            .solver_groups(o.groups());
        let kill_time = if o.life_time > 0.0 {
            world.time() + o.life_time
        } else {
            f64::INFINITY
        };
        let physics = &mut world.physics.world;
        let body = physics.insert_body(body);
        physics.insert_collider(collider, Some(body));
        if let Some(o) = self.objects.get_mut(&h) {
            o.items.push_back(Particle { body, kill_time });
            self.live += 1;
        }
        Ok(true)
    }

    /// Removes every particle of an object (`sim.addParticleObjectItem(h, nil)`).
    ///
    /// # Errors
    /// No such object.
    pub fn clear(&mut self, world: &mut World, h: Handle) -> Result<(), SimError> {
        let o = self.objects.get_mut(&h).ok_or_else(|| no_such(h))?;
        for p in o.items.drain(..) {
            world.physics.world.remove_body(p.body);
            self.live -= 1;
        }
        Ok(())
    }

    /// Removes a particle object and its particles.
    ///
    /// # Errors
    /// No such object.
    pub fn remove(&mut self, world: &mut World, h: Handle) -> Result<(), SimError> {
        self.clear(world, h)?;
        self.objects.remove(&h);
        Ok(())
    }

    /// Removes every particle object (`sim.removeParticleObject(sim.handle_all)`).
    pub fn remove_all(&mut self, world: &mut World) {
        let handles: Vec<Handle> = self.objects.keys().copied().collect();
        for h in handles {
            // Listed just above, so it exists.
            let _ = self.remove(world, h);
        }
    }

    /// World positions (m) of an object's live particles, oldest first.
    ///
    /// # Errors
    /// No such object.
    pub fn positions(&self, world: &World, h: Handle) -> Result<Vec<Vec3>, SimError> {
        let o = self.object(h)?;
        let bodies = &world.physics.world.bodies;
        Ok(o.items
            .iter()
            .filter_map(|p| bodies.get(p.body))
            .map(|rb| math::vec_from_physics(rb.translation()))
            .collect())
    }

    /// World velocities (m/s) of an object's live particles, oldest first.
    ///
    /// # Errors
    /// No such object.
    pub fn velocities(&self, world: &World, h: Handle) -> Result<Vec<Vec3>, SimError> {
        let o = self.object(h)?;
        let bodies = &world.physics.world.bodies;
        Ok(o.items
            .iter()
            .filter_map(|p| bodies.get(p.body))
            .map(|rb| math::vec_from_physics(rb.linvel()))
            .collect())
    }

    /// Before a physics step: sets each particle's gravity (water particles weigh only
    /// above z = 0) and its drag force for the step, F = -v̂ (k₁|v| + k₂|v|²), limited so
    /// that drag alone stops a particle within the step but never sends it back.
    pub fn before_step(&self, world: &mut World) {
        let dt = world.settings().dt;
        let bodies = &mut world.physics.world.bodies;
        for o in self.objects.values() {
            let m = &o.material;
            let drag = m.linear_drag != 0.0
                || m.quadratic_drag != 0.0
                || (o.has(PARTICLE_WATER) && (m.air_linear_drag != 0.0 || m.air_quadratic_drag != 0.0));
            if !drag && !o.has(PARTICLE_WATER) {
                continue;
            }
            for p in &o.items {
                let Some(rb) = bodies.get_mut(p.body) else {
                    continue;
                };
                let z = f64::from(rb.translation().z);
                if o.has(PARTICLE_WATER) {
                    rb.set_gravity_scale(gravity_scale(o, z), true);
                }
                rb.reset_forces(false);
                let v = math::vec_from_physics(rb.linvel());
                let speed = v.norm();
                if !drag || speed == 0.0 {
                    continue;
                }
                let (k1, k2) = if o.has(PARTICLE_WATER) && z >= 0.0 {
                    (m.air_linear_drag, m.air_quadratic_drag)
                } else {
                    (m.linear_drag, m.quadratic_drag)
                };
                let mass = f64::from(rb.mass());
                let stop = if dt > 0.0 { mass * speed / dt } else { f64::INFINITY };
                let magnitude = (k1 * speed + k2 * speed * speed).min(stop);
                rb.add_force(math::vec_to_physics(&(-v / speed * magnitude)), true);
            }
        }
    }

    /// After a physics step that ends at simulation time `now` (s): removes the
    /// particles whose lifetime ran out (CoppeliaSim: once the time passes the kill time).
    pub fn after_step(&mut self, world: &mut World, now: f64) {
        for o in self.objects.values_mut() {
            while o.items.front().is_some_and(|p| now > p.kill_time) {
                if let Some(p) = o.items.pop_front() {
                    world.physics.world.remove_body(p.body);
                    self.live -= 1;
                }
            }
        }
    }

    /// Removes object `h`'s oldest particle, if any.
    fn drop_oldest(&mut self, world: &mut World, h: Handle) {
        if let Some(p) = self.objects.get_mut(&h).and_then(|o| o.items.pop_front()) {
            world.physics.world.remove_body(p.body);
            self.live -= 1;
        }
    }
}

/// Gravity scale of a particle at height `z` (m): 0 when it ignores gravity, or is a
/// water particle in the water (z < 0).
fn gravity_scale(o: &ParticleObject, z: f64) -> f32 {
    if o.has(PARTICLE_IGNORESGRAVITY) || (o.has(PARTICLE_WATER) && z < 0.0) {
        0.0
    } else {
        1.0
    }
}

/// The per-item values an object's items carry after the two points, for messages.
fn extras(o: &ParticleObject) -> String {
    let mut s = String::new();
    for (flag, what) in [
        (PARTICLE_ITEMSIZES, ", size"),
        (PARTICLE_ITEMDENSITIES, ", density"),
        (PARTICLE_ITEMCOLORS, ", r, g, b"),
    ] {
        if o.has(flag) {
            s.push_str(what);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::scene::{EmbeddedFiles, LoadOptions, load_scene_text};

    /// An empty world (no floor: particles fly freely).
    fn world() -> World {
        let model = load_scene_text(
            &EmbeddedFiles::default(),
            "",
            Path::new("/empty.toml"),
            &LoadOptions::default(),
        )
        .expect("an empty scene loads");
        World::new(&model)
    }

    fn params(object_type: i64, max_items: usize, life_time: f64) -> ParticleParams {
        ParticleParams {
            object_type,
            size: 0.02,
            density: 1000.0,
            material: ParticleMaterial::default(),
            life_time,
            max_items,
            color: [1.0, 1.0, 1.0],
        }
    }

    /// One item at `x` on the x axis moving at 1 m/s along x.
    fn item(x: f64) -> [f64; 6] {
        [x, 0.0, 0.0, x + 1.0, 0.0, 0.0]
    }

    #[test]
    fn params_are_count_then_id_value_pairs() {
        // The propeller scripts' list: restitution 0.2 (id 1), ODE soft ERP (id 3).
        let m = ParticleMaterial::from_params(&[2.0, 1.0, 0.2, 3.0, 0.4]).expect("valid");
        assert_eq!(
            m,
            ParticleMaterial {
                restitution: 0.2,
                ..ParticleMaterial::default()
            }
        );
        let m = ParticleMaterial::from_params(&[3.0, 5.0, 0.1, 6.0, 0.01, 99.0, 7.0]).expect("valid");
        assert_eq!(
            (m.linear_drag, m.quadratic_drag),
            (0.1, 0.01),
            "unknown id 99 is skipped"
        );
        assert_eq!(
            ParticleMaterial::from_params(&[]).expect("empty"),
            ParticleMaterial::default()
        );
        for bad in [
            &[2.0, 1.0, 0.2][..],
            &[1.5, 1.0, 0.2],
            &[1.0, 0.5, 0.2],
            &[1.0, 5.0, -1.0],
        ] {
            assert!(ParticleMaterial::from_params(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn a_full_object_ignores_or_replaces_the_oldest() {
        let mut w = world();
        let mut ps = Particles::default();
        let plain = ps.create(params(PARTICLE_SPHERES, 2, 0.0)).expect("create");
        let cyclic = ps
            .create(params(PARTICLE_SPHERES | PARTICLE_CYCLIC, 2, 0.0))
            .expect("create");
        for x in [1.0, 2.0, 3.0] {
            let added = ps.add_item(&mut w, plain, &item(x)).expect("add");
            assert_eq!(added, x < 3.0, "the third item of a full plain object is ignored");
            assert!(ps.add_item(&mut w, cyclic, &item(x)).expect("add"));
        }
        let xs = |h| -> Vec<f64> { ps.positions(&w, h).expect("exists").iter().map(|p| p.x).collect() };
        assert_eq!(xs(plain), [1.0, 2.0]);
        assert_eq!(xs(cyclic), [2.0, 3.0], "the oldest went");
        assert_eq!(ps.live(), 4);
        // Velocity is the end point minus the start point.
        let v = ps.velocities(&w, plain).expect("exists");
        assert!((v[0] - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-6);
        ps.clear(&mut w, plain).expect("clear");
        assert_eq!(ps.object(plain).expect("kept").item_count(), 0);
        ps.remove(&mut w, cyclic).expect("remove");
        assert_eq!((ps.live(), ps.len()), (0, 1));
        assert_eq!(w.physics.world.bodies.len(), 0, "every particle body left rapier");
        assert!(ps.remove(&mut w, cyclic).is_err());
    }

    #[test]
    fn particles_go_when_their_lifetime_is_over() {
        let mut w = world();
        let mut ps = Particles::default();
        let h = ps.create(params(PARTICLE_POINTS1, 10, 0.1)).expect("create");
        ps.add_item(&mut w, h, &item(0.0)).expect("add");
        ps.after_step(&mut w, 0.1);
        assert_eq!(
            ps.object(h).expect("exists").item_count(),
            1,
            "alive at exactly its lifetime"
        );
        ps.after_step(&mut w, 0.15);
        assert_eq!(ps.object(h).expect("exists").item_count(), 0);
        assert_eq!(ps.live(), 0);
    }

    #[test]
    fn item_layout_follows_the_flags() {
        let mut w = world();
        let mut ps = Particles::default();
        let flags = PARTICLE_ITEMSIZES | PARTICLE_ITEMDENSITIES | PARTICLE_ITEMCOLORS;
        let h = ps.create(params(PARTICLE_SPHERES | flags, 10, 0.0)).expect("create");
        assert_eq!(ps.object(h).expect("exists").floats_per_item(), 11);
        let short = ps.add_item(&mut w, h, &item(0.0)).expect_err("needs 11 numbers");
        assert!(short.to_string().contains("size, density, r, g, b"), "{short}");
        let mut data = item(0.0).to_vec();
        data.extend([0.1, 2000.0, 1.0, 0.0, 0.0]);
        assert!(ps.add_item(&mut w, h, &data).expect("add"));
        data[7] = 0.0;
        assert!(ps.add_item(&mut w, h, &data).is_err(), "zero density");
        data[7] = 2000.0;
        data[2] = f64::NAN;
        assert!(ps.add_item(&mut w, h, &data).is_err());
    }

    /// Steps the world with the particles, as [`crate::sim::Sim::step_dynamics`] does.
    fn step(w: &mut World, ps: &mut Particles) {
        ps.before_step(w);
        w.step_physics();
        let end = w.time() + w.settings().dt;
        ps.after_step(w, end);
        w.advance_time();
    }

    #[test]
    fn drag_slows_particles_and_water_particles_float_below_the_surface() {
        let mut w = world();
        let mut ps = Particles::default();
        let mut p = params(PARTICLE_SPHERES | PARTICLE_IGNORESGRAVITY, 10, 0.0);
        // Linear drag of 1e-3 N per m/s on a 4.2 g ball: |v| decays by about 24% a second.
        p.material = ParticleMaterial::from_params(&[1.0, 5.0, 1e-3]).expect("valid");
        let dragged = ps.create(p).expect("create");
        let free = ps
            .create(params(PARTICLE_SPHERES | PARTICLE_IGNORESGRAVITY, 10, 0.0))
            .expect("create");
        let water = ps
            .create(params(PARTICLE_SPHERES | PARTICLE_WATER, 10, 0.0))
            .expect("create");
        for h in [dragged, free] {
            ps.add_item(&mut w, h, &item(0.0)).expect("add");
        }
        ps.add_item(&mut w, water, &[0.0, 0.0, -1.0, 0.0, 0.0, -1.0])
            .expect("under water");
        ps.add_item(&mut w, water, &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0])
            .expect("in the air");
        for _ in 0..20 {
            step(&mut w, &mut ps);
        }
        let speed = |h| ps.velocities(&w, h).expect("exists")[0].norm();
        assert!((speed(free) - 1.0).abs() < 1e-6, "no drag, no gravity: {}", speed(free));
        let expected = (-1e-3 / (1000.0 * std::f64::consts::PI / 6.0 * 0.02_f64.powi(3))).exp();
        assert!(
            (speed(dragged) - expected).abs() < 0.02,
            "{} vs {expected}",
            speed(dragged)
        );
        let z: Vec<f64> = ps.positions(&w, water).expect("exists").iter().map(|p| p.z).collect();
        assert!((z[0] + 1.0).abs() < 1e-6, "weightless in the water: {z:?}");
        assert!(z[1] < 0.0, "falls in the air: {z:?}");
    }

    #[test]
    fn bad_objects_are_refused() {
        let mut ps = Particles::default();
        for (t, size, density, life) in [
            (5, 0.1, 1.0, 0.0),
            (PARTICLE_SPHERES | 0x2_0000, 0.1, 1.0, 0.0),
            (0, 0.0, 1.0, 0.0),
            (0, 0.1, -1.0, 0.0),
            (0, 0.1, 1.0, -1.0),
        ] {
            let mut p = params(t, 1, life);
            p.size = size;
            p.density = density;
            assert!(
                ps.create(p).is_err(),
                "type {t} size {size} density {density} life {life}"
            );
        }
        assert!(ps.is_empty());
        let mut w = world();
        assert!(ps.add_item(&mut w, FIRST_PARTICLE_HANDLE, &item(0.0)).is_err());
    }
}
