//! `simIK.*` functions on objects: the dummies and joints a script builds in an
//! environment (`createDummy`, `createJoint`, `setObjectParent`, ...; CoppeliaSim 4.2-4.5
//! scripts build their IK world this way), and the same reads and writes on scene objects.
//!
//! Which tree an object belongs to follows from its handle (see [`crate::ik`]): the
//! environment's own objects are numbered from [`crate::ik::FIRST_OBJECT`], scene objects are
//! the scene's handles. On an own object a function acts on the environment's tree. On a
//! scene object it reads or writes the scene itself, since elements made from the scene
//! use the scene as their IK world; what would reshape the scene's tree (parenting,
//! erasing, joint modes and intervals) is refused with the `sim.*` function to use
//! instead. A reference frame (`relativeTo`) must belong to the same tree as the object.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret, joints, objects};
use crate::Value;
use crate::error::SimError;
use crate::ik::{HANDLE_PARENT, HANDLE_WORLD, IkJointMode, IkObjects, is_own_object};
use crate::math::{self, Pose};
use crate::scene::JointType;
use crate::sim::Sim;
use crate::world::{Handle, ObjectKind};

/// The functions this file implements, in alphabetical order.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "createDummy",
        call: ApiFn::Sim(create_dummy),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "createJoint",
        call: ApiFn::Sim(create_joint),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "doesObjectExist",
        call: ApiFn::Sim(does_object_exist),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "eraseObject",
        call: ApiFn::Sim(erase_object),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getJointInterval",
        call: ApiFn::Sim(get_joint_interval),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getJointMode",
        call: ApiFn::Sim(get_joint_mode),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getJointPosition",
        call: ApiFn::Sim(get_joint_position),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getJointType",
        call: ApiFn::Sim(get_joint_type),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getObjectHandle",
        call: ApiFn::Sim(get_object_handle),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getObjectMatrix",
        call: ApiFn::Sim(get_object_matrix),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getObjectParent",
        call: ApiFn::Sim(get_object_parent),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getObjectPose",
        call: ApiFn::Sim(get_object_pose),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getObjectType",
        call: ApiFn::Sim(get_object_type),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getTargetDummy",
        call: ApiFn::Sim(get_target_dummy),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setJointInterval",
        call: ApiFn::Sim(set_joint_interval),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setJointMode",
        call: ApiFn::Sim(set_joint_mode),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setJointPosition",
        call: ApiFn::Sim(set_joint_position),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setObjectMatrix",
        call: ApiFn::Sim(set_object_matrix),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setObjectParent",
        call: ApiFn::Sim(set_object_parent),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setObjectPose",
        call: ApiFn::Sim(set_object_pose),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "setTargetDummy",
        call: ApiFn::Sim(set_target_dummy),
        cost: Cost::Long,
    },
];

/// The constants of objects, with CoppeliaSim's values.
pub(super) const CONSTANTS: &[(&str, i64)] = &[
    ("jointtype_revolute", 10),
    ("jointtype_prismatic", 11),
    ("jointtype_spherical", 12),
    ("jointmode_passive", 0),
    ("jointmode_ik", 2),
    ("objecttype_joint", 1),
    ("objecttype_dummy", 4),
    ("handle_parent", HANDLE_PARENT),
];

/// The environment named by argument 0, its own objects.
fn own<'s>(sim: &'s mut Sim, a: &Args<'_>) -> Result<&'s mut IkObjects, SimError> {
    Ok(&mut sim.ik.get_mut(a.handle(0)?)?.objects)
}

/// Refuses a scene object where only the environment's own objects make sense.
fn own_only(h: Handle, instead: &str) -> Result<(), SimError> {
    if is_own_object(h) {
        Ok(())
    } else {
        Err(SimError::bad_argument(format!(
            "object {h} is a scene object, not one of the IK environment's (create those with \
             simIK.createDummy or simIK.createJoint); for the scene, use {instead}"
        )))
    }
}

/// An optional name argument (`nil` or absent: none).
fn name_arg<'a>(a: &Args<'a>, i: usize) -> Result<&'a str, SimError> {
    match a.get(i) {
        Value::Nil => Ok(""),
        _ => a.str(i),
    }
}

