//! An environment's own object tree: the dummies and joints a script builds one by one
//! with `simIK.createDummy`, `simIK.createJoint` and `simIK.setObjectParent` (CoppeliaSim
//! 4.2-4.5), as opposed to the scene objects `simIK.addElementFromScene` refers to.
//!
//! Handles: each environment numbers its objects from [`FIRST_OBJECT`] up, in its own
//! namespace (two environments may hand out the same handle). Scene handles are indices
//! into the world's object table and stay far below that, so every `simIK` function can
//! tell from the handle alone which tree an object belongs to ([`is_own_object`]).
//!
//! Frames follow the scene's rules (see `world`): an object's local pose is relative to
//! the frame its parent's children hang from, which for a joint is its fixed frame moved
//! by its motion (a rotation about, or translation along, local Z by its position). A
//! joint's own pose is its fixed frame. Units are metres and radians.
//!
//! Non-goals: spherical joints, joint dependencies, IK weights and maximum step sizes,
//! and objects other than dummies and joints (CoppeliaSim's IK world has no others).

use std::collections::BTreeMap;

use gantry_scene::Handle;
use gantry_scene::math::{Pose, Vec3};
use gantry_scene::scene::JointType;

use crate::error::IkError;

/// The first handle of an environment's own objects. Scene handles (indices into the
/// world's objects) never get this far, so the ranges cannot overlap.
pub const FIRST_OBJECT: Handle = 10_000_000;

/// Whether `h` names an environment's own object rather than a scene object.
pub fn is_own_object(h: Handle) -> bool {
    h >= FIRST_OBJECT
}

/// `simIK.handle_world`: no object (the world frame, or no parent).
pub const HANDLE_WORLD: Handle = -1;
/// `simIK.handle_parent`: the object's parent frame.
pub const HANDLE_PARENT: Handle = -11;

/// Whether the IK solver moves a joint (`simIK.jointmode_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IkJointMode {
    /// `simIK.jointmode_passive` (0): held at its position, part of the rigid chain.
    Passive,
    /// `simIK.jointmode_ik` (2): a degree of freedom of the solve (the default).
    Ik,
}

impl IkJointMode {
    /// The mode behind CoppeliaSim's number, `None` for an unknown or unsupported one.
    pub fn from_code(code: i64) -> Option<Self> {
        match code {
            0 => Some(Self::Passive),
            2 => Some(Self::Ik),
            _ => None,
        }
    }

    /// CoppeliaSim's number.
    pub fn code(self) -> i64 {
        match self {
            Self::Passive => 0,
            Self::Ik => 2,
        }
    }
}

/// A joint of the environment's own tree.
#[derive(Debug, Clone, PartialEq)]
pub struct IkJoint {
    /// Revolute (rad) or prismatic (m).
    pub joint_type: JointType,
    /// Whether the solver moves it.
    pub mode: IkJointMode,
    /// Whether the position wraps into (-pi, pi] (revolute only).
    pub cyclic: bool,
    /// Lower limit (rad or m); -pi for a cyclic joint.
    pub min: f64,
    /// Width of the interval (rad or m, >= 0); 2 pi for a cyclic joint.
    pub range: f64,
    /// Current position (rad or m), always within the interval.
    pub position: f64,
}

impl IkJoint {
    /// CoppeliaSim's defaults for a new joint: IK mode at 0; a revolute joint cyclic, a
    /// prismatic one limited to [-0.5, 0.5] m.
    fn new(joint_type: JointType) -> Self {
        let (cyclic, min, range) = match joint_type {
            JointType::Prismatic => (false, -0.5, 1.0),
            _ => (true, -std::f64::consts::PI, 2.0 * std::f64::consts::PI),
        };
        Self {
            joint_type,
            mode: IkJointMode::Ik,
            cyclic,
            min,
            range,
            position: 0.0,
        }
    }

    /// `q` wrapped (cyclic) or clamped to the interval, as the joint will hold it
    /// (the one rule for scene and IK joints, [`gantry_scene::math::constrain_joint`]).
    pub fn constrain(&self, q: f64) -> f64 {
        gantry_scene::math::constrain_joint(q, self.cyclic, Some((self.min, self.min + self.range)))
    }

    /// `(min, max)` limits, `None` for a cyclic joint.
    pub fn limits(&self) -> Option<(f64, f64)> {
        (!self.cyclic).then_some((self.min, self.min + self.range))
    }

