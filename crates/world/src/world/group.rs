//! Grouping shapes into one compound shape and splitting a compound again
//! (`sim.groupShapes`, `sim.ungroupShape`).
//!
//! A compound is an ordinary shape with several parts: its collision and visual parts
//! are those of the grouped shapes, expressed in the compound's frame, which is the frame
//! of the last shape listed. The grouped shapes are removed, as CoppeliaSim removes them.

use super::edit::{MIN_SHAPE_MASS, invalid};
use super::object::{Handle, ObjectKind};
use super::physics::geometry_volume;
use super::world::World;
use crate::error::SimError;
use crate::math::Pose;
use crate::scene::{GeomModel, MassModel, ShapeModel, VisualModel};

impl World {
    /// Groups `handles` (at least two distinct shapes) into a new compound shape and
    /// returns its handle. The compound takes the last shape's frame, alias, parent and
    /// dynamic settings; its mass is the sum of the parts' masses. Objects hanging from a
    /// grouped shape hang from the compound afterwards, where they were in the world.
    ///
    /// # Errors
    /// Fewer than two shapes, a shape listed twice, or a handle that names no shape; then
    /// nothing changes.
    pub fn group_shapes(&mut self, handles: &[Handle]) -> Result<Handle, SimError> {
        let Some(&last) = handles.last().filter(|_| handles.len() >= 2) else {
            return Err(invalid(format!(
                "at least 2 shapes are needed to make a compound, got {}",
                handles.len()
            )));
        };
        for (i, &h) in handles.iter().enumerate() {
            self.shape(h)?;
            if handles[..i].contains(&h) {
                return Err(invalid(format!("shape {h} is listed twice")));
            }
        }
        let frame = self.objects[last as usize].world;
        let into_group = frame.inverse();
        let mut mass = 0.0;
        let mut geoms = Vec::new();
        let mut visuals = Vec::new();
        for &h in handles {
            let at = into_group * self.objects[h as usize].world;
            mass += self.shape_mass(h)?;
            let s = self.shape(h)?;
            geoms.extend(s.geoms.iter().map(|g| GeomModel {
                geometry: g.geometry.clone(),
                local: at * g.local,
            }));
            visuals.extend(s.visuals.iter().map(|v| VisualModel {
                local: at * v.local,
                ..v.clone()
            }));
        }
        let compound = ShapeModel {
            geoms,
            visuals,
            mass: MassModel::Mass(mass.max(MIN_SHAPE_MASS)),
            ..self.shape(last)?.clone()
        };
        // The nearest ancestor of the last shape that stays.
        let mut parent = self.objects[last as usize].parent;
        while let Some(p) = parent.filter(|p| handles.contains(p)) {
            parent = self.objects[p as usize].parent;
        }
        let alias = self.objects[last as usize].alias.clone();
        let group = self.add_object(&alias, ObjectKind::Shape(Box::new(compound)), None, frame)?;
        if parent.is_some() {
            self.set_parent(group, parent, true)?;
        }
        let orphans: Vec<Handle> = handles
            .iter()
            .flat_map(|&h| self.objects[h as usize].children.clone())
            .filter(|c| !handles.contains(c) && !self.is_ancestor(*c, group))
            .collect();
        for c in orphans {
            self.set_parent(c, Some(group), true)?;
        }
        self.remove_objects(handles)?;
        Ok(group)
    }

    /// Splits a compound shape into one shape per collision part (`sim.ungroupShape`)
    /// and returns their handles in part order; a shape of one part is returned as it
    /// is. Each part keeps the compound's alias, parent and settings, sits where it was
    /// in the world, and gets its share of the mass by volume. When the compound has as
    /// many visual parts as collision parts they are paired in order; otherwise each part
    /// is drawn as its collision geometry in the first visual's colour. Objects hanging
    /// from the compound hang from the first part.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn ungroup_shape(&mut self, h: Handle) -> Result<Vec<Handle>, SimError> {
        let s = self.shape(h)?.clone();
        if s.geoms.len() < 2 {
            return Ok(vec![h]);
        }
        let mass = self.shape_mass(h)?;
        let volumes: Vec<f64> = s.geoms.iter().map(|g| geometry_volume(&g.geometry)).collect();
        let total: f64 = volumes.iter().sum();
        let paired = s.visuals.len() == s.geoms.len();
        let color = s.visuals.first().map_or([0.8, 0.8, 0.8], |v| v.color);
        let frame = self.objects[h as usize].world;
        let parent = self.objects[h as usize].parent;
        let alias = self.objects[h as usize].alias.clone();
        let mut parts = Vec::with_capacity(s.geoms.len());
        for (i, g) in s.geoms.iter().enumerate() {
            let visual = if paired {
                VisualModel {
                    local: g.local.inverse() * s.visuals[i].local,
                    ..s.visuals[i].clone()
                }
            } else {
                VisualModel {
                    geometry: g.geometry.clone(),
                    local: Pose::identity(),
                    color,
                    texture: None,
                }
            };
            let share = if total > 0.0 {
                volumes[i] / total
            } else {
                1.0 / s.geoms.len() as f64
            };
            let part = ShapeModel {
                geoms: vec![GeomModel {
                    geometry: g.geometry.clone(),
                    local: Pose::identity(),
                }],
                visuals: vec![visual],
                mass: MassModel::Mass((mass * share).max(MIN_SHAPE_MASS)),
                ..s.clone()
            };
            let p = self.add_object(&alias, ObjectKind::Shape(Box::new(part)), None, frame * g.local)?;
            if parent.is_some() {
                self.set_parent(p, parent, true)?;
            }
            parts.push(p);
        }
        for c in self.objects[h as usize].children.clone() {
            self.set_parent(c, Some(parts[0]), true)?;
        }
        self.remove_objects(&[h])?;
        Ok(parts)
    }

    /// Whether `a` is `b` or one of its ancestors.
    fn is_ancestor(&self, a: Handle, b: Handle) -> bool {
        let mut cur = Some(b);
        while let Some(c) = cur {
            if c == a {
                return true;
            }
            cur = self.objects[c as usize].parent;
        }
        false
    }
}
