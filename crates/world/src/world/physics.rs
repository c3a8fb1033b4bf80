//! The rapier side of the world: how objects map onto bodies, colliders and joints, and
//! the synchronisation before and after each physics step.
//!
//! Mapping (CoppeliaSim's rules, applied when the world is built and again to the part of
//! the tree a run-time edit touches, see `World`'s scene editing):
//! - A **dynamic shape** is its own dynamic body. If a dynamic-mode joint lies between it
//!   and the next body up the tree, it is a link of a rapier *multibody* (reduced
//!   coordinates: no joint drift); if a force sensor lies there, it is welded to that body
//!   by an impulse fixed joint whose impulses give the sensor reading; otherwise it moves
//!   freely (a dynamic child of a shape without a joint is simulated on its own, as in
//!   CoppeliaSim).
//! - A dynamic shape welded by a **fixed joint** to a dynamic body is **fused** into that
//!   body: its colliders and its inertial join the body's, as MuJoCo's compiler fuses
//!   static bodies. A multibody link without a degree of freedom would cost rapier as
//!   much as a moving one at every step (its share of the mass matrix, its Jacobian, its
//!   forward kinematics), and URDF robots are full of them: tool frames, flanges, a hand
//!   on its wrist.
//! - A **non-dynamic shape** is a collider of the nearest shape above it when nothing
//!   movable lies in between (so it moves with that shape); below a joint or force sensor
//!   it is a *kinematic* body whose pose the tree dictates every step (kinematic-mode
//!   joints, the paper's arm); at the top of the tree it is a fixed body.
//!
//! Links of one mechanism (a URDF robot, unless its `self_collision` is set) do not
//! collide with each other: the multibody's self-contacts are off, which rapier checks
//! before any contact is computed. Joined parent and child links never collide.
//!
//! Mesh colliders: a dynamic body collides with convex hulls (one per part of a
//! multi-part OBJ, as PyBullet does), because triangle meshes have no inside and give
//! dynamic bodies poor contacts; a non-convex one-part mesh on a dynamic body is warned
//! about. Static and kinematic bodies keep the triangle mesh, concavities included.
//!
//! The object tree (f64) is the source of truth for poses. After a step only two things
//! are read back from rapier: the poses of free bodies (including multibody roots) and
//! the positions of dynamic joints. Everything else follows by forward kinematics in the
//! tree, which is why kinematic chains are exact to f64 precision.

use std::collections::HashMap;

use rapier3d::prelude::*;

use super::object::{Handle, ObjectKind};
use super::property_flags::model_property;
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
    /// The owner's explicit inertial in the body frame (URDF `<inertial>`), which the
    /// body's mass adds to those of the shapes fused into it; `None` when its mass comes
    /// from its colliders.
    pub inertial: Option<MassProperties>,
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
    /// Dummy links (`sim.setLinkDummy`): the first dummy's partner and the fixed
    /// impulse joint that makes their frames coincide (CoppeliaSim's dynamic loop
    /// closure, which suction pads and attachments use).
    pub dummy_links: HashMap<Handle, (Handle, ImpulseJointHandle)>,
    /// Which object each collider belongs to, for sensor results.
    pub collider_object: HashMap<ColliderHandle, Handle>,
    /// Colliders of each shape object, in creation order (deterministic iteration).
    pub object_colliders: HashMap<Handle, Vec<ColliderHandle>>,
    /// Dynamic shapes fused into the body of the shape they are welded to (a fixed
    /// joint between them), with their explicit inertial in that body's frame; they
    /// also ride on it in `body_of`.
    pub fused: HashMap<Handle, Option<MassProperties>>,
    /// rapier steps per simulation step (1 unless collisions run at every substep).
    pub rapier_steps: u32,
    /// Index in `bodies` of the fixed body at the world origin, once one was needed.
    pub anchor: Option<usize>,
}

/// A copy of the whole physical state: bodies, colliders, joints, islands, the broad and
/// narrow phases (contacts and their warm-start impulses) and the side tables. rapier's
/// pipelines are workspaces that hold no state between steps, so the copy gets fresh
/// ones (`PhysicsWorld` itself is not `Clone` for that reason). The engine copies the
/// world at a start to restore it at the stop.
impl Clone for Physics {
    fn clone(&self) -> Self {
        let w = &self.world;
        Physics {
            world: PhysicsWorld {
                gravity: w.gravity,
                integration_parameters: w.integration_parameters,
                physics_pipeline: PhysicsPipeline::new(),
                collision_pipeline: CollisionPipeline::new(),
                islands: w.islands.clone(),
                broad_phase: w.broad_phase.clone(),
                narrow_phase: w.narrow_phase.clone(),
                bodies: w.bodies.clone(),
                colliders: w.colliders.clone(),
                impulse_joints: w.impulse_joints.clone(),
                multibody_joints: w.multibody_joints.clone(),
                soft_bodies: w.soft_bodies.clone(),
                ccd_solver: w.ccd_solver.clone(),
            },
            bodies: self.bodies.clone(),
            body_of: self.body_of.clone(),
            joints: self.joints.clone(),
            force_joints: self.force_joints.clone(),
            dummy_links: self.dummy_links.clone(),
            collider_object: self.collider_object.clone(),
            object_colliders: self.object_colliders.clone(),
            fused: self.fused.clone(),
            rapier_steps: self.rapier_steps,
            anchor: self.anchor,
        }
    }
}

