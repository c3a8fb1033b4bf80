//! Editing the scene while it runs: creating, copying and removing objects, re-parenting
//! and renaming them, shape and joint properties, one-step forces and world settings
//! (what `sim.createPrimitiveShape`, `sim.removeObjects`, `sim.setObjectParent`,
//! `sim.addForce`, `sim.setArrayParam` and their kin need).
//!
//! Invariants every edit keeps:
//! - **Handles are never reused**, as in CoppeliaSim: a removed object stays in the
//!   object table as a tombstone, and every lookup by its handle fails with
//!   [`SimError::NoSuchObject`] ("object does not exist").
//! - The tree (`roots`, `children`, `order`) never names a removed object, and `order`
//!   stays parents-first.
//! - rapier mirrors the tree: an edit takes the physics of the subtrees it touches out of
//!   rapier and inserts them again by the loader's rules ([`Physics::insert`]), which
//!   also restarts their dynamics (CoppeliaSim's `sim.resetDynamicObject`).
//! - The caches built with the world (mimic followers, speed-limited joints) are rebuilt
//!   after every structural edit; collections and drawing objects drop removed objects.
//! - Every change the viewer shows (objects, parents, aliases, colours, joint modes,
//!   sensor settings, layers) bumps [`World::scene_revision`], which makes the viewer
//!   fetch the scene description again.
//!
//! Not done: scripts are not copied with their objects, and a removed object's script is
//! the script host's business.

use std::collections::{HashMap, HashSet};

use rapier3d::prelude::RigidBodyHandle;

use super::collection::ItemKind;
use super::edit_state::{ColorComponent, EditCounters, EditState, gone};
use super::object::{Handle, Joint, Object, ObjectKind};
use super::physics::{BodyRole, TreeView, configure_integration, geometry_volume, inertial_properties};
use super::world::World;
use crate::error::SimError;
use crate::math::{self, Pose, Vec3};
use crate::scene::{Geometry, JointMode, JointModel, LightModel, MassModel, SceneModel, ShapeModel, VisionModel};

/// Smallest shape mass, kg (CoppeliaSim clamps `sim.setShapeMass` to the same).
pub const MIN_SHAPE_MASS: f64 = 1e-7;

pub(super) fn invalid(msg: impl Into<String>) -> SimError {
    SimError::BadArgument(msg.into())
}

impl World {
    /// Whether `h` names an object removed at run time (its handle is never reused).
    pub fn is_removed(&self, h: Handle) -> bool {
        self.edit.is_removed(h)
    }

    /// A number that changes whenever the scene's description does: objects created,
    /// copied or removed, re-parented or renamed, shape colours, static/dynamic flags,
    /// joint modes, vision sensor settings or visibility layers. The viewer sends the
    /// scene again when it changes.
    pub fn scene_revision(&self) -> u64 {
        self.edit.revision
    }

    /// A number that changes whenever a shape's geometry does after loading (a shape
    /// scaled by `sim.setShapeBB` or `sim.scaleObject`): caches of tessellated shapes
    /// (the vision sensors') rebuild when it changes.
    pub fn geometry_revision(&self) -> u64 {
        self.edit.geometry_revision
    }

    /// Records that shape `h`'s geometry changed: the scene description and the caches
    /// of tessellated shapes are out of date.
    pub(super) fn geometry_changed(&mut self, _h: Handle) {
        self.edit.geometry_revision += 1;
        self.bump();
    }

    /// A number that changes whenever objects are created, copied, removed or
    /// re-parented: when the list and order of [`World::handles`] may have changed (a
    /// subset of the changes [`World::scene_revision`] counts).
    pub fn structure_revision(&self) -> u64 {
        let c = self.edit.counters;
        c.created + c.destroyed + c.hierarchy
    }

    /// How many objects were created and removed, and how often the hierarchy changed.
    pub fn edit_counters(&self) -> EditCounters {
        self.edit.counters
    }

    /// Moves this world's revisions past `earlier`'s: for a world that takes the place
    /// of `earlier` (a copy restored by a stop or an undo), so that whoever compares
    /// revisions (the viewer, the vision sensors' caches) sees a change, never the same
    /// number for another scene.
    pub fn continue_revisions(&mut self, earlier: &World) {
        self.edit.revision = self.edit.revision.max(earlier.edit.revision) + 1;
        self.edit.geometry_revision = self.edit.geometry_revision.max(earlier.edit.geometry_revision) + 1;
        let (now, before) = (self.structure_revision(), earlier.structure_revision());
        self.edit.counters.hierarchy += before.saturating_sub(now) + 1;
    }

    pub(super) fn bump(&mut self) {
        self.edit.revision += 1;
    }

    /// Adds an object below `parent` (a root for `None`) at pose `local` in the parent's
    /// frame, with its physics, and returns its handle (a new one, never a reused one).
    ///
    /// # Errors
    /// The parent does not exist.
    pub fn add_object(
        &mut self,
        alias: &str,
        kind: ObjectKind,
        parent: Option<Handle>,
        local: Pose,
    ) -> Result<Handle, SimError> {
        if let Some(p) = parent {
            self.object(p)?;
        }
        let h = self.push_object(Object {
            alias: alias.to_owned(),
            parent,
            children: Vec::new(),
            local,
            world: Pose::identity(),
            model_base: false,
            extension: String::new(),
            kind,
        });
        self.refresh_subtree(h);
        self.rebuild_physics(&[h]);
        self.edit.counters.created += 1;
        self.bump();
        Ok(h)
    }

    /// Appends an object to the table and links it under its parent (which must exist
    /// and come earlier in `order`); world poses and physics are the caller's business.
    fn push_object(&mut self, object: Object) -> Handle {
        let h = self.objects.len() as Handle;
        match object.parent {
            Some(p) => self.objects[p as usize].children.push(h),
            None => self.roots.push(h),
        }
        self.objects.push(object);
        self.edit.removed.push(false);
        self.order.push(h);
        h
    }

