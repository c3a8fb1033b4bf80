//! OC trees: `sim.createOctree`, `insertVoxelsIntoOctree`, `removeVoxelsFromOctree`,
//! `getOctreeVoxels`, `insertObjectIntoOctree`, `subtractObjectFromOctree` and
//! `checkOctreePointOccupancy`, with CoppeliaSim 4.x's arguments and results. The model
//! (voxel grid, tolerance, limits) lives in `world::octree`.

use super::point_cloud::{color_bytes, points_arg, to_cloud_frame};
use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::{Pose, Vec3};
use crate::world::{DEFAULT_VOXEL_COLOR, Handle, ObjectKind, Octree, Triangle, Voxel, World};

/// The functions of this file, sorted by name.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "checkOctreePointOccupancy",
        call: ApiFn::World(check_octree_point_occupancy),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createOctree",
        call: ApiFn::World(create_octree),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getOctreeVoxels",
        call: ApiFn::World(get_octree_voxels),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "insertObjectIntoOctree",
        call: ApiFn::World(insert_object_into_octree),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "insertVoxelsIntoOctree",
        call: ApiFn::World(insert_voxels_into_octree),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "removeVoxelsFromOctree",
        call: ApiFn::World(remove_voxels_from_octree),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "subtractObjectFromOctree",
        call: ApiFn::World(subtract_object_from_octree),
        cost: Cost::Quick,
    },
];

/// Option bit 0 of the voxel functions: the points are given in the octree's frame,
/// not the world's.
const POINTS_RELATIVE: i64 = 1;
/// `insertVoxelsIntoOctree` option bit 1: one colour per point.
const COLORS_PER_POINT: i64 = 2;
/// `insertVoxelsIntoOctree` option bit 2: one tag per point.
const TAGS_PER_POINT: i64 = 4;

/// `sim.createOctree(voxelSize, options, pointSize)` → handle.
///
/// The octree is created at the world origin, at the root, with alias `Octree`, empty.
/// `voxelSize` (m) must be a finite number > 0; `options` and `pointSize` are CoppeliaSim's
/// display settings, kept as given.
fn create_octree(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let octree = Octree::new(a.finite(0)?, a.int(1)?, a.finite(2)?).map_err(|e| e.prefixed("argument 1: "))?;
    let h = w.add_object("Octree", ObjectKind::Octree(Box::new(octree)), None, Pose::identity())?;
    Ok(vec![Value::Int(h)])
}

/// Argument `i`: user tags, a table of integers 0 to 2^32-1 (at least `needed`), or a
/// single integer; nil gives tag 0.
fn tags_arg(a: &Args<'_>, i: usize, needed: usize) -> Result<Vec<u32>, SimError> {
    let tag = |k: usize, v: &Value| {
        v.as_f64()
            .filter(|t| t.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(t))
            .map(|t| t as u32)
            .ok_or_else(|| {
                SimError::bad_argument(format!(
                    "argument {}: tag {} must be an integer from 0 to 4294967295",
                    i + 1,
                    k + 1
                ))
            })
    };
    let tags = match a.get(i) {
        Value::Nil => return Ok(vec![0; needed.max(1)]),
        Value::Array(items) => items
            .iter()
            .take(needed)
            .enumerate()
            .map(|(k, v)| tag(k, v))
            .collect::<Result<Vec<_>, _>>()?,
        v @ (Value::Int(_) | Value::Float(_)) => vec![tag(0, v)?],
        other => {
            return Err(SimError::bad_argument(format!(
                "argument {}: expected table of tags (integers) or nil, got {}",
                i + 1,
                other.type_name()
            )));
        }
    };
    if tags.len() < needed {
        return Err(SimError::bad_argument(format!(
            "argument {}: expected at least {needed} tags, got {}",
            i + 1,
            tags.len()
        )));
    }
    Ok(tags)
}

/// Argument `i`: colours, `needed` RGB triples (0-255) flat, or nil for
/// [`DEFAULT_VOXEL_COLOR`].
fn colors_arg(a: &Args<'_>, i: usize, needed: usize) -> Result<Vec<[u8; 3]>, SimError> {
    if matches!(a.get(i), Value::Nil) {
        return Ok(vec![DEFAULT_VOXEL_COLOR]);
    }
    let bytes = color_bytes(a, i, 3 * needed)?;
    Ok(bytes.chunks_exact(3).take(needed).map(|c| [c[0], c[1], c[2]]).collect())
}

/// Argument `i`: points (x, y, z each), in the octree's frame once converted.
fn octree_points(w: &World, h: Handle, a: &Args<'_>, i: usize, options: i64) -> Result<Option<Vec<Vec3>>, SimError> {
    match points_arg(a, i)? {
        None => Ok(None),
        Some(points) => to_cloud_frame(w, h, points, options & POINTS_RELATIVE != 0).map(Some),
    }
}

/// `sim.insertVoxelsIntoOctree(octreeHandle, options, points, color=nil, tag=nil)` →
/// total voxel count.
///
/// Occupies the voxels holding each point (`{x1, y1, z1, ...}`, m, world frame unless
/// option bit 0): one voxel, or 2 to 8 when a point lies on voxel faces, edges or
/// corners. `color` is RGB 0-255, one triple for all points or one per point with option
/// bit 1; `tag` one integer for all, or one per point with option bit 2. An occupied
/// voxel takes the new colour and tag.
fn insert_voxels_into_octree(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.octree(h)?;
    let options = a.int(1)?;
    let points = octree_points(w, h, a, 2, options)?
        .ok_or_else(|| SimError::bad_argument("argument 3: expected table of numbers (x, y, z per point), got nil"))?;
    let per = |bit: i64| if options & bit != 0 { points.len() } else { 1 };
    let colors = colors_arg(a, 3, per(COLORS_PER_POINT))?;
    let tags = tags_arg(a, 4, per(TAGS_PER_POINT))?;
    let tags = if options & TAGS_PER_POINT != 0 {
        tags
    } else {
        tags[..1].to_vec()
    };
    let total = w.octree_mut(h)?.insert_points(&points, &colors, &tags)?;
    Ok(vec![Value::Int(total as i64)])
}

