//! The two object trees an IK element may live in, read through one view: the scene's
//! (the [`World`]) and an environment's own ([`IkObjects`]). The handle says which
//! ([`is_own_object`]); building a kinematic model only needs each object's parent, local
//! pose and, for a joint, what the solver may do with it.

use gantry_ik::{IkError, IkJointMode, IkObjectKind, IkObjects, is_own_object};

use crate::handle::Handle;
use crate::math::Pose;
use crate::scene::JointType;
use crate::world::{ObjectKind, World};

/// A joint as a model sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointView {
    /// Revolute, prismatic or fixed.
    pub joint_type: JointType,
    /// Whether the position wraps into (-pi, pi].
    pub cyclic: bool,
    /// `(min, max)`, `None` when unlimited or cyclic.
    pub limits: Option<(f64, f64)>,
    /// Current position (rad or m).
    pub position: f64,
    /// Whether the solver may move it: every revolute or prismatic scene joint, and the
    /// environment's own joints in IK mode. Others are rigid at their position.
    pub movable: bool,
}

impl JointView {
    /// The motion of a rigid (not movable) joint at its position.
    pub fn motion(&self) -> Pose {
        match self.joint_type {
            JointType::Revolute => Pose::rotation(crate::math::Vec3::z() * self.position),
            JointType::Prismatic => Pose::translation(0.0, 0.0, self.position),
            JointType::Fixed => Pose::identity(),
        }
    }
}

/// One object: its parent, its pose relative to the parent's hanging frame, and its
/// joint, if it is one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeView {
    /// The parent, `None` at a root.
    pub parent: Option<Handle>,
    /// Pose relative to the parent's hanging frame.
    pub local: Pose,
    /// The joint, for a joint.
    pub joint: Option<JointView>,
}

/// The scene's tree and one environment's own.
#[derive(Clone, Copy)]
pub struct Trees<'a> {
    /// The scene.
    pub scene: &'a World,
    /// The environment's own objects.
    pub own: &'a IkObjects,
}

impl<'a> Trees<'a> {
    /// A view over the scene and `own`.
    pub fn new(scene: &'a World, own: &'a IkObjects) -> Self {
        Self { scene, own }
    }

    /// The object behind `h` (`role` names it in the error: "base", "tip", ...).
    ///
    /// # Errors
    /// No such object in the tree `h` belongs to.
    pub fn node(&self, h: Handle, role: &'static str) -> Result<NodeView, IkError> {
        if is_own_object(h) {
            let o = self.own.get(h)?;
            let joint = match &o.kind {
                IkObjectKind::Joint(j) => Some(JointView {
                    joint_type: j.joint_type,
                    cyclic: j.cyclic,
                    limits: j.limits(),
                    position: j.position,
                    movable: j.mode == IkJointMode::Ik,
                }),
                IkObjectKind::Dummy { .. } => None,
            };
            return Ok(NodeView {
                parent: o.parent,
                local: o.local,
                joint,
            });
        }
        let o = self
            .scene
            .object(h)
            .map_err(|_| IkError::NoSuchObject { role, handle: h })?;
        let joint = match &o.kind {
            ObjectKind::Joint(j) => Some(JointView {
                joint_type: j.joint_type,
                cyclic: j.cyclic,
                limits: j.limits,
                position: j.position,
                movable: j.joint_type != JointType::Fixed,
            }),
            _ => None,
        };
        Ok(NodeView {
            parent: o.parent,
            local: o.local,
            joint,
        })
    }

    /// World pose of `h`'s frame.
    ///
    /// # Errors
    /// No such object.
    pub fn world(&self, h: Handle, role: &'static str) -> Result<Pose, IkError> {
        if is_own_object(h) {
            return self.own.world(h);
        }
        self.scene
            .object(h)
            .map(|o| o.world)
            .map_err(|_| IkError::NoSuchObject { role, handle: h })
    }

    /// World pose of the frame `h`'s local pose is relative to.
    ///
    /// # Errors
    /// No such object.
    pub fn parent_frame(&self, h: Handle) -> Result<Pose, IkError> {
        if is_own_object(h) {
            self.own.parent_frame(h)
        } else {
            Ok(self.scene.parent_frame(h))
        }
    }

    /// The dummy `tip` is linked to, if any.
    ///
    /// # Errors
    /// No such object, or an own object that is not a dummy.
    pub fn linked_dummy(&self, tip: Handle) -> Result<Option<Handle>, IkError> {
        if is_own_object(tip) {
            self.own.linked(tip)
        } else {
            self.scene.object(tip).map_err(|_| IkError::NoSuchObject {
                role: "tip",
                handle: tip,
            })?;
            Ok(self.scene.linked_dummy(tip))
        }
    }

    /// An upper bound on the depth of any tree, to bound walks up to a root.
    pub fn depth_bound(&self) -> usize {
        self.scene.len() + self.own.len()
    }
}
