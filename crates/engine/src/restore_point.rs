//! What a stop restores: the scene as it was when the simulation started.
//!
//! CoppeliaSim edits a scene while its simulation is stopped and, when a run stops,
//! puts back what the run moved. So the engine copies the simulation's scene at each
//! start (the world with its physics, the IK groups, the path curves, which vision
//! sensors are handled explicitly) and a stop puts that copy back. Objects created,
//! moved or removed while stopped (by the editor, a script's `sysCall_nonSimulation`,
//! a remote client) are kept through the run, with the same handles.
//!
//! A run that loaded models (`sim.loadModel` from a script, which CoppeliaSim keeps
//! after the stop) is instead rebuilt from the scene model, which those models joined,
//! as before this copy existed: the copy does not hold them.

use gantry_sim_core::scene::SceneModel;
use gantry_sim_core::world::ObjectKind;
use gantry_sim_core::{Handle, Sim, World, vision};

use crate::scene::{build_sim, export_scope};

/// The scene of a start.
pub(crate) struct RestorePoint {
    world: World,
    ik_groups: gantry_sim_core::ik_groups::SceneIkGroups,
    paths: gantry_sim_core::paths::Paths,
    /// Vision sensors handled explicitly.
    explicit: Vec<Handle>,
    /// How many objects the scene model had at the start: more at the stop means models
    /// were loaded during the run.
    model_objects: usize,
}

impl RestorePoint {
    /// A copy of `sim`'s scene, `model` being the engine's scene model now.
    pub(crate) fn capture(sim: &Sim, model: &SceneModel) -> Self {
        let explicit = sim
            .world
            .handles()
            .iter()
            .copied()
            .filter(|&h| {
                matches!(sim.world.object(h).map(|o| &o.kind), Ok(ObjectKind::VisionSensor(_)))
                    && vision::is_explicit(&sim.vision, h)
            })
            .collect();
        Self {
            world: sim.world.clone(),
            ik_groups: sim.ik_groups.clone(),
            paths: sim.paths.clone(),
            explicit,
            model_objects: model.objects.len(),
        }
    }

    /// The stopped simulation a stop leaves: this copy, or `model` rebuilt when models
    /// joined it during the run (see the module docs).
    pub(crate) fn restore(self, model: &SceneModel) -> Sim {
        if model.objects.len() != self.model_objects {
            return build_sim(model);
        }
        let mut sim = Sim::from_world(self.world);
        sim.ik_groups = self.ik_groups;
        sim.paths = self.paths;
        sim.graphs.set_export_scope(export_scope(model));
        for h in self.explicit {
            // The sensor is in the copied world, so this cannot fail.
            let _ = vision::set_explicit(&sim.world, &mut sim.vision, h, true);
        }
        sim
    }
}
