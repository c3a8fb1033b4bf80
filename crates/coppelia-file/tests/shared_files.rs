//! Reads every public .ttt/.ttm file in the shared folder (`../shared/coppelia-files/`
//! from the repository root, or `$GANTRY_COPPELIA_FILES`) and checks facts that can be
//! verified independently of the reader: the program version against `SOURCES.md`, the
//! object tree, joint limits, IK tip/target agreement, script texts. Prints a per-file
//! table with `--nocapture`. Where the folder is absent the test prints a note and passes,
//! since the files are not part of the repository.

use std::collections::HashMap;
use std::path::PathBuf;
use std::time::Instant;

use gantry_coppelia_file::{FileType, ObjectKind, Pose, PrimitiveKind, read};

fn folder() -> PathBuf {
    match std::env::var_os("GANTRY_COPPELIA_FILES") {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/coppelia-files"),
    }
}

/// `file name -> program version` from SOURCES.md's table (`4.10.0` -> 41000).
fn sources(dir: &std::path::Path) -> HashMap<String, u16> {
    let text = std::fs::read_to_string(dir.join("SOURCES.md")).expect("SOURCES.md next to the files");
    let mut out = HashMap::new();
    for line in text.lines().filter(|l| l.starts_with("| ")) {
        let cols: Vec<&str> = line.split('|').map(str::trim).collect();
        // | file | repository | path | commit | version | bytes |
        if cols.len() < 7 || !(cols[1].ends_with(".ttt") || cols[1].ends_with(".ttm")) {
            continue;
        }
        let v: Vec<u16> = cols[5]
            .split('.')
            .map(|p| p.parse().expect("numeric version"))
            .collect();
        out.insert(
            cols[1].to_owned(),
            v[0] * 10000 + v[1] * 100 + v.get(2).copied().unwrap_or(0),
        );
    }
    out
}

