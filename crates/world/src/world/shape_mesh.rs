//! Shapes as triangle meshes, and the mesh operations the API offers on them:
//! `sim.getShapeMesh`, `sim.getShapeViz`, `sim.computeMassAndInertia`,
//! `sim.getDecimatedMesh` and `sim.convexDecompose`.
//!
//! A shape's mesh is that of its visual parts (its collision parts when it has none), in
//! the shape frame, primitives tessellated with shared vertices as CoppeliaSim stores
//! them (a box: 8 vertices, 12 triangles).

use std::sync::Arc;

use nalgebra::Matrix3;
use parry3d::math::Vector as PVec;
use parry3d::shape::{Ball, Capsule, ConvexPolyhedron, Cuboid, Cylinder, Shape as _, SharedShape};

use super::object::Handle;
use super::world::World;
use crate::error::SimError;
use crate::math::{self, Pose, Vec3};
use crate::scene::{GeomModel, Geometry, MassModel, MeshData};

/// Segments around the axis of tessellated spheres, cylinders and capsules.
const AROUND: u32 = 32;
/// Latitude bands of tessellated spheres and capsule caps.
const BANDS: u32 = 16;
/// The most triangles a mesh operation takes (a vendor arm link has about 100,000).
pub const MAX_MESH_TRIANGLES: usize = 4_000_000;

/// A triangle mesh in a shape's frame, metres.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShapeMesh {
    /// Vertex positions.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from outside.
    pub indices: Vec<[u32; 3]>,
}

impl ShapeMesh {
    /// Appends `other` moved by `pose`.
    fn append(&mut self, other: &ShapeMesh, pose: &Pose) {
        let base = self.vertices.len() as u32;
        self.vertices.extend(other.vertices.iter().map(|v| {
            let p = pose * nalgebra::Point3::new(v[0], v[1], v[2]);
            [p.x, p.y, p.z]
        }));
        self.indices.extend(other.indices.iter().map(|t| t.map(|i| i + base)));
    }

    /// The unit normal of each triangle (zero for a degenerate one).
    pub fn face_normals(&self) -> Vec<[f64; 3]> {
        self.indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| Vec3::from(self.vertices[i as usize]));
                let n = (b - a).cross(&(c - a));
                let len = n.norm();
                if len > 0.0 { (n / len).into() } else { [0.0; 3] }
            })
            .collect()
    }
}

/// A primitive's or mesh's triangles in its own frame. Primitives with invalid sizes give
/// an empty mesh.
pub fn geometry_mesh(g: &Geometry) -> ShapeMesh {
    let from = |(v, i): (Vec<PVec>, Vec<[u32; 3]>)| ShapeMesh {
        vertices: v
            .iter()
            .map(|p| [f64::from(p.x), f64::from(p.y), f64::from(p.z)])
            .collect(),
        indices: i,
    };
    let ok = |x: f64| x.is_finite() && x > 0.0;
    match *g {
        Geometry::Box { half_extents } if half_extents.iter().all(|&h| ok(h)) => from(
            Cuboid::new(PVec::new(
                half_extents[0] as f32,
                half_extents[1] as f32,
                half_extents[2] as f32,
            ))
            .to_trimesh(),
        ),
        Geometry::Sphere { radius } if ok(radius) => from(Ball::new(radius as f32).to_trimesh(AROUND, BANDS)),
        Geometry::Cylinder { radius, length } if ok(radius) && ok(length) => {
            // parry's cylinder lies along y, gantry's along z: a quarter turn about x.
            let mut m = from(Cylinder::new(length as f32 / 2.0, radius as f32).to_trimesh(AROUND));
            for v in &mut m.vertices {
                *v = [v[0], -v[2], v[1]];
            }
            m
        }
        Geometry::Capsule { radius, length } if ok(radius) && length.is_finite() && length >= 0.0 => {
            from(Capsule::new_z(length as f32 / 2.0, radius as f32).to_trimesh(AROUND, BANDS / 2))
        }
        Geometry::Mesh(ref m) => ShapeMesh {
            vertices: m.vertices.iter().map(|v| v.map(f64::from)).collect(),
            indices: m.indices.clone(),
        },
        _ => ShapeMesh::default(),
    }
}

