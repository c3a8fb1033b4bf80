//! Bad scripts (issue #9): a runtime error in any hook (beyond `sysCall_init` and
//! `sysCall_actuation`, which `hooks.rs` covers) is reported with the script's file and
//! line, stops only that script, and leaves the others, the world and later stops and
//! restarts working. Also the string-doubling memory bomb and cleanups that fail.
//!
//! Each scene puts `rogue.lua` first, so that its hooks run before `good.lua`'s and a
//! failure cannot hide behind a script that already ran.

use crate::util;
use util::Drive;

use std::time::{Duration, Instant};

use gantry_engine::Engine;
use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_sim_core::sim::SimulationState;
use gantry_test_support::assert_contains;
use util::{Scene, int32_signal, messages_from, script_error, script_state};

/// The well-behaved neighbour: counts its hooks in signals and answers packets.
const GOOD: &str = "acted, sensed = 0, 0
function sysCall_actuation() acted = acted + 1; sim.setInt32Signal('acted', acted) end
function sysCall_sensing() sensed = sensed + 1; sim.setInt32Signal('sensed', sensed) end
function sysCall_packet(packet) return 'good got ' .. packet.code end
function sysCall_cleanup() print('good cleanup') end
";

/// A scene with `rogue.lua` on an object described by `rogue_object` (TOML lines after
/// `name`, e.g. its `kind`) and [`GOOD`] on a dummy.
fn with_rogue(tag: &str, rogue_object: &str, rogue: &str, limits: ScriptLimits) -> Scene {
    let toml = format!(
        "[[object]]\nname = \"rogue\"\n{rogue_object}\nscript = \"rogue.lua\"\n\n\
         [[object]]\nname = \"good\"\nkind = \"dummy\"\nscript = \"good.lua\"\n"
    );
    Scene::new(tag, &toml, &[("rogue.lua", rogue), ("good.lua", GOOD)], limits)
}

const DUMMY: &str = "kind = \"dummy\"";

/// Asserts that `good.lua` ran every hook of the `steps` steps so far, that simulation
/// time followed (50 ms steps) and that `good.lua` is still running.
#[track_caller]
fn good_carried_on(sim: &mut Engine, steps: i64) {
    assert_eq!(int32_signal(sim, "acted"), Some(steps), "good.lua's actuation");
    assert_eq!(int32_signal(sim, "sensed"), Some(steps), "good.lua's sensing");
    assert!((sim.world().time() - 0.05 * steps as f64).abs() < 1e-9);
    assert_eq!(script_state(sim, "good.lua"), ScriptState::Running);
}

/// The error is the script's state and is logged, both with file and line.
#[track_caller]
fn reported(sim: &Engine, place: &str, what: &str) {
    assert_contains(script_error(sim, "rogue.lua"), &[place, what]);
    let logged = messages_from(sim, "rogue.lua");
    assert!(
        logged.iter().any(|m| m.contains(place) && m.contains(what)),
        "logged with file and line: {logged:?}"
    );
}

#[test]
fn a_runtime_error_in_sensing_names_file_and_line_and_the_rest_carries_on() {
    let rogue = "n = 0
function sysCall_actuation() n = n + 1; sim.setInt32Signal('rogue.acted', n) end
function sysCall_sensing()
    if n == 2 then error('boom in sensing') end
end
";
    let mut sc = with_rogue("sensing", DUMMY, rogue, ScriptLimits::default());
    for _ in 0..6 {
        sc.sim.step();
    }
    reported(&sc.sim, "rogue.lua:4: boom in sensing", "traceback");
    // The failing script received no hook after its error; the others all of them.
    assert_eq!(int32_signal(&mut sc.sim, "rogue.acted"), Some(2));
    good_carried_on(&mut sc.sim, 6);
}

#[test]
fn a_runtime_error_in_sys_call_vision_names_file_and_line_and_the_rest_carries_on() {
    let rogue = "function sysCall_vision(inData)
    local image = nil
    return image.width
end
";
    let camera = "kind = \"vision_sensor\"\nresolution = [16, 16]";
    let mut sc = with_rogue("vision", camera, rogue, ScriptLimits::default());
    for _ in 0..4 {
        sc.sim.step();
    }
    reported(
        &sc.sim,
        "rogue.lua:3: attempt to index a nil value (local 'image')",
        "traceback",
    );
    good_carried_on(&mut sc.sim, 4);
    // The sensor itself still works for whoever reads it.
    let cam = sc.find("/rogue");
    let img = sc.remote("getVisionSensorImg", &[Value::Int(cam)]);
    assert!(matches!(&img[0], Value::Bytes(b) if b.len() == 16 * 16 * 3), "{img:?}");
}

