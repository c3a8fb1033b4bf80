//! [`LuaHost`]: the scene's scripts, the hooks the engine calls between the phases of
//! its step, and what scripts ask of the simulation (a start, pause or stop, models
//! loaded, recordings), kept until the engine carries it out.
//!
//! The host owns no simulation: the engine owns the [`Sim`] and lends it through a
//! [`SimCell`]; the engine decides when the simulation starts, steps and stops, and
//! calls the host's hooks in CoppeliaSim's order (`gantry_engine`'s `step.rs`).
//!
//! All scripts share one Lua 5.4 state (vendored) but each has its own environment
//! table, with its own copies of the global tables (`sim`, `string`, ...), so one script
//! can neither see another's globals nor change what another sees (see [`crate::sandbox`]
//! for everything scripts cannot reach). Each role of the host keeps its state in the
//! Lua state's app data (see [`crate::app_state`]); the `Lua` value is not `Send` and
//! never leaves the simulation thread.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

use gantry_sim_core::Handle;
use gantry_sim_core::scene::{LoadOptions, SceneModel, ScriptModel};
use gantry_sim_core::sim::Control;
use mlua::Lua;

use crate::app_state::{self, state};
use crate::budget;
use crate::control::PendingControl;
use crate::debugger::{self, DebugHost, DebugLink};
use crate::directory::Directory;
use crate::file_rules::FileRoots;
use crate::hooks::{Hook, HookCaller};
use crate::host_api;
use crate::launch::Launcher;
use crate::limits::ScriptLimits;
use crate::listeners::{ListenerState, Listeners};
use crate::lua_error::{ScriptError, error_text};
use crate::luasocket::{self, Sockets};
use crate::messages::Mailboxes;
use crate::models::{LoadedModel, ModelLoadError, Models};
use crate::recording::{PendingRecording, RecordingRequest};
use crate::ros::RosNetwork;
use crate::ros::host::RosHost;
use crate::running::Running;
use crate::sandbox::{SOURCE_MODE, new_debuggable_state, new_state};
use crate::scripts::{ScriptSet, ScriptState};
use crate::sim_cell::SimCell;
use crate::threads::Threads;
use crate::waiting::{WaitService, Waiting};

/// The scene's scripts in one Lua state, over a simulation the engine owns.
pub struct LuaHost {
    pub(crate) lua: Lua,
    /// The engine's simulation, lent to the `sim` functions (also in the app data).
    pub(crate) core: SimCell,
    pub(crate) scripts: ScriptSet,
    /// `simRemoteApi`: the front end's listeners and the servers started this run.
    listeners: Rc<RefCell<ListenerState>>,
    /// Remote clients' blocking calls in progress (`sim.moveToConfig`, ...).
    pub(crate) blocking: crate::threads::BlockingCalls,
}

/// What scripts asked of the simulation while they ran, for the engine to carry out
/// once none runs (see [`LuaHost::take_requests`]).
#[derive(Default)]
pub struct ScriptRequests {
    /// Models `sim.loadModel` put into the world, with their scripts still to attach
    /// ([`LuaHost::attach_scripts`]).
    pub models: Vec<LoadedModel>,
    /// A start, pause or stop (`sim.stopSimulation()`...).
    pub control: Option<Control>,
}

