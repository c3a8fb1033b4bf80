//! The simulation a scene model builds: what the engine makes at a load and rebuilds
//! at every stop.

use gantry_sim_core::Sim;
use gantry_sim_core::graph::ExportScope;
use gantry_sim_core::scene::{EmbeddedFiles, SceneModel};

/// The world of `model`, with the API's file exports (`sim.exportGraphStreams`)
/// confined to the scene's folder, or forbidden for a scene embedded in the binary,
/// which has no folder on disk. Remote clients call the same functions on the same
/// world, so they are confined too.
pub(crate) fn build_sim(model: &SceneModel) -> Sim {
    let mut sim = Sim::new(model);
    sim.graphs.set_export_scope(export_scope(model));
    sim
}

/// Where the API may write files for `model`'s simulation (see [`build_sim`]).
pub(crate) fn export_scope(model: &SceneModel) -> ExportScope {
    if model.base_dir.starts_with(EmbeddedFiles::ROOT) {
        ExportScope::Nowhere
    } else {
        ExportScope::Within(model.base_dir.clone())
    }
}
