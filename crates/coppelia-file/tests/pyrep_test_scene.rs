//! Lights and the old path of PyRep's `test_scene.ttt` (CoppeliaSim 4.1), the scene
//! PyRep's own tests open (`../shared/pyrep/tests/assets/` from the repository root, or
//! `$GANTRY_PYREP_TEST_SCENE`). The file is not part of the repository; the test
//! command reads it from the shared folder, and a missing file fails the test.

use std::path::PathBuf;

use gantry_coppelia_file::{LightType, ObjectKind, read};

fn scene() -> Option<Vec<u8>> {
    // `Option` for the callers' `let Some(..) else`; a missing file panics below.
    let path = match std::env::var_os("GANTRY_PYREP_TEST_SCENE") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/pyrep/tests/assets/test_scene.ttt"),
    };
    match std::fs::read(&path) {
        Ok(b) => Some(b),
        Err(e) => panic!(
            "PyRep's test scene {}: {e} (it comes from ../shared; set GANTRY_PYREP_TEST_SCENE)",
            path.display()
        ),
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-6
}

#[test]
fn test_scene_lights_and_old_path_read() {
    let Some(bytes) = scene() else { return };
    let f = read(&bytes).unwrap();
    let by_name = |n: &str| f.objects.iter().find(|o| o.name == n).unwrap_or_else(|| panic!("{n}"));

    // PyRep's three test lights: off, of the three kinds, with the 4.1 defaults.
    for (name, kind) in [
        ("spot_light", LightType::Spot),
        ("omni_light", LightType::Omnidirectional),
        ("directed_light", LightType::Directional),
    ] {
        let o = by_name(name);
        let ObjectKind::Light(l) = &o.kind else {
            panic!("{name} is not a light: {:?}", o.kind)
        };
        assert_eq!(l.light_type, kind, "{name}");
        assert!(!l.on && !l.local, "{name}");
        assert_eq!(l.spot_exponent, 5);
        assert!(close(l.spot_cutoff, std::f64::consts::FRAC_PI_2));
        assert!(close(l.attenuation[0], 0.25) && l.attenuation[1] == 0.0 && close(l.attenuation[2], 0.1));
        assert_eq!((l.diffuse, l.specular), ([0.5; 3], [0.5; 3]));
        assert!(gantry_coppelia_file::light::pov_casts_shadows(&o.extension), "{name}");
    }
    // A default scene light: on, directional, grey.
    let ObjectKind::Light(b) = &by_name("DefaultLightB").kind else {
        panic!("DefaultLightB")
    };
    assert!(b.on && b.light_type == LightType::Directional);
    assert!(close(b.diffuse[0], 0.4) && close(b.specular[2], 0.9));

    // The old path: three control points on a 0.051 m arc, open.
    let o = by_name("cartesian_path");
    let ObjectKind::Path(p) = &o.kind else {
        panic!("cartesian_path is not a path: {:?}", o.kind)
    };
    assert_eq!((p.points.len(), p.attributes, p.closed()), (3, 1187, false));
    for (k, pt) in p.points.iter().enumerate() {
        let angle = k as f64 * std::f64::consts::PI / 8.0;
        let [x, y, z] = pt.position;
        assert!(
            close(x, 0.05098 * angle.cos()) || (x - 0.05098 * angle.cos()).abs() < 1e-4,
            "{k}: {x}"
        );
        assert!((y - 0.05098 * angle.sin()).abs() < 1e-4 && z == 0.0, "{k}: {y}");
        // A half turn about a horizontal axis: w and z near zero, a unit quaternion.
        let [w, qx, qy, qz] = pt.rotation;
        assert!(
            w.abs() < 1e-6 && qz.abs() < 1e-6 && close(qx * qx + qy * qy, 1.0),
            "{k}"
        );
        assert!(close(pt.bezier_factors[0], 0.95) && pt.bezier_points == 15);
    }
    assert!(close(o.local_pose.position[2], 0.55));
}

