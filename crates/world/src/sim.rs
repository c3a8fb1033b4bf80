//! [`Sim`]: the top floor of sim-core. It owns the world (object tree and physics) and
//! the subsystems built on it, knows whether the simulation runs, and has the one
//! [`Sim::step`] every caller without scripts uses (benches, tests, tools). The Lua host
//! runs the same phases with its hooks between them ([`Sim::step_dynamics`],
//! [`Sim::finish_step`]), so the order is written once.
//!
//! Floors, each importing only from those below it (checked by `tools/layers.py`):
//!
//! 1. `handle`, `math`, `error`, `signals`, `tubes`: leaves; `paths` on `math`.
//! 2. `scene`: the model read from files.
//! 3. `world`: objects and physics.
//! 4. `sensor`, `vision`, `ik`, `drawing`, `graph`, `motion`, `planning`: subsystems,
//!    each taking the world as an argument. What of `ik` and `planning` needs no world,
//!    and simUI's model (`ui`), are crates below this one (`gantry-ik`,
//!    `gantry-planning`, `gantry-ui`), so that this aggregate can own their state.
//! 5. `ik_groups`: the scene's IK groups, on `ik`.
//! 6. `sim`: this aggregate.
//! 7. `api`: the `sim.*` registry over [`Sim`].

use std::collections::BTreeMap;

use gantry_ui::{FloatingViews, SimulatorMessages, Uis};

use crate::drawing::{DrawingObject, DrawingParams, Drawings, MAX_DRAWING_ITEMS};
use crate::error::SimError;
use crate::graph::Graphs;
use crate::handle::Handle;
use crate::ik::IkEnvironments;
use crate::ik_groups::SceneIkGroups;
use crate::motion::RuckigObjects;
use crate::paths::{PathObject, Paths};
use crate::planning::Planning;
use crate::scene::{ObjectModelKind, SceneModel};
use crate::signals::Signals;
use crate::tubes::Tubes;
use crate::vision::VisionStates;
use crate::world::{PARTICLE_INVISIBLE, PARTICLE_POINTS1, PARTICLE_POINTS2, PARTICLE_POINTS4, Particles, World};

/// A simulation: the world and everything scripts and clients build on it.
pub struct Sim {
    /// The object tree and physics.
    pub world: World,
    /// Running, paused or stopped, as the orchestrator (the Lua host) reports it.
    pub state: SimulationState,
    /// Which pass of a running simulation this is (see [`Advancing`]).
    pub advancing: Advancing,
    /// Named signals shared by scripts and clients.
    pub signals: Signals,
    /// Tubes between scripts (`sim.tubeOpen`), gone with the simulation at stop.
    pub tubes: Tubes,
    /// User-interface events for `sim.getSimulatorMessage` (keys pressed in the viewer).
    pub messages: SimulatorMessages,
    /// Drawing objects.
    pub drawings: Drawings,
    /// Graph streams.
    pub graphs: Graphs,
    /// Custom UIs.
    pub uis: Uis,
    /// Floating views over the viewer's 3D view (`sim.floatingViewAdd`).
    pub views: FloatingViews,
    /// IK environments.
    pub ik: IkEnvironments,
    /// The scene's IK groups (`sim.getIkGroupHandle`).
    pub ik_groups: SceneIkGroups,
    /// Vision sensors' images.
    pub vision: VisionStates,
    /// Ruckig trajectory generators (`sim.ruckigPos`), gone with the simulation at stop.
    pub ruckig: RuckigObjects,
    /// Motion-planning state spaces and tasks (`simOMPL`), gone with the simulation at
    /// stop.
    pub planning: Planning,
    /// Path objects' data (`sim.createPath`), by the handle of their dummy.
    pub paths: Paths,
    /// Particle objects (`sim.addParticleObject`), gone with the simulation at stop.
    pub particles: Particles,
    /// The drawing object that shows each visible particle object, by particle object
    /// handle (see [`Sim::draw_particles`]).
    particle_drawings: BTreeMap<Handle, ParticleDrawing>,
}

impl Sim {
    /// A stopped simulation of a resolved scene, with no drawings, UIs, IK environments
    /// or signals yet (scripts create those).
    pub fn new(model: &SceneModel) -> Self {
        let mut sim = Self::from_world(World::new(model));
        sim.ik_groups = SceneIkGroups::build(&model.ik_groups);
        // Old path objects: the world has their frames (handle = model index), the
        // curves live here.
        for (i, o) in model.objects.iter().enumerate() {
            if let ObjectModelKind::Path(p) = &o.kind {
                sim.paths.insert(i as Handle, PathObject::from_model(p));
            }
        }
        sim
    }

