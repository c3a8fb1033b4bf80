//! The errors of `sim.*` calls, structured until the edge. A function fails with an
//! [`ApiError`] (what kind of failure, and the message without the function's name);
//! a call by name fails with a [`CallError`] that adds the function. Each front end
//! formats them as CoppeliaSim does only when it hands them over: Lua raises
//! `msg (in function 'sim.x')`, ZMQ replies `{"err": ...}` with the same text, Python
//! raises `Exception` with it.

use crate::error::SimError;

/// What kind of failure a call met; front ends may react by kind (the text is the same).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// A handle or path names no object (or no UI, drawing, environment, ...).
    NoSuchObject,
    /// The object exists but is of the wrong kind for the call.
    WrongKind,
    /// An argument is missing, of the wrong type, or out of range.
    BadArgument,
    /// A well-formed call the simulation refuses in its current state (a time step
    /// changed while running, a limit reached, a file outside the scene's folder).
    Refused,
}

/// A failed function: its kind and message, without the function's name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct ApiError {
    /// What kind of failure.
    pub kind: ErrorKind,
    /// CoppeliaSim-style message, without `(in function ...)`.
    pub message: String,
}

impl ApiError {
    /// A refusal with a message (the kind of most checks inside functions).
    pub fn new(message: impl Into<String>) -> Self {
        Self::of(ErrorKind::Refused, message)
    }

    /// An argument error.
    pub fn bad_argument(message: impl Into<String>) -> Self {
        Self::of(ErrorKind::BadArgument, message)
    }

    /// An error of `kind`.
    pub fn of(kind: ErrorKind, message: impl Into<String>) -> Self {
        Self {
            kind,
            message: message.into(),
        }
    }

    /// The full message as CoppeliaSim prints it: `msg (in function 'sim.name')`.
    pub fn in_function(&self, qualified_name: &str) -> String {
        format!("{} (in function '{qualified_name}')", self.message)
    }
}

impl From<SimError> for ApiError {
    fn from(e: SimError) -> Self {
        match e {
            // CoppeliaSim's own wording, which ported scripts and clients may match on.
            SimError::PathNotFound(_) => Self::of(
                ErrorKind::NoSuchObject,
                "object does not exist, or alias/path is ill formatted.",
            ),
            SimError::NoSuchObject(h) => {
                Self::of(ErrorKind::NoSuchObject, format!("object does not exist. (handle {h})"))
            }
            e @ SimError::WrongKind { .. } => Self::of(ErrorKind::WrongKind, e.to_string()),
            SimError::InvalidArgument(m) => Self::of(ErrorKind::BadArgument, m),
            SimError::Refused(m) => Self::of(ErrorKind::Refused, m),
        }
    }
}

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
        error: ApiError,
    },
}

impl CallError {
    /// `function` (qualified) failed with `error`.
    pub fn failed(function: impl Into<String>, error: ApiError) -> Self {
        Self::Failed {
            function: function.into(),
            error,
        }
    }

    /// The kind of failure; `None` for an unknown function.
    pub fn kind(&self) -> Option<ErrorKind> {
        match self {
            CallError::NoSuchFunction(_) => None,
            CallError::Failed { error, .. } => Some(error.kind),
        }
    }
}
