//! Object lookup, hierarchy and poses.

use super::{Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::{self, Pose, Quat};
use crate::world::object_path::{ObjectTree, object_alias};
use crate::world::{Handle, World};

/// `sim.getObject(path, options={})` → handle. Options: `index`, `noError`.
pub(super) fn get_object(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let path = a.str(0)?;
    let opts = a.get(1);
    let index = match opts.get("index") {
        Some(v) => v
            .as_i64()
            .filter(|i| *i >= 0)
            .ok_or_else(|| SimError::bad_argument("options.index must be an integer >= 0"))?,
        None => 0,
    };
    let no_error = matches!(opts.get("noError"), Some(Value::Bool(true)));
    let emitter = match opts.get("proxy") {
        Some(v) => Some(
            v.as_i64()
                .ok_or_else(|| SimError::bad_argument("options.proxy must be a handle"))?,
        ),
        None => ctx.script_object,
    };
    match w.find(path, emitter, usize::try_from(index).unwrap_or(usize::MAX)) {
        Ok(h) => Ok(vec![Value::Int(h)]),
        Err(_) if no_error => Ok(vec![Value::Int(-1)]),
        Err(e) => Err(e),
    }
}

/// `sim.getObjectAlias(h, options=-1)` → string.
pub(super) fn get_object_alias(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.object(h)?;
    let option = a.opt_int(1, -1)?;
    Ok(vec![Value::Str(object_alias(w, h, option))])
}

/// `sim.getObjectParent(h)` → handle, or -1 for a root.
pub(super) fn get_object_parent(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    Ok(vec![Value::Int(w.parent(h)?.unwrap_or(-1))])
}

/// `sim.getObjectType(h)` → `sim.object_*_type`.
pub(super) fn get_object_type(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(w.object(a.handle(0)?)?.kind.type_code())])
}

/// `sim.getObjectsInTree(treeBase, objectType=sim.handle_all, options=0)` → handles.
///
/// `treeBase` may be `sim.handle_scene` for the whole scene. Options: bit 0 leaves out
/// the base itself, bit 1 returns only its direct children.
pub(super) fn get_objects_in_tree(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let base = a.handle(0)?;
    let filter = a.opt_int(1, -2)?;
    let options = a.opt_int(2, 0)?;
    let exclude_base = options & 1 != 0;
    let first_children = options & 2 != 0;
    // The objects to list: the base (unless excluded) and its descendants, or only its
    // direct children; for the scene, the roots play the children's part.
    let (base_itself, tops): (Option<Handle>, Vec<Handle>) = if base == -12 || base == -2 {
        (None, w.roots().to_vec())
    } else {
        w.object(base)?;
        ((!exclude_base).then_some(base), w.children(base).to_vec())
    };
    let mut listed: Vec<Handle> = base_itself.into_iter().collect();
    let mut stack: Vec<Handle> = tops.into_iter().rev().collect();
    while let Some(h) = stack.pop() {
        listed.push(h);
        if !first_children {
            stack.extend(w.children(h).iter().rev().copied());
        }
    }
    let out = listed
        .into_iter()
        .filter(|&h| filter == -2 || w.object(h).is_ok_and(|o| o.kind.type_code() == filter))
        .map(Value::Int)
        .collect();
    Ok(vec![Value::Array(out)])
}

/// Reads the optional `relativeTo` argument (default world).
fn rel(a: &Args<'_>, i: usize) -> Result<Handle, SimError> {
    a.opt_int(i, -1)
}

/// Splits a setter's arguments in either order: `(h, value, rel=-1)` (4.6) or the
/// legacy `(h, rel, value)` that 4.1–4.5 scripts and `simpleTest.py` use.
fn value_and_rel(a: &Args<'_>) -> Result<(usize, Handle), SimError> {
    if a.is_array(1) {
        Ok((1, rel(a, 2)?))
    } else {
        Ok((2, a.int(1)?))
    }
}

/// `sim.handleflag_reljointbaseframe`, OR-ed onto the object's handle of a pose
/// function: a joint given as the reference frame counts with its base frame, without
/// its own motion (CoppeliaSim's omni-wheel scripts reset their rollers this way).
pub(super) const HANDLEFLAG_REL_JOINT_BASE_FRAME: i64 = 0x0040_0000;

/// The object of a pose function (argument 1) and whether a joint reference frame
/// counts without its motion.
#[derive(Clone, Copy)]
struct Posed {
    object: Handle,
    joint_base: bool,
}

fn posed(a: &Args<'_>) -> Result<Posed, SimError> {
    let raw = a.handle(0)?;
    // Only a handle below the flag's bit with the flag added: any other number is a
    // handle, reported as it was given when it names nothing.
    let joint_base = (HANDLEFLAG_REL_JOINT_BASE_FRAME..2 * HANDLEFLAG_REL_JOINT_BASE_FRAME).contains(&raw);
    Ok(Posed {
        object: if joint_base {
            raw & !HANDLEFLAG_REL_JOINT_BASE_FRAME
        } else {
            raw
        },
        joint_base,
    })
}

