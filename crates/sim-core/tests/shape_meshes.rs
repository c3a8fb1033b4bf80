//! Shapes as meshes and textures, as PyRep uses them: `sim.importMesh`,
//! `sim.importShape`, `sim.getShapeMesh`, `sim.getShapeViz`, `sim.getDecimatedMesh`,
//! `sim.convexDecompose`, `sim.computeMassAndInertia`, `sim.setShapeMassAndInertia`,
//! and the texture functions (`sim.createTexture`, `sim.setShapeTexture`,
//! `sim.applyTexture`, `sim.getShapeTextureId`, `sim.getTextureId`).

use crate::util;

use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{TempDir, assert_contains, floats, int, ints, num};
use util::{err, ok, text_scene};

/// A unit cube centred on the origin as an OBJ file, each face written with its own
/// four vertices (24 in all) as exporters often do.
fn cube_obj() -> String {
    let mut s = String::from("# cube\no cube\n");
    let faces: [[[f64; 3]; 4]; 6] = [
        [
            [-0.5, -0.5, -0.5],
            [-0.5, 0.5, -0.5],
            [0.5, 0.5, -0.5],
            [0.5, -0.5, -0.5],
        ],
        [[-0.5, -0.5, 0.5], [0.5, -0.5, 0.5], [0.5, 0.5, 0.5], [-0.5, 0.5, 0.5]],
        [
            [-0.5, -0.5, -0.5],
            [0.5, -0.5, -0.5],
            [0.5, -0.5, 0.5],
            [-0.5, -0.5, 0.5],
        ],
        [[-0.5, 0.5, -0.5], [-0.5, 0.5, 0.5], [0.5, 0.5, 0.5], [0.5, 0.5, -0.5]],
        [
            [-0.5, -0.5, -0.5],
            [-0.5, -0.5, 0.5],
            [-0.5, 0.5, 0.5],
            [-0.5, 0.5, -0.5],
        ],
        [[0.5, -0.5, -0.5], [0.5, 0.5, -0.5], [0.5, 0.5, 0.5], [0.5, -0.5, 0.5]],
    ];
    for f in &faces {
        for v in f {
            s += &format!("v {} {} {}\n", v[0], v[1], v[2]);
        }
    }
    for k in 0..6 {
        let b = 4 * k + 1;
        s += &format!("f {} {} {}\nf {} {} {}\n", b, b + 1, b + 2, b, b + 2, b + 3);
    }
    s
}

fn sim_in(dir: &TempDir) -> Sim {
    text_scene(&dir.path().join("scene.toml").to_string_lossy(), "")
}

fn s(x: &str) -> Value {
    Value::from(x)
}

fn f(x: f64) -> Value {
    Value::Float(x)
}

/// A map reply's entry.
fn entry<'a>(map: &'a Value, key: &str) -> &'a Value {
    map.get(key).unwrap_or_else(|| panic!("no '{key}' in {map:?}"))
}

fn cuboid(sim: &mut Sim, size: f64) -> Handle {
    int(&ok(sim, "createPrimitiveShape", &[Value::Int(3), Value::floats(&[size; 3])])[0])
}