    /// Adds a joint made as the scene loader makes `model`'s (at its initial position,
    /// with its physics) below `parent` at pose `local`, and returns its handle. A mimic
    /// leader in `model` is not kept: a created joint follows no other.
    ///
    /// # Errors
    /// The parent does not exist.
    pub fn add_joint(
        &mut self,
        alias: &str,
        model: &JointModel,
        parent: Option<Handle>,
        local: Pose,
    ) -> Result<Handle, SimError> {
        let model = JointModel {
            mimic: None,
            ..model.clone()
        };
        let joint = Joint::from_model(&model, |leader| leader as Handle);
        self.add_object(alias, ObjectKind::Joint(joint), parent, local)
    }

    /// Removes objects (`sim.removeObjects`). As in CoppeliaSim, the children of a
    /// removed object are kept: they move up to its parent, where they are in the world.
    /// Collections forget removed objects, and drawing objects attached to them go.
    ///
    /// # Errors
    /// One of the handles names no object; then nothing is removed.
    pub fn remove_objects(&mut self, handles: &[Handle]) -> Result<(), SimError> {
        for &h in handles {
            self.object(h)?;
        }
        let mut regrown: Vec<Handle> = Vec::new();
        for &h in handles {
            if self.edit.is_removed(h) {
                continue; // listed twice
            }
            for d in self.subtrees(&[h]) {
                self.physics.remove_object(d);
            }
            let parent = self.objects[h as usize].parent;
            let children = std::mem::take(&mut self.objects[h as usize].children);
            // The children take the removed object's place among its siblings.
            let siblings = match parent {
                Some(p) => &mut self.objects[p as usize].children,
                None => &mut self.roots,
            };
            match siblings.iter().position(|&x| x == h) {
                Some(at) => {
                    siblings.splice(at..=at, children.iter().copied());
                }
                None => siblings.extend(children.iter().copied()),
            }
            for &c in &children {
                let world = self.objects[c as usize].world;
                self.objects[c as usize].parent = parent;
                self.objects[c as usize].local = self.parent_frame(c).inverse() * world;
            }
            regrown.extend(children);
            self.objects[h as usize] = Object {
                alias: String::new(),
                parent: None,
                children: Vec::new(),
                local: Pose::identity(),
                world: Pose::identity(),
                model_base: false,
                extension: String::new(),
                kind: ObjectKind::Dummy,
            };
            self.edit.removed[h as usize] = true;
            self.edit.counters.destroyed += 1;
        }
        let edit = &self.edit;
        self.order.retain(|&h| !edit.is_removed(h));
        regrown.retain(|&c| !edit.is_removed(c));
        self.forget_removed();
        self.physics.prune_joints();
        self.rebuild_physics(&regrown);
        self.edit.counters.hierarchy += 1;
        self.bump();
        Ok(())
    }

    /// Drops what referred to removed objects on this floor: collection items, mimic
    /// couplings to removed leaders, side tables ([`crate::sim::Sim::forget_removed`]
    /// does the floors above).
    fn forget_removed(&mut self) {
        let edit = &self.edit;
        for c in self.collections.iter_mut().flatten() {
            c.items
                .retain(|i| i.kind == ItemKind::All || !edit.is_removed(i.object));
        }
        let removed: Vec<Handle> = (0..self.objects.len() as Handle)
            .filter(|h| edit.is_removed(*h))
            .collect();
        for h in removed {
            self.custom.remove_object(h);
            self.selection.forget(h);
        }
        let mut freed = Vec::new();
        for (h, o) in self.objects.iter_mut().enumerate() {
            if let ObjectKind::Joint(j) = &mut o.kind
                && let Some(m) = j.mimic
                && edit.is_removed(m.leader)
            {
                // A follower without a leader is an ordinary joint again.
                j.mimic = None;
                freed.push(h as Handle);
            }
        }
        let EditState {
            removed,
            layers,
            colors,
            ..
        } = &mut self.edit;
        layers.retain(|&h, _| !gone(removed, h));
        colors.retain(|&(h, _), _| !gone(removed, h));
        for h in freed {
            self.push_motor(h);
        }
    }

    /// Copies objects (`sim.copyPasteObjects`) and returns the copies' handles in the
    /// order given. A copy keeps its alias and its pose in the world; it hangs below the
    /// copy of its parent when that was copied too, and at the root otherwise. With
    /// `full_models`, a model base is copied with everything below it. Copies have their
    /// own physics (a copied dynamic shape falls); scripts are not copied.
    ///
    /// # Errors
    /// One of the handles names no object; then nothing is copied.
    pub fn copy_objects(&mut self, handles: &[Handle], full_models: bool) -> Result<Vec<Handle>, SimError> {
        let mut chosen: HashSet<Handle> = HashSet::new();
        for &h in handles {
            let o = self.object(h)?;
            chosen.insert(h);
            if full_models && o.model_base {
                chosen.extend(self.subtrees(&[h]));
            }
        }
        // Parents first, so every copy's parent copy exists when it is made.
        let sources: Vec<Handle> = self.order.iter().copied().filter(|h| chosen.contains(h)).collect();
        let mut copy_of: HashMap<Handle, Handle> = HashMap::new();
        let mut tops = Vec::new();
        for &s in &sources {
            let src = self.objects[s as usize].clone();
            let parent = src.parent.and_then(|p| copy_of.get(&p).copied());
            let local = if parent.is_some() { src.local } else { src.world };
            let c = self.push_object(Object {
                parent,
                children: Vec::new(),
                local,
                ..src
            });
            if parent.is_none() {
                tops.push(c);
            }
            if let Some(&l) = self.edit.layers.get(&s) {
                self.edit.layers.insert(c, l);
            }
            let colors: Vec<_> = self
                .edit
                .colors
                .iter()
                .filter(|((h, _), _)| *h == s)
                .map(|((_, k), v)| ((c, *k), v.clone()))
                .collect();
            self.edit.colors.extend(colors);
            copy_of.insert(s, c);
        }
        // A copied follower follows the copy of its leader when that was copied too.
        for &c in copy_of.values() {
            if let ObjectKind::Joint(Joint { mimic: Some(m), .. }) = &mut self.objects[c as usize].kind
                && let Some(&l) = copy_of.get(&m.leader)
            {
                m.leader = l;
            }
        }
        for &t in &tops {
            self.refresh_subtree(t);
        }
        self.rebuild_physics(&tops);
        self.edit.counters.created += sources.len() as u64;
        self.bump();
        Ok(handles.iter().map(|h| copy_of[h]).collect())
    }

