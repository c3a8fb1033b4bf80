//! `sim.createVisionSensor`, `sim.createForceSensor`, `sim.createProximitySensor`:
//! sensors made at run time, with CoppeliaSim 4.1's argument lists (PyRep's
//! `VisionSensor.create`, `ForceSensor.create`).
//! Each is created at the world origin, as a root, and works as one loaded with the
//! scene: a vision sensor renders when read or handled (its image is blank until it is
//! handled or the simulation steps, as CoppeliaSim's), a force sensor measures what
//! hangs from it once an object is parented to it.
//!
//! Options gantry cannot honour are refused with the reason instead of being dropped
//! silently; those that only change how CoppeliaSim draws the sensor are accepted.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::Pose;
use crate::scene::{Projection, ProximityModel, VisionModel};
use crate::sim::Sim;
use crate::world::{ForceReading, ObjectKind, ProximitySensor, World};

/// The sensor creation functions, sorted by name.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "createForceSensor",
        call: ApiFn::World(create_force_sensor),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createProximitySensor",
        call: ApiFn::World(create_proximity_sensor),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createVisionSensor",
        call: ApiFn::Sim(create_vision_sensor),
        cost: Cost::Quick,
    },
];

/// `sim.createVisionSensor` option bits.
const VISION_EXPLICIT: i64 = 1;
const VISION_PERSPECTIVE: i64 = 2;
const VISION_PASSIVE: i64 = 16;
const VISION_NULL_PIXEL_COLOR: i64 = 128;

/// The list argument `i` of finite numbers, with at least `n` of them (CoppeliaSim's
/// reserved trailing entries may be left out).
fn leading(a: &Args<'_>, i: usize, n: usize, what: &str) -> Result<Vec<f64>, SimError> {
    let v = a.numbers(i)?;
    if v.len() < n {
        return Err(SimError::bad_argument(format!(
            "argument {}: expected at least {n} numbers ({what}), got {}",
            i + 1,
            v.len()
        )));
    }
    Ok(v)
}

/// `sim.createVisionSensor(options, intParams, floatParams, color=nil)` → handle.
///
/// `intParams`: resolution x, y (pixels), then 2 reserved. `floatParams`: near and far
/// clipping distances (m), the view angle (rad, perspective) or ortho size (m), the
/// sensor's drawn size x, y, z, the null-pixel colour r, g, b, then 2 reserved.
/// Options: bit 0 explicit handling (the sensor renders only when handled), bit 1
/// perspective (else orthographic), bit 7 the null-pixel colour: what the image shows
/// where the sensor sees nothing (without it, the scene's background,
/// `[simulation] background`, as CoppeliaSim's sensors show its environment colour);
/// bits 2, 3 (volume display), 5 (local lights) and 6 (fog) only change CoppeliaSim's
/// drawing and are accepted. Refused: bit 4 (a passive sensor fed external images).
fn create_vision_sensor(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let options = a.int(0)?;
    let ints = leading(a, 1, 2, "resolution x and y")?;
    let floats = leading(a, 2, 3, "near, far, view angle or ortho size")?;
    if !matches!(a.get(3), Value::Nil | Value::Array(_)) {
        return Err(SimError::bad_argument("argument 4: expected a list of colours or nil"));
    }
    if options & VISION_PASSIVE != 0 {
        return Err(SimError::refused(
            "option bit 4 (a passive vision sensor fed external images) is not supported: create an ordinary sensor and write its image with sim.setVisionSensorImg",
        ));
    }
    let background = if options & VISION_NULL_PIXEL_COLOR != 0 {
        match floats.get(6..9) {
            Some(&[r, g, b]) if [r, g, b].iter().all(|c| (0.0..=1.0).contains(c)) => Some([r, g, b]),
            Some(c) => {
                return Err(SimError::bad_argument(format!(
                    "argument 3: null-pixel colour {c:?} (option bit 7) must have components from 0 to 1"
                )));
            }
            None => {
                return Err(SimError::bad_argument(
                    "argument 3: option bit 7 needs the null-pixel colour r, g, b at positions 7 to 9",
                ));
            }
        }
    } else {
        None
    };
    let dim = |k: usize| -> Result<u32, SimError> {
        let v = ints[k];
        if v.fract() != 0.0 || !(1.0..=f64::from(crate::scene::MAX_VISION_RESOLUTION)).contains(&v) {
            return Err(SimError::bad_argument(format!(
                "argument 2: resolution {v} must be a whole number of pixels in 1..={}",
                crate::scene::MAX_VISION_RESOLUTION
            )));
        }
        Ok(v as u32)
    };
    let perspective = options & VISION_PERSPECTIVE != 0;
    let defaults = VisionModel {
        resolution: [dim(0)?, dim(1)?],
        projection: if perspective {
            Projection::Perspective
        } else {
            Projection::Orthographic
        },
        // The scene loader's defaults for the setting the sensor does not use now, so
        // that switching its projection later gives a usable view.
        fov: 60f64.to_radians(),
        ortho_size: 1.0,
        near: floats[0],
        far: floats[1],
        render_mode: Default::default(),
        ignore_rgb: false,
        ignore_depth: false,
        ros2_rate: None,
        background,
    };
    let model = if perspective {
        VisionModel {
            fov: floats[2],
            ..defaults
        }
    } else {
        VisionModel {
            ortho_size: floats[2],
            ..defaults
        }
    };
    let h = sim
        .world
        .add_vision_sensor("Vision_sensor", model, None, Pose::identity())?;
    if options & VISION_EXPLICIT != 0 {
        crate::vision::set_explicit(&sim.world, &mut sim.vision, h, true)?;
    }
    // Until it is first handled (by the next step, or explicitly), CoppeliaSim's new
    // sensor holds its cleared image: its blank image counts as this step's, so that
    // readers get it rather than a render (PyRep's tests read a blank image first).
    crate::vision::write(&sim.world, &mut sim.vision, h)?;
    Ok(vec![Value::Int(h)])
}

