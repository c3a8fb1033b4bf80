//! The scene as data: creating, copying, removing and re-parenting objects, aliases,
//! shape colours and masses, forces, dynamic resets and joint modes.
//!
//! The world does the editing (`world::edit`); this file reads CoppeliaSim 4.6's argument
//! forms and defaults and gives its return shapes.

use crate::error::SimError;
use crate::sim::Sim;
use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::Arc;

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::math::{Pose, Vec3};
use crate::scene::{Geometry, JointMode, MassModel, MeshData, ShapeModel};
use crate::world::object_path::ObjectTree;
use crate::world::{ColorComponent, Handle, MIN_SHAPE_MASS, ObjectKind, World};

/// `sim.handleflag_resetforce`: OR-ed onto a handle, clears the accumulated force.
const RESET_FORCE: i64 = 0x0040_0000;
/// `sim.handleflag_resettorque`: OR-ed onto a handle, clears the accumulated torque.
const RESET_TORQUE: i64 = 0x0080_0000;

/// `sim.handleflag_silenterror` (CoppeliaSim's 32-bit value): OR-ed onto the handle
/// given to `sim.setObjectAlias` (`sim.setObjectName`), a failure is ignored instead of
/// raised.
pub(super) const HANDLEFLAG_SILENT_ERROR: Handle = 0x0200_0000;

/// The `sim.*` constants of this file, with CoppeliaSim 4.6's values.
pub const CONSTANTS: &[(&str, i64)] = &[
    ("primitiveshape_none", 0),
    ("primitiveshape_plane", 1),
    ("primitiveshape_disc", 2),
    ("primitiveshape_cuboid", 3),
    ("primitiveshape_spheroid", 4),
    ("primitiveshape_cylinder", 5),
    ("primitiveshape_cone", 6),
    ("primitiveshape_heightfield", 7),
    ("primitiveshape_capsule", 8),
    ("colorcomponent_ambient", 0),
    ("colorcomponent_ambient_diffuse", 0),
    ("colorcomponent_diffuse", 1),
    ("colorcomponent_specular", 2),
    ("colorcomponent_emission", 3),
    ("colorcomponent_transparency", 4),
    ("colorcomponent_auxiliary", 5),
    ("handleflag_resetforce", RESET_FORCE),
    ("handleflag_resettorque", RESET_TORQUE),
    ("handleflag_resetforcetorque", RESET_FORCE | RESET_TORQUE),
];

/// The functions of this file, sorted by name.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "addForce",
        call: ApiFn::World(add_force),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "addForceAndTorque",
        call: ApiFn::World(add_force_and_torque),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "copyPasteObjects",
        call: ApiFn::World(copy_paste_objects),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createDummy",
        call: ApiFn::World(create_dummy),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createMeshShape",
        call: ApiFn::World(create_mesh_shape),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createPrimitiveShape",
        call: ApiFn::World(create_primitive_shape),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "createPureShape",
        call: ApiFn::World(create_pure_shape),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointMaxForce",
        call: ApiFn::World(get_joint_max_force),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointMode",
        call: ApiFn::World(get_joint_mode),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getJointTargetForce",
        call: ApiFn::World(get_joint_target_force),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectChild",
        call: ApiFn::World(get_object_child),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjectColor",
        call: ApiFn::World(get_object_color),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getObjects",
        call: ApiFn::World(get_objects),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getShapeColor",
        call: ApiFn::World(get_shape_color),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getShapeMass",
        call: ApiFn::World(get_shape_mass),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "removeObject",
        call: ApiFn::Sim(remove_object),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "removeObjects",
        call: ApiFn::Sim(remove_objects),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "resetDynamicObject",
        call: ApiFn::World(reset_dynamic_object),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "scaleObject",
        call: ApiFn::World(scale_object),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setJointMaxForce",
        call: ApiFn::World(set_joint_max_force),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setJointMode",
        call: ApiFn::World(set_joint_mode),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectAlias",
        call: ApiFn::World(set_object_alias),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectColor",
        call: ApiFn::World(set_object_color),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setObjectParent",
        call: ApiFn::World(set_object_parent),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setShapeBB",
        call: ApiFn::World(set_shape_bb),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setShapeColor",
        call: ApiFn::World(set_shape_color),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "setShapeMass",
        call: ApiFn::World(set_shape_mass),
        cost: Cost::Quick,
    },
];

