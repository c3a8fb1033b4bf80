//! Numbered parameters: of objects (`sim.getObjectInt32Param`, `sim.setObjectFloatParam`,
//! ...) and of the simulation (`sim.getInt32Param`, `sim.setArrayParam`, ...).
//!
//! CoppeliaSim's rules, kept here: an object parameter that does not apply (an unknown
//! id, or a shape parameter asked of a joint) is "not retrieved", which is no error: the
//! getter returns nothing (`nil`) and the setter does nothing. A simulation parameter
//! gantry does not have, or cannot set, is an error. A handle that names no object is
//! always an error.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::scene::{JointMode, LightModel, Projection, ProximityModel, RenderMode};
use crate::sim::Sim;
use crate::world::{ObjectKind, World};

/// CoppeliaSim version gantry's API follows (4.6.0), as `sim.intparam_program_version`
/// encodes it: major·10000 + minor·100 + patch.
pub const PROGRAM_VERSION: i64 = 40600;

// Object parameter ids (CoppeliaSim's `sim.*param_*` numbers).
const OBJ_VISIBILITY_LAYER: i64 = 10;
const OBJ_ABS_X_VELOCITY: i64 = 11;
const OBJ_ABS_ROT_VELOCITY: i64 = 14;
const OBJ_BBOX_MIN_X: i64 = 15;
const OBJ_BBOX_MAX_Z: i64 = 20;
const OBJ_MODEL_BBOX_MIN_X: i64 = 21;
const OBJ_MODEL_BBOX_MAX_Z: i64 = 26;
const OBJ_STRING_UNIQUE_ID: i64 = 35;
const VISION_NEAR: i64 = 1000;
const VISION_FAR: i64 = 1001;
const VISION_RES_X: i64 = 1002;
const VISION_RES_Y: i64 = 1003;
const VISION_ANGLE: i64 = 1004;
const VISION_ORTHO_SIZE: i64 = 1005;
/// The object or collection a vision sensor renders; -1 = everything.
const VISION_ENTITY_TO_RENDER: i64 = 1008;
/// The window a sensor renders in with a windowed render mode (gantry renders
/// off-screen: kept to read back).
const VISION_WINDOWED_SIZE_X: i64 = 1009;
const VISION_WINDOWED_SIZE_Y: i64 = 1010;
const VISION_RENDER_MODE: i64 = 1017;
const VISION_PERSPECTIVE: i64 = 1018;
const VISION_RGB_IGNORED: i64 = 1020;
const VISION_DEPTH_IGNORED: i64 = 1021;
/// `sim.rendermode_opengl`: the shapes' colours.
const RENDERMODE_OPENGL: i64 = 0;
/// `sim.rendermode_opengl3` and its windowed twin: the same visible image from
/// CoppeliaSim's newer renderer (gantry has one renderer; the choice reads back).
const RENDERMODE_OPENGL3: i64 = 6;
const RENDERMODE_OPENGL3_WINDOWED: i64 = 7;
/// `sim.rendermode_colorcoded`: each pixel the handle of the shape seen.
const RENDERMODE_COLORCODED: i64 = 2;
const JOINT_MOTOR_ENABLED: i64 = 2000;
const JOINT_CTRL_ENABLED: i64 = 2001;
const JOINT_PID_P: i64 = 2002;
const JOINT_PID_I: i64 = 2003;
const JOINT_PID_D: i64 = 2004;
const JOINT_VELOCITY: i64 = 2012;
const JOINT_UPPER_LIMIT: i64 = 2017;
const JOINT_MAXVEL: i64 = 2036;
const JOINT_VELOCITY_LOCK: i64 = 2030;
const JOINT_DYNCTRLMODE: i64 = 2039;
const SHAPE_STATIC: i64 = 3003;
const SHAPE_RESPONDABLE: i64 = 3004;
const SHAPE_MASS: i64 = 3005;
const PROX_VOLUME_TYPE: i64 = 4001;
const LIGHT_POV_CASTS_SHADOWS: i64 = 8000;
const LIGHT_SPOT_EXPONENT: i64 = 8001;
const LIGHT_SPOT_CUTOFF: i64 = 8002;
const LIGHT_CONST_ATTENUATION: i64 = 8003;
const LIGHT_QUAD_ATTENUATION: i64 = 8005;

// `sim.jointdynctrl_*`.
const DYNCTRL_FREE: i64 = 0;
const DYNCTRL_FORCE: i64 = 1;
const DYNCTRL_VELOCITY: i64 = 4;
const DYNCTRL_POSITION: i64 = 8;

