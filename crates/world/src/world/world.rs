//! [`World`]: the object tree, the physics world and simulation time, owned by one thread.

use rapier3d::prelude::*;

use super::collection::Collection;
use super::log::Log;
use super::object::{Detection, ForceReading, Handle, Joint, KinematicMotion, Object, ObjectKind, ProximitySensor};
use super::object_path::{ObjectTree, PathError, PathQuery, resolve};
use super::octree::Octree;
use super::physics::{BodyRole, Physics, TreeView, configure_motor};
use super::point_cloud::PointCloud;
use crate::error::SimError;
use crate::math::{self, Pose, Vec3};
use crate::scene::{JointMode, ObjectModelKind, SceneModel, SimSettings};

/// The simulated scene. It is not `Sync` and lives on the simulation thread; every other
/// part of gantry reaches it through requests to that thread.
#[derive(Clone)]
pub struct World {
    /// Objects by handle; removed objects stay as tombstones (see `edit`), so handles are
    /// never reused.
    pub(super) objects: Vec<Object>,
    pub(super) roots: Vec<Handle>,
    /// Handles with every parent before its children; world poses are refreshed in this order.
    pub(super) order: Vec<Handle>,
    pub(super) physics: Physics,
    pub(super) settings: SimSettings,
    time: f64,
    steps: u64,
    warnings: Vec<String>,
    /// The selected objects (`sim.getObjectSel`; the viewer's pick).
    pub selection: super::Selection,
    /// Values attached to objects (user parameters).
    pub custom: super::CustomData,
    /// Collections by handle - FIRST_COLLECTION_HANDLE; `None` once destroyed.
    pub collections: Vec<Option<Collection>>,
    /// The simulation log.
    pub log: Log,
    /// Whether bodies were moved since rapier's collision structures were last updated,
    /// so scene queries must refresh them first (rapier updates them only when stepping).
    pub(super) queries_stale: bool,
    /// Joints that follow another (`<mimic>`), in handle order.
    pub(super) mimics: Vec<Handle>,
    /// Simulated joints with a speed limit, whose position reference moves each step.
    pub(super) profiled: Vec<Handle>,
    /// Kinematic joints in motion (see [`KinematicMotion`]), moved at each step.
    pub(super) kinematic_moving: Vec<Handle>,
    /// Run-time scene editing: removed handles, the scene revision, pending forces.
    pub(super) edit: super::edit_state::EditState,
    /// The robots loaded from URDF files, in load order (a removed robot's handles
    /// name no object: handles are never reused).
    pub(super) urdf_robots: Vec<super::UrdfRobot>,
    /// Where the scene was read from.
    source: SceneSource,
    /// The scripts the scene and the models imported into it came with, each attached
    /// to an object by handle (`object` holds the handle): what `sim.saveScene` writes
    /// back. The script host runs them; this is only their text.
    pub(super) scripts: Vec<crate::scene::ScriptModel>,
    /// This world's number among the worlds of the process, from 1: the high half of
    /// its objects' unique ids (see [`World::object_uid`]).
    serial: i64,
    /// Texture objects and the textures shapes wear.
    pub(super) textures: super::texture::Textures,
}

/// The last world number given out (see `World::serial`).
static WORLDS: std::sync::atomic::AtomicI64 = std::sync::atomic::AtomicI64::new(0);

/// Where a world's scene was read from (`sim.stringparam_scene_*`).
#[derive(Debug, Clone, Default)]
pub struct SceneSource {
    /// The scene's short name (the file stem).
    pub name: String,
    /// The folder relative paths in the scene resolve against.
    pub dir: std::path::PathBuf,
    /// The file, empty for a scene built in memory.
    pub path: std::path::PathBuf,
}

impl World {
    /// `sim.setLinkDummy(a, b)`: links dummy `a` to dummy `b` (`None` unlinks `a`). The
    /// link holds the two frames together in the physics: a suction pad's dummy linked to
    /// one on a box carries the box. Linking two dummies on the same body is allowed and
    /// does nothing physically.
    ///
    /// # Errors
    /// An object that does not exist or is not a dummy.
    pub fn set_link_dummy(&mut self, a: Handle, b: Option<Handle>) -> Result<(), SimError> {
        self.link_dummy(a, b, false)
    }

    /// [`World::set_link_dummy`], holding only the dummies' origins together when
    /// `free_rotation` (a loop closed through a ball joint).
    fn link_dummy(&mut self, a: Handle, b: Option<Handle>, free_rotation: bool) -> Result<(), SimError> {
        for h in std::iter::once(a).chain(b) {
            if !matches!(self.object(h)?.kind, ObjectKind::Dummy) {
                return Err(SimError::BadArgument(format!("object {h} is not a dummy")));
            }
        }
        match b {
            None => self.physics.unlink_dummy(a),
            Some(b) => {
                let objects = &self.objects;
                let parent = |h: Handle| objects[h as usize].parent;
                let world = |h: Handle| objects[h as usize].world;
                let (ba, fa) = self.physics.body_frame(a, parent, world);
                let (bb, fb) = self.physics.body_frame(b, parent, world);
                self.physics.link_dummies((a, ba, fa), (b, bb, fb), free_rotation);
            }
        }
        Ok(())
    }

