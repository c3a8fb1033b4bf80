//! Where the files the tests read are, whichever crate's test asks.

use std::path::{Path, PathBuf};

/// A file of the repository, given relative to its root (`assets/scenes/fk_arm.toml`).
///
/// Every crate sits two levels below the root (`crates/<name>`), this one included, so
/// the path is the same from any crate's tests.
pub fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
}

/// The folder of shared CoppeliaSim scenes and models (`.ttt`/`.ttm`, with their
/// `SOURCES.md`): `GANTRY_COPPELIA_FILES` when set, else `shared/coppelia-files` beside
/// the repository. The folder may be absent; tests that need it check and skip.
pub fn coppelia_files() -> PathBuf {
    match std::env::var_os("GANTRY_COPPELIA_FILES") {
        Some(dir) => PathBuf::from(dir),
        None => repo("../shared/coppelia-files"),
    }
}

/// The assets of PyRep's own test suite (`test_scene.ttt`, `loadable_model.ttm`, meshes,
/// a texture): `GANTRY_PYREP_ASSETS` when set, else `shared/pyrep/tests/assets` beside
/// the repository. Tests that need them fail when they are absent: the suite's
/// acceptance material is part of the test command's inputs.
pub fn pyrep_assets() -> PathBuf {
    let dir = match std::env::var_os("GANTRY_PYREP_ASSETS") {
        Some(dir) => PathBuf::from(dir),
        None => repo("../shared/pyrep/tests/assets"),
    };
    assert!(
        dir.join("test_scene.ttt").is_file(),
        "PyRep's test assets are not at {} (set GANTRY_PYREP_ASSETS)",
        dir.display()
    );
    dir
}

#[cfg(test)]
mod tests {
    use super::repo;

    #[test]
    fn repo_paths_reach_the_workspace_root() {
        assert!(repo("Cargo.toml").is_file());
        assert!(repo("assets/scenes/bubble_rob.toml").is_file());
    }
}