/// The world pose of the frame `rel` the object's pose is given in.
fn frame_of(w: &World, o: Posed, rel: Handle) -> Result<Pose, SimError> {
    if o.joint_base && rel >= 0 {
        w.object(o.object)?;
        // An object's own world pose is a joint's base frame (its children hang from
        // the moved frame).
        return Ok(w.object(rel)?.world);
    }
    w.frame(o.object, rel)
}

fn pose_in(w: &World, o: Posed, rel: Handle) -> Result<Pose, SimError> {
    Ok(frame_of(w, o, rel)?.inverse() * w.object(o.object)?.world)
}

fn set_relative(w: &mut World, o: Posed, rel: Handle, local: Pose) -> Result<Ret, SimError> {
    let frame = frame_of(w, o, rel)?;
    w.set_world_pose(o.object, frame * local)?;
    Ok(Vec::new())
}

/// `sim.getObjectPosition(h, rel=-1)` → `[x, y, z]` in metres.
pub(super) fn get_object_position(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = pose_in(w, posed(a)?, rel(a, 1)?)?;
    Ok(vec![Value::floats(p.translation.vector.as_slice())])
}

/// `sim.setObjectPosition(h, [x, y, z], rel=-1)` (either argument order).
pub(super) fn set_object_position(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = posed(a)?;
    let (vi, r) = value_and_rel(a)?;
    let v = a.vec3(vi)?;
    let mut p = pose_in(w, h, r)?;
    p.translation.vector = v;
    set_relative(w, h, r, p)
}

/// `sim.getObjectOrientation(h, rel=-1)` → CoppeliaSim Euler angles `[a, b, g]`, rad.
pub(super) fn get_object_orientation(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = pose_in(w, posed(a)?, rel(a, 1)?)?;
    Ok(vec![Value::floats(&math::euler_from_quat(&p.rotation))])
}

/// `sim.setObjectOrientation(h, [a, b, g], rel=-1)` (either argument order).
pub(super) fn set_object_orientation(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = posed(a)?;
    let (vi, r) = value_and_rel(a)?;
    let e = a.floats::<3>(vi)?;
    let mut p = pose_in(w, h, r)?;
    p.rotation = math::quat_from_euler(e);
    set_relative(w, h, r, p)
}

/// `sim.getObjectQuaternion(h, rel=-1)` → `[qx, qy, qz, qw]`.
pub(super) fn get_object_quaternion(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = pose_in(w, posed(a)?, rel(a, 1)?)?;
    Ok(vec![Value::floats(&math::quat_to_array(&p.rotation))])
}

fn quat(a: &Args<'_>, i: usize) -> Result<Quat, SimError> {
    math::quat_from_array(a.floats::<4>(i)?)
        .ok_or_else(|| SimError::bad_argument(format!("argument {}: zero quaternion", i + 1)))
}

/// `sim.setObjectQuaternion(h, [qx, qy, qz, qw], rel=-1)` (either argument order).
pub(super) fn set_object_quaternion(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = posed(a)?;
    let (vi, r) = value_and_rel(a)?;
    let q = quat(a, vi)?;
    let mut p = pose_in(w, h, r)?;
    p.rotation = q;
    set_relative(w, h, r, p)
}

/// `sim.getObjectPose(h, rel=-1)` → `[x, y, z, qx, qy, qz, qw]`.
pub(super) fn get_object_pose(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = pose_in(w, posed(a)?, rel(a, 1)?)?;
    let t = p.translation.vector;
    let q = math::quat_to_array(&p.rotation);
    Ok(vec![Value::floats(&[t.x, t.y, t.z, q[0], q[1], q[2], q[3]])])
}

/// `sim.setObjectPose(h, [x, y, z, qx, qy, qz, qw], rel=-1)` (either argument order).
pub(super) fn set_object_pose(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = posed(a)?;
    let (vi, r) = value_and_rel(a)?;
    let v = a.floats::<7>(vi)?;
    let q = math::quat_from_array([v[3], v[4], v[5], v[6]])
        .ok_or_else(|| SimError::bad_argument("zero quaternion in pose"))?;
    let local = Pose::from_parts(nalgebra::Translation3::new(v[0], v[1], v[2]), q);
    set_relative(w, h, r, local)
}

/// `sim.getObjectMatrix(h, rel=-1)` → 12 numbers, row-major 3x4 (translation at 4, 8, 12).
pub(super) fn get_object_matrix(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = pose_in(w, posed(a)?, rel(a, 1)?)?;
    Ok(vec![Value::floats(&math::pose_to_matrix12(&p))])
}

/// `sim.setObjectMatrix(h, m[12], rel=-1)` (either argument order).
pub(super) fn set_object_matrix(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = posed(a)?;
    let (vi, r) = value_and_rel(a)?;
    let m = a.floats::<12>(vi)?;
    let local = math::pose_from_matrix12(&m).ok_or_else(|| SimError::bad_argument("matrix must be finite"))?;
    set_relative(w, h, r, local)
}

/// `sim.getObjectVelocity(h)` → `[vx, vy, vz]` m/s, `[wx, wy, wz]` rad/s, world frame.
pub(super) fn get_object_velocity(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (v, om) = w.velocity(a.handle(0)?)?;
    Ok(vec![Value::floats(v.as_slice()), Value::floats(om.as_slice())])
}
