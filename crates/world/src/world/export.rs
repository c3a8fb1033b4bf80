//! The world as it is now, back as a scene model: what `sim.saveScene` and
//! `sim.saveModel` hand to the scene writer (`gantry convert`'s), so that a saved scene
//! loads again with the objects, poses, joint positions and settings of the moment.
//!
//! Kept: every live object (or one model's subtree) in hierarchy order with its alias,
//! local pose, model-base flag, extension string and kind with its current settings (a
//! joint's position becomes its initial position), the simulation settings, the scripts
//! the scene and its imported models came with, and the collections and referenced
//! handles that name only exported objects. Left out, and listed in the notes: point
//! clouds' points (a cloud becomes a dummy), dynamic loop closures, the scene's IK
//! groups and its URDF robot descriptions, model property overrides, and what scripts
//! did to themselves at run time (scripts added or removed).

use std::collections::HashMap;

use super::object::{Handle, ObjectKind};
use super::world::World;
use crate::Value;
use crate::error::SimError;
use crate::scene::{
    CollectionModel, JointModel, MimicModel, ObjectModel, ObjectModelKind, ReferencedHandles, SceneModel, ScriptModel,
    ServerSettings, UserParameter,
};

/// A scene model of the world and what it could not hold.
pub struct ExportedScene {
    /// The model, objects in hierarchy order.
    pub model: SceneModel,
    /// What the model leaves out, one line each.
    pub notes: Vec<String>,
}

