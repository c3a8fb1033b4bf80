//! The rapier side of the world: how objects map onto bodies, colliders and joints, and
//! the synchronisation before and after each physics step.
//!
//! Mapping (CoppeliaSim's rules, decided once when the world is built):
//! - A **dynamic shape** is its own dynamic body. If a dynamic-mode joint lies between it
//!   and the next body up the tree, it is a link of a rapier *multibody* (reduced
//!   coordinates: no joint drift); if a force sensor lies there, it is welded to that body
//!   by an impulse fixed joint whose impulses give the sensor reading; otherwise it moves
//!   freely (a dynamic child of a shape without a joint is simulated on its own, as in
//!   CoppeliaSim).
//! - A **non-dynamic shape** is a collider of the nearest shape above it when nothing
//!   movable lies in between (so it moves with that shape); below a joint or force sensor
//!   it is a *kinematic* body whose pose the tree dictates every step (kinematic-mode
//!   joints, the paper's arm); at the top of the tree it is a fixed body.
//!
//! The object tree (f64) is the source of truth for poses. After a step only two things
//! are read back from rapier: the poses of free bodies (including multibody roots) and
//! the positions of dynamic joints. Everything else follows by forward kinematics in the
//! tree, which is why kinematic chains are exact to f64 precision.

use std::collections::HashMap;

use rapier3d::prelude::*;

use super::object::{Handle, ObjectKind};
use crate::math::{self, Pose};
use crate::scene::{Geometry, JointMode, JointType, MassModel, ShapeModel, SimSettings};

/// How a body moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum BodyRole {
    /// Never moves.
    Fixed,
    /// Follows its object's tree pose each step.
    Kinematic,
    /// Simulated; its pose is read back after each step.
    Free,
    /// Simulated as a multibody link; its pose follows from the joint position.
    Link,
}

/// A rapier body and the object that owns it.
#[derive(Debug, Clone)]
pub(crate) struct BodyEntry {
    pub handle: RigidBodyHandle,
    pub object: Handle,
    pub role: BodyRole,
}

/// A joint object bound to a multibody link.
#[derive(Debug, Clone, Copy)]
pub(crate) struct JointBinding {
    pub joint: MultibodyJointHandle,
    /// Index of the free coordinate in rapier's 6-vector: 3 = AngX, 0 = LinX.
    pub coord: usize,
    pub axis: JointAxis,
}

/// Rapier state plus the side tables that tie it to objects.
pub(crate) struct Physics {
    pub world: PhysicsWorld,
    pub bodies: Vec<BodyEntry>,
    /// Body index (into `bodies`) of each object that owns or rides on a body, with the
    /// object's pose relative to the body.
    pub body_of: HashMap<Handle, (usize, Pose)>,
    /// Multibody bindings of dynamic-mode joints.
    pub joints: HashMap<Handle, JointBinding>,
    /// Force sensors bound to impulse joints.
    pub force_joints: HashMap<Handle, ImpulseJointHandle>,
    /// Which object each collider belongs to, for sensor results.
    pub collider_object: HashMap<ColliderHandle, Handle>,
    /// Colliders of each shape object, in creation order (deterministic iteration).
    pub object_colliders: HashMap<Handle, Vec<ColliderHandle>>,
    /// rapier steps per simulation step (1 unless collisions run at every substep).
    pub rapier_steps: u32,
}

/// Rotation taking rapier's joint axis (local X) onto ours (local Z).
fn x_to_z() -> Pose {
    Pose::rotation(nalgebra::Vector3::y() * (-std::f64::consts::FRAC_PI_2))
}

/// What the tree says lies directly above an object, physically.
enum Above {
    Root,
    Shape(Handle),
    Joint(Handle),
    ForceSensor(Handle),
}

/// Read-only view of the tree used while building.
pub(crate) struct TreeView<'a> {
    pub parent: &'a dyn Fn(Handle) -> Option<Handle>,
    pub kind: &'a dyn Fn(Handle) -> &'a ObjectKind,
    pub world: &'a dyn Fn(Handle) -> Pose,
}

