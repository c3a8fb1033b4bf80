//! `gantry verify` on runs driven through the engine as the front ends drive it: calls
//! between steps and inside a step, text packets, pause, single steps, a stop and a
//! restart. The re-run is identical; changing one recorded input makes it part at the
//! step after that input.

use gantry_engine::{Engine, EngineConfig, Input, LoopControl, MidStep};
use gantry_record::{RecordParams, RecordTap, RecordedRun, Recorder, RunDescription, Verdict, VerifyError};
use gantry_sim_core::Value;
use gantry_sim_core::api::Target;
use gantry_sim_core::scene::{EmbeddedFiles, LoadOptions, LoggedFiles, bundled_files, load_scene};
use gantry_sim_core::sim::Control;
use gantry_test_support::TempDir;

fn call(engine: &mut Engine, name: &str, args: Vec<Value>) -> Vec<Value> {
    let target = Target::resolve_or_error(name).expect("known function");
    engine
        .serve(Input::Call {
            target: &target,
            args: &args,
        })
        .into_values()
        .expect("call succeeds")
}

/// Records bubble_rob driven by a remote client's kind of inputs into `path`.
fn record_driven_run(path: &std::path::Path) {
    let bundled = bundled_files();
    let scene = EmbeddedFiles::path("assets/scenes/bubble_rob.toml");
    let logged = LoggedFiles::new(&bundled);
    let model = load_scene(&logged, &scene, &LoadOptions::default()).expect("bundled scene");
    let run = RunDescription {
        scene_name: model.name.clone(),
        scene_path: scene.clone(),
        files: logged.into_read(),
        scripts: true,
        dt: model.settings.dt,
        substeps: model.settings.substeps,
        command_line: "test".to_owned(),
        ..RunDescription::default()
    };
    let recorder = Recorder::create(RecordParams::for_run(path.to_path_buf(), None, run)).expect("file");
    let config = EngineConfig {
        realtime: false,
        ..EngineConfig::default()
    };
    let mut engine = Engine::new(model, config, None).expect("engine");
    let tap = RecordTap::new(recorder, &engine.sim());
    engine.set_recorder(Box::new(tap));
    engine.serve(Input::Control(LoopControl::Control(Control::Start)));
    let left = call(&mut engine, "sim.getObject", vec![Value::from("/bubbleRob/leftMotor")])[0].clone();
    let rover = call(&mut engine, "sim.getObject", vec![Value::from("/bubbleRob")])[0].clone();
    for k in 0..120 {
        match k {
            10 => {
                // The rover's script sets its wheel speeds every step; a push is an
                // input it does not undo.
                let world = Value::Int(-1);
                let mut p = call(&mut engine, "sim.getObjectPosition", vec![rover.clone(), world.clone()]);
                let Some(Value::Array(xyz)) = p.pop() else {
                    panic!("a position")
                };
                let Value::Float(x) = xyz[0] else { panic!("x") };
                let moved = Value::Array(vec![Value::Float(x + 0.05), xyz[1].clone(), xyz[2].clone()]);
                call(&mut engine, "sim.setObjectPosition", vec![rover.clone(), world, moved]);
            }
            30 => {
                engine.serve(Input::Control(LoopControl::Control(Control::Pause)));
                engine.serve(Input::Control(LoopControl::Step));
                engine.serve(Input::Control(LoopControl::Control(Control::Start)));
            }
            60 => {
                let _ = engine.serve(Input::Packet(&Value::from("<FK#J1=0.1>")));
            }
            80 => {
                engine.serve(Input::Control(LoopControl::Control(Control::Stop)));
                engine.serve(Input::Control(LoopControl::Control(Control::Start)));
            }
            _ => {}
        }
        if k == 50 {
            let args = vec![left.clone(), Value::Float(-0.5)];
            engine.step_with(&mut |m: &mut MidStep<'_>| {
                if m.index() == 1 {
                    let target = Target::resolve_or_error("sim.setJointTargetVelocity").expect("known");
                    m.call(&target, &args).expect("mid-step call");
                }
            });
        } else {
            engine.step();
        }
    }
    engine.finish();
}