/// Vertices and triangles given as flat lists (x, y, z per vertex; three indices per
/// triangle), checked: finite coordinates, indices naming vertices, sizes in bounds.
///
/// # Errors
/// Lists of the wrong length, non-finite coordinates, or indices out of range.
pub fn mesh_from_lists(vertices: &[f64], indices: &[f64]) -> Result<ShapeMesh, SimError> {
    if vertices.is_empty() || !vertices.len().is_multiple_of(3) || vertices.iter().any(|v| !v.is_finite()) {
        return Err(SimError::bad_argument(format!(
            "vertices come as finite x, y, z triples, got {} numbers",
            vertices.len()
        )));
    }
    if indices.is_empty() || !indices.len().is_multiple_of(3) || indices.len() / 3 > MAX_MESH_TRIANGLES {
        return Err(SimError::bad_argument(format!(
            "triangles come as index triples (at most {MAX_MESH_TRIANGLES} triangles), got {} indices",
            indices.len()
        )));
    }
    let n = vertices.len() / 3;
    let index = |x: f64| {
        if x.fract() == 0.0 && x >= 0.0 && (x as usize) < n {
            Ok(x as u32)
        } else {
            Err(SimError::bad_argument(format!(
                "index {x} is not a vertex (0 to {})",
                n - 1
            )))
        }
    };
    Ok(ShapeMesh {
        vertices: vertices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        indices: indices
            .chunks_exact(3)
            .map(|c| Ok([index(c[0])?, index(c[1])?, index(c[2])?]))
            .collect::<Result<_, SimError>>()?,
    })
}

/// A coarser copy of a mesh with at most `keep` (0 to 1) of its triangles, by vertex
/// clustering: the finest grid of cubic cells whose merged vertices leave no more
/// triangles than that. Each vertex moves to the mean of its cell, so the shape is kept
/// to within a cell's diagonal.
///
/// # Errors
/// `keep` not within 0 to 1 (exclusive of 0).
pub fn decimate(mesh: &ShapeMesh, keep: f64) -> Result<ShapeMesh, SimError> {
    if !(keep > 0.0 && keep <= 1.0) {
        return Err(SimError::bad_argument(format!(
            "the share of triangles to keep must be above 0 and at most 1, got {keep}"
        )));
    }
    let target = (mesh.indices.len() as f64 * keep).floor() as usize;
    let data = MeshData {
        source: "<decimation>".into(),
        vertices: mesh.vertices.iter().map(|v| v.map(|c| c as f32)).collect(),
        indices: mesh.indices.clone(),
        parts: Vec::new(),
    };
    let to_mesh = |d: &MeshData| ShapeMesh {
        vertices: d.vertices.iter().map(|v| v.map(f64::from)).collect(),
        indices: d.indices.clone(),
    };
    if target >= mesh.indices.len() {
        return Ok(to_mesh(&data));
    }
    let (lo, hi) = mesh
        .vertices
        .iter()
        .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), v| {
            ([0, 1, 2].map(|k| lo[k].min(v[k])), [0, 1, 2].map(|k| hi[k].max(v[k])))
        });
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    // Bisection on the cell side: the triangle count falls (nearly monotonically) as the
    // cells grow. A cell as large as the whole mesh leaves no triangle at all.
    let (mut fine, mut coarse) = (0.0, diagonal.max(f64::MIN_POSITIVE));
    let mut best = crate::mesh_cluster::cluster(&data, coarse as f32).0;
    for _ in 0..24 {
        let mid = 0.5 * (fine + coarse);
        let (m, _) = crate::mesh_cluster::cluster(&data, mid as f32);
        if m.indices.len() <= target {
            coarse = mid;
            best = m;
        } else {
            fine = mid;
        }
    }
    Ok(to_mesh(&best))
}

