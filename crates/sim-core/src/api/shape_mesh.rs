//! Shapes as meshes: importing them from files (`sim.importShape`, `sim.importMesh`),
//! reading them back (`sim.getShapeMesh`, `sim.getShapeViz`), and the mesh operations
//! (`sim.getDecimatedMesh`, `sim.convexDecompose`, `sim.reorientShapeBoundingBox`).
//!
//! Mesh files are read by the scene loader (`scene::load_mesh`: OBJ, STL, COLLADA), so
//! a file imports as it would load in a scene. Files are read from where the API may
//! read files (the scene's folder unless the host allows more), as `sim.loadImage`.

use std::collections::HashMap;
use std::path::Path;

use super::image_file::confined;
use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::math::Pose;
use crate::scene::{DiskFiles, GeomModel, Geometry, ShapeModel, VisualModel, load_mesh};
use crate::sim::Sim;
use crate::world::{ColorComponent, ObjectKind, ShapeMesh, World, decimate, mesh_data, mesh_from_lists};

/// The mesh functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "convexDecompose",
        call: ApiFn::World(convex_decompose),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getDecimatedMesh",
        call: ApiFn::World(get_decimated_mesh),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "getShapeMesh",
        call: ApiFn::World(get_shape_mesh),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getShapeViz",
        call: ApiFn::World(get_shape_viz),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "importMesh",
        call: ApiFn::Sim(import_mesh),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "importShape",
        call: ApiFn::Sim(import_shape),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "reorientShapeBoundingBox",
        call: ApiFn::World(reorient_shape_bounding_box),
        cost: Cost::Quick,
    },
];

/// `options` bit of the import functions: keep identical vertices (otherwise vertices
/// at the same place are merged into one).
const KEEP_IDENTICAL_VERTICES: i64 = 1;
/// `options` bit of `sim.convexDecompose`: morph the shape into its decomposition
/// instead of creating a new shape.
const MORPH: i64 = 1;
/// The shading angle gantry reports for every shape, rad (CoppeliaSim's default for
/// imported meshes, 20°); gantry shades imported meshes flat and primitives smooth.
const SHADING_ANGLE: f64 = 20.0 * std::f64::consts::PI / 180.0;

/// A mesh file read through the scene loader, scaled, its identical vertices merged
/// unless `keep_identical`.
fn read_mesh(sim: &Sim, a: &Args<'_>) -> Result<(std::path::PathBuf, ShapeMesh, crate::scene::MeshData), SimError> {
    let format = a.int(0)?;
    let filename = a.str(1)?;
    let options = a.int(2)?;
    let tolerance = a.opt_f64(3, 0.0)?;
    let scale = a.opt_f64(4, 1.0)?;
    // CoppeliaSim's format codes (0 OBJ, 1 DXF, 2 3DS, 3 ASCII STL, 4 binary STL, 5
    // COLLADA); PyRep passes 0 for any file. gantry tells the format by the extension.
    if !(0..=5).contains(&format) {
        return Err(SimError::bad_argument(format!(
            "argument 1: file format {format} is not 0 to 5 (gantry reads the format from the file's extension)"
        )));
    }
    if !(scale.is_finite() && scale != 0.0 && tolerance.is_finite() && tolerance >= 0.0) {
        return Err(SimError::bad_argument(format!(
            "the scaling factor must be finite and not 0 (got {scale}), the vertex tolerance finite and not negative (got {tolerance})"
        )));
    }
    let path = confined(sim, filename, "read")?;
    if !path.is_file() {
        return Err(SimError::bad_argument(format!(
            "argument 2: no file '{}'",
            path.display()
        )));
    }
    let data = load_mesh(&DiskFiles, &path, [scale; 3]).map_err(|e| SimError::bad_argument(e.to_string()))?;
    let mut mesh = ShapeMesh {
        vertices: data.vertices.iter().map(|v| v.map(f64::from)).collect(),
        indices: data.indices.clone(),
    };
    if mesh.vertices.iter().flatten().any(|c| !c.is_finite()) {
        return Err(SimError::bad_argument(format!(
            "'{}' has vertices that are not finite",
            path.display()
        )));
    }
    if options & KEEP_IDENTICAL_VERTICES == 0 {
        mesh = weld(&mesh, tolerance);
    }
    Ok((path, mesh, (*data).clone()))
}