    /// The dummy linked to `h` (`sim.getLinkDummy`), if any.
    pub fn linked_dummy(&self, h: Handle) -> Option<Handle> {
        self.physics.linked_dummy(h)
    }

    /// An object's unique id (`sim.getObjectUid`): never given to another object in this
    /// process, unlike a handle, which a scene loaded later gives out again. The world's
    /// number times 2^32 plus the handle (handles are never reused within a world).
    ///
    /// # Errors
    /// No such object.
    pub fn object_uid(&self, h: Handle) -> Result<i64, SimError> {
        self.object(h)?;
        Ok((self.serial << 32) | h)
    }

    /// Where the scene was read from.
    pub fn source(&self) -> &SceneSource {
        &self.source
    }

    /// Builds the world from a resolved scene. Object handles are model indices.
    pub fn new(model: &SceneModel) -> Self {
        let mut objects: Vec<Object> = model
            .objects
            .iter()
            .map(|o| Object {
                alias: o.alias.clone(),
                parent: o.parent.map(|p| p as Handle),
                children: Vec::new(),
                local: o.local,
                world: Pose::identity(),
                model_base: o.model_base,
                extension: o.extension.clone(),
                kind: match &o.kind {
                    ObjectModelKind::Shape(s) => ObjectKind::Shape(Box::new(s.clone())),
                    ObjectModelKind::Joint(j) => ObjectKind::Joint(Joint::from_model(j, |leader| leader as Handle)),
                    ObjectModelKind::Dummy => ObjectKind::Dummy,
                    ObjectModelKind::ProximitySensor(v) => {
                        ObjectKind::ProximitySensor(ProximitySensor { volume: *v, last: None })
                    }
                    ObjectModelKind::VisionSensor(v) => ObjectKind::VisionSensor(*v),
                    ObjectModelKind::ForceSensor => ObjectKind::ForceSensor(ForceReading::default()),
                    ObjectModelKind::Graph => ObjectKind::Graph,
                    ObjectModelKind::Camera(c) => ObjectKind::Camera(*c),
                    ObjectModelKind::Light(l) => ObjectKind::Light(*l),
                    // The curve goes to `Sim::paths` (`Sim::new`).
                    ObjectModelKind::Path(_) => ObjectKind::Path,
                },
            })
            .collect();
        let mut roots = Vec::new();
        for (i, o) in model.objects.iter().enumerate() {
            match o.parent {
                Some(p) => objects[p].children.push(i as Handle),
                None => roots.push(i as Handle),
            }
        }
        // Model indices are parents-first, so one pass in index order computes every
        // world pose; the physics mapping needs them before any body exists.
        let order: Vec<Handle> = (0..objects.len() as Handle).collect();
        for &h in &order {
            let i = h as usize;
            let parent_frame = objects[i]
                .parent
                .map_or(Pose::identity(), |p| hanging_frame(&objects[p as usize]));
            objects[i].world = parent_frame * objects[i].local;
        }
        let mut warnings = model.warnings.clone();
        let tree = TreeView {
            parent: &|h| objects[h as usize].parent,
            kind: &|h| &objects[h as usize].kind,
            world: &|h| objects[h as usize].world,
            // A scene as loaded has no model property overrides yet.
            overrides: &|_| 0,
        };
        let physics = Physics::build(&tree, &order, &model.settings, &mut warnings);
        let warnings = crate::scene::dedup_warnings(warnings);
        let objects_len = objects.len();
        let mut world = World {
            objects,
            roots,
            order,
            physics,
            settings: model.settings,
            time: 0.0,
            steps: 0,
            warnings,
            selection: Default::default(),
            custom: super::CustomData::default(),
            collections: model
                .collections
                .iter()
                .map(|c| Some(Collection::from_model(c, |i| i as Handle)))
                .collect(),
            log: Log::default(),
            queries_stale: true,
            edit: super::edit_state::EditState::new(objects_len, model.settings.seed),
            mimics: Vec::new(),
            profiled: Vec::new(),
            kinematic_moving: Vec::new(),
            urdf_robots: model
                .urdf_robots
                .iter()
                .map(|r| super::UrdfRobot::from_model(r, |i| i as Handle))
                .collect(),
            source: SceneSource {
                name: model.name.clone(),
                dir: model.base_dir.clone(),
                path: model.path.clone(),
            },
            // Handles are model indices at load.
            scripts: model.scripts.clone(),
            serial: WORLDS.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
            textures: Default::default(),
        };
        world.refresh_caches();
        world.link_loop_closures(
            model.dummy_links.iter().map(|&[a, b]| [a as Handle, b as Handle]),
            false,
        );
        world.link_loop_closures(model.ball_links.iter().map(|&[a, b]| [a as Handle, b as Handle]), true);
        for r in &model.referenced_handles {
            let targets = r.targets.iter().map(|&t| t as Handle).collect();
            world.custom.set_referenced(r.object as Handle, &r.tag, targets);
        }
        for p in &model.user_parameters {
            world
                .custom
                .set(p.object as Handle, &p.name, crate::Value::Str(p.value.clone()));
        }
        for (i, o) in model.objects.iter().enumerate() {
            if o.layer != 1 {
                world.edit.layers.insert(i as Handle, i64::from(o.layer));
            }
        }
        let warnings = world.load_textures(model, |i| i as Handle);
        world.warnings.extend(warnings);
        world
    }