#[test]
fn obj_files_import_as_meshes_and_shapes() {
    let dir = TempDir::new("import-obj");
    let obj = dir.write("cube.obj", cube_obj());
    let mut sim = sim_in(&dir);
    let path = s(&obj.to_string_lossy());
    // Identical vertices are merged by default: 8 corners, 12 triangles.
    let r = ok(
        &mut sim,
        "importMesh",
        &[Value::Int(0), path.clone(), Value::Int(0), f(0.0), f(2.0)],
    );
    let (Value::Array(vs), Value::Array(is)) = (&r[0], &r[1]) else {
        panic!("tables of tables: {r:?}");
    };
    assert_eq!((vs.len(), is.len()), (1, 1), "one mesh");
    let v = floats(&vs[0]);
    assert_eq!((v.len(), ints(&is[0]).len()), (24, 36));
    assert!(v.iter().all(|c| c.abs() == 1.0), "scaled by 2: {v:?}");
    // Option bit 0 keeps them (the loader gives each triangle corner its own vertex).
    let r = ok(
        &mut sim,
        "importMesh",
        &[Value::Int(0), path.clone(), Value::Int(1), f(0.0), f(1.0)],
    );
    let Value::Array(vs) = &r[0] else { panic!() };
    assert!(floats(&vs[0]).len() >= 72, "{}", floats(&vs[0]).len());

    let h = int(&ok(
        &mut sim,
        "importShape",
        &[Value::Int(0), path.clone(), Value::Int(16), f(0.0), f(1.0)],
    )[0]);
    assert_eq!(ok(&mut sim, "getObjectAlias", &[Value::Int(h)])[0], s("cube"));
    let mesh = ok(&mut sim, "getShapeMesh", &[Value::Int(h)]);
    assert_eq!(
        (floats(&mesh[0]).len(), ints(&mesh[1]).len(), floats(&mesh[2]).len()),
        (24, 36, 108)
    );

    // Missing file, broken faces, a format gantry cannot read, bad numbers.
    let missing = s(&dir.path().join("nope.obj").to_string_lossy());
    assert_contains(
        err(
            &mut sim,
            "importShape",
            &[Value::Int(0), missing, Value::Int(0), f(0.0), f(1.0)],
        ),
        &["no file"],
    );
    let broken = dir.write("broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
    let broken = s(&broken.to_string_lossy());
    assert!(
        !err(
            &mut sim,
            "importMesh",
            &[Value::Int(0), broken, Value::Int(0), f(0.0), f(1.0)]
        )
        .is_empty()
    );
    let dxf = s(&dir.write("a.dxf", "0\nEOF\n").to_string_lossy());
    assert_contains(
        err(
            &mut sim,
            "importMesh",
            &[Value::Int(1), dxf, Value::Int(0), f(0.0), f(1.0)],
        ),
        &["format"],
    );
    assert_contains(
        err(
            &mut sim,
            "importMesh",
            &[Value::Int(0), path.clone(), Value::Int(0), f(0.0), f(f64::NAN)],
        ),
        &["scaling"],
    );
    assert_contains(
        err(
            &mut sim,
            "importMesh",
            &[Value::Int(9), path, Value::Int(0), f(0.0), f(1.0)],
        ),
        &["format"],
    );
}

#[test]
fn stl_files_import_too() {
    let dir = TempDir::new("import-stl");
    let stl = dir.write(
        "tri.stl",
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n",
    );
    let mut sim = sim_in(&dir);
    let r = ok(
        &mut sim,
        "importMesh",
        &[Value::Int(3), s(&stl.to_string_lossy()), Value::Int(0), f(0.0), f(1.0)],
    );
    let Value::Array(is) = &r[1] else { panic!() };
    assert_eq!(ints(&is[0]), [0, 1, 2]);
}

#[test]
fn a_box_mesh_is_eight_vertices_and_twelve_triangles() {
    let dir = TempDir::new("box-mesh");
    let mut sim = sim_in(&dir);
    let h = cuboid(&mut sim, 0.1);
    let mesh = ok(&mut sim, "getShapeMesh", &[Value::Int(h)]);
    let v = floats(&mesh[0]);
    assert_eq!(
        (v.len() / 3, ints(&mesh[1]).len() / 3, floats(&mesh[2]).len() / 3),
        (8, 12, 36)
    );
    assert!(v.iter().all(|c| (c.abs() - 0.05).abs() < 1e-9), "{v:?}");
    // Every normal is a unit axis.
    for n in floats(&mesh[2]).chunks(3) {
        assert!((n.iter().map(|c| c * c).sum::<f64>() - 1.0).abs() < 1e-9);
    }
    let viz = &ok(&mut sim, "getShapeViz", &[Value::Int(h), Value::Int(0)])[0];
    assert_eq!(floats(entry(viz, "vertices")).len(), 24);
    assert_eq!(floats(entry(viz, "colors")).len(), 9);
    assert!(num(entry(viz, "shadingAngle")) > 0.0);
    assert!(viz.get("texture").is_none(), "not textured");
    assert_contains(
        err(&mut sim, "getShapeViz", &[Value::Int(h), Value::Int(1)]),
        &["visual items"],
    );
    let dummy = int(&ok(&mut sim, "createDummy", &[f(0.1)])[0]);
    assert!(!err(&mut sim, "getShapeMesh", &[Value::Int(dummy)]).is_empty());
}

#[test]
fn mass_and_inertia_come_from_density_and_round_trip() {
    let dir = TempDir::new("mass");
    let mut sim = sim_in(&dir);
    let h = cuboid(&mut sim, 1.0);
    assert_eq!(
        ok(&mut sim, "computeMassAndInertia", &[Value::Int(h), f(2000.0)]),
        [Value::Int(1)]
    );
    assert!((num(&ok(&mut sim, "getShapeMass", &[Value::Int(h)])[0]) - 2000.0).abs() < 1e-6);
    for bad in [-1.0, 0.0, f64::NAN] {
        assert_contains(
            err(&mut sim, "computeMassAndInertia", &[Value::Int(h), f(bad)]),
            &["density"],
        );
    }
    let per_kg = [0.2, 0.0, 0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 0.4];
    ok(
        &mut sim,
        "setShapeMassAndInertia",
        &[
            Value::Int(h),
            f(3.0),
            Value::floats(&per_kg),
            Value::floats(&[0.01, 0.02, 0.03]),
        ],
    );
    let r = ok(&mut sim, "getShapeMassAndInertia", &[Value::Int(h)]);
    assert!((num(&r[0]) - 3.0).abs() < 1e-12);
    gantry_test_support::assert_close(&floats(&r[1]), &per_kg, 1e-9);
    gantry_test_support::assert_close(&floats(&r[2]), &[0.01, 0.02, 0.03], 1e-9);
    assert!(
        !err(
            &mut sim,
            "setShapeMassAndInertia",
            &[Value::Int(h), f(-3.0), Value::floats(&per_kg), Value::floats(&[0.0; 3])]
        )
        .is_empty()
    );
}

#[test]
fn decimation_and_convex_decomposition() {
    let dir = TempDir::new("decimate");
    let mut sim = sim_in(&dir);
    let ball = int(&ok(
        &mut sim,
        "createPrimitiveShape",
        &[Value::Int(4), Value::floats(&[1.0; 3])],
    )[0]);
    let mesh = ok(&mut sim, "getShapeMesh", &[Value::Int(ball)]);
    let n = ints(&mesh[1]).len();
    let r = ok(
        &mut sim,
        "getDecimatedMesh",
        &[mesh[0].clone(), mesh[1].clone(), f(0.2)],
    );
    let m = ints(&r[1]).len();
    assert!(m > 0 && (m as f64) < n as f64 * 0.3, "{m} of {n} indices");
    assert_contains(
        err(
            &mut sim,
            "getDecimatedMesh",
            &[mesh[0].clone(), mesh[1].clone(), f(0.95)],
        ),
        &["0.1 to 0.9"],
    );
    assert!(
        !err(
            &mut sim,
            "getDecimatedMesh",
            &[mesh[0].clone(), Value::floats(&[0.0, 1.0, 1e9]), f(0.5)]
        )
        .is_empty()
    );

    // An L of two bars: not convex, so it decomposes into at least two parts.
    let mut v = Vec::new();
    let mut i = Vec::new();
    for (x0, y0, x1, y1) in [(0.0, 0.0, 2.0, 0.2), (0.0, 0.0, 0.2, 2.0)] {
        let base = (v.len() / 3) as f64;
        for (x, y, z) in [
            (x0, y0, 0.0),
            (x1, y0, 0.0),
            (x1, y1, 0.0),
            (x0, y1, 0.0),
            (x0, y0, 0.2),
            (x1, y0, 0.2),
            (x1, y1, 0.2),
            (x0, y1, 0.2),
        ] {
            v.extend([x, y, z]);
        }
        for t in [
            [0, 2, 1],
            [0, 3, 2],
            [4, 5, 6],
            [4, 6, 7],
            [0, 1, 5],
            [0, 5, 4],
            [1, 2, 6],
            [1, 6, 5],
            [2, 3, 7],
            [2, 7, 6],
            [3, 0, 4],
            [3, 4, 7],
        ] {
            i.extend(t.map(|k| base + f64::from(k)));
        }
    }
    let l = int(&ok(
        &mut sim,
        "createMeshShape",
        &[Value::Int(0), f(0.3), Value::floats(&v), Value::floats(&i)],
    )[0]);
    let params = [Value::floats(&[0.0; 10]), Value::floats(&[0.0; 10])];
    let d = int(&ok(
        &mut sim,
        "convexDecompose",
        &[Value::Int(l), Value::Int(128), params[0].clone(), params[1].clone()],
    )[0]);
    assert_ne!(d, l);
    let info = ok(&mut sim, "getShapeGeomInfo", &[Value::Int(d)]);
    assert_eq!(int(&info[0]) & 1, 1, "a compound");
    let m = int(&ok(
        &mut sim,
        "convexDecompose",
        &[Value::Int(l), Value::Int(1), params[0].clone(), params[1].clone()],
    )[0]);
    assert_eq!(m, l, "morphed in place");
    assert_eq!(int(&ok(&mut sim, "getShapeGeomInfo", &[Value::Int(l)])[0]) & 1, 1);
}

/// A 3 x 2 JPEG (red, green, blue over white, black, grey; quality 100, no chroma
/// subsampling), as hex: gantry has no JPEG encoder to make one in the test.
const TINY_JPEG_HEX: &str = concat!(
    "ffd8ffe000104a46494600010100000100010000ffdb0043000101010101010101010101010101010101010101010101",
    "0101010101010101010101010101010101010101010101010101010101010101010101010101010101ffdb0043010101",
    "010101010101010101010101010101010101010101010101010101010101010101010101010101010101010101010101",
    "0101010101010101010101010101ffc00011080002000303011100021101031101ffc400140001000000000000000000",
    "00000000000007ffc4001b10000203010101000000000000000000000506030407080102ffc400150101010000000000",
    "0000000000000000000407ffc4001a110100030101010000000000000000000005030406070102ffda000c0301000211",
    "0311003f002a6ac4b1860d7fa7e63f91e606e609da5dbe8e1652e82a84a510959cf5e6d6819ea80b92e899bea82ba222",
    "2d2e2526afd4f6212b0a4be116c254a218550a5053b07db3b372ccb1d86e63d73a7739c48f2a93918ec1ef75590cb173",
    "b6bdfd03531d9ecfac7934655de5136d492b548bed05d1be95bf65b972c4d20ae9c7a4930ca34295f5f44ebba8d02b76",
    "ac1692774da862ee874da262f4f1c96937744fa68b8eaf7659d05d842ea6858b176dcf3c9fffd9",
);

/// A 2 x 1 RGBA PNG: opaque red, half-transparent blue.
fn tiny_png() -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut e = png::Encoder::new(&mut out, 2, 1);
        e.set_color(png::ColorType::Rgba);
        e.set_depth(png::BitDepth::Eight);
        let mut w = e.write_header().expect("header");
        w.write_image_data(&[255, 0, 0, 255, 0, 0, 255, 128]).expect("pixels");
    }
    out
}

