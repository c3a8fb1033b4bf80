//! Laser scanners: gantry's batch ray cast `sim.castRays`, and the `simVision`
//! functions CoppeliaSim's scanner models call on a depth sensor's work image
//! (`coordinatesFromWorkImg`, `velodyneDataFromWorkImg`).
//!
//! Two ways to one scan. A ray cast asks rapier's collision geometry directly and
//! renders nothing; the `simVision` path renders the depth sensor and reads points off
//! its depth map, as CoppeliaSim's Hokuyo, SICK and Velodyne models do, so their
//! scripts run unchanged. See [`crate::sensor::cast_rays`] and
//! [`crate::vision::scan`] for the geometry.

use super::vision::self_or;
use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sensor::{self, RayCastParams, RayHit};
use crate::sim::Sim;
use crate::vision::scan::{self, PointFrame};
use crate::world::{Handle, World};

/// `sim.handleflag_abscoords`: OR-ed onto a sensor handle, asks for points in the world
/// frame (CoppeliaSim's value).
const HANDLEFLAG_ABSCOORDS: i64 = 0x0080_0000;
/// `castRays` option bit 0: only shapes marked detectable.
const CAST_DETECTABLE_ONLY: i64 = 1;
/// `castRays` option bit 1: results as packed numbers rather than tables.
const CAST_PACKED: i64 = 2;

/// The `sim.*` scanner functions, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[ApiFunction {
    // gantry's own: CoppeliaSim has no batch ray cast.
    name: "castRays",
    call: ApiFn::World(cast_rays),
    cost: Cost::Long,
}];

/// The `simVision.*` scanner functions, in alphabetical order.
pub(super) const SIM_VISION_FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "coordinatesFromWorkImg",
        call: ApiFn::Sim(coordinates_from_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "velodyneDataFromWorkImg",
        call: ApiFn::Sim(velodyne_data_from_work_img),
        cost: Cost::Long,
    },
];

/// The scanner constants of `sim.*`.
pub(super) const CONSTANTS: &[(&str, i64)] = &[("handleflag_abscoords", HANDLEFLAG_ABSCOORDS)];

/// `sim.castRays(frameHandle, directions, maxDistance, ignoredTree=-1, options=0)` →
/// `distances, handles`: one ray per direction from the origin of `frameHandle`
/// (`sim.handle_self` for the calling script's object) against the scene's collision
/// geometry. `directions` holds x, y, z per ray in the frame object's coordinates, as a
/// flat table of numbers or a string of packed floats (`sim.packFloatTable`); each may
/// have any length but zero (they are normalised). Each ray reports the distance (m) to its first hit within `maxDistance`
/// and the shape hit, or `-1` and `-1` when nothing is hit that near. A ray starting
/// inside a shape hits it at 0 m: pass the scanner's model as `ignoredTree` (its root;
/// `-1` for none) and the rays pass through that object and everything below it.
/// `options` bit 0: hit only shapes marked detectable (as proximity sensors), not every
/// collidable shape (the floor included, as a depth sensor sees); bit 1: return the
/// distances as packed floats (`sim.unpackFloatTable`) and the handles as packed int32s
/// (`sim.unpackInt32Table`), which for a 3-D scan of 28,800 rays saves two tables of
/// that many numbers (with packed directions, 40 % of the call's time).
fn cast_rays(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let frame = self_or(ctx, a.handle(0)?)?;
    let directions = directions(a, 1)?;
    let max_distance = a.f64(2)?;
    let ignored_tree = match a.opt_int(3, -1)? {
        -1 => None,
        h => Some(self_or(ctx, h)?),
    };
    let options = a.opt_int(4, 0)?;
    if options & !(CAST_DETECTABLE_ONLY | CAST_PACKED) != 0 {
        return Err(SimError::bad_argument(format!(
            "argument 5: options {options} has unknown bits (bit 0: detectable shapes only; bit 1: packed results)"
        )));
    }
    let params = RayCastParams {
        max_distance,
        ignored_tree,
        detectable_only: options & CAST_DETECTABLE_ONLY != 0,
    };
    if !(max_distance.is_finite() && max_distance > 0.0) {
        return Err(SimError::bad_argument(format!(
            "argument 3: maximum distance must be finite and > 0 m, got {max_distance}"
        )));
    }
    let mut hits = Vec::with_capacity(directions.len());
    // With the distance checked, what the world refuses is the directions.
    sensor::cast_rays(w, frame, &directions, &params, &mut hits).map_err(|e| match e {
        SimError::BadArgument(_) => e.prefixed("argument 2: "),
        other => other,
    })?;
    let distances = hits.iter().map(|h| h.map_or(-1.0, |h| h.distance));
    let handles = hits.iter().map(|h: &Option<RayHit>| h.map_or(-1, |h| h.object));
    Ok(if options & CAST_PACKED != 0 {
        vec![
            Value::Bytes(distances.flat_map(|d| (d as f32).to_le_bytes()).collect()),
            // Handles are small non-negative integers or -1: they fit 32 bits.
            Value::Bytes(handles.flat_map(|h| (h as i32).to_le_bytes()).collect()),
        ]
    } else {
        vec![
            Value::Array(distances.map(Value::Float).collect()),
            Value::Array(handles.map(Value::Int).collect()),
        ]
    })
}