    /// Adds the objects of `model` (a model file: `sim.loadModel`) to the scene, with
    /// their physics, where the model places them; returns each model object's new
    /// handle, in the model's order (its first object is the model base), and the
    /// warnings of loading and building it.
    pub fn import_model(&mut self, model: &SceneModel) -> (Vec<Handle>, Vec<String>) {
        // Built as a world of its own first, so that every object is made exactly as at
        // load (initial joint positions, sensors, world poses), then moved in.
        let other = World::new(model);
        let mut warnings = other.warnings().to_vec();
        let mut map: Vec<Handle> = Vec::with_capacity(other.objects.len());
        let mut tops = Vec::new();
        // The model's vision sensors join the scene's within the image memory cap; those
        // past it come in as dummies, so the rest of the model still loads.
        let mut vision_bytes = self.vision_image_bytes(None);
        for src in &other.objects {
            let parent = src.parent.map(|p| map[p as usize]);
            let mut kind = src.kind.clone();
            if let ObjectKind::VisionSensor(v) = &kind {
                let bytes = crate::scene::vision_image_bytes(v.resolution);
                if vision_bytes + bytes > crate::scene::MAX_VISION_IMAGE_BYTES {
                    warnings.push(format!(
                        "{}: a {}x{} vision sensor would bring the scene's vision images over {} MiB; loaded as a dummy",
                        src.alias,
                        v.resolution[0],
                        v.resolution[1],
                        crate::scene::MAX_VISION_IMAGE_BYTES >> 20
                    ));
                    kind = ObjectKind::Dummy;
                } else {
                    vision_bytes += bytes;
                }
            }
            let h = self.push_object(Object {
                parent,
                children: Vec::new(),
                kind,
                ..src.clone()
            });
            if parent.is_none() {
                tops.push(h);
            }
            map.push(h);
        }
        for &h in &map {
            if let ObjectKind::Joint(Joint { mimic: Some(m), .. }) = &mut self.objects[h as usize].kind {
                m.leader = map[m.leader as usize];
            }
        }
        for &t in &tops {
            self.refresh_subtree(t);
        }
        self.rebuild_physics(&tops);
        self.link_loop_closures(model.dummy_links.iter().map(|&[a, b]| [map[a], map[b]]), false);
        self.link_loop_closures(model.ball_links.iter().map(|&[a, b]| [map[a], map[b]]), true);
        for r in &model.referenced_handles {
            let targets = r.targets.iter().map(|&t| map[t]).collect();
            self.custom.set_referenced(map[r.object], &r.tag, targets);
        }
        for p in &model.user_parameters {
            self.custom
                .set(map[p.object], &p.name, crate::Value::Str(p.value.clone()));
        }
        for (i, o) in model.objects.iter().enumerate() {
            if o.layer != 1 {
                self.edit.layers.insert(map[i], i64::from(o.layer));
            }
        }
        // Collection names stay unique among live collections: a model's collection whose
        // name is taken (a second copy of the same robot) is left out, with a warning.
        for c in &model.collections {
            if self.collection_named(&c.name).is_some() {
                warnings.push(format!(
                    "collection '{}' already exists; the model's is not added",
                    c.name
                ));
                continue;
            }
            self.collections
                .push(Some(super::Collection::from_model(c, |i| map[i])));
        }
        // The model's textures join the store, under new ids.
        warnings.extend(self.load_textures(model, |i| map[i]));
        self.urdf_robots.extend(
            model
                .urdf_robots
                .iter()
                .map(|r| super::UrdfRobot::from_model(r, |i| map[i])),
        );
        self.scripts
            .extend(model.scripts.iter().map(|s| crate::scene::ScriptModel {
                object: map[s.object] as usize,
                ..s.clone()
            }));
        self.edit.counters.created += map.len() as u64;
        self.bump();
        (map, warnings)
    }

    /// Bytes of RGB and depth images all vision sensors hold (see
    /// [`crate::scene::MAX_VISION_IMAGE_BYTES`]), leaving out `except`.
    pub fn vision_image_bytes(&self, except: Option<Handle>) -> u64 {
        self.handles()
            .iter()
            .filter(|&&o| Some(o) != except)
            .filter_map(|&o| match &self.object(o).ok()?.kind {
                ObjectKind::VisionSensor(v) => Some(crate::scene::vision_image_bytes(v.resolution)),
                _ => None,
            })
            .sum()
    }

    /// Moves `h` below `parent` (the root for `None`), last among its new siblings
    /// (`sim.setObjectParent`). With `keep_in_place` the object stays where it is in the
    /// world; otherwise it keeps its pose relative to its parent, and so moves. Its
    /// subtree's dynamics restart.
    ///
    /// # Errors
    /// No such object or parent, or `parent` is `h` or lies below it.
    pub fn set_parent(&mut self, h: Handle, parent: Option<Handle>, keep_in_place: bool) -> Result<(), SimError> {
        self.object(h)?;
        if let Some(p) = parent {
            self.object(p)?;
            let mut cur = Some(p);
            while let Some(c) = cur {
                if c == h {
                    return Err(invalid(format!(
                        "object {p} is {h} or lies below it, so it cannot become its parent"
                    )));
                }
                cur = self.objects[c as usize].parent;
            }
        }
        let world = self.objects[h as usize].world;
        match self.objects[h as usize].parent {
            Some(old) => self.objects[old as usize].children.retain(|&x| x != h),
            None => self.roots.retain(|&x| x != h),
        }
        match parent {
            Some(p) => self.objects[p as usize].children.push(h),
            None => self.roots.push(h),
        }
        self.objects[h as usize].parent = parent;
        if keep_in_place {
            self.objects[h as usize].local = self.parent_frame(h).inverse() * world;
        }
        self.refresh_subtree(h);
        self.rebuild_order();
        self.rebuild_physics(&[h]);
        self.edit.counters.hierarchy += 1;
        self.bump();
        Ok(())
    }

