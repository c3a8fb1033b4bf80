//! Wavefront OBJ text for a [`MeshData`]: what `gantry convert` writes meshes as.
//!
//! OBJ because it is text (a user can diff it), gantry's mesh loader reads it, and its
//! `o` sections carry a mesh's convex parts ([`MeshData::parts`]) the way the loader
//! reads them back (`obj_parts.rs`). Coordinates are written as the shortest decimal
//! that reads back as the same `f32`, so a written mesh loads bit-identical.
//!
//! The loader expands an OBJ to three vertices per triangle (mesh-loader does), so a
//! mesh reads back with the same triangles but not the same vertex list.

use std::collections::HashSet;
use std::fmt::Write as _;

use super::model::MeshData;
use super::obj_parts::obj_parts;

/// The OBJ text of `mesh`, and whether its convex parts were kept: `false` when the
/// triangles cannot be split into sections whose vertices are exactly the parts (then
/// the file holds one section and a dynamic body collides with its hull).
pub fn write_obj(mesh: &MeshData, title: &str) -> (String, bool) {
    let mut out = String::with_capacity(mesh.vertices.len() * 30 + mesh.indices.len() * 20);
    // A title on one line: a newline in it would start an OBJ statement.
    let title: String = title.chars().map(|c| if c.is_control() { ' ' } else { c }).collect();
    let _ = writeln!(out, "# {title}, written by gantry convert");
    for v in &mesh.vertices {
        let _ = writeln!(out, "v {} {} {}", v[0], v[1], v[2]);
    }
    if mesh.parts.is_empty() {
        write_faces(&mut out, mesh.indices.iter());
        return (out, true);
    }
    match sections(mesh) {
        Some(sections) => {
            let head = out.len();
            for (k, tris) in sections.iter().enumerate() {
                let _ = writeln!(out, "o part{}", k + 1);
                write_faces(&mut out, tris.iter().map(|&t| &mesh.indices[t]));
            }
            if same_parts(&obj_parts(&out), &mesh.parts) {
                return (out, true);
            }
            out.truncate(head);
            write_faces(&mut out, mesh.indices.iter());
            (out, false)
        }
        None => {
            write_faces(&mut out, mesh.indices.iter());
            (out, false)
        }
    }
}

fn write_faces<'a>(out: &mut String, tris: impl Iterator<Item = &'a [u32; 3]>) {
    for t in tris {
        // OBJ indices are 1-based.
        let _ = writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
}

/// Triangle indices per part: each triangle goes to the first part that holds all three
/// of its corners. `None` when a triangle fits no part.
fn sections(mesh: &MeshData) -> Option<Vec<Vec<usize>>> {
    let key = |p: &[f32; 3]| p.map(f32::to_bits);
    let sets: Vec<HashSet<[u32; 3]>> = mesh.parts.iter().map(|p| p.iter().map(key).collect()).collect();
    let mut out = vec![Vec::new(); mesh.parts.len()];
    for (t, tri) in mesh.indices.iter().enumerate() {
        let corners = tri.map(|i| mesh.vertices.get(i as usize).map(key));
        let k = sets
            .iter()
            .position(|s| corners.iter().all(|c| c.is_some_and(|c| s.contains(&c))))?;
        out[k].push(t);
    }
    Some(out)
}

/// Whether parts read back from OBJ text (f64) are the mesh's parts (f32), each as a
/// set of points (a convex part is the hull of its points, whatever their order; the
/// loader lists them in the order the section's faces first use them).
fn same_parts(read: &[Vec<[f64; 3]>], parts: &[Vec<[f32; 3]>]) -> bool {
    let set = |p: Vec<[u32; 3]>| {
        let mut p = p;
        p.sort_unstable();
        p
    };
    read.len() == parts.len()
        && read.iter().zip(parts).all(|(r, p)| {
            set(r.iter().map(|v| v.map(|x| (x as f32).to_bits())).collect())
                == set(p.iter().map(|v| v.map(f32::to_bits)).collect())
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra(offset: f32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let v = vec![
            [offset, 0.0, 0.0],
            [offset + 1.0, 0.0, 0.0],
            [offset, 0.1, 0.0],
            [offset, 0.0, 1e-7],
        ];
        (v, vec![[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    }

    #[test]
    fn one_part_meshes_are_vertices_and_faces() {
        let (vertices, indices) = tetra(0.0);
        let mesh = MeshData {
            source: "t".into(),
            vertices,
            indices,
            parts: Vec::new(),
        };
        let (text, kept) = write_obj(&mesh, "tetra\nf 1 1 1");
        assert!(kept);
        assert!(text.starts_with("# tetra f 1 1 1, written"), "{text}");
        assert!(
            text.contains("v 0 0.1 0\n") && text.contains("v 0 0 0.0000001\n"),
            "{text}"
        );
        assert!(text.ends_with("f 2 3 4\n"), "{text}");
    }

    #[test]
    fn convex_parts_become_sections_that_read_back() {
        let (mut vertices, mut indices) = tetra(0.0);
        let (v2, i2) = tetra(3.0);
        indices.extend(i2.iter().map(|t| t.map(|i| i + 4)));
        vertices.extend(v2);
        let parts = vec![vertices[..4].to_vec(), vertices[4..].to_vec()];
        let mesh = MeshData {
            source: "two".into(),
            vertices,
            indices,
            parts,
        };
        let (text, kept) = write_obj(&mesh, "two");
        assert!(kept, "{text}");
        assert_eq!(text.matches("\no part").count(), 2);
        assert!(same_parts(&obj_parts(&text), &mesh.parts));
        // Parts that are not the triangles' corners cannot be sections.
        let odd = MeshData {
            parts: vec![vec![[9.0, 9.0, 9.0]]],
            ..mesh
        };
        let (text, kept) = write_obj(&odd, "odd");
        assert!(!kept && !text.contains("\no "), "{text}");
    }
}