    /// The joint's motion at its current position.
    pub fn motion(&self) -> Pose {
        match self.joint_type {
            JointType::Prismatic => Pose::translation(0.0, 0.0, self.position),
            JointType::Revolute => Pose::rotation(Vec3::z() * self.position),
            JointType::Fixed => Pose::identity(),
        }
    }
}

/// What an object is.
#[derive(Debug, Clone, PartialEq)]
pub enum IkObjectKind {
    /// A frame; `linked` is the dummy it is linked to (`simIK.setLinkedDummy`): a tip's
    /// target, and the target's tip.
    Dummy {
        /// The linked dummy, if any.
        linked: Option<Handle>,
    },
    /// A joint.
    Joint(IkJoint),
}

/// One object of the tree.
#[derive(Debug, Clone, PartialEq)]
pub struct IkObject {
    /// Optional name (`simIK.getObjectHandle`); unique in the environment when not empty.
    pub name: String,
    /// The parent, `None` at the root.
    pub parent: Option<Handle>,
    /// Pose relative to the parent's hanging frame (the world for a root).
    pub local: Pose,
    /// Dummy or joint.
    pub kind: IkObjectKind,
}

impl IkObject {
    /// `simIK.objecttype_joint` (1) or `simIK.objecttype_dummy` (4), the numbers of
    /// `sim.object_*_type`.
    pub fn type_code(&self) -> i64 {
        match self.kind {
            IkObjectKind::Joint(_) => 1,
            IkObjectKind::Dummy { .. } => 4,
        }
    }

    /// The frame children hang from, relative to this object's frame.
    fn hanging(&self) -> Pose {
        match &self.kind {
            IkObjectKind::Joint(j) => j.motion(),
            IkObjectKind::Dummy { .. } => Pose::identity(),
        }
    }
}

/// The objects of one environment, by handle.
#[derive(Debug, Clone, PartialEq)]
pub struct IkObjects {
    objects: BTreeMap<Handle, IkObject>,
    next: Handle,
}

impl Default for IkObjects {
    fn default() -> Self {
        Self {
            objects: BTreeMap::new(),
            next: FIRST_OBJECT,
        }
    }
}

impl IkObjects {
    /// Adds a root object at the world origin and returns its handle.
    fn insert(&mut self, name: &str, kind: IkObjectKind) -> Result<Handle, IkError> {
        if !name.is_empty() && self.by_name(name).is_some() {
            return Err(IkError::BadArgument(format!(
                "an IK object named '{name}' already exists in this environment"
            )));
        }
        let h = self.next;
        self.next += 1;
        self.objects.insert(
            h,
            IkObject {
                name: name.to_owned(),
                parent: None,
                local: Pose::identity(),
                kind,
            },
        );
        Ok(h)
    }

    /// Creates a dummy at the world origin (`simIK.createDummy`).
    ///
    /// # Errors
    /// `name` is already taken.
    pub fn create_dummy(&mut self, name: &str) -> Result<Handle, IkError> {
        self.insert(name, IkObjectKind::Dummy { linked: None })
    }

    /// Creates a joint at the world origin with CoppeliaSim's defaults (IK mode,
    /// position 0, a revolute joint cyclic) (`simIK.createJoint`).
    ///
    /// # Errors
    /// A fixed joint type, or `name` already taken.
    pub fn create_joint(&mut self, joint_type: JointType, name: &str) -> Result<Handle, IkError> {
        if joint_type == JointType::Fixed {
            return Err(IkError::BadArgument(
                "an IK joint is revolute or prismatic (simIK.jointtype_revolute or jointtype_prismatic)".into(),
            ));
        }
        self.insert(name, IkObjectKind::Joint(IkJoint::new(joint_type)))
    }

    /// The object behind a handle.
    ///
    /// # Errors
    /// [`IkError::NoSuchIkObject`].
    pub fn get(&self, h: Handle) -> Result<&IkObject, IkError> {
        self.objects.get(&h).ok_or(IkError::NoSuchIkObject(h))
    }

    fn get_mut(&mut self, h: Handle) -> Result<&mut IkObject, IkError> {
        self.objects.get_mut(&h).ok_or(IkError::NoSuchIkObject(h))
    }

