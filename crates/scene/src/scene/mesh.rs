//! Mesh files (STL, OBJ, COLLADA) and the resolution of `package://` references.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::error::LoadError;
use super::files::Files;
use super::model::MeshData;

/// Loads a mesh file and applies a per-axis scale. Sub-meshes are merged for drawing;
/// the sections of a multi-part OBJ are also kept as [`MeshData::parts`], the convex parts
/// a dynamic body collides with.
///
/// # Errors
/// [`LoadError::Mesh`] if the file is missing, of an unknown format, or has no triangles.
pub fn load_mesh(files: &dyn Files, path: &Path, scale: [f64; 3]) -> Result<Arc<MeshData>, LoadError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("stl" | "obj" | "dae")) {
        return Err(LoadError::Mesh {
            path: path.to_owned(),
            message: "unsupported mesh format; use .stl, .obj or .dae".into(),
        });
    }
    let bytes = files.read(path).map_err(|e| LoadError::Mesh {
        path: path.to_owned(),
        message: format!("cannot read mesh: {e}"),
    })?;
    // Sub-meshes are merged below, each offset by the vertices before it. (The loader's
    // own `merge_meshes` offsets each by the previous sub-mesh's last index only, which
    // points the triangles of the third sub-mesh on at the wrong vertices: the UR5's
    // upper arm lost most of its tube that way.)
    let loader = mesh_loader::Loader::default();
    let scene = match loader.load_from_slice(&bytes, path) {
        Ok(scene) => Ok(scene),
        // Some exporters (the Solo and Bolt feet in example-robot-data) begin a binary STL's
        // free-form header with `solid`, which reads as ASCII STL and fails. When the size
        // is exactly a binary STL's, parse it again with the header blanked.
        Err(_) if ext.as_deref() == Some("stl") && is_binary_stl_size(&bytes) => {
            let mut binary = bytes.clone();
            binary[..80].fill(0);
            loader.load_from_slice(&binary, path)
        }
        Err(e) => Err(e),
    }
    .map_err(|e| LoadError::Mesh {
        path: path.to_owned(),
        message: format!("cannot decode mesh: {e}"),
    })?;
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for mesh in scene.meshes {
        let base = u32::try_from(vertices.len()).unwrap_or(u32::MAX);
        vertices.extend(mesh.vertices.iter().map(|v| {
            [
                (f64::from(v[0]) * scale[0]) as f32,
                (f64::from(v[1]) * scale[1]) as f32,
                (f64::from(v[2]) * scale[2]) as f32,
            ]
        }));
        indices.extend(mesh.faces.iter().map(|f| [f[0] + base, f[1] + base, f[2] + base]));
    }
    let n = vertices.len() as u64;
    if indices.is_empty() || indices.iter().flatten().any(|&i| u64::from(i) >= n) {
        return Err(LoadError::Mesh {
            path: path.to_owned(),
            message: "mesh has no triangles or refers to missing vertices".into(),
        });
    }
    // A negative scale on an odd number of axes mirrors the mesh; flip the winding so
    // that normals still point outwards.
    if scale.iter().filter(|s| **s < 0.0).count() % 2 == 1 {
        for t in &mut indices {
            t.swap(1, 2);
        }
    }
    let parts = if ext.as_deref() == Some("obj") {
        let text = String::from_utf8_lossy(&bytes);
        let parts = super::obj_parts(&text);
        if parts.len() > 1 {
            parts
                .iter()
                .map(|p| {
                    p.iter()
                        .map(|v| {
                            [
                                (v[0] * scale[0]) as f32,
                                (v[1] * scale[1]) as f32,
                                (v[2] * scale[2]) as f32,
                            ]
                        })
                        .collect()
                })
                .collect()
        } else {
            Vec::new()
        }
    } else {
        Vec::new()
    };
    Ok(Arc::new(MeshData {
        source: path.to_owned(),
        vertices,
        indices,
        parts,
    }))
}

/// True if `bytes` is as long as a binary STL whose header declares its triangle count:
/// an 80-byte header, a little-endian `u32` count and 50 bytes per triangle.
fn is_binary_stl_size(bytes: &[u8]) -> bool {
    let Some(count) = bytes.get(80..84) else {
        return false;
    };
    let count = u64::from(u32::from_le_bytes([count[0], count[1], count[2], count[3]]));
    count > 0 && bytes.len() as u64 == 84 + 50 * count
}

