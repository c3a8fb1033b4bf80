//! Geometric queries between entities: minimum distance and collision between objects
//! and collections (`sim.checkDistance`, `sim.checkCollision`).
//!
//! Octrees take part voxel by voxel, each voxel a cube: in collisions against shapes and
//! other octrees, and in distances against shapes and dummies, when named explicitly
//! (`sim.handle_all` and collections resolve to shapes only).

use rapier3d::parry::query;
use rapier3d::prelude::*;

use super::collection::{Collection, FIRST_COLLECTION_HANDLE, ItemKind};
use super::object::{Handle, ObjectKind};
use super::object_path::ObjectTree;
use super::property_flags::object_special_property;
use super::world::World;
use crate::error::SimError;
use crate::math::{self, Vec3};

/// The result of a distance query, points in the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceResult {
    /// Closest point on the first entity, m.
    pub p1: Vec3,
    /// Closest point on the second entity, m.
    pub p2: Vec3,
    /// Distance, m (0 when intersecting).
    pub distance: f64,
    /// The two objects.
    pub objects: [Handle; 2],
}

/// Whether a shape takes part in distance queries against everything or a collection:
/// its special property if one was set, else its scene flag.
fn measurable(w: &World, h: Handle) -> bool {
    has_special(w, h, object_special_property::MEASURABLE)
}

/// Whether a shape takes part in collision checks against everything or a collection.
fn collidable(w: &World, h: Handle) -> bool {
    has_special(w, h, object_special_property::COLLIDABLE)
}

fn has_special(w: &World, h: Handle, bit: i64) -> bool {
    matches!(w.object(h).map(|o| &o.kind), Ok(ObjectKind::Shape(_)))
        && w.special_property(h).is_ok_and(|p| p & bit != 0)
}

impl World {
    /// Resolves an entity (object handle, collection handle, or `sim.handle_all` = -2)
    /// to shapes. `exclude` is removed (the other side of a query). Explicit objects are
    /// measured whatever their `measurable` flag, as in CoppeliaSim.
    ///
    /// # Errors
    /// An unknown object or collection.
    pub fn entity_shapes(&self, entity: Handle, exclude: &[Handle]) -> Result<Vec<Handle>, SimError> {
        self.entity_objects(entity, exclude, measurable)
    }

    /// As [`World::entity_shapes`] for collision checks: `sim.handle_all` and
    /// collections resolve to their collidable shapes.
    ///
    /// # Errors
    /// An unknown object or collection.
    pub fn entity_collidables(&self, entity: Handle, exclude: &[Handle]) -> Result<Vec<Handle>, SimError> {
        self.entity_objects(entity, exclude, collidable)
    }

    fn entity_objects(
        &self,
        entity: Handle,
        exclude: &[Handle],
        keep: fn(&World, Handle) -> bool,
    ) -> Result<Vec<Handle>, SimError> {
        let mut out: Vec<Handle> = if entity == -2 {
            self.handles().iter().copied().filter(|&h| keep(self, h)).collect()
        } else if entity >= FIRST_COLLECTION_HANDLE {
            self.collection_objects(entity)?
                .into_iter()
                .filter(|&h| keep(self, h))
                .collect()
        } else {
            self.object(entity)?;
            vec![entity]
        };
        out.retain(|h| !exclude.contains(h));
        Ok(out)
    }

    /// The handle of the live collection named `name` (never an unnamed one).
    pub fn collection_named(&self, name: &str) -> Option<Handle> {
        if name.is_empty() {
            return None;
        }
        let at = self
            .collections
            .iter()
            .position(|c| c.as_ref().is_some_and(|c| c.name == name))?;
        Some(FIRST_COLLECTION_HANDLE + at as Handle)
    }

    /// The live collection behind a handle, if any.
    pub fn collection(&self, h: Handle) -> Option<&Collection> {
        let at = usize::try_from(h.checked_sub(FIRST_COLLECTION_HANDLE)?).ok()?;
        self.collections.get(at)?.as_ref()
    }