#[test]
fn a_runtime_error_in_a_ui_callback_names_file_and_line_and_the_rest_carries_on() {
    let rogue = r#"function sysCall_init()
    ui = simUI.create('<ui><hslider id="1" minimum="0" maximum="10" on-change="changed"/></ui>')
    sim.setInt32Signal('ui', ui)
end
function changed(ui, id, value)
    sim.setInt32Signal('changed', value)
    error('boom in the slider callback at ' .. value)
end
"#;
    let mut sc = with_rogue("uicallback", DUMMY, rogue, ScriptLimits::default());
    sc.sim.step();
    let ui = int32_signal(&mut sc.sim, "ui").expect("the script created its UI");
    // A user moves the slider: the callback runs on the script's next turn and fails.
    sc.remote("simUI.interact", &[Value::Int(ui), Value::Int(1), Value::Int(7)]);
    sc.sim.step();
    reported(&sc.sim, "rogue.lua:7: boom in the slider callback at 7", "traceback");
    // Later events for the errored script are dropped, not delivered or queued up.
    sc.remote("simUI.interact", &[Value::Int(ui), Value::Int(1), Value::Int(3)]);
    sc.sim.step();
    assert_eq!(int32_signal(&mut sc.sim, "changed"), Some(7));
    good_carried_on(&mut sc.sim, 3);
    // The window stays, as a CoppeliaSim UI outlives its script's error.
    let value = sc.remote("simUI.getSliderValue", &[Value::Int(ui), Value::Int(1)]);
    assert_eq!(value, [Value::Int(3)]);
}

#[test]
fn a_runtime_error_in_sys_call_packet_is_the_reply_and_the_next_handler_takes_over() {
    let rogue = "function sysCall_packet(packet)
    return packet.fields.J1 .. packet.fields.NOPE
end
";
    let mut sc = with_rogue("packet", DUMMY, rogue, ScriptLimits::default());
    sc.sim.step();
    let packet = Value::Map(vec![
        (Value::from("code"), Value::from("FK")),
        (
            Value::from("fields"),
            Value::Map(vec![(Value::from("J1"), Value::Float(0.5))]),
        ),
    ]);
    // The transport gets the error, with file and line, to send back to the client.
    let e = sc
        .sim
        .call_script_function("sysCall_packet", std::slice::from_ref(&packet))
        .expect_err("the handler fails");
    assert_contains(
        &e,
        &["rogue.lua:2:", "attempt to concatenate a nil value (field 'NOPE')"],
    );
    reported(&sc.sim, "rogue.lua:2:", "attempt to concatenate");
    // The errored handler is skipped from then on: the next script that handles
    // packets answers.
    let reply = sc.sim.call_script_function("sysCall_packet", &[packet]);
    assert_eq!(reply, Ok(Some(vec![Value::from("good got FK")])));
    sc.sim.step();
    good_carried_on(&mut sc.sim, 2);
}

#[test]
fn an_error_value_that_is_not_a_string_still_points_at_the_line() {
    // `error(table)` and `error()` carry no position of their own (Lua adds one only to
    // string messages); the traceback in the report still names file and line.
    for (tag, raise, first_line) in [
        ("tableerror", "error({code = 42})", "table: "),
        ("nilerror", "error()", "nil"),
    ] {
        let rogue = format!("function sysCall_actuation()\n    {raise}\nend\n");
        let mut sc = with_rogue(tag, DUMMY, &rogue, ScriptLimits::default());
        for _ in 0..3 {
            sc.sim.step();
        }
        let e = script_error(&sc.sim, "rogue.lua");
        assert!(e.starts_with(first_line), "{e:?}");
        assert_contains(&e, &["traceback", "rogue.lua:2: in function"]);
        good_carried_on(&mut sc.sim, 3);
    }
}

