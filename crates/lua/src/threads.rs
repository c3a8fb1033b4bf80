//! Threaded scripts: `sysCall_thread` (CoppeliaSim 4.6+) and `sysCall_threadmain`
//! (4.0-4.2), run as Lua coroutines on the one simulation thread.
//!
//! The simulation resumes each script's coroutine once per step, at the start of
//! actuation (before the non-threaded `sysCall_actuation` hooks), as CoppeliaSim does.
//! A coroutine gives control back in one of three ways:
//! * a blocking call (`sim.step`, `sim.switchThread`, `sim.wait`, `sim.waitForSignal`,
//!   and what is built on them such as `sim.moveToConfig`) yields; these are written
//!   in Lua (`lua/threads.lua`) because only Lua code can yield across itself here;
//! * in the default, non-stepping mode, the time-budget hook yields it once it has run
//!   for the auto-yield delay (2 ms, `sim.setAutoYieldDelay`), as CoppeliaSim pre-empts
//!   its threads; `sim.setStepping(true)`, `sim.setThreadAutomaticSwitch(false)` and
//!   `sim.acquireLock()` turn that off (each is a level: calls nest);
//! * it returns (the thread has ended; the script keeps its other hooks) or raises an
//!   error (the script is marked errored, like an error in any hook).
//!
//! Each resumption is one hook call for the time budget: 1 s of running without
//! yielding, in stepping mode, interrupts the script.
//!
//! No OS thread is involved: "thread" is CoppeliaSim's word, and the world is only
//! ever touched by the simulation thread.

use std::cell::{Cell, RefCell};
use std::ffi::c_void;
use std::time::{Duration, Instant};

use mlua::{Lua, Table, Thread};

use crate::app_state::state;
use crate::running::Running;

/// A remote client's blocking call in progress (`crate::remote_blocking`), named by
/// the engine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BlockingId(pub u64);

/// The coroutines of remote clients' blocking calls in progress, oldest first: threads
/// too, but of no script, resumed by the engine after each step.
#[derive(Default)]
pub(crate) struct BlockingCalls {
    pub(crate) running: Vec<(BlockingId, gantry_sim_core::api::ScriptHostFn, Thread)>,
}

/// CoppeliaSim's default auto-yield delay (`sim.getAutoYieldDelay`).
pub const DEFAULT_AUTO_YIELD: Duration = Duration::from_millis(2);

/// How one script's thread gives control back; one per script, reset when it loads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct ThreadMode {
    /// `sim.setStepping` level: above 0, the thread yields only in blocking calls.
    pub stepping: u32,
    /// Levels of `sim.setThreadAutomaticSwitch(false)` and `sim.acquireLock()`: above
    /// 0, no pre-emption either.
    pub locks: u32,
    /// How long the thread runs before it is pre-empted, when pre-emption is on.
    pub auto_yield: Duration,
}

impl Default for ThreadMode {
    fn default() -> Self {
        Self {
            stepping: 0,
            locks: 0,
            auto_yield: DEFAULT_AUTO_YIELD,
        }
    }
}

impl ThreadMode {
    /// Whether the thread is pre-empted after [`ThreadMode::auto_yield`].
    pub fn preemptive(&self) -> bool {
        self.stepping == 0 && self.locks == 0
    }
}

/// Every script's thread mode, and the thread being resumed now: what the time-budget
/// hook needs to pre-empt it.
pub(crate) struct Threads {
    /// Each script's thread mode, by script index.
    modes: RefCell<Vec<ThreadMode>>,
    /// The script thread being resumed now (null when none): only it is pre-empted,
    /// not a coroutine of the script's own running inside it.
    running: Cell<*const c_void>,
    /// When the thread being resumed is pre-empted, if its mode allows it.
    slice_end: Cell<Option<Instant>>,
}

impl Threads {
    /// No script, no thread running.
    pub(crate) fn new() -> Self {
        Self {
            modes: RefCell::new(Vec::new()),
            running: Cell::new(std::ptr::null()),
            slice_end: Cell::new(None),
        }
    }

    /// `scripts` scripts, each in the default mode (the scene's scripts load again).
    pub(crate) fn reset(&self, scripts: usize) {
        *self.modes.borrow_mut() = vec![ThreadMode::default(); scripts];
    }

    /// One more script, in the default mode (a model's script loaded during the run).
    pub(crate) fn push(&self) {
        self.modes.borrow_mut().push(ThreadMode::default());
    }