    /// The joint behind a handle.
    ///
    /// # Errors
    /// No such object, or not a joint.
    pub fn joint(&self, h: Handle) -> Result<&IkJoint, IkError> {
        match &self.get(h)?.kind {
            IkObjectKind::Joint(j) => Ok(j),
            IkObjectKind::Dummy { .. } => Err(IkError::WrongKind {
                handle: h,
                expected: "joint",
            }),
        }
    }

    fn joint_mut(&mut self, h: Handle) -> Result<&mut IkJoint, IkError> {
        match &mut self.get_mut(h)?.kind {
            IkObjectKind::Joint(j) => Ok(j),
            IkObjectKind::Dummy { .. } => Err(IkError::WrongKind {
                handle: h,
                expected: "joint",
            }),
        }
    }

    /// The object named `name`.
    pub fn by_name(&self, name: &str) -> Option<Handle> {
        self.objects.iter().find(|(_, o)| o.name == name).map(|(&h, _)| h)
    }

    /// Every handle, in creation order.
    pub fn handles(&self) -> impl Iterator<Item = Handle> + '_ {
        self.objects.keys().copied()
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether there is no object.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// World pose of an object's frame (a joint's fixed frame).
    ///
    /// # Errors
    /// No such object.
    pub fn world(&self, h: Handle) -> Result<Pose, IkError> {
        let local = self.get(h)?.local;
        Ok(self.parent_frame(h)? * local)
    }

    /// World pose of the frame an object's children hang from.
    fn child_frame(&self, h: Handle) -> Result<Pose, IkError> {
        let hanging = self.get(h)?.hanging();
        Ok(self.world(h)? * hanging)
    }

    /// World pose of the frame an object's local pose is relative to.
    ///
    /// # Errors
    /// No such object.
    pub fn parent_frame(&self, h: Handle) -> Result<Pose, IkError> {
        // Walk up, then compose from the root down; `set_parent` refuses loops, and the
        // bound guards the walk all the same.
        let mut chain = Vec::new();
        let mut cur = self.get(h)?.parent;
        while let Some(p) = cur {
            if chain.len() > self.objects.len() {
                return Err(IkError::BadArgument("the IK object tree has a loop".into()));
            }
            let o = self.get(p)?;
            chain.push(o);
            cur = o.parent;
        }
        Ok(chain
            .iter()
            .rev()
            .fold(Pose::identity(), |acc, o| acc * o.local * o.hanging()))
    }

    /// World pose of reference frame `rel` for object `h`: `-1` the world, `-11` the
    /// parent's frame, else object `rel`'s hanging frame (a joint's moving frame), as
    /// `sim.getObjectMatrix` reads it.
    ///
    /// # Errors
    /// No such object (`h` or `rel`).
    pub fn frame(&self, h: Handle, rel: Handle) -> Result<Pose, IkError> {
        match rel {
            HANDLE_WORLD => Ok(Pose::identity()),
            HANDLE_PARENT => self.parent_frame(h),
            r => self.child_frame(r),
        }
    }

    /// The pose of `h` in frame `rel` (see [`IkObjects::frame`]).
    ///
    /// # Errors
    /// No such object.
    pub fn pose_relative(&self, h: Handle, rel: Handle) -> Result<Pose, IkError> {
        Ok(self.frame(h, rel)?.inverse() * self.world(h)?)
    }

    /// Places `h` so that its pose in frame `rel` is `pose`; its children move with it.
    ///
    /// # Errors
    /// No such object.
    pub fn set_pose_relative(&mut self, h: Handle, rel: Handle, pose: Pose) -> Result<(), IkError> {
        let world = self.frame(h, rel)? * pose;
        let local = self.parent_frame(h)?.inverse() * world;
        self.get_mut(h)?.local = local;
        Ok(())
    }

    /// The parent of `h` (`None` at the root).
    ///
    /// # Errors
    /// No such object.
    pub fn parent(&self, h: Handle) -> Result<Option<Handle>, IkError> {
        Ok(self.get(h)?.parent)
    }

    /// Makes `parent` (`None`: the root) the parent of `h`. With `keep_in_place` the
    /// object keeps its world pose, otherwise its local pose.
    ///
    /// # Errors
    /// No such object, or a parent that is `h` itself or hangs below it.
    pub fn set_parent(&mut self, h: Handle, parent: Option<Handle>, keep_in_place: bool) -> Result<(), IkError> {
        let world = self.world(h)?;
        if let Some(p) = parent {
            self.get(p)?;
            let mut cur = Some(p);
            while let Some(c) = cur {
                if c == h {
                    return Err(IkError::BadArgument(format!(
                        "IK object {p} cannot become the parent of {h}: it is {h} itself or hangs below it"
                    )));
                }
                cur = self.get(c)?.parent;
            }
        }
        self.get_mut(h)?.parent = parent;
        if keep_in_place {
            let local = self.parent_frame(h)?.inverse() * world;
            self.get_mut(h)?.local = local;
        }
        Ok(())
    }

