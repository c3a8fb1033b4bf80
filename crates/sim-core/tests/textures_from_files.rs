//! Textures imported from CoppeliaSim files through the API: PyRep's `test_scene.ttt`
//! (CoppeliaSim 4.1; `$GANTRY_PYREP_TEST_SCENE`, else the first
//! `shared/pyrep/tests/assets/test_scene.ttt` beside an ancestor of this crate; where it
//! is absent the test prints a note and passes) has a cracker box wearing a 512 x 512
//! image with fixed coordinates, which `sim.getShapeViz` must give back as PyRep's
//! `Shape.get_shape_viz` and `apply_texture` tests read it, and which vision sensors
//! must draw.

use crate::util;

use std::path::PathBuf;

use gantry_sim_core::scene::{
    DiskFiles, LoadOptions, ObjectModelKind, SceneModel, load_coppelia_file, load_scene, write_scene,
};
use gantry_sim_core::{Sim, Value};
use gantry_test_support::{floats, num};
use util::{find, image_reply, ok};

/// PyRep's test scene, or `None` (with a note).
fn pyrep_test_scene() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("GANTRY_PYREP_TEST_SCENE") {
        return Some(PathBuf::from(p));
    }
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let found = here
        .ancestors()
        .map(|a| a.join("shared/pyrep/tests/assets/test_scene.ttt"))
        .find(|p| p.is_file());
    if found.is_none() {
        println!("PyRep's test_scene.ttt not found; skipped (set GANTRY_PYREP_TEST_SCENE)");
    }
    found
}

/// The value under `key` in a map.
fn get<'a>(map: &'a Value, key: &str) -> &'a Value {
    let Value::Map(entries) = map else {
        panic!("not a map: {map:?}")
    };
    entries
        .iter()
        .find(|(k, _)| matches!(k, Value::Str(s) if s == key))
        .map(|(_, v)| v)
        .unwrap_or_else(|| panic!("no '{key}'"))
}

#[test]
fn test_scene_cracker_box_texture_reads_back() {
    let Some(path) = pyrep_test_scene() else { return };
    let model = load_coppelia_file(&DiskFiles, &path).expect("test_scene.ttt imports");
    let mut w = Sim::new(&model);
    let h = Value::Int(find(&w, "/cracker_box_visual"));
    let id = num(&ok(&mut w, "sim.getShapeTextureId", std::slice::from_ref(&h))[0]);
    assert!(id >= 0.0, "the cracker box wears a texture");
    // The texture object keeps the file's name.
    let by_name = ok(&mut w, "sim.getTextureId", &[Value::from("importedTexture")]);
    assert_eq!((num(&by_name[0]), floats(&by_name[1])), (id, vec![512.0, 512.0]));

    let viz = ok(&mut w, "sim.getShapeViz", &[h.clone(), Value::Int(0)]).remove(0);
    let indices = floats(get(&viz, "indices"));
    let t = get(&viz, "texture");
    assert_eq!(num(get(t, "id")), id);
    assert_eq!(floats(get(t, "resolution")), vec![512.0, 512.0]);
    let Value::Bytes(rgba) = get(t, "texture") else {
        panic!("texture bytes")
    };
    assert_eq!(rgba.len(), 512 * 512 * 4);
    // Opaque; the file's first row (the bottom of the picture) is now the last.
    assert!(rgba.chunks_exact(4).all(|p| p[3] == 255));
    assert_eq!(&rgba[rgba.len() - 8..], &[0, 0, 0, 255, 0, 0, 0, 255]);
    let coords = floats(get(t, "coordinates"));
    assert_eq!(coords.len(), 2 * indices.len());
    assert_eq!(indices.len(), 3 * 15_728);
    // The file's first corner.
    assert!((coords[0] - 0.515_72).abs() < 1e-5 && (coords[1] - 0.089_156).abs() < 1e-5);
    // Interpolated, repeating along u and v, modulated: no option bit but the repeats.
    assert_eq!(num(get(t, "options")), 12.0);
    assert_eq!(num(get(t, "applyMode")), 0.0);

    // PyRep's test_apply_texture: the coordinates and image go back on the shape.
    let Value::Bytes(rgba) = get(t, "texture").clone() else {
        unreachable!()
    };
    let applied = ok(
        &mut w,
        "sim.applyTexture",
        &[
            h.clone(),
            Value::floats(&coords),
            Value::Bytes(rgba),
            Value::floats(&[512.0, 512.0]),
            Value::Int(16),
        ],
    );
    assert_eq!(num(&ok(&mut w, "sim.getShapeTextureId", &[h])[0]), num(&applied[0]));
}

