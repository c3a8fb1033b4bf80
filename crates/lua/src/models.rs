//! `sim.loadModel`: a model file's objects join the world at once (the handle of its
//! base is returned); its scripts load once the calling hook has returned, and the model
//! joins the scene model so that a stop rebuilds it. Scripts read model files inside
//! the scene's folder only, as they write exports there; a remote client may load any
//! file gantry can read, as `sim.loadScene`.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use gantry_sim_core::scene::{DiskFiles, LoadError, LoadOptions, SceneModel, load_model};
use gantry_sim_core::{Handle, SimError};
use mlua::{Function, Lua, Table, Value as LuaValue};

use crate::app_state::state;
use crate::sim_cell::SimCell;

/// How model files are read, and the models loaded whose scripts wait to load.
#[derive(Default)]
pub(crate) struct Models {
    /// How model files are read: package paths, free bases.
    pub(crate) options: RefCell<LoadOptions>,
    /// Models whose objects are in the world and whose scripts load once no script
    /// is running.
    loaded: RefCell<Vec<LoadedModel>>,
}

/// A model `sim.loadModel` put into the world, waiting for its scripts to load.
pub struct LoadedModel {
    /// The model file as loaded.
    pub model: SceneModel,
    /// The world handle of each of its objects.
    pub handles: Vec<Handle>,
}

impl Models {
    /// The models waiting, now to be attached.
    pub(crate) fn take_loaded(&self) -> Vec<LoadedModel> {
        std::mem::take(&mut *self.loaded.borrow_mut())
    }

    /// Reads the model file `path` and adds its objects to `core`'s world; returns the
    /// model base's handle. `confined`: only inside the scene's folder (for scripts).
    pub(crate) fn load(&self, core: &SimCell, path: &Path, confined: bool) -> Result<Handle, ModelLoadError> {
        let path = if confined {
            core.borrow().graphs.export_scope().resolve(path).map_err(|e| match e {
                gantry_sim_core::graph::ExportDenied::NoFolder => ModelLoadError::NoFolder,
                _ => ModelLoadError::OutsideFolder(path.to_owned()),
            })?
        } else {
            path.to_owned()
        };
        let options = self.options.borrow().clone();
        let model = load_model(&DiskFiles, &path, &options)?;
        let (handles, warnings) = {
            let mut sim = core.try_borrow_mut().map_err(|_| ModelLoadError::WorldBusy)?;
            let (handles, warnings) = sim.world.import_model(&model);
            // The model's IK groups (a PyRep arm's `<Name>_ik`), on its new objects.
            sim.ik_groups.add(&model.ik_groups, |i| handles.get(i).copied());
            (handles, warnings)
        };
        // The model's own warnings (unknown keys, URDF features) and the building's.
        for w in warnings {
            tracing::warn!("{w}");
        }
        let base = *handles.first().ok_or(ModelLoadError::Empty(path))?;
        self.loaded.borrow_mut().push(LoadedModel { model, handles });
        Ok(base)
    }
}

/// Why `sim.loadModel` (or a remote client's loadModel) loaded nothing.
#[derive(Debug, thiserror::Error)]
pub enum ModelLoadError {
    /// The scene is embedded in gantry, so there is no folder to load from.
    #[error("this scene has no folder on disk (it is embedded in gantry), so its scripts cannot load model files")]
    NoFolder,
    /// A script named a file outside the scene's folder.
    #[error(
        "{}: scripts load model files only from inside the scene's folder (give a path relative to the scene)",
        .0.display()
    )]
    OutsideFolder(PathBuf),
    /// The file is not a model, or does not load.
    #[error(transparent)]
    Load(#[from] LoadError),
    /// The world is borrowed (a re-entrant call).
    #[error("the world is busy")]
    WorldBusy,
    /// The model file has no objects.
    #[error("{}: the model has no objects", .0.display())]
    Empty(PathBuf),
    /// `sim.loadModel`'s argument is not a string (the Lua type found).
    #[error("argument 1: expected the model file's path as a string, got {0}")]
    NotAPath(&'static str),
}

/// A model that did not load, as a remote client's `sim.loadModel` reports it: the
/// argument and the file's content are the caller's to fix, the rest is refused.
impl From<ModelLoadError> for SimError {
    fn from(e: ModelLoadError) -> Self {
        match e {
            ModelLoadError::NotAPath(_) | ModelLoadError::Load(_) | ModelLoadError::Empty(_) => {
                SimError::bad_argument(e.to_string())
            }
            ModelLoadError::NoFolder | ModelLoadError::OutsideFolder(_) | ModelLoadError::WorldBusy => {
                SimError::refused(e.to_string())
            }
        }
    }
}

/// Installs `sim.loadModel` into `sim`, its failures raised through `wrap` (see
/// [`crate::host_api`]).
pub(crate) fn install(lua: &Lua, sim: &Table, wrap: &Function) -> mlua::Result<()> {
    sim.set(
        "loadModel",
        lua.create_function(move |lua, path: LuaValue| {
            let loaded = match &path {
                LuaValue::String(p) => {
                    state::<Models>(lua).load(&state::<SimCell>(lua), Path::new(&*p.to_str()?), true)
                }
                other => Err(ModelLoadError::NotAPath(other.type_name())),
            };
            Ok(match loaded {
                Ok(h) => (true, LuaValue::Integer(h)),
                Err(e) => (
                    false,
                    LuaValue::String(lua.create_string(format!("{e} (in function 'sim.loadModel')"))?),
                ),
            })
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )
}
