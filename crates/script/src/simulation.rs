//! [`Simulation`]: the world plus its scripts, stepped in CoppeliaSim's order.
//!
//! One step: every script's `sysCall_actuation` (children before parents), the physics
//! substeps, proximity sensors, every script's `sysCall_sensing`, then simulation time
//! advances. `sysCall_init` runs when the simulation starts and `sysCall_cleanup` when it
//! stops. Scripts see the step's start time throughout the step, as in CoppeliaSim.
//!
//! All scripts share one Lua 5.4 state (vendored) but each has its own environment
//! table, with its own copies of the global tables (`sim`, `string`, ...), so one script
//! can neither see another's globals nor change what another sees (see [`crate::sandbox`]
//! for everything scripts cannot reach). The world is shared with the `sim`
//! functions through an `Rc<RefCell<..>>` on this thread only: the `Lua` value is not
//! `Send` and never leaves the simulation thread.

use std::borrow::Cow;
use std::cell::{Cell, RefCell};
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime};

use gantry_sim_core::api::{self, ApiError, Args, CallContext, CallError, ErrorKind};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, SceneModel, ScriptModel, load_model};
use gantry_sim_core::sim::Control;
use gantry_sim_core::sim::{Advancing, SimulationState};
use gantry_sim_core::{Handle, Sim, Value, World};
use mlua::thread::ThreadStatus;
use mlua::{Function, HookTriggers, Lua, MultiValue, Table, Thread, Value as LuaValue, VmState};
use smallvec::SmallVec;

use crate::convert::{to_lua, to_multi, to_value};
use crate::debugger::{DebugHost, DebugLink};
use crate::limits::ScriptLimits;
use crate::listeners::{self, ListenerState, Listeners};
use crate::messages;
use crate::sandbox::{self, SOURCE_MODE, new_debuggable_state, new_state};
use crate::threads::{self, ThreadMode};

/// The hooks a script may define.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hook {
    /// `sysCall_init`.
    Init,
    /// `sysCall_actuation`.
    Actuation,
    /// `sysCall_sensing`.
    Sensing,
    /// `sysCall_cleanup`.
    Cleanup,
    /// `sysCall_beforeSimulation`: when a stopped simulation starts, before any
    /// `sysCall_init`.
    BeforeSimulation,
    /// `sysCall_afterSimulation`: when the simulation has ended, after every cleanup.
    AfterSimulation,
    /// `sysCall_suspend`: when the simulation pauses.
    Suspend,
    /// `sysCall_resume`: when a paused simulation resumes.
    Resume,
    /// `sysCall_nonSimulation`: regularly while the simulation is stopped.
    NonSimulation,
}

impl Hook {
    fn name(self) -> &'static str {
        match self {
            Hook::Init => "sysCall_init",
            Hook::Actuation => "sysCall_actuation",
            Hook::Sensing => "sysCall_sensing",
            Hook::Cleanup => "sysCall_cleanup",
            Hook::BeforeSimulation => "sysCall_beforeSimulation",
            Hook::AfterSimulation => "sysCall_afterSimulation",
            Hook::Suspend => "sysCall_suspend",
            Hook::Resume => "sysCall_resume",
            Hook::NonSimulation => "sysCall_nonSimulation",
        }
    }
}

/// Every `sysCall_*` function gantry calls. A script defining another gets one
/// warning at load, naming it, instead of silently never being called.
pub const SUPPORTED_HOOKS: &[&str] = &[
    "sysCall_actuation",
    "sysCall_afterSimulation",
    "sysCall_beforeSimulation",
    "sysCall_cleanup",
    "sysCall_init",
    "sysCall_msg",
    "sysCall_nonSimulation",
    "sysCall_packet",
    "sysCall_resume",
    "sysCall_sensing",
    "sysCall_suspend",
    "sysCall_thread",
    "sysCall_threadmain",
    "sysCall_vision",
];

/// A script's state, as the viewer and `gantry check` report it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ScriptState {
    /// Loaded and receiving hooks.
    Running,
    /// Stopped receiving hooks (except cleanup) after this error.
    Errored(String),
    /// Removed by `sim.removeScript`: its cleanup ran and it receives nothing more until
    /// the scene is restored by a stop.
    Removed,
}

/// One attached script.
struct Script {
    object: Handle,
    /// Short name for logs: the file name.
    name: Rc<str>,
    path: PathBuf,
    modified: Option<SystemTime>,
    env: Table,
    /// Cached hooks, so a script that defines none costs nothing per step.
    actuation: Option<Function>,
    sensing: Option<Function>,
    /// `sysCall_vision`, called after the script's vision sensor renders.
    vision: Option<Function>,
    state: ScriptState,
    initialised: bool,
    /// The coroutine running `sysCall_thread` (or `sysCall_threadmain`), from
    /// initialisation until it returns or fails (see [`crate::threads`]).
    thread: Option<Thread>,
}

/// What the `sim` closures share with the simulation.
pub(crate) struct Shared {
    /// The simulation scripts act on.
    pub(crate) sim: RefCell<Sim>,
    /// Object of the script running now, for `'.'` in paths.
    pub(crate) current: Cell<Option<Handle>>,
    /// Index of the script running now, for its thread mode.
    pub(crate) current_script: Cell<Option<usize>>,
    pub(crate) current_name: RefCell<Rc<str>>,
    pub(crate) deadline: Cell<Instant>,
    /// Set once the running hook passed its deadline; cleared when the next hook starts.
    pub(crate) interrupted: Cell<bool>,
    /// Environments of scripts by object, for `sim.callScriptFunction`.
    pub(crate) envs: RefCell<Vec<(Handle, Table, Rc<str>)>>,
    /// Each script's `sysCall_msg`, by script index, while it may receive messages
    /// (initialised, running, not cleaned up); see [`crate::messages`].
    pub(crate) msg_hooks: RefCell<Vec<Option<Function>>>,
    /// Scripts whose `sysCall_msg` raised an error, marked errored once no script runs.
    pub(crate) msg_failures: RefCell<Vec<(usize, mlua::Error)>>,
    /// Each script's thread mode, by script index.
    pub(crate) thread_modes: RefCell<Vec<ThreadMode>>,
    /// Scripts `sim.removeScript` removes once no script is running (by index).
    pub(crate) removals: RefCell<Vec<usize>>,
    /// How model files are read (`sim.loadModel`): package paths, free bases.
    pub(crate) load_options: RefCell<LoadOptions>,
    /// Models loaded by `sim.loadModel` whose objects are in the world and whose scripts
    /// load once no script is running (see `Simulation::attach_loaded_models`).
    pub(crate) loaded_models: RefCell<Vec<LoadedModel>>,
    /// The script thread being resumed now (null when none): only it is pre-empted,
    /// not a coroutine of the script's own running inside it.
    pub(crate) running_thread: Cell<*const std::ffi::c_void>,
    /// When the thread being resumed is pre-empted, if its mode allows it.
    pub(crate) slice_end: Cell<Option<Instant>>,
    /// A start, pause or stop asked for by a script, carried out once no script runs.
    pub(crate) control: Cell<Option<Control>>,
    /// Counts the host's calls into scripts, so that a step knows when the hook it
    /// started in has returned.
    pub(crate) entries: Cell<u64>,
    /// The hook (or callback) being called, as the debugger names the bottom frame.
    pub(crate) current_hook: RefCell<Cow<'static, str>>,
    /// The per-hook time budget, for code the debugger runs.
    pub(crate) time_budget: Cell<Duration>,
    /// With `gantry run --debug`: the script debugger.
    pub(crate) debugger: Option<DebugHost>,
    /// `simRemoteApi`: the front end's listeners and the servers started this run.
    pub(crate) listeners: Rc<RefCell<ListenerState>>,
}

impl Shared {
    /// Whether the running code is a script thread whose time slice is over and whose
    /// mode lets it be pre-empted (see [`crate::threads`]).
    fn preemption_due(&self, lua: &Lua, now: Instant) -> bool {
        let Some(end) = self.slice_end.get() else {
            return false;
        };
        if now <= end {
            return false;
        }
        let preemptive = self
            .current_script
            .get()
            .and_then(|i| self.thread_modes.borrow().get(i).map(ThreadMode::preemptive))
            .unwrap_or(false);
        preemptive && lua.current_thread().to_pointer() == self.running_thread.get()
    }
}

