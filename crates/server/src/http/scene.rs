//! The scene description a viewer gets once when it connects: the object tree (handles,
//! aliases, parents, paths), every shape's visual geometry and colour, joints with their
//! limits, sensor volumes, cameras (viewpoints the page can look through), and the
//! triangle meshes as binary messages.
//!
//! Each object's `path` is `sim.getObjectAlias(h, 2)` (the full path, `[n]` where
//! siblings share an alias), from sim-core's one implementation, so the page never
//! rebuilds it.
//!
//! Objects are listed in [`World::handles`] order (parents first), and the pose stream
//! ([`super::frame`]) indexes objects, joints and proximity sensors in that same order.
//! The description carries [`World::scene_revision`]; a frame with another revision
//! (objects created, removed, re-parented, restyled) makes the session send it again.
//! Shapes on visibility layer 0 are sent without visuals, so the page does not draw them.
//!
//! A textured shape's visuals also name a textured part ([`MSG_TEXTURED_PART`]: the
//! part's triangles with the u, v of each corner, as vision sensors draw them) and an
//! image ([`MSG_TEXTURE`], each texture object once); the page draws the part with the
//! image, and the plain geometry until both have arrived.

use std::sync::Arc;

use gantry_sim_core::scene::{Geometry, JointType, MeshData, Projection, ProximityModel};
use gantry_sim_core::vision::{TexturedPart, textured_parts};
use gantry_sim_core::world::object_path::full_paths;
use gantry_sim_core::world::{ObjectKind, Texture, World};
use serde_json::{Value as Json, json};

use super::frame::pose_f32;

/// Binary message type of a triangle mesh (the first little-endian `u32`).
pub const MSG_MESH: u32 = 3;
/// Most triangles sent per mesh; larger meshes are sent decimated by dropping triangles
/// (rare for URDF visuals, and the page would struggle anyway).
pub const MAX_MESH_TRIANGLES: usize = 500_000;

/// Binary message type of a textured visual part (the first little-endian `u32`).
pub const MSG_TEXTURED_PART: u32 = 6;
/// Binary message type of a texture image.
pub const MSG_TEXTURE: u32 = 7;
/// Largest texture side sent: larger images (up to the store's 4096) are sent resampled
/// to it, so one texture is at most 4 MiB on the wire.
pub const MAX_SENT_TEXTURE_SIDE: u32 = 1024;

/// The description: a JSON text message and the binary mesh messages it refers to.
#[derive(Debug)]
pub struct SceneDescription {
    /// `{"t":"scene",...}`.
    pub json: Json,
    /// [`MSG_MESH`] messages, one per distinct mesh, then the `MSG_TEXTURE` and
    /// `MSG_TEXTURED_PART` messages.
    pub meshes: Vec<Vec<u8>>,
}

