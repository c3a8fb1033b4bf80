//! Paths: CoppeliaSim 4.3+'s path math on flat lists of configurations
//! (`sim.getPathLengths`, `sim.getPathInterpolatedConfig`, `sim.resamplePath`), path
//! objects (`sim.createPath`, in its 4.3+ and its V-REP 3 form) and V-REP 3's path-object
//! functions on them (`sim.getPathLength`, `sim.getPositionOnPath`, ...;
//! [`crate::paths`]). The blocking `sim.followPath` and `sim.moveToPosition` are the Lua
//! host's (`lua/path_motion.lua`), written on these.
//!
//! A path object is a dummy (4.3+) or an old path object (V-REP 3's `sim.createPath`, or
//! a 4.1 scene's `PAT` object); its points also go to its custom data blocks `PATHCTRLPTS`
//! and `PATH` (packed doubles, 7 per point, in the path's frame), where 4.3+ scripts
//! read them with `sim.readCustomDataBlock` and `sim.unpackDoubleTable`.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::{Pose, euler_from_quat, quat_from_euler, quat_to_array};
use crate::paths::{DofType, Method, PathObject, PathPoint, PathRef, Shaping, count, lengths};
use crate::sim::Sim;
use crate::world::{Handle, ObjectKind, World};

/// The path functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "createPath",
        call: ApiFn::Sim(create_path),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "cutPathCtrlPoints",
        call: ApiFn::Sim(cut_path_ctrl_points),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getOrientationOnPath",
        call: ApiFn::Sim(get_orientation_on_path),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPathInterpolatedConfig",
        call: ApiFn::World(get_path_interpolated_config),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPathLength",
        call: ApiFn::Sim(get_path_length),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPathLengths",
        call: ApiFn::World(get_path_lengths),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPathPosition",
        call: ApiFn::Sim(get_path_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getPositionOnPath",
        call: ApiFn::Sim(get_position_on_path),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "insertPathCtrlPoints",
        call: ApiFn::Sim(insert_path_ctrl_points),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "resamplePath",
        call: ApiFn::World(resample_path),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setPathPosition",
        call: ApiFn::Sim(set_path_position),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setPathTargetNominalVelocity",
        call: ApiFn::Sim(set_path_target_nominal_velocity),
        cost: Cost::Quick,
    },
];

/// V-REP's distance calculation methods (`sim.moveToPosition`'s `distCalcMethod`): how
/// a linear distance dl (m) and an angle dac (rad) make one distance.
pub const CONSTANTS: &[(&str, i64)] = &[
    ("distcalcmethod_dl", 0),
    ("distcalcmethod_dac", 1),
    ("distcalcmethod_max_dl_dac", 2),
    ("distcalcmethod_dl_and_dac", 3),
    ("distcalcmethod_sqrt_dl2_and_dac2", 4),
    ("distcalcmethod_dl_if_nonzero", 5),
    ("distcalcmethod_dac_if_nonzero", 6),
];

// ---------------------------------------------------------------------------------------
// Arguments

/// Argument `i` as a table of finite numbers; `what` names it in errors.
fn numbers(a: &Args<'_>, i: usize, what: &str) -> Result<Vec<f64>, SimError> {
    let items: &[Value] = match a.get(i) {
        Value::Array(items) => items,
        // An empty Lua table may arrive as an empty map.
        Value::Map(pairs) if pairs.is_empty() => &[],
        other => {
            return Err(SimError::bad_argument(format!(
                "argument {} ({what}): expected a table of numbers, got {}",
                i + 1,
                other.type_name()
            )));
        }
    };
    items
        .iter()
        .enumerate()
        .map(|(k, v)| match v.as_f64() {
            Some(f) if f.is_finite() => Ok(f),
            _ => Err(SimError::bad_argument(format!(
                "argument {} ({what}): element {} must be a finite number",
                i + 1,
                k + 1
            ))),
        })
        .collect()
}

/// Argument `i` as a count of at least `min` (a dof, a number of points).
fn size(a: &Args<'_>, i: usize, what: &str, min: i64) -> Result<usize, SimError> {
    let n = a.int(i)?;
    if n < min {
        return Err(SimError::bad_argument(format!(
            "argument {} ({what}): expected at least {min}, got {n}",
            i + 1
        )));
    }
    usize::try_from(n).map_err(|_| SimError::bad_argument(format!("argument {} ({what}): too large", i + 1)))
}

