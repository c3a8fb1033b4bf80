//! Point clouds: `sim.createPointCloud`, `insertPointsIntoPointCloud`,
//! `removePointsFromPointCloud`, `intersectPointsWithPointCloud`, `getPointCloudPoints`
//! and `get/setPointCloudOptions`, with CoppeliaSim 4.x's arguments and results. The
//! model (voxels, tolerances, limits) lives in `world::point_cloud`.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::{Pose, Vec3};
use crate::world::{Handle, ObjectKind, PointCloud, PointCloudOptions, PointColors, World};

/// The functions of this file, sorted by name.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "createPointCloud",
        call: ApiFn::World(create_point_cloud),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPointCloudOptions",
        call: ApiFn::World(get_point_cloud_options),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPointCloudPoints",
        call: ApiFn::World(get_point_cloud_points),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "insertPointsIntoPointCloud",
        call: ApiFn::World(insert_points_into_point_cloud),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "intersectPointsWithPointCloud",
        call: ApiFn::World(intersect_points_with_point_cloud),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "removePointsFromPointCloud",
        call: ApiFn::World(remove_points_from_point_cloud),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setPointCloudOptions",
        call: ApiFn::World(set_point_cloud_options),
        cost: Cost::Quick,
    },
];

/// `insertPointsIntoPointCloud` (and removal, intersection) option bit 0: the points
/// are given in the cloud's frame, not the world's.
const POINTS_RELATIVE: i64 = 1;
/// `insertPointsIntoPointCloud` option bit 1: one colour per point.
const COLORS_PER_POINT: i64 = 2;

/// Arguments `i..i+4`: max voxel size, max point count per voxel, options, point size.
fn options_args(a: &Args<'_>, i: usize) -> Result<PointCloudOptions, SimError> {
    let voxel = a.finite(i)?;
    let count = a.int(i + 1)?;
    let options = a.int(i + 2)?;
    let size = a.finite(i + 3)?;
    PointCloudOptions::new(voxel, count, options, size)
}

/// `sim.createPointCloud(maxVoxelSize, maxPtCntPerVoxel, options, pointSize)` → handle.
///
/// The cloud is created at the world origin, at the root, with alias `PointCloud`, empty
/// and white. Sizes and counts are clamped into CoppeliaSim's ranges (voxel 0.001-1 m,
/// 1-100 points per voxel, 1-8 pixels); negative ones are an error. Options: bit 0
/// random colours, bit 1 show the OC tree, bit 3 no calculation structure, bit 4
/// emissive colour.
fn create_point_cloud(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let options = options_args(a, 0)?;
    let cloud = ObjectKind::PointCloud(Box::new(PointCloud::new(options)));
    let h = w.add_object("PointCloud", cloud, None, Pose::identity())?;
    Ok(vec![Value::Int(h)])
}

/// `sim.getPointCloudOptions(pointCloudHandle)` → `maxVoxelSize, maxPtCntPerVoxel,
/// options, pointSize`, after clamping.
fn get_point_cloud_options(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let o = w.point_cloud(a.handle(0)?)?.options();
    Ok(vec![
        Value::Float(o.max_voxel_size),
        Value::Int(o.max_points_per_voxel),
        Value::Int(o.options),
        Value::Float(o.point_size as f64),
    ])
}

/// `sim.setPointCloudOptions(pointCloudHandle, maxVoxelSize, maxPtCntPerVoxel, options,
/// pointSize)`, as `sim.createPointCloud` takes them; the points stay.
fn set_point_cloud_options(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.point_cloud(h)?;
    let options = options_args(a, 1)?;
    w.point_cloud_mut(h)?.set_options(options);
    Ok(Vec::new())
}

/// `sim.getPointCloudPoints(pointCloudHandle)` → `{x1, y1, z1, x2, ...}` in the cloud's
/// frame (m), in insertion order.
fn get_point_cloud_points(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let cloud = w.point_cloud(a.handle(0)?)?;
    let flat: Vec<f64> = cloud.points().iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    Ok(vec![Value::floats(&flat)])
}

/// Argument `i`: a flat list of coordinates, 3 per point; `None` for nil. An empty
/// table is no point.
pub(super) fn points_arg(a: &Args<'_>, i: usize) -> Result<Option<Vec<Vec3>>, SimError> {
    let items = match a.get(i) {
        Value::Nil => return Ok(None),
        Value::Array(items) => items.as_slice(),
        // An empty Lua table arrives as an empty map.
        Value::Map(pairs) if pairs.is_empty() => &[],
        other => {
            return Err(SimError::bad_argument(format!(
                "argument {}: expected table of numbers (x, y, z per point), got {}",
                i + 1,
                other.type_name()
            )));
        }
    };
    if items.len() % 3 != 0 {
        return Err(SimError::bad_argument(format!(
            "argument {}: expected 3 numbers per point (x, y, z), got {} numbers",
            i + 1,
            items.len()
        )));
    }
    let mut coords = Vec::with_capacity(items.len());
    for (k, v) in items.iter().enumerate() {
        match v.as_f64() {
            Some(f) if f.is_finite() => coords.push(f),
            _ => {
                return Err(SimError::bad_argument(format!(
                    "argument {}: element {} must be a finite number",
                    i + 1,
                    k + 1
                )));
            }
        }
    }
    Ok(Some(
        coords.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect(),
    ))
}