/// A point inside a step where [`Simulation::step_with`] lets its caller serve
/// requests, and what may be observed there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepBoundary {
    /// Between two phases: anything may be read or called.
    Phase,
    /// A vision sensor has rendered and its `sysCall_vision` has not processed the
    /// image yet. A reader of vision sensors, or a script (which might read one),
    /// would see an image CoppeliaSim never shows, so such requests must wait; other
    /// world calls are fine.
    VisionUnprocessed,
}

/// The world and its scripts.
pub struct Simulation {
    lua: Lua,
    shared: Rc<Shared>,
    scripts: Vec<Script>,
    /// Script indices in hook order: children's scripts before their parents'.
    order: Vec<usize>,
    model: SceneModel,
    limits: ScriptLimits,
    /// Modification time of each script file as last loaded, so a stop/start keeps a
    /// hot-reloaded version instead of reloading it again.
    mtimes: Vec<Option<SystemTime>>,
    /// With the debugger: calls a script function in a protected call whose message
    /// handler stops at an uncaught error (see [`install_debugger`]).
    debug_call: Option<Function>,
}

/// A script load or syntax problem, with file and line in the message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ScriptError(pub String);

impl Simulation {
    /// Builds the world and loads every script (top-level code runs now; `sysCall_init`
    /// runs at [`Simulation::start`]). A script that fails to load is marked errored and
    /// reported in the log; the others run.
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn new(model: SceneModel, limits: ScriptLimits) -> Result<Self, ScriptError> {
        let lua = new_state(limits).map_err(|e| ScriptError(format!("cannot create the Lua state: {e}")))?;
        Self::build(lua, model, limits, None)
    }

    /// [`Simulation::new`] with the script debugger attached to `link` (`gantry run
    /// --debug`): Lua's line hook is installed and scripts stop where a client asks.
    ///
    /// # Errors
    /// The Lua state could not be created.
    pub fn with_debugger(model: SceneModel, limits: ScriptLimits, link: DebugLink) -> Result<Self, ScriptError> {
        let (lua, libs) =
            new_debuggable_state(limits).map_err(|e| ScriptError(format!("cannot create the Lua state: {e}")))?;
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
        let mut core = Sim::new(&model);
        sandbox::confine(&mut core, &model);
        for w in core.world.warnings() {
            tracing::warn!("{w}");
        }
        let shared = Rc::new(Shared {
            sim: RefCell::new(core),
            current: Cell::new(None),
            current_script: Cell::new(None),
            current_name: RefCell::new(Rc::from("remote")),
            deadline: Cell::new(Instant::now() + Duration::from_secs(3600)),
            interrupted: Cell::new(false),
            envs: RefCell::new(Vec::new()),
            msg_hooks: RefCell::new(Vec::new()),
            msg_failures: RefCell::new(Vec::new()),
            thread_modes: RefCell::new(Vec::new()),
            removals: RefCell::new(Vec::new()),
            load_options: RefCell::new(LoadOptions::default()),
            loaded_models: RefCell::new(Vec::new()),
            running_thread: Cell::new(std::ptr::null()),
            slice_end: Cell::new(None),
            control: Cell::new(None),
            entries: Cell::new(0),
            current_hook: RefCell::new(Cow::Borrowed("")),
            time_budget: Cell::new(limits.time_budget),
            debugger,
            listeners: Rc::new(RefCell::new(ListenerState::default())),
        });
        install_api(&lua, &shared).map_err(|e| ScriptError(format!("cannot install the sim API: {e}")))?;
        install_budget(&lua, &shared, limits.time_budget)
            .map_err(|e| ScriptError(format!("cannot install the time budget: {e}")))?;
        let debug_call = match shared.debugger {
            Some(_) => Some(
                install_debugger(&lua, &shared).map_err(|e| ScriptError(format!("cannot start the debugger: {e}")))?,
            ),
            None => None,
        };
        let mut sim = Simulation {
            lua,
            shared,
            scripts: Vec::new(),
            order: Vec::new(),
            model,
            limits,
            mtimes: Vec::new(),
            debug_call,
        };
        sim.load_scripts();
        Ok(sim)
    }

    fn load_scripts(&mut self) {
        if let Some(d) = &self.shared.debugger {
            d.clear_scripts();
        }
        self.scripts.clear();
        self.shared.envs.borrow_mut().clear();
        self.shared.msg_hooks.borrow_mut().clear();
        self.shared.msg_failures.borrow_mut().clear();
        *self.shared.thread_modes.borrow_mut() = vec![ThreadMode::default(); self.model.scripts.len()];
        for (index, s) in self.model.scripts.clone().into_iter().enumerate() {
            self.load_script(index, &s, s.object as Handle);
        }
        self.mtimes = self.scripts.iter().map(|s| s.modified).collect();
        self.order = hook_order(&self.shared.sim.borrow().world, &self.scripts);
        for i in 0..self.scripts.len() {
            self.warn_unsupported_hooks(i);
        }
    }

    /// Loads script `index` of the model (`s`), attached to `object` in the world, and
    /// runs its chunk; a failure marks it errored, keeping indices aligned with the model.
    fn load_script(&mut self, index: usize, s: &ScriptModel, object: Handle) {
        {
            let name: Rc<str> = Rc::from(s.path.file_name().and_then(|n| n.to_str()).unwrap_or("script"));
            let modified = match self.mtimes.get(index) {
                Some(m) => *m,
                None => std::fs::metadata(&s.path).and_then(|m| m.modified()).ok(),
            };
            // Only a memory error can fail here; the script then runs in no environment
            // of its own and is marked errored below, keeping indices aligned with the model.
            let (env, env_error) = match self.make_env(&name) {
                Ok(e) => (e, None),
                Err(e) => (self.lua.globals(), Some(e)),
            };
            let script = Script {
                object,
                name: name.clone(),
                path: s.path.clone(),
                modified,
                env,
                actuation: None,
                sensing: None,
                vision: None,
                state: ScriptState::Running,
                initialised: false,
                thread: None,
            };
            self.shared.envs.borrow_mut().push((object, script.env.clone(), name));
            self.shared.msg_hooks.borrow_mut().push(None);
            self.scripts.push(script);
            self.register_with_debugger(index, &s.source);
            if let Some(e) = env_error {
                self.fail(index, e);
            } else if let Err(e) = self.exec_chunk(index, &s.source) {
                self.fail(index, e);
            }
        }
    }

    /// Lets scripts start legacy remote API servers (`simRemoteApi.start`) through the
    /// front end that runs this simulation with its transports.
    pub fn set_listeners(&mut self, listeners: Arc<dyn Listeners>) {
        self.shared.listeners.borrow_mut().front_end = Some(listeners);
    }

    /// Sets how model files are read (`sim.loadModel`); the host passes the options its
    /// scene was loaded with.
    pub fn set_load_options(&mut self, options: LoadOptions) {
        *self.shared.load_options.borrow_mut() = options;
    }

    /// `sim.loadModel(path)` for a remote client: a robot (`.urdf`) or a gantry model
    /// (`.toml`) from any path gantry can read, as `sim.loadScene`. Returns the handle of
    /// the model base.
    ///
    /// # Errors
    /// The file is not a model or does not load.
    pub fn load_model(&mut self, path: &std::path::Path) -> Result<Handle, String> {
        let h = load_model_into(&self.shared, path, false)?;
        self.attach_loaded_models();
        Ok(h)
    }

    /// Appends a loaded model's objects and scripts to the scene model (indices moved
    /// past the scene's), so that a stop rebuilds them; returns the offset.
    fn merge_into_model(&mut self, model: SceneModel) -> usize {
        let offset = self.model.objects.len();
        for mut o in model.objects {
            o.parent = o.parent.map(|p| p + offset);
            if let gantry_sim_core::scene::ObjectModelKind::Joint(j) = &mut o.kind
                && let Some(m) = &mut j.mimic
            {
                m.leader += offset;
            }
            self.model.objects.push(o);
        }
        for s in model.scripts {
            self.model.scripts.push(ScriptModel {
                object: s.object + offset,
                ..s
            });
        }
        offset
    }

    /// `sim.removeScript`: script `i`'s cleanup runs (if it was initialised), then it
    /// receives nothing more and no longer answers `sim.getScript`.
    fn remove_script(&mut self, i: usize) {
        if i >= self.scripts.len() || self.scripts[i].state == ScriptState::Removed {
            return;
        }
        if self.scripts[i].initialised {
            self.call_hook(i, Hook::Cleanup);
            self.scripts[i].initialised = false;
        }
        let s = &mut self.scripts[i];
        s.state = ScriptState::Removed;
        s.actuation = None;
        s.sensing = None;
        s.vision = None;
        s.thread = None;
        self.set_msg_hook(i, None);
        if let Some(entry) = self.shared.envs.borrow_mut().get_mut(i) {
            entry.0 = REMOVED_SCRIPT;
        }
        let name = self.scripts[i].name.clone();
        self.log(400, &name, "script removed (sim.removeScript)");
    }

