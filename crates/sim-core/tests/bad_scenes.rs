//! Bad scene and URDF files (issue #9): each is refused with a message that names the
//! file, and the line and column where the file's syntax or structure is at fault, and
//! warns rather than fails where the scene is still meaningful (unknown keys).
//!
//! Every test ends by loading a good scene, to show that a failed load leaves nothing
//! behind that could break the next one (the loader keeps no state between loads).

use std::path::Path;

use gantry_sim_core::scene::{DiskFiles, LoadError, LoadOptions, SceneModel, load_scene, load_scene_text};
use gantry_test_support::{TempDir, assert_contains, repo};

fn load(path: &Path) -> Result<SceneModel, LoadError> {
    load_scene(&DiskFiles, path, &LoadOptions::default())
}

/// The error of a load that must fail, as the user reads it.
#[track_caller]
fn load_err(path: &Path) -> String {
    match load(path) {
        Ok(m) => panic!(
            "{} loaded ({} objects); expected an error",
            path.display(),
            m.objects.len()
        ),
        Err(e) => e.to_string(),
    }
}

/// The shipped BubbleRob scene still loads: a failed load poisoned nothing.
#[track_caller]
fn good_scene_still_loads() {
    let model = load(&repo("assets/scenes/bubble_rob.toml")).expect("the shipped scene loads after a failed one");
    assert!(model.objects.len() > 5);
}

/// A two-link robot, valid; `{extra}` is spliced in before `</robot>`.
fn urdf(extra: &str) -> String {
    format!(
        "<robot name=\"r\">\n\
         <link name=\"base\"/>\n\
         <link name=\"arm\"/>\n\
         <joint name=\"shoulder\" type=\"revolute\">\n\
         <parent link=\"base\"/><child link=\"arm\"/>\n\
         <axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"5\" velocity=\"1\"/>\n\
         </joint>\n\
         {extra}</robot>\n"
    )
}

/// A scene that includes `r.urdf` from its folder.
const INCLUDES_URDF: &str = "[[robot]]\nname = \"bot\"\nurdf = \"r.urdf\"\n";

#[test]
fn a_missing_scene_file_is_an_error_naming_the_path() {
    let dir = TempDir::new("missing");
    let path = dir.path().join("no-such-scene.toml");
    let e = load_err(&path);
    assert_contains(&e, &[&path.display().to_string(), "cannot read"]);
    // The same for a bare URDF, which goes through the URDF importer.
    let urdf_path = dir.path().join("no-such-robot.urdf");
    assert_contains(load_err(&urdf_path), &["no-such-robot.urdf", "cannot read"]);
    // Files a scene refers to: the error points at the reference in the scene.
    let scene = dir.write("scene.toml", "[[robot]]\nurdf = \"gone.urdf\"\n");
    assert_contains(load_err(&scene), &["scene.toml:2:8:", "URDF", "gone.urdf", "not found"]);
    let scene = dir.write(
        "scene.toml",
        "[[object]]\nname = \"a\"\nkind = \"dummy\"\nscript = \"gone.lua\"\n",
    );
    assert_contains(
        load_err(&scene),
        &["scene.toml:4:10:", "cannot read script", "gone.lua"],
    );
    good_scene_still_loads();
}

#[test]
fn a_missing_mesh_is_an_error_naming_the_mesh_and_where_it_is_used() {
    let dir = TempDir::new("mesh");
    // In a scene: at the `mesh = ...` value.
    let scene = dir.write(
        "scene.toml",
        "[[object]]\nname = \"rock\"\nkind = \"shape\"\nshape = \"mesh\"\nmesh = \"meshes/rock.stl\"\n",
    );
    assert_contains(load_err(&scene), &["scene.toml:5:8:", "rock.stl", "cannot read mesh"]);
    // In a URDF: the link and every path tried, with the fix for package:// references.
    let robot = dir.write(
        "r.urdf",
        urdf("<link name=\"tool\"><visual><geometry><mesh filename=\"package://tools/gripper.stl\"/></geometry></visual></link>\n<joint name=\"wrist\" type=\"fixed\"><parent link=\"arm\"/><child link=\"tool\"/></joint>\n"),
    );
    let e = load_err(&robot);
    assert_contains(
        &e,
        &[
            "r.urdf",
            "link 'tool'",
            "gripper.stl",
            "not found",
            "tried:",
            "--package-path",
        ],
    );
    // The same URDF included from a scene reports the URDF, where the problem is.
    let scene = dir.write("scene.toml", INCLUDES_URDF);
    assert_contains(load_err(&scene), &["r.urdf", "link 'tool'", "gripper.stl"]);
    good_scene_still_loads();
}

