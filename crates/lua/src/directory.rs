//! The script directory: each script's object, environment and name by script index,
//! for what one script (or a remote client) asks about another: `sim.getScript`,
//! `sim.callScriptFunction`, `sim.removeScript`, messages, the debugger's globals.
//!
//! A script's handle is the handle of the object it is attached to. A removed script
//! keeps its entry (indices stay aligned with the scene's scripts) under
//! [`REMOVED_SCRIPT`], which no handle matches.

use std::cell::RefCell;
use std::rc::Rc;

use gantry_sim_core::Handle;
use mlua::Table;

/// `sim.handle_self`.
pub(crate) const HANDLE_SELF: i64 = -4;
/// The object of a removed script's entry: no handle matches it.
pub(crate) const REMOVED_SCRIPT: Handle = i64::MIN;

/// One script as others see it.
#[derive(Clone)]
pub(crate) struct Entry {
    /// Its object ([`REMOVED_SCRIPT`] once removed).
    pub(crate) object: Handle,
    /// Its environment: its globals.
    pub(crate) env: Table,
    /// Its file name, for logs.
    pub(crate) name: Rc<str>,
}

/// Every script of the scene, by index, and the removals asked for.
#[derive(Default)]
pub(crate) struct Directory {
    entries: RefCell<Vec<Entry>>,
    /// Scripts `sim.removeScript` removes once no script is running (by index).
    removals: RefCell<Vec<usize>>,
}

impl Directory {
    /// Forgets every script (before the scene's scripts load again).
    pub(crate) fn clear(&self) {
        self.entries.borrow_mut().clear();
    }

    /// Adds the next script's entry.
    pub(crate) fn push(&self, entry: Entry) {
        self.entries.borrow_mut().push(entry);
    }

    /// Script `i`, removed or not.
    pub(crate) fn entry(&self, i: usize) -> Option<Entry> {
        self.entries.borrow().get(i).cloned()
    }

    /// The first script attached to `object`, with its index.
    pub(crate) fn find(&self, object: Handle) -> Option<(usize, Entry)> {
        let entries = self.entries.borrow();
        let i = entries.iter().position(|e| e.object == object)?;
        Some((i, entries[i].clone()))
    }

    /// The index of the script whose handle (its object's) is `h`.
    pub(crate) fn index_of(&self, h: Handle) -> Option<usize> {
        if h == REMOVED_SCRIPT {
            return None;
        }
        self.entries.borrow().iter().position(|e| e.object == h)
    }

    /// Whether a script is attached to `object`.
    pub(crate) fn attached(&self, object: Handle) -> bool {
        self.entries.borrow().iter().any(|e| e.object == object)
    }

    /// Script `i` no longer answers to its object's handle.
    pub(crate) fn mark_removed(&self, i: usize) {
        if let Some(e) = self.entries.borrow_mut().get_mut(i) {
            e.object = REMOVED_SCRIPT;
        }
    }

    /// A reloaded script's new environment, for every entry of that script.
    pub(crate) fn replace_env(&self, object: Handle, name: &str, env: &Table) {
        for e in self.entries.borrow_mut().iter_mut() {
            if e.object == object && &*e.name == name {
                e.env = env.clone();
            }
        }
    }

    /// `sim.removeScript` asked for script `i`'s removal.
    pub(crate) fn request_removal(&self, i: usize) {
        self.removals.borrow_mut().push(i);
    }

    /// The removals asked for since the last call.
    pub(crate) fn take_removals(&self) -> Vec<usize> {
        std::mem::take(&mut *self.removals.borrow_mut())
    }
}