impl LuaHost {
    /// Loads every script of `scripts` into a new Lua state over `sim` (top-level code
    /// runs now; `sysCall_init` runs at [`LuaHost::initialise`]), with the script
    /// debugger attached to `debug` when given (`gantry run --debug`: Lua's line hook is
    /// installed and scripts stop where a client asks). A script that fails to load is
    /// marked errored and reported in the log; the others run. `seed` seeds
    /// `math.random`, so that every run draws the same numbers.
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn new(
        sim: SimCell,
        scripts: &[ScriptModel],
        seed: i64,
        limits: ScriptLimits,
        debug: Option<DebugLink>,
    ) -> Result<Self, ScriptError> {
        let cannot = |what: &str, e: &dyn std::fmt::Display| ScriptError(format!("cannot {what}: {e}"));
        let (lua, debugger) = match debug {
            Some(link) => {
                let (lua, libs) = new_debuggable_state(&limits).map_err(|e| cannot("create the Lua state", &e))?;
                let host = DebugHost::new(&lua, libs, link).map_err(|e| cannot("start the debugger", &e))?;
                (lua, Some(host))
            }
            None => (
                new_state(&limits).map_err(|e| cannot("create the Lua state", &e))?,
                None,
            ),
        };
        // Lua seeds `math.random` from the clock and an address; the scene's seed
        // makes every run draw the same numbers (a re-run must, see gantry verify).
        lua.load(format!("math.randomseed({seed})"))
            .set_name("@gantry/seed.lua")
            .exec()
            .map_err(|e| cannot("seed the scripts' random numbers", &e))?;
        // Every role's state goes in before any Lua runs (see `app_state`).
        app_state::install(&lua, sim.clone());
        app_state::install(&lua, Running::new(limits.time_budget));
        app_state::install(&lua, Directory::default());
        app_state::install(&lua, Threads::new());
        app_state::install(&lua, Mailboxes::default());
        app_state::install(&lua, PendingControl::default());
        app_state::install(&lua, PendingRecording::default());
        app_state::install(&lua, Models::default());
        app_state::install(&lua, RosHost::default());
        app_state::install(&lua, Launcher::new(limits.allow_launch.clone()));
        app_state::install(
            &lua,
            FileRoots {
                lua_path: limits.lua_path.clone(),
                allow_files: limits.allow_files.clone(),
            },
        );
        let sockets = Sockets::new(limits.network.clone());
        sockets.clear_interrupt();
        app_state::install(&lua, sockets);
        app_state::install(&lua, Waiting::default());
        let debugging = debugger.is_some();
        if let Some(host) = debugger {
            app_state::install(&lua, host);
        }
        let listeners = Rc::new(RefCell::new(ListenerState::default()));
        host_api::install(&lua, &listeners).map_err(|e| cannot("install the sim API", &e))?;
        luasocket::install(&lua).map_err(|e| cannot("install LuaSocket", &e))?;
        budget::install(&lua, debugging).map_err(|e| cannot("install the time budget", &e))?;
        let debug_call = if debugging {
            Some(debugger::install_protected_call(&lua).map_err(|e| cannot("start the debugger", &e))?)
        } else {
            None
        };
        let scripts_set = ScriptSet::new(lua.clone(), sim.clone(), HookCaller::new(lua.clone(), debug_call));
        let mut host = LuaHost {
            lua,
            core: sim,
            scripts: scripts_set,
            listeners,
            blocking: Default::default(),
        };
        host.scripts.load_all(scripts);
        Ok(host)
    }

    /// Lets scripts start legacy remote API servers (`simRemoteApi.start`) through the
    /// front end that runs this simulation with its transports.
    pub fn set_listeners(&mut self, listeners: Arc<dyn Listeners>) {
        self.listeners.borrow_mut().front_end = Some(listeners);
    }

    /// Lets scripts join a ROS 2 graph (`simROS2`, `simROS`) through the front end's
    /// network.
    pub fn set_ros_network(&mut self, network: Arc<dyn RosNetwork>) {
        *state::<RosHost>(&self.lua).network.borrow_mut() = Some(network);
    }

    /// Has blocking LuaSocket calls serve the front end through `service` while they
    /// wait, instead of sleeping (see [`WaitService`](crate::WaitService)).
    pub fn set_wait_service(&mut self, service: Option<WaitService>) {
        state::<Waiting>(&self.lua).set(service);
    }

    /// Sets how model files are read (`sim.loadModel`); the engine passes the options its
    /// scene was loaded with.
    pub fn set_load_options(&mut self, options: LoadOptions) {
        *state::<Models>(&self.lua).options.borrow_mut() = options;
    }