#[test]
fn a_urdf_joint_cycle_is_refused_naming_its_joints() {
    let dir = TempDir::new("cycle");
    // Every link has a parent, so there is no root at all.
    let robot = dir.write(
        "loop.urdf",
        "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n\
         <joint name=\"ab\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>\n\
         <joint name=\"ba\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint>\n</robot>\n",
    );
    assert_contains(
        load_err(&robot),
        &[
            "loop.urdf:4:1:",
            "the joints 'ab' -> 'ba' form a cycle",
            "must be a tree",
        ],
    );
    // Regression: a cycle beside a proper root used to load without error, and the links
    // on the cycle (here elbow and hand) were silently missing from the robot.
    let robot = dir.write(
        "r.urdf",
        urdf(
            "<link name=\"elbow\"/>\n<link name=\"hand\"/>\n\
             <joint name=\"j1\" type=\"fixed\"><parent link=\"elbow\"/><child link=\"hand\"/></joint>\n\
             <joint name=\"j2\" type=\"fixed\"><parent link=\"hand\"/><child link=\"elbow\"/></joint>\n",
        ),
    );
    let e = load_err(&robot);
    assert_contains(&e, &["r.urdf:10:1:", "'j1' -> 'j2' form a cycle", "link 'elbow'"]);
    // Included from a scene, the error still names the URDF's line, not the scene's.
    let scene = dir.write("scene.toml", INCLUDES_URDF);
    assert_contains(load_err(&scene), &["r.urdf:10:1:", "cycle"]);
    good_scene_still_loads();
}

#[test]
fn a_urdf_link_with_two_parents_is_refused_at_the_second_joint() {
    let dir = TempDir::new("twoparents");
    let robot = dir.write(
        "r.urdf",
        urdf("<joint name=\"again\" type=\"fixed\"><parent link=\"base\"/><child link=\"arm\"/></joint>\n"),
    );
    assert_contains(
        load_err(&robot),
        &[
            "r.urdf:8:1:",
            "link 'arm' is the child of two joints ('shoulder' and 'again')",
            "must be a tree",
        ],
    );
    // A joint naming a link that does not exist is located the same way.
    let robot = dir.write(
        "r.urdf",
        urdf("<joint name=\"stray\" type=\"fixed\"><parent link=\"arm\"/><child link=\"ghost\"/></joint>\n"),
    );
    assert_contains(
        load_err(&robot),
        &[
            "r.urdf:8:1:",
            "joint 'stray' names child link 'ghost', which does not exist",
        ],
    );
    good_scene_still_loads();
}

#[test]
fn duplicate_names_are_refused_at_the_second_one() {
    let dir = TempDir::new("duplicates");
    // Scene objects: the error points at the second `name = "box"` value.
    let scene = dir.write(
        "scene.toml",
        "[[object]]\nname = \"box\"\nkind = \"dummy\"\n\n[[object]]\nname = \"box\"\nkind = \"dummy\"\n",
    );
    assert_contains(load_err(&scene), &["scene.toml:6:8:", "duplicate name 'box'"]);
    // An object and a robot share one namespace, since both can be parents.
    dir.write("r.urdf", urdf(""));
    let scene = dir.write(
        "scene.toml",
        "[[object]]\nname = \"bot\"\nkind = \"dummy\"\n\n[[robot]]\nname = \"bot\"\nurdf = \"r.urdf\"\n",
    );
    assert_contains(load_err(&scene), &["scene.toml:", "duplicate name 'bot'"]);
    // URDF links.
    let robot = dir.write("r.urdf", urdf("<link name=\"arm\"/>\n"));
    assert_contains(
        load_err(&robot),
        &["r.urdf:8:1:", "two links are named 'arm'; link names must be unique"],
    );
    // Regression: duplicate joint names used to load, the second joint shadowing the first
    // in `bot/shoulder` references.
    let robot = dir.write(
        "r.urdf",
        urdf(
            "<link name=\"hand\"/>\n<joint name=\"shoulder\" type=\"fixed\"><parent link=\"arm\"/><child link=\"hand\"/></joint>\n",
        ),
    );
    assert_contains(
        load_err(&robot),
        &[
            "r.urdf:9:1:",
            "two joints are named 'shoulder'; joint names must be unique",
        ],
    );
    good_scene_still_loads();
}

