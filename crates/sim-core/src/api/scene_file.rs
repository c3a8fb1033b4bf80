//! `sim.saveScene`, `sim.saveModel`: the running scene (or one model of it) written as
//! gantry's TOML scene, with its meshes as OBJ files and its scripts as Lua files beside
//! it, by `gantry convert`'s writer. What is saved is the scene as it is now: poses,
//! joint positions, object settings (see `world::export` for what is left out, which the
//! file's header lists too).
//!
//! gantry never writes CoppeliaSim's binary formats: a `.ttt` or `.ttm` path is refused
//! with that reason (so a CoppeliaSim file is never overwritten). Paths are confined
//! like every file the API writes (the scene's folder under `gantry run`). Each file is
//! written to a temporary name, then renamed over the target, so a failure never leaves
//! a half-written scene file.

use std::path::{Path, PathBuf};

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::error::SimError;
use crate::scene::write_scene;
use crate::sim::Sim;
use crate::world::Handle;

/// The scene file functions, sorted by name.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "saveModel",
        call: ApiFn::Sim(save_model),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "saveScene",
        call: ApiFn::Sim(save_scene),
        cost: Cost::Long,
    },
];

/// `sim.saveScene(filename)`: the whole scene as `<name>.toml` (and `meshes/`,
/// `scripts/` beside it).
fn save_scene(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let filename = a.str(0)?;
    save(sim, None, filename, 1)?;
    Ok(Vec::new())
}

/// `sim.saveModel(modelBaseHandle, filename)`: the model (an object flagged as model
/// base, and everything below it) as a TOML scene that `sim.loadModel` reads back; its
/// base keeps its pose in the world.
fn save_model(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let filename = a.str(1)?;
    if !sim.world.object(h)?.model_base {
        return Err(SimError::bad_argument(format!(
            "argument 1: object {h} is not a model base (flag it with sim.setModelProperty or save the scene)"
        )));
    }
    save(sim, Some(h), filename, 2)?;
    Ok(Vec::new())
}

/// Exports the scene or the model at `root`, and writes it as `filename` (argument
/// `arg`, for messages).
fn save(sim: &Sim, root: Option<Handle>, filename: &str, arg: usize) -> Result<(), SimError> {
    let path = Path::new(filename);
    let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("toml") => {}
        Some("ttt" | "ttm" | "simscene" | "simmodel") => {
            return Err(SimError::bad_argument(format!(
                "argument {arg}: gantry saves scenes as its own TOML files, never in CoppeliaSim's formats; name the file '.toml', not '{filename}'"
            )));
        }
        _ => {
            return Err(SimError::bad_argument(format!(
                "argument {arg}: name the file '.toml' (gantry's scene format), not '{filename}'"
            )));
        }
    }
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .ok_or_else(|| SimError::bad_argument(format!("argument {arg}: '{filename}' names no file")))?;
    let dir = sim
        .graphs
        .export_scope()
        .resolve(path.parent().unwrap_or(Path::new("")))
        .map_err(|e| SimError::refused(format!("cannot write '{filename}': {e}")))?;
    let exported = sim.world.export_scene(root)?;
    let source = match root {
        Some(h) => format!("the running scene (model {})", sim.world.object(h)?.alias),
        None => "the running scene".to_owned(),
    };
    let mut written = write_scene(&exported.model, stem, &source)
        .map_err(|e| SimError::refused(format!("cannot save '{filename}': {e}")))?;
    // The writer names what the format cannot hold in the file's header; the export's
    // own notes go there too.
    if !exported.notes.is_empty()
        && let Some((_, toml)) = written.files.first_mut()
    {
        let header: String = exported.notes.iter().map(|n| format!("# gantry save: {n}\n")).collect();
        toml.splice(0..0, header.into_bytes());
    }
    for (rel, bytes) in &written.files {
        write_atomically(&dir.join(rel), bytes)?;
    }
    Ok(())
}

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`.
fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), SimError> {
    let fail =
        |what: &str, p: &Path, e: std::io::Error| SimError::refused(format!("cannot {what} '{}': {e}", p.display()));
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(|e| fail("create", parent, e))?;
    }
    let mut tmp: PathBuf = path.to_owned();
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    tmp.set_file_name(format!(".{name}.gantry-tmp"));
    std::fs::write(&tmp, bytes).map_err(|e| fail("write", &tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        fail("write", path, e)
    })
}