    /// `sim.loadModel(path)` for a remote client: a robot (`.urdf`) or a gantry model
    /// (`.toml`) from any path gantry can read, as `sim.loadScene`. Returns the handle of
    /// the model base; its scripts wait in [`LuaHost::take_requests`].
    ///
    /// # Errors
    /// The file is not a model or does not load.
    pub fn load_model(&mut self, path: &Path) -> Result<Handle, ModelLoadError> {
        state::<Models>(&self.lua).load(&self.core, path, false)
    }

    /// What scripts asked of the simulation since the last call: models loaded (their
    /// scripts to attach) and a start, pause or stop. Failed message receivers and
    /// removed scripts are settled here too, now that no script runs.
    pub fn take_requests(&mut self) -> ScriptRequests {
        let models = state::<Models>(&self.lua).take_loaded();
        self.scripts.settle();
        let control = state::<PendingControl>(&self.lua).take();
        ScriptRequests { models, control }
    }

    /// Attaches `scripts` (the scene model's scripts from index `first` on, those of a
    /// model just loaded), each to the live object `objects[k]`, and initialises them
    /// at once if `running`. Script indices stay aligned with the scene model's.
    pub fn attach_scripts(&mut self, first: usize, scripts: &[ScriptModel], objects: &[Handle], running: bool) {
        for (k, (s, &object)) in scripts.iter().zip(objects).enumerate() {
            self.scripts.append(first + k, s, object);
        }
        self.scripts.reorder();
        if running {
            for i in first..self.scripts.list.len() {
                self.scripts.initialise(i);
            }
        }
    }

    /// `sysCall_nonSimulation` of every script: the engine calls it regularly while the
    /// simulation is stopped, as CoppeliaSim does.
    pub fn non_simulation(&mut self) {
        self.scripts.call_hook_everywhere(Hook::NonSimulation);
    }

    /// Serves the debugger's requests that arrived while no script is stopped (a
    /// stopped script serves them itself). The engine calls it between steps.
    pub fn debug_poll(&mut self) {
        if let Some(d) = self.lua.app_data_ref::<DebugHost>() {
            d.poll(&self.lua);
        }
    }

    /// Whether the debugger is attached.
    pub fn debugging(&self) -> bool {
        self.lua.app_data_ref::<DebugHost>().is_some()
    }

    /// Takes the debugger's link, to give it to the host of a newly loaded scene.
    pub fn take_debug_link(&mut self) -> Option<DebugLink> {
        self.lua.app_data_ref::<DebugHost>().and_then(|d| d.take_link())
    }

    /// A start or stop is being served: a script blocked in a LuaSocket call must not
    /// be cut short by the request that is now carried out.
    pub fn clear_interrupt(&self) {
        state::<Sockets>(&self.lua).clear_interrupt();
    }

    /// `sysCall_beforeSimulation` of every script: a stopped simulation starts.
    pub fn before_simulation(&mut self) {
        self.scripts.call_hook_everywhere(Hook::BeforeSimulation);
    }

    /// `sysCall_resume` of every script: a paused simulation goes on.
    pub fn resumed(&mut self) {
        self.scripts.call_hook_everywhere(Hook::Resume);
    }

    /// `sysCall_suspend` of every script: the simulation pauses.
    pub fn suspended(&mut self) {
        self.scripts.call_hook_everywhere(Hook::Suspend);
    }

    /// `sysCall_init` of every script not yet initialised, in hook order.
    pub fn initialise(&mut self) {
        for k in 0..self.scripts.order.len() {
            let i = self.scripts.order[k];
            if self.scripts.list[i].initialised {
                continue;
            }
            // A script whose object was removed while the simulation was stopped goes
            // with it, as in CoppeliaSim, rather than run without its object.
            if self.scripts.object_gone(i) {
                self.scripts
                    .remove_because(i, "script removed with its object (removed while stopped)");
                continue;
            }
            self.scripts.initialise(i);
        }
    }

