//! `sim.broadcastMsg` and `sysCall_msg`, in the style of CoppeliaSim's editor add-ons
//! ("Find midpoint" and the point sampler it talks to): a tool asks a sampler for points
//! by message, the sampler answers with clicks, the tool builds a dummy between the two
//! points it got. Every other script receives a message at once, the sender never does,
//! each receiver gets its own copy and the sender's handle, and a receiver's error is its
//! own; a threaded script may broadcast, and a receiver cannot block.
//! `simUI.getKeyboardModifiers` reports no key held in a headless run.

use crate::util;
use util::Drive;

use gantry_lua::{ScriptLimits, ScriptState};
use gantry_sim_core::Value;
use gantry_test_support::{assert_close, assert_contains};
use util::{LUA_ERR, Scene, int32_signal, script_error, script_state, world_position};

const SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "tool"
kind = "dummy"
script = "midpoint.lua"

[[object]]
name = "sampler"
kind = "dummy"
parent = "tool"
script = "sampler.lua"

[[object]]
name = "broken"
kind = "dummy"
parent = "tool"
script = "broken.lua"

[[object]]
name = "p1"
kind = "dummy"
position = [1, 0, 0]

[[object]]
name = "p2"
kind = "dummy"
position = [0, 2, 0.5]
"#;

/// Plays the point sampler: remembers who enabled it, and at the first two steps sends
/// each of them a click on `/p1`, then `/p2`.
const SAMPLER: &str = r#"
function sysCall_init()
    clients = {}
    received = {}
    steps = 0
end