impl World {
    /// The whole scene (`root` `None`) or the model rooted at `root` as a scene model;
    /// the root of a model keeps its pose in the world.
    ///
    /// # Errors
    /// `root` names no object.
    pub fn export_scene(&self, root: Option<Handle>) -> Result<ExportedScene, SimError> {
        let tops = match root {
            Some(h) => {
                self.object(h)?;
                vec![h]
            }
            None => self.roots().to_vec(),
        };
        let list = self.subtrees(&tops);
        let index: HashMap<Handle, usize> = list.iter().enumerate().map(|(i, &h)| (h, i)).collect();
        let mut notes = Vec::new();
        let mut objects = Vec::with_capacity(list.len());
        for &h in &list {
            let o = &self.objects[h as usize];
            let parent = o.parent.and_then(|p| index.get(&p).copied());
            let kind = match &o.kind {
                ObjectKind::Shape(s) => ObjectModelKind::Shape((**s).clone()),
                ObjectKind::Joint(j) => ObjectModelKind::Joint(JointModel {
                    joint_type: j.joint_type,
                    mode: j.mode,
                    limits: j.limits,
                    cyclic: j.cyclic,
                    initial: j.position,
                    target_position: j.target_position,
                    target_velocity: j.target_velocity,
                    max_force: j.max_force,
                    kp: j.kp,
                    kd: j.kd,
                    damping: j.damping,
                    friction: j.friction,
                    max_velocity: j.max_velocity,
                    mimic: j.mimic.and_then(|m| match index.get(&m.leader) {
                        Some(&leader) => Some(MimicModel {
                            leader,
                            multiplier: m.multiplier,
                            offset: m.offset,
                        }),
                        None => {
                            notes.push(format!(
                                "{}: follows joint {}, which is not saved with it; saved without the coupling",
                                o.alias, m.leader
                            ));
                            None
                        }
                    }),
                }),
                ObjectKind::Dummy => ObjectModelKind::Dummy,
                ObjectKind::ProximitySensor(p) => ObjectModelKind::ProximitySensor(p.volume),
                ObjectKind::VisionSensor(v) => ObjectModelKind::VisionSensor(*v),
                ObjectKind::ForceSensor(_) => ObjectModelKind::ForceSensor,
                ObjectKind::Graph => ObjectModelKind::Graph,
                ObjectKind::Camera(c) => ObjectModelKind::Camera(*c),
                ObjectKind::Light(l) => ObjectModelKind::Light(*l),
                ObjectKind::Path => {
                    // The curve of a 4.1 path object lives with the simulation's paths
                    // (`Sim::paths`), which the world does not hold.
                    notes.push(format!(
                        "{}: a CoppeliaSim 4.1 path object, saved as a dummy without its control points",
                        o.alias
                    ));
                    ObjectModelKind::Dummy
                }
                ObjectKind::PointCloud(_) => {
                    notes.push(format!(
                        "{}: a point cloud, saved as a dummy (scene files hold no points)",
                        o.alias
                    ));
                    ObjectModelKind::Dummy
                }
                ObjectKind::Octree(_) => {
                    notes.push(format!(
                        "{}: an octree, saved as a dummy (scene files hold no voxels)",
                        o.alias
                    ));
                    ObjectModelKind::Dummy
                }
            };
            objects.push(ObjectModel {
                alias: o.alias.clone(),
                parent,
                // A model's root keeps its place in the world: its parent is not saved.
                local: if parent.is_none() { o.world } else { o.local },
                model_base: o.model_base,
                extension: o.extension.clone(),
                layer: self.layer(h).ok().and_then(|l| u16::try_from(l).ok()).unwrap_or(1),
                kind,
            });
        }
        let scripts = self
            .scripts
            .iter()
            .filter_map(|s| {
                let object = *index.get(&(s.object as Handle))?;
                Some(ScriptModel { object, ..s.clone() })
            })
            .collect();
        let collections = self
            .collections
            .iter()
            .flatten()
            .filter_map(|c| {
                let model = c.to_model(|h| index.get(&h).copied());
                if model.is_none() && root.is_none() {
                    notes.push(if c.name.is_empty() {
                        "an unnamed collection (scene files hold named ones) is left out".to_owned()
                    } else {
                        format!("collection '{}' names objects that are not saved; left out", c.name)
                    });
                }
                model
            })
            .collect::<Vec<CollectionModel>>();
        let referenced_handles = list
            .iter()
            .flat_map(|&h| {
                self.custom
                    .referenced_tags(h)
                    .into_iter()
                    .map(move |tag| (h, tag.to_owned(), self.custom.referenced(h, tag)))
            })
            .filter_map(|(h, tag, targets)| {
                let targets = targets
                    .iter()
                    .map(|t| index.get(t).copied())
                    .collect::<Option<Vec<usize>>>()?;
                Some(ReferencedHandles {
                    object: index[&h],
                    tag,
                    targets,
                })
            })
            .collect();
        // User parameters as text, as scene files keep them (their units are not kept
        // with the world); a value a script set to a table or a buffer is left out.
        let mut user_parameters = Vec::new();
        for &h in &list {
            for (name, value) in self.custom.values_of(h) {
                let value = match value {
                    Value::Str(s) => s.clone(),
                    Value::Int(i) => i.to_string(),
                    Value::Float(f) => f.to_string(),
                    Value::Bool(b) => b.to_string(),
                    _ => {
                        notes.push(format!("user parameter '{name}' holds no text or number; left out"));
                        continue;
                    }
                };
                user_parameters.push(UserParameter {
                    object: index[&h],
                    name: name.to_owned(),
                    unit: String::new(),
                    value,
                });
            }
        }
        let linked = list.iter().any(|&h| self.linked_dummy(h).is_some());
        if linked {
            notes.push("dynamic loop closures (linked dummies) are not saved".to_owned());
        }
        // Visual textures name the loaded scene's texture table, which is not kept with
        // the world: they are left out rather than left dangling.
        let mut textured = false;
        for o in &mut objects {
            if let ObjectModelKind::Shape(shape) = &mut o.kind {
                for v in &mut shape.visuals {
                    textured |= v.texture.take().is_some();
                }
            }
        }
        if textured {
            notes.push("textures are not saved".to_owned());
        }
        let source = self.source();
        Ok(ExportedScene {
            model: SceneModel {
                name: source.name.clone(),
                base_dir: source.dir.clone(),
                path: source.path.clone(),
                settings: self.settings,
                server: ServerSettings::default(),
                objects,
                scripts,
                dummy_links: Vec::new(),
                ball_links: Vec::new(),
                referenced_handles,
                user_parameters,
                ik_groups: Vec::new(),
                collections,
                urdf_robots: Vec::new(),
                warnings: Vec::new(),
                textures: Vec::new(),
            },
            notes,
        })
    }
}
