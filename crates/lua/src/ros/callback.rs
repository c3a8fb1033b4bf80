//! [`Callback`]: how a script names the function `simROS2` calls for a message,
//! request or action event.

/// What a subscription or a service calls: a function, or the name of a global of the
/// owning script (both forms are CoppeliaSim's).
pub(crate) enum Callback {
    /// A Lua function, kept in the registry.
    Function(mlua::RegistryKey),
    /// A function looked up in the script's environment at each call.
    Name(String),
}
