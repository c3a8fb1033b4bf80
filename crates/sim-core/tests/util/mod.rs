//! Helpers shared by sim-core's integration tests: simulations of the repository's
//! scenes or of inline scene text, `sim.*` calls as a remote client makes them, and the
//! `fk_arm` scene's arm. The value accessors and assertions other crates' tests use too
//! are `gantry_test_support`'s.

use std::path::{Path, PathBuf};

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::scene::{DiskFiles, LoadOptions, load_scene_text};
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{load, repo};

/// A file of the repository's `assets/`, e.g. `scenes/bubble_rob.toml`.
pub fn asset(rel: &str) -> PathBuf {
    repo("assets").join(rel)
}

/// A simulation of the repository's scene `assets/<rel>`.
pub fn asset_scene(rel: &str) -> Sim {
    Sim::new(&load(&asset(rel)))
}

/// A simulation of the scene `text`, read as if from `path` (relative to this crate's
/// folder), from which its relative file references resolve.
pub fn text_scene(path: &str, text: &str) -> Sim {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let model = load_scene_text(&DiskFiles, text, &path, &LoadOptions::default()).expect("scene loads");
    Sim::new(&model)
}

/// The object at `path` (CoppeliaSim's path syntax, its first match).
pub fn find(w: &Sim, path: &str) -> Handle {
    w.world.find(path, None, 0).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Steps the simulation `n` times.
pub fn step(w: &mut Sim, n: usize) {
    for _ in 0..n {
        w.step();
    }
}

/// `sim.<name>(args)` as a remote client calls it (no script object), an error as its
/// message.
pub fn call(w: &mut Sim, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    api::call(w, &CallContext::default(), name, args).map_err(|e| e.to_string())
}

/// The image bytes and `{width, height}` of a `sim.getVisionSensorImg`-shaped reply
/// (also depth and mask replies).
pub fn image_reply(reply: &[Value]) -> (Vec<u8>, [usize; 2]) {
    let (Some(Value::Bytes(bytes)), Some(Value::Array(res))) = (reply.first(), reply.get(1)) else {
        panic!("expected bytes and a resolution, got {reply:?}");
    };
    let dim = |k: usize| res[k].as_i64().expect("integer") as usize;
    (bytes.clone(), [dim(0), dim(1)])
}

/// [`call`] that must succeed.
pub fn ok(w: &mut Sim, name: &str, args: &[Value]) -> Vec<Value> {
    call(w, name, args).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// [`call`] that must fail: its message.
pub fn err(w: &mut Sim, name: &str, args: &[Value]) -> String {
    match call(w, name, args) {
        Ok(r) => panic!("{name}({args:?}) should fail, returned {r:?}"),
        Err(e) => e,
    }
}

/// The `fk_arm` scene's six-joint arm, as the IK tests drive it.
pub struct Arm {
    /// The simulation of the scene.
    pub sim: Sim,
    /// The arm's base (`/arm6`).
    pub base: Handle,
    /// Joints 1 to 6.
    pub joints: [Handle; 6],
    /// The tool tip dummy.
    pub tip: Handle,
    /// The IK target dummy.
    pub target: Handle,
}

/// The `fk_arm` scene, loaded fresh.
pub fn arm() -> Arm {
    let sim = asset_scene("scenes/fk_arm.toml");
    let joints = [1, 2, 3, 4, 5, 6].map(|i| find(&sim, &format!("/arm6/joint{i}")));
    let (base, tip, target) = (find(&sim, "/arm6"), find(&sim, "/arm6/tip/tip"), find(&sim, "/target"));
    Arm {
        sim,
        base,
        joints,
        tip,
        target,
    }
}

/// Integers as a list of values.
pub fn int_values(v: &[i64]) -> Vec<Value> {
    v.iter().map(|&i| Value::Int(i)).collect()
}