    /// A stopped simulation of an already built world.
    pub fn from_world(world: World) -> Self {
        Self {
            world,
            state: SimulationState::Stopped,
            advancing: Advancing::default(),
            signals: Signals::default(),
            tubes: Tubes::default(),
            messages: SimulatorMessages::default(),
            drawings: Drawings::default(),
            graphs: Graphs::default(),
            uis: Uis::default(),
            views: FloatingViews::default(),
            ik: IkEnvironments::default(),
            ik_groups: SceneIkGroups::default(),
            vision: VisionStates::default(),
            ruckig: RuckigObjects::default(),
            planning: Planning::default(),
            paths: Paths::default(),
            particles: Particles::default(),
            particle_drawings: BTreeMap::new(),
        }
    }

    /// `sim.getSimulationState()`: 0 stopped, 8 paused, or the advancing pass (16-21).
    pub fn simulation_state_code(&self) -> i64 {
        match self.state {
            SimulationState::Running => self.advancing.code(),
            other => other.code(),
        }
    }

    /// One simulation step without scripts: [`Sim::step_dynamics`], then vision sensors
    /// not handled explicitly render lazily when read, then [`Sim::finish_step`].
    pub fn step(&mut self) {
        self.step_dynamics();
        self.finish_step();
    }

    /// The part of a step between actuation and sensing, in CoppeliaSim's order: the
    /// scene's IK groups not handled explicitly are solved (the 4.1 main script's
    /// `sim.handleIkGroup(sim.handle_all_except_explicit)`, after the scripts' actuation),
    /// joints, physics and particles advance one step, then every proximity sensor is
    /// handled. Simulation time does not move yet: scripts see the step's start time
    /// until [`Sim::finish_step`].
    pub fn step_dynamics(&mut self) {
        self.ik_groups.handle_automatic(&mut self.world);
        self.particles.before_step(&mut self.world);
        self.world.step_physics();
        let end = self.world.time() + self.world.settings().dt;
        self.particles.after_step(&mut self.world, end);
        self.draw_particles();
        crate::sensor::handle_all_proximity_sensors(&mut self.world);
    }

    /// Shows the particles in the viewer: each visible particle object has a drawing
    /// object (sphere points of the particles' diameter, or 1, 2 or 4-pixel points for
    /// the point types, in the object's colour) holding its particles' current
    /// positions. Per-item sizes and colours are not drawn. A drawing object a script
    /// removed is made again; one whose particle object is gone is removed.
    pub fn draw_particles(&mut self) {
        let gone: Vec<Handle> = self
            .particle_drawings
            .keys()
            .copied()
            .filter(|&p| self.particles.object(p).is_err())
            .collect();
        for p in gone {
            if let Some(pd) = self.particle_drawings.remove(&p)
                && self.drawings.get(pd.handle).is_some_and(|d| pd.is(d))
                && !self.particle_drawings.values().any(|other| other.handle == pd.handle)
            {
                let _ = self.drawings.remove(pd.handle);
            }
        }
        // Drawing handles given to a particle object in this pass: after a restart of
        // the drawing handles, a stale entry of a later object may name one of them.
        let mut claimed: Vec<Handle> = Vec::new();
        for (p, o) in self.particles.iter() {
            if o.has(PARTICLE_INVISIBLE) {
                continue;
            }
            let (object_type, size) = match o.kind() {
                PARTICLE_POINTS1 => (0, 1.0),
                PARTICLE_POINTS2 => (0, 2.0),
                PARTICLE_POINTS4 => (0, 4.0),
                _ => (7, o.size()),
            };
            let existing = self.particle_drawings.get(&p).copied();
            let d = match existing
                .filter(|pd| !claimed.contains(&pd.handle) && self.drawings.get(pd.handle).is_some_and(|d| pd.is(d)))
            {
                Some(pd) => pd.handle,
                None => {
                    let params = DrawingParams {
                        object_type,
                        size,
                        duplicate_tolerance: 0.0,
                        parent: None,
                        max_items: o.max_items().min(MAX_DRAWING_ITEMS),
                        color: o.color(),
                        emission: None,
                    };
                    // At the drawing objects' cap the particles are simply not drawn.
                    let Ok(d) = self.drawings.create(params) else {
                        continue;
                    };
                    d
                }
            };
            claimed.push(d);
            let Ok(positions) = self.particles.positions(&self.world, p) else {
                continue;
            };
            if let Ok(drawing) = self.drawings.object_mut(d) {
                drawing.clear();
                let frame = crate::math::Pose::identity();
                for v in positions {
                    // Positions come from rapier and are finite.
                    let _ = drawing.add_item(&[v.x, v.y, v.z], &frame);
                }
                self.particle_drawings.insert(
                    p,
                    ParticleDrawing {
                        handle: d,
                        object_type: drawing.object_type(),
                        size: drawing.size(),
                        color: drawing.color(),
                        written: drawing.item_count(),
                    },
                );
            }
        }
    }