/// A required table of handles.
pub(super) fn handle_list(a: &Args<'_>, i: usize) -> Result<Vec<Handle>, SimError> {
    match a.get(i) {
        Value::Array(items) => items
            .iter()
            .enumerate()
            .map(|(k, v)| {
                v.as_i64().ok_or_else(|| {
                    SimError::bad_argument(format!("argument {}: element {} must be a handle", i + 1, k + 1))
                })
            })
            .collect(),
        // An empty Lua table arrives as an empty map.
        Value::Map(pairs) if pairs.is_empty() => Ok(Vec::new()),
        other => Err(SimError::bad_argument(format!(
            "argument {}: expected table of handles, got {}",
            i + 1,
            other.type_name()
        ))),
    }
}

/// `sim.createPrimitiveShape(primitiveType, sizes, options=0)` → handle.
///
/// `sizes` are the bounding box's x, y, z in m (diameters for round shapes; a capsule's
/// z is its total length). The shape is created at the world origin, static and not
/// respondable, white, with a density of 1000 kg/m³, as CoppeliaSim creates it; make it
/// fall with `sim.setObjectInt32Param(h, sim.shapeintparam_static, 0)` and
/// `sim.shapeintparam_respondable, 1`. Options bit 0 (culling), 1 (edges) and 2 (open
/// ends) only change how CoppeliaSim draws it and are accepted and ignored.
fn create_primitive_shape(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let kind = a.int(0)?;
    let sizes = a.floats::<3>(1)?;
    a.opt_int(2, 0)?;
    let (alias, geometry) = primitive(kind, sizes, 2)?;
    // CoppeliaSim creates primitives white and not respondable.
    let shape = ShapeModel {
        respondable: false,
        ..ShapeModel::single(geometry, [1.0, 1.0, 1.0])
    };
    let h = w.add_object(alias, ObjectKind::Shape(Box::new(shape)), None, Pose::identity())?;
    Ok(vec![Value::Int(h)])
}

/// `sim.createPureShape(primitiveType, options, sizes, mass, precision=nil)` → handle:
/// V-REP 3's form of [`create_primitive_shape`]. Types 0 cuboid, 1 sphere, 2 cylinder,
/// 3 cone; `sizes` the bounding box (m), `mass` in kg. Options bit 3 makes the shape
/// respondable and bit 4 static (without it the shape is dynamic and falls); bits 0
/// (culling), 1 (edges), 2 (smooth) and 5 (open ends) only change how CoppeliaSim
/// draws it and are accepted and ignored, as is `precision` (gantry's round shapes are
/// exact primitives, not tessellated).
fn create_pure_shape(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let kind = match a.int(0)? {
        0 => 3,
        1 => 4,
        2 => 5,
        3 => 6,
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 1: invalid primitive type {other} (0 cuboid, 1 sphere, 2 cylinder, 3 cone)"
            )));
        }
    };
    let options = a.int(1)?;
    let sizes = a.floats::<3>(2)?;
    let mass = a.f64(3)?;
    if !(mass.is_finite() && mass > 0.0) {
        return Err(SimError::bad_argument(format!(
            "argument 4: mass must be positive, got {mass}"
        )));
    }
    let (alias, geometry) = primitive(kind, sizes, 3)?;
    let shape = ShapeModel {
        respondable: options & 8 != 0,
        dynamic: options & 16 == 0,
        mass: MassModel::Mass(mass.max(MIN_SHAPE_MASS)),
        ..ShapeModel::single(geometry, [1.0, 1.0, 1.0])
    };
    let h = w.add_object(alias, ObjectKind::Shape(Box::new(shape)), None, Pose::identity())?;
    Ok(vec![Value::Int(h)])
}