    /// Holds each pair of dummies together in the physics (the scene's dynamic loop
    /// closures): their frames, or only their origins with `free_rotation`. A pair that is
    /// not two dummies is skipped with a warning.
    pub(super) fn link_loop_closures(&mut self, pairs: impl Iterator<Item = [Handle; 2]>, free_rotation: bool) {
        for [a, b] in pairs {
            if let Err(e) = self.link_dummy(a, Some(b), free_rotation) {
                self.warnings.push(format!("loop closure {a}-{b} not made: {e}"));
            }
        }
    }

    /// The robots loaded from URDF files, in load order, removed ones included (their
    /// handles name no object).
    pub fn urdf_robots(&self) -> &[super::UrdfRobot] {
        &self.urdf_robots
    }

    /// Warnings from loading and building (unsupported features, ignored keys).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Simulation settings.
    pub fn settings(&self) -> &SimSettings {
        &self.settings
    }

    /// Simulation time, s: the time at the start of the current step.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Number of completed steps.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Number of handles handed out so far: live objects have handles in `0..len`, but
    /// removed ones leave gaps (CoppeliaSim never reuses a handle).
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether the scene has no objects.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Root objects in hierarchy order.
    pub fn roots(&self) -> &[Handle] {
        &self.roots
    }

    /// Every handle, parents before children.
    pub fn handles(&self) -> &[Handle] {
        &self.order
    }

    /// The object behind a handle.
    ///
    /// # Errors
    /// [`SimError::NoSuchObject`].
    pub fn object(&self, h: Handle) -> Result<&Object, SimError> {
        usize::try_from(h)
            .ok()
            .filter(|_| !self.edit.is_removed(h))
            .and_then(|i| self.objects.get(i))
            .ok_or(SimError::NoSuchObject(h))
    }

    pub(super) fn object_mut(&mut self, h: Handle) -> Result<&mut Object, SimError> {
        usize::try_from(h)
            .ok()
            .filter(|_| !self.edit.is_removed(h))
            .and_then(|i| self.objects.get_mut(i))
            .ok_or(SimError::NoSuchObject(h))
    }

    /// The joint state behind a handle.
    ///
    /// # Errors
    /// No such object, or not a joint.
    pub fn joint(&self, h: Handle) -> Result<&Joint, SimError> {
        match &self.object(h)?.kind {
            ObjectKind::Joint(j) => Ok(j),
            other => Err(SimError::WrongKind {
                handle: h,
                expected: "joint",
                actual: other.name(),
            }),
        }
    }

    pub(super) fn joint_mut(&mut self, h: Handle) -> Result<&mut Joint, SimError> {
        match &mut self.object_mut(h)?.kind {
            ObjectKind::Joint(j) => Ok(j),
            other => Err(SimError::WrongKind {
                handle: h,
                expected: "joint",
                actual: other.name(),
            }),
        }
    }

    /// The point cloud behind a handle.
    ///
    /// # Errors
    /// No such object, or not a point cloud.
    pub fn point_cloud(&self, h: Handle) -> Result<&PointCloud, SimError> {
        match &self.object(h)?.kind {
            ObjectKind::PointCloud(c) => Ok(c),
            other => Err(SimError::WrongKind {
                handle: h,
                expected: "point cloud",
                actual: other.name(),
            }),
        }
    }

    /// The point cloud behind a handle, to insert or remove points. Points are not part
    /// of the scene description, so this does not change [`World::scene_revision`].
    ///
    /// # Errors
    /// No such object, or not a point cloud.
    pub fn point_cloud_mut(&mut self, h: Handle) -> Result<&mut PointCloud, SimError> {
        match &mut self.object_mut(h)?.kind {
            ObjectKind::PointCloud(c) => Ok(c),
            other => Err(SimError::WrongKind {
                handle: h,
                expected: "point cloud",
                actual: other.name(),
            }),
        }
    }

    /// The octree behind a handle.
    ///
    /// # Errors
    /// No such object, or not an octree.
    pub fn octree(&self, h: Handle) -> Result<&Octree, SimError> {
        match &self.object(h)?.kind {
            ObjectKind::Octree(o) => Ok(o),
            other => Err(SimError::WrongKind {
                handle: h,
                expected: "octree",
                actual: other.name(),
            }),
        }
    }