    /// Links dummy `a` to dummy `b` (`None` unlinks `a`); a link is mutual, and each
    /// dummy has at most one, so earlier partners are unlinked.
    ///
    /// # Errors
    /// No such object, not a dummy, or `a == b`.
    pub fn set_linked(&mut self, a: Handle, b: Option<Handle>) -> Result<(), IkError> {
        let old = self.linked(a)?;
        if let Some(b) = b {
            if a == b {
                return Err(IkError::BadArgument(format!("IK dummy {a} cannot be linked to itself")));
            }
            self.linked(b)?;
        }
        for d in [old, b.and_then(|b| self.linked(b).ok().flatten())]
            .into_iter()
            .flatten()
        {
            self.set_link_field(d, None)?;
        }
        self.set_link_field(a, b)?;
        if let Some(b) = b {
            self.set_link_field(b, Some(a))?;
        }
        Ok(())
    }

    fn set_link_field(&mut self, d: Handle, to: Option<Handle>) -> Result<(), IkError> {
        match &mut self.get_mut(d)?.kind {
            IkObjectKind::Dummy { linked } => {
                *linked = to;
                Ok(())
            }
            IkObjectKind::Joint(_) => Err(IkError::WrongKind {
                handle: d,
                expected: "dummy",
            }),
        }
    }

    /// The dummy `d` is linked to.
    ///
    /// # Errors
    /// No such object, or not a dummy.
    pub fn linked(&self, d: Handle) -> Result<Option<Handle>, IkError> {
        match self.get(d)?.kind {
            IkObjectKind::Dummy { linked } => Ok(linked),
            IkObjectKind::Joint(_) => Err(IkError::WrongKind {
                handle: d,
                expected: "dummy",
            }),
        }
    }

    /// Sets a joint's position (rad or m), wrapped or clamped to its interval as
    /// CoppeliaSim does.
    ///
    /// # Errors
    /// No such object, not a joint, or a non-finite value.
    pub fn set_joint_position(&mut self, h: Handle, q: f64) -> Result<(), IkError> {
        if !q.is_finite() {
            return Err(IkError::BadArgument(format!("joint position must be finite, got {q}")));
        }
        let j = self.joint_mut(h)?;
        j.position = j.constrain(q);
        Ok(())
    }

    /// Sets whether the solver moves a joint.
    ///
    /// # Errors
    /// No such object, or not a joint.
    pub fn set_joint_mode(&mut self, h: Handle, mode: IkJointMode) -> Result<(), IkError> {
        self.joint_mut(h)?.mode = mode;
        Ok(())
    }

    /// Sets a joint's interval: cyclic (revolute only; the interval is then (-pi, pi]
    /// whatever `min` and `range` say, as in CoppeliaSim), or `[min, min + range]`. The
    /// position is brought into the new interval.
    ///
    /// # Errors
    /// No such object, not a joint, a cyclic prismatic joint, a non-finite bound or a
    /// negative range (min above max).
    pub fn set_joint_interval(&mut self, h: Handle, cyclic: bool, min: f64, range: f64) -> Result<(), IkError> {
        let j = self.joint_mut(h)?;
        if cyclic {
            if j.joint_type != JointType::Revolute {
                return Err(IkError::BadArgument(format!(
                    "IK joint {h} is prismatic: only a revolute joint can be cyclic"
                )));
            }
            j.cyclic = true;
            j.min = -std::f64::consts::PI;
            j.range = 2.0 * std::f64::consts::PI;
        } else {
            if !(min.is_finite() && range.is_finite()) {
                return Err(IkError::BadArgument(format!(
                    "joint interval must be finite, got min {min}, range {range}"
                )));
            }
            if range < 0.0 {
                return Err(IkError::BadArgument(format!(
                    "joint interval {{min, range}} has a negative range {range} (min {min} above max {})",
                    min + range
                )));
            }
            j.cyclic = false;
            j.min = min;
            j.range = range;
        }
        j.position = j.constrain(j.position);
        Ok(())
    }