/// The alias and geometry of `sim.primitiveshape_*` `kind` with bounding box `sizes`
/// (x, y, z in m; diameters for round shapes), the sizes being argument `sizes_arg`.
fn primitive(kind: i64, sizes: [f64; 3], sizes_arg: usize) -> Result<(&'static str, Geometry), SimError> {
    if let Some(s) = sizes.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(SimError::bad_argument(format!(
            "argument {sizes_arg}: sizes must be positive, got {s}"
        )));
    }
    let [x, y, z] = sizes;
    let thin = 1e-4; // CoppeliaSim's thickness of planes and discs, m
    let (alias, geometry) = match kind {
        1 => (
            "Plane",
            Geometry::Box {
                half_extents: [x / 2.0, y / 2.0, thin / 2.0],
            },
        ),
        2 => (
            "Disc",
            Geometry::Cylinder {
                radius: (x + y) / 4.0,
                length: thin,
            },
        ),
        3 => (
            "Cuboid",
            Geometry::Box {
                half_extents: [x / 2.0, y / 2.0, z / 2.0],
            },
        ),
        4 if x == y && y == z => ("Sphere", Geometry::Sphere { radius: x / 2.0 }),
        4 => ("Sphere", revolved_mesh("spheroid", &sphere_profile(), [x, y, z])),
        5 if x == y => (
            "Cylinder",
            Geometry::Cylinder {
                radius: x / 2.0,
                length: z,
            },
        ),
        5 => (
            "Cylinder",
            revolved_mesh(
                "cylinder",
                &[(0.0, -0.5), (1.0, -0.5), (1.0, 0.5), (0.0, 0.5)],
                [x, y, z],
            ),
        ),
        6 => (
            "Cone",
            revolved_mesh("cone", &[(0.0, -0.5), (1.0, -0.5), (0.0, 0.5)], [x, y, z]),
        ),
        8 => {
            let radius = (x + y) / 4.0;
            (
                "Capsule",
                Geometry::Capsule {
                    radius,
                    length: (z - 2.0 * radius).max(0.0),
                },
            )
        }
        _ => {
            return Err(SimError::bad_argument(format!(
                "argument 1: invalid primitive type {kind} (sim.primitiveshape_plane, _disc, _cuboid, _spheroid, _cylinder, _cone or _capsule)"
            )));
        }
    };
    Ok((alias, geometry))
}

/// The unit half circle from the south to the north pole, as `(radius, z)` pairs.
fn sphere_profile() -> Vec<(f64, f64)> {
    const RINGS: usize = 12;
    (0..=RINGS)
        .map(|i| {
            let a = -PI / 2.0 + PI * i as f64 / RINGS as f64;
            // Exact zeros at the poles, where the ring collapses to one vertex.
            let r = if i == 0 || i == RINGS { 0.0 } else { a.cos() };
            (r, 0.5 * a.sin())
        })
        .collect()
}

/// A closed surface of revolution about Z from a profile of `(radius, z)` pairs (radius
/// 1 and z in -0.5..0.5 at full size, first and last radius 0), scaled to the box
/// `size` (x, y, z in m): how non-round spheroids, elliptic cylinders and cones, which
/// rapier has no primitive for, become (convex) meshes.
fn revolved_mesh(name: &str, profile: &[(f64, f64)], size: [f64; 3]) -> Geometry {
    const SIDES: usize = 32;
    let scale = |r: f64, a: f64, z: f64| {
        [
            (r * a.cos() * size[0] / 2.0) as f32,
            (r * a.sin() * size[1] / 2.0) as f32,
            (z * size[2]) as f32,
        ]
    };
    let mut vertices = Vec::new();
    let mut rings = Vec::new();
    for &(r, z) in profile {
        let start = vertices.len() as u32;
        if r == 0.0 {
            vertices.push(scale(0.0, 0.0, z));
            rings.push((start, 1));
        } else {
            for k in 0..SIDES {
                vertices.push(scale(r, 2.0 * PI * k as f64 / SIDES as f64, z));
            }
            rings.push((start, SIDES as u32));
        }
    }
    let mut indices = Vec::new();
    let n = SIDES as u32;
    for pair in rings.windows(2) {
        let ((a, na), (b, nb)) = (pair[0], pair[1]);
        for k in 0..n {
            let (k1, k2) = (k, (k + 1) % n);
            let at = |start: u32, count: u32, i: u32| if count == 1 { start } else { start + i };
            let (a1, a2, b1, b2) = (at(a, na, k1), at(a, na, k2), at(b, nb, k1), at(b, nb, k2));
            // Counter-clockwise seen from outside, going up the profile.
            if a1 != a2 {
                indices.push([a1, a2, b1]);
            }
            if b1 != b2 {
                indices.push([a2, b2, b1]);
            }
        }
    }
    Geometry::Mesh(Arc::new(MeshData {
        source: PathBuf::from(format!("<{name} primitive>")),
        vertices,
        indices,
        parts: Vec::new(),
    }))
}