    /// Renames an object (`sim.setObjectAlias`). Characters that would break paths
    /// (anything but letters, digits and `_`) become `_`, as CoppeliaSim does.
    ///
    /// # Errors
    /// No such object, or an empty alias.
    pub fn set_alias(&mut self, h: Handle, alias: &str) -> Result<(), SimError> {
        self.object(h)?;
        if alias.is_empty() {
            return Err(invalid("the alias must not be empty"));
        }
        let clean: String = alias
            .chars()
            .map(|c| if c.is_alphanumeric() || c == '_' { c } else { '_' })
            .collect();
        self.objects[h as usize].alias = clean;
        self.bump();
        Ok(())
    }

    /// Restarts the dynamics of `h` and its subtree (`sim.resetDynamicObject`): their
    /// bodies are removed from the physics engine and added again where the tree says,
    /// at rest.
    ///
    /// # Errors
    /// No such object.
    pub fn reset_dynamics(&mut self, h: Handle) -> Result<(), SimError> {
        self.object(h)?;
        self.rebuild_physics(&[h]);
        Ok(())
    }

    /// Rebuilds rapier's side of the subtrees rooted at `tops` from the tree as it is.
    pub(super) fn rebuild_physics(&mut self, tops: &[Handle]) {
        let list = self.subtrees(tops);
        if list.is_empty() {
            return;
        }
        for &h in &list {
            self.physics.remove_object(h);
        }
        self.physics.prune_joints();
        let objects = &self.objects;
        let model_props = &self.edit.model_props;
        let tree = TreeView {
            parent: &|h| objects[h as usize].parent,
            kind: &|h| &objects[h as usize].kind,
            world: &|h| objects[h as usize].world,
            overrides: &|h| super::properties::cumulative(model_props, |x| objects[x as usize].parent, h),
        };
        let mut warnings = Vec::new();
        self.physics.insert(&tree, &list, &mut warnings);
        // Followers outside the rebuilt part lost their coupling with the leader's old
        // link: couple them to the new one.
        let rebuilt: HashSet<Handle> = list.iter().copied().collect();
        let orphans: Vec<Handle> = self
            .mimics
            .iter()
            .copied()
            .filter(|f| !rebuilt.contains(f))
            .filter(|&f| {
                matches!(&objects[f as usize].kind, ObjectKind::Joint(Joint { mimic: Some(m), .. }) if rebuilt.contains(&m.leader))
            })
            .collect();
        self.physics.couple_mimics(&tree, &orphans, &mut warnings);
        let t = self.time();
        for w in crate::scene::dedup_warnings(warnings) {
            self.log.push(t, 300, "physics", &w);
        }
        self.refresh_caches();
        self.queries_stale = true;
    }

    /// Every live object of the subtrees rooted at `tops`, parents first, each once.
    pub(super) fn subtrees(&self, tops: &[Handle]) -> Vec<Handle> {
        let mut seen = HashSet::new();
        let mut out = Vec::new();
        for &t in tops {
            let mut stack = vec![t];
            while let Some(h) = stack.pop() {
                if self.object(h).is_err() || !seen.insert(h) {
                    continue;
                }
                out.push(h);
                stack.extend(self.objects[h as usize].children.iter().rev().copied());
            }
        }
        out
    }

    /// Recomputes `order` (parents first, in hierarchy order) after re-parenting.
    fn rebuild_order(&mut self) {
        let roots = self.roots.clone();
        self.order = self.subtrees(&roots);
    }

    /// Rebuilds the lists the world keeps of mimic followers and speed-limited joints
    /// (at construction, and after every edit that adds or removes objects).
    pub(super) fn refresh_caches(&mut self) {
        let live = |h: &Handle| !self.edit.is_removed(*h);
        let joint = |h: Handle| match &self.objects[h as usize].kind {
            ObjectKind::Joint(j) => Some(j),
            _ => None,
        };
        let all = (0..self.objects.len() as Handle).filter(live);
        self.mimics = all
            .clone()
            .filter(|&h| joint(h).is_some_and(|j| j.mimic.is_some()))
            .collect();
        self.profiled = all
            .filter(|&h| joint(h).is_some_and(|j| j.max_velocity.is_some()) && self.physics.joints.contains_key(&h))
            .collect();
    }