    /// The octree behind a handle, to insert or remove voxels. Voxels are not part of
    /// the scene description, so this does not change [`World::scene_revision`].
    ///
    /// # Errors
    /// No such object, or not an octree.
    pub fn octree_mut(&mut self, h: Handle) -> Result<&mut Octree, SimError> {
        match &mut self.object_mut(h)?.kind {
            ObjectKind::Octree(o) => Ok(o),
            other => Err(SimError::WrongKind {
                handle: h,
                expected: "octree",
                actual: other.name(),
            }),
        }
    }

    /// Resolves a `sim.getObject` path. `emitter` is the calling script's object.
    ///
    /// # Errors
    /// [`SimError::PathNotFound`].
    pub fn find(&self, path: &str, emitter: Option<Handle>, index: usize) -> Result<Handle, SimError> {
        let mut q = PathQuery::new(path).skipping(index);
        if let Some(e) = emitter {
            q = q.emitted_by(e);
        }
        resolve(self, &q).map_err(|e: PathError| SimError::PathNotFound(e.path().to_owned()))
    }

    /// The frame children of `h` hang from: the object frame, moved by a joint's motion.
    fn child_frame(&self, h: Handle) -> Pose {
        hanging_frame(&self.objects[h as usize])
    }

    /// World pose of the frame an object's local pose is relative to.
    pub fn parent_frame(&self, h: Handle) -> Pose {
        match self.objects.get(h as usize).and_then(|o| o.parent) {
            Some(p) => self.child_frame(p),
            None => Pose::identity(),
        }
    }

    /// Recomputes world poses of `h` and its descendants.
    pub(super) fn refresh_subtree(&mut self, h: Handle) {
        let mut stack = vec![h];
        while let Some(cur) = stack.pop() {
            let world = self.parent_frame(cur) * self.objects[cur as usize].local;
            self.objects[cur as usize].world = world;
            stack.extend(self.objects[cur as usize].children.iter().rev().copied());
        }
    }

    /// Sets an object's pose in the world frame. A simulated body is teleported with its
    /// velocities zeroed (CoppeliaSim resets the dynamics of a moved object).
    ///
    /// # Errors
    /// No such object, or a non-finite pose.
    pub fn set_world_pose(&mut self, h: Handle, pose: Pose) -> Result<(), SimError> {
        // A NaN orientation (from NaN Euler angles, say) would reach rapier and the
        // renderers as surely as a NaN position.
        let finite = pose
            .translation
            .vector
            .iter()
            .chain(pose.rotation.coords.iter())
            .all(|v| v.is_finite());
        if !finite {
            return Err(SimError::BadArgument("pose must be finite".into()));
        }
        self.object(h)?;
        let local = self.parent_frame(h).inverse() * pose;
        self.objects[h as usize].local = local;
        self.refresh_subtree(h);
        self.push_body_pose(h);
        Ok(())
    }

    /// Brings rapier's broad and narrow phase up to date with bodies moved through the
    /// API since the last step, so sensors and distance queries see the current poses
    /// (rapier itself refreshes them only inside a step).
    pub fn refresh_queries(&mut self) {
        if std::mem::take(&mut self.queries_stale) {
            place_colliders(&mut self.physics.world);
            self.physics.world.detect_collisions(&(), &());
            // The collision pipeline's own update puts the colliders of bodies it sees
            // as changed back at the bodies' current poses: place them again.
            place_colliders(&mut self.physics.world);
            // rapier 0.36's collision pipeline takes the bodies' list of changes without
            // passing it to the island manager, so a body created, made dynamic or woken
            // since the last step would never be simulated (it froze in mid-air). Mark
            // the moving bodies changed again: the next step files them properly.
            let bodies = &mut self.physics.world.bodies;
            let moving: Vec<_> = bodies.iter().filter(|(_, rb)| !rb.is_fixed()).map(|(h, _)| h).collect();
            for h in moving {
                let _ = bodies.get_mut(h);
            }
        }
    }

    /// Teleports the rapier bodies of `h`'s subtree to their tree poses.
    pub(super) fn push_body_pose(&mut self, h: Handle) {
        self.queries_stale = true;
        let mut stack = vec![h];
        while let Some(cur) = stack.pop() {
            if let Some(&(bi, rel)) = self.physics.body_of.get(&cur) {
                let entry = &self.physics.bodies[bi];
                if entry.object == cur {
                    let pose = math::to_physics(&(self.objects[cur as usize].world * rel.inverse()));
                    if let Some(rb) = self.physics.world.bodies.get_mut(entry.handle) {
                        match entry.role {
                            BodyRole::Kinematic => place_kinematic(rb, pose),
                            _ => {
                                rb.set_position(pose, true);
                                rb.set_linvel(Vector::ZERO, true);
                                rb.set_angvel(Vector::ZERO, true);
                                // Placing a body stopped by containment brings it back.
                                rb.set_enabled(true);
                            }
                        }
                    }
                }
            }
            stack.extend(self.objects[cur as usize].children.iter().copied());
        }
        // A multibody takes its root pose from the root body only when asked to.
        let w = &mut self.physics.world;
        let roots: Vec<_> = w
            .multibody_joints
            .multibodies()
            .map(|mb| mb.root().rigid_body_handle())
            .collect();
        for root in roots {
            if let Some(id) = w.multibody_joints.rigid_body_link(root).copied()
                && let Some(mb) = w.multibody_joints.get_multibody_mut(id.multibody)
            {
                mb.forward_kinematics(&w.bodies, true);
            }
        }
    }

