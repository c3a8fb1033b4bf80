//! What the scene and URDF targets share: an in-memory file set (the shipped robot,
//! scripts and a tiny mesh, so fuzzed scenes that reference them resolve for real and
//! never touch the disk) and the invariants every resolved model must keep.

use std::collections::HashMap;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use gantry_scene::scene::{EmbeddedFiles, Files, Geometry, ObjectModelKind, SceneModel, normalize_path};

/// A unit cube as OBJ text: the mesh fuzzed scenes can reference as
/// `../meshes/cube.obj` (from `assets/scenes/`).
const CUBE_OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

/// One ASCII STL triangle, for the `.stl` path of the mesh loader.
const TRI_STL: &[u8] = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
endloop\nendfacet\nendsolid t\n";

/// The shipped files (as the binary embeds them) plus the meshes: built once per
/// process, so each run costs only the load itself.
struct Shipped {
    embedded: EmbeddedFiles,
    meshes: HashMap<PathBuf, &'static [u8]>,
}

/// `(path relative to the repository root, its bytes)`, compiled in.
macro_rules! repo_file {
    ($path:literal) => {
        ($path, include_bytes!(concat!("../../../", $path)) as &'static [u8])
    };
}

fn shipped() -> &'static Shipped {
    static SHIPPED: OnceLock<Shipped> = OnceLock::new();
    SHIPPED.get_or_init(|| Shipped {
        embedded: EmbeddedFiles::new(&[
            repo_file!("assets/scenes/showroom.toml"),
            repo_file!("assets/scenes/bubble_rob.toml"),
            repo_file!("assets/scenes/fk_arm.toml"),
            repo_file!("assets/robots/arm6/arm6.urdf"),
            repo_file!("scripts/bubble_rob.lua"),
            repo_file!("scripts/fk_server.lua"),
            repo_file!("scripts/edge_detect.lua"),
        ]),
        meshes: [("assets/meshes/cube.obj", CUBE_OBJ), ("assets/meshes/tri.stl", TRI_STL)]
            .into_iter()
            .map(|(p, b)| (EmbeddedFiles::path(p), b))
            .collect(),
    })
}

/// The shipped files and meshes, plus at most one file whose bytes come from the
/// fuzzer.
pub struct MemFiles<'a> {
    extra: Option<(PathBuf, &'a [u8])>,
}

impl<'a> MemFiles<'a> {
    /// The shipped set; `extra` adds (or shadows) one file by virtual path.
    pub fn new(extra: Option<(PathBuf, &'a [u8])>) -> Self {
        Self {
            extra: extra.map(|(p, b)| (normalize_path(&p), b)),
        }
    }
}

impl Files for MemFiles<'_> {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        let key = normalize_path(path);
        if let Some((p, b)) = &self.extra
            && *p == key
        {
            return Ok(b.to_vec());
        }
        match shipped().meshes.get(&key) {
            Some(b) => Ok(b.to_vec()),
            None => shipped().embedded.read(path),
        }
    }

    fn is_file(&self, path: &Path) -> bool {
        let key = normalize_path(path);
        self.extra.as_ref().is_some_and(|(p, _)| *p == key)
            || shipped().meshes.contains_key(&key)
            || shipped().embedded.is_file(path)
    }
}

/// What the resolver promises about every model it returns (`scene::model` docs):
/// parents come before their children, scripts name existing objects, the settings
/// are in range, and every mesh index names a vertex.
pub fn check_model(m: &SceneModel) {
    for (i, o) in m.objects.iter().enumerate() {
        if let Some(p) = o.parent {
            assert!(p < i, "object {i} ({}) has parent {p}, not before it", o.alias);
        }
        if let ObjectModelKind::Shape(s) = &o.kind {
            let geometries = s.geoms.iter().map(|g| &g.geometry);
            for g in geometries.chain(s.visuals.iter().map(|v| &v.geometry)) {
                if let Geometry::Mesh(mesh) = g {
                    let n = mesh.vertices.len();
                    assert!(!mesh.indices.is_empty(), "empty mesh {}", mesh.source.display());
                    assert!(mesh.indices.iter().flatten().all(|&i| (i as usize) < n));
                }
            }
        }
    }
    for s in &m.scripts {
        assert!(
            s.object < m.objects.len(),
            "script {} on object {}",
            s.path.display(),
            s.object
        );
    }
    let st = &m.settings;
    assert!(st.dt.is_finite() && st.dt > 0.0 && st.dt <= 1.0, "dt {}", st.dt);
    assert!((1..=1000).contains(&st.substeps), "substeps {}", st.substeps);
    assert!(st.gravity.iter().all(|g| g.is_finite()), "gravity {:?}", st.gravity);
}
