//! Scene loading in three stages (style guide G11):
//!
//! 1. [`raw`]: serde structs mirroring the TOML file; syntax and types only.
//! 2. [`model`]: the resolved scene ([`SceneModel`]): names are indices, angles radians,
//!    files read, defaults applied. No rapier types, so it is unit-testable.
//! 3. The world (`crate::world`) inserts the model into rapier.
//!
//! Bare URDFs and CoppeliaSim models (`.ttm`) load as a floor plus the robot; CoppeliaSim
//! scenes (`.ttt`) and models import through [`load_coppelia`] (module `coppelia`). `docs/scene-format.md` documents the file; [`write_scene`] writes a
//! model back as one (`gantry convert`).

mod bundled;
mod client_load;
mod coppelia;
mod error;
mod files;
mod floor;
mod load;
mod mesh;
pub mod model;
mod model_file;
mod obj_parts;
mod obj_write;
pub mod raw;
pub mod texture_file;
mod urdf;
mod urdf_fixups;
mod write;

pub use bundled::{BUNDLED_SCENES, bundled_files, load_bundled};
pub use client_load::load_client_scene;
pub use coppelia::old_scripts::{Rewrites as OldScriptRewrites, modernize as modernize_old_script};
pub use coppelia::{COPPELIA_SOLVER_ITERATIONS, ImportReport, load_coppelia, load_coppelia_file};
pub use error::LoadError;
pub use files::{DiskFiles, EmbeddedFiles, Files, LoggedFiles, MapFiles, normalize as normalize_path};
pub use load::dedup as dedup_warnings;
pub use load::{DEFAULT_VELOCITY_KD, LoadOptions, load_scene, load_scene_text};
pub use mesh::{load_mesh, resolve_mesh_path};
pub use model::*;
pub use model_file::load_model;
pub use obj_parts::obj_parts;
pub use obj_write::write_obj;
pub use urdf::{DEFAULT_KD, DEFAULT_KP, UrdfInclude, UrdfIndex, import_urdf};
pub use write::{SceneFiles, WriteError, write_scene};
