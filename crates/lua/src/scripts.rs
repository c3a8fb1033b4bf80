//! The scene's scripts: each one's state (its environment, cached hooks, thread, error),
//! loading and hot reloading, and calling one hook of one script, or of all in hook
//! order. What other roles need to know about a script lives with them: its entry in
//! the [`Directory`], its thread mode in [`Threads`], its message receiver in
//! [`Mailboxes`].

use std::borrow::Cow;
use std::path::PathBuf;
use std::rc::Rc;
use std::time::SystemTime;

use gantry_sim_core::Handle;
use gantry_sim_core::graph::ExportScope;
use gantry_sim_core::scene::ScriptModel;
use gantry_sim_core::world::object_path::object_alias;
use mlua::thread::ThreadStatus;
use mlua::{Function, Lua, MultiValue, Table, Thread, Value as LuaValue};

use crate::app_state::state;
use crate::debugger::DebugHost;
use crate::directory::{Directory, Entry};
use crate::file_rules::{FileRoots, Folders};
use crate::hooks::{Hook, HookCaller, SUPPORTED_HOOKS, hook_order};
use crate::lua_error::error_text;
use crate::luasocket::Sockets;
use crate::messages::Mailboxes;
use crate::running::Running;
use crate::sandbox::{self, SOURCE_MODE};
use crate::sim_cell::SimCell;
use crate::threads::Threads;

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
pub(crate) struct Script {
    pub(crate) object: Handle,
    /// Short name for logs: the file name.
    pub(crate) name: Rc<str>,
    pub(crate) path: PathBuf,
    pub(crate) modified: Option<SystemTime>,
    pub(crate) env: Table,
    /// Cached hooks, so a script that defines none costs nothing per step.
    pub(crate) actuation: Option<Function>,
    pub(crate) sensing: Option<Function>,
    /// `sysCall_vision`, called after the script's vision sensor renders.
    pub(crate) vision: Option<Function>,
    pub(crate) state: ScriptState,
    pub(crate) initialised: bool,
    /// The coroutine running `sysCall_thread` (or `sysCall_threadmain`), from
    /// initialisation until it returns or fails (see [`crate::threads`]).
    pub(crate) thread: Option<Thread>,
}

/// Every script of the scene, by index (aligned with the scene model's scripts).
pub(crate) struct ScriptSet {
    lua: Lua,
    core: SimCell,
    caller: HookCaller,
    pub(crate) list: Vec<Script>,
    /// Script indices in hook order: children's scripts before their parents'.
    pub(crate) order: Vec<usize>,
    /// Modification time of each script file as last loaded, so a stop/start keeps a
    /// hot-reloaded version instead of reloading it again.
    mtimes: Vec<Option<SystemTime>>,
}

impl ScriptSet {
    /// No scripts yet; they call into Lua through `caller`.
    pub(crate) fn new(lua: Lua, core: SimCell, caller: HookCaller) -> Self {
        Self {
            lua,
            core,
            caller,
            list: Vec::new(),
            order: Vec::new(),
            mtimes: Vec::new(),
        }
    }

    /// (Re)loads every script of the scene and runs its chunk.
    pub(crate) fn load_all(&mut self, scripts: &[ScriptModel]) {
        if let Some(d) = self.lua.app_data_ref::<DebugHost>() {
            d.clear_scripts();
        }
        self.list.clear();
        state::<Directory>(&self.lua).clear();
        state::<Mailboxes>(&self.lua).clear();
        state::<Threads>(&self.lua).reset(scripts.len());
        for (index, s) in scripts.iter().enumerate() {
            self.load_one(index, s, s.object as Handle);
        }
        self.mtimes = self.list.iter().map(|s| s.modified).collect();
        self.reorder();
        for i in 0..self.list.len() {
            self.warn_unsupported_hooks(i);
        }
    }

    /// Adds script `index` of the model (`s`, loaded with a model during the run),
    /// attached to the live object `object`.
    pub(crate) fn append(&mut self, index: usize, s: &ScriptModel, object: Handle) {
        state::<Threads>(&self.lua).push();
        self.load_one(index, s, object);
        self.mtimes.push(self.list[index].modified);
        self.warn_unsupported_hooks(index);
    }