/// `simIK.createDummy(env, name='')` → handle: a dummy of the environment at the world
/// origin, with no parent.
fn create_dummy(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = name_arg(a, 1)?;
    Ok(vec![Value::Int(own(sim, a)?.create_dummy(name)?)])
}

/// `simIK.createJoint(env, jointType, name='')` → handle: a revolute (10) or prismatic
/// (11) joint of the environment at the world origin, in IK mode at position 0; a
/// revolute joint is cyclic, a prismatic one limited to [-0.5, 0.5] m, as in CoppeliaSim.
fn create_joint(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let code = a.int(1)?;
    let joint_type = match code {
        10 => JointType::Revolute,
        11 => JointType::Prismatic,
        12 => {
            return Err(SimError::bad_argument(
                "argument 2: spherical joints are not supported by gantry's IK (use three revolute joints)",
            ));
        }
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 2: unknown joint type {other} (use simIK.jointtype_revolute or simIK.jointtype_prismatic)"
            )));
        }
    };
    let name = name_arg(a, 2)?;
    Ok(vec![Value::Int(own(sim, a)?.create_joint(joint_type, name)?)])
}

/// `simIK.getObjectHandle(env, name)` → the handle of the environment's object named so.
fn get_object_handle(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(1)?;
    own(sim, a)?
        .by_name(name)
        .filter(|_| !name.is_empty())
        .map(|h| vec![Value::Int(h)])
        .ok_or_else(|| SimError::no_such_item(format!("no IK object named '{name}' in this environment")))
}

/// `simIK.doesObjectExist(env, name)` → whether the environment has an object named so.
fn does_object_exist(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let name = a.str(1)?;
    let found = !name.is_empty() && own(sim, a)?.by_name(name).is_some();
    Ok(vec![Value::Bool(found)])
}

/// `simIK.eraseObject(env, object)`: removes one of the environment's objects. Its
/// children keep their world pose and hang from its parent; elements tipped at it (or
/// targeting it) are removed, elements based on it are based on the world.
fn erase_object(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    own_only(h, "sim.removeObjects")?;
    sim.ik.get_mut(a.handle(0)?)?.erase_object(h)?;
    Ok(Vec::new())
}

/// `simIK.getObjectParent(env, object)` → parent handle, -1 at the root.
fn get_object_parent(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    let parent = if is_own_object(h) {
        own(sim, a)?.parent(h)?
    } else {
        sim.ik.get(a.handle(0)?)?;
        sim.world.parent(h)?
    };
    Ok(vec![Value::Int(parent.unwrap_or(HANDLE_WORLD))])
}

/// `simIK.setObjectParent(env, object, parent, keepInPlace=true)`: hangs one of the
/// environment's objects below another (`parent` -1: at the root). With `keepInPlace`
/// it keeps its world pose, otherwise its pose relative to the parent.
fn set_object_parent(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    own_only(h, "sim.setObjectParent")?;
    let parent = a.handle(2)?;
    let parent = match parent {
        HANDLE_WORLD => None,
        p if is_own_object(p) => Some(p),
        p => {
            return Err(SimError::bad_argument(format!(
                "argument 3: object {p} is a scene object; an IK environment's object can only hang \
                 below another of its objects (or -1)"
            )));
        }
    };
    let keep = a.opt_bool(3, true)?;
    own(sim, a)?.set_parent(h, parent, keep)?;
    Ok(Vec::new())
}

/// `simIK.getObjectType(env, object)` → `simIK.objecttype_joint` (1) or
/// `objecttype_dummy` (4); for a scene object, its `sim.object_*_type`.
fn get_object_type(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    if is_own_object(h) {
        return Ok(vec![Value::Int(own(sim, a)?.get(h)?.type_code())]);
    }
    sim.ik.get(a.handle(0)?)?;
    objects::get_object_type(&mut sim.world, ctx, &Args::new(&[Value::Int(h)]))
}

