//! `simRemoteApi`: scripts start legacy remote API servers through the front end that
//! runs them (here a recording stand-in; the real servers are tested with the real
//! client in tests/python/test_legacy_remote_api.py). A server started during the run
//! ends when the simulation stops; without a front end the functions say why they
//! cannot work; `require 'simRemoteApi'` returns the module; bad ports are refused.

use crate::util;
use util::Drive;

use std::sync::{Arc, Mutex};

use gantry_lua::{ListenerError, ListenerStatus, Listeners, ScriptLimits, ScriptState};
use gantry_test_support::assert_contains;
use util::{Scene, int32_signal, script_error, script_state};

#[derive(Debug, Default)]
struct Recorder {
    running: Mutex<Vec<u16>>,
    calls: Mutex<Vec<String>>,
}

impl Listeners for Recorder {
    fn start_legacy(&self, port: u16) -> Result<(), ListenerError> {
        self.calls.lock().unwrap().push(format!("start {port}"));
        let mut r = self.running.lock().unwrap();
        if r.contains(&port) {
            return Err(ListenerError::AlreadyRunning(port));
        }
        r.push(port);
        Ok(())
    }
    fn stop_legacy(&self, port: u16) -> Result<(), ListenerError> {
        self.calls.lock().unwrap().push(format!("stop {port}"));
        let mut r = self.running.lock().unwrap();
        let before = r.len();
        r.retain(|&p| p != port);
        if r.len() == before {
            return Err(ListenerError::NotRunning(port));
        }
        Ok(())
    }
    fn legacy_status(&self, port: u16) -> Option<ListenerStatus> {
        self.running.lock().unwrap().contains(&port).then(|| ListenerStatus {
            connected: false,
            client_version: 0,
            client_ip: String::new(),
            server_version: 11,
        })
    }
}

const SCENE: &str = r#"
[simulation]
dt = 0.05

[[object]]
name = "server"
kind = "dummy"
script = "server.lua"
"#;

const SERVER: &str = r#"
local api = require 'simRemoteApi'
function sysCall_init()
    sim.setInt32Signal('first', api.start(19999))
    sim.setInt32Signal('again', simRemoteApi.start(19999))
    sim.setInt32Signal('status', (simRemoteApi.status(19999)))
    sim.setInt32Signal('none', (simRemoteApi.status(20000)))
    local ok, err = pcall(simRemoteApi.start, 70000)
    sim.setStringSignal('badPort', err)
end
"#;

#[test]
fn servers_started_in_a_run_end_with_it() {
    let mut sc = Scene::new("listeners", SCENE, &[("server.lua", SERVER)], ScriptLimits::default());
    let recorder = Arc::new(Recorder::default());
    sc.sim.set_listeners(recorder.clone());
    sc.sim.start();
    assert_eq!(
        script_state(&sc.sim, "server.lua"),
        ScriptState::Running,
        "{}",
        script_error(&sc.sim, "server.lua")
    );
    assert_eq!(int32_signal(&mut sc.sim, "first"), Some(1));
    assert_eq!(
        int32_signal(&mut sc.sim, "again"),
        Some(0),
        "a second server on one port"
    );
    assert_eq!(int32_signal(&mut sc.sim, "status"), Some(0), "waiting for a client");
    assert_eq!(int32_signal(&mut sc.sim, "none"), Some(-1), "no server there");
    let bad = match sc
        .remote("getStringSignal", &[gantry_sim_core::Value::Str("badPort".into())])
        .first()
    {
        Some(gantry_sim_core::Value::Bytes(b)) => String::from_utf8_lossy(b).into_owned(),
        Some(gantry_sim_core::Value::Str(s)) => s.clone(),
        other => panic!("no error text: {other:?}"),
    };
    assert_contains(bad, &["70000", "between 1 and 65535", "simRemoteApi.start"]);
    assert_eq!(*recorder.running.lock().unwrap(), vec![19999]);
    sc.sim.stop();
    assert!(
        recorder.running.lock().unwrap().is_empty(),
        "the run's server outlived it"
    );
    assert_eq!(
        *recorder.calls.lock().unwrap(),
        vec!["start 19999", "start 19999", "stop 19999"]
    );
}

#[test]
fn without_a_front_end_the_functions_say_why() {
    let mut sc = Scene::new(
        "listeners-none",
        SCENE,
        &[("server.lua", SERVER)],
        ScriptLimits::default(),
    );
    sc.sim.start();
    assert!(matches!(script_state(&sc.sim, "server.lua"), ScriptState::Errored(_)));
    assert_contains(
        script_error(&sc.sim, "server.lua"),
        &["simRemoteApi.start", "gantry run"],
    );
}

#[test]
fn the_lua_module_has_exactly_the_registry_functions() {
    let names = r#"
function names()
    local t = {}
    for k, v in pairs(simRemoteApi) do if type(v) == 'function' then t[#t + 1] = k end end
    table.sort(t)
    return table.concat(t, ',')
end
"#;
    let mut sc = Scene::new(
        "listeners-names",
        SCENE,
        &[("server.lua", names)],
        ScriptLimits::default(),
    );
    sc.sim.start();
    let seen = sc.call("names", &[]);
    let module = gantry_sim_core::api::HOST_MODULES
        .iter()
        .find(|m| m.name == "simRemoteApi")
        .expect("simRemoteApi in the registry");
    let listed: Vec<&str> = module.functions.iter().map(|f| f.name).collect();
    assert_eq!(seen, [gantry_sim_core::Value::Str(listed.join(","))]);
    assert_eq!(listed, gantry_lua::listeners::FUNCTIONS);
}