#[test]
fn test_scene_environment_reads() {
    let Some(bytes) = scene() else { return };
    let env = read(&bytes).unwrap().settings.environment;
    // CoppeliaSim 4.1's defaults, saved as f32: the grey-blue background gradient, and
    // the black fog colour its vision sensors show where they see nothing.
    assert_eq!(env.background_up, Some([0.804f32, 0.867, 0.916].map(f64::from)));
    assert_eq!(env.background_down, Some([0.05f32, 0.05, 0.1].map(f64::from)));
    assert_eq!(env.fog_color, Some([0.0; 3]));
    assert_eq!(
        (env.fog_enabled, env.fog, env.fog_end),
        (Some(false), Some((0, 0.0, 0.5)), Some(5.0))
    );
}

#[test]
fn test_scene_cracker_box_texture_reads() {
    let Some(bytes) = scene() else { return };
    let f = read(&bytes).unwrap();
    // Two texture objects: a 256 x 256 concrete and the cracker box's 512 x 512 image.
    assert_eq!(f.textures.len(), 2);
    let concrete = &f.textures[0];
    assert_eq!(
        (concrete.id, concrete.name.as_str(), concrete.resolution),
        (2_180_009, "garageConcrete3", [256, 256])
    );
    let image = &f.textures[1];
    assert_eq!(
        (image.id, image.name.as_str(), image.resolution),
        (2_180_010, "importedTexture", [512, 512])
    );
    assert_eq!(image.rgba.len(), 512 * 512 * 4);
    // The first pixels are opaque black; the concrete's first is a light grey-beige.
    assert_eq!(&image.rgba[..8], &[0, 0, 0, 255, 0, 0, 0, 255]);
    assert_eq!(&concrete.rgba[..8], &[0xf7, 0xf1, 0xe5, 0xff, 0xf7, 0xf1, 0xe4, 0xff]);

    let o = f.objects.iter().find(|o| o.name == "cracker_box_visual").unwrap();
    let ObjectKind::Shape(s) = &o.kind else {
        panic!("not a shape")
    };
    assert_eq!(s.leaves.len(), 1);
    let leaf = &s.leaves[0];
    let t = leaf.texture.as_ref().expect("the cracker box wears a texture");
    assert_eq!(t.texture, image.id);
    assert_eq!(t.mapping, gantry_coppelia_file::TextureMapping::Plane);
    assert_eq!(
        (t.apply_mode, t.interpolate, t.repeat_u, t.repeat_v),
        (0, true, true, true)
    );
    let coords = t.coordinates.as_ref().expect("fixed coordinates");
    // u, v for each corner of each triangle.
    assert_eq!(coords.len(), 2 * leaf.indices.len());
    assert_eq!(leaf.indices.len(), 3 * 15_728);
    assert!(
        (coords[0] - 0.515_722).abs() < 1e-5 && (coords[1] - 0.089_155).abs() < 1e-5,
        "{:?}",
        &coords[..2]
    );
    assert!(coords.iter().all(|c| c.is_finite()));
}

#[test]
fn spherical_sensor_user_parameters_read() {
    let Some(bytes) = scene() else { return };
    let f = read(&bytes).unwrap();
    // The model's script reads these with `sim.getScriptSimulationParameter`.
    let o = f
        .objects
        .iter()
        .find(|o| o.name == "sphericalVisionRGBAndDepth")
        .expect("the spherical sensor's base");
    let got: Vec<(&str, &str, &str)> = o
        .user_parameters
        .iter()
        .map(|p| (p.name.as_str(), p.unit.as_str(), p.value.as_str()))
        .collect();
    assert_eq!(
        got,
        [
            ("sensorResolutionX", "pixels", "512"),
            ("sensorResolutionY", "pixels", "256"),
            ("boxSensorResolutionXY", "pixels", "128"),
            ("horizontalAngle", "degrees (5-360)", "360"),
            ("verticalAngle", "degrees (5-180)", "180"),
            ("updateEveryXSimulationPass", "-", "1"),
        ]
    );
    assert!(o.user_parameters.iter().all(|p| p.properties == 1));
    let others = f.objects.iter().filter(|o| !o.user_parameters.is_empty()).count();
    assert_eq!(others, 1, "only the spherical sensor holds user parameters");
}