    /// Makes the models `sim.loadModel` put into the world part of the scene: the
    /// model's objects join the scene model (so a stop rebuilds them too) and its
    /// scripts load, and initialise at once if the simulation is running.
    fn attach_loaded_models(&mut self) {
        let loaded = std::mem::take(&mut *self.shared.loaded_models.borrow_mut());
        for LoadedModel { model, handles } in loaded {
            // Script indices stay aligned with the model's: the new ones come last in both.
            let first = self.scripts.len();
            let objects: Vec<usize> = model.scripts.iter().map(|s| s.object).collect();
            self.merge_into_model(model);
            for (k, object) in objects.into_iter().enumerate() {
                // The script runs on the object's live handle (the model's index is
                // where a stop will rebuild it).
                let live = handles[object];
                let index = first + k;
                let s = self.model.scripts[index].clone();
                self.shared.thread_modes.borrow_mut().push(ThreadMode::default());
                self.load_script(index, &s, live);
                self.mtimes.push(self.scripts[index].modified);
                self.warn_unsupported_hooks(index);
            }
            self.order = hook_order(&self.shared.sim.borrow().world, &self.scripts);
            if self.state() != SimulationState::Stopped {
                for i in first..self.scripts.len() {
                    self.scripts[i].initialised = true;
                    self.call_hook(i, Hook::Init);
                    if self.scripts[i].state == ScriptState::Running {
                        self.cache_hooks(i);
                    }
                }
            }
        }
    }

    /// Names, once per load, the `sysCall_*` functions of script `i` that gantry never
    /// calls (CoppeliaSim's add-on and editor callbacks, `sysCall_contactCallback`, ...).
    fn warn_unsupported_hooks(&self, i: usize) {
        let script = &self.scripts[i];
        let mut unsupported: Vec<String> = script
            .env
            .pairs::<LuaValue, LuaValue>()
            .filter_map(|pair| {
                let (k, v) = pair.ok()?;
                let name = k.as_string()?.to_str().ok()?.to_owned();
                (name.starts_with("sysCall_") && v.is_function() && !SUPPORTED_HOOKS.contains(&name.as_str()))
                    .then_some(name)
            })
            .collect();
        if unsupported.is_empty() {
            return;
        }
        unsupported.sort_unstable();
        let msg = format!(
            "{} not supported by gantry and will never be called (supported: {})",
            unsupported.join(", "),
            SUPPORTED_HOOKS.join(", ")
        );
        self.log(300, &script.name.clone(), &msg);
    }

    /// Calls `hook` of every script that has not errored, in hook order.
    fn call_hook_everywhere(&mut self, hook: Hook) {
        for k in 0..self.order.len() {
            let i = self.order[k];
            self.call_hook(i, hook);
        }
    }

    /// `sysCall_nonSimulation` of every script, if the simulation is stopped. The
    /// simulation thread calls it regularly while stopped, as CoppeliaSim does.
    pub fn non_simulation(&mut self) {
        if self.state() == SimulationState::Stopped {
            self.call_hook_everywhere(Hook::NonSimulation);
            self.apply_control();
        }
    }

    fn make_env(&self, name: &Rc<str>) -> mlua::Result<Table> {
        // Private copies of the global tables: see `sandbox::script_env`.
        let env = sandbox::script_env(&self.lua)?;
        // `print` logs with the script's name (CoppeliaSim prints to its status bar).
        let shared = self.shared.clone();
        let source = name.clone();
        let print = self.lua.create_function(move |_, args: MultiValue| {
            let text: Vec<String> = args.iter().map(display).collect();
            let w = &mut shared.sim.borrow_mut().world;
            let t = w.time();
            w.log.push(t, 450, &source, &text.join("\t"));
            Ok(())
        })?;
        env.set("print", print)?;
        sandbox::add_require(&self.lua, &env)?;
        Ok(env)
    }

    fn exec_chunk(&self, i: usize, source: &str) -> mlua::Result<()> {
        self.enter(i, Cow::Borrowed("main chunk"));
        let script = &self.scripts[i];
        let r = self
            .lua
            .load(source)
            .set_name(format!("@{}", script.path.display()))
            .set_mode(SOURCE_MODE)
            .set_environment(script.env.clone())
            .exec();
        self.leave();
        r
    }

    fn enter(&self, i: usize, hook: Cow<'static, str>) {
        self.shared.entries.set(self.shared.entries.get().wrapping_add(1));
        *self.shared.current_hook.borrow_mut() = hook;
        let script = &self.scripts[i];
        self.shared.current.set(Some(script.object));
        self.shared.current_script.set(Some(i));
        *self.shared.current_name.borrow_mut() = script.name.clone();
        self.shared.deadline.set(Instant::now() + self.limits.time_budget);
        self.shared.interrupted.set(false);
    }

    /// Calls a script function: directly, or with the debugger through the protected
    /// call that stops at an uncaught error.
    fn call_script<R: mlua::FromLuaMulti>(&self, f: &Function, args: impl mlua::IntoLuaMulti) -> mlua::Result<R> {
        match &self.debug_call {
            None => f.call(args),
            Some(dc) => {
                let mut all = args.into_lua_multi(&self.lua)?;
                all.push_front(LuaValue::Function(f.clone()));
                dc.call(all)
            }
        }
    }

    /// Tells the debugger (if any) about script `i` and its source.
    fn register_with_debugger(&self, i: usize, source: &str) {
        let Some(d) = &self.shared.debugger else { return };
        let script = &self.scripts[i];
        let object_path = {
            use gantry_sim_core::world::object_path::object_alias;
            object_alias(&self.shared.sim.borrow().world, script.object, 2)
        };
        d.register_script(i, &script.path, object_path, source);
    }

    /// Serves the debugger's requests that arrived while no script is stopped (a
    /// stopped script serves them itself). The simulation thread calls it between steps.
    pub fn debug_poll(&mut self) {
        if let Some(d) = &self.shared.debugger {
            d.poll(&self.lua, &self.shared);
        }
    }

    /// Whether this simulation runs with the debugger.
    pub fn debugging(&self) -> bool {
        self.shared.debugger.is_some()
    }

    /// Takes the debugger's link, to give it to the simulation of a newly loaded scene.
    pub fn take_debug_link(&mut self) -> Option<DebugLink> {
        self.shared.debugger.as_ref().and_then(DebugHost::take_link)
    }

    fn leave(&self) {
        self.shared.interrupted.set(false);
        self.shared.current.set(None);
        self.shared.current_script.set(None);
        self.shared.deadline.set(Instant::now() + Duration::from_secs(3600));
    }

    /// Marks script `i` errored after `e`: it receives no more hooks but cleanup, and
    /// its thread, if any, is not resumed again.
    fn fail(&mut self, i: usize, e: mlua::Error) {
        let msg = error_text(&e);
        let script = &mut self.scripts[i];
        let w = &mut self.shared.sim.borrow_mut().world;
        let t = w.time();
        w.log.push(
            t,
            200,
            &script.name,
            &format!("script error; it will receive no more hooks: {msg}"),
        );
        script.state = ScriptState::Errored(msg);
        script.actuation = None;
        script.sensing = None;
        script.vision = None;
        script.thread = None;
        self.set_msg_hook(i, None);
    }

    /// Sets (or, with `None`, withdraws) script `i`'s message receiver.
    fn set_msg_hook(&self, i: usize, f: Option<Function>) {
        if let Some(slot) = self.shared.msg_hooks.borrow_mut().get_mut(i) {
            *slot = f;
        }
    }

    /// Calls one hook of one script, if it defines it and has not errored.
    fn call_hook(&mut self, i: usize, hook: Hook) {
        let script = &self.scripts[i];
        if script.state == ScriptState::Removed || hook != Hook::Cleanup && script.state != ScriptState::Running {
            return;
        }
        let f = match hook {
            Hook::Actuation => script.actuation.clone(),
            Hook::Sensing => script.sensing.clone(),
            _ => script.env.raw_get::<Option<Function>>(hook.name()).ok().flatten(),
        };
        let Some(f) = f else { return };
        self.enter(i, Cow::Borrowed(hook.name()));
        let r = self.call_script::<()>(&f, ());
        self.leave();
        if let Err(e) = r {
            self.fail(i, e);
        }
    }