fn above(tree: &TreeView<'_>, h: Handle) -> Above {
    let mut cur = (tree.parent)(h);
    while let Some(p) = cur {
        match (tree.kind)(p) {
            ObjectKind::Shape(_) => return Above::Shape(p),
            ObjectKind::Joint(_) => return Above::Joint(p),
            ObjectKind::ForceSensor(_) => return Above::ForceSensor(p),
            _ => cur = (tree.parent)(p),
        }
    }
    Above::Root
}

impl Physics {
    /// Builds rapier bodies, colliders and joints for `order` (parents before children).
    pub fn build(tree: &TreeView<'_>, order: &[Handle], settings: &SimSettings, warnings: &mut Vec<String>) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = math::vec_to_physics(&settings.gravity.into());
        let rapier_steps = configure_integration(&mut world.integration_parameters, settings);
        let mut p = Physics {
            world,
            bodies: Vec::new(),
            body_of: HashMap::new(),
            joints: HashMap::new(),
            force_joints: HashMap::new(),
            collider_object: HashMap::new(),
            object_colliders: HashMap::new(),
            rapier_steps,
        };
        // A fixed body at the world origin anchors joints whose parent side is the world.
        let mut anchor: Option<usize> = None;
        for &h in order {
            let ObjectKind::Shape(shape) = (tree.kind)(h) else {
                continue;
            };
            let pose = (tree.world)(h);
            let placement = above(tree, h);
            if shape.dynamic {
                match placement {
                    Above::Joint(j) => {
                        let ObjectKind::Joint(joint) = (tree.kind)(j) else {
                            unreachable!("above() returned a joint")
                        };
                        // A fixed joint has nothing to drive: its dynamic child is a rigid
                        // multibody link whatever the mode says.
                        if joint.mode == JointMode::Kinematic && joint.joint_type != JointType::Fixed {
                            p.new_body(h, &pose, BodyRole::Kinematic, shape);
                        } else {
                            let parent_body = p.parent_body(tree, j, &mut anchor);
                            let child = p.new_body(h, &pose, BodyRole::Link, shape);
                            p.add_multibody_joint(tree, j, parent_body, child, warnings);
                        }
                    }
                    Above::ForceSensor(f) => {
                        let parent_body = p.parent_body(tree, f, &mut anchor);
                        let child = p.new_body(h, &pose, BodyRole::Free, shape);
                        p.add_force_joint(tree, f, parent_body, child);
                    }
                    Above::Shape(_) | Above::Root => {
                        p.new_body(h, &pose, BodyRole::Free, shape);
                    }
                }
            } else {
                match placement {
                    Above::Shape(s) => match p.body_of.get(&s).copied() {
                        Some((bi, offset)) => {
                            let rel = offset * (tree.world)(s).inverse() * pose;
                            p.body_of.insert(h, (bi, rel));
                            p.add_colliders(h, bi, &rel, shape);
                        }
                        None => {
                            p.new_body(h, &pose, BodyRole::Fixed, shape);
                        }
                    },
                    Above::Joint(_) | Above::ForceSensor(_) => {
                        p.new_body(h, &pose, BodyRole::Kinematic, shape);
                    }
                    Above::Root => {
                        p.new_body(h, &pose, BodyRole::Fixed, shape);
                    }
                }
            }
        }
        for &h in order {
            if let ObjectKind::Joint(j) = (tree.kind)(h)
                && j.mode != JointMode::Kinematic
                && j.joint_type != JointType::Fixed
                && !p.joints.contains_key(&h)
            {
                warnings.push(format!(
                    "joint {h} is in {:?} mode but has no dynamic shape below it, so it cannot move; make its child shape dynamic or use kinematic mode",
                    j.mode
                ));
            }
        }
        p
    }

    /// The body index on the parent side of joint or force sensor `j`.
    fn parent_body(&mut self, tree: &TreeView<'_>, j: Handle, anchor: &mut Option<usize>) -> usize {
        match above(tree, j) {
            Above::Shape(s) => {
                if let Some((bi, _)) = self.body_of.get(&s) {
                    return *bi;
                }
                self.anchor(anchor)
            }
            _ => self.anchor(anchor),
        }
    }