/// `method` of the interpolating functions: nil, or `{type='linear'|'quadraticBezier',
/// strength=1.0, forceOpen=false}`.
fn method(a: &Args<'_>, i: usize) -> Result<Method, SimError> {
    let m = a.get(i);
    let bad = |msg: String| SimError::bad_argument(format!("argument {} (method): {msg}", i + 1));
    match m {
        Value::Nil => return Ok(Method::LINEAR),
        Value::Map(_) => {}
        Value::Array(items) if items.is_empty() => return Ok(Method::LINEAR),
        other => return Err(bad(format!("expected a map, got {}", other.type_name()))),
    }
    let force_open = match m.get("forceOpen") {
        None | Some(Value::Nil) => false,
        Some(Value::Bool(b)) => *b,
        Some(other) => return Err(bad(format!("'forceOpen' must be a boolean, got {}", other.type_name()))),
    };
    let bezier = match m.get("type").map(|v| v.as_str()) {
        None | Some(Some("linear")) => None,
        Some(Some("quadraticBezier")) => {
            let s = match m.get("strength") {
                None | Some(Value::Nil) => 1.0,
                Some(v) => v
                    .as_f64()
                    .ok_or_else(|| bad("'strength' must be a number".to_owned()))?,
            };
            if !(0.05..=1.0).contains(&s) {
                return Err(bad(format!("'strength' is from 0.05 to 1.0, got {s}")));
            }
            Some(s)
        }
        Some(t) => {
            return Err(bad(format!(
                "'type' is 'linear' or 'quadraticBezier', got {}",
                t.unwrap_or("a non-string")
            )));
        }
    };
    Ok(Method { bezier, force_open })
}

/// `types` of the interpolating functions: nil (all Cartesian) or one code per value.
fn types(a: &Args<'_>, i: usize) -> Result<Vec<DofType>, SimError> {
    if a.get(i) == &Value::Nil {
        return Ok(Vec::new());
    }
    numbers(a, i, "types")?
        .into_iter()
        .map(|t| {
            if t.fract() != 0.0 {
                return Err(SimError::bad_argument(format!(
                    "argument {} (types): expected integers, got {t}",
                    i + 1
                )));
            }
            DofType::from_code(t as i64).map_err(|e| SimError::bad_argument(format!("argument {} (types): {e}", i + 1)))
        })
        .collect()
}

/// The path and lengths of arguments 1 and 2, with the dof they imply.
fn path_and_lengths(a: &Args<'_>) -> Result<(Vec<f64>, Vec<f64>, usize), SimError> {
    let path = numbers(a, 0, "path")?;
    let lengths = numbers(a, 1, "pathLengths")?;
    if lengths.is_empty() || path.is_empty() || !path.len().is_multiple_of(lengths.len()) {
        return Err(SimError::bad_argument(format!(
            "arguments 1 and 2: a path of {} values does not hold one configuration per length ({})",
            path.len(),
            lengths.len()
        )));
    }
    let dof = path.len() / lengths.len();
    Ok((path, lengths, dof))
}

// ---------------------------------------------------------------------------------------
// Path math

/// `sim.getPathLengths(path, dof, distCallback=nil)` → (pathLengths, totalLength):
/// each configuration's distance from the first along the path, in the first (up to) 3
/// values as Cartesian coordinates.
fn get_path_lengths(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let path = numbers(a, 0, "path")?;
    let dof = size(a, 1, "dof", 1)?;
    if a.get(2) != &Value::Nil {
        return Err(SimError::bad_argument(
            "argument 3 (distCallback): gantry measures paths in their first 3 values only; \
             compute other distances in the script",
        ));
    }
    let (l, total) = lengths(&path, dof)?;
    Ok(vec![Value::floats(&l), Value::Float(total)])
}

/// `sim.getPathInterpolatedConfig(path, pathLengths, t, method=nil, types=nil)` → the
/// configuration at length `t` (clamped to the path).
fn get_path_interpolated_config(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (path, l, dof) = path_and_lengths(a)?;
    let t = a.finite(2)?;
    let (m, ty) = (method(a, 3)?, types(a, 4)?);
    let p = PathRef::new(&path, dof, &l, &ty)?;
    Ok(vec![Value::floats(&p.interpolate(t, m))])
}

/// `sim.resamplePath(path, pathLengths, finalConfigCnt, method=nil, types=nil)` → the
/// path as `finalConfigCnt` configurations at equal lengths.
fn resample_path(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (path, l, dof) = path_and_lengths(a)?;
    let n = size(a, 2, "finalConfigCnt", 2)?;
    if n.saturating_mul(dof) > 10_000_000 {
        return Err(SimError::bad_argument(format!(
            "argument 3 (finalConfigCnt): {n} configurations of {dof} values is too many"
        )));
    }
    let (m, ty) = (method(a, 3)?, types(a, 4)?);
    let p = PathRef::new(&path, dof, &l, &ty)?;
    Ok(vec![Value::floats(&p.resample(n, m))])
}

