//! The scene a remote or in-process client asks for with `sim.loadScene(path)` or
//! `sim.closeScene()`: a gantry scene, a robot, or a CoppeliaSim scene or model.

use std::path::Path;

use super::{DiskFiles, LoadError, LoadOptions, SceneModel, load_scene, load_scene_text};

/// Loads the scene a client named (`Some(path)`), or an empty scene (`None`, what
/// `sim.closeScene()` leaves). The error's text is the message a client sees, without
/// the `(in function ...)` suffix, which the caller adds.
///
/// # Errors
/// CoppeliaSim 4.8+'s XML files (`.simscene`, `.simmodel`) are refused by name
/// ([`LoadError::CoppeliaXml`]); otherwise the file's load error.
pub fn load_client_scene(path: Option<&Path>, opts: &LoadOptions) -> Result<SceneModel, LoadError> {
    match path {
        Some(path) => {
            let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
            if matches!(ext.as_deref(), Some("simscene" | "simmodel")) {
                return Err(LoadError::CoppeliaXml(path.to_owned()));
            }
            load_scene(&DiskFiles, path, opts)
        }
        None => {
            // An empty scene still needs a folder for relative paths: the working one.
            let here = std::env::current_dir().unwrap_or_default().join("empty.toml");
            load_scene_text(&DiskFiles, "", &here, opts)
        }
    }
}