    /// Sets a joint's position (clamped to limits, cyclic joints wrapped) and moves every
    /// descendant at once, before any physics step.
    ///
    /// # Errors
    /// No such object, not a joint, or a non-finite value.
    pub fn set_joint_position(&mut self, h: Handle, q: f64) -> Result<(), SimError> {
        if !q.is_finite() {
            return Err(SimError::BadArgument(format!("joint position must be finite, got {q}")));
        }
        let j = self.joint_mut(h)?;
        // Placing a joint ends its kinematic motion (a later target starts a new one).
        j.motion = KinematicMotion::Still;
        if j.max_velocity.is_some() {
            // The speed-limited controller goes on from where the joint now is.
            j.reference = j.constrain(q);
            j.reference_velocity = 0.0;
        }
        self.place_joint(h, q)?;
        self.move_followers(h)
    }

    /// Puts the `<mimic>` followers of joint `h` where its position says, and theirs in
    /// turn (the loader refuses mimic cycles, and the depth is bounded by the count).
    fn move_followers(&mut self, h: Handle) -> Result<(), SimError> {
        let mut todo = vec![h];
        let mut hops = 0;
        while let Some(leader) = todo.pop() {
            hops += 1;
            if hops > self.mimics.len() + 1 {
                break;
            }
            let q = self.joint(leader)?.position;
            for i in 0..self.mimics.len() {
                let f = self.mimics[i];
                let Ok(Joint { mimic: Some(m), .. }) = self.joint(f) else {
                    continue;
                };
                if m.leader == leader {
                    let target = m.multiplier * q + m.offset;
                    self.place_joint(f, target)?;
                    todo.push(f);
                }
            }
        }
        Ok(())
    }

    /// Sets one joint's position (clamped, wrapped), and rapier's coordinate if it is
    /// simulated, and moves its subtree; its followers are `move_followers`'s business.
    fn place_joint(&mut self, h: Handle, q: f64) -> Result<(), SimError> {
        let j = self.joint_mut(h)?;
        let q = j.constrain(q);
        let old = j.position;
        j.position = q;
        if let Some(b) = self.physics.joints.get(&h).copied()
            && let Some((mb, link)) = self.physics.world.multibody_joints.get_mut(b.joint)
        {
            if let Some(l) = mb.link_mut(link) {
                let mut disp = [0.0f32; 6];
                disp[0] = (q - old) as f32;
                let n = l.joint.ndofs().min(6);
                l.joint.apply_displacement(&disp[..n]);
            }
            mb.forward_kinematics(&self.physics.world.bodies, false);
            self.queries_stale = true;
            self.refresh_subtree(h);
        } else {
            // Bodies below a kinematic joint are headed to their new poses now, so
            // that collision checks and sensors see the joint where it was put before
            // the next step takes them there.
            self.refresh_subtree(h);
            self.push_body_pose(h);
        }
        Ok(())
    }

    /// Sets a joint's position target (position mode; stored for other modes).
    ///
    /// # Errors
    /// No such object, not a joint, or a non-finite value.
    pub fn set_joint_target_position(&mut self, h: Handle, q: f64) -> Result<(), SimError> {
        if !q.is_finite() {
            return Err(SimError::BadArgument(format!(
                "target position must be finite, got {q}"
            )));
        }
        let j = self.joint_mut(h)?;
        j.target_position = if j.cyclic { q } else { j.constrain(q) };
        if j.mode == JointMode::Kinematic {
            // As CoppeliaSim's: the joint moves there over the next steps, at its speed.
            j.motion = KinematicMotion::ToTarget;
            self.start_kinematic_motion(h);
            return Ok(());
        }
        if j.max_velocity.is_none() {
            // A speed-limited reference moves at the next step (`step_physics`).
            j.advance_reference(0.0);
        }
        self.push_motor(h);
        Ok(())
    }

    /// Sets a joint's velocity target, rad/s or m/s.
    ///
    /// # Errors
    /// No such object, not a joint, or a non-finite value.
    pub fn set_joint_target_velocity(&mut self, h: Handle, v: f64) -> Result<(), SimError> {
        if !v.is_finite() {
            return Err(SimError::BadArgument(format!(
                "target velocity must be finite, got {v}"
            )));
        }
        let j = self.joint_mut(h)?;
        j.target_velocity = v;
        if j.mode == JointMode::Kinematic {
            // As CoppeliaSim's: a kinematic joint moves at that speed from the next step.
            j.motion = if v == 0.0 {
                KinematicMotion::Still
            } else {
                KinematicMotion::AtVelocity
            };
            self.start_kinematic_motion(h);
            return Ok(());
        }
        self.push_motor(h);
        Ok(())
    }