/// Volume, centre and inertia about that centre at unit density of a mesh's convex hull
/// (`None` when the hull is flat or the mesh has too few points).
fn hull_unit_density(m: &MeshData) -> Option<(f64, Vec3, Matrix3<f64>)> {
    let points: Vec<PVec> = m.vertices.iter().map(|v| PVec::new(v[0], v[1], v[2])).collect();
    let hull = ConvexPolyhedron::from_convex_hull(&points)?;
    let p = hull.mass_properties(1.0);
    let mass = f64::from(p.mass());
    if !(mass.is_finite() && mass > 0.0) {
        return None;
    }
    let i = p.reconstruct_inertia_matrix().to_cols_array().map(f64::from);
    let com = Vec3::new(
        f64::from(p.local_com.x),
        f64::from(p.local_com.y),
        f64::from(p.local_com.z),
    );
    Some((mass, com, Matrix3::from_column_slice(&i)))
}

impl World {
    /// The meshes of a shape's visual parts (of its collision parts when it has no
    /// visual), each in the shape frame, with its colour.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape_part_meshes(&self, h: Handle) -> Result<Vec<(ShapeMesh, [f32; 3])>, SimError> {
        let s = self.shape(h)?;
        let parts: Vec<(&Geometry, &Pose, [f32; 3])> = if s.visuals.is_empty() {
            s.geoms.iter().map(|g| (&g.geometry, &g.local, [0.5; 3])).collect()
        } else {
            s.visuals.iter().map(|v| (&v.geometry, &v.local, v.color)).collect()
        };
        Ok(parts
            .into_iter()
            .map(|(g, local, color)| {
                let mut m = ShapeMesh::default();
                m.append(&geometry_mesh(g), local);
                (m, color)
            })
            .collect())
    }

    /// A shape's whole mesh in its frame: its parts one after the other
    /// (`sim.getShapeMesh`).
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn shape_mesh(&self, h: Handle) -> Result<ShapeMesh, SimError> {
        let mut all = ShapeMesh::default();
        for (m, _) in self.shape_part_meshes(h)? {
            all.append(&m, &Pose::identity());
        }
        Ok(all)
    }

    /// `sim.computeMassAndInertia(shape, density)`: gives the shape the mass and inertia
    /// of its collision parts filled at `density` (kg/m³). Primitives count exactly; a
    /// mesh counts as its convex hull (CoppeliaSim computes only convex shapes, and
    /// refuses others; gantry takes their hull instead). Restarts the shape's dynamics.
    ///
    /// # Errors
    /// No such object, not a shape, a density that is not a positive finite number, or
    /// a shape with no volume.
    pub fn compute_mass_and_inertia(&mut self, h: Handle, density: f64) -> Result<(), SimError> {
        if !(density.is_finite() && density > 0.0) {
            return Err(SimError::bad_argument(format!(
                "density must be a positive number (kg/m³), got {density}"
            )));
        }
        let s = self.shape(h)?;
        let mut parts = Vec::new();
        for g in &s.geoms {
            let own = match &g.geometry {
                Geometry::Mesh(m) => hull_unit_density(m),
                other => Some(super::mass::unit_density_part(other)),
            };
            let Some((v, c, i)) = own else { continue };
            let r = g.local.rotation.to_rotation_matrix().into_inner();
            let c = (g.local * nalgebra::Point3::from(c)).coords;
            parts.push((v, c, r * i * r.transpose()));
        }
        let volume: f64 = parts.iter().map(|p| p.0).sum();
        if !(volume.is_finite() && volume > 0.0) {
            return Err(SimError::bad_argument(format!("shape {h} has no volume to fill")));
        }
        let com = parts.iter().map(|(v, c, _)| c * *v).sum::<Vec3>() / volume;
        let mut inertia = Matrix3::zeros();
        for (v, c, own) in &parts {
            let d = c - com;
            inertia += (own + (Matrix3::identity() * d.norm_squared() - d * d.transpose()) * *v) * density;
        }
        let mass = (volume * density).max(super::MIN_SHAPE_MASS);
        self.set_shape_inertial(h, mass, com, &inertia)
    }

    /// Gives a shape an explicit mass (kg), centre of mass (shape frame, m) and inertia
    /// tensor about it (shape axes, kg·m²), as `sim.setShapeMassAndInertia` does.
    /// Restarts the shape's dynamics.
    ///
    /// # Errors
    /// No such object, not a shape, a mass that is not positive and finite, or
    /// non-finite values.
    pub fn set_shape_inertial(
        &mut self,
        h: Handle,
        mass: f64,
        com: Vec3,
        inertia: &Matrix3<f64>,
    ) -> Result<(), SimError> {
        if !(mass.is_finite() && mass > 0.0) || com.iter().chain(inertia.iter()).any(|v| !v.is_finite()) {
            return Err(SimError::bad_argument(
                "mass, centre of mass and inertia must be finite, the mass positive",
            ));
        }
        let i = (inertia + inertia.transpose()) * 0.5;
        let s = self.shape_mut(h)?;
        s.mass = MassModel::Inertial {
            mass,
            com: com.into(),
            frame: math::quat_to_array(&math::Quat::identity()),
            inertia: [i[(0, 0)], i[(0, 1)], i[(0, 2)], i[(1, 1)], i[(1, 2)], i[(2, 2)]],
        };
        self.rebuild_physics(&[h]);
        self.bump();
        Ok(())
    }

    /// Replaces a shape's collision parts (the shape frame's), keeping its visuals,
    /// as `sim.convexDecompose` morphs a shape. Restarts the shape's dynamics.
    ///
    /// # Errors
    /// No such object, not a shape, or no parts.
    pub fn set_shape_collision_parts(&mut self, h: Handle, geoms: Vec<GeomModel>) -> Result<(), SimError> {
        if geoms.is_empty() {
            return Err(SimError::bad_argument(format!(
                "shape {h} needs at least one collision part"
            )));
        }
        self.shape_mut(h)?.geoms = geoms;
        self.rebuild_physics(&[h]);
        self.bump();
        Ok(())
    }

    /// Turns a shape's frame to `rotation` (world frame) about its origin while its
    /// geometry, its children and a texture's placement stay where they are in the world
    /// (`sim.reorientShapeBoundingBox`: the bounding box follows the frame's axes).
    /// Restarts the shape's dynamics.
    ///
    /// # Errors
    /// No such object, or not a shape.
    pub fn reorient_shape_frame(&mut self, h: Handle, rotation: math::Quat) -> Result<(), SimError> {
        self.shape(h)?;
        let old = self.objects[h as usize].world;
        let new = Pose::from_parts(old.translation, rotation);
        // From the old shape frame to the new one.
        let delta = new.inverse() * old;
        let s = self.shape_mut(h)?;
        for g in &mut s.geoms {
            g.local = delta * g.local;
        }
        for v in &mut s.visuals {
            v.local = delta * v.local;
        }
        if let MassModel::Inertial { com, frame, .. } = &mut s.mass {
            *com = (delta * nalgebra::Point3::from(Vec3::from(*com))).coords.into();
            let f = math::quat_from_array(*frame).unwrap_or_else(math::Quat::identity);
            *frame = math::quat_to_array(&(delta.rotation * f));
        }
        if let Some(t) = self.textures.on_shapes.get_mut(&h) {
            let placed = delta * math::pose_from_euler(t.position, t.orientation);
            t.position = placed.translation.vector.into();
            t.orientation = math::euler_from_quat(&placed.rotation);
            self.textures.revision += 1;
        }
        let children: Vec<(Handle, Pose)> = self.objects[h as usize]
            .children
            .iter()
            .map(|&c| (c, self.objects[c as usize].world))
            .collect();
        self.set_world_pose(h, new)?;
        for (c, world) in children {
            self.objects[c as usize].local = new.inverse() * world;
        }
        self.refresh_subtree(h);
        self.rebuild_physics(&[h]);
        self.bump();
        Ok(())
    }

    /// The world orientation of the axes of a shape's smallest bounding box, as far as
    /// its mesh's principal axes give it (the eigenvectors of its vertices' covariance).
    ///
    /// # Errors
    /// No such object, not a shape, or a shape without vertices.
    pub fn shape_principal_axes(&self, h: Handle) -> Result<math::Quat, SimError> {
        let mesh = self.shape_mesh(h)?;
        if mesh.vertices.is_empty() {
            return Err(SimError::bad_argument(format!("shape {h} has no vertices")));
        }
        let n = mesh.vertices.len() as f64;
        let mean = mesh.vertices.iter().map(|v| Vec3::from(*v)).sum::<Vec3>() / n;
        let cov = mesh
            .vertices
            .iter()
            .map(|v| {
                let d = Vec3::from(*v) - mean;
                d * d.transpose()
            })
            .sum::<Matrix3<f64>>()
            / n;
        let eigen = cov.symmetric_eigen();
        // Largest spread first, along x; a right-handed frame.
        let mut order = [0, 1, 2];
        order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));
        let x = eigen.eigenvectors.column(order[0]).into_owned();
        let y = eigen.eigenvectors.column(order[1]).into_owned();
        let z = x.cross(&y);
        let r = nalgebra::Rotation3::from_matrix(&Matrix3::from_columns(&[x, y, z]));
        Ok(self.objects[h as usize].world.rotation * math::Quat::from_rotation_matrix(&r))
    }

    /// The convex decomposition of a shape's whole mesh (V-HACD through parry), as
    /// meshes in the shape frame, one per convex part.
    ///
    /// # Errors
    /// No such object, not a shape, or a mesh with nothing to decompose.
    pub fn convex_decomposition(&self, h: Handle) -> Result<Vec<ShapeMesh>, SimError> {
        let mesh = self.shape_mesh(h)?;
        if mesh.indices.is_empty() || mesh.indices.len() > MAX_MESH_TRIANGLES {
            return Err(SimError::bad_argument(format!(
                "shape {h} has {} triangles: convex decomposition needs 1 to {MAX_MESH_TRIANGLES}",
                mesh.indices.len()
            )));
        }
        let vertices: Vec<PVec> = mesh
            .vertices
            .iter()
            .map(|v| PVec::new(v[0] as f32, v[1] as f32, v[2] as f32))
            .collect();
        let decomposed = SharedShape::convex_decomposition(&vertices, &mesh.indices);
        let compound = decomposed
            .as_compound()
            .ok_or_else(|| SimError::bad_argument(format!("shape {h}: the decomposition gave no parts")))?;
        let mut out = Vec::new();
        for (pose, part) in compound.shapes() {
            let Some(poly) = part.as_convex_polyhedron() else {
                continue;
            };
            let (v, i) = poly.to_trimesh();
            let m = ShapeMesh {
                vertices: v
                    .iter()
                    .map(|p| {
                        let q = pose.transform_point(*p);
                        [f64::from(q.x), f64::from(q.y), f64::from(q.z)]
                    })
                    .collect(),
                indices: i,
            };
            out.push(m);
        }
        if out.is_empty() {
            return Err(SimError::bad_argument(format!(
                "shape {h}: the decomposition gave no parts"
            )));
        }
        Ok(out)
    }
}