#[test]
fn unknown_keys_are_warned_with_a_hint_and_the_scene_still_loads() {
    let dir = TempDir::new("unknown");
    let scene = dir.write(
        "scene.toml",
        "[simulation]\ndt = 0.01\nsubstep = 4\n\n[[object]]\nname = \"ball\"\nkind = \"shape\"\n\
         shape = \"sphere\"\nradius = 0.1\ncolour = [1, 0, 0]\nsparkle = true\n",
    );
    let model = load(&scene).expect("unknown keys do not stop the load");
    assert_eq!(
        model.warnings,
        [
            "unknown key 'simulation.substep' (did you mean 'substeps'?)",
            "unknown key 'object[0] ('ball').colour' (did you mean 'color'?)",
            "unknown key 'object[0] ('ball').sparkle'",
        ]
    );
    // The known keys took effect.
    assert_eq!(model.settings.dt, 0.01);
    assert!(model.objects.iter().any(|o| o.alias == "ball"));
    good_scene_still_loads();
}

#[test]
fn malformed_toml_is_an_error_with_file_line_and_column() {
    let dir = TempDir::new("toml");
    let cases = [
        // An unterminated array.
        ("[simulation]\ndt = [\n", "scene.toml:2:7:", "unclosed array"),
        // An unterminated string.
        (
            "[[object]]\nname = \"a\nkind = \"dummy\"\n",
            "scene.toml:2:10:",
            "invalid basic string",
        ),
        // A value of the wrong type.
        ("[simulation]\ndt = \"fast\"\n", "scene.toml:2:6:", "expected f64"),
        // A required key missing: the table that lacks it.
        (
            "[[object]]\nkind = \"dummy\"\n",
            "scene.toml:1:1:",
            "missing field `name`",
        ),
        // A key given twice.
        ("[simulation]\ndt = 0.1\ndt = 0.2\n", "scene.toml:3:1:", "duplicate key"),
    ];
    for (text, place, what) in cases {
        let scene = dir.write("scene.toml", text);
        let e = load_err(&scene);
        assert_contains(&e, &[place, what]);
        // The in-memory entry point reports the same place for the same text.
        let from_text = load_scene_text(&DiskFiles, text, &scene, &LoadOptions::default())
            .expect_err("malformed")
            .to_string();
        assert_eq!(from_text, e, "{text:?}");
    }
    let scene = dir.write("scene.toml", b"name = \"caf\xe9\"\n");
    assert_contains(load_err(&scene), &["scene.toml:1:1:", "not UTF-8"]);
    good_scene_still_loads();
}

#[test]
fn malformed_urdf_xml_is_an_error_with_file_line_and_column() {
    let dir = TempDir::new("xml");
    // urdf-rs alone reported "Elements not properly nested" or "No elements found"
    // without any position; these must name the line and column of the fault.
    let cases = [
        // A closing tag that does not match.
        (
            urdf("<link name=\"x\"></joint>\n"),
            "r.urdf:8:16:",
            "expected 'link' tag, not 'joint'",
        ),
        // An element never closed.
        (
            urdf("<link name=\"x\">\n"),
            "r.urdf:9:1:",
            "expected 'link' tag, not 'robot'",
        ),
        // Not a tag at all.
        (urdf("<<<\n"), "r.urdf:8:2:", "malformed URDF XML"),
        // An empty file.
        (String::new(), "r.urdf:1:1:", "malformed URDF XML"),
    ];
    for (text, place, what) in &cases {
        let robot = dir.write("r.urdf", text);
        assert_contains(load_err(&robot), &[place, what]);
        // Included from a scene, the URDF's own position is reported.
        let scene = dir.write("scene.toml", INCLUDES_URDF);
        assert_contains(load_err(&scene), &[place, what]);
    }
    // Well-formed XML that is not a valid URDF keeps urdf-rs's explanation.
    let robot = dir.write("r.urdf", urdf("<link/>\n"));
    assert_contains(load_err(&robot), &["r.urdf:", "malformed URDF", "missing field `name`"]);
    // A robot without links.
    let robot = dir.write("r.urdf", "<robot name=\"empty\"></robot>\n");
    assert_contains(load_err(&robot), &["r.urdf", "no <link>"]);
    good_scene_still_loads();
}

#[test]
fn solver_iterations_are_read_and_bounded() {
    let dir = TempDir::new("solver");
    let scene = dir.write("scene.toml", "[simulation]\nsolver_iterations = 4\n");
    assert_eq!(load(&scene).expect("loads").settings.solver_iterations, 4);
    let scene = dir.write("zero.toml", "[simulation]\nsolver_iterations = 0\n");
    assert_contains(
        load_err(&scene),
        &["zero.toml:2:1:", "solver_iterations = 0: use 1 to 100"],
    );
    good_scene_still_loads();
}
