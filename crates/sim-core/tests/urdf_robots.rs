//! The world remembers which robots came from URDF files (issue 29: ROS 2's
//! `/robot_description` and link-named TF frames need it): the file's text as read, and
//! which objects its links and joints became, through a bare URDF (placed after a
//! floor), a scene's `[[robot]]`s and a model imported into a running world.

use crate::util;

use std::sync::Arc;

use gantry_sim_core::World;
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene, load_scene_text};
use util::asset;

/// Checks that each of `world`'s URDF robots names objects aliased by their URDF names,
/// below its model base.
fn parts_are_where_the_urdf_put_them(world: &World) {
    for r in world.urdf_robots() {
        assert!(world.object(r.base).expect("the base").model_base);
        for (h, name) in r.links.iter().chain(&r.joints) {
            let o = world.object(*h).expect("the part");
            assert_eq!(&o.alias, name);
            let mut at = o.parent;
            while at.is_some_and(|p| p != r.base) {
                at = world.object(at.expect("a parent")).expect("the parent").parent;
            }
            assert_eq!(at, Some(r.base), "{name} lies below the robot's base");
        }
    }
}

#[test]
fn a_bare_urdf_keeps_its_text_and_parts_after_the_floor() {
    let path = asset("robots/arm6/arm6.urdf");
    let model = load_scene(&DiskFiles, &path, &LoadOptions::default()).expect("the URDF loads");
    let file = std::fs::read_to_string(&path).expect("readable");
    assert_eq!(model.urdf_robots.len(), 1);
    let r = &model.urdf_robots[0];
    assert_eq!(r.base, 1, "the floor came in front");
    assert_eq!(r.text.as_deref(), Some(file.as_str()), "the text as read");
    assert_eq!(r.path, path);
    assert_eq!(r.links.len(), 8);
    assert_eq!(r.joints.len(), 7);
    let world = World::new(&model);
    parts_are_where_the_urdf_put_them(&world);
    assert_eq!(world.urdf_robots()[0].base, 1);
}

#[test]
fn scene_robots_and_an_imported_model_are_all_kept() {
    let urdf = asset("robots/arm6/arm6.urdf");
    let text = format!(
        "[[object]]\nname = \"box\"\nkind = \"dummy\"\n\
         [[robot]]\nname = \"left\"\nurdf = {urdf:?}\n\
         [[robot]]\nname = \"right\"\nurdf = {urdf:?}\nparent = \"box\"\n"
    );
    let model = load_scene_text(&DiskFiles, &text, &asset("scenes/robots.toml"), &LoadOptions::default())
        .expect("the scene loads");
    assert_eq!(model.urdf_robots.len(), 2);
    let mut world = World::new(&model);
    let bases: Vec<&str> = world
        .urdf_robots()
        .iter()
        .map(|r| world.object(r.base).expect("a base").alias.as_str())
        .collect();
    assert_eq!(bases, ["left", "right"]);
    parts_are_where_the_urdf_put_them(&world);

    let bare = load_scene(&DiskFiles, &urdf, &LoadOptions::default()).expect("the URDF loads");
    let before = world.len() as i64;
    let (handles, _) = world.import_model(&bare);
    let robots = world.urdf_robots();
    assert_eq!(robots.len(), 3);
    assert_eq!(robots[2].base, handles[1], "mapped to the new handles");
    assert!(robots[2].links.iter().all(|(h, _)| *h >= before));
    assert!(Arc::ptr_eq(
        robots[2].text.as_ref().expect("text"),
        bare.urdf_robots[0].text.as_ref().expect("text")
    ));
    parts_are_where_the_urdf_put_them(&world);
}