/// The most vertices `sim.createMeshShape` takes (a mesh beyond that belongs in a file).
const MAX_MESH_VERTICES: usize = 1_000_000;

/// `sim.createMeshShape(options, shadingAngle, vertices, indices)` → handle: a shape
/// from a triangle mesh, vertices as x, y, z triples (m) and triangles as 0-based index
/// triples, at the world origin, static and not respondable, white, as CoppeliaSim
/// creates it. Options bit 0 (culling) and bit 1 (edges) and the shading angle only
/// change how CoppeliaSim draws it and are accepted and ignored.
fn create_mesh_shape(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    a.int(0)?;
    a.f64(1)?;
    let v = a.numbers(2)?;
    let idx = a.numbers(3)?;
    if v.is_empty() || !v.len().is_multiple_of(3) || v.len() / 3 > MAX_MESH_VERTICES {
        return Err(SimError::bad_argument(format!(
            "argument 3: vertices come as x, y, z triples (1 to {MAX_MESH_VERTICES} of them), got {} numbers",
            v.len()
        )));
    }
    if idx.is_empty() || !idx.len().is_multiple_of(3) || idx.len() > 6 * MAX_MESH_VERTICES {
        return Err(SimError::bad_argument(format!(
            "argument 4: triangles come as index triples, got {} indices",
            idx.len()
        )));
    }
    let n = v.len() / 3;
    let index = |x: f64| -> Result<u32, SimError> {
        if x.fract() == 0.0 && x >= 0.0 && (x as usize) < n {
            Ok(x as u32)
        } else {
            Err(SimError::bad_argument(format!(
                "argument 4: index {x} is not a vertex (0 to {})",
                n - 1
            )))
        }
    };
    let vertices = v
        .chunks_exact(3)
        .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
        .collect();
    let indices = idx
        .chunks_exact(3)
        .map(|c| Ok([index(c[0])?, index(c[1])?, index(c[2])?]))
        .collect::<Result<Vec<_>, SimError>>()?;
    let geometry = Geometry::Mesh(Arc::new(MeshData {
        source: PathBuf::from("<sim.createMeshShape>"),
        vertices,
        indices,
        parts: Vec::new(),
    }));
    let shape = ShapeModel {
        respondable: false,
        dynamic: false,
        ..ShapeModel::single(geometry, [1.0, 1.0, 1.0])
    };
    let h = w.add_object("Shape", ObjectKind::Shape(Box::new(shape)), None, Pose::identity())?;
    Ok(vec![Value::Int(h)])
}

/// `sim.createDummy(size)` → handle, at the world origin. The size (m) only sets how
/// big CoppeliaSim draws it.
fn create_dummy(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    a.finite(0)?;
    let h = w.add_object("Dummy", ObjectKind::Dummy, None, Pose::identity())?;
    Ok(vec![Value::Int(h)])
}

/// `sim.removeObjects(objectHandles)`: all or nothing; children of a removed object move
/// up to its parent.
fn remove_objects(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    sim.remove_objects(&handle_list(a, 0)?)?;
    Ok(Vec::new())
}

/// `sim.removeObject(objectHandle)`: the pre-4.3 name for one object.
fn remove_object(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    sim.remove_objects(&[a.handle(0)?])?;
    Ok(Vec::new())
}

/// `sim.copyPasteObjects(objectHandles, options=0)` → copies' handles, in the given order.
/// Options bit 0: copy whole models for model bases.
fn copy_paste_objects(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let handles = handle_list(a, 0)?;
    let options = a.opt_int(1, 0)?;
    let copies = w.copy_objects(&handles, options & 1 != 0)?;
    Ok(vec![Value::Array(copies.into_iter().map(Value::Int).collect())])
}