#[test]
fn a_cleanup_that_errors_or_loops_does_not_stop_stop_or_restart() {
    let limits = ScriptLimits {
        time_budget: Duration::from_millis(200),
        ..ScriptLimits::default()
    };
    let toml = "[[object]]\nname = \"fails\"\nkind = \"dummy\"\nscript = \"fails.lua\"\n\n\
                [[object]]\nname = \"loops\"\nkind = \"dummy\"\nscript = \"loops.lua\"\n\n\
                [[object]]\nname = \"good\"\nkind = \"dummy\"\nscript = \"good.lua\"\n";
    let fails = "function sysCall_init() sim.setInt32Signal('fails.init', 1) end
function sysCall_cleanup()
    error('boom in cleanup')
end
";
    let loops = "function sysCall_cleanup()
    while true do end
end
";
    let mut sc = Scene::new(
        "cleanup",
        toml,
        &[("fails.lua", fails), ("loops.lua", loops), ("good.lua", GOOD)],
        limits,
    );
    for _ in 0..3 {
        sc.sim.step();
    }
    let t0 = Instant::now();
    sc.sim.stop();
    assert!(t0.elapsed() < Duration::from_secs(3), "stop took {:?}", t0.elapsed());
    // Stop completed: cleanups ran in order despite the failures, the scene is back at
    // its start.
    assert_eq!(sc.sim.state(), SimulationState::Stopped);
    assert_eq!(sc.sim.world().time(), 0.0);
    let failed = messages_from(&sc.sim, "fails.lua");
    assert!(
        failed.iter().any(|m| m.contains("fails.lua:3: boom in cleanup")),
        "{failed:?}"
    );
    let looped = messages_from(&sc.sim, "loops.lua");
    assert!(
        looped
            .iter()
            .any(|m| m.contains("loops.lua:2:") && m.contains("time budget")),
        "{looped:?}"
    );
    assert!(messages_from(&sc.sim, "good.lua").contains(&"good cleanup".to_owned()));
    // Restart: every script is loaded afresh, so the failed ones run again too.
    sc.sim.call("clearInt32Signal", &[]).expect("clear");
    for _ in 0..2 {
        sc.sim.step();
    }
    good_carried_on(&mut sc.sim, 2);
    assert_eq!(int32_signal(&mut sc.sim, "fails.init"), Some(1));
    for file in ["fails.lua", "loops.lua", "good.lua"] {
        assert_eq!(script_state(&sc.sim, file), ScriptState::Running, "{file}");
    }
    // The process-exit path (cleanup without a restore) copes the same way.
    let t0 = Instant::now();
    sc.sim.cleanup();
    assert!(t0.elapsed() < Duration::from_secs(3), "cleanup took {:?}", t0.elapsed());
    assert_eq!(sc.sim.state(), SimulationState::Stopped);
    let cleanups = messages_from(&sc.sim, "good.lua")
        .iter()
        .filter(|m| *m == "good cleanup")
        .count();
    assert_eq!(cleanups, 2);
}

#[test]
fn a_string_doubling_memory_bomb_hits_the_cap_and_the_memory_comes_back() {
    let limits = ScriptLimits {
        memory: 64 << 20,
        ..ScriptLimits::default()
    };
    // Doubling a string reaches any cap in a few dozen steps, and each step needs one
    // allocation twice the size of the last: the worst case for a late check.
    let rogue = "function sysCall_init()
    local s = 'x'
    while true do s = s .. s end
end
";
    let mut sc = with_rogue("stringbomb", DUMMY, rogue, limits);
    sc.sim.step();
    assert_eq!(script_error(&sc.sim, "rogue.lua"), "out of memory: not enough memory");
    // The bomb's garbage is collected: another script can use half the cap at once
    // (string.rep holds a 16 MiB buffer and the 16 MiB result).
    let big = "function sysCall_init() end
function fill() local s = string.rep('y', 16 << 20); return #s end
";
    std::fs::write(sc.dir.path().join("rogue.lua"), big).expect("rewrite the script");
    sc.sim.reload(0);
    assert_eq!(script_state(&sc.sim, "rogue.lua"), ScriptState::Running);
    let filled = util::call(&mut sc.sim, "fill", &[]);
    assert_eq!(filled, [Value::Int(16 << 20)]);
    for _ in 0..2 {
        sc.sim.step();
    }
    good_carried_on(&mut sc.sim, 3);
}
