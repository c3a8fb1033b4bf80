//! `sim.startRecording(path [, options])` and `sim.stopRecording()` from scripts: a
//! request kept here and carried out by the engine once the script's call returns
//! (the recorder belongs to the front end, above this crate). gantry's own functions,
//! not CoppeliaSim's: a script can record the part of a run it cares about.
//!
//! `options` is a table: `rate` (snapshots per simulated second; default every step)
//! and `images` (`{[sensorPath] = rateHz, ...}`, vision sensors whose images are
//! recorded). The folder of `path` must exist; other failures (a file that cannot be
//! created) are logged as errors when the engine starts the recording.

use std::cell::RefCell;
use std::path::{Path, PathBuf};

use mlua::{Function, Lua, Table, Value as LuaValue};

use crate::app_state::state;

/// What a script asked of the recorder.
#[derive(Debug, Clone, PartialEq)]
pub enum RecordingRequest {
    /// Start recording into `path` (a recording already running ends first).
    Start {
        /// The MCAP file.
        path: PathBuf,
        /// Snapshots per simulated second (`None`: every step).
        rate_hz: Option<f64>,
        /// Vision sensors (path or alias) whose images are recorded, with their rate.
        images: Vec<(String, f64)>,
    },
    /// End the recording (its file gets its summary).
    Stop,
}

/// The last request, carried out by the engine after the call that made it.
#[derive(Default)]
pub(crate) struct PendingRecording(RefCell<Option<RecordingRequest>>);

impl PendingRecording {
    /// The request, if any, now to be carried out.
    pub(crate) fn take(&self) -> Option<RecordingRequest> {
        self.0.borrow_mut().take()
    }
}

/// Why `sim.startRecording` refused its arguments (the script sees this text).
#[derive(Debug, thiserror::Error)]
enum StartError {
    /// The path is not a Lua string.
    #[error("the path must be a string, got {0}")]
    PathType(&'static str),
    /// The path is not UTF-8.
    #[error("the path is not UTF-8")]
    PathNotUtf8,
    /// The file's folder is missing.
    #[error("the folder {} does not exist", .0.display())]
    NoFolder(PathBuf),
    /// A rate that is not a positive number of Hz.
    #[error("{what} must be a positive number of Hz, got {value}")]
    Rate { what: String, value: f64 },
    /// `images` is not a table of sensor paths to rates.
    #[error("images must map sensor paths to rates in Hz")]
    Images,
}

/// Reads `sim.startRecording`'s arguments.
fn start_request(path: &LuaValue, options: Option<&Table>) -> Result<RecordingRequest, StartError> {
    let LuaValue::String(p) = path else {
        return Err(StartError::PathType(path.type_name()));
    };
    let path = PathBuf::from(p.to_str().map_err(|_| StartError::PathNotUtf8)?.to_string());
    let folder = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !folder.is_dir() {
        return Err(StartError::NoFolder(folder.to_path_buf()));
    }
    let positive = |what: String, value: f64| {
        if value.is_finite() && value > 0.0 {
            Ok(value)
        } else {
            Err(StartError::Rate { what, value })
        }
    };
    let mut rate_hz = None;
    let mut images = Vec::new();
    if let Some(o) = options {
        if let Ok(Some(r)) = o.get::<Option<f64>>("rate") {
            rate_hz = Some(positive("rate".to_owned(), r)?);
        }
        if let Ok(Some(t)) = o.get::<Option<Table>>("images") {
            for pair in t.pairs::<String, f64>() {
                let (sensor, hz) = pair.map_err(|_| StartError::Images)?;
                images.push((sensor.clone(), positive(format!("the image rate of {sensor}"), hz)?));
            }
            // Lua's table order is not defined: a stable order keeps runs identical.
            images.sort_by(|a, b| a.0.cmp(&b.0));
        }
    }
    Ok(RecordingRequest::Start { path, rate_hz, images })
}

/// Installs the two functions into `sim`, their failures raised through `wrap`.
pub(crate) fn install(lua: &Lua, sim: &Table, wrap: &Function) -> mlua::Result<()> {
    sim.set(
        "startRecording",
        lua.create_function(|lua, (path, options): (LuaValue, Option<Table>)| {
            Ok(match start_request(&path, options.as_ref()) {
                Ok(req) => {
                    *state::<PendingRecording>(lua).0.borrow_mut() = Some(req);
                    (true, LuaValue::Nil)
                }
                Err(e) => (
                    false,
                    LuaValue::String(lua.create_string(format!("{e} (in function 'sim.startRecording')"))?),
                ),
            })
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )?;
    sim.set(
        "stopRecording",
        lua.create_function(|lua, ()| {
            *state::<PendingRecording>(lua).0.borrow_mut() = Some(RecordingRequest::Stop);
            Ok((true, LuaValue::Nil))
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )
}