function sysCall_msg(msg, origin)
    received[#received + 1] = msg.id
    if msg.id == 'pointSampler.enable' then
        clients[msg.data.key] = origin
    elseif msg.id == 'pointSampler.disable' then
        clients[msg.data.key] = nil
    end
end

function sysCall_actuation()
    steps = steps + 1
    if steps > 2 then return end
    for key in pairs(clients) do
        sim.broadcastMsg({id = 'pointSampler.click', data = {key = key, dummy = sim.getObject('/p' .. steps)}})
    end
end

function receivedIds() return table.concat(received, ',') end

function badCalls()
    return err(sim.broadcastMsg, 'text') .. '|' .. err(sim.broadcastMsg, {id = 'x', f = print}) .. '|'
        .. err(sim.broadcastMsg, {id = 'x'}, 'options')
end
"#;

/// The tool, in the style of "Find midpoint": asks the sampler for points, and once it has
/// two, creates a dummy halfway (two evenly spaced ones with Shift held).
const MIDPOINT: &str = r#"
sim = require 'sim'

function sysCall_init()
    simUI = require 'simUI'
    sim.broadcastMsg {id = 'pointSampler.enable', data = {key = 'findMidpoint', dummy = true}}
    local m = simUI.getKeyboardModifiers()
    sim.setInt32Signal('modifiers', (m.control and 1 or 0) + (m.shift and 2 or 0) + (m.alt and 4 or 0))
end

function sysCall_msg(event, origin)
    if not event.data or event.data.key ~= 'findMidpoint' then return end
    if event.id ~= 'pointSampler.click' then return end
    local p = sim.getObjectPosition(event.data.dummy, -1)
    -- This copy is the tool's own: the next receiver still sees the original.
    event.data.key = 'changed'
    if not firstPoint then
        firstPoint = p
        return
    end
    local n = simUI.getKeyboardModifiers().shift and 2 or 1
    for i = 1, n do
        local d = sim.createDummy(0.01)
        sim.setObjectAlias(d, 'Midpoint')
        local f = i / (n + 1)
        sim.setObjectPosition(d, -1, {firstPoint[1] + (p[1] - firstPoint[1]) * f,
            firstPoint[2] + (p[2] - firstPoint[2]) * f, firstPoint[3] + (p[3] - firstPoint[3]) * f})
    end
    sim.setInt32Signal('origin', origin)
    sim.broadcastMsg {id = 'pointSampler.disable', data = {key = 'findMidpoint'}}
end
"#;

/// A receiver that fails on clicks, after noting what it was sent.
const BROKEN: &str = r#"
function sysCall_msg(msg)
    if msg.id == 'pointSampler.click' then
        sim.setStringSignal('seen', msg.data.key)
        error('broken receiver')
    end
end
"#;

#[test]
fn broadcast_messages_reach_the_other_scripts_at_once() {
    let sampler = format!("{SAMPLER}{LUA_ERR}");
    let mut sc = Scene::new(
        "messages",
        SCENE,
        &[
            ("midpoint.lua", MIDPOINT),
            ("sampler.lua", &sampler),
            ("broken.lua", BROKEN),
        ],
        ScriptLimits::default(),
    );
    sc.sim.start();
    assert_eq!(int32_signal(&mut sc.sim, "modifiers"), Some(0), "no key held");
    for _ in 0..3 {
        sc.sim.step();
    }
    // The tool got both clicks and built the dummy halfway.
    let mid = sc.find("/Midpoint");
    assert_close(&world_position(&sc.sim, mid), &[0.5, 1.0, 0.25], 1e-12);
    // Each click came from the sampler, and the sampler never heard its own clicks.
    let sampler = sc.find("/tool/sampler");
    assert_eq!(int32_signal(&mut sc.sim, "origin"), Some(sampler));
    let ids = sc.call("receivedIds", &[]);
    assert_eq!(ids, vec![Value::Str("pointSampler.enable,pointSampler.disable".into())]);
    // The broken receiver saw its own copy, unchanged by the tool, and only it failed.
    let seen = sc.remote("getStringSignal", &["seen".into()]);
    assert_eq!(seen, vec![Value::Bytes(b"findMidpoint".to_vec())]);
    assert_contains(script_error(&sc.sim, "broken.lua"), &["broken receiver", "sysCall_msg"]);
    assert_eq!(script_state(&sc.sim, "sampler.lua"), ScriptState::Running);
    assert_eq!(script_state(&sc.sim, "midpoint.lua"), ScriptState::Running);
    // Bad calls name the argument.
    let bad = sc.call("badCalls", &[]);
    let Value::Str(bad) = &bad[0] else { panic!("{bad:?}") };
    assert_contains(
        bad,
        &[
            "argument 1: expected the message",
            "got string",
            "cannot pass a function",
            "argument 2: expected options",
            "sim.broadcastMsg",
        ],
    );
}

#[test]
fn a_threaded_script_broadcasts_and_a_receiver_cannot_block() {
    let toml = r#"
[simulation]
dt = 0.05

[[object]]
name = "talker"
kind = "dummy"
script = "talker.lua"

[[object]]
name = "listener"
kind = "dummy"
script = "listener.lua"

[[object]]
name = "blocker"
kind = "dummy"
script = "blocker.lua"
"#;
    let talker = "function sysCall_thread()
        sim.setStepping(true)
        for i = 1, 3 do
            sim.broadcastMsg({id = 'tick', data = {n = i}})
            sim.step()
        end
    end";
    let listener = "function sysCall_init() sim.setInt32Signal('ticks', 0) end
    function sysCall_msg(msg)
        if msg.id == 'tick' then sim.setInt32Signal('ticks', sim.getInt32Signal('ticks') + msg.data.n) end
    end";
    let blocker = "function sysCall_msg(msg) sim.wait(0.1) end";
    let mut sc = Scene::new(
        "messages-thread",
        toml,
        &[
            ("talker.lua", talker),
            ("listener.lua", listener),
            ("blocker.lua", blocker),
        ],
        ScriptLimits::default(),
    );
    for _ in 0..5 {
        sc.sim.step();
    }
    assert_eq!(int32_signal(&mut sc.sim, "ticks"), Some(1 + 2 + 3));
    assert_eq!(script_state(&sc.sim, "talker.lua"), ScriptState::Running);
    assert_eq!(script_state(&sc.sim, "listener.lua"), ScriptState::Running);
    assert_contains(script_error(&sc.sim, "blocker.lua"), &["in sysCall_msg", "sim.wait"]);
}
