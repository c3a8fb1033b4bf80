//! [`Simulation`]: the world plus its scripts, and the simulation's life: start, pause,
//! stop, hot reload, models loaded during the run.
//!
//! `sysCall_init` runs when the simulation starts and `sysCall_cleanup` when it stops;
//! one step is in [`crate::step`], the calls of remote clients in [`crate::remote`].
//!
//! All scripts share one Lua 5.4 state (vendored) but each has its own environment
//! table, with its own copies of the global tables (`sim`, `string`, ...), so one script
//! can neither see another's globals nor change what another sees (see [`crate::sandbox`]
//! for everything scripts cannot reach). Each role of the host keeps its state in the
//! Lua state's app data (see [`crate::app_state`]); the world is shared with the `sim`
//! functions through an `Rc<RefCell<..>>` ([`CoreCell`]) on this thread only: the `Lua`
//! value is not `Send` and never leaves the simulation thread.

use std::cell::{Ref, RefCell, RefMut};
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

use gantry_sim_core::scene::{LoadOptions, SceneModel};
use gantry_sim_core::sim::{Advancing, Control, SimulationState};
use gantry_sim_core::{Handle, Sim, World};
use mlua::Lua;

use crate::app_state::{self, state};
use crate::budget;
use crate::control::PendingControl;
use crate::core_cell::CoreCell;
use crate::debugger::{self, DebugHost, DebugLink};
use crate::directory::Directory;
use crate::hooks::{Hook, HookCaller};
use crate::host_api;
use crate::launch::Launcher;
use crate::limits::ScriptLimits;
use crate::listeners::{ListenerState, Listeners};
use crate::lua_error::{ScriptError, error_text};
use crate::luasocket::{self, Sockets};
use crate::messages::Mailboxes;
use crate::models::{self, LoadedModel, ModelLoadError, Models};
use crate::recording::{PendingRecording, RecordingRequest};
use crate::ros::RosNetwork;
use crate::ros::host::RosHost;
use crate::running::Running;
use crate::sandbox::{self, SOURCE_MODE, new_debuggable_state, new_state};
use crate::scripts::{ScriptSet, ScriptState};
use crate::threads::Threads;

/// The world and its scripts.
pub struct Simulation {
    pub(crate) lua: Lua,
    /// The world and its subsystems, also in the Lua state for the `sim` functions.
    pub(crate) core: CoreCell,
    pub(crate) scripts: ScriptSet,
    /// The scene as loaded, plus models loaded since: what a stop rebuilds.
    pub(crate) model: SceneModel,
    /// `simRemoteApi`: the front end's listeners and the servers started this run.
    listeners: Rc<RefCell<ListenerState>>,
    /// Remote clients' blocking calls in progress (`sim.moveToConfig`, ...).
    pub(crate) blocking: crate::threads::BlockingCalls,
}

impl Simulation {
    /// Builds the world and loads every script (top-level code runs now; `sysCall_init`
    /// runs at [`Simulation::start`]). A script that fails to load is marked errored and
    /// reported in the log; the others run.
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn new(model: SceneModel, limits: ScriptLimits) -> Result<Self, ScriptError> {
        let lua = new_state(&limits).map_err(|e| ScriptError(format!("cannot create the Lua state: {e}")))?;
        Self::build(lua, model, limits, None)
    }

    /// [`Simulation::new`] with the script debugger attached to `link` (`gantry run
    /// --debug`): Lua's line hook is installed and scripts stop where a client asks.
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn with_debugger(model: SceneModel, limits: ScriptLimits, link: DebugLink) -> Result<Self, ScriptError> {
        let (lua, libs) =
            new_debuggable_state(&limits).map_err(|e| ScriptError(format!("cannot create the Lua state: {e}")))?;
        let host =
            DebugHost::new(&lua, libs, link).map_err(|e| ScriptError(format!("cannot start the debugger: {e}")))?;
        Self::build(lua, model, limits, Some(host))
    }