// ---------------------------------------------------------------------------------------
// Path objects

/// Most points `sim.createPath` makes, and most control points a path takes.
const MAX_POINTS: usize = 1_000_000;

/// `sim.createPath` → the path's handle, an object at the world origin. Two forms:
/// * 4.3+: `(ctrlPts, options=0, subdiv=100, smoothness=1.0, orientationMode=0,
///   upVector={0,0,1})`, 7 values per control point (`x, y, z, qx, qy, qz, qw` in the
///   path's frame); options bit 2 (4): closed. The other option bits (display, an
///   extruded shape) have nothing to act on in gantry.
/// * V-REP 3 (CoppeliaSim 4.1's): `(attributes, intParams, floatParams, color)`, an
///   empty old path object (`sim.object_path_type`, 8) that `sim.insertPathCtrlPoints`
///   fills; the arguments only concern display. The 4.3+ form makes a dummy, as 4.3+
///   does.
fn create_path(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (ctrl, closed, shaping, kind) = if a.get(0).as_f64().is_some() {
        // V-REP 3's form makes an old path object (`sim.object_path_type`).
        (Vec::new(), false, Shaping::POLYLINE, ObjectKind::Path)
    } else {
        let flat = numbers(a, 0, "ctrlPts")?;
        let n = count(&flat, 7).map_err(|e| SimError::bad_argument(format!("argument 1 (ctrlPts): {e}")))?;
        if n < 2 {
            return Err(SimError::bad_argument(
                "argument 1 (ctrlPts): a path needs at least 2 control points",
            ));
        }
        let options = a.opt_int(1, 0)?;
        let subdiv = match a.get(2) {
            Value::Nil => 100,
            _ => size(a, 2, "subdiv", 2)?,
        };
        if subdiv > MAX_POINTS {
            return Err(SimError::bad_argument(format!(
                "argument 3 (subdiv): at most {MAX_POINTS} points"
            )));
        }
        let smoothness = a.opt_f64(3, 1.0)?;
        if !(0.0..=1.0).contains(&smoothness) {
            return Err(SimError::bad_argument(format!(
                "argument 4 (smoothness): expected a value from 0 to 1, got {smoothness}"
            )));
        }
        let orientation = match u8::try_from(a.opt_int(4, 0)?) {
            Ok(m) if m <= 6 => m,
            _ => {
                return Err(SimError::bad_argument(format!(
                    "argument 5 (orientationMode): expected 0 to 6, got {}",
                    a.int(4)?
                )));
            }
        };
        let up = match a.get(5) {
            Value::Nil => [0.0, 0.0, 1.0],
            _ => a.floats::<3>(5)?,
        };
        let shaping = Shaping {
            subdiv,
            smoothness,
            orientation,
            up,
        };
        (points7(&flat), options & 4 != 0, shaping, ObjectKind::Dummy)
    };
    let path = PathObject::new(ctrl, closed, shaping)?;
    let h = sim.world.add_object("Path", kind, None, Pose::identity())?;
    sim.paths.insert(h, path);
    publish(sim, h);
    Ok(vec![Value::Int(h)])
}

/// Flat numbers, 7 per point, as points.
fn points7(flat: &[f64]) -> Vec<PathPoint> {
    flat.chunks_exact(7)
        .map(|c| [c[0], c[1], c[2], c[3], c[4], c[5], c[6]])
        .collect()
}

/// Writes path `h`'s control points and points to its custom data blocks.
fn publish(sim: &mut Sim, h: Handle) {
    let Some(p) = sim.paths.get(h) else { return };
    let pack = |pts: &[PathPoint]| Value::Bytes(pts.iter().flatten().flat_map(|v| v.to_le_bytes()).collect());
    let (ctrl, points) = (pack(p.ctrl_points()), pack(p.points()));
    sim.world.custom.write_block(h, "PATHCTRLPTS", ctrl);
    sim.world.custom.write_block(h, "PATH", points);
}

/// The path object of argument `i`.
fn path_of<'s>(sim: &'s Sim, a: &Args<'_>, i: usize) -> Result<(Handle, &'s PathObject), SimError> {
    let h = a.handle(i)?;
    sim.world.object(h)?;
    let p = sim.paths.get(h).ok_or_else(|| not_a_path(h))?;
    Ok((h, p))
}

fn not_a_path(h: Handle) -> SimError {
    SimError::bad_argument(format!(
        "object {h} is not a path (paths are made by sim.createPath or loaded with a scene; a copy of one is not)"
    ))
}