    /// Puts the scripts back in hook order (after objects or scripts were added).
    pub(crate) fn reorder(&mut self) {
        let objects: Vec<Handle> = self.list.iter().map(|s| s.object).collect();
        self.order = hook_order(&self.core.borrow().world, &objects);
    }

    /// Loads script `index` of the model (`s`), attached to `object` in the world, and
    /// runs its chunk; a failure marks it errored, keeping indices aligned with the model.
    fn load_one(&mut self, index: usize, s: &ScriptModel, object: Handle) {
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
        state::<Directory>(&self.lua).push(Entry {
            object,
            env: env.clone(),
            name: name.clone(),
        });
        state::<Mailboxes>(&self.lua).push();
        self.list.push(Script {
            object,
            name,
            path: s.path.clone(),
            modified,
            env,
            actuation: None,
            sensing: None,
            vision: None,
            state: ScriptState::Running,
            initialised: false,
            thread: None,
        });
        self.register_with_debugger(index, &s.source);
        if crate::ros::lua_api::uses_ros1(&s.source) {
            crate::ros::lua_api::notice_ros1(&self.lua);
        }
        if let Some(e) = env_error {
            self.fail(index, e);
        } else if let Err(e) = self.exec_chunk(index, &s.source) {
            self.fail(index, e);
        }
    }

    fn make_env(&self, name: &Rc<str>) -> mlua::Result<Table> {
        // Private copies of the global tables: see `sandbox::script_env`.
        let env = sandbox::script_env(&self.lua)?;
        // `print` logs with the script's name (CoppeliaSim prints to its status bar).
        let source = name.clone();
        let print = self.lua.create_function(move |lua, args: MultiValue| {
            let text: Vec<String> = args.iter().map(display).collect();
            state::<SimCell>(lua).log(450, &source, &text.join("\t"));
            Ok(())
        })?;
        env.set("print", print)?;
        let folders = Rc::new(self.folders());
        sandbox::add_require(&self.lua, &env, crate::modules::finder(&self.lua, folders.clone())?)?;
        crate::script_io::add_io(&self.lua, &env, folders)?;
        sandbox::add_vrep3_names(&self.lua, &env)?;
        Ok(env)
    }

    /// The folders a script may reach (modules and files): the scene's folder, unless
    /// the scene is embedded in gantry, and the user's `--lua-path`/`--allow-files`.
    fn folders(&self) -> Folders {
        let scene = match self.core.borrow().graphs.export_scope() {
            ExportScope::Within(dir) => Some(dir.clone()),
            ExportScope::Anywhere | ExportScope::Nowhere => None,
        };
        let roots = state::<FileRoots>(&self.lua);
        Folders {
            scene,
            lua_path: roots.lua_path.clone(),
            writable: roots.allow_files.clone(),
        }
    }