// Simulation parameter ids.
const INT_PROGRAM_VERSION: i64 = 1;
const INT_DYNAMIC_STEP_DIVIDER: i64 = 7;
const INT_PLATFORM: i64 = 19;
const INT_PROGRAM_REVISION: i64 = 30;
const INT_PROGRAM_FULL_VERSION: i64 = 39;
const INT_OBJECT_CREATION_COUNTER: i64 = 48;
const INT_OBJECT_DESTRUCTION_COUNTER: i64 = 49;
const INT_HIERARCHY_CHANGE_COUNTER: i64 = 50;
const FLOAT_RAND: i64 = 0;
const FLOAT_SIMULATION_TIME_STEP: i64 = 1;
const FLOAT_DYNAMIC_STEP_SIZE: i64 = 3;
const FLOAT_PHYSICS_TIME_STEP: i64 = 5;
const BOOL_DYNAMICS_HANDLING: i64 = 6;
const BOOL_PROXIMITY_SENSOR_HANDLING: i64 = 9;
const BOOL_VISION_SENSOR_HANDLING: i64 = 10;
const BOOL_REALTIME_SIMULATION: i64 = 25;
const BOOL_HEADLESS: i64 = 34;
const ARRAY_GRAVITY: i64 = 0;
const STRING_APPLICATION_PATH: i64 = 0;
const STRING_SCENE_PATH_AND_NAME: i64 = 13;
const STRING_SCENE_PATH: i64 = 14;
const STRING_SCENE_NAME: i64 = 15;
const STRING_TEMP_DIR: i64 = 127;
const STRING_SCENE_DEFAULT_DIR: i64 = 132;
const STRING_MODEL_DEFAULT_DIR: i64 = 133;