    fn start_kinematic_motion(&mut self, h: Handle) {
        if !self.kinematic_moving.contains(&h) {
            self.kinematic_moving.push(h);
        }
    }

    /// Moves the kinematic joints in motion one step on (`dt` seconds), and sets their
    /// velocity to what the step did.
    fn step_kinematic_joints(&mut self, dt: f64) {
        let mut i = 0;
        while i < self.kinematic_moving.len() {
            let h = self.kinematic_moving[i];
            let next = match &mut self.objects[h as usize].kind {
                ObjectKind::Joint(j) if j.mode == JointMode::Kinematic && !self.edit.is_removed(h) => {
                    j.kinematic_step(dt).map(|q| (j.position, q))
                }
                _ => None,
            };
            if let Some((_, q)) = next
                && self.place_joint(h, q).is_ok()
            {
                let _ = self.move_followers(h);
            }
            let mut moving = false;
            if let ObjectKind::Joint(j) = &mut self.objects[h as usize].kind {
                j.velocity = match next {
                    Some((before, _)) if j.cyclic => math::wrap_angle(j.position - before) / dt,
                    Some((before, _)) => (j.position - before) / dt,
                    None => 0.0,
                };
                moving = j.mode == JointMode::Kinematic && (j.motion != KinematicMotion::Still || j.velocity != 0.0);
            }
            if moving {
                i += 1;
            } else {
                self.kinematic_moving.swap_remove(i);
            }
        }
    }

    /// Sets a joint's maximum torque/force (its magnitude; CoppeliaSim's signed variant
    /// is accepted and the sign ignored).
    ///
    /// # Errors
    /// No such object, not a joint, or a non-finite value.
    pub fn set_joint_max_force(&mut self, h: Handle, f: f64) -> Result<(), SimError> {
        self.set_joint_target_force(h, f, false)
    }

    /// `sim.setJointTargetForce(h, f, signedValue)`: the largest torque (N·m) or force
    /// (N) of the joint's controller, `|f|`; a joint in force mode applies `f` itself,
    /// or `|f|` when `signed` is false.
    ///
    /// # Errors
    /// No such object, not a joint, or a non-finite value.
    pub fn set_joint_target_force(&mut self, h: Handle, f: f64, signed: bool) -> Result<(), SimError> {
        if !f.is_finite() {
            return Err(SimError::BadArgument(format!("force must be finite, got {f}")));
        }
        let j = self.joint_mut(h)?;
        j.max_force = f.abs();
        j.target_force = if signed { f } else { f.abs() };
        self.push_motor(h);
        Ok(())
    }

    pub(super) fn push_motor(&mut self, h: Handle) {
        let Some(b) = self.physics.joints.get(&h).copied() else {
            return;
        };
        let ObjectKind::Joint(joint) = &self.objects[h as usize].kind else {
            return;
        };
        if let Some((mb, link)) = self.physics.world.multibody_joints.get_mut(b.joint)
            && let Some(l) = mb.link_mut(link)
        {
            configure_motor(&mut l.joint.data, b.axis, joint);
        }
    }

    /// Advances physics by one simulation step (one rapier step of `substeps` solver
    /// substeps, or `substeps` rapier steps, see `physics::configure_integration`) and
    /// reads the
    /// results back into the tree. Does not advance simulation time (see
    /// [`World::advance_time`]), because CoppeliaSim scripts see the step's start time
    /// until the step ends.
    pub(crate) fn step_physics(&mut self) {
        // Speed-limited position controllers: move their references one step on.
        let dt = self.settings.dt;
        self.step_kinematic_joints(dt);
        for i in 0..self.profiled.len() {
            let h = self.profiled[i];
            if let ObjectKind::Joint(j) = &mut self.objects[h as usize].kind
                && j.mode == JointMode::Position
                && j.advance_reference(dt)
            {
                self.push_motor(h);
            }
        }
        // Kinematic bodies follow the tree. Only those that moved are touched: rapier
        // treats every body given a target as moving (broad phase, contacts) even when
        // the target is where it already is.
        for e in &self.physics.bodies {
            if e.role != BodyRole::Kinematic {
                continue;
            }
            let target = math::to_physics(&self.objects[e.object as usize].world);
            if let Some(rb) = self.physics.world.bodies.get_mut(e.handle)
                && *rb.position() != target
            {
                place_kinematic(rb, target);
            }
        }
        for _ in 0..self.physics.rapier_steps {
            self.step_rapier_contained();
        }
        // `sim.addForce` acts during one step only; rapier would keep applying it.
        self.clear_step_forces();
        self.queries_stale = false;
        self.read_back();
        // Kinematic followers of simulated leaders follow in the tree (simulated pairs are
        // coupled inside rapier and read back like any joint).
        for i in 0..self.mimics.len() {
            let f = self.mimics[i];
            if self.physics.joints.contains_key(&f) {
                continue;
            }
            if let Ok(Joint { mimic: Some(m), .. }) = self.joint(f)
                && self.physics.joints.contains_key(&m.leader)
                && let Ok(leader) = self.joint(m.leader)
            {
                let q = m.multiplier * leader.position + m.offset;
                // Both handles were checked to be joints above, so this cannot fail.
                let _ = self.place_joint(f, q);
            }
        }
    }

