//! A copy of a simulation's scene, to put back later: what a stop restores (the scene
//! as the run started) and what the editor's undo and redo swap in.
//!
//! CoppeliaSim edits a scene while its simulation is stopped and, when a run stops,
//! puts back what the run moved. So the engine copies the scene at each start (the
//! world with its physics, the IK groups, the path curves, which vision sensors are
//! handled explicitly) and a stop puts that copy back: objects created, moved or
//! removed while stopped (by the editor, a script's `sysCall_nonSimulation`, a remote
//! client) are kept through the run, with the same handles.
//!
//! A run that loaded models (`sim.loadModel` from a script, which CoppeliaSim keeps
//! after the stop) is instead rebuilt from the scene model, which those models joined:
//! the copy does not hold them.

use gantry_sim_core::scene::SceneModel;
use gantry_sim_core::world::ObjectKind;
use gantry_sim_core::{Handle, Sim, World, vision};

use crate::scene::{build_sim, export_scope};

/// A scene, copied.
pub(crate) struct SceneCopy {
    world: World,
    ik_groups: gantry_sim_core::ik_groups::SceneIkGroups,
    paths: gantry_sim_core::paths::Paths,
    /// Vision sensors handled explicitly.
    explicit: Vec<Handle>,
}

impl SceneCopy {
    /// A copy of `sim`'s scene.
    pub(crate) fn capture(sim: &Sim) -> Self {
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
        }
    }

    /// Puts the copied scene in `sim`'s place, keeping the rest of `sim` (signals,
    /// drawings, the log). Vision sensors render afresh.
    pub(crate) fn put_back(self, sim: &mut Sim) {
        let mut world = self.world;
        world.continue_revisions(&sim.world);
        world.log = std::mem::take(&mut sim.world.log);
        sim.world = world;
        sim.vision = Default::default();
        Self::settle(sim, self.ik_groups, self.paths, self.explicit);
    }

    /// A new stopped simulation of the copied scene.
    fn into_sim(self) -> Sim {
        let mut sim = Sim::from_world(self.world);
        Self::settle(&mut sim, self.ik_groups, self.paths, self.explicit);
        sim
    }

    fn settle(
        sim: &mut Sim,
        ik_groups: gantry_sim_core::ik_groups::SceneIkGroups,
        paths: gantry_sim_core::paths::Paths,
        explicit: Vec<Handle>,
    ) {
        sim.ik_groups = ik_groups;
        sim.paths = paths;
        for h in explicit {
            // The sensor is in the copied world, so this cannot fail.
            let _ = vision::set_explicit(&sim.world, &mut sim.vision, h, true);
        }
    }
}

/// The scene of a start, and how many objects the scene model had then: more at the
/// stop means models were loaded during the run.
pub(crate) struct RestorePoint {
    copy: SceneCopy,
    model_objects: usize,
}

impl RestorePoint {
    /// A copy of `sim`'s scene, `model` being the engine's scene model now.
    pub(crate) fn capture(sim: &Sim, model: &SceneModel) -> Self {
        Self {
            copy: SceneCopy::capture(sim),
            model_objects: model.objects.len(),
        }
    }

    /// The stopped simulation a stop leaves in place of `running`: the copy, or `model`
    /// rebuilt when models joined it during the run (see the module docs).
    pub(crate) fn restore(self, model: &SceneModel, running: &Sim) -> Sim {
        let mut sim = if model.objects.len() == self.model_objects {
            self.copy.into_sim()
        } else {
            build_sim(model)
        };
        sim.world.continue_revisions(&running.world);
        sim.graphs.set_export_scope(export_scope(model));
        sim
    }
}
