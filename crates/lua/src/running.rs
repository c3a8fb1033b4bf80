//! The script running now, as every host function sees it: which object and script
//! called (`'.'` in paths, `sim.handle_self`, its thread mode), under which name (logs),
//! in which hook (the debugger names the bottom frame after it), and its time budget.
//!
//! The host sets it when it calls into a script ([`Running::enter`]) and clears it when
//! the call returns; code run on another script's behalf (`sim.callScriptFunction`, a
//! message) borrows the identity with [`Running::act_as`] and gives it back.

use std::borrow::Cow;
use std::cell::{Cell, RefCell};
use std::rc::Rc;
use std::time::{Duration, Instant};

use gantry_sim_core::Handle;

/// The deadline while no hook runs: far enough away never to interrupt anything.
const IDLE: Duration = Duration::from_secs(3600);

/// Who runs now and until when (see the module documentation).
pub(crate) struct Running {
    /// Object of the script running now, for `'.'` in paths; `None` outside scripts.
    pub(crate) object: Cell<Option<Handle>>,
    /// Index of the script running now, for its thread mode.
    pub(crate) script: Cell<Option<usize>>,
    /// Name of the caller in logs: the script's file name, or `remote`.
    pub(crate) name: RefCell<Rc<str>>,
    /// The hook (or callback) being called, as the debugger names the bottom frame.
    pub(crate) hook: RefCell<Cow<'static, str>>,
    /// Counts the host's calls into scripts, so that a debugger step knows when the
    /// hook it started in has returned.
    pub(crate) entries: Cell<u64>,
    /// When the running hook is interrupted.
    pub(crate) deadline: Cell<Instant>,
    /// Set once the running hook passed its deadline; cleared when the next hook starts.
    pub(crate) interrupted: Cell<bool>,
    /// The per-hook time budget.
    pub(crate) budget: Duration,
}

/// A caller's identity, saved while code runs on another script's behalf.
pub(crate) struct Caller {
    /// The calling script's object.
    pub(crate) object: Option<Handle>,
    /// The calling script's index.
    pub(crate) script: Option<usize>,
    /// The calling script's name.
    pub(crate) name: Rc<str>,
}

impl Running {
    /// Nobody running, with `budget` per hook.
    pub(crate) fn new(budget: Duration) -> Self {
        Self {
            object: Cell::new(None),
            script: Cell::new(None),
            name: RefCell::new(Rc::from("remote")),
            hook: RefCell::new(Cow::Borrowed("")),
            entries: Cell::new(0),
            deadline: Cell::new(Instant::now() + IDLE),
            interrupted: Cell::new(false),
            budget,
        }
    }

    /// The host calls `hook` of script `script` (on `object`, named `name`): a new entry
    /// with a fresh budget.
    pub(crate) fn enter(&self, object: Handle, script: usize, name: Rc<str>, hook: Cow<'static, str>) {
        self.entries.set(self.entries.get().wrapping_add(1));
        *self.hook.borrow_mut() = hook;
        self.object.set(Some(object));
        self.script.set(Some(script));
        *self.name.borrow_mut() = name;
        self.restart_budget();
    }

    /// The host's call returned: nobody runs (the name stays, for late log lines).
    pub(crate) fn leave(&self) {
        self.interrupted.set(false);
        self.object.set(None);
        self.script.set(None);
        self.deadline.set(Instant::now() + IDLE);
    }

    /// A fresh budget for script code run outside any hook (for a remote client).
    pub(crate) fn restart_budget(&self) {
        self.deadline.set(Instant::now() + self.budget);
        self.interrupted.set(false);
    }

    /// Runs as `caller` from now on; returns the identity to give back.
    pub(crate) fn act_as(&self, caller: Caller) -> Caller {
        Caller {
            object: self.object.replace(caller.object),
            script: self.script.replace(caller.script),
            name: self.name.replace(caller.name),
        }
    }
}