    /// The objects of a collection, applying its items in order.
    ///
    /// # Errors
    /// The handle names no collection.
    pub fn collection_objects(&self, c: Handle) -> Result<Vec<Handle>, SimError> {
        let coll = usize::try_from(c - FIRST_COLLECTION_HANDLE)
            .ok()
            .and_then(|i| self.collections.get(i))
            .and_then(|c| c.as_ref())
            .ok_or_else(|| SimError::NoSuchItem(format!("collection {c} does not exist")))?;
        let mut set: Vec<Handle> = Vec::new();
        for item in &coll.items {
            let mut objs: Vec<Handle> = match item.kind {
                ItemKind::Single => vec![item.object],
                ItemKind::All => self.handles().to_vec(),
                ItemKind::Tree => {
                    let mut v = Vec::new();
                    let mut stack = vec![item.object];
                    while let Some(h) = stack.pop() {
                        v.push(h);
                        stack.extend(self.children(h).iter().rev().copied());
                    }
                    v
                }
                ItemKind::Chain => {
                    let mut v = vec![item.object];
                    let mut cur = self.parent(item.object)?;
                    while let Some(p) = cur {
                        v.push(p);
                        cur = self.parent(p)?;
                    }
                    v
                }
            };
            if item.exclude_base && matches!(item.kind, ItemKind::Tree | ItemKind::Chain) {
                objs.retain(|&h| h != item.object);
            }
            if item.remove {
                set.retain(|h| !objs.contains(h));
            } else {
                for h in objs {
                    if !set.contains(&h) {
                        set.push(h);
                    }
                }
            }
        }
        Ok(set)
    }

    /// Minimum distance between two sets of objects (shapes, and dummies as points), or
    /// `None` if either has no geometry
    /// or, with `threshold > 0`, nothing is closer than the threshold.
    ///
    /// Exact queries are expensive (GJK on every pair), and a rover measuring its distance
    /// to `sim.handle_all` would pair its colliders with every collider in the scene, so
    /// the cost of a hundred rovers would grow with the square of their number. Instead
    /// the search looks in a growing box around the first set, asking rapier's broad-phase
    /// tree for the colliders inside it, and stops as soon as the best distance found is
    /// within the box's margin (nothing outside can be closer). Inside the box, candidate
    /// pairs are visited nearest bounding box first, and the exact query runs only while a
    /// pair's bounding-box gap (a lower bound) can still beat the best distance.
    pub fn distance(&self, a: &[Handle], b: &[Handle], threshold: f64) -> Option<DistanceResult> {
        let shapes = self.shape_distance(a, b, threshold);
        // A dummy is a point to distance queries, as in CoppeliaSim.
        let limit = shapes.map_or(if threshold > 0.0 { threshold } else { f64::INFINITY }, |r| r.distance);
        let best = match self.point_distance(a, b, limit) {
            Some(p) => Some(p),
            None => shapes,
        };
        let limit = best.map_or(limit, |r| r.distance);
        match self.octree_distance(a, b, limit) {
            Some(o) => Some(o),
            None => best,
        }
    }

    /// Whether `h` is an octree.
    fn is_octree(&self, h: Handle) -> bool {
        matches!(self.object(h).map(|o| &o.kind), Ok(ObjectKind::Octree(_)))
    }