#[test]
fn textures_are_created_worn_and_read_back() {
    let dir = TempDir::new("textures");
    let jpeg: Vec<u8> = (0..TINY_JPEG_HEX.len() / 2)
        .map(|k| u8::from_str_radix(&TINY_JPEG_HEX[2 * k..2 * k + 2], 16).expect("hex"))
        .collect();
    let jpg = dir.write("wood.jpg", jpeg);
    let png = dir.write("dots.png", tiny_png());
    let mut sim = sim_in(&dir);

    // A JPEG plane: 1 m along the longer side.
    let r = ok(&mut sim, "createTexture", &[s(&jpg.to_string_lossy()), Value::Int(0)]);
    let (plane, id) = (int(&r[0]), int(&r[1]));
    assert!(id >= 0);
    assert_eq!(ints(&r[2]), [3, 2]);
    assert_eq!(int(&ok(&mut sim, "getShapeTextureId", &[Value::Int(plane)])[0]), id);
    let found = ok(&mut sim, "getTextureId", &[s("wood")]);
    assert_eq!((int(&found[0]), ints(&found[1])), (id, vec![3, 2]));
    assert_eq!(int(&ok(&mut sim, "getTextureId", &[s("nothing")])[0]), -1);
    let geom = ok(&mut sim, "getShapeGeomInfo", &[Value::Int(plane)]);
    assert_eq!(int(&geom[1]), 1, "a plane");
    gantry_test_support::assert_close(&floats(&geom[2])[..2], &[1.0, 2.0 / 3.0], 1e-9);
    let viz = &ok(&mut sim, "getShapeViz", &[Value::Int(plane), Value::Int(0)])[0];
    let t = entry(viz, "texture");
    let Value::Bytes(pixels) = entry(t, "texture") else {
        panic!("bytes")
    };
    assert_eq!(pixels.len(), 3 * 2 * 4);
    // JPEG is lossy; quality 100 keeps these flat colours within a few levels.
    assert!(pixels[0] > 230 && pixels[1] < 25 && pixels[3] == 255, "{pixels:?}");
    let coords = floats(entry(t, "coordinates"));
    assert_eq!(coords.len(), floats(entry(viz, "indices")).len() * 2);
    assert!(coords.iter().all(|c| (-1e-6..=1.0 + 1e-6).contains(c)), "{coords:?}");

    // A PNG texture put on a cube.
    let r = ok(&mut sim, "createTexture", &[s(&png.to_string_lossy()), Value::Int(0)]);
    let dots = int(&r[1]);
    assert_ne!(dots, id);
    let cube = cuboid(&mut sim, 0.2);
    assert_eq!(int(&ok(&mut sim, "getShapeTextureId", &[Value::Int(cube)])[0]), -1);
    ok(
        &mut sim,
        "setShapeTexture",
        &[
            Value::Int(cube),
            Value::Int(dots),
            Value::Int(3),
            Value::Int(4),
            Value::floats(&[0.2, 0.2]),
        ],
    );
    assert_eq!(int(&ok(&mut sim, "getShapeTextureId", &[Value::Int(cube)])[0]), dots);
    let viz = &ok(&mut sim, "getShapeViz", &[Value::Int(cube), Value::Int(0)])[0];
    let t = entry(viz, "texture");
    assert_eq!(
        (
            int(entry(t, "id")),
            int(entry(t, "applyMode")),
            int(entry(t, "options"))
        ),
        (dots, 3, 4)
    );
    assert_eq!(entry(t, "texture"), &Value::Bytes(vec![255, 0, 0, 255, 0, 0, 255, 128]));
    assert_eq!(ints(entry(t, "resolution")), [2, 1]);
    // Cube mapping: each face's corners at 0 or 1 (the face spans the texture).
    let c = floats(entry(t, "coordinates"));
    assert!(c.iter().all(|c| c.abs() < 1e-6 || (c - 1.0).abs() < 1e-6), "{c:?}");

    // Explicit coordinates and an RGB image read back exactly; bit 6 flips rows.
    let coords: Vec<f64> = (0..12 * 6).map(|k| f64::from(k % 5) * 0.25).collect();
    let image = vec![1, 2, 3, 4, 5, 6];
    let applied = int(&ok(
        &mut sim,
        "applyTexture",
        &[
            Value::Int(cube),
            Value::floats(&coords),
            Value::Bytes(image),
            Value::floats(&[1.0, 2.0]),
            Value::Int(64),
        ],
    )[0]);
    assert_eq!(int(&ok(&mut sim, "getShapeTextureId", &[Value::Int(cube)])[0]), applied);
    let viz = &ok(&mut sim, "getShapeViz", &[Value::Int(cube), Value::Int(0)])[0];
    let t = entry(viz, "texture");
    assert_eq!(floats(entry(t, "coordinates")), coords);
    assert_eq!(entry(t, "texture"), &Value::Bytes(vec![4, 5, 6, 255, 1, 2, 3, 255]));
    // Removing it.
    ok(
        &mut sim,
        "setShapeTexture",
        &[
            Value::Int(cube),
            Value::Int(-1),
            Value::Int(0),
            Value::Int(0),
            Value::floats(&[1.0, 1.0]),
        ],
    );
    assert_eq!(int(&ok(&mut sim, "getShapeTextureId", &[Value::Int(cube)])[0]), -1);

    // Refusals: absurd sizes, wrong byte and coordinate counts, bad modes, bad files.
    let rgb = |n: usize| Value::Bytes(vec![0; n]);
    let apply = |coords: &[f64], image: Value, res: [f64; 2]| {
        [
            Value::Int(cube),
            Value::floats(coords),
            image,
            Value::floats(&res),
            Value::Int(0),
        ]
    };
    assert_contains(
        err(&mut sim, "applyTexture", &apply(&coords, rgb(3), [100000.0, 1.0])),
        &["resolution"],
    );
    assert_contains(
        err(&mut sim, "applyTexture", &apply(&coords, rgb(5), [1.0, 2.0])),
        &["bytes"],
    );
    assert_contains(
        err(&mut sim, "applyTexture", &apply(&coords[..6], rgb(6), [1.0, 2.0])),
        &["12 triangles"],
    );
    let bad_mode = [
        Value::Int(cube),
        Value::Int(dots),
        Value::Int(7),
        Value::Int(0),
        Value::floats(&[1.0, 1.0]),
    ];
    assert_contains(err(&mut sim, "setShapeTexture", &bad_mode), &["mapping mode"]);
    let no_texture = [
        Value::Int(cube),
        Value::Int(999),
        Value::Int(0),
        Value::Int(0),
        Value::floats(&[1.0, 1.0]),
    ];
    assert_contains(err(&mut sim, "setShapeTexture", &no_texture), &["texture 999"]);
    let missing = s(&dir.path().join("none.png").to_string_lossy());
    assert!(!err(&mut sim, "createTexture", &[missing, Value::Int(0)]).is_empty());
    let junk = dir.write("junk.png", b"not an image at all");
    assert_contains(
        err(&mut sim, "createTexture", &[s(&junk.to_string_lossy()), Value::Int(0)]),
        &["PNG or JPEG"],
    );
    // A fixed resolution resamples; an absurd one is refused.
    let r = ok(
        &mut sim,
        "createTexture",
        &[
            s(&png.to_string_lossy()),
            Value::Int(0),
            Value::Nil,
            Value::Nil,
            Value::Nil,
            Value::Int(1),
            Value::floats(&[4.0, 2.0]),
        ],
    );
    assert_eq!(ints(&r[2]), [4, 2]);
    let huge = [
        s(&png.to_string_lossy()),
        Value::Int(0),
        Value::Nil,
        Value::Nil,
        Value::Nil,
        Value::Int(1),
        Value::floats(&[1e6, 2.0]),
    ];
    assert_contains(err(&mut sim, "createTexture", &huge), &["resolution"]);
}