/// `sim.setObjectParent(objectHandle, parentHandle, keepInPlace=true)`; a parent of -1
/// makes the object a root.
fn set_object_parent(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let parent = match a.handle(1)? {
        -1 => None,
        p => Some(p),
    };
    let keep = a.opt_bool(2, true)?;
    w.set_parent(h, parent, keep)?;
    Ok(Vec::new())
}

/// `sim.getObjectChild(objectHandle, index)` → the index-th child (0-based, hierarchy
/// order), or -1 past the last.
fn get_object_child(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let index = a.int(1)?;
    w.object(h)?;
    let child = usize::try_from(index)
        .ok()
        .and_then(|i| w.children(h).get(i).copied())
        .unwrap_or(-1);
    Ok(vec![Value::Int(child)])
}

/// `sim.getObjects(index, objectType)` → the index-th object (0-based, creation order)
/// of a type (`sim.handle_all` for any), or -1 past the last.
fn get_objects(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let index = a.int(0)?;
    let kind = a.int(1)?;
    let found = usize::try_from(index).ok().and_then(|i| {
        (0..w.len() as Handle)
            .filter(|&h| w.object(h).is_ok_and(|o| kind == -2 || o.kind.type_code() == kind))
            .nth(i)
    });
    Ok(vec![Value::Int(found.unwrap_or(-1))])
}

/// `sim.setObjectAlias(objectHandle, alias)`. With `sim.handleflag_silenterror` OR-ed onto
/// the handle (4.0-4.2 scripts pass it to `sim.setObjectName`), a missing object or a bad
/// alias is ignored instead of raised; argument types are still checked.
fn set_object_alias(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let raw = a.handle(0)?;
    let silent = raw >= 0 && raw & HANDLEFLAG_SILENT_ERROR != 0;
    let h = if silent { raw & !HANDLEFLAG_SILENT_ERROR } else { raw };
    match w.set_alias(h, a.str(1)?) {
        Err(_) if silent => Ok(Vec::new()),
        r => r.map(|()| Vec::new()),
    }
}

/// The colour name argument: `nil`, `""` and `"@compound"` mean every part; gantry's
/// parts have no names, so any other name matches nothing.
fn all_parts(a: &Args<'_>, i: usize) -> Result<bool, SimError> {
    match a.get(i) {
        Value::Nil => Ok(true),
        _ => Ok(matches!(a.str(i)?, "" | "@compound")),
    }
}

fn color_component(a: &Args<'_>, i: usize) -> Result<ColorComponent, SimError> {
    let c = a.int(i)?;
    ColorComponent::from_code(c).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument {}: invalid color component {c} (sim.colorcomponent_ambient_diffuse .. _auxiliary)",
            i + 1
        ))
    })
}

/// `sim.getShapeColor(shapeHandle, colorName, colorComponent)` → `result, rgbData`:
/// result 1 and the colour when found, 0 and zeros when the name matches no part.
fn get_shape_color(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let all = all_parts(a, 1)?;
    let component = color_component(a, 2)?;
    let color = w.shape_color(h, component)?.filter(|_| all);
    Ok(match color {
        Some(c) => vec![Value::Int(1), Value::floats(&c)],
        None => vec![Value::Int(0), Value::floats(&vec![0.0; component.value_count()])],
    })
}

/// `sim.setShapeColor(shapeHandle, colorName, colorComponent, rgbData)`: 3 values in
/// 0..1 (1 for transparency).
fn set_shape_color(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let all = all_parts(a, 1)?;
    let component = color_component(a, 2)?;
    let values: Vec<f64> = match a.get(3) {
        Value::Array(items) => items.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect(),
        other => {
            return Err(SimError::bad_argument(format!(
                "argument 4: expected table of numbers, got {}",
                other.type_name()
            )));
        }
    };
    w.shape(h)?;
    if all {
        w.set_shape_color(h, component, &values)?;
    }
    Ok(Vec::new())
}

