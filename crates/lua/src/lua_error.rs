//! Lua errors as people read them: the message and traceback without mlua's wrapping,
//! and the error a script load reports at the crate's boundary.

/// A script load or syntax problem, with file and line in the message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ScriptError(pub String);

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
