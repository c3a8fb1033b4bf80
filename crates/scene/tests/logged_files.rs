//! A scene read through `LoggedFiles` loads again from `MapFiles` of what was read:
//! the contract a recording's scene attachment relies on (`gantry verify`, `gantry replay`).

use std::path::Path;

use gantry_scene::scene::{EmbeddedFiles, Files, LoadOptions, LoggedFiles, MapFiles, bundled_files, load_scene};

#[test]
fn every_file_a_scene_needs_is_logged_and_loads_again_from_memory() {
    let bundled = bundled_files();
    for scene in [
        "assets/scenes/showroom.toml",
        "assets/scenes/bubble_rob.toml",
        "assets/scenes/fk_arm.toml",
    ] {
        let path = EmbeddedFiles::path(scene);
        let logged = LoggedFiles::new(&bundled);
        let first = load_scene(&logged, &path, &LoadOptions::default()).expect("bundled scene");
        let read = logged.into_read();
        assert_eq!(read[0].0, path, "the scene file is read first");
        let names: Vec<_> = read.iter().map(|(p, _)| p.clone()).collect();
        let mut unique = names.clone();
        unique.dedup();
        assert_eq!(names.len(), unique.len(), "each file is kept once: {names:?}");

        let again = load_scene(&MapFiles::new(read), &path, &LoadOptions::default()).expect("from memory");
        let aliases =
            |m: &gantry_scene::scene::SceneModel| m.objects.iter().map(|o| o.alias.clone()).collect::<Vec<_>>();
        assert_eq!(aliases(&first), aliases(&again), "{scene}");
        let sources =
            |m: &gantry_scene::scene::SceneModel| m.scripts.iter().map(|s| s.source.clone()).collect::<Vec<_>>();
        assert_eq!(sources(&first), sources(&again), "{scene}");
    }
}

#[test]
fn a_file_missing_from_memory_is_a_clear_not_found() {
    let files = MapFiles::new([(Path::new("/a/b/../scene.toml").to_path_buf(), b"x".to_vec())]);
    assert!(files.is_file(Path::new("/a/scene.toml")), "paths are normalised");
    let e = files.read(Path::new("/a/robot.urdf")).unwrap_err();
    assert_eq!(e.kind(), std::io::ErrorKind::NotFound);
    assert!(
        e.to_string().contains("/a/robot.urdf is not among the recorded files"),
        "{e}"
    );
}