    /// Moves simulation time forward by one step.
    pub(crate) fn advance_time(&mut self) {
        self.steps += 1;
        self.time = self.steps as f64 * self.settings.dt;
    }

    fn read_back(&mut self) {
        // Dynamic joint positions and velocities.
        for (&h, b) in &self.physics.joints {
            if let Some((mb, link)) = self.physics.world.multibody_joints.get(b.joint)
                && let Some(l) = mb.link(link)
            {
                let q = f64::from(l.joint.coords()[b.coord]);
                let v = mb.joint_velocity(l);
                let vel = v.get(0).copied().map_or(0.0, f64::from);
                if !(q.is_finite() && vel.is_finite()) {
                    // A blown-up mechanism (stopped by containment): keep the last good
                    // reading rather than spread NaN into the tree and the API.
                    continue;
                }
                if let ObjectKind::Joint(j) = &mut self.objects[h as usize].kind {
                    j.position = if j.cyclic { math::wrap_angle(q) } else { q };
                    j.velocity = vel;
                    j.force = match j.mode {
                        _ if j.mimic.is_some() => 0.0,
                        JointMode::Position => (j.kp * (j.reference - q) + j.kd * (j.reference_velocity - vel))
                            .clamp(-j.max_force, j.max_force),
                        JointMode::Velocity => (j.kd * (j.commanded_velocity() - vel)).clamp(-j.max_force, j.max_force),
                        JointMode::Force => j.target_force,
                        JointMode::Kinematic | JointMode::Free => 0.0,
                    };
                }
            }
        }
        // Free bodies: their poses define their objects' local poses. Parents come first
        // in `order`, so one pass suffices.
        for i in 0..self.order.len() {
            let h = self.order[i];
            let world = match self.physics.body_of.get(&h) {
                Some(&(bi, rel))
                    if self.physics.bodies[bi].object == h && self.physics.bodies[bi].role == BodyRole::Free =>
                {
                    self.physics
                        .world
                        .bodies
                        .get(self.physics.bodies[bi].handle)
                        .map(|rb| math::from_physics(rb.position()) * rel)
                }
                _ => None,
            };
            let parent = self.parent_frame(h);
            let o = &mut self.objects[h as usize];
            match world {
                Some(w) => {
                    o.world = w;
                    o.local = parent.inverse() * w;
                }
                None => o.world = parent * o.local,
            }
        }
        // Force sensors: the joint impulse over the step is the transmitted force.
        for (&h, &jh) in &self.physics.force_joints {
            if let Some(j) = self.physics.world.impulse_joints.get(jh) {
                let imp = j.impulses;
                // rapier splits its step into `num_solver_iterations` substeps and keeps
                // the impulse of the last one, so the force is impulse / (dt / n).
                let ip = &self.physics.world.integration_parameters;
                let scale = ip.num_solver_iterations as f64 / f64::from(ip.dt);
                if let ObjectKind::ForceSensor(r) = &mut self.objects[h as usize].kind {
                    r.valid = true;
                    r.force = Vec3::new(f64::from(imp[0]), f64::from(imp[1]), f64::from(imp[2])) * scale;
                    r.torque = Vec3::new(f64::from(imp[3]), f64::from(imp[4]), f64::from(imp[5])) * scale;
                }
            }
        }
    }

    /// Linear and angular velocity of an object in the world frame (m/s, rad/s): that of
    /// the body it rides on, zero for objects not attached to a body.
    ///
    /// # Errors
    /// No such object.
    pub fn velocity(&self, h: Handle) -> Result<(Vec3, Vec3), SimError> {
        self.object(h)?;
        let Some(&(bi, _)) = self.physics.body_of.get(&h) else {
            return Ok((Vec3::zeros(), Vec3::zeros()));
        };
        let Some(rb) = self.physics.world.bodies.get(self.physics.bodies[bi].handle) else {
            return Ok((Vec3::zeros(), Vec3::zeros()));
        };
        let w = math::vec_from_physics(rb.angvel());
        // The body's linear velocity is at its centre of mass; move it to the object origin.
        let com = math::vec_from_physics(rb.center_of_mass());
        let p = self.objects[h as usize].world.translation.vector;
        Ok((math::vec_from_physics(rb.linvel()) + w.cross(&(p - com)), w))
    }

    /// Stores proximity sensor `h`'s latest detection (the sensor floor computes it).
    pub(crate) fn store_detection(&mut self, h: Handle, detection: Option<Detection>) {
        if let Some(Object {
            kind: ObjectKind::ProximitySensor(s),
            ..
        }) = self.objects.get_mut(h as usize)
        {
            s.last = Some(detection);
        }
    }

    /// The object owning a collider.
    pub(crate) fn collider_owner(&self, c: ColliderHandle) -> Option<Handle> {
        self.physics.collider_object.get(&c).copied()
    }

