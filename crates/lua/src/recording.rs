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

/// Reads `sim.startRecording`'s arguments.
fn start_request(path: &LuaValue, options: Option<&Table>) -> Result<RecordingRequest, String> {
    let LuaValue::String(p) = path else {
        return Err(format!("the path must be a string, got {}", path.type_name()));
    };
    let path = PathBuf::from(p.to_str().map_err(|_| "the path is not UTF-8".to_owned())?.to_string());
    let folder = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !folder.is_dir() {
        return Err(format!("the folder {} does not exist", folder.display()));
    }
    let positive = |what: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(format!("{what} must be a positive number of Hz, got {v}"))
        }
    };
    let mut rate_hz = None;
    let mut images = Vec::new();
    if let Some(o) = options {
        if let Ok(Some(r)) = o.get::<Option<f64>>("rate") {
            rate_hz = Some(positive("rate", r)?);
        }
        if let Ok(Some(t)) = o.get::<Option<Table>>("images") {
            for pair in t.pairs::<String, f64>() {
                let (sensor, hz) = pair.map_err(|_| "images must map sensor paths to rates in Hz".to_owned())?;
                images.push((sensor.clone(), positive(&format!("the image rate of {sensor}"), hz)?));
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