/// `simIK.setTargetDummy(env, tip, target)` (4.2: `setLinkedDummy(env, dummy,
/// linkedDummy)`): links two of the environment's dummies (-1 unlinks); an element
/// added with `simIK.addElement` drives its tip onto the dummy linked to it.
fn set_target_dummy(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let d = a.handle(1)?;
    own_only(d, "sim.setLinkDummy")?;
    let to = match a.handle(2)? {
        HANDLE_WORLD => None,
        t => {
            own_only(t, "sim.setLinkDummy").map_err(|e| e.prefixed("argument 3: "))?;
            Some(t)
        }
    };
    own(sim, a)?.set_linked(d, to)?;
    Ok(Vec::new())
}

/// `simIK.getTargetDummy(env, dummy)` (4.2: `getLinkedDummy`) → the linked dummy, -1
/// when none; for a scene dummy, its `sim.setLinkDummy` partner.
fn get_target_dummy(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let d = a.handle(1)?;
    let linked = if is_own_object(d) {
        own(sim, a)?.linked(d)?
    } else {
        sim.ik.get(a.handle(0)?)?;
        sim.world.object(d)?;
        sim.world.linked_dummy(d)
    };
    Ok(vec![Value::Int(linked.unwrap_or(HANDLE_WORLD))])
}

/// `simIK.getJointPosition(env, joint)` → rad or m: an own joint's value; for a scene
/// joint, a pending solution (`handleGroup{syncWorlds=false}`) if there is one, else the
/// scene's value.
fn get_joint_position(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, joint) = (a.handle(0)?, a.handle(1)?);
    if is_own_object(joint) {
        return Ok(vec![Value::Float(own(sim, a)?.joint(joint)?.position)]);
    }
    let pending = sim.ik.get(env)?.pending.get(&joint).copied();
    let q = match pending {
        Some(q) => q,
        None => sim.world.joint(joint)?.position,
    };
    Ok(vec![Value::Float(q)])
}

/// `simIK.setJointPosition(env, joint, position)`: rad or m, wrapped (cyclic) or clamped
/// to the joint's interval. A scene joint is set in the scene (as `sim.setJointPosition`)
/// and any solution pending for it is forgotten.
fn set_joint_position(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (env, joint) = (a.handle(0)?, a.handle(1)?);
    if is_own_object(joint) {
        let q = a.finite(2)?;
        own(sim, a)?.set_joint_position(joint, q)?;
        return Ok(Vec::new());
    }
    sim.ik.get(env)?;
    let rest = without_environment(a);
    let out = joints::set_joint_position(&mut sim.world, ctx, &Args::new(&rest))?;
    sim.ik.get_mut(env)?.pending.remove(&joint);
    Ok(out)
}

/// `simIK.getJointMode(env, joint)` → `simIK.jointmode_passive` (0) or `jointmode_ik`
/// (2). Every revolute or prismatic scene joint of a scene chain is solved for, so scene
/// joints report IK mode (fixed ones passive).
fn get_joint_mode(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    let mode = if is_own_object(h) {
        own(sim, a)?.joint(h)?.mode
    } else {
        sim.ik.get(a.handle(0)?)?;
        match sim.world.joint(h)?.joint_type {
            JointType::Fixed => IkJointMode::Passive,
            _ => IkJointMode::Ik,
        }
    };
    Ok(vec![Value::Int(mode.code())])
}

/// `simIK.setJointMode(env, joint, mode)`: `simIK.jointmode_ik` (the solver moves the
/// joint) or `jointmode_passive` (it stays at its position, a rigid part of the chain).
fn set_joint_mode(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    own_only(
        h,
        "a fixed joint in the scene file to keep a scene joint out of a chain",
    )?;
    let code = a.int(2)?;
    let mode = IkJointMode::from_code(code).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument 3: unsupported joint mode {code} (use simIK.jointmode_ik or simIK.jointmode_passive; \
             gantry has no dependent joints in IK)"
        ))
    })?;
    own(sim, a)?.set_joint_mode(h, mode)?;
    Ok(Vec::new())
}

/// `simIK.getJointInterval(env, joint)` → cyclic, {min, range} (rad or m).
fn get_joint_interval(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    if is_own_object(h) {
        let j = own(sim, a)?.joint(h)?;
        return Ok(vec![Value::Bool(j.cyclic), Value::floats(&[j.min, j.range])]);
    }
    sim.ik.get(a.handle(0)?)?;
    joints::get_joint_interval(&mut sim.world, ctx, &Args::new(&[Value::Int(h)]))
}

