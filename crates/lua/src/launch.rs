//! `sim.launchExecutable`: starting a program for a script, which only the command line
//! can allow (`gantry run --allow-launch PROGRAM`, repeatable). A scene file is other
//! people's code: by default it starts nothing, and says which option would let it.
//!
//! An allowed program is started directly, never through a shell: its arguments are the
//! words of the `arguments` string (split at white space, no quoting or expansion).
//! Programs a run started are ended when the simulation stops, so a stopped or finished
//! run leaves nothing behind.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use mlua::{Function, Lua, Table, Value as LuaValue};

use crate::app_state::state;
use crate::running::Running;
use crate::sim_cell::SimCell;

/// CoppeliaSim's "could not launch".
const FAILED: i64 = -1;
/// `sim.verbosity_warnings`.
const WARNING: i64 = 300;

/// Why `sim.launchExecutable` started nothing (logged as a warning; the script gets -1).
#[derive(Debug, thiserror::Error)]
enum LaunchError {
    /// The program is not one of the `--allow-launch` programs.
    #[error("scripts start no programs unless gantry is run with --allow-launch {0}")]
    NotAllowed(String),
    /// The operating system could not start it.
    #[error("{program} could not be started: {source}")]
    Spawn { program: String, source: std::io::Error },
}

/// What scripts may start, and what they started.
#[derive(Debug, Default)]
pub(crate) struct Launcher {
    /// Programs allowed, as given on the command line.
    allowed: Vec<PathBuf>,
    /// Programs started during this run.
    children: RefCell<Vec<Child>>,
}

impl Launcher {
    pub(crate) fn new(allowed: Vec<PathBuf>) -> Self {
        Self {
            allowed,
            children: RefCell::new(Vec::new()),
        }
    }

    /// Whether `program` is one of the allowed programs: the same text, or the same
    /// file once both are resolved.
    fn allows(&self, program: &str) -> bool {
        let asked = Path::new(program);
        self.allowed.iter().any(|a| {
            a == asked || matches!((a.canonicalize(), resolve(asked).canonicalize()), (Ok(x), Ok(y)) if x == y)
        })
    }

    /// Starts `program` with `arguments`: its process id, or why not.
    fn launch(&self, program: &str, arguments: &str) -> Result<u32, LaunchError> {
        if !self.allows(program) {
            return Err(LaunchError::NotAllowed(program.to_owned()));
        }
        let child = Command::new(resolve(Path::new(program)))
            .args(arguments.split_whitespace())
            .stdin(Stdio::null())
            .spawn()
            .map_err(|source| LaunchError::Spawn {
                program: program.to_owned(),
                source,
            })?;
        let pid = child.id();
        self.children.borrow_mut().push(child);
        Ok(pid)
    }

    /// Ends the programs this run started (the run is over).
    pub(crate) fn simulation_ended(&self) {
        for mut c in self.children.borrow_mut().drain(..) {
            // Already gone is fine; either way, reap it.
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

impl Drop for Launcher {
    fn drop(&mut self) {
        self.simulation_ended();
    }
}

/// A bare name is looked up on `PATH`, as a shell would (without running one).
fn resolve(program: &Path) -> PathBuf {
    if program.components().count() > 1 {
        return program.to_path_buf();
    }
    std::env::var_os("PATH")
        .iter()
        .flat_map(std::env::split_paths)
        .map(|dir| dir.join(program))
        .find(|p| p.is_file())
        .unwrap_or_else(|| program.to_path_buf())
}

/// Installs `sim.launchExecutable(program, arguments, showStatus)`: the process id, or
/// -1 (CoppeliaSim's failure value) with a warning in the log saying why, so that a
/// script written for a machine with the program goes on without it.
pub(crate) fn install(lua: &Lua, sim: &Table, wrap: &Function) -> mlua::Result<()> {
    let f = lua.create_function(|lua, (program, arguments): (LuaValue, Option<String>)| {
        let program = match &program {
            LuaValue::String(s) => s.to_str()?.to_string(),
            other => {
                return Ok((
                    false,
                    LuaValue::String(lua.create_string(format!(
                        "argument 1: expected string, got {} (in function 'sim.launchExecutable')",
                        other.type_name()
                    ))?),
                ));
            }
        };
        let launched = state::<Launcher>(lua).launch(&program, arguments.as_deref().unwrap_or(""));
        Ok((
            true,
            LuaValue::Integer(match launched {
                Ok(pid) => i64::from(pid),
                Err(why) => {
                    let source = state::<Running>(lua).name.borrow().clone();
                    tracing::warn!("{source}: sim.launchExecutable: {why}");
                    // The same warning in the scene's log, where scripts and clients read it.
                    if let Ok(core) = state::<SimCell>(lua).try_borrow_mut() {
                        let mut core = core;
                        let t = core.world.time();
                        core.world
                            .log
                            .push(t, WARNING, &source, &format!("sim.launchExecutable: {why}"));
                    }
                    FAILED
                }
            }),
        ))
    })?;
    sim.set("launchExecutable", wrap.call::<Function>(f)?)
}
