//! Inverse kinematics without a scene (`simIK`'s machinery): environments and their
//! groups of base/tip/target elements, an environment's own object tree (the *IK world*
//! of CoppeliaSim 4.2-4.5 scripts), the pure snapshot of a group's chains (forward
//! kinematics, analytic Jacobian, tip-to-target errors) and the damped-least-squares
//! solver that iterates on it.
//!
//! It sits below the world (`gantry-world`), whose `Sim` owns the [`IkEnvironments`],
//! and knows no physics. Reading chains out of the scene's tree, solving groups on the
//! scene and writing solutions back are the world's part (`gantry_world::ik`, which
//! re-exports this crate, as `gantry_sim_core::ik` does); there the module docs say how
//! gantry's scene elements differ from CoppeliaSim's mirrored IK world.
//!
//! Layout: `environment` holds the handles and settings, `objects` an environment's own
//! tree, `chain` the snapshot as pure data, `solver` the iteration on it.

mod chain;
mod environment;
mod error;
mod objects;
mod solver;

pub use chain::{ChainPose, Distance, ElementChain, ElementModel, JointSlot, KinematicModel, Linearization};
pub use environment::{
    Constraints, ElementTarget, GroupFlags, IkElement, IkEnvironment, IkEnvironments, IkGroup, IkMethod,
};
pub use error::IkError;
pub use objects::{
    FIRST_OBJECT, HANDLE_PARENT, HANDLE_WORLD, IkJoint, IkJointMode, IkObject, IkObjectKind, IkObjects, is_own_object,
};
pub use solver::{
    CALC_CANNOT_INVERT, CALC_LIMIT_HIT, CALC_NOT_PERFORMED, CALC_NOT_WITHIN_TOLERANCE, IkResult, STOP_TOLERANCE,
    Solution, SolveParams, solve,
};