/// The mesh with vertices closer than `tolerance` (m; 0: at the same place) merged, the
/// first of each group kept, and the triangles left with fewer than three corners dropped.
fn weld(mesh: &ShapeMesh, tolerance: f64) -> ShapeMesh {
    let mut ids: HashMap<[i64; 3], u32> = HashMap::new();
    let mut vertices = Vec::new();
    let key = |v: &[f64; 3]| {
        if tolerance > 0.0 {
            v.map(|c| (c / tolerance).round() as i64)
        } else {
            // The bits of each coordinate (with -0 as 0): equal places only.
            v.map(|c| (c + 0.0).to_bits() as i64)
        }
    };
    let map: Vec<u32> = mesh
        .vertices
        .iter()
        .map(|v| {
            *ids.entry(key(v)).or_insert_with(|| {
                vertices.push(*v);
                vertices.len() as u32 - 1
            })
        })
        .collect();
    let indices = mesh
        .indices
        .iter()
        .map(|t| t.map(|i| map[i as usize]))
        .filter(|[a, b, c]| a != b && b != c && a != c)
        .collect();
    ShapeMesh { vertices, indices }
}

/// Flat lists of a mesh: vertices, then indices.
fn lists(m: &ShapeMesh) -> (Value, Value) {
    (
        Value::floats(&m.vertices.concat()),
        Value::Array(m.indices.iter().flatten().map(|&i| Value::Int(i64::from(i))).collect()),
    )
}

/// The normals of a mesh as `sim.getShapeMesh` gives them: 3 numbers per index, each
/// corner carrying its triangle's normal (gantry's meshes are shaded flat).
fn corner_normals(m: &ShapeMesh) -> Value {
    Value::floats(
        &m.face_normals()
            .iter()
            .flat_map(|n| [*n; 3])
            .flatten()
            .collect::<Vec<f64>>(),
    )
}

/// `sim.importMesh(fileformat, pathAndFilename, options, identicalVerticeTolerance,
/// scalingFactor)` → `vertices, indices`: one table per mesh of the file (gantry merges
/// a file's sub-meshes into one, so there is one), vertices in metres after scaling.
/// Option bit 0 keeps identical vertices; otherwise vertices within the tolerance (m)
/// are merged. gantry does not turn Y-up files to Z-up (option bit 7 changes nothing).
fn import_mesh(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (_, mesh, _) = read_mesh(sim, a)?;
    let (v, i) = lists(&mesh);
    Ok(vec![Value::Array(vec![v]), Value::Array(vec![i])])
}

/// `sim.importShape(fileformat, pathAndFilename, options, identicalVerticeTolerance,
/// scalingFactor)` → the handle of a new static, non-respondable shape made of the
/// file's mesh, at the world origin, named after the file. A multi-part OBJ keeps its
/// sections as the convex parts it collides with once made dynamic. gantry reads no
/// colours or textures from the file (option bits 3 and 4 change nothing) and keeps
/// the file's frame (bit 5 does not reorient the bounding box).
fn import_shape(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let (path, mesh, data) = read_mesh(sim, a)?;
    let name = alias_of(&path);
    let mut geometry = mesh_data(&mesh, &path.to_string_lossy());
    if let Some(d) = std::sync::Arc::get_mut(&mut geometry) {
        d.parts = data.parts;
    }
    let shape = ShapeModel {
        respondable: false,
        dynamic: false,
        ..ShapeModel::single(Geometry::Mesh(geometry), [0.7, 0.7, 0.7])
    };
    let h = sim
        .world
        .add_object(&name, ObjectKind::Shape(Box::new(shape)), None, Pose::identity())?;
    Ok(vec![Value::Int(h)])
}

