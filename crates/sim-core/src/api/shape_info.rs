//! What a shape is made of and how its mass is spread: `sim.getShapeGeomInfo`,
//! `sim.getShapeInertia`, `sim.computeMassAndInertia` and V-REP 3's
//! `sim.getShapeMassAndInertia` / `sim.setShapeMassAndInertia`.

use nalgebra::Matrix3;

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::{self, Pose, Vec3};
use crate::scene::Geometry;
use crate::world::World;

/// The shape information functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "computeMassAndInertia",
        call: ApiFn::World(compute_mass_and_inertia),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getShapeGeomInfo",
        call: ApiFn::World(get_shape_geom_info),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getShapeInertia",
        call: ApiFn::World(get_shape_inertia),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getShapeMassAndInertia",
        call: ApiFn::World(get_shape_mass_and_inertia),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setShapeMassAndInertia",
        call: ApiFn::World(set_shape_mass_and_inertia),
        cost: Cost::Quick,
    },
];

/// Thickness below which a box is a plane and a cylinder a disc, m (the primitives
/// `sim.createPrimitiveShape` makes are 0.1 mm thick).
const FLAT: f64 = 2e-4;

/// `sim.primitiveshape_*` of a primitive and its dimensions (x size or diameter, y size,
/// z size or height), or `None` for a mesh.
fn primitive(g: &Geometry) -> Option<(i64, [f64; 3])> {
    Some(match *g {
        Geometry::Box {
            half_extents: [x, y, z],
        } => (if 2.0 * z <= FLAT { 1 } else { 3 }, [2.0 * x, 2.0 * y, 2.0 * z]),
        Geometry::Sphere { radius } => (4, [2.0 * radius; 3]),
        Geometry::Cylinder { radius, length } => {
            (if length <= FLAT { 2 } else { 5 }, [2.0 * radius, 2.0 * radius, length])
        }
        Geometry::Capsule { radius, length } => (8, [2.0 * radius, 2.0 * radius, length + 2.0 * radius]),
        Geometry::Mesh(_) => return None,
    })
}

/// `sim.getShapeGeomInfo(shapeHandle)` → `result, pureType, dimensions`. `result` bit 0:
/// compound (several parts), bit 1: pure (every part a primitive), bit 2: convex (every
/// part a primitive; gantry does not test meshes for convexity). `pureType` is the
/// `sim.primitiveshape_*` of a simple pure shape, else `sim.primitiveshape_none`;
/// `dimensions` its x size or diameter, y size, z size or height and inside scaling
/// (1). CoppeliaSim leaves them undefined for other shapes; gantry gives the bounding
/// box size in the shape frame then.
fn get_shape_geom_info(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let s = w.shape(h)?;
    let compound = s.geoms.len() > 1;
    let pure = !s.geoms.is_empty() && s.geoms.iter().all(|g| primitive(&g.geometry).is_some());
    let result = i64::from(compound) | i64::from(pure) << 1 | i64::from(pure) << 2;
    let simple = match s.geoms.as_slice() {
        [g] if !compound => primitive(&g.geometry),
        _ => None,
    };
    let (kind, dims) = match simple {
        Some(p) => p,
        None => {
            let (lo, hi) = w.bounding_box(h)?;
            (0, [0, 1, 2].map(|k| hi[k] - lo[k]))
        }
    };
    Ok(vec![
        Value::Int(result),
        Value::Int(kind),
        Value::floats(&[dims[0], dims[1], dims[2], 1.0]),
    ])
}

/// A 3×3 matrix as 9 numbers, row by row.
fn rows(m: &Matrix3<f64>) -> Value {
    Value::floats(&[0, 1, 2].map(|r| [0, 1, 2].map(|c| m[(r, c)])).concat())
}

/// `sim.getShapeInertia(shapeHandle)` → `inertiaMatrix, transformationMatrix`: the
/// inertia tensor (9 values, kg·m², not divided by the mass) about the centre of mass,
/// and the frame it is expressed in relative to the shape frame (12 values: the shape's
/// axes at the centre of mass).
fn get_shape_inertia(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let p = w.shape_mass_properties(a.handle(0)?)?;
    let frame = Pose::from_parts(p.com.into(), math::Quat::identity());
    Ok(vec![rows(&p.inertia), Value::floats(&math::pose_to_matrix12(&frame))])
}

/// `sim.getShapeMassAndInertia(shapeHandle, transformation=nil)` (V-REP 3) → `mass,
/// inertiaMatrix, centerOfMass`: the mass (kg), the inertia tensor about the centre of
/// mass divided by the mass (9 values, m²), and the centre of mass (3 values), both
/// relative to `transformation` (an absolute 12-value matrix), or to the shape frame
/// when it is nil.
fn get_shape_mass_and_inertia(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let p = w.shape_mass_properties(h)?;
    let into = match a.get(1) {
        Value::Nil => Pose::identity(),
        _ => {
            let m = a.floats::<12>(1)?;
            let frame = math::pose_from_matrix12(&m).ok_or_else(|| {
                SimError::bad_argument("argument 2: the transformation's rotation part is not a rotation")
            })?;
            frame.inverse() * w.object(h)?.world
        }
    };
    let r = into.rotation.to_rotation_matrix().into_inner();
    let per_kg = if p.mass > 0.0 { 1.0 / p.mass } else { 0.0 };
    let com = into * nalgebra::Point3::from(p.com);
    Ok(vec![
        Value::Float(p.mass),
        rows(&(r * p.inertia * r.transpose() * per_kg)),
        Value::floats(com.coords.as_slice()),
    ])
}

/// `sim.computeMassAndInertia(shapeHandle, density)` → 1: gives the shape the mass
/// (volume × density, kg/m³) and inertia of its collision parts filled uniformly.
/// CoppeliaSim computes convex shapes only (0 for others); gantry takes a mesh's convex
/// hull, so it always computes.
fn compute_mass_and_inertia(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let density = a.f64(1)?;
    w.compute_mass_and_inertia(h, density)?;
    Ok(vec![Value::Int(1)])
}

/// `sim.setShapeMassAndInertia(shapeHandle, mass, inertiaMatrix, centerOfMass,
/// transformation=nil)` (V-REP 3): sets the mass (kg), the inertia tensor divided by the
/// mass (9 values, m²) and the centre of mass (3 values), both relative to
/// `transformation` (an absolute 12-value matrix), or to the shape frame when it is nil:
/// the inverse of `sim.getShapeMassAndInertia`.
fn set_shape_mass_and_inertia(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let mass = a.finite(1)?;
    let per_kg = a.floats::<9>(2)?;
    let com = a.floats::<3>(3)?;
    let from = match a.get(4) {
        Value::Nil => Pose::identity(),
        _ => {
            let m = a.floats::<12>(4)?;
            let frame = math::pose_from_matrix12(&m).ok_or_else(|| {
                SimError::bad_argument("argument 5: the transformation's rotation part is not a rotation")
            })?;
            w.object(h)?.world.inverse() * frame
        }
    };
    if mass <= 0.0 {
        return Err(SimError::bad_argument(format!(
            "argument 2: the mass must be positive, got {mass}"
        )));
    }
    let r = from.rotation.to_rotation_matrix().into_inner();
    let inertia = r * Matrix3::from_row_slice(&per_kg) * r.transpose() * mass;
    let com = (from * nalgebra::Point3::from(Vec3::from(com))).coords;
    w.set_shape_inertial(h, mass, com, &inertia)?;
    Ok(Vec::new())
}