/// `gantry convert`'s writer on `test_scene.ttt`: the textures become PNG files and the
/// cracker box's coordinates a `.uv` file beside the TOML, and loading the TOML gives
/// back the same images, the same links and the same coordinates, to the bit.
#[test]
fn test_scene_textures_survive_a_toml_round_trip() {
    let Some(path) = pyrep_test_scene() else { return };
    let model = load_coppelia_file(&DiskFiles, &path).expect("test_scene.ttt imports");
    assert_eq!(model.textures.len(), 2);
    let written = write_scene(&model, "test_scene", "test_scene.ttt").expect("writes");
    let pngs: Vec<_> = written
        .files
        .iter()
        .filter(|(p, _)| p.extension().is_some_and(|e| e == "png"))
        .collect();
    assert_eq!(pngs.len(), 2, "one PNG per texture");
    let dir = std::env::temp_dir().join(format!("gantry-textures-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    for (rel, bytes) in &written.files {
        let p = dir.join(rel);
        std::fs::create_dir_all(p.parent().expect("in the folder")).expect("mkdir");
        std::fs::write(&p, bytes).expect("write");
    }
    let back = load_scene(&DiskFiles, &dir.join("test_scene.toml"), &LoadOptions::default()).expect("loads back");
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        back.textures, model.textures,
        "the PNG files read back as the same images"
    );
    let visual_textures = |m: &SceneModel, name: &str| {
        let o = m.objects.iter().find(|o| o.alias == name).expect(name);
        let ObjectModelKind::Shape(s) = &o.kind else {
            panic!("{name}")
        };
        s.visuals.iter().map(|v| v.texture.clone()).collect::<Vec<_>>()
    };
    let before = visual_textures(&model, "cracker_box_visual");
    assert!(before[0].as_ref().is_some_and(|t| t.coordinates.is_some()));
    for o in &model.objects {
        if matches!(o.kind, ObjectModelKind::Shape(_)) {
            assert_eq!(
                visual_textures(&back, &o.alias),
                visual_textures(&model, &o.alias),
                "{}",
                o.alias
            );
        }
    }
    // And through the API, as from the binary file.
    let mut w = Sim::new(&back);
    let h = Value::Int(find(&w, "/cracker_box_visual"));
    let viz = ok(&mut w, "sim.getShapeViz", &[h, Value::Int(0)]).remove(0);
    let t = get(&viz, "texture");
    assert_eq!(floats(get(t, "resolution")), vec![512.0, 512.0]);
    assert_eq!(
        floats(get(t, "coordinates")).len(),
        2 * floats(get(&viz, "indices")).len()
    );
}

/// A vision sensor 0.5 m above the cracker box, looking down at it, sees its printed
/// box: where the box is, the image differs from the same view with the texture taken
/// off, and shows many colours where the plain box shows its few shades (288 against
/// 43 when written).
#[test]
fn test_scene_cracker_box_texture_is_seen_by_vision_sensors() {
    let Some(path) = pyrep_test_scene() else { return };
    let model = load_coppelia_file(&DiskFiles, &path).expect("test_scene.ttt imports");
    let mut w = Sim::new(&model);
    let cracker = Value::Int(find(&w, "/cracker_box_visual"));
    let at = floats(&ok(&mut w, "sim.getObjectPosition", &[cracker.clone(), Value::Int(-1)])[0]);
    // Explicit handling, perspective; 64 x 64 px, near 1 cm, far 2 m, 40 degrees.
    let sensor = ok(
        &mut w,
        "sim.createVisionSensor",
        &[
            Value::Int(1 | 2),
            Value::floats(&[64.0, 64.0, 0.0, 0.0]),
            Value::floats(&[0.01, 2.0, 40f64.to_radians(), 0.1, 0.1, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0]),
        ],
    )
    .remove(0);
    ok(
        &mut w,
        "sim.setObjectPosition",
        &[
            sensor.clone(),
            Value::Int(-1),
            Value::floats(&[at[0], at[1], at[2] + 0.5]),
        ],
    );
    // Turned over about x: the sensor's +z (its viewing axis) points down.
    ok(
        &mut w,
        "sim.setObjectOrientation",
        &[
            sensor.clone(),
            Value::Int(-1),
            Value::floats(&[std::f64::consts::PI, 0.0, 0.0]),
        ],
    );
    let view = |w: &mut Sim| {
        ok(w, "sim.handleVisionSensor", std::slice::from_ref(&sensor));
        let (rgb, res) = image_reply(&ok(w, "sim.getVisionSensorImg", std::slice::from_ref(&sensor)));
        assert_eq!(res, [64, 64]);
        rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>()
    };
    let textured = view(&mut w);
    ok(
        &mut w,
        "sim.setShapeTexture",
        &[
            cracker,
            Value::Int(-1),
            Value::Int(0),
            Value::Int(0),
            Value::floats(&[1.0, 1.0]),
        ],
    );
    let plain = view(&mut w);
    let differing: Vec<usize> = (0..textured.len()).filter(|&i| textured[i] != plain[i]).collect();
    assert!(
        differing.len() > 200,
        "only {} of 4096 pixels change with the texture",
        differing.len()
    );
    let distinct = |img: &[[u8; 3]]| {
        let mut c: Vec<[u8; 3]> = differing.iter().map(|&i| img[i]).collect();
        c.sort_unstable();
        c.dedup();
        c.len()
    };
    let (printed, bare) = (distinct(&textured), distinct(&plain));
    assert!(
        printed > 100 && printed > 3 * bare,
        "{printed} colours where the box is textured, {bare} where it is not"
    );
}