/// An alias from a file name: its stem with characters CoppeliaSim does not allow in
/// aliases replaced by `_`.
fn alias_of(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let alias: String = stem
        .chars()
        .map(|c| if c.is_alphanumeric() || c == '_' { c } else { '_' })
        .collect();
    if alias.is_empty() { "Shape".to_owned() } else { alias }
}

/// `sim.getShapeMesh(shapeHandle)` → `vertices, indices, normals`: the shape's mesh in
/// its own frame (vertices 3 numbers each, m; indices 3 per triangle), every visual part
/// of a compound one after the other; normals 3 numbers per index. Primitives are
/// tessellated (a box has 8 vertices and 12 triangles).
fn get_shape_mesh(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let m = w.shape_mesh(a.handle(0)?)?;
    let (v, i) = lists(&m);
    Ok(vec![v, i, corner_normals(&m)])
}

/// `sim.getShapeViz(shapeHandle, itemIndex)` → a map of visual part `itemIndex` (0 for
/// a simple shape): `vertices` (shape frame), `indices`, `normals` (3 per index),
/// `colors` (9: ambient-diffuse, specular, emission), `shadingAngle`, and, when the
/// shape wears a texture, `texture`: `texture` (RGBA bytes, rows from the top), `id`,
/// `resolution`, `coordinates` (u, v per index), `applyMode` and `options`.
fn get_shape_viz(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let item = a.int(1)?;
    let parts = w.shape_part_meshes(h)?;
    let index = usize::try_from(item).ok().filter(|&i| i < parts.len()).ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument 2: shape {h} has {} visual items (0 to {}), got {item}",
            parts.len(),
            parts.len().saturating_sub(1)
        ))
    })?;
    let (mesh, color) = &parts[index];
    let mut colors: Vec<f64> = color.iter().map(|&c| f64::from(c)).collect();
    for component in [ColorComponent::Specular, ColorComponent::Emission] {
        let c = w.shape_color(h, component)?.unwrap_or_else(|| vec![0.0; 3]);
        colors.extend(c.iter().take(3));
    }
    let (v, i) = lists(mesh);
    let mut map = vec![
        (Value::from("vertices"), v),
        (Value::from("indices"), i),
        (Value::from("normals"), corner_normals(mesh)),
        (Value::from("colors"), Value::floats(&colors)),
        (Value::from("shadingAngle"), Value::Float(SHADING_ANGLE)),
    ];
    if let Some(t) = w.shape_texture(h)?.cloned() {
        // The part's triangles start after those of the parts before it.
        let first: usize = parts[..index].iter().map(|(m, _)| m.indices.len()).sum();
        let coordinates = super::textures::coordinates(w, h, &t)?;
        let mine = coordinates
            .get(first * 6..(first + mesh.indices.len()) * 6)
            .unwrap_or_default();
        let image = w.textures().get(t.id)?;
        let [rw, rh] = image.resolution;
        map.push((
            Value::from("texture"),
            Value::Map(vec![
                (Value::from("texture"), Value::Bytes(image.rgba.to_vec())),
                (Value::from("id"), Value::Int(t.id)),
                (
                    Value::from("resolution"),
                    Value::Array(vec![Value::Int(i64::from(rw)), Value::Int(i64::from(rh))]),
                ),
                (
                    Value::from("coordinates"),
                    Value::floats(&mine.iter().map(|&c| f64::from(c)).collect::<Vec<f64>>()),
                ),
                (Value::from("applyMode"), Value::Int(t.mapping.code())),
                (Value::from("options"), Value::Int(t.options)),
            ]),
        ));
    }
    Ok(vec![Value::Map(map)])
}

/// `sim.getDecimatedMesh(vertices, indices, decimationPercentage)` → `vertices,
/// indices`: a coarser mesh with at most `decimationPercentage` (0.1 to 0.9, a share of
/// the triangles) of the triangles, by vertex clustering (each vertex moves to the mean
/// of its grid cell; the finest grid that reaches the share is taken).
fn get_decimated_mesh(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let mesh = mesh_from_lists(&a.numbers(0)?, &a.numbers(1)?)?;
    let keep = a.finite(2)?;
    if !(0.1..=0.9).contains(&keep) {
        return Err(SimError::bad_argument(format!(
            "argument 3: the decimation percentage is a share of the triangles from 0.1 to 0.9, got {keep}"
        )));
    }
    let (v, i) = lists(&decimate(&mesh, keep)?);
    Ok(vec![v, i])
}