/// Argument `i` as ray directions: a flat table of numbers or packed `f32`s, 3 per ray.
/// Read straight into triples: a 3-D scan is 86,400 numbers, and every intermediate
/// buffer of that size costed about a tenth of the ray cast.
fn directions(a: &Args<'_>, i: usize) -> Result<Vec<[f64; 3]>, SimError> {
    let whole = |n: usize| {
        if n.is_multiple_of(3) {
            Ok(())
        } else {
            Err(SimError::bad_argument(format!(
                "argument {}: {n} numbers do not make whole directions (3 per ray)",
                i + 1
            )))
        }
    };
    match a.get(i) {
        Value::Array(items) => {
            whole(items.len())?;
            let number = |k: usize, v: &Value| {
                v.as_f64().ok_or_else(|| {
                    SimError::bad_argument(format!(
                        "argument {}: element {} is a {}, expected a number",
                        i + 1,
                        k + 1,
                        v.type_name()
                    ))
                })
            };
            // A loop into a buffer of the final size: collecting through `Result` grows
            // the vector by doubling, a few copies of a 700 KB buffer per 3-D scan.
            let mut out = Vec::with_capacity(items.len() / 3);
            for (k, c) in items.chunks_exact(3).enumerate() {
                out.push([
                    number(3 * k, &c[0])?,
                    number(3 * k + 1, &c[1])?,
                    number(3 * k + 2, &c[2])?,
                ]);
            }
            Ok(out)
        }
        Value::Bytes(b) => packed_directions(b, i),
        Value::Str(s) => packed_directions(s.as_bytes(), i),
        other => Err(SimError::bad_argument(format!(
            "argument {}: expected a table of directions (x, y, z per ray) or packed floats, got {}",
            i + 1,
            other.type_name()
        ))),
    }
}

/// Directions packed as little-endian `f32`s, 3 per ray, from argument `i`.
fn packed_directions(bytes: &[u8], i: usize) -> Result<Vec<[f64; 3]>, SimError> {
    if !bytes.len().is_multiple_of(12) {
        return Err(SimError::bad_argument(format!(
            "argument {}: {} bytes of packed floats do not make whole directions (3 floats, 12 bytes, per ray)",
            i + 1,
            bytes.len()
        )));
    }
    let float = |b: &[u8]| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    Ok(bytes
        .chunks_exact(12)
        .map(|c| [float(&c[0..4]), float(&c[4..8]), float(&c[8..12])])
        .collect())
}