    /// The shape model behind a handle.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape(&self, h: Handle) -> Result<&ShapeModel, SimError> {
        match &self.object(h)?.kind {
            ObjectKind::Shape(s) => Ok(s),
            other => Err(SimError::WrongKind {
                handle: h,
                expected: "shape",
                actual: other.name(),
            }),
        }
    }

    pub(super) fn shape_mut(&mut self, h: Handle) -> Result<&mut ShapeModel, SimError> {
        match &mut self.object_mut(h)?.kind {
            ObjectKind::Shape(s) => Ok(s),
            other => Err(SimError::WrongKind {
                handle: h,
                expected: "shape",
                actual: other.name(),
            }),
        }
    }

    /// Makes a shape dynamic (simulated) or static (`sim.shapeintparam_static`); its
    /// subtree's physics is rebuilt, so the change takes effect at once.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn set_shape_dynamic(&mut self, h: Handle, dynamic: bool) -> Result<(), SimError> {
        let s = self.shape_mut(h)?;
        if s.dynamic != dynamic {
            s.dynamic = dynamic;
            self.rebuild_physics(&[h]);
            self.bump();
        }
        Ok(())
    }

    /// Makes a shape take part in contacts or not (`sim.shapeintparam_respondable`); a
    /// non-respondable shape is still seen by sensors and queries.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn set_shape_respondable(&mut self, h: Handle, respondable: bool) -> Result<(), SimError> {
        self.shape_mut(h)?.respondable = respondable;
        let respondable = respondable
            && self.cumulative_model_property(h) & super::property_flags::model_property::NOT_RESPONDABLE == 0;
        for c in self.colliders_of(h).to_vec() {
            if let Some(col) = self.physics.world.colliders.get_mut(c) {
                col.set_sensor(!respondable);
                col.set_collision_groups(super::physics::pair_groups(col.solver_groups(), respondable));
            }
        }
        self.queries_stale = true;
        Ok(())
    }

    /// A shape's mass, kg, from its model (a density is integrated over the collision
    /// geometry; meshes count with their bounding box, as the loader spreads masses).
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape_mass(&self, h: Handle) -> Result<f64, SimError> {
        let s = self.shape(h)?;
        Ok(match s.mass {
            MassModel::Density(d) => d * s.geoms.iter().map(|g| geometry_volume(&g.geometry)).sum::<f64>(),
            MassModel::Mass(m) => m,
            MassModel::Inertial { mass, .. } => mass,
        })
    }

    /// Sets a shape's mass, kg (`sim.setShapeMass`), at least [`MIN_SHAPE_MASS`]. An
    /// explicit inertia tensor scales with it. The body keeps moving: its colliders'
    /// masses are scaled in place rather than rebuilt.
    ///
    /// # Errors
    /// No such object, not a shape, or a mass that is not a finite number.
    pub fn set_shape_mass(&mut self, h: Handle, mass: f64) -> Result<(), SimError> {
        if !mass.is_finite() {
            return Err(invalid(format!("mass must be a finite number, got {mass}")));
        }
        let mass = mass.max(MIN_SHAPE_MASS);
        let s = self.shape_mut(h)?;
        s.mass = match s.mass {
            MassModel::Inertial {
                mass: old,
                com,
                frame,
                inertia,
            } => {
                let k = if old > 0.0 { mass / old } else { 1.0 };
                MassModel::Inertial {
                    mass,
                    com,
                    frame,
                    inertia: inertia.map(|i| i * k),
                }
            }
            _ => MassModel::Mass(mass),
        };
        let model = s.mass;
        // rapier: the colliders of this shape carry its mass (unless an explicit
        // inertial does); scale them so that they sum to the new mass.
        let colliders = self.colliders_of(h).to_vec();
        let world = &mut self.physics.world;
        let total: f32 = colliders
            .iter()
            .filter_map(|&c| world.colliders.get(c))
            .map(|c| c.mass())
            .sum();
        let mut bodies = Vec::new();
        for &c in &colliders {
            if let Some(col) = world.colliders.get_mut(c) {
                if total > 0.0 && inertial_properties(&model).is_none() {
                    let share = col.mass() / total;
                    col.set_mass(share * mass as f32);
                }
                bodies.extend(col.parent());
            }
        }
        for b in bodies {
            if let Some(rb) = world.bodies.get_mut(b) {
                rb.recompute_mass_properties_from_colliders(&world.colliders);
            }
        }
        // An explicit inertial: that of the body's owner, or of a shape fused into the
        // body, which sums them.
        if let Some(props) = inertial_properties(&model) {
            self.physics.set_inertial(h, Some(props));
        }
        Ok(())
    }

    /// A colour component of a shape: the colour of its first visual for
    /// ambient-diffuse (`None` when it has no visual), the stored or default value for
    /// the components gantry does not render.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape_color(&self, h: Handle, component: ColorComponent) -> Result<Option<Vec<f64>>, SimError> {
        let s = self.shape(h)?;
        Ok(match component {
            ColorComponent::AmbientDiffuse | ColorComponent::Diffuse => s
                .visuals
                .first()
                .map(|v| v.color.iter().map(|&c| f64::from(c)).collect()),
            other => Some(
                self.edit
                    .colors
                    .get(&(h, other))
                    .cloned()
                    .unwrap_or_else(|| other.default_value()),
            ),
        })
    }

    /// Sets a colour component of every visual of a shape, each value clamped to 0..1
    /// (`sim.setShapeColor` with no colour name). Only ambient-diffuse is drawn.
    ///
    /// # Errors
    /// No such object, not a shape, or fewer values than the component has.
    pub fn set_shape_color(&mut self, h: Handle, component: ColorComponent, values: &[f64]) -> Result<(), SimError> {
        self.shape(h)?;
        let n = component.value_count();
        if values.len() < n || values[..n].iter().any(|v| !v.is_finite()) {
            return Err(invalid(format!("the colour needs {n} finite values")));
        }
        let v: Vec<f64> = values[..n].iter().map(|c| c.clamp(0.0, 1.0)).collect();
        match component {
            ColorComponent::AmbientDiffuse | ColorComponent::Diffuse => {
                for visual in &mut self.shape_mut(h)?.visuals {
                    visual.color = [v[0] as f32, v[1] as f32, v[2] as f32];
                }
            }
            other => {
                self.edit.colors.insert((h, other), v);
            }
        }
        self.bump();
        Ok(())
    }

    /// The rapier body a dynamic shape owns, or is fused into (see `physics`), with, for
    /// a fused shape, its own centre of mass in the world frame: where a force given
    /// without a point acts on it.
    fn dynamic_body(&self, h: Handle) -> Result<(RigidBodyHandle, Option<Vec3>), SimError> {
        self.shape(h)?;
        let fused = self.physics.fused.contains_key(&h);
        match self.physics.body_of.get(&h) {
            Some(&(bi, _))
                if (self.physics.bodies[bi].object == h || fused)
                    && matches!(self.physics.bodies[bi].role, BodyRole::Free | BodyRole::Link) =>
            {
                let com = fused.then(|| self.fused_centre_of_mass(h));
                Ok((self.physics.bodies[bi].handle, com))
            }
            _ => Err(invalid(format!(
                "shape {h} is not dynamically simulated (make it dynamic with sim.setObjectInt32Param(h, sim.shapeintparam_static, 0))"
            ))),
        }
    }

    /// A fused shape's own centre of mass, world frame: that of its explicit inertial,
    /// else of its colliders' masses, else its origin.
    fn fused_centre_of_mass(&self, h: Handle) -> Vec3 {
        let world = self.objects[h as usize].world;
        if let Ok(ShapeModel {
            mass: MassModel::Inertial { com, .. },
            ..
        }) = self.shape(h)
        {
            return world.transform_point(&Vec3::from(*com).into()).coords;
        }
        let (mut mass, mut moment) = (0.0, Vec3::zeros());
        for c in self.colliders_of(h) {
            if let Some(col) = self.physics.world.colliders.get(*c) {
                let m = f64::from(col.mass());
                let local = math::vec_from_physics(col.mass_properties().local_com);
                moment += m * math::from_physics(col.position()).transform_point(&local.into()).coords;
                mass += m;
            }
        }
        if mass > 0.0 {
            moment / mass
        } else {
            world.translation.vector
        }
    }

    /// Adds a force (N) and a torque (N·m), both in the world frame, to a dynamic shape
    /// for the coming simulation step only (`sim.addForce`, `sim.addForceAndTorque`):
    /// they accumulate until the step and are cleared after it. With `at` (a point in
    /// the world frame, m) the force acts there and adds its moment about the centre of
    /// mass; without, it acts at the centre of mass.
    ///
    /// # Errors
    /// No such object, not a shape, not dynamically simulated, or a non-finite value.
    pub fn add_force(&mut self, h: Handle, force: Vec3, at: Option<Vec3>, torque: Vec3) -> Result<(), SimError> {
        let finite = |v: &Vec3| v.iter().all(|x| x.is_finite());
        if !(finite(&force) && finite(&torque) && at.as_ref().is_none_or(finite)) {
            return Err(invalid("force, torque and position must be finite"));
        }
        let (b, own_com) = self.dynamic_body(h)?;
        let Some(rb) = self.physics.world.bodies.get_mut(b) else {
            return Err(SimError::NoSuchObject(h));
        };
        let mut moment = torque;
        // A shape fused into a larger body is pushed at its own centre of mass, as it
        // was when it was a body of its own.
        if let Some(p) = at.or(own_com) {
            let com = math::vec_from_physics(rb.center_of_mass());
            moment += (p - com).cross(&force);
        }
        rb.add_force(math::vec_to_physics(&force), true);
        rb.add_torque(math::vec_to_physics(&moment), true);
        if !self.edit.forced.contains(&b) {
            self.edit.forced.push(b);
        }
        Ok(())
    }

    /// Clears the force and/or torque added to a dynamic shape for the coming step
    /// (`sim.handleflag_resetforce` / `resettorque`).
    ///
    /// # Errors
    /// No such object, not a shape, or not dynamically simulated.
    pub fn reset_force(&mut self, h: Handle, force: bool, torque: bool) -> Result<(), SimError> {
        let (b, _) = self.dynamic_body(h)?;
        if let Some(rb) = self.physics.world.bodies.get_mut(b) {
            if force {
                rb.reset_forces(true);
            }
            if torque {
                rb.reset_torques(true);
            }
        }
        Ok(())
    }

    /// Removes the one-step forces after the step they acted in.
    pub(super) fn clear_step_forces(&mut self) {
        for b in std::mem::take(&mut self.edit.forced) {
            if let Some(rb) = self.physics.world.bodies.get_mut(b) {
                rb.reset_forces(false);
                rb.reset_torques(false);
            }
        }
    }

    /// Changes how a joint is driven (`sim.setJointMode`, `sim.jointintparam_dynctrlmode`).
    /// A joint becoming position-controlled holds where it is; the physics of its
    /// subtree is rebuilt, since the mode decides whether its child is a simulated link.
    ///
    /// # Errors
    /// No such object, or not a joint.
    pub fn set_joint_mode(&mut self, h: Handle, mode: JointMode) -> Result<(), SimError> {
        let j = self.joint_mut(h)?;
        j.ik_mode = false;
        if j.mode == mode {
            return Ok(());
        }
        if mode == JointMode::Position && j.mode != JointMode::Velocity {
            j.target_position = j.position;
        }
        j.mode = mode;
        j.motion = super::object::KinematicMotion::Still;
        j.reference = j.position;
        j.reference_velocity = 0.0;
        self.rebuild_physics(&[h]);
        self.bump();
        Ok(())
    }

    /// Marks a kinematic joint as in CoppeliaSim 4.1's IK mode, or not (see
    /// [`Joint::ik_mode`](super::object::Joint::ik_mode)).
    ///
    /// # Errors
    /// No such object, or not a joint.
    pub fn set_joint_ik_mode(&mut self, h: Handle, on: bool) -> Result<(), SimError> {
        self.joint_mut(h)?.ik_mode = on;
        Ok(())
    }

    /// Locks a velocity-controlled joint at zero target velocity, or not (see
    /// [`Joint::velocity_lock`](super::object::Joint::velocity_lock)).
    ///
    /// # Errors
    /// No such object, or not a joint.
    pub fn set_joint_velocity_lock(&mut self, h: Handle, on: bool) -> Result<(), SimError> {
        let j = self.joint_mut(h)?;
        if j.velocity_lock == on {
            return Ok(());
        }
        j.velocity_lock = on;
        self.rebuild_physics(&[h]);
        self.bump();
        Ok(())
    }

    /// Sets or clears a joint's speed limit, rad/s or m/s (`sim.jointfloatparam_maxvel`).
    ///
    /// # Errors
    /// No such object, not a joint, or a limit that is not a positive number.
    pub fn set_joint_max_velocity(&mut self, h: Handle, limit: Option<f64>) -> Result<(), SimError> {
        if let Some(v) = limit
            && (v.is_nan() || v <= 0.0)
        {
            return Err(invalid(format!("maximum velocity must be positive, got {v}")));
        }
        let j = self.joint_mut(h)?;
        j.max_velocity = limit;
        // The limited controller goes on from where the joint is.
        j.reference = if limit.is_some() { j.position } else { j.target_position };
        j.reference_velocity = 0.0;
        self.refresh_caches();
        self.push_motor(h);
        Ok(())
    }

    /// Sets a joint's position gain (N·m/rad or N/m) and/or damping gain
    /// (`sim.jointfloatparam_pid_p`, `_pid_d`).
    ///
    /// # Errors
    /// No such object, not a joint, or a gain that is negative or not finite.
    pub fn set_joint_gains(&mut self, h: Handle, kp: Option<f64>, kd: Option<f64>) -> Result<(), SimError> {
        for g in kp.iter().chain(kd.iter()) {
            if !(g.is_finite() && *g >= 0.0) {
                return Err(invalid(format!("gains must be finite and >= 0, got {g}")));
            }
        }
        let j = self.joint_mut(h)?;
        if let Some(kp) = kp {
            j.kp = kp;
        }
        if let Some(kd) = kd {
            j.kd = kd;
        }
        self.push_motor(h);
        Ok(())
    }

    /// Gravity in the world frame, m/s².
    pub fn gravity(&self) -> Vec3 {
        self.settings.gravity.into()
    }

    /// Sets gravity, m/s² (`sim.setArrayParam(sim.arrayparam_gravity, g)`); it acts from
    /// the next step.
    ///
    /// # Errors
    /// A non-finite component.
    pub fn set_gravity(&mut self, g: Vec3) -> Result<(), SimError> {
        if !g.iter().all(|v| v.is_finite()) {
            return Err(invalid("gravity must be finite"));
        }
        self.settings.gravity = g.into();
        self.physics.world.gravity = math::vec_to_physics(&g);
        Ok(())
    }

    /// Sets the simulation time step, s (`sim.floatparam_simulation_time_step`);
    /// [`crate::sim::Sim::set_time_step`] allows it only while the simulation is stopped.
    ///
    /// # Errors
    /// `dt` is not a positive number.
    pub fn set_time_step(&mut self, dt: f64) -> Result<(), SimError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(invalid(format!("time step must be positive, got {dt}")));
        }
        self.settings.dt = dt;
        self.physics.rapier_steps =
            configure_integration(&mut self.physics.world.integration_parameters, &self.settings);
        Ok(())
    }

    /// `sim.boolparam_realtime_simulation` as last set (gantry's pacing comes from the
    /// command line; the flag is only reported back).
    pub fn realtime_flag(&self) -> bool {
        self.edit.realtime
    }

    /// Stores `sim.boolparam_realtime_simulation`.
    pub fn set_realtime_flag(&mut self, on: bool) {
        self.edit.realtime = on;
    }

    /// A pseudo-random number in [0, 1) (`sim.floatparam_rand`), the same sequence in
    /// every run so that simulations stay reproducible.
    pub fn next_random(&mut self) -> f64 {
        let mut x = self.edit.rand;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.edit.rand = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// An object's visibility layer bits (`sim.objintparam_visibility_layer`, default 1).
    ///
    /// # Errors
    /// No such object.
    pub fn layer(&self, h: Handle) -> Result<i64, SimError> {
        self.object(h)?;
        Ok(self.edit.layers.get(&h).copied().unwrap_or(1))
    }

    /// Whether an object is on one of the active layers ([`crate::scene::VISIBLE_LAYERS`]):
    /// what vision sensors draw and the viewer shows. CoppeliaSim files keep a model's
    /// respondable shapes on hidden layers, under the visual meshes seen instead.
    pub fn is_shown(&self, h: Handle) -> bool {
        self.layer(h)
            .is_ok_and(|l| l & i64::from(crate::scene::VISIBLE_LAYERS) != 0)
    }

    /// Sets an object's visibility layer bits (16 bits); vision sensors and the viewer
    /// show the objects on the active layers ([`World::is_shown`]).
    ///
    /// # Errors
    /// No such object, or bits outside 0..=0xffff.
    pub fn set_layer(&mut self, h: Handle, layer: i64) -> Result<(), SimError> {
        self.object(h)?;
        if !(0..=0xffff).contains(&layer) {
            return Err(invalid(format!("visibility layer must be 0..=65535, got {layer}")));
        }
        self.edit.layers.insert(h, layer);
        self.bump();
        Ok(())
    }

    /// Checks a vision sensor model for sensor `h` (a new sensor for `None`): the rules
    /// of [`World::set_vision_model`].
    fn check_vision_model(&self, h: Option<Handle>, model: &VisionModel) -> Result<(), SimError> {
        use crate::scene::{MAX_VISION_IMAGE_BYTES, MAX_VISION_RESOLUTION, vision_image_bytes};
        let max = MAX_VISION_RESOLUTION;
        let ok = model.resolution.iter().all(|r| (1..=max).contains(r))
            && model.fov > 0.0
            && model.fov < std::f64::consts::PI
            && model.ortho_size > 0.0
            && model.ortho_size.is_finite()
            && model.near > 0.0
            && model.near < model.far
            && model.far.is_finite();
        if !ok {
            return Err(invalid(format!(
                "vision sensor settings out of range: resolution 1..={max} per side, 0 < view angle < pi, ortho size > 0, 0 < near < far"
            )));
        }
        // Every other sensor's images plus this one's at its new resolution.
        let total = self.vision_image_bytes(h) + vision_image_bytes(model.resolution);
        if total > MAX_VISION_IMAGE_BYTES {
            let [w, hgt] = model.resolution;
            return Err(invalid(format!(
                "vision sensor{}: {w}x{hgt} would bring the vision images of the scene (RGB and depth) to {} MiB, over the {} MiB cap",
                h.map(|h| format!(" {h}")).unwrap_or_default(),
                total.div_ceil(1 << 20),
                MAX_VISION_IMAGE_BYTES >> 20
            )));
        }
        Ok(())
    }

    /// Adds a vision sensor of `model` below `parent` (a root for `None`) at pose `local`
    /// in the parent's frame (`sim.createVisionSensor`); it renders like one loaded with
    /// the scene.
    ///
    /// # Errors
    /// The parent does not exist, or the model breaks the rules of
    /// [`World::set_vision_model`].
    pub fn add_vision_sensor(
        &mut self,
        alias: &str,
        model: VisionModel,
        parent: Option<Handle>,
        local: Pose,
    ) -> Result<Handle, SimError> {
        self.check_vision_model(None, &model)?;
        self.add_object(alias, ObjectKind::VisionSensor(model), parent, local)
    }

    /// Replaces a vision sensor's resolution, projection, view angle, ortho size and
    /// clipping planes.
    ///
    /// # Errors
    /// No such object, not a vision sensor, or a setting out of range (resolution
    /// 1..=[`crate::scene::MAX_VISION_RESOLUTION`] per side, 0 < view angle < π, ortho
    /// size > 0, 0 < near < far), or a resolution that would bring the images of all
    /// vision sensors over [`crate::scene::MAX_VISION_IMAGE_BYTES`].
    pub fn set_vision_model(&mut self, h: Handle, model: VisionModel) -> Result<(), SimError> {
        self.check_vision_model(Some(h), &model)?;
        match &mut self.object_mut(h)?.kind {
            ObjectKind::VisionSensor(v) => *v = model,
            other => {
                return Err(SimError::WrongKind {
                    handle: h,
                    expected: "vision sensor",
                    actual: other.name(),
                });
            }
        }
        self.bump();
        Ok(())
    }

    /// Replaces a light's parameters.
    ///
    /// # Errors
    /// No such object, not a light, or a value out of CoppeliaSim's ranges: colours 0..1,
    /// spot exponent 0..=128, spot cutoff 5 degrees to pi/2, attenuation factors
    /// finite and >= 0.
    pub fn set_light(&mut self, h: Handle, model: LightModel) -> Result<(), SimError> {
        let unit = |c: [f64; 3]| c.iter().all(|v| (0.0..=1.0).contains(v));
        let ok = unit(model.diffuse)
            && unit(model.specular)
            && (0..=LightModel::MAX_SPOT_EXPONENT).contains(&model.spot_exponent)
            && (LightModel::MIN_SPOT_CUTOFF..=LightModel::MAX_SPOT_CUTOFF).contains(&model.spot_cutoff)
            && model.attenuation.iter().all(|v| v.is_finite() && *v >= 0.0);
        if !ok {
            return Err(invalid(format!(
                "light {h}: settings out of range: colours 0..1, spot exponent 0..=128, spot cutoff 5 degrees to pi/2 rad, attenuation factors >= 0"
            )));
        }
        match &mut self.object_mut(h)?.kind {
            ObjectKind::Light(l) => *l = model,
            other => {
                return Err(SimError::WrongKind {
                    handle: h,
                    expected: "light",
                    actual: other.name(),
                });
            }
        }
        self.bump();
        Ok(())
    }

    /// The bounding box of an object in its own frame, `(min, max)` in m: the union of a
    /// shape's collision and visual geometry; a point at the origin for other objects.
    ///
    /// # Errors
    /// No such object.
    pub fn bounding_box(&self, h: Handle) -> Result<([f64; 3], [f64; 3]), SimError> {
        let ObjectKind::Shape(s) = &self.object(h)?.kind else {
            return Ok(([0.0; 3], [0.0; 3]));
        };
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let parts = s.geoms.iter().map(|g| (&g.geometry, &g.local));
        for (g, local) in parts.chain(s.visuals.iter().map(|v| (&v.geometry, &v.local))) {
            let (a, b) = geometry_box(g, local);
            for i in 0..3 {
                lo[i] = lo[i].min(a[i]);
                hi[i] = hi[i].max(b[i]);
            }
        }
        if lo[0] > hi[0] {
            return Ok(([0.0; 3], [0.0; 3]));
        }
        Ok((lo, hi))
    }
}