/// `sim.convexDecompose(shapeHandle, options, intParams, floatParams)` → the handle of
/// a compound shape made of convex parts that cover the shape's mesh (V-HACD, parry's
/// default parameters: CoppeliaSim's HACD and V-HACD parameters are read and not used),
/// at the shape's pose, static and non-respondable like an imported shape; with option
/// bit 0 (morph) the shape itself takes those parts as its collision geometry and its
/// handle is returned.
fn convex_decompose(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let options = a.int(1)?;
    let parts = w.convex_decomposition(h)?;
    let geoms: Vec<GeomModel> = parts
        .iter()
        .map(|m| GeomModel {
            geometry: Geometry::Mesh(mesh_data(m, "<sim.convexDecompose>")),
            local: Pose::identity(),
        })
        .collect();
    if options & MORPH != 0 {
        w.set_shape_collision_parts(h, geoms)?;
        return Ok(vec![Value::Int(h)]);
    }
    let color = w.shape_part_meshes(h)?.first().map_or([0.7; 3], |p| p.1);
    let shape = ShapeModel {
        visuals: geoms
            .iter()
            .map(|g| VisualModel {
                geometry: g.geometry.clone(),
                local: g.local,
                color,
                texture: None,
            })
            .collect(),
        geoms,
        respondable: false,
        dynamic: false,
        ..ShapeModel::single(Geometry::Sphere { radius: 1.0 }, color)
    };
    let pose = w.object(h)?.world;
    let alias = format!("{}_convex", w.object(h)?.alias);
    let d = w.add_object(&alias, ObjectKind::Shape(Box::new(shape)), None, pose)?;
    Ok(vec![Value::Int(d)])
}

/// `sim.handle_self` for `sim.reorientShapeBoundingBox`: the smallest bounding box.
const HANDLE_SELF: i64 = -4;

/// `sim.reorientShapeBoundingBox(shapeHandle, relativeToHandle)` → 1: turns the shape's
/// frame (about its origin; the geometry and the children stay in place in the world) so
/// that its bounding box is aligned with the frame of `relativeToHandle` (-1: the world;
/// `sim.handle_self`: the smallest box, taken along the mesh's principal axes).
fn reorient_shape_bounding_box(w: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = a.handle(0)?;
    let relative = a.int(1)?;
    let rotation = match relative {
        -1 => crate::math::Quat::identity(),
        HANDLE_SELF => w.shape_principal_axes(h)?,
        other => w.object(other)?.world.rotation,
    };
    w.reorient_shape_frame(h, rotation)?;
    Ok(vec![Value::Int(1)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn welding_merges_equal_places_and_drops_collapsed_triangles() {
        let m = ShapeMesh {
            vertices: vec![
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [-0.0, 0.0, 0.0],
                [1.0, 0.0, 1e-9],
            ],
            indices: vec![[0, 1, 2], [3, 1, 2], [0, 3, 1]],
        };
        // -0 joins 0; the vertex 1 nm off stays apart.
        let exact = weld(&m, 0.0);
        assert_eq!(exact.vertices.len(), 4, "{:?}", exact.vertices);
        assert_eq!(exact.indices, [[0, 1, 2], [0, 1, 2]]);
        // With a tolerance, the vertex 1 nm away joins too.
        let loose = weld(
            &ShapeMesh {
                indices: vec![[0, 1, 2], [4, 2, 0]],
                ..m
            },
            1e-6,
        );
        assert_eq!(loose.indices, [[0, 1, 2], [1, 2, 0]]);
    }

    #[test]
    fn aliases_come_from_file_stems() {
        assert_eq!(alias_of(Path::new("/a/test_mesh-bowl.obj")), "test_mesh_bowl");
        assert_eq!(alias_of(Path::new("/")), "Shape");
    }
}
