//! The scene a remote or in-process client asks for with `sim.loadScene(path)` or
//! `sim.closeScene()`: a gantry scene or robot file, never a CoppeliaSim one.

use std::path::Path;

use super::{DiskFiles, LoadOptions, SceneModel, load_scene, load_scene_text};

/// Loads the scene a client named (`Some(path)`), or an empty scene (`None`, what
/// `sim.closeScene()` leaves). The error is the message a client sees, without the
/// `(in function ...)` suffix, which the caller adds.
///
/// # Errors
/// A CoppeliaSim file (`.ttt`, `.ttm`, ...) is refused by name; any load error of the
/// file is returned as text.
pub fn load_client_scene(path: Option<&Path>, opts: &LoadOptions) -> Result<SceneModel, String> {
    match path {
        Some(path) => {
            let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
            if matches!(ext.as_deref(), Some("ttt" | "ttm" | "simscene" | "simmodel")) {
                return Err(format!(
                    "'{}' is a CoppeliaSim file, which gantry cannot read: load a gantry scene (.toml, see docs/scene-format.md) or a robot (.urdf)",
                    path.display()
                ));
            }
            load_scene(&DiskFiles, path, opts).map_err(|e| e.to_string())
        }
        None => {
            // An empty scene still needs a folder for relative paths: the working one.
            let here = std::env::current_dir().unwrap_or_default().join("empty.toml");
            load_scene_text(&DiskFiles, "", &here, opts).map_err(|e| e.to_string())
        }
    }
}