    /// Erases an object (`simIK.eraseObject`). Its children keep their world pose and
    /// hang from its parent instead; a dummy linked to it is unlinked.
    ///
    /// # Errors
    /// No such object.
    pub fn erase(&mut self, h: Handle) -> Result<(), IkError> {
        let parent = self.parent(h)?;
        if self.linked(h).is_ok() {
            self.set_linked(h, None)?;
        }
        let children: Vec<Handle> = self
            .objects
            .iter()
            .filter(|(_, o)| o.parent == Some(h))
            .map(|(&c, _)| c)
            .collect();
        for c in children {
            self.set_parent(c, parent, true)?;
        }
        self.objects.remove(&h);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &Pose, b: &Pose) -> bool {
        (a.translation.vector - b.translation.vector).norm() < 1e-12 && a.rotation.angle_to(&b.rotation) < 1e-12
    }

    #[test]
    fn children_hang_from_a_joints_moving_frame_and_keep_in_place_on_reparenting() {
        let mut o = IkObjects::default();
        let j = o.create_joint(JointType::Revolute, "j").expect("joint");
        let d = o.create_dummy("").expect("dummy");
        assert!(is_own_object(j) && is_own_object(d));
        o.set_pose_relative(d, HANDLE_WORLD, Pose::translation(1.0, 0.0, 0.0))
            .expect("place");
        o.set_joint_position(j, std::f64::consts::FRAC_PI_2).expect("position");
        o.set_parent(d, Some(j), true).expect("parent");
        // Kept in place: the moving frame's rotation is undone by the local pose.
        assert!(close(&o.world(d).expect("world"), &Pose::translation(1.0, 0.0, 0.0)));
        o.set_joint_position(j, 0.0).expect("position");
        let p = o.world(d).expect("world").translation.vector;
        assert!((p - Vec3::new(0.0, -1.0, 0.0)).norm() < 1e-12, "{p}");
        // Relative to the joint: its moving frame, in which the dummy sits where the
        // re-parenting put it (turned back by the quarter turn the joint had then).
        let rel = o.pose_relative(d, j).expect("relative");
        let expected = Pose::translation(0.0, -1.0, 0.0) * Pose::rotation(Vec3::z() * -std::f64::consts::FRAC_PI_2);
        assert!(close(&rel, &expected), "{rel}");
        assert!(o.set_parent(j, Some(d), true).is_err(), "a loop");
        assert_eq!(o.by_name("j"), Some(j));
        assert!(o.create_dummy("j").is_err(), "duplicate name");
    }

    #[test]
    fn intervals_clamp_and_cyclic_wraps() {
        let mut o = IkObjects::default();
        let r = o.create_joint(JointType::Revolute, "").expect("joint");
        let p = o.create_joint(JointType::Prismatic, "").expect("joint");
        o.set_joint_position(r, 4.0).expect("wrap");
        assert!((o.joint(r).expect("j").position - (4.0 - 2.0 * std::f64::consts::PI)).abs() < 1e-12);
        o.set_joint_interval(r, false, -1.0, 1.5).expect("interval");
        assert_eq!(o.joint(r).expect("j").position, -1.0);
        o.set_joint_position(r, 2.0).expect("clamp");
        assert_eq!(o.joint(r).expect("j").position, 0.5);
        assert!(o.set_joint_interval(r, false, 1.0, -0.5).is_err());
        assert!(o.set_joint_interval(p, true, 0.0, 1.0).is_err());
        assert_eq!(o.joint(p).expect("j").limits(), Some((-0.5, 0.5)));
    }

    #[test]
    fn links_are_mutual_and_erasing_unlinks_and_reparents() {
        let mut o = IkObjects::default();
        let [a, b, c] = [0, 1, 2].map(|_| o.create_dummy("").expect("dummy"));
        o.set_linked(a, Some(b)).expect("link");
        assert_eq!((o.linked(a).ok(), o.linked(b).ok()), (Some(Some(b)), Some(Some(a))));
        o.set_linked(c, Some(b)).expect("relink");
        assert_eq!(o.linked(a).expect("a"), None);
        o.set_parent(a, Some(c), false).expect("parent");
        o.erase(c).expect("erase");
        assert_eq!(o.linked(b).expect("b"), None);
        assert_eq!(o.parent(a).expect("a"), None);
        assert!(o.get(c).is_err());
    }
}