/// `simIK.setJointInterval(env, joint, cyclic, {min, range}={})`: a cyclic revolute
/// joint wraps into (-pi, pi] (the interval is then ignored, as in CoppeliaSim); otherwise
/// the joint is limited to [min, min + range]. The range may not be negative. The
/// position is brought into the new interval.
fn set_joint_interval(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    own_only(h, "the limits in the scene file")?;
    let cyclic = a.bool(2)?;
    let (min, range) = if cyclic && matches!(a.get(3), Value::Nil) {
        (-std::f64::consts::PI, 2.0 * std::f64::consts::PI)
    } else {
        let [min, range] = a.floats::<2>(3)?;
        (min, range)
    };
    own(sim, a)?.set_joint_interval(h, cyclic, min, range)?;
    Ok(Vec::new())
}

/// `simIK.getJointType(env, joint)` → `simIK.jointtype_revolute` (10) or
/// `jointtype_prismatic` (11) (a fixed scene joint: `sim.joint_fixed_subtype`).
fn get_joint_type(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    if is_own_object(h) {
        let code = match own(sim, a)?.joint(h)?.joint_type {
            JointType::Prismatic => 11,
            _ => 10,
        };
        return Ok(vec![Value::Int(code)]);
    }
    sim.ik.get(a.handle(0)?)?;
    joints::get_joint_type(&mut sim.world, ctx, &Args::new(&[Value::Int(h)]))
}

/// The arguments after the environment handle, for the `sim.*` function of the same shape.
fn without_environment(a: &Args<'_>) -> Vec<Value> {
    (1..a.len()).map(|i| a.get(i).clone()).collect()
}

/// Checks that frame `rel` belongs to the same tree as object `h`.
fn same_tree(h: Handle, rel: Handle, arg: usize) -> Result<(), SimError> {
    if rel == HANDLE_WORLD || rel == HANDLE_PARENT || is_own_object(rel) == is_own_object(h) {
        return Ok(());
    }
    let (what, other) = if is_own_object(h) {
        ("the IK environment's", "a scene object")
    } else {
        ("a scene", "an IK environment's object")
    };
    Err(SimError::bad_argument(format!(
        "argument {arg}: object {h} is {what} object and frame {rel} is {other}: \
         poses are relative to -1, sim.handle_parent or an object of the same tree"
    )))
}

/// For setters taking `(env, object, relativeTo, value)` (4.2-4.4) or `(env, object,
/// value, relativeTo=-1)` (4.5+): the index of the value and the reference frame.
fn value_and_rel(a: &Args<'_>) -> Result<(usize, Handle), SimError> {
    if a.is_array(2) {
        Ok((2, a.opt_int(3, HANDLE_WORLD)?))
    } else {
        Ok((3, a.int(2)?))
    }
}

/// The pose of own object `h` in frame `rel`.
fn own_pose(sim: &mut Sim, a: &Args<'_>, h: Handle, rel: Handle) -> Result<Pose, SimError> {
    Ok(own(sim, a)?.pose_relative(h, rel)?)
}

/// `simIK.getObjectMatrix(env, object, relativeTo=-1)` → 12 numbers, row-major 3x4 (m),
/// as `sim.getObjectMatrix` (a joint's frame without its motion; relative to a joint:
/// its moving frame). For a scene object, the scene object's pose; a solution held back
/// by `handleGroup{syncWorlds=false}` is not reflected.
fn get_object_matrix(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    let rel = a.opt_int(2, HANDLE_WORLD)?;
    same_tree(h, rel, 3)?;
    if is_own_object(h) {
        let p = own_pose(sim, a, h, rel)?;
        return Ok(vec![Value::floats(&math::pose_to_matrix12(&p))]);
    }
    sim.ik.get(a.handle(0)?)?;
    objects::get_object_matrix(&mut sim.world, ctx, &Args::new(&without_environment(a)))
}