/// `sim.getObjectColor(objectHandle, index, colorComponent)` → `rgbData`, or nil when
/// the object has no colour `index` (CoppeliaSim 4.8's form of `sim.getShapeColor`: a
/// shape has one colour, index 0).
fn get_object_color(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let index = a.int(1)?;
    let component = color_component(a, 2)?;
    if index != 0 || !matches!(w.object(h)?.kind, ObjectKind::Shape(_)) {
        return Ok(vec![Value::Nil]);
    }
    Ok(vec![
        w.shape_color(h, component)?.map_or(Value::Nil, |c| Value::floats(&c)),
    ])
}

/// `sim.setObjectColor(objectHandle, index, colorComponent, rgbData)` → whether the
/// object has colour `index` (a shape has one, index 0) and it was set.
fn set_object_color(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let index = a.int(1)?;
    color_component(a, 2)?;
    if index != 0 || !matches!(w.object(h)?.kind, ObjectKind::Shape(_)) {
        return Ok(vec![Value::Bool(false)]);
    }
    let args = [Value::Int(h), Value::Nil, a.get(2).clone(), a.get(3).clone()];
    set_shape_color(w, ctx, &Args::new(&args))?;
    Ok(vec![Value::Bool(true)])
}

/// `sim.getShapeMass(shapeHandle)` → kg.
fn get_shape_mass(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.shape_mass(a.handle(0)?)?)])
}

/// `sim.setShapeMass(shapeHandle, mass)`, kg.
fn set_shape_mass(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.set_shape_mass(h, a.finite(1)?)?;
    Ok(Vec::new())
}

/// `sim.setShapeBB(shapeHandle, size)`: scales the shape along its own axes so that its
/// bounding box (as `sim.getShapeBB` gives it) becomes `size`, m.
fn set_shape_bb(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let size = a.vec3(1)?;
    w.shape(h)?;
    let (lo, hi) = w.bounding_box(h)?;
    let mut factors = [1.0; 3];
    for k in 0..3 {
        let now = hi[k] - lo[k];
        if !(size[k].is_finite() && size[k] > 0.0) {
            return Err(SimError::bad_argument(format!(
                "sizes must be finite and > 0, got {:?}",
                size.as_slice()
            )));
        }
        if now <= 0.0 {
            return Err(SimError::refused(
                "the shape is flat along an axis and cannot be stretched along it",
            ));
        }
        factors[k] = size[k] / now;
    }
    w.scale_shape(h, factors)?;
    Ok(Vec::new())
}

/// `sim.scaleObject(objectHandle, xScale, yScale, zScale, options=0)`: scales a shape along
/// its own axes (its mass at the same density). gantry scales shapes only.
fn scale_object(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let factors = [a.finite(1)?, a.finite(2)?, a.finite(3)?];
    w.scale_shape(h, factors)?;
    Ok(Vec::new())
}

/// Splits `sim.handleflag_resetforce` / `_resettorque` off a handle and applies them.
fn flagged_handle(w: &mut World, raw: i64) -> Result<Handle, SimError> {
    let h = raw & !(RESET_FORCE | RESET_TORQUE);
    let (force, torque) = (raw & RESET_FORCE != 0, raw & RESET_TORQUE != 0);
    if force || torque {
        w.reset_force(h, force, torque)?;
    }
    Ok(h)
}

/// `sim.addForce(shapeHandle, position, force)`: a force (N) at a point (m), both in
/// absolute coordinates, on a dynamic shape for the next simulation step only.
fn add_force(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = flagged_handle(w, a.handle(0)?)?;
    let at = a.vec3(1)?;
    let force = a.vec3(2)?;
    w.add_force(h, force, Some(at), Vec3::zeros())?;
    Ok(Vec::new())
}

/// `sim.addForceAndTorque(shapeHandle, force=nil, torque=nil)`: a force (N) at the centre
/// of mass and a torque (N·m), absolute coordinates, for the next simulation step only.
fn add_force_and_torque(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = flagged_handle(w, a.handle(0)?)?;
    let opt = |i: usize| match a.get(i) {
        Value::Nil => Ok(Vec3::zeros()),
        _ => a.vec3(i),
    };
    let (force, torque) = (opt(1)?, opt(2)?);
    w.add_force(h, force, None, torque)?;
    Ok(Vec::new())
}