/// The path object of argument `i`, to change.
fn path_mut<'s>(sim: &'s mut Sim, a: &Args<'_>, i: usize) -> Result<(Handle, &'s mut PathObject), SimError> {
    let h = a.handle(i)?;
    sim.world.object(h)?;
    let p = sim.paths.get_mut(h).ok_or_else(|| not_a_path(h))?;
    Ok((h, p))
}

/// The world pose on path argument 0 at relative distance argument 1 (in [0, 1]).
fn world_pose_on_path(sim: &Sim, a: &Args<'_>) -> Result<Pose, SimError> {
    let (h, p) = path_of(sim, a, 0)?;
    let rel = a.finite(1)?.clamp(0.0, 1.0);
    let (pos, q) = p
        .pose_at(rel * p.length())
        .ok_or_else(|| SimError::bad_argument(format!("path {h} has no control points")))?;
    let local = Pose::from_parts(pos.into(), q);
    Ok(sim.world.object(h)?.world * local)
}

/// `sim.getPathLength(pathHandle)` → the path's length, m.
fn get_path_length(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(path_of(sim, a, 0)?.1.length())])
}

/// `sim.getPositionOnPath(pathHandle, relativeDistance)` → the world position at that
/// fraction (0 start, 1 end) of the path's length.
fn get_position_on_path(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = world_pose_on_path(sim, a)?.translation.vector;
    Ok(vec![Value::floats(&[p.x, p.y, p.z])])
}

/// `sim.getOrientationOnPath(pathHandle, relativeDistance)` → the world Euler angles
/// there.
fn get_orientation_on_path(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let q = world_pose_on_path(sim, a)?.rotation;
    Ok(vec![Value::floats(&euler_from_quat(&q))])
}

/// `sim.getPathPosition(pathHandle)` → the path position, m along the path.
fn get_path_position(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(path_of(sim, a, 0)?.1.position())])
}

/// `sim.setPathPosition(pathHandle, position)`: m along the path, kept on it (wrapped
/// round a closed path).
fn set_path_position(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let pos = a.finite(1)?;
    path_mut(sim, a, 0)?.1.set_position(pos);
    Ok(vec![Value::Int(1)])
}

/// `sim.setPathTargetNominalVelocity(pathHandle, velocity)`: kept (the path position
/// does not advance by itself in gantry).
fn set_path_target_nominal_velocity(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let v = a.finite(1)?;
    path_mut(sim, a, 0)?.1.target_velocity = v;
    Ok(vec![Value::Int(1)])
}

/// `sim.insertPathCtrlPoints(pathHandle, options, startIndex, ptCnt, ptData)` (V-REP 3):
/// control points before index `startIndex`, each `x, y, z, alpha, beta, gamma` in the
/// path's frame followed by maximum relative velocity, on-spot distance, Bezier point
/// count and two Bezier factors (11 values), then auxiliary flags and 4 auxiliary
/// channels when options bit 1 (2) is set (16 values); gantry keeps the pose and ignores
/// the rest. Options bit 0 (1): the path is closed (else open).
fn insert_path_ctrl_points(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let options = a.int(1)?;
    let start = size(a, 2, "startIndex", 0)?;
    let n = size(a, 3, "ptCnt", 0)?;
    let data = numbers(a, 4, "ptData")?;
    let stride = if options & 2 != 0 { 16 } else { 11 };
    if n > MAX_POINTS || data.len() < n * stride {
        return Err(SimError::bad_argument(format!(
            "argument 5 (ptData): {n} points need {} values ({stride} per point), got {}",
            n.saturating_mul(stride),
            data.len()
        )));
    }
    let pts: Vec<PathPoint> = data
        .chunks_exact(stride)
        .take(n)
        .map(|c| {
            let q = quat_to_array(&quat_from_euler([c[3], c[4], c[5]]));
            [c[0], c[1], c[2], q[0], q[1], q[2], q[3]]
        })
        .collect();
    let (h, p) = path_mut(sim, a, 0)?;
    p.insert_ctrl_points(start, pts)?;
    p.set_closed(options & 1 != 0);
    publish(sim, h);
    Ok(vec![Value::Int(1)])
}

/// `sim.cutPathCtrlPoints(pathHandle, startIndex, ptCnt)` (V-REP 3): removes `ptCnt`
/// control points from `startIndex` on; a negative index or count removes them all.
fn cut_path_ctrl_points(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (start, n) = (a.int(1)?, a.int(2)?);
    let (h, p) = path_mut(sim, a, 0)?;
    if start < 0 || n < 0 {
        p.cut_ctrl_points(0, usize::MAX);
    } else {
        p.cut_ctrl_points(
            usize::try_from(start).unwrap_or(usize::MAX),
            usize::try_from(n).unwrap_or(usize::MAX),
        );
    }
    publish(sim, h);
    Ok(vec![Value::Int(1)])
}