    fn anchor(&mut self, anchor: &mut Option<usize>) -> usize {
        *anchor.get_or_insert_with(|| {
            let handle = self.world.insert_body(RigidBodyBuilder::fixed());
            self.bodies.push(BodyEntry {
                handle,
                object: -1,
                role: BodyRole::Fixed,
            });
            self.bodies.len() - 1
        })
    }

    fn new_body(&mut self, h: Handle, pose: &Pose, role: BodyRole, shape: &ShapeModel) -> usize {
        let builder = match role {
            BodyRole::Fixed => RigidBodyBuilder::fixed(),
            BodyRole::Kinematic => RigidBodyBuilder::kinematic_position_based(),
            // Robots must never fall asleep: a sleeping island ignores new motor targets
            // (rapier 0.36 does not wake it when a multibody target changes).
            BodyRole::Free | BodyRole::Link => RigidBodyBuilder::dynamic().can_sleep(false),
        };
        let mut builder = builder.pose(math::to_physics(pose));
        if let MassModel::Inertial {
            mass,
            com,
            frame,
            inertia,
        } = shape.mass
        {
            let [ixx, ixy, ixz, iyy, iyz, izz] = inertia;
            let m = nalgebra::Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz);
            let r = math::quat_from_array(frame).unwrap_or_else(math::Quat::identity);
            let rm = r.to_rotation_matrix();
            let i = rm.matrix() * m * rm.matrix().transpose();
            let mat = rapier3d::math::Matrix::from_cols_array(&[
                i[(0, 0)] as f32,
                i[(1, 0)] as f32,
                i[(2, 0)] as f32,
                i[(0, 1)] as f32,
                i[(1, 1)] as f32,
                i[(2, 1)] as f32,
                i[(0, 2)] as f32,
                i[(1, 2)] as f32,
                i[(2, 2)] as f32,
            ]);
            let com = rapier3d::math::Vector::new(com[0] as f32, com[1] as f32, com[2] as f32);
            builder = builder.additional_mass_properties(MassProperties::with_inertia_matrix(com, mass as f32, mat));
        }
        let handle = self.world.insert_body(builder);
        self.bodies.push(BodyEntry {
            handle,
            object: h,
            role,
        });
        let bi = self.bodies.len() - 1;
        self.body_of.insert(h, (bi, Pose::identity()));
        self.add_colliders(h, bi, &Pose::identity(), shape);
        bi
    }

    /// Adds one collider per geometry part of `shape`, placed at `rel` in the body frame.
    fn add_colliders(&mut self, h: Handle, bi: usize, rel: &Pose, shape: &ShapeModel) {
        let volume: f64 = shape.geoms.iter().map(|g| geometry_volume(&g.geometry)).sum();
        let density = match shape.mass {
            MassModel::Density(d) => d,
            MassModel::Mass(m) if volume > 0.0 => m / volume,
            MassModel::Mass(_) => 0.0,
            // Explicit inertials carry the whole mass; colliders add none.
            MassModel::Inertial { .. } => 0.0,
        };
        let groups = InteractionGroups::new(
            Group::from_bits_retain(shape.collision_group),
            Group::from_bits_retain(shape.collision_mask),
            InteractionTestMode::And,
        );
        for g in &shape.geoms {
            let (shared, fix) = shared_shape(&g.geometry);
            let local = rel * g.local * fix;
            let collider = ColliderBuilder::new(shared)
                .position(math::to_physics(&local))
                .density(density as f32)
                .friction(shape.friction as f32)
                .restitution(shape.restitution as f32)
                .collision_groups(groups)
                .solver_groups(groups)
                .sensor(!shape.respondable)
                .build();
            let body = self.bodies[bi].handle;
            let ch = self.world.insert_collider(collider, Some(body));
            self.collider_object.insert(ch, h);
            self.object_colliders.entry(h).or_default().push(ch);
        }
    }

    fn add_multibody_joint(
        &mut self,
        tree: &TreeView<'_>,
        j: Handle,
        parent: usize,
        child: usize,
        warnings: &mut Vec<String>,
    ) {
        let ObjectKind::Joint(joint) = (tree.kind)(j) else {
            return;
        };
        let joint_world = (tree.world)(j);
        let parent_world = self.body_world(tree, parent);
        let child_world = (tree.world)(self.bodies[child].object);
        // Our joints move about/along local Z; rapier's free axis is the frame's X.
        let frame = joint_world * x_to_z();
        let frame1 = parent_world.inverse() * frame;
        // The child body's pose is its pose at the current joint position; the joint
        // frame on the child side is the moving frame, i.e. after the motion.
        let frame2 = child_world.inverse() * joint_world * joint.motion() * x_to_z();
        let (mut data, axis, coord) = match joint.joint_type {
            JointType::Revolute => (
                GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES).build(),
                JointAxis::AngX,
                3,
            ),
            JointType::Prismatic => (
                GenericJointBuilder::new(JointAxesMask::LOCKED_PRISMATIC_AXES).build(),
                JointAxis::LinX,
                0,
            ),
            JointType::Fixed => (
                GenericJointBuilder::new(JointAxesMask::LOCKED_FIXED_AXES).build(),
                JointAxis::AngX,
                3,
            ),
        };
        data.set_local_frame1(math::to_physics(&frame1));
        data.set_local_frame2(math::to_physics(&frame2));
        data.set_contacts_enabled(false);
        if joint.joint_type != JointType::Fixed {
            if let Some((lo, hi)) = joint.limits {
                data.set_limits(axis, [lo as f32, hi as f32]);
            }
            data.set_motor_model(axis, MotorModel::ForceBased);
            configure_motor(&mut data, axis, joint);
        }
        let (b1, b2) = (self.bodies[parent].handle, self.bodies[child].handle);
        match self.world.multibody_joints.insert(b1, b2, data, true) {
            Some(handle) => {
                if joint.joint_type != JointType::Fixed {
                    self.joints.insert(
                        j,
                        JointBinding {
                            joint: handle,
                            coord,
                            axis,
                        },
                    );
                    // frame2 was taken at the tree's current position q0, so rapier's
                    // coordinate must start at q0 too for the two to agree.
                    if let Some((mb, link)) = self.world.multibody_joints.get_mut(handle)
                        && let Some(l) = mb.link_mut(link)
                    {
                        let mut disp = [0.0f32; 6];
                        disp[0] = joint.position as f32;
                        l.joint.apply_displacement(&disp[..l.joint.ndofs()]);
                    }
                }
            }
            None => warnings.push(format!(
                "joint {j}: closes a kinematic loop; rapier multibodies must be trees, the joint was not simulated"
            )),
        }
    }

    fn add_force_joint(&mut self, tree: &TreeView<'_>, f: Handle, parent: usize, child: usize) {
        let sensor_world = (tree.world)(f);
        let frame1 = self.body_world(tree, parent).inverse() * sensor_world;
        let frame2 = (tree.world)(self.bodies[child].object).inverse() * sensor_world;
        let data = GenericJointBuilder::new(JointAxesMask::LOCKED_FIXED_AXES)
            .local_frame1(math::to_physics(&frame1))
            .local_frame2(math::to_physics(&frame2))
            .contacts_enabled(false)
            .build();
        let (b1, b2) = (self.bodies[parent].handle, self.bodies[child].handle);
        let handle = self.world.insert_impulse_joint(b1, b2, data);
        self.force_joints.insert(f, handle);
    }

    fn body_world(&self, tree: &TreeView<'_>, bi: usize) -> Pose {
        match self.bodies[bi].object {
            -1 => Pose::identity(),
            h => (tree.world)(h),
        }
    }
}