/// The axis-aligned box, in the shape frame, of a geometry placed at `local`.
fn geometry_box(g: &Geometry, local: &Pose) -> ([f64; 3], [f64; 3]) {
    let centre = local.translation.vector;
    let r = local.rotation.to_rotation_matrix();
    let m = r.matrix();
    // Half extents of a rotated box: |R| times the local half extents.
    let rotated_box = |h: [f64; 3]| -> Vec3 { Vec3::from_fn(|i, _| (0..3).map(|j| m[(i, j)].abs() * h[j]).sum()) };
    let half = match g {
        Geometry::Box { half_extents } => rotated_box(*half_extents),
        Geometry::Sphere { radius } => Vec3::repeat(*radius),
        // A cylinder along local Z: the axis contributes |d_i| L/2, the disc r sqrt(1-d_i²).
        Geometry::Cylinder { radius, length } => {
            let d = m.column(2);
            Vec3::from_fn(|i, _| d[i].abs() * length / 2.0 + radius * (1.0 - d[i] * d[i]).max(0.0).sqrt())
        }
        Geometry::Capsule { radius, length } => {
            let d = m.column(2);
            Vec3::from_fn(|i, _| d[i].abs() * length / 2.0 + radius)
        }
        Geometry::Mesh(mesh) => {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for v in &mesh.vertices {
                let p = local.transform_point(&nalgebra::Point3::new(
                    f64::from(v[0]),
                    f64::from(v[1]),
                    f64::from(v[2]),
                ));
                for i in 0..3 {
                    lo[i] = lo[i].min(p[i]);
                    hi[i] = hi[i].max(p[i]);
                }
            }
            return (lo, hi);
        }
    };
    (
        [centre.x - half.x, centre.y - half.y, centre.z - half.z],
        [centre.x + half.x, centre.y + half.y, centre.z + half.z],
    )
}