/// `simIK.setObjectMatrix(env, object, relativeTo, matrix)` (4.2-4.4 order) or `(env,
/// object, matrix, relativeTo=-1)`: places the object so that its pose in the frame is
/// the matrix; its children move with it. Scripts use it to copy a target's pose into
/// the IK world. A scene object is moved in the scene (elements made from the scene use
/// it as their IK world); scene joints are refused, since moving one would reshape the
/// robot in the scene, not just in an IK copy.
fn set_object_matrix(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    let (vi, rel) = value_and_rel(a)?;
    same_tree(h, rel, if vi == 2 { 4 } else { 3 })?;
    let m = a.floats::<12>(vi)?;
    if is_own_object(h) {
        let pose = math::pose_from_matrix12(&m)
            .ok_or_else(|| SimError::bad_argument(format!("argument {}: matrix must be finite", vi + 1)))?;
        own(sim, a)?.set_pose_relative(h, rel, pose)?;
        return Ok(Vec::new());
    }
    sim.ik.get(a.handle(0)?)?;
    refuse_scene_joint(sim, h)?;
    objects::set_object_matrix(&mut sim.world, ctx, &Args::new(&without_environment(a)))
}

/// `simIK.getObjectPose(env, object, relativeTo=-1)` → {x, y, z, qx, qy, qz, qw}, as
/// [`get_object_matrix`] in pose form.
fn get_object_pose(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    let rel = a.opt_int(2, HANDLE_WORLD)?;
    same_tree(h, rel, 3)?;
    if is_own_object(h) {
        let p = own_pose(sim, a, h, rel)?;
        let t = p.translation.vector;
        let q = math::quat_to_array(&p.rotation);
        return Ok(vec![Value::floats(&[t.x, t.y, t.z, q[0], q[1], q[2], q[3]])]);
    }
    sim.ik.get(a.handle(0)?)?;
    objects::get_object_pose(&mut sim.world, ctx, &Args::new(&without_environment(a)))
}

/// `simIK.setObjectPose(env, object, relativeTo, pose)` (4.3-4.4 order) or `(env, object,
/// pose, relativeTo=-1)`: as [`set_object_matrix`] with a pose {x, y, z, qx, qy, qz, qw}.
fn set_object_pose(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(1)?;
    let (vi, rel) = value_and_rel(a)?;
    same_tree(h, rel, if vi == 2 { 4 } else { 3 })?;
    let v = a.floats::<7>(vi)?;
    if is_own_object(h) {
        let q = math::quat_from_array([v[3], v[4], v[5], v[6]])
            .ok_or_else(|| SimError::bad_argument(format!("argument {}: zero quaternion in pose", vi + 1)))?;
        let pose = Pose::from_parts(nalgebra::Translation3::new(v[0], v[1], v[2]), q);
        own(sim, a)?.set_pose_relative(h, rel, pose)?;
        return Ok(Vec::new());
    }
    sim.ik.get(a.handle(0)?)?;
    refuse_scene_joint(sim, h)?;
    objects::set_object_pose(&mut sim.world, ctx, &Args::new(&without_environment(a)))
}

/// Refuses to move a scene joint through `simIK`.
fn refuse_scene_joint(sim: &Sim, h: Handle) -> Result<(), SimError> {
    if matches!(sim.world.object(h)?.kind, ObjectKind::Joint(_)) {
        return Err(SimError::refused(format!(
            "object {h} is a scene joint: moving it would reshape the robot in the scene. Set its value \
             with simIK.setJointPosition, or build the chain from the IK environment's own objects \
             (simIK.createJoint)"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ik;

    #[test]
    fn setters_accept_both_argument_orders() {
        let old = [
            Value::Int(1),
            Value::Int(ik::FIRST_OBJECT),
            Value::Int(-1),
            Value::floats(&[0.0; 12]),
        ];
        let new = [Value::Int(1), Value::Int(ik::FIRST_OBJECT), Value::floats(&[0.0; 12])];
        assert_eq!(value_and_rel(&Args::new(&old)).expect("old"), (3, -1));
        assert_eq!(value_and_rel(&Args::new(&new)).expect("new"), (2, -1));
        let d = ik::FIRST_OBJECT;
        assert!(same_tree(d, 3, 3).is_err());
        assert!(same_tree(3, d, 3).is_err());
        assert!(same_tree(d, HANDLE_PARENT, 3).is_ok());
    }
}