    /// Script `i` starts afresh in the default mode (it was reloaded).
    pub(crate) fn reset_mode(&self, i: usize) {
        if let Some(m) = self.modes.borrow_mut().get_mut(i) {
            *m = ThreadMode::default();
        }
    }

    /// Resumes `thread`, script `i`'s, for one time slice; returns once it yields,
    /// returns or fails.
    pub(crate) fn resume(&self, i: usize, thread: &Thread) -> mlua::Result<()> {
        let mode = self.modes.borrow().get(i).copied().unwrap_or_default();
        self.running.set(thread.to_pointer());
        self.slice_end.set(Some(Instant::now() + mode.auto_yield));
        let r = thread.resume::<()>(());
        self.slice_end.set(None);
        self.running.set(std::ptr::null());
        r
    }

    /// Suspends the running slice's end (code that must not be pre-empted runs, or
    /// the debugger holds the simulation); give it back with [`Threads::set_slice_end`].
    pub(crate) fn take_slice_end(&self) -> Option<Instant> {
        self.slice_end.take()
    }

    /// Restores what [`Threads::take_slice_end`] took.
    pub(crate) fn set_slice_end(&self, end: Option<Instant>) {
        self.slice_end.set(end);
    }

    /// Whether the running code is script `script`'s thread, its time slice is over and
    /// its mode lets it be pre-empted.
    pub(crate) fn preemption_due(&self, lua: &Lua, script: Option<usize>, now: Instant) -> bool {
        let Some(end) = self.slice_end.get() else {
            return false;
        };
        if now <= end {
            return false;
        }
        let preemptive = script
            .and_then(|i| self.modes.borrow().get(i).map(ThreadMode::preemptive))
            .unwrap_or(false);
        preemptive && lua.current_thread().to_pointer() == self.running.get()
    }
}

/// The Lua side of the blocking calls.
const THREADS_LUA: &str = include_str!("lua/threads.lua");

/// `sim.moveToConfig` and `sim.moveToPose`, blocking calls built on `sim.ruckigPos`,
/// `sim.ruckigStep` and `sim.step`.
const MOTION_LUA: &str = include_str!("lua/motion.lua");

/// `sim.followPath` and `sim.moveToPosition` (V-REP 3), blocking calls built on the path
/// and pose functions and `sim.step`.
const PATH_MOTION_LUA: &str = include_str!("lua/path_motion.lua");

