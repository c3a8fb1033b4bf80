//! Why an IK call was refused: the one error of the IK subsystem, shared by the
//! environments, their objects and the tree views.

use gantry_scene::Handle;
use gantry_scene::SimError;

/// Why an IK call was refused. Messages name the offending handle and say what is expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkError {
    /// Unknown or erased environment.
    #[error("IK environment {0} does not exist (create one with simIK.createEnvironment)")]
    NoSuchEnvironment(Handle),
    /// Unknown group in an existing environment.
    #[error("IK group {0} does not exist in this environment (create one with simIK.createGroup)")]
    NoSuchGroup(Handle),
    /// Unknown element in an existing group.
    #[error("IK element {element} does not exist in IK group {group}")]
    NoSuchElement {
        /// The group searched.
        group: Handle,
        /// The element asked for.
        element: Handle,
    },
    /// An object handle of the environment's own range that names no object.
    #[error(
        "IK object {0} does not exist in this environment (create one with simIK.createDummy or simIK.createJoint)"
    )]
    NoSuchIkObject(Handle),
    /// An object of the wrong kind (a joint where a dummy is expected, ...).
    #[error("object {handle} is not a {expected}")]
    WrongKind {
        /// The object given.
        handle: Handle,
        /// "dummy" or "joint".
        expected: &'static str,
    },
    /// An element whose target is the tip's linked dummy, and the tip has none.
    #[error("tip dummy {tip} has no target: link one with simIK.setLinkedDummy (sim.setLinkDummy for a scene dummy)")]
    NoTarget {
        /// The tip.
        tip: Handle,
    },
    /// A scene handle that names no object.
    #[error("{role} object does not exist (handle {handle})")]
    NoSuchObject {
        /// "base", "tip" or "target".
        role: &'static str,
        /// The handle given.
        handle: Handle,
    },
    /// The tip does not hang below the base in the object tree.
    #[error(
        "tip (handle {tip}) is not below base (handle {base}) in its object tree (the scene's, or the IK environment's own)"
    )]
    TipNotBelowBase {
        /// The tip.
        tip: Handle,
        /// The base.
        base: Handle,
    },
    /// No revolute or prismatic joint between base and tip.
    #[error("no revolute or prismatic joint between base (handle {base}) and tip (handle {tip})")]
    NoJoints {
        /// The tip.
        tip: Handle,
        /// The base.
        base: Handle,
    },
    /// An argument out of range (a method or constraint code, a negative damping, ...).
    #[error("{0}")]
    BadArgument(String),
}

/// An IK failure as the registry returns it: missing things are missing items, wrong
/// kinds and bad values argument errors, and a chain that cannot be built a refusal.
/// The text is the IK error's own.
impl From<IkError> for SimError {
    fn from(e: IkError) -> Self {
        let message = e.to_string();
        match e {
            IkError::NoSuchEnvironment(_)
            | IkError::NoSuchGroup(_)
            | IkError::NoSuchElement { .. }
            | IkError::NoSuchIkObject(_)
            | IkError::NoSuchObject { .. } => SimError::NoSuchItem(message),
            IkError::WrongKind { .. } | IkError::BadArgument(_) => SimError::BadArgument(message),
            IkError::NoTarget { .. } | IkError::TipNotBelowBase { .. } | IkError::NoJoints { .. } => {
                SimError::Refused(message)
            }
        }
    }
}