    fn cache_hooks(&mut self, i: usize) {
        let s = &mut self.scripts[i];
        s.actuation = s.env.raw_get::<Option<Function>>(Hook::Actuation.name()).ok().flatten();
        s.sensing = s.env.raw_get::<Option<Function>>(Hook::Sensing.name()).ok().flatten();
        s.vision = s.env.raw_get::<Option<Function>>("sysCall_vision").ok().flatten();
        let msg = s.env.raw_get::<Option<Function>>("sysCall_msg").ok().flatten();
        self.set_msg_hook(i, msg);
        let s = &mut self.scripts[i];
        // 4.6+ names the thread's body sysCall_thread; 4.0-4.2 threaded child scripts,
        // sysCall_threadmain. The coroutine first runs at the next step's actuation.
        let body = ["sysCall_thread", "sysCall_threadmain"]
            .iter()
            .find_map(|name| s.env.raw_get::<Option<Function>>(*name).ok().flatten());
        s.thread = None;
        if let Some(body) = body {
            // With the debugger, the body runs inside the protected call that stops at
            // an uncaught error (Lua 5.4 lets a coroutine yield across it).
            let body = match &self.debug_call {
                Some(dc) => dc.bind(body),
                None => Ok(body),
            };
            match body.and_then(|b| self.lua.create_thread(b)) {
                Ok(t) => self.scripts[i].thread = Some(t),
                Err(e) => self.fail(i, e),
            }
        }
    }

    /// Resumes every script thread once, in hook order (see [`crate::threads`]).
    fn resume_threads(&mut self) {
        for k in 0..self.order.len() {
            let i = self.order[k];
            let Some(thread) = self.scripts[i].thread.clone() else {
                continue;
            };
            self.enter(i, Cow::Borrowed("sysCall_thread"));
            let mode = self.shared.thread_modes.borrow().get(i).copied().unwrap_or_default();
            self.shared.running_thread.set(thread.to_pointer());
            self.shared.slice_end.set(Some(Instant::now() + mode.auto_yield));
            let r = thread.resume::<()>(());
            self.shared.slice_end.set(None);
            self.shared.running_thread.set(std::ptr::null());
            self.leave();
            match r {
                Ok(()) if thread.status() == ThreadStatus::Resumable => {}
                // The body returned: the thread has ended, the script's hooks go on.
                Ok(()) => self.scripts[i].thread = None,
                Err(e) => self.fail(i, e),
            }
        }
    }

    /// Starts (or resumes) the simulation; runs `sysCall_init` of scripts not yet initialised.
    pub fn start(&mut self) {
        match self.state() {
            SimulationState::Stopped => {
                self.call_hook_everywhere(Hook::BeforeSimulation);
                self.shared.sim.borrow_mut().advancing = Advancing::FirstAfterStop;
            }
            SimulationState::Paused => {
                let mut w = self.shared.sim.borrow_mut();
                w.state = SimulationState::Running;
                w.advancing = Advancing::FirstAfterPause;
                drop(w);
                self.call_hook_everywhere(Hook::Resume);
            }
            SimulationState::Running => {}
        }
        self.shared.sim.borrow_mut().state = SimulationState::Running;
        for k in 0..self.order.len() {
            let i = self.order[k];
            if !self.scripts[i].initialised {
                self.scripts[i].initialised = true;
                self.call_hook(i, Hook::Init);
                if self.scripts[i].state == ScriptState::Running {
                    self.cache_hooks(i);
                }
            }
        }
        self.apply_control();
    }

    /// Carries out a start, pause or stop that a script asked for (see
    /// [`Control`]), now that no script is running.
    fn apply_control(&mut self) {
        if !self.shared.loaded_models.borrow().is_empty() {
            self.attach_loaded_models();
        }
        let failures = std::mem::take(&mut *self.shared.msg_failures.borrow_mut());
        for (i, e) in failures {
            if self.scripts.get(i).is_some_and(|s| s.state == ScriptState::Running) {
                self.fail(i, e);
            }
        }
        let removals = std::mem::take(&mut *self.shared.removals.borrow_mut());
        for i in removals {
            self.remove_script(i);
        }
        match self.shared.control.take() {
            Some(Control::Start) if self.state() != SimulationState::Running => self.start(),
            Some(Control::Pause) => self.pause(),
            Some(Control::Stop) => self.stop(),
            _ => {}
        }
    }

    /// Pauses: steps are refused until [`Simulation::start`].
    pub fn pause(&mut self) {
        if self.state() == SimulationState::Running {
            self.shared.sim.borrow_mut().state = SimulationState::Paused;
            self.call_hook_everywhere(Hook::Suspend);
        }
    }

    /// Stops: runs every script's `sysCall_cleanup`, then restores the scene's initial
    /// state (world and scripts are rebuilt from the scene model).
    pub fn stop(&mut self) {
        if self.state() == SimulationState::Stopped {
            return;
        }
        self.shared.sim.borrow_mut().advancing = Advancing::AboutToStop;
        self.cleanup();
        // Legacy remote API servers started during the run end with it, as in CoppeliaSim.
        self.shared.listeners.borrow_mut().simulation_ended();
        // What cleanup hooks asked for: a removal ends with the run (the scene comes back
        // as loaded), a model loaded joins the scene now being rebuilt.
        self.shared.removals.borrow_mut().clear();
        let loaded = std::mem::take(&mut *self.shared.loaded_models.borrow_mut());
        for l in loaded {
            self.merge_into_model(l.model);
        }
        let log = std::mem::take(&mut self.shared.sim.borrow_mut().world.log);
        let mut sim = Sim::new(&self.model);
        sandbox::confine(&mut sim, &self.model);
        sim.world.log = log;
        *self.shared.sim.borrow_mut() = sim;
        self.load_scripts();
        // A cleanup hook asking to stop again, or to start, is not obeyed: the stop
        // was asked for by whoever called this.
        self.shared.control.set(None);
    }

    /// Runs `sysCall_cleanup` of every initialised script (errored ones included, as in
    /// CoppeliaSim). Called by [`Simulation::stop`] and on process exit.
    pub fn cleanup(&mut self) {
        let ended = self.state() != SimulationState::Stopped;
        for k in 0..self.order.len() {
            let i = self.order[k];
            if self.scripts[i].initialised {
                self.call_hook(i, Hook::Cleanup);
                self.scripts[i].initialised = false;
                self.set_msg_hook(i, None);
            }
        }
        self.shared.sim.borrow_mut().state = SimulationState::Stopped;
        if ended {
            self.call_hook_everywhere(Hook::AfterSimulation);
        }
    }

    /// The simulation state.
    pub fn state(&self) -> SimulationState {
        self.shared.sim.borrow().state
    }

    /// One simulation step in CoppeliaSim's order. Starts the simulation if stopped;
    /// does nothing while paused.
    pub fn step(&mut self) {
        self.step_with(&mut |_, _| {});
    }

    /// [`Simulation::step`], calling `between` at each boundary between its phases:
    /// after actuation, after physics and proximity sensing, and for each vision
    /// sensor with a `sysCall_vision`, after its render and after its callback. No
    /// script is running at those points, so `between` may call [`Simulation::call`]
    /// and script functions, as CoppeliaSim serves remote clients between its scripts;
    /// the [`StepBoundary`] says what is safe to observe there. The server uses it to
    /// answer requests during a long step instead of after it. `between` must not
    /// start, stop, pause or step the simulation.
    pub fn step_with(&mut self, between: &mut dyn FnMut(&mut Simulation, StepBoundary)) {
        match self.state() {
            SimulationState::Stopped => self.start(),
            SimulationState::Paused => return,
            SimulationState::Running => {}
        }
        // A script's sysCall_init may have stopped or paused the simulation.
        if self.state() != SimulationState::Running {
            return;
        }
        self.dispatch_ui_events();
        // CoppeliaSim resumes threads at the start of actuation.
        self.resume_threads();
        for k in 0..self.order.len() {
            let i = self.order[k];
            if self.scripts[i].actuation.is_some() {
                self.call_hook(i, Hook::Actuation);
            }
        }
        between(self, StepBoundary::Phase);
        self.shared.sim.borrow_mut().step_dynamics();
        between(self, StepBoundary::Phase);
        self.handle_vision(between);
        for k in 0..self.order.len() {
            let i = self.order[k];
            if self.scripts[i].sensing.is_some() {
                self.call_hook(i, Hook::Sensing);
            }
        }
        self.shared.sim.borrow_mut().finish_step();
        self.apply_control();
    }