/// Installs the thread functions into the global `sim` table: the blocking calls from
/// `lua/threads.lua` and the mode setters below, which act on the calling script.
pub(crate) fn install(lua: &Lua, sim: &Table) -> mlua::Result<()> {
    let host = lua.create_table()?;
    // Each setter reads or changes the mode of the script running now; outside any
    // script (never reached from Lua) there is no mode to change.
    let with_mode = |f: fn(&mut ThreadMode, Option<mlua::Value>) -> mlua::Result<mlua::Value>| {
        // Failures come back as (false, message) and threads.lua raises the message
        // as a Lua string from the caller's line, like every other API error.
        lua.create_function(move |lua, arg: Option<mlua::Value>| {
            let script = state::<Running>(lua).script.get();
            let threads = state::<Threads>(lua);
            let mut modes = threads.modes.borrow_mut();
            let result = match script.and_then(|i| modes.get_mut(i)) {
                Some(mode) => f(mode, arg),
                None => Err(mlua::Error::runtime("no script is running")),
            };
            Ok(match result {
                Ok(v) => (true, v),
                Err(e) => (false, mlua::Value::String(lua.create_string(e.to_string())?)),
            })
        })
    };
    host.set(
        "setStepping",
        with_mode(|m, arg| {
            let enable = truthy(arg.as_ref(), "setStepping")?;
            let previous = m.stepping;
            m.stepping = level(m.stepping, enable);
            Ok(mlua::Value::Integer(i64::from(previous)))
        })?,
    )?;
    host.set(
        "getStepping",
        with_mode(|m, _| Ok(mlua::Value::Boolean(m.stepping > 0)))?,
    )?;
    host.set(
        "setThreadAutomaticSwitch",
        with_mode(|m, arg| {
            let automatic = truthy(arg.as_ref(), "setThreadAutomaticSwitch")?;
            let previous = m.locks;
            m.locks = level(m.locks, !automatic);
            Ok(mlua::Value::Integer(i64::from(previous)))
        })?,
    )?;
    host.set(
        "getThreadAutomaticSwitch",
        with_mode(|m, _| Ok(mlua::Value::Boolean(m.preemptive())))?,
    )?;
    host.set(
        "acquireLock",
        with_mode(|m, _| {
            m.locks = m.locks.saturating_add(1);
            Ok(mlua::Value::Nil)
        })?,
    )?;
    host.set(
        "releaseLock",
        with_mode(|m, _| {
            m.locks = m.locks.saturating_sub(1);
            Ok(mlua::Value::Nil)
        })?,
    )?;
    host.set(
        "setAutoYieldDelay",
        with_mode(|m, arg| {
            let seconds = seconds(arg.as_ref(), "setAutoYieldDelay", 1.0)?;
            let previous = m.auto_yield.as_secs_f64();
            m.auto_yield = Duration::from_secs_f64(seconds);
            Ok(mlua::Value::Number(previous))
        })?,
    )?;
    host.set(
        "getAutoYieldDelay",
        with_mode(|m, _| Ok(mlua::Value::Number(m.auto_yield.as_secs_f64())))?,
    )?;
    // CoppeliaSim 4.0-4.5: the same delay in milliseconds.
    host.set(
        "setThreadSwitchTiming",
        with_mode(|m, arg| {
            m.auto_yield = Duration::from_secs_f64(seconds(arg.as_ref(), "setThreadSwitchTiming", 1000.0)?);
            Ok(mlua::Value::Integer(1))
        })?,
    )?;
    // V-REP 3: a "free" thread ran unsynchronised with the simulation, to block in
    // system calls. gantry's threads are coroutines on the simulation thread whose
    // blocking calls yield, so there is nothing to free: the flag is checked and
    // accepted, with V-REP 3's 1 for success.
    host.set(
        "setThreadIsFree",
        with_mode(|_, arg| {
            truthy(arg.as_ref(), "setThreadIsFree")?;
            Ok(mlua::Value::Integer(1))
        })?,
    )?;
    host.set(
        "isScriptRunningInThread",
        lua.create_function(move |lua, ()| {
            let ptr = lua.current_thread().to_pointer();
            Ok(i64::from(!ptr.is_null() && ptr == state::<Threads>(lua).running.get()))
        })?,
    )?;
    let motion_helpers: Table = lua.load(MOTION_LUA).set_name("@gantry/motion.lua").call(sim.clone())?;
    lua.load(PATH_MOTION_LUA)
        .set_name("@gantry/path_motion.lua")
        .call::<()>((sim.clone(), motion_helpers))?;
    lua.load(THREADS_LUA).set_name("@gantry/threads.lua").call::<()>((
        sim.clone(),
        host,
        lua.globals().get::<Table>("coroutine")?,
        lua.globals().get::<mlua::Function>("error")?,
        lua.globals().get::<mlua::Function>("type")?,
        lua.globals().get::<Table>("string")?,
        lua.globals().get::<mlua::Function>("ipairs")?,
    ))
}

/// A level that `true` raises and `false` lowers (never below 0).
fn level(current: u32, raise: bool) -> u32 {
    if raise {
        current.saturating_add(1)
    } else {
        current.saturating_sub(1)
    }
}

/// A boolean argument; CoppeliaSim 4.0-4.5 scripts also pass 0 and 1.
fn truthy(v: Option<&mlua::Value>, f: &str) -> mlua::Result<bool> {
    match v {
        Some(mlua::Value::Boolean(b)) => Ok(*b),
        Some(mlua::Value::Integer(i)) => Ok(*i != 0),
        Some(mlua::Value::Number(n)) => Ok(*n != 0.0),
        other => Err(mlua::Error::runtime(format!(
            "argument 1: expected boolean, got {} (in function 'sim.{f}')",
            other.map_or("no value", |v| v.type_name())
        ))),
    }
}

/// A non-negative duration argument of at most one hour, in seconds; `scale` is the
/// argument's units per second (1000 for milliseconds).
fn seconds(v: Option<&mlua::Value>, f: &str, scale: f64) -> mlua::Result<f64> {
    let x = match v {
        Some(mlua::Value::Integer(i)) => *i as f64,
        Some(mlua::Value::Number(n)) => *n,
        other => {
            return Err(mlua::Error::runtime(format!(
                "argument 1: expected number, got {} (in function 'sim.{f}')",
                other.map_or("no value", |v| v.type_name())
            )));
        }
    };
    let s = x / scale;
    if !(0.0..=3600.0).contains(&s) {
        return Err(mlua::Error::runtime(format!(
            "argument 1: expected a delay between 0 and 3600 s, got {x} (in function 'sim.{f}')"
        )));
    }
    Ok(s)
}