/// rapier's settings for one simulation step of `dt` seconds split into `substeps`;
/// returns how many rapier steps make one simulation step.
///
/// By default, one rapier step per simulation step with the substeps done inside the
/// solver: rapier's soft-TGS solver re-linearises every constraint (contacts, joints,
/// motors) and integrates positions at each of its `num_solver_iterations` substeps, so
/// joints and motors see `dt / substeps` as with separate steps, while collision detection
/// runs once per step instead of once per substep. For robots this is as accurate
/// (contacts within the prediction distance are followed through every substep) and
/// several times cheaper; docs/performance.md has the measurements behind the choice.
/// `collisions_every_substep` restores separate rapier steps of `dt / substeps`, each with
/// one solver iteration, for scenes with fast impacts.
pub(crate) fn configure_integration(p: &mut IntegrationParameters, s: &SimSettings) -> u32 {
    let n = s.substeps.max(1);
    if s.collisions_every_substep {
        p.dt = (s.dt / f64::from(n)) as f32;
        p.num_solver_iterations = 1;
        n
    } else {
        p.dt = s.dt as f32;
        p.num_solver_iterations = n as usize;
        1
    }
}

/// Sets a joint's motor from its mode and targets (ForceBased: torque = kp e + kd ė).
pub(crate) fn configure_motor(data: &mut GenericJoint, axis: JointAxis, joint: &super::object::Joint) {
    match joint.mode {
        JointMode::Position => {
            data.set_motor(
                axis,
                joint.target_position as f32,
                0.0,
                joint.kp as f32,
                joint.kd as f32,
            );
        }
        JointMode::Velocity => {
            data.set_motor(axis, 0.0, joint.target_velocity as f32, 0.0, joint.kd as f32);
        }
        JointMode::Kinematic => {
            data.set_motor(axis, 0.0, 0.0, 0.0, 0.0);
        }
    }
    data.set_motor_max_force(axis, joint.max_force as f32);
}