#[test]
fn bounding_boxes_reorient_with_the_frame() {
    let dir = TempDir::new("reorient");
    let mut sim = sim_in(&dir);
    let h = cuboid(&mut sim, 0.2);
    ok(
        &mut sim,
        "setObjectOrientation",
        &[Value::Int(h), Value::Int(-1), Value::floats(&[0.0, 0.0, 0.5])],
    );
    let before = floats(&ok(&mut sim, "getObjectPosition", &[Value::Int(h), Value::Int(-1)])[0]);
    assert_eq!(
        ok(&mut sim, "reorientShapeBoundingBox", &[Value::Int(h), Value::Int(-1)]),
        [Value::Int(1)]
    );
    let e = floats(&ok(&mut sim, "getObjectOrientation", &[Value::Int(h), Value::Int(-1)])[0]);
    gantry_test_support::assert_close(&e, &[0.0; 3], 1e-12);
    let after = floats(&ok(&mut sim, "getObjectPosition", &[Value::Int(h), Value::Int(-1)])[0]);
    gantry_test_support::assert_close(&after, &before, 1e-12);
    // The turned cube's box, along the world axes, is wider than the cube.
    let mesh = ok(&mut sim, "getShapeMesh", &[Value::Int(h)]);
    let xmax = floats(&mesh[0]).chunks(3).map(|v| v[0]).fold(f64::MIN, f64::max);
    assert!((xmax - 0.1 * (0.5f64.cos() + 0.5f64.sin())).abs() < 1e-6, "{xmax}");
    assert_eq!(
        ok(&mut sim, "reorientShapeBoundingBox", &[Value::Int(h), Value::Int(-4)]),
        [Value::Int(1)]
    );
    assert!(
        !err(
            &mut sim,
            "reorientShapeBoundingBox",
            &[Value::Int(h), Value::Int(12345)]
        )
        .is_empty()
    );
}