/// `sim.createForceSensor(options, intParams, floatParams, color=nil)` → handle.
///
/// `intParams`: the filter (0 average, 1 median), its sample count, the consecutive
/// threshold violations before breaking, then 2 reserved. `floatParams`: the drawn size
/// (m), the force (N) and torque (N·m) thresholds, then 2 reserved. Options bit 0 and 1
/// enable the force and torque thresholds. gantry's force sensors report each step's
/// reading unfiltered and never break, so a sample count above 1 or an enabled
/// threshold is refused; everything else is accepted.
fn create_force_sensor(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let options = a.int(0)?;
    let ints = leading(a, 1, 3, "filter type, sample count, violation count")?;
    leading(a, 2, 1, "size")?;
    if !matches!(a.get(3), Value::Nil | Value::Array(_)) {
        return Err(SimError::bad_argument("argument 4: expected a list of colours or nil"));
    }
    if options & 3 != 0 {
        return Err(SimError::refused(
            "force sensor thresholds (options bits 0 and 1) are not supported: gantry's force sensors never break",
        ));
    }
    if !(0.0..=1.0).contains(&ints[0]) {
        return Err(SimError::bad_argument(format!(
            "argument 2: filter type {} must be 0 (average) or 1 (median)",
            ints[0]
        )));
    }
    if ints[1] > 1.0 {
        return Err(SimError::refused(format!(
            "a force sensor filter over {} samples is not supported: gantry's force sensors report each step's reading (use 0 or 1)",
            ints[1]
        )));
    }
    let h = w.add_object(
        "Force_sensor",
        ObjectKind::ForceSensor(ForceReading::default()),
        None,
        Pose::identity(),
    )?;
    Ok(vec![Value::Int(h)])
}

/// `sim.proximitysensor_*_subtype`: the volume types.
const PYRAMID: i64 = 30;
const CYLINDER: i64 = 31;
const DISC: i64 = 32;
const CONE: i64 = 33;
const RAY: i64 = 34;

/// `sim.createProximitySensor` option bits gantry cannot honour, with the reason.
const PROXIMITY_REFUSED: [(i64, &str); 5] = [
    (
        8,
        "bit 3 (front faces not detected): gantry's sensors detect both faces",
    ),
    (
        16,
        "bit 4 (back faces not detected): gantry's sensors detect both faces",
    ),
    (
        64,
        "bit 6 (a limit on the angle between the ray and the surface normal)",
    ),
    (256, "bit 8 (a smallest detection distance)"),
    (512, "bit 9 (randomized ray detection)"),
];