    /// The rapier world, read-only (sensors, distance queries, the viewer).
    pub(crate) fn physics(&self) -> &Physics {
        &self.physics
    }

    pub(crate) fn physics_mut(&mut self) -> &mut Physics {
        &mut self.physics
    }

    /// The object that owns rapier body `b` (`None` for the world anchor).
    pub(crate) fn body_owner(&self, b: RigidBodyHandle) -> Option<Handle> {
        self.physics
            .bodies
            .iter()
            .find(|e| e.handle == b)
            .map(|e| e.object)
            .filter(|&o| o >= 0)
    }

    /// Pose of `h` expressed in frame `rel`: `-1` world, `-11` (`sim.handle_parent`) the
    /// parent's frame, otherwise the frame of object `rel` (a joint's moving frame).
    ///
    /// # Errors
    /// No such object.
    pub fn pose_relative(&self, h: Handle, rel: Handle) -> Result<Pose, SimError> {
        let world = self.object(h)?.world;
        Ok(self.frame(h, rel)?.inverse() * world)
    }

    /// The world pose of reference frame `rel` for object `h` (see [`World::pose_relative`]).
    ///
    /// # Errors
    /// No such object.
    pub fn frame(&self, h: Handle, rel: Handle) -> Result<Pose, SimError> {
        match rel {
            -1 => Ok(Pose::identity()),
            -11 => {
                self.object(h)?;
                Ok(self.parent_frame(h))
            }
            r => {
                self.object(r)?;
                Ok(self.child_frame(r))
            }
        }
    }

    /// Parent of an object.
    ///
    /// # Errors
    /// No such object.
    pub fn parent(&self, h: Handle) -> Result<Option<Handle>, SimError> {
        Ok(self.object(h)?.parent)
    }

    /// Shapes (with their colliders) for distance and collision queries.
    pub(crate) fn colliders_of(&self, h: Handle) -> &[ColliderHandle] {
        self.physics.object_colliders.get(&h).map_or(&[], Vec::as_slice)
    }

    /// Gives up the world's rapier state and the number of rapier steps that make one
    /// simulation step: the bare physics floor that benchmarks compare gantry's per-step
    /// overhead against.
    pub fn into_rapier(self) -> (PhysicsWorld, u32) {
        (self.physics.world, self.physics.rapier_steps)
    }

    /// Pose of a rapier body as the physics engine sees it (f32), for consistency tests.
    pub fn physics_pose(&self, h: Handle) -> Option<Pose> {
        let &(bi, rel) = self.physics.body_of.get(&h)?;
        let rb = self.physics.world.bodies.get(self.physics.bodies[bi].handle)?;
        Some(math::from_physics(rb.position()) * rel)
    }
}

/// Moves a body that follows the tree: a kinematic body is given its next pose (so
/// contacts see its velocity); one that roots a mechanism was made fixed (see
/// `Physics::mount`) and is teleported.
/// Puts every collider where the API put its body: rapier moves a body's colliders
/// with it only inside a step, and a kinematic body placed through the API only gets
/// there at the next step (`set_next_kinematic_position`, so that the step knows its
/// velocity). A query before that step must see every body where the API put it; the
/// step recomputes the colliders from the bodies, to the same poses.
fn place_colliders(world: &mut rapier3d::prelude::PhysicsWorld) {
    let rapier3d::prelude::PhysicsWorld { bodies, colliders, .. } = world;
    for (_, rb) in bodies.iter() {
        let at = if rb.is_kinematic() {
            *rb.next_position()
        } else {
            *rb.position()
        };
        for &ch in rb.colliders() {
            if let Some(c) = colliders.get_mut(ch)
                && let Some(rel) = c.position_wrt_parent().copied()
                && *c.position() != at * rel
            {
                c.set_position(at * rel);
            }
        }
    }
}

fn place_kinematic(rb: &mut RigidBody, pose: rapier3d::math::Pose) {
    if rb.is_fixed() {
        rb.set_position(pose, true);
    } else {
        rb.set_next_kinematic_position(pose);
    }
}

/// The world frame an object's children hang from: its own frame, moved by a joint's
/// motion (children of a joint are attached to its moving side, as in CoppeliaSim).
fn hanging_frame(o: &Object) -> Pose {
    match &o.kind {
        ObjectKind::Joint(j) => o.world * j.motion(),
        _ => o.world,
    }
}

impl ObjectTree for World {
    fn roots(&self) -> &[i64] {
        &self.roots
    }
    fn children(&self, h: i64) -> &[i64] {
        self.objects.get(h as usize).map_or(&[], |o| o.children.as_slice())
    }
    fn parent(&self, h: i64) -> Option<i64> {
        self.objects.get(h as usize).and_then(|o| o.parent)
    }
    fn alias(&self, h: i64) -> &str {
        self.objects.get(h as usize).map_or("", |o| o.alias.as_str())
    }
    fn is_model_base(&self, h: i64) -> bool {
        self.objects.get(h as usize).is_some_and(|o| o.model_base)
    }
}