/// Describes the world. Runs on the simulation thread.
pub fn describe(world: &World) -> SceneDescription {
    let mut meshes: Vec<&Arc<MeshData>> = Vec::new();
    // Texture ids in the order first worn, and the encoded textured parts.
    let mut images: Vec<i64> = Vec::new();
    let mut parts: Vec<Vec<u8>> = Vec::new();
    let mut objects = Vec::with_capacity(world.handles().len());
    // Both by handle, built once: the description stays linear in the number of objects.
    let index: std::collections::HashMap<i64, usize> =
        world.handles().iter().enumerate().map(|(i, &h)| (h, i)).collect();
    let index_of = |h: i64| index.get(&h).copied();
    let mut paths = full_paths(world);
    for &h in world.handles() {
        let Ok(o) = world.object(h) else {
            objects.push(json!({"handle": h, "alias": "", "path": "", "parent": null, "kind": "gone"}));
            continue;
        };
        let mut obj = json!({
            "handle": h,
            "alias": o.alias,
            "path": paths.remove(&h).unwrap_or_default(),
            "parent": o.parent.and_then(index_of),
            "model_base": o.model_base,
            "kind": o.kind.name(),
        });
        match &o.kind {
            ObjectKind::Shape(s) => {
                let hidden = !world.is_shown(h);
                let worn = world.shape_texture(h).ok().flatten().filter(|_| !hidden);
                let textured = worn.map_or(Ok(None), |_| textured_parts(world, h)).ok().flatten();
                let visuals: Vec<Json> = s
                    .visuals
                    .iter()
                    .enumerate()
                    .filter(|_| !hidden)
                    .map(|(i, v)| {
                        let mut g = geometry(&v.geometry, &mut meshes);
                        g["local"] = json!(pose_f32(&v.local));
                        g["color"] = json!(v.color);
                        if let (Some(t), Some(part)) = (worn, textured.as_ref().and_then(|p| p.get(i)))
                            && !part.positions.is_empty()
                        {
                            let image = images.iter().position(|&id| id == t.id).unwrap_or_else(|| {
                                images.push(t.id);
                                images.len() - 1
                            });
                            g["texture"] = json!({
                                "image": image,
                                "part": parts.len(),
                                // sim.setShapeTexture's option bits.
                                "interpolate": t.options & 1 == 0,
                                "decal": t.options & 2 != 0,
                                "repeat": [t.options & 4 != 0, t.options & 8 != 0],
                            });
                            parts.push(encode_part(parts.len() as u32, part));
                        }
                        g
                    })
                    .collect();
                obj["visuals"] = json!(visuals);
                obj["dynamic"] = json!(s.dynamic);
            }
            ObjectKind::Joint(j) => {
                obj["joint"] = json!({
                    "type": match j.joint_type {
                        JointType::Revolute => "revolute",
                        JointType::Prismatic => "prismatic",
                        JointType::Fixed => "fixed",
                    },
                    "mode": j.mode.name(),
                    "limits": j.limits.map(|(lo, hi)| [lo, hi]),
                    "cyclic": j.cyclic,
                });
            }
            ObjectKind::ProximitySensor(p) => {
                obj["proximity"] = match p.volume {
                    ProximityModel::Ray { offset, range } => {
                        json!({"shape": "ray", "offset": offset, "range": range})
                    }
                    ProximityModel::Cone {
                        offset,
                        range,
                        half_angle,
                    } => json!({"shape": "cone", "offset": offset, "range": range, "half_angle": half_angle}),
                    ProximityModel::Pyramid {
                        offset,
                        range,
                        near_size,
                        far_size,
                    } => json!({"shape": "pyramid", "offset": offset, "range": range,
                                "near_size": near_size, "far_size": far_size}),
                    ProximityModel::Cylinder {
                        offset,
                        range,
                        radius,
                        radius_far,
                    } => json!({"shape": "cylinder", "offset": offset, "range": range,
                                "radius": radius, "radius_far": radius_far}),
                    ProximityModel::Disc {
                        offset,
                        range,
                        half_angle,
                        thickness,
                    } => json!({"shape": "disc", "offset": offset, "range": range,
                                "half_angle": half_angle, "thickness": thickness}),
                };
            }
            ObjectKind::VisionSensor(v) => {
                obj["vision"] = json!({
                    "resolution": v.resolution,
                    "projection": match v.projection {
                        Projection::Perspective => "perspective",
                        Projection::Orthographic => "orthographic",
                    },
                    "fov": v.fov,
                    "ortho_size": v.ortho_size,
                    "near": v.near,
                    "far": v.far,
                });
            }
            ObjectKind::Camera(c) => {
                // The view angle spans the larger side of the view (CoppeliaSim's rule),
                // rad; `pose` is the world pose when described, `[x, y, z, qx, qy, qz,
                // qw]` as in frames, which keep it current. The camera looks along its
                // +Z with +Y up.
                obj["camera"] = json!({
                    "fov": c.fov,
                    "pose": pose_f32(&o.world),
                });
            }
            _ => {}
        }
        objects.push(obj);
    }
    let json = json!({
        "t": "scene",
        "objects": objects,
        "meshes": meshes.len(),
        "textures": images.len(),
        "textured_parts": parts.len(),
        "dt": world.settings().dt,
        "revision": world.scene_revision(),
        "structure": world.structure_revision(),
    });
    let textures = images
        .iter()
        .enumerate()
        .filter_map(|(i, &id)| Some(encode_texture(i as u32, world.textures().get(id).ok()?)));
    let meshes = meshes
        .iter()
        .enumerate()
        .map(|(i, m)| encode_mesh(i as u32, m))
        .chain(textures)
        .chain(parts)
        .collect();
    SceneDescription { json, meshes }
}

