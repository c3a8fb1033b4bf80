//! The error of a call by name. A function fails with the simulation's one error,
//! [`SimError`] (its kind and the message without the function's name); a call by name
//! fails with a [`CallError`] that adds the function. Each front end formats it as
//! CoppeliaSim does only when it hands it over: Lua raises
//! `msg (in function 'sim.x')`, ZMQ replies `{"err": ...}` with the same text, Python
//! raises `Exception` with it.

use crate::error::SimError;

/// A failed call by name, as it reaches a front end.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CallError {
    /// No function of that name (qualified, `sim.x`).
    #[error("No such function: {0}")]
    NoSuchFunction(String),
    /// The function failed.
    #[error("{error} (in function '{function}')")]
    Failed {
        /// Qualified name, `sim.getObject`.
        function: String,
        /// Why.
        error: SimError,
    },
}

impl CallError {
    /// `function` (qualified) failed with `error`.
    pub fn failed(function: impl Into<String>, error: SimError) -> Self {
        Self::Failed {
            function: function.into(),
            error,
        }
    }

    /// Why the function failed; `None` for an unknown function.
    pub fn error(&self) -> Option<&SimError> {
        match self {
            CallError::NoSuchFunction(_) => None,
            CallError::Failed { error, .. } => Some(error),
        }
    }
}