    /// Runs the callbacks of UI events (a slider moved in the viewer, `simUI.interact`)
    /// in the scripts that created the UIs: `callback(ui, id, value)`, on the script's
    /// next turn, before actuation.
    fn dispatch_ui_events(&mut self) {
        let events = self.shared.sim.borrow_mut().uis.take_events();
        for ev in events {
            let Some(i) = self
                .scripts
                .iter()
                .position(|s| Some(s.object) == ev.script_object && s.state == ScriptState::Running)
            else {
                continue;
            };
            let Ok(Some(f)) = self.scripts[i].env.get::<Option<Function>>(ev.callback.as_str()) else {
                let msg = format!("UI callback '{}' is not a function of this script", ev.callback);
                self.log(300, &self.scripts[i].name.clone(), &msg);
                continue;
            };
            let args = match to_multi(&self.lua, &[Value::Int(ev.ui), Value::Int(ev.widget), ev.value.clone()]) {
                Ok(a) => a,
                Err(e) => {
                    self.log(200, &self.scripts[i].name.clone(), &format!("UI event dropped: {e}"));
                    continue;
                }
            };
            self.enter(i, Cow::Owned(ev.callback.clone()));
            let r = self.call_script::<()>(&f, args);
            self.leave();
            if let Err(e) = r {
                self.fail(i, e);
            }
        }
    }

    /// Renders the vision sensors whose scripts define `sysCall_vision`, then calls it
    /// with `inData.handle` (CoppeliaSim handles vision sensors after proximity sensors,
    /// before `sysCall_sensing`). Sensors without such a script render only when read.
    fn handle_vision(&mut self, between: &mut dyn FnMut(&mut Simulation, StepBoundary)) {
        for k in 0..self.order.len() {
            let i = self.order[k];
            let Some(f) = self.scripts[i].vision.clone() else {
                continue;
            };
            let h = self.scripts[i].object;
            let rendered = {
                let sim = &mut *self.shared.sim.borrow_mut();
                gantry_sim_core::vision::handle_vision_sensor(&sim.world, &mut sim.vision, h)
            };
            if let Err(e) = rendered {
                let msg = format!("sysCall_vision needs the script on a vision sensor: {e}");
                self.log(300, &self.scripts[i].name.clone(), &msg);
                self.scripts[i].vision = None;
                continue;
            }
            between(self, StepBoundary::VisionUnprocessed);
            let in_data = match self.vision_in_data(h) {
                Ok(t) => t,
                Err(e) => {
                    self.fail(i, e);
                    continue;
                }
            };
            self.enter(i, Cow::Borrowed("sysCall_vision"));
            let r = self.call_script::<Option<Table>>(&f, in_data);
            self.leave();
            match r {
                // `return {trigger = true, packedPackets = {sim.packFloatTable(...)}}`
                // makes readVisionSensor report a detection, as in CoppeliaSim.
                Ok(Some(out)) => {
                    let trigger = out.get::<Option<bool>>("trigger").ok().flatten().unwrap_or(false);
                    let packets: Vec<Vec<f64>> = out
                        .get::<Option<Vec<mlua::LuaString>>>("packedPackets")
                        .ok()
                        .flatten()
                        .unwrap_or_default()
                        .iter()
                        .map(|p| gantry_sim_core::vision::unpack_floats(&p.as_bytes()))
                        .collect();
                    let _ = self
                        .shared
                        .sim
                        .borrow_mut()
                        .vision
                        .set_callback_result(h, trigger, packets);
                }
                Ok(None) => {}
                Err(e) => {
                    self.fail(i, e);
                }
            }
            between(self, StepBoundary::Phase);
        }
    }

    /// CoppeliaSim's `inData` for `sysCall_vision`: handle, resolution, clipping planes,
    /// view angle (rad) and the perspective flag.
    fn vision_in_data(&self, h: Handle) -> mlua::Result<Table> {
        let t = self.lua.create_table()?;
        t.set("handle", h)?;
        if let Ok(gantry_sim_core::world::ObjectKind::VisionSensor(v)) =
            self.shared.sim.borrow().world.object(h).map(|o| &o.kind)
        {
            t.set(
                "resolution",
                vec![i64::from(v.resolution[0]), i64::from(v.resolution[1])],
            )?;
            t.set("clippingPlanes", vec![v.near, v.far])?;
            t.set("viewAngle", v.fov)?;
            t.set("orthoSize", 0.0)?;
            t.set("perspectiveOperation", true)?;
        }
        Ok(t)
    }