/// One visual's geometry as JSON; meshes are numbered in first-seen order (shared
/// meshes once).
fn geometry<'a>(g: &'a Geometry, meshes: &mut Vec<&'a Arc<MeshData>>) -> Json {
    match g {
        Geometry::Box { half_extents } => json!({"geom": "box", "half_extents": half_extents}),
        Geometry::Sphere { radius } => json!({"geom": "sphere", "radius": radius}),
        Geometry::Cylinder { radius, length } => json!({"geom": "cylinder", "radius": radius, "length": length}),
        Geometry::Capsule { radius, length } => json!({"geom": "capsule", "radius": radius, "length": length}),
        Geometry::Mesh(m) => {
            let id = match meshes.iter().position(|x| Arc::ptr_eq(x, m)) {
                Some(i) => i,
                None => {
                    meshes.push(m);
                    meshes.len() - 1
                }
            };
            json!({"geom": "mesh", "mesh": id})
        }
    }
}

/// Binary layout, little-endian: `u32` [`MSG_MESH`], `u32` id, `u32` vertex count,
/// `u32` triangle count, 3 `f32` per vertex (m, shape-part frame), 3 `u32` per triangle.
fn encode_mesh(id: u32, m: &MeshData) -> Vec<u8> {
    let nv = m.vertices.len();
    // A triangle that names a missing vertex would make the page read garbage.
    let tris = m
        .indices
        .iter()
        .filter(|t| t.iter().all(|&i| (i as usize) < nv))
        .take(MAX_MESH_TRIANGLES);
    let nt = tris.clone().count();
    let mut b = Vec::with_capacity(16 + 12 * nv + 12 * nt);
    for v in [MSG_MESH, id, nv as u32, nt as u32] {
        b.extend(v.to_le_bytes());
    }
    for v in m.vertices.iter().flatten() {
        b.extend(v.to_le_bytes());
    }
    for i in tris.flatten() {
        b.extend(i.to_le_bytes());
    }
    b
}

/// Binary layout, little-endian: `u32` [`MSG_TEXTURED_PART`], `u32` id, `u32` corner
/// count (3 per triangle), 3 `f32` per corner (m, part frame), then 2 `f32` (u, v) per
/// corner. At most [`MAX_MESH_TRIANGLES`] triangles.
fn encode_part(id: u32, part: &TexturedPart) -> Vec<u8> {
    let n = part.positions.len().min(part.uvs.len()).min(3 * MAX_MESH_TRIANGLES) / 3 * 3;
    let mut b = Vec::with_capacity(12 + 20 * n);
    for v in [MSG_TEXTURED_PART, id, n as u32] {
        b.extend(v.to_le_bytes());
    }
    for v in part.positions[..n].iter().flatten() {
        b.extend(v.to_le_bytes());
    }
    for v in part.uvs[..n].iter().flatten() {
        b.extend(v.to_le_bytes());
    }
    b
}