/// A mesh as scene mesh data (single precision, as meshes are stored).
pub fn mesh_data(mesh: &ShapeMesh, source: &str) -> Arc<MeshData> {
    Arc::new(MeshData {
        source: source.into(),
        vertices: mesh.vertices.iter().map(|v| v.map(|c| c as f32)).collect(),
        indices: mesh.indices.clone(),
        parts: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::scene::{EmbeddedFiles, LoadOptions, ShapeModel, load_scene_text};
    use crate::world::{ObjectKind, ShapeTexture, TextureMapping};

    fn world() -> World {
        let model = load_scene_text(
            &EmbeddedFiles::default(),
            "",
            Path::new("/empty.toml"),
            &LoadOptions::default(),
        )
        .expect("an empty scene loads");
        World::new(&model)
    }

    fn add(w: &mut World, g: Geometry) -> Handle {
        let shape = ShapeModel {
            dynamic: true,
            ..ShapeModel::single(g, [0.2, 0.4, 0.6])
        };
        w.add_object("s", ObjectKind::Shape(Box::new(shape)), None, Pose::identity())
            .expect("adds")
    }

    #[test]
    fn a_box_is_eight_shared_vertices_and_twelve_outward_triangles() {
        let mut w = world();
        let h = add(
            &mut w,
            Geometry::Box {
                half_extents: [0.5, 1.0, 1.5],
            },
        );
        let m = w.shape_mesh(h).expect("a shape");
        assert_eq!((m.vertices.len(), m.indices.len()), (8, 12));
        assert!(m.vertices.contains(&[0.5, -1.0, 1.5]));
        // Outward: each face normal points away from the centre.
        for (t, n) in m.indices.iter().zip(m.face_normals()) {
            let c = Vec3::from(m.vertices[t[0] as usize]);
            assert!(c.dot(&Vec3::from(n)) > 0.0, "{t:?} {n:?}");
        }
        assert!(w.shape_mesh(-5).is_err());
    }

    #[test]
    fn a_cylinder_lies_along_z() {
        let m = geometry_mesh(&Geometry::Cylinder {
            radius: 0.1,
            length: 2.0,
        });
        let zmax = m.vertices.iter().map(|v| v[2]).fold(f64::MIN, f64::max);
        let ymax = m.vertices.iter().map(|v| v[1]).fold(f64::MIN, f64::max);
        assert!((zmax - 1.0).abs() < 1e-6 && (ymax - 0.1).abs() < 1e-6, "{zmax} {ymax}");
    }

    #[test]
    fn mass_and_inertia_follow_density_and_hull() {
        let mut w = world();
        let h = add(
            &mut w,
            Geometry::Box {
                half_extents: [0.5, 0.5, 0.5],
            },
        );
        w.compute_mass_and_inertia(h, 2000.0).expect("computes");
        let p = w.shape_mass_properties(h).expect("props");
        assert!((p.mass - 2000.0).abs() < 1e-9, "{}", p.mass);
        // A unit cube: m (a² + b²) / 12 about each axis.
        assert!((p.inertia[(0, 0)] - 2000.0 * 2.0 / 12.0).abs() < 1e-6, "{}", p.inertia);
        // A mesh counts as its hull: a unit tetrahedron's volume is 1/6.
        let tet = MeshData {
            source: "t".into(),
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            indices: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            parts: Vec::new(),
        };
        let t = add(&mut w, Geometry::Mesh(Arc::new(tet)));
        w.compute_mass_and_inertia(t, 600.0).expect("computes");
        let p = w.shape_mass_properties(t).expect("props");
        assert!((p.mass - 100.0).abs() < 1e-3, "{}", p.mass);
        assert!((p.com - Vec3::repeat(0.25)).norm() < 1e-5, "{}", p.com);
        for bad in [f64::NAN, -1.0, 0.0, f64::INFINITY] {
            assert!(w.compute_mass_and_inertia(h, bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn decimation_keeps_at_most_the_share_asked() {
        let m = geometry_mesh(&Geometry::Sphere { radius: 1.0 });
        let n = m.indices.len();
        let d = decimate(&m, 0.2).expect("decimates");
        assert!(
            !d.indices.is_empty() && d.indices.len() <= n / 5,
            "{} of {n}",
            d.indices.len()
        );
        assert!(d.indices.iter().flatten().all(|&i| (i as usize) < d.vertices.len()));
        assert!(decimate(&m, 0.0).is_err() && decimate(&m, f64::NAN).is_err() && decimate(&m, 1.5).is_err());
    }

    #[test]
    fn lists_are_checked() {
        assert!(mesh_from_lists(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], &[0.0, 1.0, 2.0]).is_ok());
        assert!(mesh_from_lists(&[0.0, 0.0, f64::NAN, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], &[0.0, 1.0, 2.0]).is_err());
        assert!(mesh_from_lists(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], &[0.0, 1.0, 3.0]).is_err());
        assert!(mesh_from_lists(&[0.0, 0.0], &[0.0, 1.0, 2.0]).is_err());
    }

    #[test]
    fn a_concave_mesh_decomposes_into_convex_parts() {
        let mut w = world();
        // Two boxes joined at an edge: an L, not convex.
        let a = geometry_mesh(&Geometry::Box {
            half_extents: [1.0, 0.1, 0.1],
        });
        let mut l = ShapeMesh::default();
        l.append(&a, &Pose::translation(0.0, 0.0, 0.0));
        l.append(
            &a,
            &Pose::from_parts(
                nalgebra::Translation3::new(0.9, 0.9, 0.0),
                math::Quat::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            ),
        );
        let h = add(&mut w, Geometry::Mesh(mesh_data(&l, "L")));
        let parts = w.convex_decomposition(h).expect("decomposes");
        assert!(parts.len() >= 2, "{} parts", parts.len());
    }

    #[test]
    fn reorienting_keeps_geometry_and_children_in_place() {
        let mut w = world();
        let h = add(
            &mut w,
            Geometry::Box {
                half_extents: [0.3, 0.1, 0.05],
            },
        );
        let turned = math::Quat::from_euler_angles(0.0, 0.0, 0.7);
        w.set_world_pose(h, Pose::from_parts(nalgebra::Translation3::new(1.0, 2.0, 3.0), turned))
            .expect("moves");
        let child = w
            .add_object("c", ObjectKind::Dummy, Some(h), Pose::translation(0.5, 0.0, 0.0))
            .expect("adds");
        let corner = |w: &World| {
            let m = w.shape_mesh(h).expect("mesh");
            let at = w.object(h).expect("shape").world;
            let mut pts: Vec<[i64; 3]> = m
                .vertices
                .iter()
                .map(|v| {
                    let p = at * nalgebra::Point3::new(v[0], v[1], v[2]);
                    [p.x, p.y, p.z].map(|c| (c * 1e5).round() as i64)
                })
                .collect();
            pts.sort_unstable();
            pts
        };
        let (before, child_before) = (corner(&w), w.object(child).expect("child").world);
        w.reorient_shape_frame(h, math::Quat::identity()).expect("reorients");
        assert_eq!(w.object(h).expect("shape").world.rotation, math::Quat::identity());
        assert_eq!(corner(&w), before, "the geometry stays");
        let child_after = w.object(child).expect("child").world;
        assert!((child_after.translation.vector - child_before.translation.vector).norm() < 1e-12);
        // The principal axes of the box: its own, turned by 0.7 rad.
        let axes = w.shape_principal_axes(h).expect("axes");
        let x = axes * Vec3::x();
        assert!(
            (x.x.abs() - 0.7f64.cos()).abs() < 1e-6 && (x.y.abs() - 0.7f64.sin()).abs() < 1e-6,
            "{x}"
        );
    }

    #[test]
    fn a_texture_on_a_shape_round_trips() {
        let mut w = world();
        let h = add(&mut w, Geometry::Box { half_extents: [0.5; 3] });
        let id = w.add_texture("wood", [1, 1], vec![1, 2, 3, 4]).expect("adds");
        assert_eq!(w.shape_texture(h), Ok(None));
        let t = ShapeTexture {
            id,
            mapping: TextureMapping::Cube,
            options: 4,
            uv_scaling: [1.0, 2.0],
            position: [0.0; 3],
            orientation: [0.0; 3],
            coordinates: None,
        };
        w.set_shape_texture(h, Some(t.clone())).expect("sets");
        assert_eq!(w.shape_texture(h), Ok(Some(&t)));
        // Explicit coordinates must cover the 12 triangles.
        let short = ShapeTexture {
            mapping: TextureMapping::Coordinates,
            coordinates: Some(Arc::new(vec![0.0; 6])),
            ..t.clone()
        };
        assert!(w.set_shape_texture(h, Some(short)).is_err());
        assert!(w.set_shape_texture(h, Some(ShapeTexture { id: 9, ..t })).is_err());
        w.set_shape_texture(h, None).expect("removes");
        assert_eq!(w.shape_texture(h), Ok(None));
    }
}