    /// Ends a step: simulation time moves on, and the first pass after a start or a
    /// pause becomes an ordinary one.
    pub fn finish_step(&mut self) {
        self.world.advance_time();
        if matches!(self.advancing, Advancing::FirstAfterStop | Advancing::FirstAfterPause) {
            self.advancing = Advancing::Running;
        }
    }

    /// Sets the simulation time step, s. As in CoppeliaSim, only while stopped.
    ///
    /// # Errors
    /// The simulation is not stopped, or `dt` is not a positive number.
    pub fn set_time_step(&mut self, dt: f64) -> Result<(), SimError> {
        if self.state != SimulationState::Stopped {
            return Err(SimError::Refused(
                "the time step can only be changed while the simulation is stopped".into(),
            ));
        }
        self.world.set_time_step(dt)
    }

    /// Removes objects (`sim.removeObjects`) and what the floors above attached to them:
    /// drawing objects parented to them, floating views showing them.
    ///
    /// # Errors
    /// As [`World::remove_objects`]; nothing is removed then.
    pub fn remove_objects(&mut self, handles: &[Handle]) -> Result<(), SimError> {
        self.world.remove_objects(handles)?;
        self.forget_removed();
        Ok(())
    }

    /// Drops what the floors above the world kept about removed objects.
    pub fn forget_removed(&mut self) {
        let world = &self.world;
        let orphans: Vec<Handle> = self
            .drawings
            .iter()
            .filter(|(_, d)| d.parent().is_some_and(|p| world.is_removed(p)))
            .map(|(h, _)| h)
            .collect();
        for d in orphans {
            // Listed just above, so it exists.
            let _ = self.drawings.remove(d);
        }
        self.paths.retain(|h| !world.is_removed(h));
        for h in 0..world.len() as Handle {
            if world.is_removed(h) {
                self.views.forget_object(h);
            }
        }
    }
}

/// A drawing object showing a particle object, as last drawn.
#[derive(Debug, Clone, Copy)]
struct ParticleDrawing {
    handle: Handle,
    object_type: i64,
    size: f64,
    color: [f64; 3],
    /// Items it was given.
    written: usize,
}

impl ParticleDrawing {
    /// Whether `d`, found at this handle, is still this drawing.
    /// `sim.removeDrawingObject(sim.handle_all)` restarts the drawing handles, so a
    /// script's new drawing object may have taken the handle: it is left alone unless it
    /// is exactly what was drawn here last.
    fn is(&self, d: &DrawingObject) -> bool {
        d.object_type() == self.object_type
            && d.size() == self.size
            && d.color() == self.color
            && d.parent().is_none()
            && d.item_count() == self.written
    }
}

/// Starting, pausing and stopping, whoever asks (a script, a remote client, the
/// viewer's buttons, the command line).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Control {
    /// `sim.startSimulation()`: start, or resume from pause.
    Start,
    /// `sim.pauseSimulation()`.
    Pause,
    /// `sim.stopSimulation()`: cleanup hooks run and the scene returns to its initial state.
    Stop,
}

/// CoppeliaSim's simulation states (`sim.getSimulationState`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimulationState {
    /// Not running; the scene is in its initial state.
    Stopped,
    /// Running (advancing).
    Running,
    /// Paused.
    Paused,
}

/// Which pass of an advancing simulation this is, as `sim.getSimulationState` reports
/// it (CoppeliaSim 4.x): scripts that loop until "about to stop", or that act once
/// on the first pass after a start or a pause, depend on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Advancing {
    /// The first step after a start (`simulation_advancing_firstafterstop`, 16).
    FirstAfterStop,
    /// Any other step (`simulation_advancing_running`, 17).
    #[default]
    Running,
    /// A pause was asked for and happens at the end of this step (19).
    LastBeforePause,
    /// The first step after a pause (`simulation_advancing_firstafterpause`, 20).
    FirstAfterPause,
    /// A stop was asked for: the rest of this step and the cleanup hooks (21).
    AboutToStop,
}

impl Advancing {
    /// CoppeliaSim's number.
    pub fn code(self) -> i64 {
        match self {
            Advancing::FirstAfterStop => 16,
            Advancing::Running => 17,
            Advancing::LastBeforePause => 19,
            Advancing::FirstAfterPause => 20,
            Advancing::AboutToStop => 21,
        }
    }
}

impl SimulationState {
    /// CoppeliaSim's number: 0 stopped, 8 paused, 17 advancing/running.
    pub fn code(self) -> i64 {
        match self {
            SimulationState::Stopped => 0,
            SimulationState::Paused => 8,
            SimulationState::Running => 17,
        }
    }
}