    /// The world (objects and physics), borrowed for reading.
    pub fn world(&self) -> std::cell::Ref<'_, World> {
        std::cell::Ref::map(self.shared.sim.borrow(), |s| &s.world)
    }

    /// The world, borrowed for writing.
    pub fn world_mut(&self) -> std::cell::RefMut<'_, World> {
        std::cell::RefMut::map(self.shared.sim.borrow_mut(), |s| &mut s.world)
    }

    /// The whole simulation (the world and the subsystems on it: UIs, drawings,
    /// graphs, vision images, IK, signals), borrowed for reading.
    pub fn core(&self) -> std::cell::Ref<'_, Sim> {
        self.shared.sim.borrow()
    }

    /// The whole simulation, borrowed for writing.
    pub fn core_mut(&self) -> std::cell::RefMut<'_, Sim> {
        self.shared.sim.borrow_mut()
    }

    /// Each script's file and state.
    pub fn scripts(&self) -> Vec<(PathBuf, Handle, ScriptState)> {
        self.scripts
            .iter()
            .map(|s| (s.path.clone(), s.object, s.state.clone()))
            .collect()
    }

    /// Calls a `sim.*` function for a remote client (no emitting object), by name: the
    /// name is resolved here, once (see [`api::Target`]).
    ///
    /// # Errors
    /// The CoppeliaSim-style error message.
    pub fn call(&mut self, name: &str, args: &[Value]) -> Result<Vec<Value>, CallError> {
        let target = api::Target::resolve_or_error(name)?;
        self.call_target(&target, args)
    }

    /// Calls a resolved function for a remote client (no emitting object). Functions of
    /// the simulation loop ([`api::Target::FrontEnd`]) are the engine's, not the
    /// scene's: they are refused here.
    ///
    /// # Errors
    /// The CoppeliaSim-style error message.
    pub fn call_target(&mut self, target: &api::Target, args: &[Value]) -> Result<Vec<Value>, CallError> {
        match *target {
            api::Target::Core { function, .. } => self
                .call_function(function, args)
                .map_err(|e| CallError::failed(target.qualified(), e)),
            api::Target::ScriptHost(f) => self.call_script_host(f, args),
            api::Target::FrontEnd(_) => Err(CallError::NoSuchFunction(target.qualified())),
        }
    }

    /// A function the Lua host serves for remote clients (it needs the scripts).
    ///
    /// # Errors
    /// The CoppeliaSim-style error message.
    pub fn call_script_host(&mut self, f: api::ScriptHostFn, args: &[Value]) -> Result<Vec<Value>, CallError> {
        use api::ScriptHostFn;
        let in_function = |e: ApiError| CallError::failed(format!("sim.{}", f.name()), e);
        match f {
            ScriptHostFn::GetScriptAssociatedWithObject => script_handle(
                &self.shared,
                &[Value::Int(1), args.first().cloned().unwrap_or_default()],
            )
            .map(|h| vec![Value::Int(h)])
            .map_err(|e| in_function(ApiError::new(e))),
            ScriptHostFn::RemoveScript => {
                let h = args.first().and_then(Value::as_i64);
                match h.map(|h| (h, script_index(&self.shared, h))) {
                    Some((_, Some(i))) => {
                        self.remove_script(i);
                        Ok(Vec::new())
                    }
                    Some((HANDLE_SELF, None)) => Err(ApiError::bad_argument(
                        "sim.handle_self names the calling script, and a remote client has none",
                    )),
                    Some((h, None)) => Err(ApiError::of(
                        ErrorKind::NoSuchObject,
                        format!("argument 1: no script has handle {h}"),
                    )),
                    None => Err(ApiError::bad_argument(format!(
                        "argument 1: expected a script handle, got {}",
                        args.first().map_or("nil", Value::type_name)
                    ))),
                }
                .map_err(in_function)
            }
            ScriptHostFn::LoadModel => match args.first() {
                Some(Value::Str(path)) => self
                    .load_model(std::path::Path::new(path))
                    .map_err(|e| in_function(ApiError::new(e))),
                _ => Err(in_function(ApiError::bad_argument(
                    "argument 1: expected the model file's path as a string",
                ))),
            }
            .map(|h| vec![Value::Int(h)]),
            ScriptHostFn::GetScript => script_handle(&self.shared, args)
                .map(|h| vec![Value::Int(h)])
                .map_err(|e| in_function(ApiError::new(e))),
            ScriptHostFn::CallScriptFunction => {
                // Script code running for a remote client is outside any hook, so it gets
                // a hook's time budget here; otherwise a loop in the called function
                // would hold the simulation thread until the idle deadline, an hour away.
                self.shared.deadline.set(Instant::now() + self.limits.time_budget);
                self.shared.interrupted.set(false);
                let r = call_script_function(&self.lua, &self.shared, args);
                self.leave();
                self.apply_control();
                r.map_err(|e| in_function(ApiError::new(error_text(&e))))
            }
        }
    }

    /// Calls one registry function for a client outside the scene (no emitting object),
    /// already looked up: what an in-process client does on every call, so that no
    /// name is searched for per call. The error is the function's own, unqualified.
    ///
    /// # Errors
    /// The function's error.
    pub fn call_function(&mut self, f: &api::ApiFunction, args: &[Value]) -> Result<Vec<Value>, api::ApiError> {
        let ctx = CallContext {
            script_object: None,
            source: "remote",
        };
        f.invoke(&mut self.shared.sim.borrow_mut(), &ctx, &Args::new(args))
    }

    /// Reloads scripts whose files changed on disk: the old script's cleanup runs, then
    /// the new one loads and initialises, with the world left as it is. A script that
    /// fails to compile keeps the old version running and the error is logged.
    pub fn reload_changed(&mut self) {
        for i in 0..self.scripts.len() {
            let modified = std::fs::metadata(&self.scripts[i].path).and_then(|m| m.modified()).ok();
            // A removed script stays removed until a stop restores the scene.
            if modified.is_none()
                || modified == self.scripts[i].modified
                || self.scripts[i].state == ScriptState::Removed
            {
                continue;
            }
            self.scripts[i].modified = modified;
            if let Some(m) = self.mtimes.get_mut(i) {
                *m = modified;
            }
            self.reload(i);
        }
    }

    /// Reloads script `i` from its file (see [`Simulation::reload_changed`]).
    pub fn reload(&mut self, i: usize) {
        let Some(script) = self.scripts.get(i) else {
            return;
        };
        let (path, name) = (script.path.clone(), script.name.clone());
        let source = match std::fs::read_to_string(&path) {
            Ok(s) => s,
            Err(e) => {
                self.log(
                    200,
                    &name,
                    &format!(
                        "reload failed, keeping the running version: cannot read {}: {e}",
                        path.display()
                    ),
                );
                return;
            }
        };
        if let Err(e) = self
            .lua
            .load(&source)
            .set_name(format!("@{}", path.display()))
            .set_mode(SOURCE_MODE)
            .into_function()
        {
            self.log(
                200,
                &name,
                &format!("reload failed, keeping the running version: {}", error_text(&e)),
            );
            return;
        }
        let was_running = self.scripts[i].initialised;
        if was_running {
            self.call_hook(i, Hook::Cleanup);
        }
        self.set_msg_hook(i, None);
        let env = match self.make_env(&name) {
            Ok(e) => e,
            Err(e) => {
                self.log(200, &name, &format!("reload failed: {e}"));
                return;
            }
        };
        let object = self.scripts[i].object;
        let s = &mut self.scripts[i];
        s.env = env.clone();
        s.state = ScriptState::Running;
        s.actuation = None;
        s.sensing = None;
        s.vision = None;
        s.initialised = false;
        // A reloaded threaded script starts its thread afresh, in the default mode.
        s.thread = None;
        if let Some(m) = self.shared.thread_modes.borrow_mut().get_mut(i) {
            *m = ThreadMode::default();
        }
        for e in self.shared.envs.borrow_mut().iter_mut() {
            if e.0 == object && e.2 == name {
                e.1 = env.clone();
            }
        }
        let r = self.exec_chunk(i, &source);
        if let Err(e) = r {
            self.fail(i, e);
            return;
        }
        self.register_with_debugger(i, &source);
        self.model.scripts[i].source = source;
        self.log(450, &name, "reloaded");
        if was_running && self.state() != SimulationState::Stopped {
            self.scripts[i].initialised = true;
            self.call_hook(i, Hook::Init);
            if self.scripts[i].state == ScriptState::Running {
                self.cache_hooks(i);
            }
        }
    }

    fn log(&self, verbosity: i64, source: &str, msg: &str) {
        let w = &mut self.shared.sim.borrow_mut().world;
        let t = w.time();
        w.log.push(t, verbosity, source, msg);
    }

    /// Calls a named global function of the scripts attached to `object` (or of every
    /// script, for `None`) with `args`; returns the first script's results. Used by the
    /// transports for hooks such as `sysCall_packet`.
    ///
    /// Returns `Ok(None)` when no script defines the function.
    ///
    /// # Errors
    /// The function raised an error (the script is then marked errored).
    pub fn call_hook_function(&mut self, function: &str, args: &[Value]) -> Result<Option<Vec<Value>>, String> {
        for k in 0..self.order.len() {
            let i = self.order[k];
            if self.scripts[i].state != ScriptState::Running {
                continue;
            }
            let Ok(Some(f)) = self.scripts[i].env.raw_get::<Option<Function>>(function) else {
                continue;
            };
            let lua_args = to_multi(&self.lua, args).map_err(|e| e.to_string())?;
            self.enter(i, Cow::Owned(function.to_owned()));
            let r = self.call_script::<MultiValue>(&f, lua_args);
            self.leave();
            let out = match r {
                Ok(values) => values
                    .iter()
                    .map(to_value)
                    .collect::<mlua::Result<Vec<_>>>()
                    .map(Some)
                    .map_err(|e| e.to_string()),
                Err(e) => {
                    let text = error_text(&e);
                    self.fail(i, e);
                    Err(text)
                }
            };
            self.apply_control();
            return out;
        }
        Ok(None)
    }
}

/// Children's scripts before their parents' (post-order over the tree), siblings in
/// hierarchy order; several scripts on one object keep their scene order.
fn hook_order(world: &World, scripts: &[Script]) -> Vec<usize> {
    use gantry_sim_core::world::object_path::ObjectTree;
    let mut post = Vec::new();
    let mut stack: Vec<(Handle, bool)> = world.roots().iter().rev().map(|&h| (h, false)).collect();
    while let Some((h, visited)) = stack.pop() {
        if visited {
            post.push(h);
        } else {
            stack.push((h, true));
            stack.extend(world.children(h).iter().rev().map(|&c| (c, false)));
        }
    }
    let mut order = Vec::new();
    for h in post {
        order.extend(
            scripts
                .iter()
                .enumerate()
                .filter(|(_, s)| s.object == h)
                .map(|(i, _)| i),
        );
    }
    order
}

/// The message of a Lua error with its traceback, without mlua's wrapping noise.
pub(crate) fn error_text(e: &mlua::Error) -> String {
    match e {
        mlua::Error::CallbackError { traceback, cause } => {
            format!("{}\n{traceback}", error_text(cause))
        }
        mlua::Error::RuntimeError(m) | mlua::Error::SyntaxError { message: m, .. } => m.clone(),
        mlua::Error::MemoryError(m) => format!("out of memory: {m}"),
        other => other.to_string(),
    }
}

fn display(v: &LuaValue) -> String {
    match v {
        LuaValue::Nil => "nil".into(),
        LuaValue::Boolean(b) => b.to_string(),
        LuaValue::Integer(i) => i.to_string(),
        LuaValue::Number(n) => n.to_string(),
        LuaValue::String(s) => s.to_string_lossy(),
        other => format!("{}: {:?}", other.type_name(), other.to_pointer()),
    }
}