/// `sim.createProximitySensor(sensorType, subType, options, intParams, floatParams,
/// color=nil)` → handle.
///
/// `sensorType`: `sim.proximitysensor_pyramid_subtype` (30), `cylinder` (31), `disc`
/// (32), `cone` (33) or `ray` (34); `subType` (CoppeliaSim's deprecated detection
/// subtype) is ignored. `floatParams` (m, rad): offset, range, x size, y size, x size
/// far, y size far, inside gap, radius, radius far, angle, then CoppeliaSim's threshold
/// angle, smallest distance and point size, which gantry does not use; a pyramid uses
/// its four sizes, a cylinder its radii, a cone its full opening angle (below π), a disc
/// its opening angle (up to 2π) and its y size as its thickness. `intParams` (face
/// counts and subdivisions of CoppeliaSim's drawn volume) are checked to be a list.
/// Options: bit 0 (explicit handling), 1, 2 (volume display), 5 (fast detection) and 7
/// (occlusion check: gantry's sensors report the closest point, which nothing
/// occludes) are accepted; bits 3, 4, 6, 8 and 9 are refused with the reason.
fn create_proximity_sensor(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let kind = a.int(0)?;
    a.int(1)?;
    let options = a.int(2)?;
    a.numbers(3)?;
    let f = leading(a, 4, 10, "offset, range, sizes, radii and angle")?;
    if !matches!(a.get(5), Value::Nil | Value::Array(_)) {
        return Err(SimError::bad_argument("argument 6: expected a list of colours or nil"));
    }
    if let Some((_, why)) = PROXIMITY_REFUSED.iter().find(|(bit, _)| options & bit != 0) {
        return Err(SimError::refused(format!("argument 3: option {why} is not supported")));
    }
    let bad = |what: &str, v: f64| SimError::bad_argument(format!("argument 5: the {what} is out of range: {v}"));
    let (offset, range) = (f[0], f[1]);
    if !(offset.is_finite() && offset >= 0.0) {
        return Err(bad("offset (m, >= 0)", offset));
    }
    if !(range.is_finite() && range > 0.0) {
        return Err(bad("range (m, > 0)", range));
    }
    let non_negative = |k: usize, what: &str| -> Result<f64, SimError> {
        let v = f[k];
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(bad(what, v))
        }
    };
    let volume = match kind {
        RAY => ProximityModel::Ray { offset, range },
        PYRAMID => {
            let near_size = [
                non_negative(2, "x size (m, >= 0)")?,
                non_negative(3, "y size (m, >= 0)")?,
            ];
            let far_size = [
                non_negative(4, "x size far (m, >= 0)")?,
                non_negative(5, "y size far (m, >= 0)")?,
            ];
            if near_size.iter().chain(&far_size).sum::<f64>() <= 0.0 {
                return Err(SimError::bad_argument(
                    "argument 5: a pyramid's four sizes (positions 3 to 6) cannot all be 0",
                ));
            }
            ProximityModel::Pyramid {
                offset,
                range,
                near_size,
                far_size,
            }
        }
        CYLINDER => {
            let radius = non_negative(7, "radius (m, >= 0)")?;
            let radius_far = non_negative(8, "radius far (m, >= 0)")?;
            if radius + radius_far <= 0.0 {
                return Err(SimError::bad_argument(
                    "argument 5: a cylinder's radius and radius far (positions 8 and 9) cannot both be 0",
                ));
            }
            ProximityModel::Cylinder {
                offset,
                range,
                radius,
                radius_far,
            }
        }
        CONE => {
            let angle = f[9];
            if !(angle > 0.0 && angle < std::f64::consts::PI) {
                return Err(bad("cone angle (rad, full opening, in (0, pi))", angle));
            }
            ProximityModel::Cone {
                offset,
                range,
                half_angle: angle / 2.0,
            }
        }
        DISC => {
            let angle = f[9];
            if !(angle > 0.0 && angle <= std::f64::consts::TAU) {
                return Err(bad("disc angle (rad, in (0, 2 pi])", angle));
            }
            let thickness = f[3];
            if !(thickness.is_finite() && thickness > 0.0) {
                return Err(bad("disc thickness (y size, m, > 0)", thickness));
            }
            ProximityModel::Disc {
                offset,
                range,
                half_angle: angle / 2.0,
                thickness,
            }
        }
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 1: invalid proximity sensor type {other} (sim.proximitysensor_pyramid_subtype, _cylinder_, _disc_, _cone_ or _ray_subtype)"
            )));
        }
    };
    let h = w.add_object(
        "Proximity_sensor",
        ObjectKind::ProximitySensor(ProximitySensor { volume, last: None }),
        None,
        Pose::identity(),
    )?;
    Ok(vec![Value::Int(h)])
}