/// Binary layout, little-endian: `u32` [`MSG_TEXTURE`], `u32` index (the visuals'
/// `texture.image`), `u32` width, `u32` height, then RGBA bytes, rows from the bottom of
/// the picture (where v = 0, as WebGL reads them). Sides over
/// [`MAX_SENT_TEXTURE_SIDE`] are resampled to it (nearest pixel).
fn encode_texture(index: u32, t: &Texture) -> Vec<u8> {
    let [w, h] = t.resolution;
    let (sw, sh) = (w.min(MAX_SENT_TEXTURE_SIDE), h.min(MAX_SENT_TEXTURE_SIDE));
    let mut b = Vec::with_capacity(16 + 4 * sw as usize * sh as usize);
    for v in [MSG_TEXTURE, index, sw, sh] {
        b.extend(v.to_le_bytes());
    }
    for y in (0..sh as usize).rev() {
        let row = y * h as usize / sh as usize;
        for x in 0..sw as usize {
            let col = x * w as usize / sw as usize;
            let at = (row * w as usize + col) * 4;
            b.extend(t.rgba.get(at..at + 4).unwrap_or(&[0; 4]));
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meshes_are_encoded_with_valid_triangles_only() {
        let m = MeshData {
            source: "t.stl".into(),
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            indices: vec![[0, 1, 2], [0, 1, 9]],
            parts: Vec::new(),
        };
        let b = encode_mesh(4, &m);
        let word = |i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        assert_eq!([word(0), word(4), word(8), word(12)], [MSG_MESH, 4, 3, 1]);
        assert_eq!(b.len(), 16 + 9 * 4 + 3 * 4);
    }

    #[test]
    fn textured_shapes_come_with_their_parts_and_images() {
        use gantry_sim_core::Sim;
        use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
        use gantry_sim_core::world::{ShapeTexture, TextureMapping};
        let text = "[[object]]\nname = \"plate\"\nkind = \"shape\"\nshape = \"box\"\nsize = [1, 1, 0.01]\n\n\
                    [[object]]\nname = \"bare\"\nkind = \"shape\"\nshape = \"box\"\nsize = [1, 1, 1]\n";
        let model = load_scene_text(
            &DiskFiles,
            text,
            std::path::Path::new("s.toml"),
            &LoadOptions::default(),
        )
        .expect("scene");
        let mut sim = Sim::new(&model);
        // 1 x 2: red on top, blue below.
        let id = sim
            .world
            .add_texture("t", [1, 2], vec![255, 0, 0, 255, 0, 0, 255, 255])
            .expect("texture");
        let plate = sim.world.find("/plate", None, 0).expect("plate");
        let before = sim.world.scene_revision();
        let texture = ShapeTexture {
            id,
            mapping: TextureMapping::Plane,
            options: 1 | 8,
            uv_scaling: [1.0, 1.0],
            position: [0.0; 3],
            orientation: [0.0; 3],
            coordinates: None,
        };
        sim.world.set_shape_texture(plate, Some(texture)).expect("worn");
        assert_ne!(sim.world.scene_revision(), before, "the page is told to reload");
        let d = describe(&sim.world);
        assert_eq!(
            (d.json["textures"].as_u64(), d.json["textured_parts"].as_u64()),
            (Some(1), Some(1))
        );
        let objects = d.json["objects"].as_array().expect("objects");
        let visual = |name: &str| objects.iter().find(|o| o["alias"] == name).expect(name)["visuals"][0].clone();
        let t = &visual("plate")["texture"];
        assert_eq!((t["image"].as_u64(), t["part"].as_u64()), (Some(0), Some(0)));
        assert_eq!(
            (t["interpolate"].as_bool(), t["decal"].as_bool()),
            (Some(false), Some(false))
        );
        assert_eq!(t["repeat"], json!([false, true]));
        assert!(visual("bare").get("texture").is_none());
        // The image, bottom row first, then the box's 12 triangles with u, v per corner.
        let word = |b: &[u8], i: usize| u32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        let image = d.meshes.iter().find(|m| word(m, 0) == MSG_TEXTURE).expect("image");
        assert_eq!([word(image, 4), word(image, 8), word(image, 12)], [0, 1, 2]);
        assert_eq!(&image[16..], &[0, 0, 255, 255, 255, 0, 0, 255]);
        let part = d.meshes.iter().find(|m| word(m, 0) == MSG_TEXTURED_PART).expect("part");
        assert_eq!([word(part, 4), word(part, 8)], [0, 36]);
        assert_eq!(part.len(), 12 + 36 * 20);
        // Plane mapping of a 1 m plate: u, v = x + 0.5, y + 0.5.
        let float = |i: usize| f32::from_le_bytes([part[i], part[i + 1], part[i + 2], part[i + 3]]);
        for c in 0..36 {
            let (x, y) = (float(12 + 12 * c), float(16 + 12 * c));
            let (u, v) = (float(12 + 36 * 12 + 8 * c), float(16 + 36 * 12 + 8 * c));
            assert!((u - x - 0.5).abs() < 1e-6 && (v - y - 0.5).abs() < 1e-6, "corner {c}");
        }
    }

    #[test]
    fn shared_meshes_are_sent_once() {
        let m = Arc::new(MeshData {
            source: "t.stl".into(),
            vertices: vec![],
            indices: vec![],
            parts: Vec::new(),
        });
        let (a, b) = (Geometry::Mesh(m.clone()), Geometry::Mesh(m));
        let mut meshes = Vec::new();
        assert_eq!(geometry(&a, &mut meshes)["mesh"], 0);
        assert_eq!(geometry(&b, &mut meshes)["mesh"], 0);
        assert_eq!(meshes.len(), 1);
    }

    #[test]
    fn cameras_are_listed_with_their_pose_and_view_angle() {
        use gantry_sim_core::Sim;
        use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
        // A camera 2 m up on a mount at x = 1, pitched to look down (Euler 180°
        // about X: its +Z along the world's -Z), and an orthographic vision sensor.
        let text = r#"
[[object]]
name = "mount"
kind = "dummy"
position = [1, 0, 0]

[[object]]
name = "overhead"
kind = "camera"
parent = "mount"
position = [0, 0, 2]
orientation_deg = [180, 0, 0]
fov_deg = 50

[[object]]
name = "eye"
kind = "vision_sensor"
projection = "orthographic"
ortho_size = 0.25
"#;
        let model = load_scene_text(
            &DiskFiles,
            text,
            std::path::Path::new("s.toml"),
            &LoadOptions::default(),
        )
        .expect("scene");
        let sim = Sim::new(&model);
        let d = describe(&sim.world);
        let objects = d.json["objects"].as_array().expect("objects");
        let cameras: Vec<&Json> = objects.iter().filter(|o| o["kind"] == "camera").collect();
        assert_eq!(cameras.len(), 1);
        let c = cameras[0];
        assert_eq!(c["alias"], "overhead");
        assert_eq!(c["path"], "/mount/overhead");
        let fov = c["camera"]["fov"].as_f64().expect("fov");
        assert!((fov - 50f64.to_radians()).abs() < 1e-12, "{fov}");
        // World pose [x, y, z, qx, qy, qz, qw]: (1, 0, 2), a half turn about X.
        let pose: Vec<f64> = c["camera"]["pose"]
            .as_array()
            .expect("pose")
            .iter()
            .map(|v| v.as_f64().expect("number"))
            .collect();
        let want = [1.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0];
        let sign = pose[3].signum();
        for (k, (g, w)) in pose.iter().zip(want).enumerate() {
            let w = if k >= 3 { w * sign } else { w };
            assert!((g - w).abs() < 1e-6, "pose {pose:?}");
        }
        let eye = objects.iter().find(|o| o["alias"] == "eye").expect("sensor");
        assert_eq!(eye["vision"]["projection"], "orthographic");
        assert_eq!(eye["vision"]["ortho_size"], 0.25);
    }
}
