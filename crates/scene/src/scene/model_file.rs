//! The files `sim.loadModel` reads: a robot (`.urdf`), a CoppeliaSim model (`.ttm`) or a
//! gantry model, a scene file
//! with objects, robots and scripts only (a model joins a scene that already has its
//! floor, time step and listeners).

use std::path::Path;

use super::coppelia::load_coppelia;
use super::load::load_urdf_model;
use super::{Files, LoadError, LoadOptions, SceneModel, load_scene_text};

/// Sections a model file may not have, because they belong to a whole scene.
const SCENE_ONLY: &[&str] = &["simulation", "floor", "server"];

/// Loads the model file `path`. Its objects come in hierarchy order, its first root is
/// the model base.
///
/// # Errors
/// Another extension, a CoppeliaSim scene (not a model) named `.ttm`, an unreadable or invalid file,
/// or a `.toml` with a `[simulation]`, `[floor]` or `[server]` section.
pub fn load_model(files: &dyn Files, path: &Path, opts: &LoadOptions) -> Result<SceneModel, LoadError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let invalid = |message: String| LoadError::Invalid {
        path: path.to_owned(),
        line: 1,
        column: 1,
        message,
    };
    match ext.as_deref() {
        Some("urdf") => load_urdf_model(files, path, opts),
        Some("toml") => {
            let bytes = files.read(path).map_err(|e| LoadError::Io {
                path: path.to_owned(),
                source: e,
                hint: String::new(),
            })?;
            let text = String::from_utf8(bytes).map_err(|_| invalid("the model file is not UTF-8 text".into()))?;
            // Checked on the parsed table, so that a comment or a string naming a section
            // does not count; syntax errors are left to the loader, which places them.
            if let Ok(table) = text.parse::<toml::Table>()
                && let Some(section) = SCENE_ONLY.iter().find(|s| table.contains_key(**s))
            {
                return Err(invalid(format!(
                    "a model has no [{section}] section: it joins a scene that has its own; keep [[object]], [[robot]] and [[script]]"
                )));
            }
            let model = load_scene_text(files, &text, path, opts)?;
            if model.objects.is_empty() {
                return Err(invalid("the model has no objects".into()));
            }
            Ok(model)
        }
        Some("ttm") => {
            let bytes = files.read(path).map_err(|e| LoadError::Io {
                path: path.to_owned(),
                source: e,
                hint: String::new(),
            })?;
            let (model, report) = load_coppelia(&bytes, path)?;
            if !report.is_model {
                return Err(invalid(
                    "this is a CoppeliaSim scene saved with a .ttm name: load it with sim.loadScene".into(),
                ));
            }
            if model.objects.is_empty() {
                return Err(invalid("the model has no objects".into()));
            }
            Ok(model)
        }
        Some("simmodel") => Err(invalid(
            "a CoppeliaSim 4.8+ XML model, which gantry cannot read: save it as .ttm, or load a robot (.urdf) or a gantry model (.toml, docs/scene-format.md)".into(),
        )),
        _ => Err(invalid(
            "sim.loadModel reads a robot (.urdf), a gantry model (.toml) or a CoppeliaSim model (.ttm)".into(),
        )),
    }
}