/// `sim.resetDynamicObject(objectHandle)`: the object and everything below it leave the
/// physics engine and come back at rest where they are; `sim.handle_all` resets the
/// whole scene.
fn reset_dynamic_object(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    match a.handle(0)? {
        -2 => {
            for h in w.roots().to_vec() {
                w.reset_dynamics(h)?;
            }
        }
        h => w.reset_dynamics(h)?,
    }
    Ok(Vec::new())
}

/// `sim.setJointMode(jointHandle, jointMode, options=0)`: `sim.jointmode_kinematic` (0),
/// CoppeliaSim 4.1's `sim.jointmode_ik` (2: kinematic, moved by IK groups) or
/// `sim.jointmode_dynamic` (5; a joint that was kinematic becomes position-controlled
/// and holds where it is). `sim.jointmode_dependent` (4) exists only for URDF `<mimic>`
/// followers, which already are.
fn set_joint_mode(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let mode = a.int(1)?;
    a.opt_int(2, 0)?;
    let joint = w.joint(h)?;
    let new = match mode {
        0 | 2 => JointMode::Kinematic,
        5 if joint.mode.is_dynamic() => joint.mode,
        5 => JointMode::Position,
        4 if joint.mimic.is_some() => joint.mode,
        4 => {
            return Err(SimError::bad_argument(
                "argument 2: gantry has dependent joints only as URDF <mimic> followers",
            ));
        }
        _ => {
            return Err(SimError::bad_argument(format!(
                "argument 2: invalid joint mode {mode} (sim.jointmode_kinematic, sim.jointmode_ik or sim.jointmode_dynamic)"
            )));
        }
    };
    w.set_joint_mode(h, new)?;
    if mode == 2 {
        w.set_joint_ik_mode(h, true)?;
    }
    Ok(Vec::new())
}

/// `sim.getJointMode(jointHandle)` → `jointMode, options`: 0 kinematic, 2 kinematic in
/// CoppeliaSim 4.1's IK mode, 4 a `<mimic>` follower, 5 dynamic; options are always 0.
fn get_joint_mode(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let j = w.joint(a.handle(0)?)?;
    let mode = match j.mode {
        _ if j.mimic.is_some() => 4,
        JointMode::Kinematic if j.ik_mode => 2,
        JointMode::Kinematic => 0,
        _ => 5,
    };
    Ok(vec![Value::Int(mode), Value::Int(0)])
}

/// `sim.getJointMaxForce(jointHandle)` → the motor's largest torque (N·m) or force (N).
fn get_joint_max_force(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.joint(a.handle(0)?)?.max_force)])
}

/// `sim.getJointTargetForce(jointHandle)` → `sim.setJointTargetForce`'s value, signed.
fn get_joint_target_force(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![Value::Float(w.joint(a.handle(0)?)?.target_force)])
}

/// `sim.setJointMaxForce(jointHandle, forceOrTorque)`: the pre-4.3 name of
/// `sim.setJointTargetForce`.
fn set_joint_max_force(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    w.set_joint_max_force(h, a.finite(1)?)?;
    Ok(Vec::new())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn revolved_meshes_are_closed_and_sized() {
        for (profile, top) in [
            (vec![(0.0, -0.5), (1.0, -0.5), (0.0, 0.5)], 0.5),
            (sphere_profile(), 0.5),
        ] {
            let Geometry::Mesh(m) = revolved_mesh("t", &profile, [0.2, 0.4, 1.0]) else {
                panic!("a mesh")
            };
            // Closed: every edge is shared by exactly two triangles.
            let mut edges = std::collections::HashMap::new();
            for t in &m.indices {
                for k in 0..3 {
                    let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                    *edges.entry((a, b)).or_insert(0) += 1;
                }
            }
            assert!(edges.values().all(|&n| n == 2), "open mesh");
            let max = |i: usize| m.vertices.iter().map(|v| v[i]).fold(f32::MIN, f32::max);
            assert!((max(0) - 0.1).abs() < 1e-6 && (max(1) - 0.2).abs() < 1e-6);
            assert!((max(2) - top).abs() < 1e-6);
        }
    }
}
