//! A free-running (`--fast`) simulation shares its thread with a client that calls
//! without pause (`serve_share` in the simulation thread): the client's calls are
//! answered between steps, and the simulation still advances, however fast the client
//! calls. The latency this buys is measured by `tools/bench/zmq_floor.py`.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use gantry_server::{Request, SimConfig, channel, run_sim_thread};
use gantry_sim_core::Value;
use gantry_sim_core::api::Target;
use gantry_test_support::{TempDir, load};
use tokio::sync::oneshot;

fn simulation_time(sim: &gantry_server::SimHandle) -> f64 {
    let (reply, rx) = oneshot::channel();
    sim.send(Request::Call {
        target: Target::resolve("getSimulationTime").expect("a known function"),
        args: vec![],
        reply,
    })
    .expect("queued");
    match rx.blocking_recv().expect("reply").expect("ok").first() {
        Some(Value::Float(t)) => *t,
        other => panic!("getSimulationTime returned {other:?}"),
    }
}

#[test]
fn a_client_calling_without_pause_does_not_stall_a_free_running_simulation() {
    let dir = TempDir::new("call-share");
    dir.write(
        "scene.toml",
        "[simulation]\ndt = 0.01\n\n[[object]]\nname = \"box\"\nkind = \"shape\"\nshape = \"sphere\"\nradius = 0.1\nposition = [0, 0, 1]\ndynamic = true\nmass = 1.0\n",
    );
    let model = load(&dir.path().join("scene.toml"));
    let (sim, rx) = channel();
    let stop = Arc::new(AtomicBool::new(false));
    let stop_flag = stop.clone();
    let thread = std::thread::spawn(move || {
        let config = SimConfig {
            fast: true,
            autostart: true,
            ..SimConfig::default()
        };
        run_sim_thread(model, config, rx, || stop_flag.load(Ordering::Relaxed))
    });

    let first = simulation_time(&sim);
    let mut last = first;
    let mut advanced = 0;
    for _ in 0..5_000 {
        let t = simulation_time(&sim);
        assert!(t >= last, "simulation time went back from {last} to {t}");
        if t > last {
            advanced += 1;
        }
        last = t;
    }
    // Every step the client saw advance between two of its calls proves a step ran
    // while it was calling without pause; a starved simulation would show none.
    assert!(
        advanced >= 10,
        "the simulation advanced between only {advanced} of 5000 back-to-back calls ({first} s to {last} s)"
    );

    stop.store(true, Ordering::Relaxed);
    drop(sim);
    let summary = thread.join().expect("sim thread").expect("run");
    assert!(summary.steps >= 10);
}
