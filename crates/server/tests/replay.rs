//! `gantry replay`'s pose setting against the run it replays (issue 31): the showroom
//! is stepped and recorded, its scene built again with no scripts, and at every
//! snapshot time (and between two) `apply_at` must put every object at the world pose it
//! had in the run and every joint at its recorded position, and build a frame of them.

use std::collections::BTreeMap;

use gantry_engine::{Engine, EngineConfig};
use gantry_record::{RecordParams, RecordedScene, Recorder, Recording};
use gantry_server::http::replay::{apply_at, frame_handles};
use gantry_sim_core::Sim;
use gantry_sim_core::math::Pose;
use gantry_sim_core::scene::{LoadOptions, load_bundled};
use gantry_sim_core::world::ObjectKind;

fn showroom() -> gantry_sim_core::scene::SceneModel {
    load_bundled("showroom", &LoadOptions::default())
        .expect("bundled")
        .expect("loads")
}

/// Every object's world pose, by path.
fn world_poses(world: &gantry_sim_core::World) -> BTreeMap<String, Pose> {
    gantry_server::http::replay::object_names(world)
        .into_iter()
        .filter_map(|(name, h)| Some((name, world.object(h).ok()?.world)))
        .collect()
}

fn close(a: &Pose, b: &Pose) -> bool {
    (a.translation.vector - b.translation.vector).norm() < 1e-9 && a.rotation.angle_to(&b.rotation) < 1e-9
}

#[test]
fn every_object_is_where_the_run_had_it() {
    let path = std::env::temp_dir().join(format!("gantry-replay-test-{}.mcap", std::process::id()));
    let model = showroom();
    let mut sim = Sim::new(&model);
    let metadata = [("scene_file", "(bundled showroom)"), ("dt", "0.05")]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v.to_owned()))
        .collect();
    let mut rec = Recorder::create(RecordParams {
        path: path.clone(),
        metadata,
        ..RecordParams::default()
    })
    .expect("recording starts");
    // Objects settle under gravity in the first steps, so poses change.
    let mut run: Vec<(u64, BTreeMap<String, Pose>)> = Vec::new();
    for _ in 0..40 {
        sim.step();
        rec.record(&sim);
        run.push((
            gantry_record::msg::nanos_from_secs(sim.world.time()),
            world_poses(&sim.world),
        ));
    }
    let report = rec.finish(Some(&sim), BTreeMap::new());
    assert_eq!(report.error, None);
    let recording = Recording::open(&path).expect("reads");
    let _ = std::fs::remove_file(&path);
    assert!(run[0].1 != run[39].1, "something moved during the run");

    let mut replay_model = recording.scene_model().expect("the scene rebuilds");
    replay_model.scripts.clear();
    let mut replay = Engine::new(replay_model, EngineConfig::default(), None).expect("built");
    let map = frame_handles(&recording, &replay.sim().world);
    let missing: Vec<&String> = recording
        .frames()
        .iter()
        .zip(&map)
        .filter(|(n, h)| *n != "world" && h.is_none())
        .map(|(n, _)| n)
        .collect();
    assert!(missing.is_empty(), "recorded frames not in the scene: {missing:?}");
    // Backwards too: a scrub goes anywhere, and what was set before must not show.
    for (t, want) in run.iter().rev().chain(run.iter().step_by(7)) {
        for at in [*t, t + 1] {
            let frame = apply_at(&recording, &map, at, &mut replay);
            let got = world_poses(&replay.sim().world);
            assert_eq!(got.len(), want.len());
            for (name, pose) in want {
                assert!(close(&got[name], pose), "{name} at {at} ns: {} vs {}", got[name], pose);
            }
            assert_eq!(frame.poses.len(), replay.sim().world.handles().len());
            // The joints are where /joint_states had them (rad or m).
            let js = recording.joints_at(at).expect("joint states");
            let core = replay.sim();
            for (&name, &q) in js.names.iter().zip(&js.position) {
                let h = map[name.0 as usize].expect("a joint of the scene");
                match &core.world.object(h).expect("object").kind {
                    ObjectKind::Joint(j) => assert_eq!(j.position, q, "{}", recording.frame_name(name)),
                    other => panic!("{} is a {}", recording.frame_name(name), other.name()),
                }
            }
        }
    }
}
