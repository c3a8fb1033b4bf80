//! Scenes from disk, for tests that only want the model.

use std::path::Path;

use gantry_scene::scene::{DiskFiles, LoadOptions, SceneModel, load_scene};

/// Loads the scene file at `path` (TOML, URDF or CoppeliaSim) with the default options.
///
/// # Panics
/// If the scene does not load: the message names the file and the loader's error.
/// Tests of load errors call `load_scene` themselves.
#[track_caller]
pub fn load(path: &Path) -> SceneModel {
    load_scene(&DiskFiles, path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{} loads: {e}", path.display()))
}