#[test]
fn a_driven_run_re_runs_identically_and_a_changed_input_parts_at_its_step() {
    let dir = TempDir::new("verify");
    let path = dir.path().join("driven.mcap");
    record_driven_run(&path);
    let run = RecordedRun::open(&path).expect("reads");
    assert_eq!(run.steps, 121, "120 steps and the single step while paused");
    let kinds: Vec<(u64, u32, &str, &str)> = run
        .inputs
        .iter()
        .map(|i| (i.step, i.boundary, i.kind.as_str(), i.name.as_str()))
        .collect();
    assert!(kinds.contains(&(0, 0, "control", "start")), "{kinds:?}");
    assert!(kinds.contains(&(30, 0, "control", "step")), "{kinds:?}");
    assert!(kinds.contains(&(61, 0, "packet", "")), "{kinds:?}");
    assert!(kinds.contains(&(81, 0, "control", "stop")), "{kinds:?}");
    assert!(
        kinds.contains(&(51, 1, "call", "sim.setJointTargetVelocity")),
        "the mid-step call, at the first boundary of step 52: {kinds:?}"
    );
    match run.verify().expect("re-runs") {
        Verdict::Identical { steps, messages } => {
            assert_eq!(steps, 121);
            assert!(messages > 4 * 120, "{messages}");
        }
        other => panic!("expected identical, got {other}"),
    }

    // The same run with the push made 1 mm shorter: it parts at the step after the
    // push (the first state recorded after it), not before.
    let mut changed = run.clone();
    let i = changed
        .inputs
        .iter()
        .position(|i| i.name == "sim.setObjectPosition")
        .expect("the push");
    assert_eq!(changed.inputs[i].step, 10);
    let Value::Array(xyz) = &mut changed.inputs[i].args[2] else {
        panic!("a position")
    };
    let Value::Float(x) = &mut xyz[0] else { panic!("x") };
    *x -= 0.001;
    match changed.verify().expect("re-runs") {
        Verdict::Differs { step, topic, .. } => {
            assert_eq!(step, 11, "parted on {topic}");
        }
        other => panic!("expected a difference, got {other}"),
    }
}

#[test]
fn files_that_are_not_complete_gantry_recordings_are_refused_clearly() {
    let dir = TempDir::new("verify");
    let path = dir.path().join("cut.mcap");
    record_driven_run(&path);
    let bytes = std::fs::read(&path).expect("recorded");

    let text = |r: Result<RecordedRun, VerifyError>| r.expect_err("refused").to_string();
    let e = text(RecordedRun::from_bytes(b"{\"not\": \"mcap\"}"));
    assert!(e.contains("not a readable MCAP file"), "{e}");
    let e = text(RecordedRun::from_bytes(&bytes[..bytes.len() / 2]));
    assert!(e.contains("needs a complete recording"), "{e}");

    // A later format version: refused, naming both versions.
    let newer = rewrite_format_version(&bytes, b'9');
    let e = text(RecordedRun::from_bytes(&newer));
    assert!(
        e.contains("format version 9") && e.contains("use a newer gantry"),
        "{e}"
    );
}

/// `bytes` with the one-digit `format_version` of the `gantry` metadata record made
/// `digit` (in place: lengths and indexes stay valid; metadata has no checksum).
fn rewrite_format_version(bytes: &[u8], digit: u8) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let mut needle = b"format_version".to_vec();
    needle.extend_from_slice(&1u32.to_le_bytes());
    let at = out
        .windows(needle.len())
        .position(|w| w == needle.as_slice())
        .expect("the key, then a one-byte value");
    out[at + needle.len()] = digit;
    out
}