    /// The world poses of the voxels of octree `h` that may overlap the world box
    /// `region`, and the voxels' half size.
    fn voxel_cubes(&self, h: Handle, region: &Aabb) -> (Vec<rapier3d::math::Pose>, f32) {
        let (Ok(o), Ok(octree)) = (self.object(h), self.octree(h)) else {
            return (Vec::new(), 0.0);
        };
        let (mn, mx) = (math::vec_from_physics(region.mins), math::vec_from_physics(region.maxs));
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for k in 0..8 {
            let corner = Vec3::new(
                if k & 1 == 0 { mn.x } else { mx.x },
                if k & 2 == 0 { mn.y } else { mx.y },
                if k & 4 == 0 { mn.z } else { mx.z },
            );
            let p = o.world.inverse_transform_point(&corner.into()).coords;
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
        let (ilo, ihi) = octree.index_box(&lo, &hi);
        let poses = octree
            .voxels_in(ilo, ihi)
            .map(|k| {
                let c = octree.voxel_center(&k);
                math::to_physics(&(o.world * nalgebra::Translation3::from(c)))
            })
            .collect();
        (poses, (octree.voxel_size() / 2.0) as f32)
    }

    /// Whether an octree and another object (a shape or an octree) collide.
    fn octree_collides(&self, octree: Handle, other: Handle) -> bool {
        let colliders = &self.physics().world.colliders;
        let everywhere = Aabb::new(Vector::splat(f32::MIN), Vector::splat(f32::MAX));
        if self.is_octree(other) {
            // Each voxel of the smaller octree against the voxels of the other around it.
            let count = |h: Handle| self.octree(h).map_or(0, |o| o.len());
            let (small, large) = if count(octree) <= count(other) {
                (octree, other)
            } else {
                (other, octree)
            };
            let (cubes, half) = self.voxel_cubes(small, &everywhere);
            let cube = Cuboid::new(Vector::splat(half));
            return cubes.iter().any(|pose| {
                let (near, half2) = self.voxel_cubes(large, &cube.compute_aabb(pose));
                let cube2 = Cuboid::new(Vector::splat(half2));
                near.iter()
                    .any(|p2| query::intersection_test(pose, &cube, p2, &cube2).is_ok_and(|i| i.intersecting))
            });
        }
        self.colliders_of(other)
            .iter()
            .filter_map(|&c| colliders.get(c))
            .any(|c| {
                let (cubes, half) = self.voxel_cubes(octree, &c.compute_aabb());
                let cube = Cuboid::new(Vector::splat(half));
                cubes.iter().any(|pose| {
                    query::intersection_test(pose, &cube, c.position(), c.shape()).is_ok_and(|i| i.intersecting)
                })
            })
    }

    /// The closest pair in which one side is an octree and the other a shape or a dummy,
    /// if any is closer than `limit`. Voxels are visited nearest bounding box first, and
    /// the exact query runs only while a voxel's gap (a lower bound) can still win.
    fn octree_distance(&self, a: &[Handle], b: &[Handle], limit: f64) -> Option<DistanceResult> {
        if !a.iter().chain(b).any(|&h| self.is_octree(h)) {
            return None;
        }
        let colliders = &self.physics().world.colliders;
        let everywhere = Aabb::new(Vector::splat(f32::MIN), Vector::splat(f32::MAX));
        let mut best: Option<DistanceResult> = None;
        for &ha in a {
            for &hb in b {
                let (octree, other, swapped) = match (self.is_octree(ha), self.is_octree(hb)) {
                    (true, false) => (ha, hb, false),
                    (false, true) => (hb, ha, true),
                    _ => continue,
                };
                let (cubes, half) = self.voxel_cubes(octree, &everywhere);
                let cube = Cuboid::new(Vector::splat(half));
                let lim = |best: &Option<DistanceResult>| best.map_or(limit, |r| r.distance.min(limit));
                // (point on the octree, point on the other object)
                let mut found: Option<(Vec3, Vec3, f64)> = None;
                if let Ok(o) = self.object(other)
                    && matches!(o.kind, ObjectKind::Dummy)
                {
                    let p = o.world.translation.vector;
                    for pose in &cubes {
                        let proj = cube.project_point(pose, math::vec_to_physics(&p), true);
                        let q = if proj.is_inside {
                            p
                        } else {
                            math::vec_from_physics(proj.point)
                        };
                        let d = (q - p).norm();
                        if d < found.map_or(lim(&best), |f| f.2) {
                            found = Some((q, p, d));
                        }
                    }
                } else {
                    let mut candidates: Vec<(f64, &rapier3d::math::Pose, &Collider)> = Vec::new();
                    for c in self.colliders_of(other).iter().filter_map(|&c| colliders.get(c)) {
                        let cb = c.compute_aabb();
                        candidates.extend(cubes.iter().map(|p| (aabb_gap(&cube.compute_aabb(p), &cb), p, c)));
                    }
                    candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
                    for (gap, pose, c) in candidates {
                        let l = found.map_or(lim(&best), |f| f.2);
                        if gap >= l {
                            break;
                        }
                        let max = if l.is_finite() { l as f32 } else { f32::MAX };
                        let Ok(cp) = query::closest_points(pose, &cube, c.position(), c.shape(), max) else {
                            continue;
                        };
                        let (p1, p2) = match cp {
                            query::ClosestPoints::Intersecting => {
                                let p = math::vec_from_physics(pose.translation);
                                (p, p)
                            }
                            query::ClosestPoints::WithinMargin(p1, p2) => {
                                (math::vec_from_physics(p1), math::vec_from_physics(p2))
                            }
                            query::ClosestPoints::Disjoint => continue,
                        };
                        let d = (p2 - p1).norm();
                        if d < l {
                            found = Some((p1, p2, d));
                        }
                    }
                }
                if let Some((po, pother, d)) = found {
                    let (p1, p2) = if swapped { (pother, po) } else { (po, pother) };
                    best = Some(DistanceResult {
                        p1,
                        p2,
                        distance: d,
                        objects: [ha, hb],
                    });
                }
            }
        }
        best
    }

    /// The closest pair in which one side or both are dummies (points), if any is
    /// closer than `limit`.
    fn point_distance(&self, a: &[Handle], b: &[Handle], limit: f64) -> Option<DistanceResult> {
        let point = |h: Handle| match self.object(h) {
            Ok(o) if matches!(o.kind, ObjectKind::Dummy) => Some(o.world.translation.vector),
            _ => None,
        };
        let colliders = &self.physics().world.colliders;
        // The closest point of `shape` to `p`, and the distance.
        let nearest_on = |shape: Handle, p: &Vec3| -> Option<(Vec3, f64)> {
            self.colliders_of(shape)
                .iter()
                .filter_map(|&c| colliders.get(c))
                .map(|c| {
                    let proj = c.shape().project_point(c.position(), math::vec_to_physics(p), true);
                    let q = if proj.is_inside {
                        *p
                    } else {
                        math::vec_from_physics(proj.point)
                    };
                    (q, (q - p).norm())
                })
                .min_by(|x, y| x.1.total_cmp(&y.1))
        };
        let mut best: Option<DistanceResult> = None;
        for &ha in a {
            for &hb in b {
                if ha == hb {
                    continue;
                }
                let pair = match (point(ha), point(hb)) {
                    (None, None) => continue,
                    (Some(pa), Some(pb)) => Some((pa, pb)),
                    (Some(pa), None) => nearest_on(hb, &pa).map(|(q, _)| (pa, q)),
                    (None, Some(pb)) => nearest_on(ha, &pb).map(|(q, _)| (q, pb)),
                };
                let Some((p1, p2)) = pair else { continue };
                let d = (p2 - p1).norm();
                if d < best.map_or(limit, |r| r.distance) {
                    best = Some(DistanceResult {
                        p1,
                        p2,
                        distance: d,
                        objects: [ha, hb],
                    });
                }
            }
        }
        best
    }

    /// The closest pair of shapes, searched as [`World::distance`] explains.
    fn shape_distance(&self, a: &[Handle], b: &[Handle], threshold: f64) -> Option<DistanceResult> {
        let physics = self.physics();
        let colliders = &physics.world.colliders;
        let sa: Vec<(Handle, &Collider, Aabb)> = a
            .iter()
            .flat_map(|&h| self.colliders_of(h).iter().map(move |&c| (h, c)))
            .filter_map(|(h, c)| colliders.get(c).map(|col| (h, col, col.compute_aabb())))
            .collect();
        let (Some(first), true) = (sa.first(), !b.is_empty()) else {
            return None;
        };
        let union = sa.iter().fold(first.2, |acc, (_, _, bb)| acc.merged(bb));
        // Membership of the second set by object handle (handles index the object table,
        // which keeps removed objects' slots: `len`, not the number of live objects).
        let mut in_b = vec![false; self.len()];
        for &h in b {
            if let Some(slot) = usize::try_from(h).ok().and_then(|i| in_b.get_mut(i)) {
                *slot = true;
            }
        }
        let qp = physics.world.query_pipeline();
        let limit0 = if threshold > 0.0 { threshold } else { f64::INFINITY };
        let mut margin = if threshold > 0.0 { threshold } else { 0.25 };
        loop {
            let region = union.loosened(margin as f32);
            let mut seen = 0;
            let mut sb: Vec<(Handle, ColliderHandle, &Collider, Aabb)> = Vec::new();
            for (ch, c) in qp.intersect_aabb_conservative(region) {
                seen += 1;
                if let Some(owner) = self.collider_owner(ch)
                    && usize::try_from(owner).ok().and_then(|i| in_b.get(i)).copied() == Some(true)
                {
                    sb.push((owner, ch, c, c.compute_aabb()));
                }
            }
            let covers_scene = seen == colliders.len();
            // Broad-phase order is not the scene's; sort so that ties between equally
            // distant pairs resolve the same way whatever the tree's shape.
            sb.sort_by_key(|(h, ch, _, _)| (*h, ch.into_raw_parts()));
            let sb: Vec<(Handle, &Collider, Aabb)> = sb.into_iter().map(|(h, _, c, bb)| (h, c, bb)).collect();
            let best = nearest_pair(&sa, &sb, limit0);
            match best {
                Some(r) if r.distance <= margin => return Some(r),
                _ if covers_scene || margin >= limit0 => return best,
                _ => margin *= 4.0,
            }
        }
    }

    /// The first colliding pair between two sets of shapes.
    pub fn collision(&self, a: &[Handle], b: &[Handle]) -> Option<[Handle; 2]> {
        let colliders = &self.physics().world.colliders;
        for &ha in a {
            for &ca in self.colliders_of(ha) {
                let Some(c1) = colliders.get(ca) else {
                    continue;
                };
                for &hb in b {
                    if ha == hb {
                        continue;
                    }
                    for &cb in self.colliders_of(hb) {
                        let Some(c2) = colliders.get(cb) else {
                            continue;
                        };
                        if query::intersection_test(c1.position(), c1.shape(), c2.position(), c2.shape())
                            .is_ok_and(|i| i.intersecting)
                        {
                            return Some([ha, hb]);
                        }
                    }
                }
            }
        }
        // Pairs with an octree, after the shapes so that shape pairs are reported as
        // before octrees existed.
        if !a.iter().chain(b).any(|&h| self.is_octree(h)) {
            return None;
        }
        for &ha in a {
            for &hb in b {
                let hit = ha != hb
                    && match (self.is_octree(ha), self.is_octree(hb)) {
                        (true, _) => self.octree_collides(ha, hb),
                        (false, true) => self.octree_collides(hb, ha),
                        _ => false,
                    };
                if hit {
                    return Some([ha, hb]);
                }
            }
        }
        None
    }
}

/// The closest pair between two lists of colliders, nearest bounding boxes first, or
/// `None` if none is closer than `limit`.
fn nearest_pair(
    sa: &[(Handle, &Collider, Aabb)],
    sb: &[(Handle, &Collider, Aabb)],
    limit: f64,
) -> Option<DistanceResult> {
    let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
    for (i, (ha, _, aabb1)) in sa.iter().enumerate() {
        for (k, (hb, _, aabb2)) in sb.iter().enumerate() {
            let gap = aabb_gap(aabb1, aabb2);
            if ha != hb && gap < limit {
                candidates.push((gap, i, k));
            }
        }
    }
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut best: Option<DistanceResult> = None;
    for (gap, i, k) in candidates {
        let lim = best.map_or(limit, |r| r.distance.min(limit));
        if gap >= lim {
            break;
        }
        let ((ha, c1, _), (hb, c2, _)) = (&sa[i], &sb[k]);
        let max = if lim.is_finite() { lim as f32 } else { f32::MAX };
        let Ok(cp) = query::closest_points(c1.position(), c1.shape(), c2.position(), c2.shape(), max) else {
            continue;
        };
        let (p1, p2) = match cp {
            query::ClosestPoints::Intersecting => {
                let p = math::vec_from_physics(c1.position().translation);
                (p, p)
            }
            query::ClosestPoints::WithinMargin(p1, p2) => (math::vec_from_physics(p1), math::vec_from_physics(p2)),
            query::ClosestPoints::Disjoint => continue,
        };
        let d = (p2 - p1).norm();
        if d < lim {
            best = Some(DistanceResult {
                p1,
                p2,
                distance: d,
                objects: [*ha, *hb],
            });
        }
    }
    best
}

/// Distance between two axis-aligned boxes (0 when they overlap).
fn aabb_gap(a: &Aabb, b: &Aabb) -> f64 {
    let mut sq = 0.0f64;
    for i in 0..3 {
        let g = (b.mins[i] - a.maxs[i]).max(a.mins[i] - b.maxs[i]).max(0.0);
        sq += f64::from(g) * f64::from(g);
    }
    sq.sqrt()
}
