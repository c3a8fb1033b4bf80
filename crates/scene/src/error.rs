//! The error of world operations, shared by every `sim.*` function.

use crate::handle::Handle;

/// Why a world operation was refused. Messages follow CoppeliaSim's wording where one
/// exists, so ported scripts see familiar errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// The handle names no object.
    #[error("object does not exist (handle {0})")]
    NoSuchObject(Handle),
    /// The object exists but is of the wrong kind for the call.
    #[error("object {handle} is a {actual}, not a {expected}")]
    WrongKind {
        /// The object.
        handle: Handle,
        /// What the call needs, e.g. "joint".
        expected: &'static str,
        /// What it is.
        actual: &'static str,
    },
    /// A path did not resolve.
    #[error("object does not exist, or alias/path is ill formatted: '{0}'")]
    PathNotFound(String),
    /// An argument is out of range or malformed.
    #[error("{0}")]
    InvalidArgument(String),
    /// A valid request refused in the simulation's current state (e.g. a time step
    /// changed while running).
    #[error("{0}")]
    Refused(String),
}