/// The parameter constants, with CoppeliaSim 4.6's values.
pub const CONSTANTS: &[(&str, i64)] = &[
    ("intparam_program_version", INT_PROGRAM_VERSION),
    ("intparam_dynamic_step_divider", INT_DYNAMIC_STEP_DIVIDER),
    ("intparam_platform", INT_PLATFORM),
    ("intparam_program_revision", INT_PROGRAM_REVISION),
    ("intparam_program_full_version", INT_PROGRAM_FULL_VERSION),
    ("intparam_objectcreationcounter", INT_OBJECT_CREATION_COUNTER),
    ("intparam_objectdestructioncounter", INT_OBJECT_DESTRUCTION_COUNTER),
    ("intparam_hierarchychangecounter", INT_HIERARCHY_CHANGE_COUNTER),
    ("floatparam_rand", FLOAT_RAND),
    ("floatparam_simulation_time_step", FLOAT_SIMULATION_TIME_STEP),
    ("floatparam_dynamic_step_size", FLOAT_DYNAMIC_STEP_SIZE),
    ("floatparam_physicstimestep", FLOAT_PHYSICS_TIME_STEP),
    ("boolparam_dynamics_handling_enabled", BOOL_DYNAMICS_HANDLING),
    (
        "boolparam_proximity_sensor_handling_enabled",
        BOOL_PROXIMITY_SENSOR_HANDLING,
    ),
    ("boolparam_vision_sensor_handling_enabled", BOOL_VISION_SENSOR_HANDLING),
    ("boolparam_realtime_simulation", BOOL_REALTIME_SIMULATION),
    ("boolparam_headless", BOOL_HEADLESS),
    ("arrayparam_gravity", ARRAY_GRAVITY),
    ("stringparam_application_path", STRING_APPLICATION_PATH),
    ("stringparam_scene_path_and_name", STRING_SCENE_PATH_AND_NAME),
    ("stringparam_scene_path", STRING_SCENE_PATH),
    ("stringparam_scene_name", STRING_SCENE_NAME),
    ("stringparam_tempdir", STRING_TEMP_DIR),
    ("stringparam_scenedefaultdir", STRING_SCENE_DEFAULT_DIR),
    ("stringparam_modeldefaultdir", STRING_MODEL_DEFAULT_DIR),
    ("objintparam_visibility_layer", OBJ_VISIBILITY_LAYER),
    ("objfloatparam_abs_x_velocity", OBJ_ABS_X_VELOCITY),
    ("objfloatparam_abs_y_velocity", OBJ_ABS_X_VELOCITY + 1),
    ("objfloatparam_abs_z_velocity", OBJ_ABS_X_VELOCITY + 2),
    ("objfloatparam_abs_rot_velocity", OBJ_ABS_ROT_VELOCITY),
    ("objfloatparam_objbbox_min_x", OBJ_BBOX_MIN_X),
    ("objfloatparam_objbbox_min_y", OBJ_BBOX_MIN_X + 1),
    ("objfloatparam_objbbox_min_z", OBJ_BBOX_MIN_X + 2),
    ("objfloatparam_objbbox_max_x", OBJ_BBOX_MIN_X + 3),
    ("objfloatparam_objbbox_max_y", OBJ_BBOX_MIN_X + 4),
    ("objfloatparam_objbbox_max_z", OBJ_BBOX_MAX_Z),
    ("objstringparam_unique_id", OBJ_STRING_UNIQUE_ID),
    ("objfloatparam_modelbbox_min_x", OBJ_MODEL_BBOX_MIN_X),
    ("objfloatparam_modelbbox_min_y", OBJ_MODEL_BBOX_MIN_X + 1),
    ("objfloatparam_modelbbox_min_z", OBJ_MODEL_BBOX_MIN_X + 2),
    ("objfloatparam_modelbbox_max_x", OBJ_MODEL_BBOX_MIN_X + 3),
    ("objfloatparam_modelbbox_max_y", OBJ_MODEL_BBOX_MIN_X + 4),
    ("objfloatparam_modelbbox_max_z", OBJ_MODEL_BBOX_MAX_Z),
    ("visionfloatparam_near_clipping", VISION_NEAR),
    ("visionfloatparam_far_clipping", VISION_FAR),
    ("visionintparam_resolution_x", VISION_RES_X),
    ("visionintparam_resolution_y", VISION_RES_Y),
    ("visionfloatparam_perspective_angle", VISION_ANGLE),
    ("visionfloatparam_ortho_size", VISION_ORTHO_SIZE),
    ("visionintparam_perspective_operation", VISION_PERSPECTIVE),
    ("visionintparam_render_mode", VISION_RENDER_MODE),
    ("visionintparam_rgbignored", VISION_RGB_IGNORED),
    ("visionintparam_depthignored", VISION_DEPTH_IGNORED),
    ("lightintparam_pov_casts_shadows", LIGHT_POV_CASTS_SHADOWS),
    ("lightfloatparam_spot_exponent", LIGHT_SPOT_EXPONENT),
    ("lightfloatparam_spot_cutoff", LIGHT_SPOT_CUTOFF),
    ("lightfloatparam_const_attenuation", LIGHT_CONST_ATTENUATION),
    ("lightfloatparam_lin_attenuation", LIGHT_CONST_ATTENUATION + 1),
    ("lightfloatparam_quad_attenuation", LIGHT_QUAD_ATTENUATION),
    ("rendermode_opengl", RENDERMODE_OPENGL),
    ("rendermode_colorcoded", RENDERMODE_COLORCODED),
    ("rendermode_opengl3", RENDERMODE_OPENGL3),
    ("rendermode_opengl3windowed", RENDERMODE_OPENGL3_WINDOWED),
    ("visionintparam_entity_to_render", VISION_ENTITY_TO_RENDER),
    ("visionintparam_windowed_size_x", VISION_WINDOWED_SIZE_X),
    ("visionintparam_windowed_size_y", VISION_WINDOWED_SIZE_Y),
    ("jointintparam_motor_enabled", JOINT_MOTOR_ENABLED),
    ("jointintparam_ctrl_enabled", JOINT_CTRL_ENABLED),
    ("jointintparam_velocity_lock", JOINT_VELOCITY_LOCK),
    ("jointfloatparam_pid_p", JOINT_PID_P),
    ("jointfloatparam_pid_i", JOINT_PID_I),
    ("jointfloatparam_pid_d", JOINT_PID_D),
    ("jointfloatparam_velocity", JOINT_VELOCITY),
    ("jointfloatparam_upper_limit", JOINT_UPPER_LIMIT),
    ("jointfloatparam_maxvel", JOINT_MAXVEL),
    ("jointintparam_dynctrlmode", JOINT_DYNCTRLMODE),
    ("jointdynctrl_free", DYNCTRL_FREE),
    ("jointdynctrl_force", DYNCTRL_FORCE),
    ("jointdynctrl_velocity", DYNCTRL_VELOCITY),
    ("jointdynctrl_position", DYNCTRL_POSITION),
    ("jointdynctrl_spring", 12),
    ("jointdynctrl_callback", 16),
    ("shapeintparam_static", SHAPE_STATIC),
    ("shapeintparam_respondable", SHAPE_RESPONDABLE),
    ("shapefloatparam_mass", SHAPE_MASS),
    ("proxintparam_volume_type", PROX_VOLUME_TYPE),
    ("volume_pyramid", 0),
    ("volume_cylinder", 1),
    ("volume_disc", 2),
    ("volume_cone", 3),
    ("volume_ray", 4),
];