    fn build(
        lua: Lua,
        model: SceneModel,
        limits: ScriptLimits,
        debugger: Option<DebugHost>,
    ) -> Result<Self, ScriptError> {
        // Lua seeds `math.random` from the clock and an address; the scene's seed
        // makes every run draw the same numbers (a re-run must, see gantry verify).
        let seed = model.settings.seed;
        lua.load(format!("math.randomseed({seed})"))
            .set_name("@gantry/seed.lua")
            .exec()
            .map_err(|e| ScriptError(format!("cannot seed the scripts' random numbers: {e}")))?;
        let mut sim = Sim::new(&model);
        sandbox::confine(&mut sim, &model);
        for w in sim.world.warnings() {
            tracing::warn!("{w}");
        }
        let core = CoreCell(Rc::new(RefCell::new(sim)));
        // Every role's state goes in before any Lua runs (see `app_state`).
        app_state::install(&lua, core.clone());
        app_state::install(&lua, Running::new(limits.time_budget));
        app_state::install(&lua, Directory::default());
        app_state::install(&lua, Threads::new());
        app_state::install(&lua, Mailboxes::default());
        app_state::install(&lua, PendingControl::default());
        app_state::install(&lua, PendingRecording::default());
        app_state::install(&lua, Models::default());
        app_state::install(&lua, RosHost::default());
        app_state::install(&lua, Launcher::new(limits.allow_launch.clone()));
        let sockets = Sockets::new(limits.network.clone());
        sockets.clear_interrupt();
        app_state::install(&lua, sockets);
        let debugging = debugger.is_some();
        if let Some(host) = debugger {
            app_state::install(&lua, host);
        }
        let listeners = Rc::new(RefCell::new(ListenerState::default()));
        host_api::install(&lua, &listeners).map_err(|e| ScriptError(format!("cannot install the sim API: {e}")))?;
        luasocket::install(&lua).map_err(|e| ScriptError(format!("cannot install LuaSocket: {e}")))?;
        budget::install(&lua, debugging).map_err(|e| ScriptError(format!("cannot install the time budget: {e}")))?;
        let debug_call = if debugging {
            Some(
                debugger::install_protected_call(&lua)
                    .map_err(|e| ScriptError(format!("cannot start the debugger: {e}")))?,
            )
        } else {
            None
        };
        let scripts = ScriptSet::new(lua.clone(), core.clone(), HookCaller::new(lua.clone(), debug_call));
        let mut sim = Simulation {
            lua,
            core,
            scripts,
            model,
            listeners,
            blocking: Default::default(),
        };
        sim.scripts.load_all(&sim.model.scripts);
        Ok(sim)
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

    /// Sets how model files are read (`sim.loadModel`); the host passes the options its
    /// scene was loaded with.
    pub fn set_load_options(&mut self, options: LoadOptions) {
        *state::<Models>(&self.lua).options.borrow_mut() = options;
    }

    /// `sim.loadModel(path)` for a remote client: a robot (`.urdf`) or a gantry model
    /// (`.toml`) from any path gantry can read, as `sim.loadScene`. Returns the handle of
    /// the model base.
    ///
    /// # Errors
    /// The file is not a model or does not load.
    pub fn load_model(&mut self, path: &Path) -> Result<Handle, ModelLoadError> {
        let h = state::<Models>(&self.lua).load(&self.core, path, false)?;
        self.attach_loaded_models();
        Ok(h)
    }

    /// Makes the models `sim.loadModel` put into the world part of the scene: the
    /// model's objects join the scene model (so a stop rebuilds them too) and its
    /// scripts load, and initialise at once if the simulation is running.
    fn attach_loaded_models(&mut self) {
        let loaded = state::<Models>(&self.lua).take_loaded();
        for LoadedModel { model, handles } in loaded {
            // Script indices stay aligned with the model's: the new ones come last in both.
            let first = self.scripts.list.len();
            let objects: Vec<usize> = model.scripts.iter().map(|s| s.object).collect();
            models::merge_into(&mut self.model, model);
            for (k, object) in objects.into_iter().enumerate() {
                // The script runs on the object's live handle (the model's index is
                // where a stop will rebuild it).
                let index = first + k;
                self.scripts.append(index, &self.model.scripts[index], handles[object]);
            }
            self.scripts.reorder();
            if self.state() != SimulationState::Stopped {
                for i in first..self.scripts.list.len() {
                    self.scripts.initialise(i);
                }
            }
        }
    }

    /// `sysCall_nonSimulation` of every script, if the simulation is stopped. The
    /// simulation thread calls it regularly while stopped, as CoppeliaSim does.
    pub fn non_simulation(&mut self) {
        if self.state() == SimulationState::Stopped {
            self.scripts.call_hook_everywhere(Hook::NonSimulation);
            self.apply_control();
        }
    }

    /// Serves the debugger's requests that arrived while no script is stopped (a
    /// stopped script serves them itself). The simulation thread calls it between steps.
    pub fn debug_poll(&mut self) {
        if let Some(d) = self.lua.app_data_ref::<DebugHost>() {
            d.poll(&self.lua);
        }
    }

    /// Whether this simulation runs with the debugger.
    pub fn debugging(&self) -> bool {
        self.lua.app_data_ref::<DebugHost>().is_some()
    }

    /// Takes the debugger's link, to give it to the simulation of a newly loaded scene.
    pub fn take_debug_link(&mut self) -> Option<DebugLink> {
        self.lua.app_data_ref::<DebugHost>().and_then(|d| d.take_link())
    }

    /// Starts (or resumes) the simulation; runs `sysCall_init` of scripts not yet initialised.
    pub fn start(&mut self) {
        // An interrupt left by a request that did not stop (a scene that failed to
        // load) must not cut the new run's first wait short.
        state::<Sockets>(&self.lua).clear_interrupt();
        match self.state() {
            SimulationState::Stopped => {
                self.scripts.call_hook_everywhere(Hook::BeforeSimulation);
                self.core.borrow_mut().advancing = Advancing::FirstAfterStop;
            }
            SimulationState::Paused => {
                let mut w = self.core.borrow_mut();
                w.state = SimulationState::Running;
                w.advancing = Advancing::FirstAfterPause;
                drop(w);
                self.scripts.call_hook_everywhere(Hook::Resume);
            }
            SimulationState::Running => {}
        }
        self.core.borrow_mut().state = SimulationState::Running;
        for k in 0..self.scripts.order.len() {
            let i = self.scripts.order[k];
            if !self.scripts.list[i].initialised {
                self.scripts.initialise(i);
            }
        }
        self.apply_control();
    }

    /// Carries out what scripts asked for while running, now that no script runs:
    /// models loaded, receivers failed, scripts removed, and a start, pause or stop
    /// (see [`Control`]).
    pub(crate) fn apply_control(&mut self) {
        if state::<Models>(&self.lua).pending() {
            self.attach_loaded_models();
        }
        self.scripts.settle();
        let control = state::<PendingControl>(&self.lua).take();
        match control {
            Some(Control::Start) if self.state() != SimulationState::Running => self.start(),
            Some(Control::Pause) => self.pause(),
            Some(Control::Stop) => self.stop(),
            _ => {}
        }
    }

    /// What a script last asked of the recorder (`sim.startRecording`,
    /// `sim.stopRecording`), once: the engine carries it out.
    pub fn take_recording_request(&self) -> Option<RecordingRequest> {
        state::<PendingRecording>(&self.lua).take()
    }

    /// Pauses: steps are refused until [`Simulation::start`].
    pub fn pause(&mut self) {
        if self.state() == SimulationState::Running {
            self.core.borrow_mut().state = SimulationState::Paused;
            self.scripts.call_hook_everywhere(Hook::Suspend);
        }
    }

    /// Stops: runs every script's `sysCall_cleanup`, then restores the scene's initial
    /// state (world and scripts are rebuilt from the scene model).
    pub fn stop(&mut self) {
        // The stop asked for is being served (even when already stopped).
        state::<Sockets>(&self.lua).clear_interrupt();
        if self.state() == SimulationState::Stopped {
            return;
        }
        self.core.borrow_mut().advancing = Advancing::AboutToStop;
        self.cleanup();
        // The run's scripts are gone, and so are their sockets: the scripts about to
        // load bind the same ports again, as CoppeliaSim's fresh Lua states do.
        state::<Sockets>(&self.lua).close_all();
        // Legacy remote API servers started during the run end with it, as in CoppeliaSim.
        self.listeners.borrow_mut().simulation_ended();
        // So do the run's ROS publishers, subscriptions and services, and the programs
        // its scripts started.
        state::<RosHost>(&self.lua).simulation_ended();
        state::<Launcher>(&self.lua).simulation_ended();
        // What cleanup hooks asked for: a removal ends with the run (the scene comes back
        // as loaded), a model loaded joins the scene now being rebuilt.
        state::<Directory>(&self.lua).take_removals();
        let loaded = state::<Models>(&self.lua).take_loaded();
        for l in loaded {
            models::merge_into(&mut self.model, l.model);
        }
        let log = std::mem::take(&mut self.core.borrow_mut().world.log);
        let mut sim = Sim::new(&self.model);
        sandbox::confine(&mut sim, &self.model);
        sim.world.log = log;
        *self.core.borrow_mut() = sim;
        self.scripts.load_all(&self.model.scripts);
        // A cleanup hook asking to stop again, or to start, is not obeyed: the stop
        // was asked for by whoever called this.
        state::<PendingControl>(&self.lua).clear();
    }

    /// Runs `sysCall_cleanup` of every initialised script (errored ones included, as in
    /// CoppeliaSim). Called by [`Simulation::stop`] and on process exit.
    pub fn cleanup(&mut self) {
        let ended = self.state() != SimulationState::Stopped;
        for k in 0..self.scripts.order.len() {
            let i = self.scripts.order[k];
            self.scripts.clean_up(i);
        }
        self.core.borrow_mut().state = SimulationState::Stopped;
        if ended {
            self.scripts.call_hook_everywhere(Hook::AfterSimulation);
        }
    }

    /// The addresses scripts listen on now through LuaSocket (`socket.bind`), e.g. to
    /// find the port a script got when its port is mapped to 0.
    pub fn script_listeners(&self) -> Vec<std::net::SocketAddr> {
        state::<Sockets>(&self.lua).listening()
    }

    /// Closes every socket the scripts opened (LuaSocket), for a simulation about to be
    /// replaced by another scene's: its ports are free when this returns. A script that
    /// uses one afterwards gets LuaSocket's `"closed"`.
    pub fn close_sockets(&self) {
        state::<Sockets>(&self.lua).close_all();
    }

    /// The simulation state.
    pub fn state(&self) -> SimulationState {
        self.core.borrow().state
    }

    /// The world (objects and physics), borrowed for reading.
    pub fn world(&self) -> Ref<'_, World> {
        Ref::map(self.core.borrow(), |s| &s.world)
    }

