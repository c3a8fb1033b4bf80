//! The one error of the simulation: why a world operation or a `sim.*` call failed.
//! World functions, the subsystems and the registry all return it, so a failure keeps
//! its kind from where it is found to the edge, where each front end formats it as
//! CoppeliaSim does (Lua raises `msg (in function 'sim.x')`, ZMQ replies
//! `{"err": ...}` with the same text, Python raises an exception with it).

use crate::handle::Handle;

/// Why a simulation operation failed. The kind is the variant; the text (`Display`) is
/// exactly what clients see, in CoppeliaSim's wording where one exists, since ported
/// scripts and clients may match on it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// The handle names no object.
    #[error("object does not exist. (handle {0})")]
    NoSuchObject(Handle),
    /// A handle or name names no item of another kind (a UI, a drawing, an IK
    /// environment, a point cloud, a signal...); the message says which.
    #[error("{0}")]
    NoSuchItem(String),
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
    /// A path did not resolve. The path is kept for the caller; the message is
    /// CoppeliaSim's, which does not repeat it.
    #[error("object does not exist, or alias/path is ill formatted.")]
    PathNotFound(String),
    /// An argument is missing, of the wrong type, malformed or out of range.
    #[error("{0}")]
    BadArgument(String),
    /// A well-formed request the simulation refuses in its current state (a time step
    /// changed while running, a limit reached, a file outside the scene's folder).
    #[error("{0}")]
    Refused(String),
}

impl SimError {
    /// A refusal with a message.
    pub fn refused(message: impl Into<String>) -> Self {
        Self::Refused(message.into())
    }

    /// An argument error.
    pub fn bad_argument(message: impl Into<String>) -> Self {
        Self::BadArgument(message.into())
    }

    /// A missing item that is not an object (the message names it).
    pub fn no_such_item(message: impl Into<String>) -> Self {
        Self::NoSuchItem(message.into())
    }

    /// The same failure with `prefix` before its message (`argument 3: ...`); the kind
    /// stays, except that an object error becomes an argument error once its text is
    /// no longer CoppeliaSim's fixed wording.
    pub fn prefixed(self, prefix: &str) -> Self {
        let message = format!("{prefix}{self}");
        match self {
            Self::NoSuchObject(_) | Self::NoSuchItem(_) | Self::PathNotFound(_) => Self::NoSuchItem(message),
            Self::WrongKind { .. } | Self::BadArgument(_) => Self::BadArgument(message),
            Self::Refused(_) => Self::Refused(message),
        }
    }

    /// The full message as CoppeliaSim prints it: `msg (in function 'sim.name')`.
    pub fn in_function(&self, qualified_name: &str) -> String {
        format!("{self} (in function '{qualified_name}')")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_coppeliasims() {
        assert_eq!(
            SimError::NoSuchObject(7).to_string(),
            "object does not exist. (handle 7)"
        );
        assert_eq!(
            SimError::PathNotFound("/a".into()).in_function("sim.getObject"),
            "object does not exist, or alias/path is ill formatted. (in function 'sim.getObject')"
        );
        let e = SimError::WrongKind {
            handle: 3,
            expected: "joint",
            actual: "shape",
        };
        assert_eq!(e.to_string(), "object 3 is a shape, not a joint");
        assert_eq!(
            e.prefixed("argument 2: "),
            SimError::BadArgument("argument 2: object 3 is a shape, not a joint".into())
        );
    }
}