/// The functions of this file, sorted by name.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getArrayParam",
        call: ApiFn::World(get_array_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getBoolParam",
        call: ApiFn::World(get_bool_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getFloatParam",
        call: ApiFn::World(get_float_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getInt32Param",
        call: ApiFn::World(get_int32_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectFloatParam",
        call: ApiFn::World(get_object_float_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectInt32Param",
        call: ApiFn::World(get_object_int32_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectStringParam",
        call: ApiFn::World(get_object_string_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectUid",
        call: ApiFn::World(get_object_uid),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getStringParam",
        call: ApiFn::World(get_string_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setArrayParam",
        call: ApiFn::World(set_array_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setBoolParam",
        call: ApiFn::World(set_bool_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setFloatParam",
        call: ApiFn::Sim(set_float_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setInt32Param",
        call: ApiFn::World(set_int32_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectFloatParam",
        call: ApiFn::World(set_object_float_param),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectInt32Param",
        call: ApiFn::World(set_object_int32_param),
        cost: Cost::Quick,
    },
];

/// The largest window side `sim.visionintparam_windowed_size_x`/`_y` accept, pixels.
const MAX_WINDOW_SIDE: i64 = 16384;

/// A parameter value, or nothing when the parameter does not apply.
fn found(v: Option<Value>) -> Ret {
    v.into_iter().collect()
}

/// `sim.getObjectUid(objectHandle)` → the object's unique id: no other object of this
/// process gets it, even in a scene loaded later (handles start again with each scene).
fn get_object_uid(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Int(w.object_uid(a.handle(0)?)?)])
}

/// `sim.getObjectStringParam(objectHandle, parameterID)` → text. gantry's objects have
/// one string parameter, `sim.objstringparam_unique_id` (the unique id of
/// `sim.getObjectUid` as decimal text); any other is an error naming it.
fn get_object_string_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    match a.int(1)? {
        OBJ_STRING_UNIQUE_ID => Ok(vec![Value::Str(w.object_uid(h)?.to_string())]),
        other => {
            w.object(h)?;
            Err(SimError::refused(format!(
                "object string parameter {other} is not one gantry has: it has sim.objstringparam_unique_id ({OBJ_STRING_UNIQUE_ID}) only"
            )))
        }
    }
}

/// `sim.getObjectInt32Param(objectHandle, parameterID)` → value, or nothing (`nil`) when
/// the parameter does not apply to the object.
pub(super) fn get_object_int32_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let id = a.int(1)?;
    let kind = &w.object(h)?.kind;
    let v = match (id, kind) {
        (OBJ_VISIBILITY_LAYER, _) => Some(w.layer(h)?),
        (SHAPE_STATIC, ObjectKind::Shape(s)) => Some(i64::from(!s.dynamic)),
        (SHAPE_RESPONDABLE, ObjectKind::Shape(s)) => Some(i64::from(s.respondable)),
        (VISION_RES_X, ObjectKind::VisionSensor(v)) => Some(i64::from(v.resolution[0])),
        (VISION_RES_Y, ObjectKind::VisionSensor(v)) => Some(i64::from(v.resolution[1])),
        (VISION_PERSPECTIVE, ObjectKind::VisionSensor(v)) => Some(i64::from(v.projection == Projection::Perspective)),
        (VISION_RENDER_MODE, ObjectKind::VisionSensor(v)) => Some(match v.render_mode {
            RenderMode::Visible => w.stored_param(h, VISION_RENDER_MODE)?.unwrap_or(RENDERMODE_OPENGL),
            RenderMode::ColorCoded => RENDERMODE_COLORCODED,
        }),
        (VISION_WINDOWED_SIZE_X | VISION_WINDOWED_SIZE_Y, ObjectKind::VisionSensor(_)) => {
            Some(w.stored_param(h, id)?.unwrap_or(0))
        }
        (VISION_ENTITY_TO_RENDER, ObjectKind::VisionSensor(_)) => Some(-1),
        (JOINT_VELOCITY_LOCK, ObjectKind::Joint(j)) => Some(i64::from(j.velocity_lock)),
        (VISION_RGB_IGNORED, ObjectKind::VisionSensor(v)) => Some(i64::from(v.ignore_rgb)),
        (VISION_DEPTH_IGNORED, ObjectKind::VisionSensor(v)) => Some(i64::from(v.ignore_depth)),
        (LIGHT_POV_CASTS_SHADOWS, ObjectKind::Light(l)) => Some(i64::from(l.casts_shadows)),
        (PROX_VOLUME_TYPE, ObjectKind::ProximitySensor(p)) => Some(match p.volume {
            ProximityModel::Pyramid { .. } => 0,
            ProximityModel::Cylinder { .. } => 1,
            ProximityModel::Disc { .. } => 2,
            ProximityModel::Cone { .. } => 3,
            ProximityModel::Ray { .. } => 4,
        }),
        (JOINT_MOTOR_ENABLED, ObjectKind::Joint(j)) => {
            Some(i64::from(j.mode.is_dynamic() && j.mode != JointMode::Free))
        }
        (JOINT_CTRL_ENABLED, ObjectKind::Joint(j)) => Some(i64::from(j.mode == JointMode::Position)),
        (JOINT_DYNCTRLMODE, ObjectKind::Joint(j)) => Some(match j.mode {
            JointMode::Position => DYNCTRL_POSITION,
            JointMode::Velocity => DYNCTRL_VELOCITY,
            JointMode::Force => DYNCTRL_FORCE,
            JointMode::Free | JointMode::Kinematic => DYNCTRL_FREE,
        }),
        _ => None,
    };
    Ok(found(v.map(Value::Int)))
}

/// `sim.setObjectInt32Param(objectHandle, parameterID, value)`; a parameter that does
/// not apply is ignored. Setting `sim.jointintparam_dynctrlmode` makes the joint
/// dynamic with that controller (free, velocity or position). A vision sensor's
/// resolution is 1..=2048 a side, within 1 GiB of RGB and depth images for all
/// sensors together; `sim.visionintparam_perspective_operation` is 1 for perspective,
/// 0 for orthographic; `sim.visionintparam_render_mode` is `sim.rendermode_opengl` (0)
/// or `sim.rendermode_colorcoded` (2, each pixel the handle of the shape seen, `r + 256
/// g + 65536 b`, white where none); `sim.visionintparam_rgbignored` and
/// `sim.visionintparam_depthignored` (0 or 1) skip the colour or the depth image.
fn set_object_int32_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let id = a.int(1)?;
    let v = a.int(2)?;
    let kind = &w.object(h)?.kind;
    match (id, kind) {
        (OBJ_VISIBILITY_LAYER, _) => w.set_layer(h, v)?,
        (SHAPE_STATIC, ObjectKind::Shape(_)) => w.set_shape_dynamic(h, v == 0)?,
        (SHAPE_RESPONDABLE, ObjectKind::Shape(_)) => w.set_shape_respondable(h, v != 0)?,
        (VISION_RES_X | VISION_RES_Y, ObjectKind::VisionSensor(m)) => {
            let mut m = *m;
            let side =
                u32::try_from(v).map_err(|_| SimError::bad_argument(format!("argument 3: invalid resolution {v}")))?;
            m.resolution[usize::from(id == VISION_RES_Y)] = side;
            w.set_vision_model(h, m)?;
        }
        (VISION_PERSPECTIVE, ObjectKind::VisionSensor(m)) => {
            let mut m = *m;
            m.projection = if v != 0 {
                Projection::Perspective
            } else {
                Projection::Orthographic
            };
            w.set_vision_model(h, m)?;
        }
        (VISION_RENDER_MODE, ObjectKind::VisionSensor(m)) => {
            let mut m = *m;
            m.render_mode = match v {
                RENDERMODE_OPENGL | RENDERMODE_OPENGL3 | RENDERMODE_OPENGL3_WINDOWED => RenderMode::Visible,
                RENDERMODE_COLORCODED => RenderMode::ColorCoded,
                _ => {
                    return Err(SimError::bad_argument(format!(
                        "argument 3: gantry's vision sensors render the visible colours (sim.rendermode_opengl, 0, \
                         or sim.rendermode_opengl3, 6 and 7) or colour-coded handles (sim.rendermode_colorcoded, 2), \
                         not render mode {v}"
                    )));
                }
            };
            w.set_vision_model(h, m)?;
            let newer = matches!(v, RENDERMODE_OPENGL3 | RENDERMODE_OPENGL3_WINDOWED);
            w.set_stored_param(h, VISION_RENDER_MODE, newer.then_some(v))?;
        }
        (VISION_WINDOWED_SIZE_X | VISION_WINDOWED_SIZE_Y, ObjectKind::VisionSensor(_)) => {
            if !(0..=MAX_WINDOW_SIDE).contains(&v) {
                return Err(SimError::bad_argument(format!(
                    "argument 3: a window side is 0 (full screen) to {MAX_WINDOW_SIDE} pixels, not {v}"
                )));
            }
            w.set_stored_param(h, id, Some(v))?;
        }
        (VISION_ENTITY_TO_RENDER, ObjectKind::VisionSensor(_)) if v != -1 => {
            return Err(SimError::refused(format!(
                "gantry's vision sensors render every renderable object (sim.visionintparam_entity_to_render -1), \
                 not only entity {v}; hide what the sensor should not see with sim.setObjectInt32Param \
                 (sim.objintparam_visibility_layer) instead"
            )));
        }
        (JOINT_VELOCITY_LOCK, ObjectKind::Joint(_)) => w.set_joint_velocity_lock(h, v != 0)?,
        // CoppeliaSim's motor and controller switches, onto gantry's one joint mode:
        // motor off is free, motor on without the controller velocity, with it position.
        (JOINT_MOTOR_ENABLED, ObjectKind::Joint(j)) if j.mode.is_dynamic() && j.mimic.is_none() => {
            let mode = match (v != 0, j.mode) {
                (false, _) => JointMode::Free,
                (true, JointMode::Free) => JointMode::Velocity,
                (true, mode) => mode,
            };
            w.set_joint_mode(h, mode)?;
        }
        (JOINT_CTRL_ENABLED, ObjectKind::Joint(j))
            if matches!(j.mode, JointMode::Velocity | JointMode::Position) && j.mimic.is_none() =>
        {
            let mode = if v != 0 {
                JointMode::Position
            } else {
                JointMode::Velocity
            };
            w.set_joint_mode(h, mode)?;
        }
        (VISION_RGB_IGNORED | VISION_DEPTH_IGNORED, ObjectKind::VisionSensor(m)) => {
            let mut m = *m;
            if id == VISION_RGB_IGNORED {
                m.ignore_rgb = v != 0;
            } else {
                m.ignore_depth = v != 0;
            }
            w.set_vision_model(h, m)?;
        }
        (LIGHT_POV_CASTS_SHADOWS, ObjectKind::Light(l)) => {
            let l = LightModel {
                casts_shadows: v != 0,
                ..*l
            };
            w.set_light(h, l)?;
        }
        (JOINT_DYNCTRLMODE, ObjectKind::Joint(_)) => {
            let mode = match v {
                DYNCTRL_FREE => JointMode::Free,
                DYNCTRL_FORCE => JointMode::Force,
                DYNCTRL_VELOCITY => JointMode::Velocity,
                DYNCTRL_POSITION => JointMode::Position,
                _ => {
                    return Err(SimError::bad_argument(format!(
                        "argument 3: gantry's dynamic joints have the free (0), force (1), velocity (4) and position (8) controllers, not {v}"
                    )));
                }
            };
            w.set_joint_mode(h, mode)?;
        }
        _ => {}
    }
    Ok(Vec::new())
}

/// `sim.getObjectFloatParam(objectHandle, parameterID)` → value, or nothing (`nil`) when
/// the parameter does not apply. Velocities are m/s and rad/s in the world frame, the
/// bounding box in m in the object's frame, angles in rad, a vision sensor's clipping
/// planes and ortho size (its view's extent along the larger image side) in m. A
/// light's spot exponent reads as a number with no fraction, its cutoff in rad (half
/// the cone's opening).
pub(super) fn get_object_float_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let id = a.int(1)?;
    let kind = &w.object(h)?.kind;
    let v = match (id, kind) {
        (OBJ_ABS_X_VELOCITY..=OBJ_ABS_ROT_VELOCITY, _) => {
            let (lin, ang) = w.velocity(h)?;
            Some(match id {
                OBJ_ABS_ROT_VELOCITY => ang.norm(),
                _ => lin[(id - OBJ_ABS_X_VELOCITY) as usize],
            })
        }
        (OBJ_BBOX_MIN_X..=OBJ_BBOX_MAX_Z, _) => {
            let (lo, hi) = w.bounding_box(h)?;
            let i = (id - OBJ_BBOX_MIN_X) as usize;
            Some(if i < 3 { lo[i] } else { hi[i - 3] })
        }
        // The whole model's box (the object and everything below it), in the object's
        // frame: min x, y, z, then max x, y, z, as the object box above.
        (OBJ_MODEL_BBOX_MIN_X..=OBJ_MODEL_BBOX_MAX_Z, _) => {
            let (lo, hi) = w.model_bounding_box(h)?;
            let i = (id - OBJ_MODEL_BBOX_MIN_X) as usize;
            Some(if i < 3 { lo[i] } else { hi[i - 3] })
        }
        (SHAPE_MASS, ObjectKind::Shape(_)) => Some(w.shape_mass(h)?),
        (VISION_NEAR, ObjectKind::VisionSensor(v)) => Some(v.near),
        (VISION_FAR, ObjectKind::VisionSensor(v)) => Some(v.far),
        (VISION_ANGLE, ObjectKind::VisionSensor(v)) => Some(v.fov),
        (VISION_ORTHO_SIZE, ObjectKind::VisionSensor(v)) => Some(v.ortho_size),
        (LIGHT_SPOT_EXPONENT, ObjectKind::Light(l)) => Some(f64::from(l.spot_exponent)),
        (LIGHT_SPOT_CUTOFF, ObjectKind::Light(l)) => Some(l.spot_cutoff),
        (LIGHT_CONST_ATTENUATION..=LIGHT_QUAD_ATTENUATION, ObjectKind::Light(l)) => {
            Some(l.attenuation[(id - LIGHT_CONST_ATTENUATION) as usize])
        }
        (JOINT_PID_P, ObjectKind::Joint(j)) => Some(j.kp),
        (JOINT_PID_I, ObjectKind::Joint(_)) => Some(0.0),
        (JOINT_PID_D, ObjectKind::Joint(j)) => Some(j.kd),
        (JOINT_VELOCITY, ObjectKind::Joint(j)) => Some(j.velocity),
        // No limit reads as an infinite one.
        (JOINT_MAXVEL | JOINT_UPPER_LIMIT, ObjectKind::Joint(j)) => Some(j.max_velocity.unwrap_or(f64::INFINITY)),
        _ => None,
    };
    Ok(found(v.map(Value::Float)))
}

/// `sim.setObjectFloatParam(objectHandle, parameterID, value)`; a parameter that does
/// not apply, or is read-only, is ignored. A light's spot exponent is rounded and held
/// in 0..=128 and its spot cutoff in 5 degrees..pi/2, as CoppeliaSim holds them; its
/// attenuation factors are read-only, as in CoppeliaSim (whose setter ignores them).
fn set_object_float_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let id = a.int(1)?;
    let v = a.f64(2)?;
    let kind = &w.object(h)?.kind;
    match (id, kind) {
        (SHAPE_MASS, ObjectKind::Shape(_)) => w.set_shape_mass(h, v)?,
        (VISION_NEAR | VISION_FAR | VISION_ANGLE | VISION_ORTHO_SIZE, ObjectKind::VisionSensor(m)) => {
            let mut m = *m;
            match id {
                VISION_NEAR => m.near = v,
                VISION_FAR => m.far = v,
                VISION_ORTHO_SIZE => m.ortho_size = v,
                _ => m.fov = v,
            }
            w.set_vision_model(h, m)?;
        }
        (LIGHT_SPOT_EXPONENT, ObjectKind::Light(l)) => {
            // CoppeliaSim keeps an integer exponent from 0 to 128: the value is rounded
            // and held in range, as its setter does.
            let e = if v.is_finite() {
                v.round().clamp(0.0, 128.0) as i32
            } else {
                l.spot_exponent
            };
            let l = LightModel { spot_exponent: e, ..*l };
            w.set_light(h, l)?;
        }
        (LIGHT_SPOT_CUTOFF, ObjectKind::Light(l)) => {
            // Held between 5 degrees and pi/2, as CoppeliaSim's setter holds it.
            let c = if v.is_finite() {
                v.clamp(LightModel::MIN_SPOT_CUTOFF, LightModel::MAX_SPOT_CUTOFF)
            } else {
                l.spot_cutoff
            };
            let l = LightModel { spot_cutoff: c, ..*l };
            w.set_light(h, l)?;
        }
        (JOINT_PID_P, ObjectKind::Joint(_)) => w.set_joint_gains(h, Some(v), None)?,
        (JOINT_PID_D, ObjectKind::Joint(_)) => w.set_joint_gains(h, None, Some(v))?,
        (JOINT_MAXVEL | JOINT_UPPER_LIMIT, ObjectKind::Joint(_)) => {
            w.set_joint_max_velocity(h, (v != f64::INFINITY).then_some(v))?;
        }
        _ => {}
    }
    Ok(Vec::new())
}

fn unknown(what: &str, id: i64) -> SimError {
    SimError::bad_argument(format!("could not {what} parameter {id}: gantry does not have it"))
}

/// `sim.getInt32Param(parameter)`: the program version (40600, the CoppeliaSim API
/// gantry follows), revision, full version, platform (0 Windows, 1 macOS, 2 Linux),
/// physics substeps per step, and the object creation/destruction/hierarchy counters.
fn get_int32_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    let c = w.edit_counters();
    let v = match id {
        INT_PROGRAM_VERSION => PROGRAM_VERSION,
        INT_PROGRAM_REVISION => 0,
        INT_PROGRAM_FULL_VERSION => PROGRAM_VERSION * 100,
        INT_PLATFORM => match std::env::consts::OS {
            "windows" => 0,
            "macos" => 1,
            _ => 2,
        },
        INT_DYNAMIC_STEP_DIVIDER => i64::from(w.settings().substeps.max(1)),
        INT_OBJECT_CREATION_COUNTER => c.created as i64,
        INT_OBJECT_DESTRUCTION_COUNTER => c.destroyed as i64,
        INT_HIERARCHY_CHANGE_COUNTER => c.hierarchy as i64,
        _ => return Err(unknown("retrieve", id)),
    };
    Ok(vec![Value::Int(v)])
}

/// `sim.setInt32Param(parameter, value)`: gantry's integer parameters are all read-only.
fn set_int32_param(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    a.int(1)?;
    Err(unknown("set", id))
}

/// `sim.getFloatParam(parameter)`: a random number in [0, 1), the simulation time step
/// (s), or the physics time step (s, the step over the substeps).
fn get_float_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    let s = *w.settings();
    let v = match id {
        FLOAT_RAND => w.next_random(),
        FLOAT_SIMULATION_TIME_STEP => s.dt,
        FLOAT_DYNAMIC_STEP_SIZE | FLOAT_PHYSICS_TIME_STEP => s.dt / f64::from(s.substeps.max(1)),
        _ => return Err(unknown("retrieve", id)),
    };
    Ok(vec![Value::Float(v)])
}

/// `sim.setFloatParam(parameter, value)`: the simulation time step (s), while stopped.
fn set_float_param(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    let v = a.f64(1)?;
    match id {
        FLOAT_SIMULATION_TIME_STEP => sim.set_time_step(v)?,
        _ => return Err(unknown("set", id)),
    }
    Ok(Vec::new())
}

/// `sim.getBoolParam(parameter)`: whether dynamics, proximity and vision sensors are
/// handled (always), headless (always: the viewer is a separate page), and the
/// real-time flag as last set.
fn get_bool_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    let v = match id {
        BOOL_DYNAMICS_HANDLING | BOOL_PROXIMITY_SENSOR_HANDLING | BOOL_VISION_SENSOR_HANDLING | BOOL_HEADLESS => true,
        BOOL_REALTIME_SIMULATION => w.realtime_flag(),
        _ => return Err(unknown("retrieve", id)),
    };
    Ok(vec![Value::Bool(v)])
}

