//! CoppeliaSim shapes to [`ShapeModel`]s: geometry per mesh leaf, mass, flags.
//!
//! Each leaf keeps its vertex frame (`GeomModel::local`). Boxes, round spheres and round
//! cylinders become primitives; everything else (planes, discs, cones, ellipsoids,
//! heightfields, capsules, free meshes) becomes its stored triangles, which are exact for
//! drawing, and for a dynamic shape each leaf is one convex part, as CoppeliaSim builds
//! respondable links from convex parts.
//!
//! Mass: a dynamic shape carries its stored mass, centre of mass and inertia. A static
//! shape carries none: CoppeliaSim ignores a static shape's stored mass, but gantry would
//! add a static shape hanging on a dynamic one to that body's mass (the `linkN_visible`
//! children of every library robot store kilograms), so it gets zero.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use gantry_coppelia_file as cf;

use crate::scene::model::{
    GeomModel, Geometry, MassModel, MeshData, ShapeModel, TextureModel, VisualModel, VisualTexture,
};

use super::pose::to_pose;

/// Colour of a leaf that stores none: CoppeliaSim's default grey.
const DEFAULT_COLOUR: [f32; 3] = [0.8, 0.8, 0.8];

/// Relative tolerance under which two sizes count as equal (a round sphere or cylinder).
const ROUND: f64 = 1e-6;

/// Converts one shape; `detectable` and `measurable` are the object's flags.
pub fn convert(
    shape: &cf::Shape,
    name: &str,
    source: &Path,
    detectable: bool,
    measurable: bool,
    warnings: &mut Vec<String>,
) -> ShapeModel {
    let mut geoms = Vec::with_capacity(shape.leaves.len());
    let mut visuals = Vec::with_capacity(shape.leaves.len());
    for (k, leaf) in shape.leaves.iter().enumerate() {
        let geometry = geometry(leaf, source, &format!("{name}#{k}"));
        let local = to_pose(&leaf.frame);
        visuals.push(VisualModel {
            geometry: geometry.clone(),
            local,
            color: leaf.colour.unwrap_or(DEFAULT_COLOUR),
            texture: None,
        });
        geoms.push(GeomModel { geometry, local });
    }
    let mass = if shape.dynamic {
        let i = shape.inertia_per_kg;
        let m = shape.mass;
        MassModel::Inertial {
            mass: m,
            com: shape.centre_of_mass,
            // The inertia is already in shape-frame axes: identity frame, [x, y, z, w].
            frame: [0.0, 0.0, 0.0, 1.0],
            inertia: [
                i[0][0] * m,
                i[0][1] * m,
                i[0][2] * m,
                i[1][1] * m,
                i[1][2] * m,
                i[2][2] * m,
            ],
        }
    } else {
        MassModel::Mass(0.0)
    };
    // CoppeliaSim's mask: the low byte filters shapes of the same model, the high byte
    // shapes of other models. gantry has one group/mask pair; the model-local bits
    // decide whether a mechanism's links collide with each other.
    let local_bits = shape.respondable_mask & 0x00ff;
    let global_bits = shape.respondable_mask >> 8;
    if shape.respondable && global_bits != 0xff {
        warnings.push(format!(
            "{name}: respondable mask {:#06x} approximated (gantry collides it with every other model)",
            shape.respondable_mask
        ));
    }
    ShapeModel {
        geoms,
        visuals,
        dynamic: shape.dynamic,
        mass,
        friction: shape.friction.unwrap_or(0.5),
        restitution: shape.restitution.unwrap_or(0.0).clamp(0.0, 1.0),
        collision_group: u32::MAX,
        collision_mask: u32::MAX,
        respondable: shape.respondable,
        detectable,
        measurable,
        // The object's flag, set by the caller with the other object-level ones.
        collidable: true,
        self_collision: local_bits != 0,
    }
}

/// The file's texture objects as the scene's (rows turned top first), and each file id's
/// index among them.
pub fn convert_textures(file: &cf::CoppeliaFile) -> (Vec<TextureModel>, HashMap<i32, usize>) {
    let mut textures = Vec::with_capacity(file.textures.len());
    let mut index = HashMap::new();
    for t in &file.textures {
        let row = t.resolution[0] as usize * 4;
        // The reader checked the length against the resolution; rows are whole.
        let rgba: Vec<u8> = t.rgba.chunks_exact(row).rev().flatten().copied().collect();
        index.insert(t.id, textures.len());
        textures.push(TextureModel {
            name: t.name.clone(),
            resolution: t.resolution,
            rgba: Arc::new(rgba),
        });
    }
    (textures, index)
}

/// Puts on each visual of `shape` (one per leaf, in leaf order, as [`convert`] makes
/// them) the texture its leaf wears. A vision sensor's image as texture, or a texture
/// id the file lacks, is warned and left off.
pub fn attach_textures(
    shape: &mut ShapeModel,
    leaves: &[cf::ShapeLeaf],
    textures: &HashMap<i32, usize>,
    name: &str,
    warnings: &mut Vec<String>,
) {
    for (visual, leaf) in shape.visuals.iter_mut().zip(leaves) {
        let Some(t) = &leaf.texture else { continue };
        let Some(&texture) = textures.get(&t.texture) else {
            let why = if t.from_vision_sensor() {
                format!("wears the image of vision sensor {}", t.texture)
            } else {
                format!("names texture {}, which the file lacks", t.texture)
            };
            warnings.push(format!("{name}: {why}; left untextured"));
            continue;
        };
        let mapping = match t.mapping {
            cf::TextureMapping::Plane => 0,
            cf::TextureMapping::Cylinder => 1,
            cf::TextureMapping::Sphere => 2,
            cf::TextureMapping::Cube => 3,
            cf::TextureMapping::Other(code) => {
                warnings.push(format!("{name}: texture mapping {code} unknown; projected as a plane"));
                0
            }
        };
        let options = i64::from(!t.interpolate)
            | if t.apply_mode == 1 { 2 } else { 0 }
            | if t.repeat_u { 4 } else { 0 }
            | if t.repeat_v { 8 } else { 0 };
        visual.texture = Some(VisualTexture {
            texture,
            mapping,
            options,
            scaling: t.scaling,
            frame: to_pose(&t.frame),
            coordinates: t.coordinates.as_ref().map(|c| Arc::new(c.to_vec())),
        });
    }
}