/// A parry shape for a geometry, and the pose correction from parry's axis convention
/// (cylinders and capsules along Y) to ours (along Z).
fn shared_shape(g: &Geometry) -> (SharedShape, Pose) {
    let y_to_z = Pose::rotation(nalgebra::Vector3::x() * std::f64::consts::FRAC_PI_2);
    match g {
        Geometry::Box {
            half_extents: [x, y, z],
        } => (SharedShape::cuboid(*x as f32, *y as f32, *z as f32), Pose::identity()),
        Geometry::Sphere { radius } => (SharedShape::ball(*radius as f32), Pose::identity()),
        Geometry::Cylinder { radius, length } => {
            (SharedShape::cylinder((*length / 2.0) as f32, *radius as f32), y_to_z)
        }
        Geometry::Capsule { radius, length } => (
            SharedShape::capsule_z((*length / 2.0) as f32, *radius as f32),
            Pose::identity(),
        ),
        Geometry::Mesh(m) => {
            let vertices = m
                .vertices
                .iter()
                .map(|v| rapier3d::math::Vector::new(v[0], v[1], v[2]))
                .collect();
            match SharedShape::trimesh(vertices, m.indices.clone()) {
                Ok(s) => (s, Pose::identity()),
                // A degenerate mesh (no area) cannot collide; a tiny ball keeps the body valid.
                Err(_) => (SharedShape::ball(1e-4), Pose::identity()),
            }
        }
    }
}

/// Volume of a geometry, m³ (meshes: of their bounding box, a documented approximation
/// used only to spread a given total mass).
fn geometry_volume(g: &Geometry) -> f64 {
    use std::f64::consts::PI;
    match g {
        Geometry::Box {
            half_extents: [x, y, z],
        } => 8.0 * x * y * z,
        Geometry::Sphere { radius } => 4.0 / 3.0 * PI * radius.powi(3),
        Geometry::Cylinder { radius, length } => PI * radius * radius * length,
        Geometry::Capsule { radius, length } => PI * radius * radius * length + 4.0 / 3.0 * PI * radius.powi(3),
        Geometry::Mesh(m) => {
            let mut lo = [f64::MAX; 3];
            let mut hi = [f64::MIN; 3];
            for v in &m.vertices {
                for i in 0..3 {
                    lo[i] = lo[i].min(f64::from(v[i]));
                    hi[i] = hi[i].max(f64::from(v[i]));
                }
            }
            (0..3).map(|i| (hi[i] - lo[i]).max(0.0)).product()
        }
    }
}