/// Interrupts any Lua code that runs past the current deadline.
///
/// Once interrupted, a script stays interrupted until the hook call returns: `pcall`,
/// `xpcall` and `coroutine.resume` re-raise the interrupt, so a loop that catches errors
/// cannot defeat the budget.
fn install_budget(lua: &Lua, shared: &Rc<Shared>, budget: Duration) -> mlua::Result<()> {
    let hook_shared = shared.clone();
    // A global hook: mlua gives it to every thread it creates, and Lua copies it into
    // the coroutines scripts create, so no coroutine escapes the budget.
    // With the debugger, the same hook also sees every new line (see `debugger`).
    let triggers = match shared.debugger {
        Some(_) => HookTriggers::new().every_nth_instruction(4096).every_line(),
        None => HookTriggers::new().every_nth_instruction(4096),
    };
    lua.set_global_hook(triggers, move |lua, debug| {
        if debug.event() == mlua::debug::DebugEvent::Line {
            return match &hook_shared.debugger {
                Some(d) => d.on_line(lua, debug, &hook_shared),
                None => Ok(VmState::Continue),
            };
        }
        let now = Instant::now();
        if hook_shared.interrupted.get() || now > hook_shared.deadline.get() {
            hook_shared.interrupted.set(true);
            let src = debug.source();
            let place = match (src.short_src.as_deref(), debug.current_line()) {
                (Some(file), Some(line)) => format!("{file}:{line}: "),
                _ => String::new(),
            };
            let msg = format!(
                "{place}script interrupted: it ran past its time budget of {budget:?} (an infinite loop in a hook?)"
            );
            // Errors raised by a hook carry no traceback of their own; add one so the
            // loop can be found like any other runtime error.
            let traceback = lua.traceback(Some(&msg), 0).map(|s| s.to_string_lossy()).unwrap_or(msg);
            Err(mlua::Error::runtime(traceback))
        } else if hook_shared.preemption_due(lua, now) {
            // Yields only the script's thread itself, and only at a point where Lua
            // can yield (mlua checks; where it cannot, the thread runs on and the
            // budget above still applies). It is resumed at the next step.
            Ok(VmState::Yield)
        } else {
            Ok(VmState::Continue)
        }
    })?;
    let flag = shared.clone();
    let interrupted = lua.create_function(move |_, ()| Ok(flag.interrupted.get()))?;
    lua.load(
        r#"
        local interrupted, rawpcall, rawxpcall, rawresume, error = ...
        local function check(...)
            if interrupted() then error("script interrupted: it ran past its time budget", 0) end
            return ...
        end
        pcall = function(...) return check(rawpcall(...)) end
        xpcall = function(...) return check(rawxpcall(...)) end
        coroutine.resume = function(...) return check(rawresume(...)) end
        "#,
    )
    .set_name("@gantry/budget.lua")
    .call::<()>((
        interrupted,
        lua.globals().get::<Function>("pcall")?,
        lua.globals().get::<Function>("xpcall")?,
        lua.globals().get::<Table>("coroutine")?.get::<Function>("resume")?,
        lua.globals().get::<Function>("error")?,
    ))
}

/// The protected call scripts run in under the debugger: `call(f, ...)` runs `f` with
/// a message handler that lets the debugger stop at an uncaught error while the failing
/// frame is still on the stack, then raises the error on as if nothing had been there.
fn install_debugger(lua: &Lua, shared: &Rc<Shared>) -> mlua::Result<Function> {
    let hook_shared = shared.clone();
    let on_error = lua.create_function(move |lua, message: LuaValue| {
        if let Some(d) = &hook_shared.debugger {
            d.on_error(lua, &message, &hook_shared);
        }
        Ok(message)
    })?;
    lua.load(
        r#"
        local xpcall, error, on_error = ...
        local function finish(ok, ...)
            if ok then return ... end
            error((...), 0)
        end
        return function(f, ...) return finish(xpcall(f, on_error, ...)) end
        "#,
    )
    .set_name("@gantry/debug_call.lua")
    .call((
        lua.globals().get::<Function>("xpcall")?,
        lua.globals().get::<Function>("error")?,
        on_error,
    ))
}