/// `BodyEntry::object` of a slot whose body was removed (the anchor is -1).
pub(crate) const REMOVED_BODY: Handle = Handle::MIN;

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
    /// The object's cumulative model property (`sim.modelproperty_*` overrides).
    pub overrides: &'a dyn Fn(Handle) -> i64,
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
            dummy_links: HashMap::new(),
            collider_object: HashMap::new(),
            object_colliders: HashMap::new(),
            fused: HashMap::new(),
            rapier_steps,
            anchor: None,
        };
        p.insert(tree, order, warnings);
        p
    }

    /// Adds the bodies, colliders and joints of the objects in `order` (parents before
    /// children), placed by the rules in the module docs. Whatever lies above them must
    /// already be in place: the whole tree when the world is built, or the rest of the
    /// scene when part of it is rebuilt after an edit (`World`'s scene editing).
    pub fn insert(&mut self, tree: &TreeView<'_>, order: &[Handle], warnings: &mut Vec<String>) {
        for &h in order {
            self.place(tree, h, warnings);
        }
        for &h in order {
            if let ObjectKind::Joint(j) = (tree.kind)(h)
                && j.mode.is_dynamic()
                && j.joint_type != JointType::Fixed
                && !self.joints.contains_key(&h)
            {
                warnings.push(format!(
                    "joint {h} is in {} mode but has no dynamic shape below it, so it cannot move; make its child shape dynamic or use kinematic mode",
                    j.mode.name()
                ));
            }
        }
        self.couple_mimics(tree, order, warnings);
    }

    /// Gives shape `h` its body or colliders (anything else has none of its own).
    fn place(&mut self, tree: &TreeView<'_>, h: Handle, warnings: &mut Vec<String>) {
        let ObjectKind::Shape(shape) = (tree.kind)(h) else {
            return;
        };
        // A model above may override the shape's own flags (`sim.setModelProperty`).
        let overridden;
        let shape: &ShapeModel =
            match (tree.overrides)(h) & (model_property::NOT_DYNAMIC | model_property::NOT_RESPONDABLE) {
                0 => shape,
                flags => {
                    overridden = ShapeModel {
                        dynamic: shape.dynamic && flags & model_property::NOT_DYNAMIC == 0,
                        respondable: shape.respondable && flags & model_property::NOT_RESPONDABLE == 0,
                        ..ShapeModel::clone(shape)
                    };
                    &overridden
                }
            };
        let pose = (tree.world)(h);
        let placement = above(tree, h);
        if shape.dynamic {
            match placement {
                Above::Joint(j) => {
                    let ObjectKind::Joint(joint) = (tree.kind)(j) else {
                        unreachable!("above() returned a joint")
                    };
                    // A fixed joint has nothing to drive: its dynamic child is fused into
                    // the dynamic body above, or else a rigid multibody link, whatever
                    // the mode says.
                    if !joint.mode.is_dynamic() && joint.joint_type != JointType::Fixed {
                        self.new_body(h, &pose, BodyRole::Kinematic, shape, warnings);
                    } else if let Some((s, (bi, offset))) = self.weld_target(tree, j)
                        && self.fuse(h, bi, offset * (tree.world)(s).inverse() * pose, shape, warnings)
                    {
                        // Fused into the body above.
                    } else {
                        let parent_body = self.parent_body(tree, j);
                        let child = self.new_body(h, &pose, BodyRole::Link, shape, warnings);
                        self.add_multibody_joint(tree, j, parent_body, child, shape.self_collision, warnings);
                    }
                }
                Above::ForceSensor(f) => {
                    let parent_body = self.parent_body(tree, f);
                    let child = self.new_body(h, &pose, BodyRole::Free, shape, warnings);
                    self.add_force_joint(tree, f, parent_body, child);
                }
                Above::Shape(_) | Above::Root => {
                    self.new_body(h, &pose, BodyRole::Free, shape, warnings);
                }
            }
        } else {
            match placement {
                Above::Shape(s) => match self.body_of.get(&s).copied() {
                    Some((bi, offset)) => self.ride(tree, h, s, (bi, offset), shape, warnings),
                    None => {
                        self.new_body(h, &pose, BodyRole::Fixed, shape, warnings);
                    }
                },
                Above::Joint(j) if matches!((tree.kind)(j), ObjectKind::Joint(jt) if jt.joint_type == JointType::Fixed) =>
                {
                    // Welded to what is above (the `world` link ROS arm descriptions
                    // start with): ride on its body rather than be a kinematic body of
                    // its own. A multibody rooted on an awake kinematic body is
                    // integrated twice per step by rapier 0.36's solver (the root and
                    // its first link both enlist it), so arms below one fell at twice
                    // the speed.
                    match above(tree, j) {
                        Above::Shape(s) => match self.body_of.get(&s).copied() {
                            Some((bi, offset))
                                if matches!(self.bodies[bi].role, BodyRole::Fixed | BodyRole::Kinematic) =>
                            {
                                self.ride(tree, h, s, (bi, offset), shape, warnings);
                            }
                            _ => {
                                self.new_body(h, &pose, BodyRole::Kinematic, shape, warnings);
                            }
                        },
                        Above::Root => {
                            self.new_body(h, &pose, BodyRole::Fixed, shape, warnings);
                        }
                        Above::Joint(_) | Above::ForceSensor(_) => {
                            self.new_body(h, &pose, BodyRole::Kinematic, shape, warnings);
                        }
                    }
                }
                Above::Joint(_) | Above::ForceSensor(_) => {
                    self.new_body(h, &pose, BodyRole::Kinematic, shape, warnings);
                }
                Above::Root => {
                    self.new_body(h, &pose, BodyRole::Fixed, shape, warnings);
                }
            }
        }
    }

    /// Ties each simulated `<mimic>` follower to its simulated leader with rapier's DoF
    /// coupling (`q_f = m q_l + c` as a velocity-level equality), so the mechanism moves as
    /// one, as a gear would. Followers of kinematic leaders follow in the tree instead
    /// (`World::set_joint_position`).
    pub(crate) fn couple_mimics(&mut self, tree: &TreeView<'_>, order: &[Handle], warnings: &mut Vec<String>) {
        for &h in order {
            let ObjectKind::Joint(j) = (tree.kind)(h) else { continue };
            let Some(m) = j.mimic else { continue };
            let (Some(f), Some(l)) = (self.joints.get(&h).copied(), self.joints.get(&m.leader).copied()) else {
                if j.mode.is_dynamic() != matches!((tree.kind)(m.leader), ObjectKind::Joint(l) if l.mode.is_dynamic()) {
                    warnings.push(format!(
                        "joint {h} mimics joint {}, but one is simulated and the other kinematic; the follower is set from the leader after each step",
                        m.leader
                    ));
                }
                continue;
            };
            let mbj = &mut self.world.multibody_joints;
            let (Some((mb_l, link_l)), Some((mb_f, link_f))) = (mbj.get(l.joint), mbj.get(f.joint)) else {
                continue;
            };
            if !std::ptr::eq(mb_l, mb_f) {
                warnings.push(format!(
                    "joint {h} mimics joint {}, which belongs to another mechanism; the coupling was not simulated",
                    m.leader
                ));
                continue;
            }
            if let Some((mb, _)) = mbj.get_mut(f.joint) {
                mb.add_dof_coupling(MultibodyDofCoupling {
                    link1: link_l,
                    dof1: 0,
                    axis1: l.coord,
                    link2: link_f,
                    dof2: 0,
                    axis2: f.coord,
                    coeff: m.multiplier as f32,
                    offset: m.offset as f32,
                });
            }
        }
    }

    /// Makes shape `h` ride on the body of shape `s`, which sits at `offset` in body
    /// `bi`: its colliders join that body, at their pose relative to it.
    fn ride(
        &mut self,
        tree: &TreeView<'_>,
        h: Handle,
        s: Handle,
        (bi, offset): (usize, Pose),
        shape: &ShapeModel,
        warnings: &mut Vec<String>,
    ) {
        let rel = offset * (tree.world)(s).inverse() * (tree.world)(h);
        self.body_of.insert(h, (bi, rel));
        self.add_colliders(h, bi, &rel, shape, warnings);
    }

    /// The dynamic body that fixed joint `j` welds its child to: the shape directly
    /// above it and its place on its body, when that body is simulated.
    fn weld_target(&self, tree: &TreeView<'_>, j: Handle) -> Option<(Handle, (usize, Pose))> {
        if !matches!((tree.kind)(j), ObjectKind::Joint(joint) if joint.joint_type == JointType::Fixed) {
            return None;
        }
        let Above::Shape(s) = above(tree, j) else {
            return None;
        };
        let &(bi, offset) = self.body_of.get(&s)?;
        matches!(self.bodies[bi].role, BodyRole::Free | BodyRole::Link).then_some((s, (bi, offset)))
    }

    /// Fuses dynamic shape `h` into body `bi`, where a fixed joint welds it at `rel`: it
    /// rides on that body, and its colliders and its inertial join the body's. Returns false, with nothing done, when its colliders are
    /// thinner than the body's: rapier's automatic CCD judges a body fast by its thinnest
    /// collider and then, at every step, recomputes the mass properties of all its
    /// colliders (mesh hulls: microseconds each), so a tool's 1 cm box fused into the
    /// UR5's wrist made the arm 12 % slower where it was to gain.
    fn fuse(&mut self, h: Handle, bi: usize, rel: Pose, shape: &ShapeModel, warnings: &mut Vec<String>) -> bool {
        let pieces = collider_pieces(&rel, shape, true, warnings);
        let thinnest = |shapes: &mut dyn Iterator<Item = &dyn Shape>| {
            shapes.map(Shape::ccd_thickness).fold(Real::INFINITY, Real::min)
        };
        let own = thinnest(&mut pieces.iter().map(|(p, _)| &**p));
        let body = self
            .world
            .bodies
            .get(self.bodies[bi].handle)
            .map_or(Real::INFINITY, |rb| {
                let colliders = &self.world.colliders;
                thinnest(
                    &mut rb
                        .colliders()
                        .iter()
                        .filter_map(|&c| colliders.get(c))
                        .map(|c| c.shape()),
                )
            });
        if own < body {
            return false;
        }
        let inertial = inertial_properties(&shape.mass).map(|p| p.transform_by(&math::to_physics(&rel)));
        self.fused.insert(h, inertial);
        self.body_of.insert(h, (bi, rel));
        self.insert_colliders(h, bi, shape, pieces);
        self.compose_mass(bi);
        true
    }

    /// Sets the explicit inertial of shape `h` (a body's owner or a shape fused into
    /// one), in its own frame, and the body's mass that sums them.
    pub fn set_inertial(&mut self, h: Handle, inertial: Option<MassProperties>) {
        let Some(&(bi, rel)) = self.body_of.get(&h) else {
            return;
        };
        if self.bodies[bi].object == h {
            self.bodies[bi].inertial = inertial;
        } else if let Some(fused) = self.fused.get_mut(&h) {
            *fused = inertial.map(|p| p.transform_by(&math::to_physics(&rel)));
        } else {
            return;
        }
        self.compose_mass(bi);
    }

    /// Gives body `bi` the sum of its owner's explicit inertial and those of the shapes
    /// fused into it (their colliders' masses rapier adds itself). Summed in handle
    /// order, so that the f32 result does not depend on a hash map's order.
    fn compose_mass(&mut self, bi: usize) {
        let entry = &self.bodies[bi];
        if entry.object == REMOVED_BODY {
            return;
        }
        let mut riders: Vec<(Handle, MassProperties)> = self
            .fused
            .iter()
            .filter(|(h, _)| self.body_of.get(h).is_some_and(|&(b, _)| b == bi))
            .filter_map(|(&h, p)| p.map(|p| (h, p)))
            .collect();
        riders.sort_by_key(|&(h, _)| h);
        let total = riders
            .into_iter()
            .fold(entry.inertial, |sum, (_, p)| Some(sum.map_or(p, |s| s + p)));
        if let Some(rb) = self.world.bodies.get_mut(entry.handle) {
            rb.set_additional_mass_properties(total.unwrap_or_default(), true);
            rb.recompute_mass_properties_from_colliders(&self.world.colliders);
        }
    }

    /// The body index on the parent side of joint or force sensor `j`.
    fn parent_body(&mut self, tree: &TreeView<'_>, j: Handle) -> usize {
        match above(tree, j) {
            Above::Shape(s) => match self.body_of.get(&s) {
                Some(&(bi, _)) if self.bodies[bi].role == BodyRole::Kinematic => self.mount(bi),
                Some(&(bi, _)) => bi,
                None => self.anchor(),
            },
            _ => self.anchor(),
        }
    }

    /// Kinematic body `bi`, made the root of a mechanism hanging from it. It becomes a
    /// fixed body that [`World`](super::World) teleports to its tree pose each step:
    /// rapier 0.36 integrates a multibody rooted on an awake kinematic body twice per
    /// step (its solver enlists the multibody for the root and again for the first
    /// link), so a free arm below a kinematic joint fell at twice the speed. The cost:
    /// contacts with that one link see it jump rather than move with a velocity.
    fn mount(&mut self, bi: usize) -> usize {
        if let Some(rb) = self.world.bodies.get_mut(self.bodies[bi].handle) {
            rb.set_body_type(RigidBodyType::Fixed, true);
        }
        bi
    }

    /// The fixed body at the world origin that anchors joints whose parent side is the
    /// world, created on first need.
    fn anchor(&mut self) -> usize {
        if let Some(a) = self.anchor {
            return a;
        }
        let handle = self.world.insert_body(RigidBodyBuilder::fixed());
        let a = self.push_entry(BodyEntry {
            handle,
            object: -1,
            role: BodyRole::Fixed,
            inertial: None,
        });
        self.anchor = Some(a);
        a
    }

    /// Stores a body entry, in the slot of a removed body if there is one (indices of
    /// live entries must not move: `body_of` holds them).
    fn push_entry(&mut self, entry: BodyEntry) -> usize {
        match self.bodies.iter().position(|e| e.object == REMOVED_BODY) {
            Some(i) => {
                self.bodies[i] = entry;
                i
            }
            None => {
                self.bodies.push(entry);
                self.bodies.len() - 1
            }
        }
    }

    /// Takes object `h` out of rapier: the body it owns (with every collider and joint
    /// attached to it) or, for a shape riding on another body, its own colliders, and
    /// every side-table entry that names it. Objects that depended on it (riders,
    /// mechanisms hanging from it) must be removed and re-inserted by the caller.
    pub fn remove_object(&mut self, h: Handle) {
        let body = self.body_of.remove(&h);
        if let Some((bi, _)) = body
            && self.bodies[bi].object == h
        {
            self.world.remove_body(self.bodies[bi].handle);
            // The slot stays (other entries keep their indices) and is reused; a fixed
            // role keeps the per-step kinematic update away from it.
            self.bodies[bi].object = REMOVED_BODY;
            self.bodies[bi].role = BodyRole::Fixed;
        }
        for c in self.object_colliders.remove(&h).unwrap_or_default() {
            self.world.remove_collider(c);
            self.collider_object.remove(&c);
        }
        if self.fused.remove(&h).is_some()
            && let Some((bi, _)) = body
        {
            // The body it was fused into carries its mass no more.
            self.compose_mass(bi);
        }
        self.joints.remove(&h);
        if let Some(j) = self.force_joints.remove(&h) {
            self.world.remove_impulse_joint(j);
        }
        self.unlink_dummy(h);
    }

    /// Ties dummy `a` to dummy `b`: a fixed impulse joint between the bodies they ride
    /// on pulls their frames together (a ball joint, their origins only, with
    /// `free_rotation`). Each side is a body index and the dummy's frame in that body, or
    /// `None` and the dummy's world pose for a dummy on no body (the world anchor holds
    /// it). Returns false, with no joint, when both ride on the same body.
    pub fn link_dummies(
        &mut self,
        a: (Handle, Option<usize>, Pose),
        b: (Handle, Option<usize>, Pose),
        free_rotation: bool,
    ) -> bool {
        self.unlink_dummy(a.0);
        self.unlink_dummy(b.0);
        let (ba, fa) = (a.1.unwrap_or_else(|| self.anchor()), a.2);
        let (bb, fb) = (b.1.unwrap_or_else(|| self.anchor()), b.2);
        let (a, b) = (a.0, b.0);
        if ba == bb {
            return false;
        }
        let axes = if free_rotation {
            JointAxesMask::LOCKED_SPHERICAL_AXES
        } else {
            JointAxesMask::LOCKED_FIXED_AXES
        };
        let data = GenericJointBuilder::new(axes)
            .local_frame1(math::to_physics(&fa))
            .local_frame2(math::to_physics(&fb))
            .contacts_enabled(false)
            .build();
        let handle = self
            .world
            .insert_impulse_joint(self.bodies[ba].handle, self.bodies[bb].handle, data);
        self.dummy_links.insert(a, (b, handle));
        true
    }

    /// Removes the link of dummy `h`, whichever side of it `h` is.
    pub fn unlink_dummy(&mut self, h: Handle) {
        let keys: Vec<Handle> = self
            .dummy_links
            .iter()
            .filter(|(a, (b, _))| **a == h || *b == h)
            .map(|(a, _)| *a)
            .collect();
        for a in keys {
            if let Some((_, j)) = self.dummy_links.remove(&a) {
                self.world.remove_impulse_joint(j);
            }
        }
    }

    /// The dummy linked to `h`, if any.
    pub fn linked_dummy(&self, h: Handle) -> Option<Handle> {
        self.dummy_links.iter().find_map(|(a, (b, _))| {
            if *a == h {
                Some(*b)
            } else if *b == h {
                Some(*a)
            } else {
                None
            }
        })
    }

    /// The body under object `h` (its own, or its nearest ancestor's: dummies ride on
    /// the body of the shape they are attached to) and `h`'s frame in it, given the
    /// world poses of the tree; `None` and the world pose when no ancestor has one.
    pub fn body_frame(
        &self,
        h: Handle,
        parent: impl Fn(Handle) -> Option<Handle>,
        world: impl Fn(Handle) -> Pose,
    ) -> (Option<usize>, Pose) {
        let mut cur = Some(h);
        while let Some(o) = cur {
            if let Some(&(bi, rel)) = self.body_of.get(&o) {
                // The body's world pose from its object's, then h's frame in it.
                let body_world = world(o) * rel.inverse();
                return (Some(bi), body_world.inverse() * world(h));
            }
            cur = parent(o);
        }
        (None, world(h))
    }

    /// Forgets joint bindings whose rapier joint went away with a removed body.
    pub fn prune_joints(&mut self) {
        let multibody = &self.world.multibody_joints;
        self.joints.retain(|_, b| multibody.get(b.joint).is_some());
        let impulse = &self.world.impulse_joints;
        self.force_joints.retain(|_, j| impulse.get(*j).is_some());
        self.dummy_links.retain(|_, (_, j)| impulse.get(*j).is_some());
    }

    fn new_body(
        &mut self,
        h: Handle,
        pose: &Pose,
        role: BodyRole,
        shape: &ShapeModel,
        warnings: &mut Vec<String>,
    ) -> usize {
        let builder = match role {
            BodyRole::Fixed => RigidBodyBuilder::fixed(),
            BodyRole::Kinematic => RigidBodyBuilder::kinematic_position_based(),
            // Robots must never fall asleep: a sleeping island ignores new motor targets
            // (rapier 0.36 does not wake it when a multibody target changes).
            BodyRole::Free | BodyRole::Link => RigidBodyBuilder::dynamic().can_sleep(false),
        };
        let mut builder = builder.pose(math::to_physics(pose));
        let inertial = inertial_properties(&shape.mass);
        if let Some(props) = inertial {
            builder = builder.additional_mass_properties(props);
        }
        let handle = self.world.insert_body(builder);
        let bi = self.push_entry(BodyEntry {
            handle,
            object: h,
            role,
            inertial,
        });
        self.body_of.insert(h, (bi, Pose::identity()));
        self.add_colliders(h, bi, &Pose::identity(), shape, warnings);
        bi
    }

    /// Adds one collider per geometry part of `shape` (a mesh on a dynamic body may give
    /// several: its convex parts), placed at `rel` in the body frame.
    fn add_colliders(&mut self, h: Handle, bi: usize, rel: &Pose, shape: &ShapeModel, warnings: &mut Vec<String>) {
        let dynamic = matches!(self.bodies[bi].role, BodyRole::Free | BodyRole::Link);
        let pieces = collider_pieces(rel, shape, dynamic, warnings);
        self.insert_colliders(h, bi, shape, pieces);
    }

    /// Adds colliders of `pieces` (shapes at their poses in the body frame) to body
    /// `bi` for shape `h`, with the shape's material, groups and mass.
    fn insert_colliders(&mut self, h: Handle, bi: usize, shape: &ShapeModel, pieces: Vec<(SharedShape, Pose)>) {
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
        for (shared, local) in pieces {
            let collider = ColliderBuilder::new(shared)
                .position(math::to_physics(&local))
                .density(density as f32)
                .friction(shape.friction as f32)
                .restitution(shape.restitution as f32)
                .collision_groups(pair_groups(groups, shape.respondable))
                .solver_groups(groups)
                .sensor(!shape.respondable)
                .build();
            let body = self.bodies[bi].handle;
            let ch = self.world.insert_collider(collider, Some(body));
            self.collider_object.insert(ch, h);
            self.object_colliders.entry(h).or_default().push(ch);
        }
        // rapier sums a body's mass from its colliders at the next step; until then its
        // centre of mass reads as the world origin, and `sim.addForce` before the first
        // step (or after a rebuild) turned the body about that point.
        if matches!(self.bodies[bi].role, BodyRole::Free | BodyRole::Link)
            && let Some(rb) = self.world.bodies.get_mut(self.bodies[bi].handle)
        {
            rb.recompute_mass_properties_from_colliders(&self.world.colliders);
        }
    }

    fn add_multibody_joint(
        &mut self,
        tree: &TreeView<'_>,
        j: Handle,
        parent: usize,
        child: usize,
        self_collision: bool,
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
                        // rapier gives every free angular DoF a damping of 0.1 N·m·s/rad
                        // unasked; gantry's joints have exactly the damping and Coulomb
                        // friction the model gives (URDF `<dynamics>`, else none), so that
                        // passive motion matches other engines. Both are per DoF, at the
                        // link's assembly index, which rapier keeps when the root's DoFs
                        // are dropped at the first step.
                        let dof = l.assembly_id();
                        if let Some(d) = mb.damping_mut().get_mut(dof) {
                            *d = joint.damping as f32;
                        }
                        if let Some(f) = mb.frictions_mut().get_mut(dof) {
                            *f = joint.friction as f32;
                        }
                    }
                }
                if !self_collision && let Some((mb, _)) = self.world.multibody_joints.get_mut(handle) {
                    mb.set_self_contacts_enabled(false);
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

/// rapier's mass properties for an explicit inertial (URDF `<inertial>`), `None` for the
/// other mass models (their mass comes from the colliders).
pub(crate) fn inertial_properties(model: &MassModel) -> Option<MassProperties> {
    let MassModel::Inertial {
        mass,
        com,
        frame,
        inertia,
    } = *model
    else {
        return None;
    };
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
    Some(MassProperties::with_inertia_matrix(com, mass as f32, mat))
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
    p.num_internal_pgs_iterations = s.solver_iterations.max(1) as usize;
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
/// A simulated `<mimic>` follower has no motor: the coupling moves it.
/// Force mode's motor speed, rad/s or m/s: far beyond any joint's, so that the motor
/// always pushes with its largest force.
const FORCE_MODE_SPEED: f32 = 1.0e6;
/// Force mode's motor gain: any velocity error saturates the motor at once.
const FORCE_MODE_GAIN: f32 = 1.0e6;

pub(crate) fn configure_motor(data: &mut GenericJoint, axis: JointAxis, joint: &super::object::Joint) {
    let mode = if joint.mimic.is_some() {
        JointMode::Free
    } else {
        joint.mode
    };
    match mode {
        JointMode::Position => {
            data.set_motor(
                axis,
                joint.reference as f32,
                joint.reference_velocity as f32,
                joint.kp as f32,
                joint.kd as f32,
            );
        }
        JointMode::Velocity => {
            data.set_motor(axis, 0.0, joint.commanded_velocity() as f32, 0.0, joint.kd as f32);
        }
        JointMode::Force => {
            // A velocity motor that can never reach its speed applies its largest force
            // every step: exactly the set torque, in the set direction.
            let speed = FORCE_MODE_SPEED.copysign(joint.target_force as f32);
            data.set_motor(axis, 0.0, speed, 0.0, FORCE_MODE_GAIN);
        }
        JointMode::Kinematic | JointMode::Free => {
            data.set_motor(axis, 0.0, 0.0, 0.0, 0.0);
        }
    }
    let max_force = match mode {
        JointMode::Free => 0.0,
        JointMode::Force => joint.target_force.abs(),
        // Locked at zero velocity: the motor holds whatever it takes.
        JointMode::Velocity if joint.velocity_lock && joint.commanded_velocity() == 0.0 => f64::from(f32::MAX),
        _ => joint.max_force,
    };
    data.set_motor_max_force(axis, max_force as f32);
}

/// The collision shapes of a geometry on a body: one for a primitive, one triangle mesh
/// for a mesh on a static or kinematic body, and on a dynamic body one convex hull per
/// part of the mesh (PyBullet's rule), with a warning when a one-part mesh is not convex.
/// The collision shapes of `shape` at their poses in the frame of its body, of which
/// `rel` is the shape's pose.
///
/// The convex parts of every mesh of a dynamic shape go into one compound, even when
/// there is one: parry bounds a convex polyhedron by visiting all its points (the hulls
/// of vendor STL meshes have hundreds) whenever the body moves, which was a third of a
/// mesh arm's step, while a compound keeps its local bounding box and only transforms
/// it (Bullet caches hull bounds the same way). One collider per link also leaves the
/// broad phase fewer pairs between a robot's links.
fn collider_pieces(
    rel: &Pose,
    shape: &ShapeModel,
    dynamic: bool,
    warnings: &mut Vec<String>,
) -> Vec<(SharedShape, Pose)> {
    let mut hulls: Vec<(rapier3d::math::Pose, SharedShape)> = Vec::new();
    let mut pieces: Vec<(SharedShape, Pose)> = Vec::new();
    for g in &shape.geoms {
        let merge = dynamic && matches!(g.geometry, Geometry::Mesh(_));
        for (shared, fix) in collision_shapes(&g.geometry, dynamic, warnings) {
            let local = rel * g.local * fix;
            if merge {
                hulls.push((math::to_physics(&local), shared));
            } else {
                pieces.push((shared, local));
            }
        }
    }
    if !hulls.is_empty() {
        pieces.push((SharedShape::compound(hulls), Pose::identity()));
    }
    pieces
}

fn collision_shapes(g: &Geometry, dynamic: bool, warnings: &mut Vec<String>) -> Vec<(SharedShape, Pose)> {
    let Geometry::Mesh(m) = g else {
        return vec![shared_shape(g)];
    };
    if !dynamic {
        return vec![shared_shape(g)];
    }
    // Distinct points only: an STL repeats each vertex for every triangle that shares it
    // (about six times), and the hull and the convexity check cost per point.
    let distinct = |vertices: &[[f32; 3]]| {
        let mut keys: Vec<[u32; 3]> = vertices.iter().map(|v| v.map(f32::to_bits)).collect();
        keys.sort_unstable();
        keys.dedup();
        keys.into_iter()
            .map(|k| rapier3d::math::Vector::new(f32::from_bits(k[0]), f32::from_bits(k[1]), f32::from_bits(k[2])))
            .collect::<Vec<_>>()
    };
    let parts: Vec<Vec<rapier3d::math::Vector>> = if m.parts.is_empty() {
        vec![distinct(&m.vertices)]
    } else {
        m.parts.iter().map(|p| distinct(p)).collect()
    };
    let mut hulls = Vec::with_capacity(parts.len());
    for points in &parts {
        match hull(points) {
            Some((vertices, indices)) => {
                if m.parts.is_empty() && !is_convex(points, &vertices, &indices) {
                    warnings.push(format!(
                        "mesh {}: not convex, so a dynamic body collides with its convex hull (as in PyBullet); for a closer fit give a convex decomposition (an OBJ with one `o` section per convex part)",
                        m.source.display()
                    ));
                }
                if let Some(s) = SharedShape::convex_mesh(vertices, &indices) {
                    hulls.push((s, Pose::identity()));
                }
            }
            None => warnings.push(format!(
                "mesh {}: a part has no volume (flat, or fewer than 4 points) and cannot collide on a dynamic body; it was left out",
                m.source.display()
            )),
        }
    }
    if hulls.is_empty() {
        // A body needs a collider for sensors and queries to see it; a tiny ball at its
        // origin keeps it valid without changing contacts.
        hulls.push((SharedShape::ball(1e-4), Pose::identity()));
    }
    hulls
}

/// A hull's vertices and outward triangles.
type Hull = (Vec<rapier3d::math::Vector>, Vec<[u32; 3]>);

/// The convex hull of a point set, or `None` when it is flat or degenerate. parry's hull
/// may panic on some degenerate inputs; a bad mesh must not bring the simulator down.
fn hull(points: &[rapier3d::math::Vector]) -> Option<Hull> {
    if points.len() < 4 || points.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let result = std::panic::catch_unwind(|| parry3d::transformation::try_convex_hull(points)).ok()?;
    let (vertices, indices) = result.ok()?;
    (!indices.is_empty()).then_some((vertices, indices))
}

/// Whether a mesh equals its convex hull: no mesh vertex lies clearly inside the hull
/// (deeper than 0.5 % of the hull's diagonal below every face). A concave mesh has such a
/// vertex at the bottom of each dent, unless the dent is spanned by hull vertices alone.
fn is_convex(points: &[rapier3d::math::Vector], vertices: &[rapier3d::math::Vector], indices: &[[u32; 3]]) -> bool {
    let (mut lo, mut hi) = (vertices[0], vertices[0]);
    for v in vertices {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    let tolerance = 0.005 * (hi - lo).length();
    // Outward face planes n·x = d; a point is at depth d - n·x below a face.
    let planes: Vec<(rapier3d::math::Vector, f32)> = indices
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let n = (b - a).cross(c - a);
            let len = n.length();
            (len > 0.0).then(|| (n / len, (n / len).dot(a)))
        })
        .collect();
    points
        .iter()
        .all(|p| planes.iter().any(|(n, d)| d - n.dot(*p) <= tolerance))
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
pub(crate) fn geometry_volume(g: &Geometry) -> f64 {
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

/// The groups rapier pairs a collider by. A non-respondable shape is a rapier sensor,
/// and nothing reads rapier's intersection events (proximity sensors, `sim.checkCollision`
/// and the distance queries test the shapes themselves), so it is kept out of every
/// pair: rapier would otherwise test it, every step, against each collider its box
/// overlaps (a Panda's visual meshes against its own links: a sixth of its step).
/// `solver_groups` keep the shape's own groups, to restore them when it becomes
/// respondable.
pub(super) fn pair_groups(groups: InteractionGroups, respondable: bool) -> InteractionGroups {
    if respondable { groups } else { InteractionGroups::none() }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use crate::scene::{EmbeddedFiles, LoadOptions, load_scene_text};
    use crate::world::World;

    /// Two balls overlapping in the air, `a` respondable or not as given, `b` not.
    fn world(a_respondable: bool) -> World {
        let text = format!(
            r#"
[[object]]
name = "a"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [0, 0, 1]
dynamic = true
respondable = {a_respondable}

[[object]]
name = "b"
kind = "shape"
shape = "sphere"
radius = 0.1
position = [0.05, 0, 1]
dynamic = true
respondable = false
"#
        );
        let model = load_scene_text(
            &EmbeddedFiles::default(),
            &text,
            Path::new("/t.toml"),
            &LoadOptions::default(),
        )
        .expect("the scene loads");
        World::new(&model)
    }

    #[test]
    fn non_respondable_shapes_are_not_paired_by_rapier_but_still_collide_in_queries() {
        let mut w = world(false);
        w.step_physics();
        let pairs = w.physics().world.narrow_phase.intersection_pairs().count();
        assert_eq!(pairs, 0, "nothing reads rapier's sensor pairs: none are computed");
        let (a, b) = (w.find("/a", None, 0).unwrap(), w.find("/b", None, 0).unwrap());
        assert_eq!(
            w.collision(&[a], &[b]),
            Some([a, b]),
            "sim.checkCollision still sees them"
        );

        // Respondable again: back in rapier's pairs with its own groups.
        w.set_shape_respondable(a, true).unwrap();
        w.set_shape_respondable(b, true).unwrap();
        w.step_physics();
        assert!(
            w.physics()
                .world
                .narrow_phase
                .contact_pairs()
                .any(|p| p.has_any_active_contact())
        );
    }
}
