//! Requests are answered between the phases of a step, not only between steps: a
//! world call that arrives while a long phase runs is served as soon as that phase
//! ends, and requests that control the simulation wait for the end of the step.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use gantry_lua::ScriptLimits;
use gantry_server::{ClientId, LoopControl, RemoteOp, Request, SimConfig, SimHandle, channel, run_sim_thread};
use gantry_sim_core::Value;
use gantry_sim_core::api::{CallError, Target};
use gantry_sim_core::sim::Control;
use gantry_test_support::{TempDir, load};
use tokio::sync::oneshot;

/// A scene whose one script spends 1 s in actuation and 0.5 s in sensing (so that the
/// step is still running when the test looks; wide margins for a loaded machine), and
/// records, in actuation and in sensing, whether the signal `mid` was set yet.
fn slow_scene() -> (TempDir, gantry_sim_core::scene::SceneModel) {
    let dir = TempDir::new("mid-step");
    dir.write(
        "scene.toml",
        "[simulation]\ndt = 0.05\n\n[[object]]\nname = \"slow\"\nkind = \"dummy\"\nscript = \"slow.lua\"\n",
    );
    dir.write(
        "slow.lua",
        r#"
function sysCall_actuation()
    sim.setInt32Signal('actuation_saw', sim.getInt32Signal('mid') or 0)
    local t = sim.getSystemTime()
    while sim.getSystemTime() - t < 1.0 do end
end
function sysCall_sensing()
    sim.setInt32Signal('sensing_saw', sim.getInt32Signal('mid') or 0)
    local t = sim.getSystemTime()
    while sim.getSystemTime() - t < 0.5 do end
end
"#,
    );
    let model = load(&dir.path().join("scene.toml"));
    (dir, model)
}

fn call(sim: &SimHandle, name: &str, args: Vec<Value>) -> oneshot::Receiver<Result<Vec<Value>, CallError>> {
    let (reply, rx) = oneshot::channel();
    sim.send(Request::Call {
        target: Target::resolve(name).expect("a known function"),
        args,
        reply,
    })
    .expect("queued");
    rx
}

fn signal(sim: &SimHandle, name: &str) -> Value {
    let ret = call(sim, "getInt32Signal", vec![Value::Str(name.to_owned())])
        .blocking_recv()
        .expect("reply")
        .expect("ok");
    ret.into_iter().next().unwrap_or(Value::Nil)
}

#[test]
fn a_world_call_during_a_long_phase_is_answered_before_the_step_ends() {
    let (_dir, model) = slow_scene();
    let (sim, rx) = channel();
    let stop = Arc::new(AtomicBool::new(false));
    let stop_flag = stop.clone();
    let thread = std::thread::spawn(move || {
        let config = SimConfig {
            fast: true,
            limits: ScriptLimits {
                time_budget: Duration::from_secs(10),
                ..ScriptLimits::default()
            },
            autostart: false,
            ..SimConfig::default()
        };
        run_sim_thread(model, config, rx, || stop_flag.load(Ordering::Relaxed))
    });

    // A stepping client holds the simulation; then it asks for one step.
    let client = ClientId(1);
    let (reply, level) = oneshot::channel();
    sim.send(Request::Remote {
        client,
        op: RemoteOp::SetStepping(true),
        reply,
    })
    .expect("queued");
    level.blocking_recv().expect("reply").expect("stepping on");
    let (reply, started) = oneshot::channel();
    sim.send(Request::Control {
        action: LoopControl::Control(Control::Start),
        reply,
    })
    .expect("queued");
    started.blocking_recv().expect("started");
    let (done, mut step_done) = oneshot::channel();
    sim.send(Request::Step { client, done }).expect("queued");

    // Well inside the 1 s actuation phase: a world call, then a control request.
    std::thread::sleep(Duration::from_millis(300));
    let set = call(&sim, "setInt32Signal", vec![Value::Str("mid".into()), Value::Int(1)]);
    let (reply, mut paused) = oneshot::channel();
    sim.send(Request::Control {
        action: LoopControl::Control(Control::Pause),
        reply,
    })
    .expect("queued");

    set.blocking_recv().expect("reply").expect("signal set");
    assert!(
        step_done.try_recv().is_err(),
        "the call was answered only after the step; it should be served between phases"
    );
    assert!(
        paused.try_recv().is_err(),
        "a control request must wait for the end of the step"
    );
    step_done.blocking_recv().expect("step done");
    paused.blocking_recv().expect("paused after the step");

    // Served after actuation, before sensing, of that same step.
    assert_eq!(signal(&sim, "actuation_saw"), Value::Int(0));
    assert_eq!(signal(&sim, "sensing_saw"), Value::Int(1));

    stop.store(true, Ordering::Relaxed);
    drop(sim);
    let summary = thread.join().expect("sim thread").expect("run");
    assert_eq!(summary.steps, 1);
}