    /// The world, borrowed for writing.
    pub fn world_mut(&self) -> RefMut<'_, World> {
        RefMut::map(self.core.borrow_mut(), |s| &mut s.world)
    }

    /// The whole simulation (the world and the subsystems on it: UIs, drawings,
    /// graphs, vision images, IK, signals), borrowed for reading.
    pub fn core(&self) -> Ref<'_, Sim> {
        self.core.borrow()
    }

    /// The whole simulation, borrowed for writing.
    pub fn core_mut(&self) -> RefMut<'_, Sim> {
        self.core.borrow_mut()
    }

    /// Each script's file and state.
    pub fn scripts(&self) -> Vec<(PathBuf, Handle, ScriptState)> {
        self.scripts
            .list
            .iter()
            .map(|s| (s.path.clone(), s.object, s.state.clone()))
            .collect()
    }

    /// Reloads scripts whose files changed on disk: the old script's cleanup runs, then
    /// the new one loads and initialises, with the world left as it is. A script that
    /// fails to compile keeps the old version running and the error is logged.
    pub fn reload_changed(&mut self) {
        for i in self.scripts.changed_on_disk() {
            self.reload(i);
        }
    }

    /// Reloads script `i` from its file (see [`Simulation::reload_changed`]).
    pub fn reload(&mut self, i: usize) {
        let running = self.state() != SimulationState::Stopped;
        if let Some(source) = self.scripts.reload(i, running) {
            self.model.scripts[i].source = source;
        }
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