/// Points as the cloud stores them: in its frame. `relative` points already are;
/// others are world-frame and go through the inverse of the cloud's pose.
pub(super) fn to_cloud_frame(w: &World, h: Handle, points: Vec<Vec3>, relative: bool) -> Result<Vec<Vec3>, SimError> {
    if relative {
        return Ok(points);
    }
    let pose = w.object(h)?.world;
    Ok(points
        .iter()
        .map(|p| pose.inverse_transform_point(&(*p).into()).coords)
        .collect())
}

/// Argument `i`: colour bytes (0-255), as a table of numbers or a byte string; at least
/// `needed` of them (extra ones are ignored, as in CoppeliaSim).
pub(super) fn color_bytes(a: &Args<'_>, i: usize, needed: usize) -> Result<Vec<u8>, SimError> {
    let bytes: Vec<u8> = match a.get(i) {
        Value::Array(items) => items
            .iter()
            .take(needed)
            .enumerate()
            .map(|(k, v)| {
                v.as_f64()
                    .filter(|c| (0.0..256.0).contains(c))
                    // Truncated like CoppeliaSim's conversion to unsigned char.
                    .map(|c| c as u8)
                    .ok_or_else(|| {
                        SimError::bad_argument(format!(
                            "argument {}: colour element {} must be a number from 0 to 255",
                            i + 1,
                            k + 1
                        ))
                    })
            })
            .collect::<Result<_, _>>()?,
        Value::Bytes(b) => b.clone(),
        Value::Str(s) => s.as_bytes().to_vec(),
        Value::Map(pairs) if pairs.is_empty() => Vec::new(),
        other => {
            return Err(SimError::bad_argument(format!(
                "argument {}: expected table of colour bytes (0-255) or nil, got {}",
                i + 1,
                other.type_name()
            )));
        }
    };
    if bytes.len() < needed {
        return Err(SimError::bad_argument(format!(
            "argument {}: expected at least {needed} colour values (3 {}), got {}",
            i + 1,
            if needed == 3 { "for all points" } else { "per point" },
            bytes.len()
        )));
    }
    Ok(bytes)
}

/// `sim.insertPointsIntoPointCloud(pointCloudHandle, options, points, color=nil,
/// duplicateTolerance=0)` → total point count.
///
/// `points` is `{x1, y1, z1, x2, ...}` (m), world frame unless option bit 0; `color` is
/// RGB 0-255, one triple for all points, or one per point with option bit 1; without
/// it points are white. A point closer than `duplicateTolerance` (m, clamped to 1) to
/// one already in the cloud, or inserted before it, is skipped.
fn insert_points_into_point_cloud(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.point_cloud(h)?;
    let options = a.int(1)?;
    let points = points_arg(a, 2)?
        .ok_or_else(|| SimError::bad_argument("argument 3: expected table of numbers (x, y, z per point), got nil"))?;
    let per_point = options & COLORS_PER_POINT != 0;
    let colors: Option<Vec<[u8; 3]>> = match a.get(3) {
        Value::Nil => None,
        _ => {
            let n = if per_point { points.len() } else { 1 };
            let bytes = color_bytes(a, 3, 3 * n)?;
            Some(bytes.chunks_exact(3).take(n).map(|c| [c[0], c[1], c[2]]).collect())
        }
    };
    let tolerance = match a.get(4) {
        Value::Nil => 0.0,
        _ => a.finite(4)?,
    };
    let points = to_cloud_frame(w, h, points, options & POINTS_RELATIVE != 0)?;
    let colors = match &colors {
        None => PointColors::Default,
        Some(c) if per_point => PointColors::PerPoint(c),
        Some(c) => PointColors::Uniform(c[0]),
    };
    let total = w.point_cloud_mut(h)?.insert(&points, colors, tolerance)?;
    Ok(vec![Value::Int(total as i64)])
}

/// `sim.removePointsFromPointCloud(pointCloudHandle, options, points, tolerance)` →
/// total point count. Removes every point closer than `tolerance` (m) to one of
/// `points` (world frame unless option bit 0); `points` nil removes them all.
fn remove_points_from_point_cloud(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.point_cloud(h)?;
    let options = a.int(1)?;
    let Some(points) = points_arg(a, 2)? else {
        let cloud = w.point_cloud_mut(h)?;
        cloud.clear();
        return Ok(vec![Value::Int(0)]);
    };
    let tolerance = a.finite(3)?;
    let points = to_cloud_frame(w, h, points, options & POINTS_RELATIVE != 0)?;
    let cloud = w.point_cloud_mut(h)?;
    cloud.remove_near(&points, tolerance)?;
    Ok(vec![Value::Int(cloud.len() as i64)])
}

/// `sim.intersectPointsWithPointCloud(pointCloudHandle, options, points, tolerance)` →
/// total point count. Keeps only the points closer than `tolerance` (m) to one of
/// `points` (world frame unless option bit 0); `points` nil removes them all.
fn intersect_points_with_point_cloud(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.point_cloud(h)?;
    let options = a.int(1)?;
    let Some(points) = points_arg(a, 2)? else {
        w.point_cloud_mut(h)?.clear();
        return Ok(vec![Value::Int(0)]);
    };
    let tolerance = a.finite(3)?;
    let points = to_cloud_frame(w, h, points, options & POINTS_RELATIVE != 0)?;
    let total = w.point_cloud_mut(h)?.intersect(&points, tolerance)?;
    Ok(vec![Value::Int(total as i64)])
}