/// `sim.setBoolParam(parameter, value)`: only the real-time flag, which is stored and
/// reported back (gantry's pacing is chosen on the command line, `--fast`).
fn set_bool_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    let v = a.bool(1)?;
    match id {
        BOOL_REALTIME_SIMULATION => w.set_realtime_flag(v),
        _ => return Err(unknown("set", id)),
    }
    Ok(Vec::new())
}

/// `sim.getStringParam(parameter)`: the scene's file (`sim.stringparam_scene_path_and_name`,
/// empty for a scene built in memory), its folder (`_scene_path`) and file name
/// (`_scene_name`), the folder of gantry's executable (`_application_path`), the
/// temporary folder (`_tempdir`). CoppeliaSim's default scene and model folders
/// (`_scenedefaultdir`, `_modeldefaultdir`) are its installation's; gantry has none and
/// answers the scene's folder (the working folder for a scene built in memory), where
/// relative paths in `sim.loadScene` and `sim.loadModel` resolve.
fn get_string_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    let source = w.source();
    let text = |p: &std::path::Path| p.to_string_lossy().into_owned();
    let v = match id {
        STRING_APPLICATION_PATH => std::env::current_exe()
            .ok()
            .and_then(|p| p.parent().map(text))
            .unwrap_or_default(),
        STRING_SCENE_PATH_AND_NAME => text(&source.path),
        STRING_SCENE_PATH => text(&source.dir),
        STRING_SCENE_NAME => source
            .path
            .file_name()
            .map_or_else(|| source.name.clone(), |n| n.to_string_lossy().into_owned()),
        STRING_TEMP_DIR => text(&std::env::temp_dir()),
        STRING_SCENE_DEFAULT_DIR | STRING_MODEL_DEFAULT_DIR => {
            if source.dir.as_os_str().is_empty() {
                std::env::current_dir().map(|d| text(&d)).unwrap_or_default()
            } else {
                text(&source.dir)
            }
        }
        _ => return Err(unknown("retrieve", id)),
    };
    Ok(vec![Value::Str(v)])
}

/// `sim.getArrayParam(parameter)`: gravity, `[x, y, z]` in m/s².
fn get_array_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    match id {
        ARRAY_GRAVITY => Ok(vec![Value::floats(w.gravity().as_slice())]),
        _ => Err(unknown("retrieve", id)),
    }
}

/// `sim.setArrayParam(parameter, values)`: gravity, `[x, y, z]` in m/s², from the next
/// step on.
fn set_array_param(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let id = a.int(0)?;
    match id {
        ARRAY_GRAVITY => w.set_gravity(a.vec3(1)?)?,
        _ => return Err(unknown("set", id)),
    }
    Ok(Vec::new())
}