/// Creates the API's global tables (`sim`, and `simIK`, `simUI`, `simVision` as they
/// exist): every function of [`api::MODULES`] plus constants.
fn install_api(lua: &Lua, shared: &Rc<Shared>) -> mlua::Result<()> {
    // CoppeliaSim raises API errors as plain strings prefixed with the caller's
    // position, which scripts concatenate and match on. An error raised from Rust would
    // reach Lua as userdata, so each function reports failure as a value and this
    // wrapper raises it with `error(msg, 2)` from the caller's point of view.
    let wrap: Function = lua
        .load(
            r#"
            local error = ...
            local function finish(ok, ...)
                if ok then return ... end
                error((...), 3)
            end
            return function(f) return function(...) return finish(f(...)) end end
            "#,
        )
        .set_name("@gantry/api.lua")
        .call(lua.globals().get::<Function>("error")?)?;
    let mut sim = None;
    for module in api::MODULES {
        let table = lua.create_table()?;
        for (name, f) in module.callable() {
            let shared = shared.clone();
            let f = *f;
            let qualified = format!("{}.{name}", module.name);
            let func = lua.create_function(move |lua, args: MultiValue| {
                // This runs for every API call a script makes, often dozens per step: no
                // heap allocation for the usual handful of arguments, and the caller's
                // name is borrowed, not copied (API functions never call back into Lua).
                let values = args
                    .iter()
                    .map(to_value)
                    .collect::<mlua::Result<SmallVec<[Value; 4]>>>()?;
                let source = shared.current_name.borrow();
                let ctx = CallContext {
                    script_object: shared.current.get(),
                    source: &source,
                };
                let result = {
                    let mut sim = shared
                        .sim
                        .try_borrow_mut()
                        .map_err(|_| mlua::Error::runtime(format!("the world is busy (in function '{qualified}')")))?;
                    f.invoke(&mut sim, &ctx, &Args::new(&values))
                };
                // The Lua wrapper turns (false, message) into a Lua string error.
                match result {
                    Ok(ret) => {
                        let mut out = MultiValue::with_capacity(ret.len() + 1);
                        out.push_back(LuaValue::Boolean(true));
                        for v in ret.iter() {
                            out.push_back(to_lua(lua, v)?);
                        }
                        Ok(out)
                    }
                    Err(e) => Ok(MultiValue::from_iter([
                        LuaValue::Boolean(false),
                        LuaValue::String(lua.create_string(e.in_function(&qualified))?),
                    ])),
                }
            })?;
            table.set(name, wrap.call::<Function>(func)?)?;
        }
        for (name, value) in module.constants {
            table.set(*name, *value)?;
        }
        lua.globals().set(module.name, table.clone())?;
        if module.name == "sim" {
            sim = Some(table);
        }
    }
    let sim = sim.ok_or_else(|| mlua::Error::runtime("the API has no sim module"))?;
    let run_shared = shared.clone();
    let remote_api = listeners::install(
        lua,
        &shared.listeners,
        Rc::new(move || {
            run_shared
                .sim
                .try_borrow()
                .map(|s| s.state != SimulationState::Stopped)
                .unwrap_or(true)
        }),
        &wrap,
    )?;
    lua.globals().set("simRemoteApi", remote_api)?;
    let cs_shared = shared.clone();
    sim.set(
        "callScriptFunction",
        lua.create_function(move |lua, args: MultiValue| {
            let values = args.iter().map(to_value).collect::<mlua::Result<Vec<_>>>()?;
            match call_script_function(lua, &cs_shared, &values) {
                Ok(ret) => {
                    let mut out = to_multi(lua, &ret)?;
                    out.push_front(LuaValue::Boolean(true));
                    Ok(out)
                }
                Err(e) => Ok(MultiValue::from_iter([
                    LuaValue::Boolean(false),
                    LuaValue::String(
                        lua.create_string(format!("{} (in function 'sim.callScriptFunction')", error_text(&e)))?,
                    ),
                ])),
            }
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )?;
    // A script's handle is the handle of the object it is attached to.
    let gs_shared = shared.clone();
    sim.set(
        "getScript",
        lua.create_function(move |lua, args: MultiValue| {
            let values = args.iter().map(to_value).collect::<mlua::Result<Vec<_>>>()?;
            Ok(match script_handle(&gs_shared, &values) {
                Ok(h) => (true, LuaValue::Integer(h)),
                Err(e) => (
                    false,
                    LuaValue::String(lua.create_string(format!("{e} (in function 'sim.getScript')"))?),
                ),
            })
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )?;
    // Delivered at once to the other scripts' sysCall_msg (see `crate::messages`).
    let bm_shared = shared.clone();
    sim.set(
        "broadcastMsg",
        lua.create_function(move |lua, args: MultiValue| {
            Ok(match messages::broadcast(lua, &bm_shared, &args) {
                Ok(()) => (true, LuaValue::Nil),
                Err(e) => (
                    false,
                    LuaValue::String(lua.create_string(format!("{e} (in function 'sim.broadcastMsg')"))?),
                ),
            })
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )?;
    // A model's objects join the world at once (the handle is returned); its scripts
    // load when the calling hook has returned. Scripts read model files inside the
    // scene's folder only, as they write exports there.
    let lm_shared = shared.clone();
    sim.set(
        "loadModel",
        lua.create_function(move |lua, path: LuaValue| {
            let loaded = match &path {
                LuaValue::String(p) => load_model_into(&lm_shared, std::path::Path::new(&*p.to_str()?), true),
                other => Err(format!(
                    "argument 1: expected the model file's path as a string, got {}",
                    other.type_name()
                )),
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
    )?;
    // Removal waits for the calling hook to return (a script may remove itself and go
    // on, as CoppeliaSim's does, until its function ends).
    let rs_shared = shared.clone();
    sim.set(
        "removeScript",
        lua.create_function(move |lua, h: LuaValue| {
            let handle = match &h {
                LuaValue::Integer(i) => Some(*i),
                LuaValue::Number(n) if n.fract() == 0.0 => Some(*n as i64),
                _ => None,
            };
            // The calling script itself, even when its object carries several scripts.
            let index = match handle {
                Some(HANDLE_SELF) => rs_shared.current_script.get(),
                Some(h) => script_index(&rs_shared, h),
                None => None,
            };
            Ok(match index {
                Some(i) => {
                    rs_shared.removals.borrow_mut().push(i);
                    (true, LuaValue::Nil)
                }
                None => (
                    false,
                    LuaValue::String(lua.create_string(match handle {
                        Some(h) => format!("argument 1: no script has handle {h} (in function 'sim.removeScript')"),
                        None => format!(
                            "argument 1: expected a script handle, got {} (in function 'sim.removeScript')",
                            h.type_name()
                        ),
                    })?),
                ),
            })
        })
        .and_then(|f| wrap.call::<Function>(f))?,
    )?;
    // CoppeliaSim 4.0-4.2: the script attached to an object, -1 when none.
    let sa_shared = shared.clone();
    sim.set(
        "getScriptAssociatedWithObject",
        lua.create_function(move |_, object: LuaValue| {
            let object = to_value(&object)?;
            Ok(script_handle(&sa_shared, &[Value::Int(1), object]).unwrap_or(-1))
        })?,
    )?;
    for (name, control) in [
        ("startSimulation", Control::Start),
        ("pauseSimulation", Control::Pause),
        ("stopSimulation", Control::Stop),
    ] {
        let shared = shared.clone();
        sim.set(
            name,
            lua.create_function(move |_, ()| {
                shared.control.set(Some(control));
                // Scripts see the request in `sim.getSimulationState` for the rest of
                // the step, as CoppeliaSim's "last before pause" / "about to stop".
                if let Ok(mut w) = shared.sim.try_borrow_mut()
                    && w.state == SimulationState::Running
                {
                    match control {
                        Control::Pause => w.advancing = Advancing::LastBeforePause,
                        Control::Stop => w.advancing = Advancing::AboutToStop,
                        Control::Start => {}
                    }
                }
                Ok(())
            })?,
        )?;
    }
    threads::install(lua, shared, &sim)
}

/// `sim.getScript(scriptType, object = -1)`: the handle of the script attached to
/// `object` (a handle or a path), which in gantry is the object's handle, or -1 when
/// it has no script; `sim.getScript(sim.handle_self)` is the calling script's.
/// `sim.handle_self`.
const HANDLE_SELF: i64 = -4;
/// The object of a removed script's environment entry: no handle matches it.
pub(crate) const REMOVED_SCRIPT: Handle = i64::MIN;

/// The index of the script whose handle (its object's) is `h`.
fn script_index(shared: &Shared, h: Handle) -> Option<usize> {
    if h == REMOVED_SCRIPT {
        return None;
    }
    shared.envs.borrow().iter().position(|(o, _, _)| *o == h)
}

fn script_handle(shared: &Shared, args: &[Value]) -> Result<i64, String> {
    let kind = args
        .first()
        .and_then(Value::as_i64)
        .ok_or("argument 1: expected integer (a script type or sim.handle_self)")?;
    if kind == HANDLE_SELF {
        return shared
            .current
            .get()
            .ok_or_else(|| "sim.handle_self names the calling script, and a remote client has none".to_owned());
    }
    let object = match args.get(1) {
        None | Some(Value::Nil) => return Ok(-1),
        Some(Value::Str(path)) => {
            let ctx = CallContext {
                script_object: shared.current.get(),
                source: "getScript",
            };
            let mut world = shared
                .sim
                .try_borrow_mut()
                .map_err(|_| "the world is busy".to_owned())?;
            let found = api::call(&mut world, &ctx, "getObject", &[Value::Str(path.clone())]).map_err(|e| match e {
                CallError::Failed { error, .. } => error.message,
                other => other.to_string(),
            })?;
            found.first().and_then(Value::as_i64).unwrap_or(-1)
        }
        Some(v) => v.as_i64().ok_or("argument 2: expected an object handle or path")?,
    };
    let attached = shared.envs.borrow().iter().any(|(h, _, _)| *h == object);
    Ok(if attached { object } else { -1 })
}

/// `sim.callScriptFunction(name, scriptHandle, ...)`: calls a global function of the
/// script attached to object `scriptHandle` (also accepts CoppeliaSim's `name@alias`).
fn call_script_function(lua: &Lua, shared: &Rc<Shared>, args: &[Value]) -> mlua::Result<Vec<Value>> {
    let name = match args.first() {
        Some(Value::Str(s)) => s.split('@').next().unwrap_or_default().to_owned(),
        _ => {
            return Err(mlua::Error::runtime("argument 1: expected string (the function name)"));
        }
    };
    let target = args
        .get(1)
        .and_then(Value::as_i64)
        .ok_or_else(|| mlua::Error::runtime("argument 2: expected a script handle"))?;
    let env = shared
        .envs
        .borrow()
        .iter()
        .find(|(h, _, _)| *h == target)
        .map(|(h, env, n)| (*h, env.clone(), n.clone()));
    let Some((object, env, script_name)) = env else {
        return Err(mlua::Error::runtime(format!(
            "no script is attached to object {target}"
        )));
    };
    let f: Function = match env.raw_get::<LuaValue>(name.as_str())? {
        LuaValue::Function(f) => f,
        _ => {
            return Err(mlua::Error::runtime(format!(
                "script {script_name} has no function '{name}'"
            )));
        }
    };
    let call_args = to_multi(lua, &args[2.min(args.len())..])?;
    let (prev, prev_name) = (shared.current.get(), shared.current_name.borrow().clone());
    shared.current.set(Some(object));
    *shared.current_name.borrow_mut() = script_name;
    let r = f.call::<MultiValue>(call_args);
    shared.current.set(prev);
    *shared.current_name.borrow_mut() = prev_name;
    r?.iter().map(to_value).collect()
}

/// Compiles every script of a scene without running it, for `gantry check`.
/// Returns one message per script that does not compile, with file and line.
pub fn check_syntax(model: &SceneModel) -> Vec<String> {
    let Ok(lua) = new_state(ScriptLimits::default()) else {
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

/// A model `sim.loadModel` put into the world, waiting for its scripts to load.
pub(crate) struct LoadedModel {
    /// The model file as loaded.
    model: SceneModel,
    /// The world handle of each of its objects.
    handles: Vec<Handle>,
}

/// Reads the model file `path` and adds its objects to the world; returns the model
/// base's handle. `confined`: only inside the scene's folder (for scripts).
fn load_model_into(shared: &Shared, path: &std::path::Path, confined: bool) -> Result<Handle, String> {
    let path = if confined {
        shared
            .sim
            .borrow()
            .graphs
            .export_scope()
            .resolve(path)
            .map_err(|e| match e {
                gantry_sim_core::graph::ExportDenied::NoFolder => {
                    "this scene has no folder on disk (it is embedded in gantry), so its scripts cannot load model files".to_owned()
                }
                _ => format!(
                    "{}: scripts load model files only from inside the scene's folder (give a path relative to the scene)",
                    path.display()
                ),
            })?
    } else {
        path.to_owned()
    };
    let options = shared.load_options.borrow().clone();
    let model = load_model(&DiskFiles, &path, &options).map_err(|e| e.to_string())?;
    let (handles, warnings) = shared
        .sim
        .try_borrow_mut()
        .map_err(|_| "the world is busy".to_owned())?
        .world
        .import_model(&model);
    // The model's own warnings (unknown keys, URDF features) and the building's.
    for w in warnings {
        tracing::warn!("{w}");
    }
    let base = *handles
        .first()
        .ok_or_else(|| format!("{}: the model has no objects", path.display()))?;
    shared.loaded_models.borrow_mut().push(LoadedModel { model, handles });
    Ok(base)
}