    fn exec_chunk(&self, i: usize, source: &str) -> mlua::Result<()> {
        self.enter(i, Cow::Borrowed("main chunk"));
        let script = &self.list[i];
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

    /// Script `i` runs `hook` from now on (see [`Running::enter`]).
    pub(crate) fn enter(&self, i: usize, hook: Cow<'static, str>) {
        let script = &self.list[i];
        state::<Running>(&self.lua).enter(script.object, i, script.name.clone(), hook);
    }

    /// The host's call into a script returned.
    pub(crate) fn leave(&self) {
        state::<Running>(&self.lua).leave();
    }

    /// Calls a script function (see [`HookCaller::call`]).
    pub(crate) fn call_script<R: mlua::FromLuaMulti>(
        &self,
        f: &Function,
        args: impl mlua::IntoLuaMulti,
    ) -> mlua::Result<R> {
        self.caller.call(f, args)
    }

    /// Tells the debugger (if any) about script `i` and its source.
    fn register_with_debugger(&self, i: usize, source: &str) {
        let Some(d) = self.lua.app_data_ref::<DebugHost>() else {
            return;
        };
        let script = &self.list[i];
        let object_path = object_alias(&self.core.borrow().world, script.object, 2);
        d.register_script(i, &script.path, object_path, source);
    }

    /// Marks script `i` errored after `e`: it receives no more hooks but cleanup, and
    /// its thread, if any, is not resumed again.
    pub(crate) fn fail(&mut self, i: usize, e: mlua::Error) {
        let msg = error_text(&e);
        let script = &mut self.list[i];
        self.core.log(
            200,
            &script.name,
            &format!("script error; it will receive no more hooks: {msg}"),
        );
        script.state = ScriptState::Errored(msg);
        script.actuation = None;
        script.sensing = None;
        script.vision = None;
        script.thread = None;
        state::<Mailboxes>(&self.lua).set_receiver(i, None);
    }

    /// Calls one hook of one script, if it defines it and has not errored.
    pub(crate) fn call_hook(&mut self, i: usize, hook: Hook) {
        let script = &self.list[i];
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

    /// Calls `hook` of every script that has not errored, in hook order.
    pub(crate) fn call_hook_everywhere(&mut self, hook: Hook) {
        for k in 0..self.order.len() {
            let i = self.order[k];
            self.call_hook(i, hook);
        }
    }

    /// `sysCall_init` of script `i`, then its other hooks are looked up once.
    pub(crate) fn initialise(&mut self, i: usize) {
        self.list[i].initialised = true;
        self.call_hook(i, Hook::Init);
        if self.list[i].state == ScriptState::Running {
            self.cache_hooks(i);
        }
    }

    /// `sysCall_cleanup` of script `i` if it was initialised; it receives no messages.
    pub(crate) fn clean_up(&mut self, i: usize) {
        if self.list[i].initialised {
            self.call_hook(i, Hook::Cleanup);
            self.list[i].initialised = false;
            state::<Mailboxes>(&self.lua).set_receiver(i, None);
        }
    }

    fn cache_hooks(&mut self, i: usize) {
        let s = &mut self.list[i];
        s.actuation = s.env.raw_get::<Option<Function>>(Hook::Actuation.name()).ok().flatten();
        s.sensing = s.env.raw_get::<Option<Function>>(Hook::Sensing.name()).ok().flatten();
        s.vision = s.env.raw_get::<Option<Function>>("sysCall_vision").ok().flatten();
        let msg = s.env.raw_get::<Option<Function>>("sysCall_msg").ok().flatten();
        state::<Mailboxes>(&self.lua).set_receiver(i, msg);
        let s = &mut self.list[i];
        // 4.6+ names the thread's body sysCall_thread; 4.0-4.2 threaded child scripts,
        // sysCall_threadmain. The coroutine first runs at the next step's actuation.
        let body = ["sysCall_thread", "sysCall_threadmain"]
            .iter()
            .find_map(|name| s.env.raw_get::<Option<Function>>(*name).ok().flatten());
        s.thread = None;
        if let Some(body) = body {
            match self.caller.thread_body(body).and_then(|b| self.lua.create_thread(b)) {
                Ok(t) => self.list[i].thread = Some(t),
                Err(e) => self.fail(i, e),
            }
        }
    }

    /// Resumes every script thread once, in hook order (see [`crate::threads`]).
    pub(crate) fn resume_threads(&mut self) {
        for k in 0..self.order.len() {
            let i = self.order[k];
            let Some(thread) = self.list[i].thread.clone() else {
                continue;
            };
            self.enter(i, Cow::Borrowed("sysCall_thread"));
            let r = state::<Threads>(&self.lua).resume(i, &thread);
            self.leave();
            match r {
                Ok(()) if thread.status() == ThreadStatus::Resumable => {}
                // The body returned: the thread has ended, the script's hooks go on.
                Ok(()) => self.list[i].thread = None,
                Err(e) => self.fail(i, e),
            }
        }
    }

    /// `sim.removeScript`: script `i`'s cleanup runs (if it was initialised), then it
    /// receives nothing more and no longer answers `sim.getScript`.
    pub(crate) fn remove(&mut self, i: usize) {
        self.remove_because(i, "script removed (sim.removeScript)");
    }

    /// Whether script `i`'s object is gone from the scene (removed while the simulation
    /// was stopped: CoppeliaSim removes an object's scripts with it).
    pub(crate) fn object_gone(&self, i: usize) -> bool {
        self.list
            .get(i)
            .is_some_and(|s| self.core.borrow().world.object(s.object).is_err())
    }

    /// Removes script `i` as [`ScriptSet::remove`] does, logging `why`.
    pub(crate) fn remove_because(&mut self, i: usize, why: &str) {
        if i >= self.list.len() || self.list[i].state == ScriptState::Removed {
            return;
        }
        if self.list[i].initialised {
            self.call_hook(i, Hook::Cleanup);
            self.list[i].initialised = false;
        }
        let s = &mut self.list[i];
        s.state = ScriptState::Removed;
        s.actuation = None;
        s.sensing = None;
        s.vision = None;
        s.thread = None;
        state::<Mailboxes>(&self.lua).set_receiver(i, None);
        state::<Directory>(&self.lua).mark_removed(i);
        state::<Sockets>(&self.lua).close_owned_by(i);
        let name = self.list[i].name.clone();
        self.core.log(400, &name, why);
    }

    /// What scripts asked for while running, now that none runs: receivers whose
    /// `sysCall_msg` failed are marked errored, and removals are carried out.
    pub(crate) fn settle(&mut self) {
        let failures = state::<Mailboxes>(&self.lua).take_failures();
        for (i, e) in failures {
            if self.list.get(i).is_some_and(|s| s.state == ScriptState::Running) {
                self.fail(i, e);
            }
        }
        let removals = state::<Directory>(&self.lua).take_removals();
        for i in removals {
            self.remove(i);
        }
    }

    /// Names, once per load, the `sysCall_*` functions of script `i` that gantry never
    /// calls (CoppeliaSim's add-on and editor callbacks, `sysCall_contactCallback`, ...).
    fn warn_unsupported_hooks(&self, i: usize) {
        let script = &self.list[i];
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
        self.core.log(300, &script.name.clone(), &msg);
    }

    /// The scripts whose files changed on disk since they were loaded, with their new
    /// modification times recorded (a removed script stays removed until a stop).
    pub(crate) fn changed_on_disk(&mut self) -> Vec<usize> {
        let mut changed = Vec::new();
        for i in 0..self.list.len() {
            let modified = std::fs::metadata(&self.list[i].path).and_then(|m| m.modified()).ok();
            if modified.is_none() || modified == self.list[i].modified || self.list[i].state == ScriptState::Removed {
                continue;
            }
            self.list[i].modified = modified;
            if let Some(m) = self.mtimes.get_mut(i) {
                *m = modified;
            }
            changed.push(i);
        }
        changed
    }

    /// Reloads script `i` from its file: the old script's cleanup runs, then the new one
    /// loads, and initialises if the old one was and `running`. Returns the new source,
    /// or `None` when the old version keeps running (the reason is logged).
    pub(crate) fn reload(&mut self, i: usize, running: bool) -> Option<String> {
        let script = self.list.get(i)?;
        let (path, name) = (script.path.clone(), script.name.clone());
        let source = match std::fs::read_to_string(&path) {
            Ok(s) => s,
            Err(e) => {
                self.core.log(
                    200,
                    &name,
                    &format!(
                        "reload failed, keeping the running version: cannot read {}: {e}",
                        path.display()
                    ),
                );
                return None;
            }
        };
        if let Err(e) = self
            .lua
            .load(&source)
            .set_name(format!("@{}", path.display()))
            .set_mode(SOURCE_MODE)
            .into_function()
        {
            self.core.log(
                200,
                &name,
                &format!("reload failed, keeping the running version: {}", error_text(&e)),
            );
            return None;
        }
        let was_running = self.list[i].initialised;
        if was_running {
            self.call_hook(i, Hook::Cleanup);
        }
        state::<Mailboxes>(&self.lua).set_receiver(i, None);
        // The new version binds its ports again.
        state::<Sockets>(&self.lua).close_owned_by(i);
        let env = match self.make_env(&name) {
            Ok(e) => e,
            Err(e) => {
                self.core.log(200, &name, &format!("reload failed: {e}"));
                return None;
            }
        };
        let object = self.list[i].object;
        let s = &mut self.list[i];
        s.env = env.clone();
        s.state = ScriptState::Running;
        s.actuation = None;
        s.sensing = None;
        s.vision = None;
        s.initialised = false;
        // A reloaded threaded script starts its thread afresh, in the default mode.
        s.thread = None;
        state::<Threads>(&self.lua).reset_mode(i);
        state::<Directory>(&self.lua).replace_env(object, &name, &env);
        if let Err(e) = self.exec_chunk(i, &source) {
            self.fail(i, e);
            return None;
        }
        self.register_with_debugger(i, &source);
        self.core.log(450, &name, "reloaded");
        if was_running && running {
            self.initialise(i);
        }
        Some(source)
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