/// Argument 0 of the `simVision` scanner functions: the sensor (`sim.handle_self` for
/// the calling script's object), with `sim.handleflag_abscoords` asking for world
/// coordinates.
fn scan_sensor(ctx: &CallContext<'_>, a: &Args<'_>) -> Result<(Handle, PointFrame), SimError> {
    let raw = a.handle(0)?;
    if raw >= 0 && raw & HANDLEFLAG_ABSCOORDS != 0 {
        Ok((raw & !HANDLEFLAG_ABSCOORDS, PointFrame::World))
    } else {
        Ok((self_or(ctx, raw)?, PointFrame::Sensor))
    }
}

/// Argument `i` as the point counts `{x, y}`, positive integers.
fn counts(a: &Args<'_>, i: usize) -> Result<[usize; 2], SimError> {
    let bad = || {
        SimError::bad_argument(format!(
            "argument {}: expected a table of 2 positive integers (points along x and y)",
            i + 1
        ))
    };
    match a.get(i) {
        Value::Array(items) if items.len() == 2 => {
            let get = |k: usize| {
                items[k]
                    .as_i64()
                    .and_then(|v| usize::try_from(v).ok())
                    .filter(|&v| v > 0)
                    .ok_or_else(bad)
            };
            Ok([get(0)?, get(1)?])
        }
        _ => Err(bad()),
    }
}

/// The scan as CoppeliaSim returns it: `false` (never a trigger), the floats packed and,
/// when colours were returned, their bytes (`sim.unpackUInt8Table` reads them).
fn scan_values(scan: scan::Scan) -> Ret {
    let mut out = vec![
        Value::Bool(false),
        Value::Bytes(scan.packet.iter().flat_map(|v| v.to_le_bytes()).collect()),
    ];
    out.extend(scan.colours.map(Value::Bytes));
    out
}

/// `simVision.coordinatesFromWorkImg(h [| sim.handleflag_abscoords], {nx, ny},
/// angularSpace, returnRgb=false)` → `false, packedPoints`: `nx x ny` points from the
/// depth work image (`simVision.sensorDepthMapToWorkImg`), evenly spaced in angle
/// (`angularSpace`) or across the image, in the sensor frame (the world frame with the
/// flag). Packed floats: `nx, ny`, then `x, y, z, distance` per point, x varying fastest,
/// from image right to left and bottom to top. Distance is the point's range (its depth
/// for an orthographic sensor); a direction with nothing nearer than the far clipping
/// plane gives the point at the far distance along it, with distance = far. With
/// `returnRgb`, a third value holds R, G, B bytes per point from buffer 1
/// (`simVision.workImgToBuffer1` of the colour image), when it holds an image.
fn coordinates_from_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (h, frame) = scan_sensor(ctx, a)?;
    let counts = counts(a, 1)?;
    let angular = a.bool(2)?;
    let rgb = a.opt_bool(3, false)?;
    let scan = scan::coordinates_from_work(&sim.world, &sim.vision, h, counts, angular, frame, rgb)?;
    Ok(scan_values(scan))
}

/// `simVision.velodyneDataFromWorkImg(h [| sim.handleflag_abscoords], {nx, ny},
/// verticalAngle, returnRgb=false)` → `false, packedPoints`: `nx` azimuths evenly spaced
/// in angle across the view, each with `ny` beams evenly spaced in elevation over
/// `verticalAngle` (rad), read from the depth work image of a perspective sensor. The
/// packet is `coordinatesFromWorkImg`'s with y (the beams of one azimuth) varying
/// fastest. The beams at the view's sides must stay inside the image. `returnRgb` as
/// for `coordinatesFromWorkImg`.
fn velodyne_data_from_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (h, frame) = scan_sensor(ctx, a)?;
    let counts = counts(a, 1)?;
    let vertical = a.finite(2)?;
    let rgb = a.opt_bool(3, false)?;
    let scan = scan::velodyne_from_work(&sim.world, &sim.vision, h, counts, vertical, frame, rgb)?;
    Ok(scan_values(scan))
}
