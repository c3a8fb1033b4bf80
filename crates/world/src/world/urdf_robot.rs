//! The robots of the world that came from URDF files: which objects each file's links
//! and joints became, and the file's text. The object tree itself forgets where an
//! object came from; consumers that speak ROS (the ROS 2 graph's `/robot_description`,
//! TF frames named by URDF link) need it. Nothing here is simulated.

use std::path::PathBuf;
use std::sync::Arc;

use crate::scene::UrdfRobotModel;
use crate::world::Handle;

/// A robot loaded from a URDF file (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfRobot {
    /// The model base (the dummy aliased by the robot name).
    pub base: Handle,
    /// The file it was read from.
    pub path: PathBuf,
    /// The file's text as read, unchanged; `None` when it was too long to keep (see
    /// [`crate::scene::MAX_URDF_TEXT_BYTES`]).
    pub text: Option<Arc<str>>,
    /// Each link's object and URDF link name, by handle.
    pub links: Vec<(Handle, String)>,
    /// Each joint's object and URDF joint name, by handle.
    pub joints: Vec<(Handle, String)>,
}

impl UrdfRobot {
    /// The robot of `model`, with each object index mapped to a handle by `map`.
    pub(super) fn from_model(model: &UrdfRobotModel, map: impl Fn(usize) -> Handle) -> Self {
        let parts = |v: &[(usize, String)]| v.iter().map(|(i, n)| (map(*i), n.clone())).collect();
        Self {
            base: map(model.base),
            path: model.path.clone(),
            text: model.text.clone(),
            links: parts(&model.links),
            joints: parts(&model.joints),
        }
    }
}
