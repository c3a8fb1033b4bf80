//! Where each role of the Lua host keeps its state: mlua's app data, one slot per type.
//!
//! Each role (the running script in [`crate::running`], the script directory, the
//! threads, the messages, ...) owns a type of its own. The host puts one value of each
//! into the Lua state when it is built and never replaces it, so a host function finds
//! the state it needs through the `&Lua` every callback receives, instead of capturing a
//! bag of everything. Only shared borrows are taken (`app_data_ref`) and the states
//! change through cells: a host function that calls back into Lua, whose code calls
//! another host function reading the same state, never finds it borrowed mutably.

use mlua::{AppDataRef, Lua};

/// Puts a role's state into the Lua state, once, while the host is built (mlua refuses a
/// new slot while any is borrowed, which never happens at that point).
pub(crate) fn install<T: 'static>(lua: &Lua, state: T) {
    let previous = lua.set_app_data(state);
    debug_assert!(previous.is_none(), "{} installed twice", std::any::type_name::<T>());
}

/// A role's state, borrowed for reading (its cells allow changes).
///
/// # Panics
/// The state was never installed: a bug in the host's construction, which installs
/// every role before any Lua code runs.
pub(crate) fn state<T: 'static>(lua: &Lua) -> AppDataRef<'_, T> {
    lua.app_data_ref::<T>()
        .unwrap_or_else(|| panic!("{} is installed before any Lua runs", std::any::type_name::<T>()))
}