    /// `sysCall_cleanup` of every initialised script (errored ones included, as in
    /// CoppeliaSim), in hook order.
    pub fn clean_up(&mut self) {
        for k in 0..self.scripts.order.len() {
            let i = self.scripts.order[k];
            self.scripts.clean_up(i);
        }
    }

    /// `sysCall_afterSimulation` of every script: the simulation has ended.
    pub fn after_simulation(&mut self) {
        self.scripts.call_hook_everywhere(Hook::AfterSimulation);
    }

    /// The run is over (its cleanup hooks ran) and the world is about to be rebuilt:
    /// what the run's scripts opened goes with it. Their sockets close (the scripts
    /// about to load bind the same ports again, as CoppeliaSim's fresh Lua states do),
    /// and so do the legacy remote API servers, ROS endpoints and programs they started;
    /// removals asked for end with the run (the scene comes back as loaded). Returns the
    /// models cleanup hooks loaded, which join the scene being rebuilt.
    pub fn simulation_ended(&mut self) -> Vec<LoadedModel> {
        state::<Sockets>(&self.lua).close_all();
        self.listeners.borrow_mut().simulation_ended();
        state::<RosHost>(&self.lua).simulation_ended();
        state::<Launcher>(&self.lua).simulation_ended();
        state::<Directory>(&self.lua).take_removals();
        state::<Models>(&self.lua).take_loaded()
    }

    /// Loads `scripts` afresh over the rebuilt world (after a stop); a start, pause or
    /// stop cleanup hooks asked for is dropped (the stop was asked for by whoever
    /// stopped the simulation).
    pub fn reload_all(&mut self, scripts: &[ScriptModel]) {
        self.scripts.load_all(scripts);
        state::<PendingControl>(&self.lua).clear();
    }

    /// What a script last asked of the recorder (`sim.startRecording`,
    /// `sim.stopRecording`), once: the engine carries it out.
    pub fn take_recording_request(&self) -> Option<RecordingRequest> {
        state::<PendingRecording>(&self.lua).take()
    }

    /// The addresses scripts listen on now through LuaSocket (`socket.bind`), e.g. to
    /// find the port a script got when its port is mapped to 0.
    pub fn script_listeners(&self) -> Vec<std::net::SocketAddr> {
        state::<Sockets>(&self.lua).listening()
    }

    /// Closes every socket the scripts opened (LuaSocket), for a host about to be
    /// replaced by another scene's: its ports are free when this returns. A script that
    /// uses one afterwards gets LuaSocket's `"closed"`.
    pub fn close_sockets(&self) {
        state::<Sockets>(&self.lua).close_all();
    }

    /// Each script's file, object and state.
    pub fn scripts(&self) -> Vec<(PathBuf, Handle, ScriptState)> {
        self.scripts
            .list
            .iter()
            .map(|s| (s.path.clone(), s.object, s.state.clone()))
            .collect()
    }

    /// The scripts whose files changed on disk since they were loaded.
    pub fn changed_on_disk(&mut self) -> Vec<usize> {
        self.scripts.changed_on_disk()
    }

    /// Reloads script `i` from its file: the old script's cleanup runs (if `running`),
    /// then the new one loads and initialises, with the world left as it is. A script
    /// that fails to compile keeps the old version running and the error is logged.
    /// Returns the new source, which the scene model keeps for the next stop.
    pub fn reload(&mut self, i: usize, running: bool) -> Option<String> {
        self.scripts.reload(i, running)
    }
}

/// Compiles every script of a scene without running it, for `gantry check`.
/// Returns one message per script that does not compile, with file and line.
pub fn check_syntax(model: &SceneModel) -> Vec<String> {
    let Ok(lua) = new_state(&ScriptLimits::default()) else {
        return vec!["cannot create a Lua state".into()];
    };
    model
        .scripts
        .iter()
        .filter_map(|s| {
            lua.load(&s.source)
                .set_name(format!("@{}", s.path.display()))
                .set_mode(SOURCE_MODE)
                .into_function()
                .err()
                .map(|e| error_text(&e))
        })
        .collect()
}
