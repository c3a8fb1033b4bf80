//! The convex parts of a Wavefront OBJ collision mesh.
//!
//! Convex decompositions (V-HACD and its kin) ship as one OBJ file whose parts are
//! separate `o` (object) or `g` (group) sections. PyBullet makes each section of a
//! collision OBJ its own convex hull, and so does gantry, so that a robot file behaves
//! the same in both. mesh-loader, which reads the mesh for drawing, merges the sections
//! and ignores `o` lines, so this module reads which vertices each section's faces use.
//!
//! Only `v`, `f`, `o` and `g` lines matter here; everything else (normals, texture
//! coordinates, materials, comments) is skipped. The reader is total: a malformed line
//! is skipped rather than refused, because mesh-loader has already decided whether the
//! file is a valid mesh.

/// The vertex positions (file units, unscaled) used by the faces of each `o`/`g` section
/// of an OBJ text, in file order. Sections without faces are left out, so a file without
/// sections gives one part and a file without faces gives none.
pub fn obj_parts(text: &str) -> Vec<Vec<[f64; 3]>> {
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut parts: Vec<Vec<[f64; 3]>> = Vec::new();
    // Indices used by the section being read, and a per-vertex mark so a vertex shared
    // by many faces is taken once. `mark[i] == parts.len() + 1` means "in this section".
    let mut current: Vec<usize> = Vec::new();
    let mut mark: Vec<usize> = Vec::new();
    let finish = |current: &mut Vec<usize>, parts: &mut Vec<Vec<[f64; 3]>>, vertices: &[[f64; 3]]| {
        if !current.is_empty() {
            parts.push(current.iter().map(|&i| vertices[i]).collect());
            current.clear();
        }
    };
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut xyz = [0.0; 3];
                let mut ok = true;
                for c in &mut xyz {
                    match words.next().and_then(|w| w.parse::<f64>().ok()) {
                        Some(v) if v.is_finite() => *c = v,
                        _ => ok = false,
                    }
                }
                // A malformed vertex still takes its index, so later faces keep
                // pointing at the vertices the file means; it sits at the origin.
                vertices.push(if ok { xyz } else { [0.0; 3] });
                mark.push(0);
            }
            Some("f") => {
                for w in words {
                    let index = w.split('/').next().and_then(|i| i.parse::<i64>().ok());
                    // OBJ indices are 1-based; negative ones count back from the last vertex.
                    let resolved = match index {
                        Some(i) if i > 0 => usize::try_from(i - 1).ok(),
                        Some(i) if i < 0 => vertices.len().checked_sub(i.unsigned_abs() as usize),
                        _ => None,
                    };
                    if let Some(i) = resolved.filter(|&i| i < vertices.len()) {
                        let tag = parts.len() + 1;
                        if mark[i] != tag {
                            mark[i] = tag;
                            current.push(i);
                        }
                    }
                }
            }
            Some("o" | "g") => finish(&mut current, &mut parts, &vertices),
            _ => {}
        }
    }
    finish(&mut current, &mut parts, &vertices);
    parts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_become_parts_with_their_own_vertices() {
        let text = "# two tetrahedra\n\
            o first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
            f 1 2 3\nf 1 2 4\nf 1//1 3//1 4//1\nf 2/1/1 3/1/1 4/1/1\n\
            o second\nv 5 0 0\nv 6 0 0\nv 5 1 0\nv 5 0 1\n\
            f -4 -3 -2\nf -4 -3 -1\n";
        let parts = obj_parts(text);
        assert_eq!(parts.len(), 2);
        assert_eq!(
            parts[0],
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        );
        assert_eq!(
            parts[1],
            vec![[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0], [5.0, 0.0, 1.0]]
        );
    }

    #[test]
    fn groups_split_too_and_empty_sections_are_dropped() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\ng a\nf 1 2 3\ng empty\ng b\nf 3 2 1\no trailing\n";
        let parts = obj_parts(text);
        assert_eq!(parts.len(), 2);
        assert!(parts.iter().all(|p| p.len() == 3));
    }

    #[test]
    fn a_plain_mesh_is_one_part() {
        let parts = obj_parts("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\n");
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].len(), 4);
    }

    #[test]
    fn bad_lines_are_skipped_without_panicking() {
        let text = "v 1 2\nv nan 0 0\nv 0 0 0\nf 0 9 -9 x 1/ /2 -1\nf 99999999999999999999\nv 1e400 0 0\n";
        let parts = obj_parts(text);
        // Only the valid references survive: 1 (the short vertex, at the origin) and -1.
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].len(), 2);
        assert!(obj_parts("").is_empty());
        assert!(obj_parts("v 0 0 0\n").is_empty());
    }
}