/// Resolves a URDF mesh reference the way ROS tools do.
///
/// - `package://NAME/rest`: `NAME` is looked for as (1) a folder named `NAME` among the
///   URDF's folder and its ancestors, (2) a folder `NAME` inside any of those, (3) a
///   folder `NAME` inside, or named by, each `--package-path`.
/// - `file:///abs` and absolute paths are used as they are.
/// - Anything else is relative to the URDF's folder.
///
/// Returns every candidate tried when none exists, so the error can list them.
pub fn resolve_mesh_path(
    files: &dyn Files,
    reference: &str,
    urdf_dir: &Path,
    package_paths: &[PathBuf],
) -> Result<PathBuf, Vec<PathBuf>> {
    let mut tried = Vec::new();
    if let Some(rest) = reference.strip_prefix("package://") {
        let (pkg, sub) = rest.split_once('/').unwrap_or((rest, ""));
        for dir in urdf_dir.ancestors() {
            if dir.file_name().and_then(|n| n.to_str()) == Some(pkg) {
                tried.push(dir.join(sub));
            }
            tried.push(dir.join(pkg).join(sub));
        }
        for p in package_paths {
            if p.file_name().and_then(|n| n.to_str()) == Some(pkg) {
                tried.push(p.join(sub));
            }
            tried.push(p.join(pkg).join(sub));
        }
    } else if let Some(abs) = reference.strip_prefix("file://") {
        tried.push(PathBuf::from(abs));
    } else {
        tried.push(urdf_dir.join(reference));
    }
    match tried.iter().find(|p| files.is_file(p)) {
        Some(p) => Ok(p.clone()),
        None => Err(tried),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::files::DiskFiles;

    /// A fresh folder for one test's files (each test removes its own at the end).
    fn scratch(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("gantry-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("tmp dir");
        dir
    }

    #[test]
    fn package_uri_resolves_against_ancestors_and_package_paths() {
        let dir = scratch("mesh");
        let pkg = dir.join("my_robot");
        std::fs::create_dir_all(pkg.join("meshes")).expect("tmp dir");
        std::fs::create_dir_all(pkg.join("urdf")).expect("tmp dir");
        std::fs::write(pkg.join("meshes/a.stl"), b"solid a\nendsolid a\n").expect("write");
        let found = resolve_mesh_path(&DiskFiles, "package://my_robot/meshes/a.stl", &pkg.join("urdf"), &[]);
        assert_eq!(found, Ok(pkg.join("meshes/a.stl")));
        let via_path = resolve_mesh_path(
            &DiskFiles,
            "package://my_robot/meshes/a.stl",
            Path::new("/nonexistent"),
            std::slice::from_ref(&dir),
        );
        assert_eq!(via_path, Ok(pkg.join("meshes/a.stl")));
        let missing = resolve_mesh_path(&DiskFiles, "package://other/x.stl", &pkg.join("urdf"), &[]);
        assert!(missing.is_err_and(|t| !t.is_empty()));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn multi_part_obj_keeps_its_sections_scaled() {
        let dir = scratch("obj");
        let p = dir.join("two.obj");
        std::fs::write(
            &p,
            "o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n\
             o b\nv 3 0 0\nv 4 0 0\nv 3 1 0\nv 3 0 1\nf 5 6 7\nf 5 6 8\nf 5 7 8\nf 6 7 8\n",
        )
        .expect("write");
        let m = load_mesh(&DiskFiles, &p, [2.0, 1.0, 1.0]).expect("loads");
        assert_eq!(m.indices.len(), 8, "drawn as one merged mesh");
        assert_eq!(m.parts.len(), 2);
        assert!(m.parts[1].contains(&[8.0, 0.0, 0.0]), "{:?}", m.parts[1]);
        // A one-section OBJ needs no parts: its hull is that of the whole mesh.
        let q = dir.join("one.obj");
        std::fs::write(&q, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("write");
        assert!(load_mesh(&DiskFiles, &q, [1.0; 3]).expect("loads").parts.is_empty());
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A geometry: its positions and its triangles (0-based indices into them).
    type Geometry<'a> = (&'a [[f32; 3]], &'a [[u32; 3]]);

    /// A COLLADA document with one geometry per entry, each instanced once at the origin.
    fn collada(geometries: &[Geometry<'_>]) -> String {
        let mut lib = String::new();
        let mut nodes = String::new();
        for (k, (positions, triangles)) in geometries.iter().enumerate() {
            let floats: Vec<String> = positions.iter().flatten().map(f32::to_string).collect();
            let idx: Vec<String> = triangles.iter().flatten().map(u32::to_string).collect();
            lib += &format!(
                r##"<geometry id="g{k}"><mesh>
<source id="g{k}-p"><float_array id="g{k}-a" count="{n}">{floats}</float_array>
<technique_common><accessor source="#g{k}-a" count="{v}" stride="3">
<param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
</accessor></technique_common></source>
<vertices id="g{k}-v"><input semantic="POSITION" source="#g{k}-p"/></vertices>
<triangles count="{t}"><input semantic="VERTEX" source="#g{k}-v" offset="0"/><p>{idx}</p></triangles>
</mesh></geometry>
"##,
                n = floats.len(),
                floats = floats.join(" "),
                v = positions.len(),
                t = triangles.len(),
                idx = idx.join(" "),
            );
            nodes += &format!(r##"<node id="n{k}"><instance_geometry url="#g{k}"/></node>"##);
        }
        format!(
            r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
<library_geometries>{lib}</library_geometries>
<library_visual_scenes><visual_scene id="s">{nodes}</visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"##
        )
    }

    #[test]
    fn every_sub_mesh_keeps_its_own_triangles() {
        // Three geometries far apart (x near 0, 10 and 20 m), of different vertex and
        // triangle counts, whose last triangles do not end on their last vertex, as
        // vendor meshes (the UR5's upper arm: five geometries) have them. Each merged
        // triangle must join three corners of its own geometry.
        let a: &[[f32; 3]] = &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        let b: &[[f32; 3]] = &[[10.0, 0.0, 0.0], [11.0, 0.0, 0.0], [10.0, 1.0, 0.0]];
        let c: &[[f32; 3]] = &[
            [20.0, 0.0, 0.0],
            [21.0, 0.0, 0.0],
            [20.0, 1.0, 0.0],
            [21.0, 1.0, 0.0],
            [20.0, 0.0, 1.0],
        ];
        let text = collada(&[
            (a, &[[0, 1, 2], [3, 2, 1]]),
            (b, &[[2, 1, 0]]),
            (c, &[[0, 1, 2], [1, 3, 2], [0, 1, 4]]),
        ]);
        let dir = scratch("sub-meshes");
        let p = dir.join("three.dae");
        std::fs::write(&p, text).expect("write");
        let m = load_mesh(&DiskFiles, &p, [1.0; 3]).expect("loads");
        let owners: Vec<[u32; 3]> = m
            .indices
            .iter()
            .map(|t| t.map(|i| (m.vertices[i as usize][0] / 10.0) as u32))
            .collect();
        assert_eq!(
            owners,
            [[0; 3], [0; 3], [1; 3], [2; 3], [2; 3], [2; 3]],
            "each triangle's geometry"
        );
        // And the very corners written: the third geometry's last triangle.
        let last = m.indices[5].map(|i| m.vertices[i as usize]);
        assert_eq!(last, [[20.0, 0.0, 0.0], [21.0, 0.0, 0.0], [20.0, 0.0, 1.0]]);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn binary_stl_whose_header_starts_with_solid_loads() {
        // The layout of solo_foot.stl in example-robot-data: "solid foot" padded with
        // spaces to 80 bytes, then a binary triangle count and triangles.
        let mut bytes = format!("{:<80}", "solid foot").into_bytes();
        bytes.extend(1u32.to_le_bytes());
        for f in [0.0f32, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            bytes.extend(f.to_le_bytes());
        }
        bytes.extend([0, 0]);
        let dir = scratch("bstl");
        let p = dir.join("foot.stl");
        std::fs::write(&p, &bytes).expect("write");
        let m = load_mesh(&DiskFiles, &p, [1.0; 3]).expect("loads as binary STL");
        assert_eq!(m.indices.len(), 1);
        assert!(m.vertices.contains(&[1.0, 0.0, 0.0]), "{:?}", m.vertices);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn ascii_stl_loads_and_scales() {
        let dir = scratch("stl");
        let p = dir.join("tri.stl");
        std::fs::write(
            &p,
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n",
        )
        .expect("write");
        let m = load_mesh(&DiskFiles, &p, [2.0, 2.0, 2.0]).expect("loads");
        assert_eq!(m.indices.len(), 1);
        assert!(m.vertices.contains(&[2.0, 0.0, 0.0]));
        assert!(load_mesh(&DiskFiles, &dir.join("missing.stl"), [1.0; 3]).is_err());
        std::fs::remove_dir_all(&dir).ok();
    }
}