/// The geometry of one leaf, in its vertex frame.
fn geometry(leaf: &cf::ShapeLeaf, source: &Path, label: &str) -> Geometry {
    let [x, y, z] = leaf.size;
    let round = |a: f64, b: f64| (a - b).abs() <= ROUND * a.abs().max(b.abs());
    let positive = leaf.size.iter().all(|s| s.is_finite() && *s > 0.0);
    match leaf.primitive {
        cf::PrimitiveKind::Cuboid if positive => {
            return Geometry::Box {
                half_extents: [x / 2.0, y / 2.0, z / 2.0],
            };
        }
        cf::PrimitiveKind::Spheroid if positive && round(x, y) && round(y, z) => {
            return Geometry::Sphere { radius: x / 2.0 };
        }
        cf::PrimitiveKind::Cylinder if positive && round(x, y) => {
            return Geometry::Cylinder {
                radius: x / 2.0,
                length: z,
            };
        }
        _ => {}
    }
    let vertices = leaf.vertices.to_vec();
    let indices = leaf.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    // On a dynamic body the leaf collides as its convex hull (empty `parts`), one
    // convex part per leaf as in CoppeliaSim.
    Geometry::Mesh(Arc::new(MeshData {
        source: source.join(label),
        vertices,
        indices,
        parts: Vec::new(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leaf(primitive: cf::PrimitiveKind, size: [f64; 3]) -> cf::ShapeLeaf {
        cf::ShapeLeaf {
            name: "sub__0".into(),
            mass: 1.0,
            frame: cf::Pose::new([1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.25]),
            primitive,
            size,
            colour: None,
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].into(),
            indices: vec![0, 1, 2].into(),
            normals: None,
            texture: None,
        }
    }

    #[test]
    fn primitives_map_when_they_fit_and_meshes_otherwise() {
        let p = Path::new("x.ttt");
        let g = |l: &cf::ShapeLeaf| geometry(l, p, "s");
        assert!(matches!(g(&leaf(cf::PrimitiveKind::Cuboid, [0.2, 0.4, 0.6])),
            Geometry::Box { half_extents } if half_extents == [0.1, 0.2, 0.3]));
        assert!(matches!(g(&leaf(cf::PrimitiveKind::Spheroid, [0.2, 0.2, 0.2])),
            Geometry::Sphere { radius } if radius == 0.1));
        assert!(matches!(g(&leaf(cf::PrimitiveKind::Cylinder, [0.2, 0.2, 0.5])),
            Geometry::Cylinder { radius, length } if radius == 0.1 && length == 0.5));
        // An ellipsoid, an elliptic cylinder, a cone, a zero-size box: the triangles.
        for l in [
            leaf(cf::PrimitiveKind::Spheroid, [0.2, 0.3, 0.2]),
            leaf(cf::PrimitiveKind::Cylinder, [0.2, 0.3, 0.5]),
            leaf(cf::PrimitiveKind::Cone, [0.2, 0.2, 0.5]),
            leaf(cf::PrimitiveKind::Cuboid, [0.0, 0.2, 0.5]),
        ] {
            let Geometry::Mesh(m) = g(&l) else {
                panic!("{:?} should be a mesh", l.primitive)
            };
            assert_eq!(m.indices, vec![[0, 1, 2]]);
        }
    }

    #[test]
    fn static_shapes_carry_no_mass_and_dynamic_ones_their_inertia() {
        let mut s = cf::Shape {
            dynamic: true,
            respondable: true,
            respondable_mask: 0xff00,
            mass: 2.0,
            centre_of_mass: [0.0, 0.0, 0.1],
            inertia_per_kg: [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]],
            friction: Some(0.7),
            restitution: None,
            compound: false,
            leaves: vec![leaf(cf::PrimitiveKind::Cuboid, [0.2, 0.2, 0.2])],
        };
        let mut w = Vec::new();
        let m = convert(&s, "link", Path::new("x.ttt"), true, true, &mut w);
        let MassModel::Inertial { mass, com, inertia, .. } = m.mass else {
            panic!("inertial")
        };
        assert_eq!(
            (mass, com, inertia),
            (2.0, [0.0, 0.0, 0.1], [2.0, 0.0, 0.0, 4.0, 0.0, 6.0])
        );
        assert!(!m.self_collision && m.friction == 0.7 && w.is_empty());
        assert_eq!(m.geoms[0].local.translation.vector.z, 0.25);
        s.dynamic = false;
        s.respondable_mask = 0x00ff;
        let m = convert(&s, "link_visible", Path::new("x.ttt"), true, true, &mut w);
        assert_eq!(m.mass, MassModel::Mass(0.0));
        assert!(m.self_collision);
        assert_eq!(w.len(), 1, "{w:?}");
    }
}