#[test]
fn every_shared_file_reads_and_makes_sense() {
    let dir = folder();
    if !dir.join("SOURCES.md").is_file() {
        println!(
            "coppelia-files not found at {}; skipped (set GANTRY_COPPELIA_FILES)",
            dir.display()
        );
        return;
    }
    let versions = sources(&dir);
    let mut names: Vec<String> = versions.keys().cloned().collect();
    names.sort();
    assert!(names.len() >= 30, "SOURCES.md lists {} files", names.len());

    println!(
        "{:<42} {:>7} {:>4} {:>7} {:>6} {:>6} {:>7} {:>9} {:>8}",
        "file", "version", "ser", "objects", "shapes", "joints", "scripts", "vertices", "ms"
    );
    let mut slowest = (String::new(), 0.0f64);
    let mut tip_target_pairs = 0;
    let mut primitives = 0;
    for name in &names {
        let bytes = std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let t0 = Instant::now();
        let file = read(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        if ms > slowest.1 {
            slowest = (name.clone(), ms);
        }

        // The header agrees with the version the repository's owner recorded.
        assert_eq!(file.header.program_version, versions[name], "{name}: program version");
        let expected_type = if name.ends_with(".ttt") {
            FileType::Scene
        } else {
            FileType::Model
        };
        assert_eq!(file.header.file_type, expected_type, "{name}: file type");
        assert!(!file.objects.is_empty(), "{name}: no objects");

        // Every parent exists; handles are unique.
        let mut seen = std::collections::HashSet::new();
        for o in &file.objects {
            assert!(seen.insert(o.handle), "{name}: handle {} twice", o.handle);
            assert!(!o.name.is_empty(), "{name}: object {} has no name", o.handle);
        }
        for o in &file.objects {
            if let Some(p) = o.parent {
                assert!(file.object(p).is_some(), "{name}: {} has missing parent {p}", o.name);
            }
        }
        let world: HashMap<i32, Pose> = file
            .world_poses()
            .into_iter()
            .zip(&file.objects)
            .map(|(p, o)| {
                (
                    o.handle,
                    p.unwrap_or_else(|| panic!("{name}: {} has no world pose", o.name)),
                )
            })
            .collect();

        let (mut shapes, mut joints, mut vertices) = (0, 0, 0usize);
        for o in &file.objects {
            match &o.kind {
                ObjectKind::Shape(s) => {
                    shapes += 1;
                    assert!(!s.leaves.is_empty(), "{name}: shape {} has no mesh", o.name);
                    assert!(
                        s.mass.is_finite() && s.mass >= 0.0,
                        "{name}: {} mass {}",
                        o.name,
                        s.mass
                    );
                    for leaf in &s.leaves {
                        vertices += leaf.vertices.len();
                        assert_eq!(leaf.indices.len() % 3, 0);
                        assert!(leaf.indices.iter().all(|&i| (i as usize) < leaf.vertices.len()));
                        // A box, sphere or cylinder's triangles span its stored sizes,
                        // centred on the vertex frame: checks the mesh buffers, the
                        // primitive chunk and the frame convention against each other.
                        if matches!(
                            leaf.primitive,
                            PrimitiveKind::Cuboid | PrimitiveKind::Spheroid | PrimitiveKind::Cylinder
                        ) {
                            let mut lo = [f64::MAX; 3];
                            let mut hi = [f64::MIN; 3];
                            for v in leaf.vertices.iter() {
                                for k in 0..3 {
                                    lo[k] = lo[k].min(f64::from(v[k]));
                                    hi[k] = hi[k].max(f64::from(v[k]));
                                }
                            }
                            for k in 0..3 {
                                let tol = 1e-3 * (1.0 + leaf.size[k]);
                                assert!(
                                    (hi[k] - lo[k] - leaf.size[k]).abs() < tol && (hi[k] + lo[k]).abs() < tol,
                                    "{name}: {} {:?} of size {:?} spans {lo:?}..{hi:?}",
                                    o.name,
                                    leaf.primitive,
                                    leaf.size
                                );
                            }
                            primitives += 1;
                        }
                    }
                    let i = s.inertia_per_kg;
                    assert!(
                        (0..3).all(|a| i[a][a] >= 0.0 && (0..3).all(|b| (i[a][b] - i[b][a]).abs() < 1e-6)),
                        "{name}: {} inertia {i:?}",
                        o.name
                    );
                }
                ObjectKind::Joint(j) => {
                    joints += 1;
                    assert!(
                        j.min.is_finite() && j.range.is_finite() && j.position.is_finite(),
                        "{name}: joint {} limits {} + {}",
                        o.name,
                        j.min,
                        j.range
                    );
                    assert!(j.range >= 0.0, "{name}: joint {} range {}", o.name, j.range);
                }
                _ => {}
            }
        }

        // PyRep's robot models: the base is a model base named after the file, and the
        // IK tip and target dummies of each arm sit at the same place.
        if let Some(robot) = name.strip_prefix("PyRep__").and_then(|n| n.strip_suffix(".ttm")) {
            let base = file.objects.iter().find(|o| o.parent.is_none()).expect("a root object");
            assert!(base.model_base, "{name}: root {} is not a model base", base.name);
            let simple = |s: &str| {
                s.chars()
                    .filter(char::is_ascii_alphanumeric)
                    .collect::<String>()
                    .to_lowercase()
            };
            let (base_name, stem) = (simple(&base.name), simple(robot));
            // `XArm7.ttm` holds `xarm`: one name starts the other.
            assert!(
                stem.starts_with(&base_name) || base_name.starts_with(&stem),
                "{name}: root object is {:?}, expected {robot:?}",
                base.name
            );
            for tip in file.objects.iter().filter(|o| o.name.ends_with("_tip")) {
                let stem = &tip.name[..tip.name.len() - 4];
                let Some(target) = file.objects.iter().find(|o| o.name == format!("{stem}_target")) else {
                    continue;
                };
                let (a, b) = (world[&tip.handle].position, world[&target.handle].position);
                let d = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
                assert!(d < 1e-4, "{name}: {} and {} are {d} m apart", tip.name, target.name);
                tip_target_pairs += 1;
            }
        }

        // Script texts decode to Lua or Python, not noise.
        for s in &file.scripts {
            if s.text.is_empty() {
                assert!(
                    s.default_main,
                    "{name}: empty script that is not the default main script"
                );
                continue;
            }
            assert!(
                s.text.contains("function") || s.text.contains("sim") || s.text.contains("require"),
                "{name}: script does not look like code: {:?}",
                &s.text[..s.text.len().min(80)]
            );
            let printable = s.text.chars().filter(|c| !c.is_control() || c.is_whitespace()).count();
            assert!(
                printable * 100 >= s.text.chars().count() * 99,
                "{name}: script has control characters"
            );
        }
        if name == "paper__Blue_Robot.ttt" {
            assert!(
                file.scripts
                    .iter()
                    .any(|s| s.text.contains("socket") && s.text.contains("6000")),
                "{name}: the TCP server script (socket, port 6000) is missing"
            );
        }
        // Scenes carry their settings; the engine step divides the time step.
        if expected_type == FileType::Scene {
            let st = file.settings;
            let dt = st.time_step.expect("scene time step");
            let step = st.engine_step.expect("scene engine step");
            assert!(
                dt > 0.0 && dt < 1.0 && step > 0.0 && step <= dt,
                "{name}: dt {dt}, step {step}"
            );
            assert!(
                ((dt / step) - (dt / step).round()).abs() < 1e-3,
                "{name}: dt {dt}, step {step}"
            );
            assert!(
                st.gravity.is_some_and(|g| (g[2] + 9.81).abs() < 1e-3),
                "{name}: gravity {:?}",
                st.gravity
            );
            // Every public scene, 3.6 to 4.10, keeps CoppeliaSim's default environment:
            // the light grey-blue background gradient, a black fog colour (what vision
            // sensors show where they see nothing), fog off, a 0.4 grey ambient light.
            // Models carry no environment.
            let env = st.environment;
            let f = |v: [f32; 3]| Some(v.map(f64::from));
            assert_eq!(env.background_up, f([0.804, 0.867, 0.916]), "{name}");
            assert_eq!(env.background_down, f([0.05, 0.05, 0.1]), "{name}");
            assert_eq!(env.fog_color, Some([0.0; 3]), "{name}");
            assert_eq!(env.ambient_light, f([0.4, 0.4, 0.4]), "{name}");
            assert_eq!(env.fog_enabled, Some(false), "{name}");
            assert_eq!(env.fog, Some((0, 0.0, 0.5)), "{name}");
            assert_eq!(env.fog_end, Some(5.0), "{name}");
        } else {
            assert_eq!(file.settings.environment, Default::default(), "{name}");
        }

        println!(
            "{:<42} {:>7} {:>4} {:>7} {:>6} {:>6} {:>7} {:>9} {:>8.1}",
            name,
            file.header.program_version_text(),
            file.header.serialization_version,
            file.objects.len(),
            shapes,
            joints,
            file.scripts.len(),
            vertices,
            ms
        );
    }
    // The largest file, best of five: the figure issue 28 asks to stay under 0.5 s.
    // Reported, not asserted (a timing depends on what else the machine runs);
    // measure it with `cargo test --release -p gantry-coppelia-file --test integration shared_files::
    // -- --nocapture`.
    let largest = names
        .iter()
        .max_by_key(|n| std::fs::metadata(dir.join(n)).map(|m| m.len()).unwrap_or(0))
        .expect("files");
    let bytes = std::fs::read(dir.join(largest)).expect("read");
    let best = (0..5)
        .map(|_| {
            let t0 = Instant::now();
            read(&bytes).expect("reads");
            t0.elapsed().as_secs_f64()
        })
        .fold(f64::MAX, f64::min);
    println!(
        "largest: {largest} ({} bytes) in {:.1} ms (best of 5)",
        bytes.len(),
        best * 1e3
    );
    assert!(
        tip_target_pairs >= 5,
        "only {tip_target_pairs} IK tip/target pairs checked"
    );
    assert!(primitives >= 100, "only {primitives} primitive meshes checked");
    println!(
        "slowest: {} in {:.1} ms; {tip_target_pairs} IK tip/target pairs coincide; \
         {primitives} primitive meshes span their sizes",
        slowest.0, slowest.1
    );
}