/// `sim.removeVoxelsFromOctree(octreeHandle, options, points)` → total voxel count.
/// Empties the voxels holding each point (world frame unless option bit 0); `points` nil
/// empties them all.
fn remove_voxels_from_octree(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.octree(h)?;
    let options = a.int(1)?;
    let Some(points) = octree_points(w, h, a, 2, options)? else {
        w.octree_mut(h)?.clear();
        return Ok(vec![Value::Int(0)]);
    };
    let total = w.octree_mut(h)?.remove_points(&points)?;
    Ok(vec![Value::Int(total as i64)])
}

/// `sim.getOctreeVoxels(octreeHandle)` → `{x1, y1, z1, x2, ...}`: the occupied voxels'
/// centres in the octree's frame (m), in grid order (x, then y, then z).
fn get_octree_voxels(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let octree = w.octree(a.handle(0)?)?;
    let flat: Vec<f64> = octree.centers().iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    Ok(vec![Value::floats(&flat)])
}

/// `sim.checkOctreePointOccupancy(octreeHandle, options, points)` → `result, tag`.
///
/// `result` is 1 when at least one of the points (world frame unless option bit 0) lies
/// in an occupied voxel, else 0 (CoppeliaSim's rule: the points collide with the
/// voxels). `tag` is that voxel's tag when a single point is tested and found, else 0.
/// CoppeliaSim's third and fourth results (the voxel's location in its tree) are not
/// given: they name nodes of CoppeliaSim's tree layout, which gantry does not have.
fn check_octree_point_occupancy(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.octree(h)?;
    let options = a.int(1)?;
    let points = octree_points(w, h, a, 2, options)?.unwrap_or_default();
    if points.is_empty() {
        return Err(SimError::bad_argument(
            "argument 3: expected at least one point (x, y, z)",
        ));
    }
    let found = w.octree(h)?.occupied(&points)?;
    let tag = match found {
        Some(v) if points.len() == 1 => i64::from(v.tag),
        _ => 0,
    };
    Ok(vec![Value::Int(i64::from(found.is_some())), Value::Int(tag)])
}

/// What an object adds to or removes from an octree, in the octree's frame.
enum Geometry {
    /// A shape's mesh.
    Triangles(Vec<Triangle>),
    /// A point cloud's points.
    Points(Vec<Vec3>),
}

/// The geometry of `object` in the frame of `octree`. Shapes give their mesh (visual
/// parts, collision parts when they have none), point clouds their points.
fn object_geometry(w: &World, octree: Handle, object: Handle) -> Result<Geometry, SimError> {
    if object == octree {
        return Err(SimError::bad_argument(
            "argument 2: an octree cannot be inserted into or subtracted from itself",
        ));
    }
    let o = w.object(object)?;
    let to_octree = w.object(octree)?.world.inverse() * o.world;
    let moved = |p: Vec3| (to_octree * nalgebra::Point3::from(p)).coords;
    match &o.kind {
        ObjectKind::Shape(_) => {
            let mesh = w.shape_mesh(object)?;
            let v: Vec<Vec3> = mesh.vertices.iter().map(|p| moved(Vec3::from(*p))).collect();
            Ok(Geometry::Triangles(
                mesh.indices.iter().map(|t| t.map(|i| v[i as usize])).collect(),
            ))
        }
        ObjectKind::PointCloud(c) => Ok(Geometry::Points(c.points().iter().map(|p| moved(*p)).collect())),
        other => Err(SimError::bad_argument(format!(
            "argument 2: object {object} is a {}; only shapes and point clouds can be inserted into \
             or subtracted from an octree",
            other.name()
        ))),
    }
}

/// `sim.insertObjectIntoOctree(octreeHandle, objectHandle, options, color=nil, tag=0)`
/// → total voxel count.
///
/// Occupies the voxels that the object touches, with `color` (one RGB triple, 0-255)
/// and `tag`: for a shape, every voxel its mesh surface touches (a closed mesh is not
/// filled, as in CoppeliaSim); for a point cloud, the voxels holding its points.
/// `options` is reserved (CoppeliaSim's too).
fn insert_object_into_octree(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.octree(h)?;
    let object = a.handle(1)?;
    a.opt_int(2, 0)?;
    let color = colors_arg(a, 3, 1)?[0];
    let tag = tags_arg(a, 4, 1)?[0];
    let geometry = object_geometry(w, h, object)?;
    let octree = w.octree_mut(h)?;
    let total = match geometry {
        Geometry::Triangles(t) => octree.insert_triangles(&t, Voxel { color, tag })?,
        Geometry::Points(p) => octree.insert_points(&p, &[color], &[tag])?,
    };
    Ok(vec![Value::Int(total as i64)])
}

/// `sim.subtractObjectFromOctree(octreeHandle, objectHandle, options)` → total voxel
/// count. Empties the voxels the object touches, as `sim.insertObjectIntoOctree` would
/// occupy them. `options` is reserved.
fn subtract_object_from_octree(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.octree(h)?;
    let object = a.handle(1)?;
    a.opt_int(2, 0)?;
    let geometry = object_geometry(w, h, object)?;
    let octree = w.octree_mut(h)?;
    let total = match geometry {
        Geometry::Triangles(t) => octree.subtract_triangles(&t)?,
        Geometry::Points(p) => octree.remove_points(&p)?,
    };
    Ok(vec![Value::Int(total as i64)])
}
