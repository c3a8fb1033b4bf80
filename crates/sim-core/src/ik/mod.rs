//! Inverse kinematics (`simIK`): environments, groups of base/tip/target elements, and a
//! damped-least-squares solver over the scene's joints.

/// Every IK environment.
#[derive(Debug, Clone, Default)]
pub struct IkEnvironments {}
