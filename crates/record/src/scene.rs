//! A recording's scene, rebuilt from what the recording holds: the files the loader
//! read at the start (attached at the paths it read them) and the `gantry` metadata
//! record (scene path, package paths, `free_base`, time step, substeps, seed, whether
//! scripts ran). `gantry replay` shows it and `gantry verify` simulates it again.
//!
//! Here rather than in gantry-mcap, which reads the recording as data: rebuilding runs
//! the scene loader, and the format crate stays a pure codec.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use gantry_mcap::{AttachedFile, Recording};
use gantry_sim_core::scene::{
    Files, LoadError, LoadOptions, MapFiles, SceneModel, load_bundled, load_client_scene, load_scene,
};

/// Why a recording's scene cannot be rebuilt. The texts are for the user.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The recording does not hold the files its scene needs.
    #[error("{path}: the scene cannot be rebuilt from the recording: {reason}")]
    Missing {
        /// The recording.
        path: PathBuf,
        /// What is missing.
        reason: String,
    },
    /// The recorded scene files do not load.
    #[error("{path}: the recorded scene {scene} does not load")]
    Load {
        /// The recording.
        path: PathBuf,
        /// The scene's path in the recording.
        scene: String,
        /// The loader's error (boxed: it is large, and this is not a hot path).
        #[source]
        source: Box<LoadError>,
    },
}

/// The scene of a [`Recording`] read back.
pub trait RecordedScene {
    /// The recorded scene, loaded from the attachments as the run loaded it, with the
    /// recorded time step and substeps (see [`scene_from_files`]).
    ///
    /// # Errors
    /// The scene file is not attached, or does not load.
    fn scene_model(&self) -> Result<SceneModel, SceneError>;
}

impl RecordedScene for Recording {
    fn scene_model(&self) -> Result<SceneModel, SceneError> {
        scene_from_files(self.path(), self.metadata(), self.attachments())
    }
}

/// The scene of a recording from its `gantry` metadata record and its attachments:
/// every file the loader read, at the path it read it (`scene_path` names the scene;
/// an empty one is the empty scene of `gantry.Client()`), with the recorded package
/// paths, `free_base`, time step and substeps, and without its scripts when the run had
/// none (`scripts = false`). Older recordings name no `scene_path`: the bundled
/// showroom, or the first attachment with the scripts named relative to it. `path`
/// names the recording in errors.
///
/// # Errors
/// The scene file is not attached, or does not load.
pub fn scene_from_files(
    path: &Path,
    meta: &BTreeMap<String, String>,
    attachments: &[AttachedFile],
) -> Result<SceneModel, SceneError> {
    let opts = LoadOptions {
        package_paths: meta
            .get("package_paths")
            .map(|p| p.lines().filter(|l| !l.is_empty()).map(PathBuf::from).collect())
            .unwrap_or_default(),
        free_base: meta.get("free_base").is_some_and(|v| v == "true"),
    };
    let scene_error = |scene: String, source: LoadError| SceneError::Load {
        path: path.to_path_buf(),
        scene,
        source: Box::new(source),
    };
    let (files, scene) = match meta.get("scene_path") {
        Some(scene) if scene.is_empty() => {
            let model = load_client_scene(None, &opts).map_err(|e| scene_error("(empty scene)".into(), e))?;
            return Ok(with_settings(meta, model));
        }
        Some(scene) => (
            MapFiles::new(attachments.iter().map(|a| (PathBuf::from(&a.name), a.data.clone()))),
            PathBuf::from(scene),
        ),
        None if meta.get("scene_file").is_some_and(|f| f == "(bundled showroom)") => {
            let model = load_bundled("showroom", &opts)
                .ok_or_else(|| SceneError::Missing {
                    path: path.to_path_buf(),
                    reason: "it was recorded on the bundled showroom, which this gantry does not have".into(),
                })?
                .map_err(|e| scene_error("showroom".into(), e))?;
            return Ok(with_settings(meta, model));
        }
        None => {
            // Older recordings: the scene file first, then its scripts named
            // relative to it; put them under one made-up folder.
            let root = Path::new("/recording");
            let first = attachments.first().ok_or_else(|| SceneError::Missing {
                path: path.to_path_buf(),
                reason: "it has no attachments (the scene file is missing)".into(),
            })?;
            (
                MapFiles::new(attachments.iter().map(|a| (root.join(&a.name), a.data.clone()))),
                root.join(&first.name),
            )
        }
    };
    if !files.is_file(&scene) {
        return Err(SceneError::Missing {
            path: path.to_path_buf(),
            reason: format!("the scene file {} is not attached", scene.display()),
        });
    }
    let model = load_scene(&files, &scene, &opts).map_err(|e| scene_error(scene.display().to_string(), e))?;
    Ok(with_settings(meta, model))
}

/// `model` with the recorded time step, substeps and seed (command-line overrides of
/// the run included), and without scripts when the run had none.
fn with_settings(meta: &BTreeMap<String, String>, mut model: SceneModel) -> SceneModel {
    if let Some(dt) = meta
        .get("dt")
        .and_then(|v| v.parse::<f64>().ok())
        .filter(|d| d.is_finite() && *d > 0.0)
    {
        model.settings.dt = dt;
    }
    if let Some(n) = meta
        .get("substeps")
        .and_then(|v| v.parse::<u32>().ok())
        .filter(|n| *n > 0)
    {
        model.settings.substeps = n;
    }
    if let Some(seed) = meta.get("seed").and_then(|v| v.parse::<i64>().ok()) {
        model.settings.seed = seed;
    }
    if meta.get("scripts").is_some_and(|v| v == "false") {
        model.scripts.clear();
    }
    model
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `gantry` metadata record of the bundled showroom, with `extra` entries.
    fn metadata(extra: &[(&str, &str)]) -> BTreeMap<String, String> {
        [("scene_file", "(bundled showroom)"), ("dt", "0.05"), ("substeps", "4")]
            .iter()
            .chain(extra)
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect()
    }

    #[test]
    fn the_scene_is_rebuilt_from_the_attachments() {
        let scene_of = |metadata: BTreeMap<String, String>, attachments: Vec<AttachedFile>| {
            scene_from_files(Path::new("test.mcap"), &metadata, &attachments)
        };
        // The bundled showroom of an older recording.
        let model = scene_of(metadata(&[("dt", "0.02")]), Vec::new()).expect("loads");
        assert_eq!(model.settings.dt, 0.02);
        assert!(model.objects.len() > 20);
        // A scene named by the path it was read at, with its files.
        let scene = "[[object]]\nname = \"crate\"\nkind = \"shape\"\nshape = \"box\"\nsize = [1, 1, 1]\n";
        let files = vec![AttachedFile {
            name: "/home/u/sim/s.toml".into(),
            media_type: "application/toml".into(),
            data: scene.as_bytes().to_vec(),
        }];
        let model = scene_of(metadata(&[("scene_path", "/home/u/sim/s.toml")]), files.clone()).expect("loads");
        assert!(
            model.objects.iter().any(|o| o.alias == "crate"),
            "{:?}",
            model.objects.len()
        );
        // A scene file that is not attached.
        let e = scene_of(metadata(&[("scene_path", "/elsewhere.toml")]), files).expect_err("missing");
        assert!(matches!(e, SceneError::Missing { .. }), "{e}");
        assert!(e.to_string().contains("is not attached"), "{e}");
    }
}
