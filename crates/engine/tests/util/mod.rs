//! Helpers shared by the tests of scenes with scripts (the Lua host driven by the
//! engine): temporary scene folders with inline scripts, the BubbleRob scene with a
//! replacement script, the engine driven as a front end drives it ([`Drive`]), and
//! what scripts logged and signalled. Helpers other crates' tests need too (temp dirs,
//! repository paths, value accessors, assertions) are `gantry_test_support`'s.

pub mod loopback;

use std::cell::Ref;

use gantry_engine::{Engine, EngineConfig, Input, LoopControl};
use gantry_lua::{DebugLink, ScriptError, ScriptLimits, ScriptState};
use gantry_sim_core::api::{CallError, Target};
use gantry_sim_core::scene::SceneModel;
use gantry_sim_core::sim::Control;
use gantry_sim_core::{Handle, Sim, Value};
use gantry_test_support::{TempDir, load, repo};

/// The engine of `model` with `limits`, stopped, stepped only when a test says so.
pub fn engine(model: SceneModel, limits: ScriptLimits) -> Result<Engine, ScriptError> {
    Engine::new(
        model,
        EngineConfig {
            limits,
            ..EngineConfig::default()
        },
        None,
    )
}

/// [`engine`] with the script debugger on `link`.
pub fn engine_debugged(model: SceneModel, limits: ScriptLimits, link: DebugLink) -> Result<Engine, ScriptError> {
    Engine::new(
        model,
        EngineConfig {
            limits,
            ..EngineConfig::default()
        },
        Some(link),
    )
}

/// What the tests do to an engine, each as a front end does it: through
/// [`Engine::serve`].
pub trait Drive {
    /// Starts (or resumes) the simulation.
    fn start(&mut self);
    /// Pauses it.
    fn pause(&mut self);
    /// Stops it: cleanup hooks, the scene rebuilt.
    fn stop(&mut self);
    /// Calls `sim.<name>` (or a qualified name) as a remote client.
    ///
    /// # Errors
    /// The call's error.
    fn call(&mut self, name: &str, args: &[Value]) -> Result<Vec<Value>, CallError>;
    /// The simulation, to read.
    fn core(&self) -> Ref<'_, Sim>;
    /// Ends the run (cleanup hooks).
    fn cleanup(&mut self);
}

impl Drive for Engine {
    fn start(&mut self) {
        self.serve(Input::Control(LoopControl::Control(Control::Start)));
    }
    fn pause(&mut self) {
        self.serve(Input::Control(LoopControl::Control(Control::Pause)));
    }
    fn stop(&mut self) {
        self.serve(Input::Control(LoopControl::Control(Control::Stop)));
    }
    fn call(&mut self, name: &str, args: &[Value]) -> Result<Vec<Value>, CallError> {
        let target = Target::resolve_or_error(name)?;
        self.serve(Input::Call { target: &target, args }).into_values()
    }
    fn core(&self) -> Ref<'_, Sim> {
        self.sim()
    }
    fn cleanup(&mut self) {
        self.finish();
    }
}

/// The head of a scene with the paper's six-axis arm (`assets/robots/arm6/arm6.urdf`,
/// kinematic, in its start pose with the tool down) as `arm6`, `script` attached to it;
/// the caller appends its own objects.
pub fn arm6_scene_head(script: Option<&str>) -> String {
    let urdf = repo("assets/robots/arm6/arm6.urdf");
    let script = script.map(|s| format!("script = \"{s}\"\n")).unwrap_or_default();
    format!(
        "[simulation]\ndt = 0.05\n\n[[robot]]\nname = \"arm6\"\nurdf = \"{}\"\njoint_mode = \"kinematic\"\ninitial = {{ joint5 = -90 }}\n{script}",
        urdf.display()
    )
}

/// The text of `assets/scenes/bubble_rob.toml` with the rover's script replaced by
/// `script` (a file name relative to the scene), or removed for `None`. The camera's
/// edge-detection script is left out: these tests are about the controller.
pub fn bubble_rob_toml(script: Option<&str>) -> String {
    let text = std::fs::read_to_string(repo("assets/scenes/bubble_rob.toml")).expect("bubble_rob.toml is readable");
    let original = "script = \"../../scripts/bubble_rob.lua\"";
    assert!(
        text.contains(original),
        "bubble_rob.toml no longer attaches scripts/bubble_rob.lua"
    );
    let replacement = script.map_or(String::new(), |s| format!("script = \"{s}\""));
    text.replace(original, &replacement)
        .replace("script = \"../../scripts/edge_detect.lua\"", "")
}

/// A scene written to a temporary folder, and its simulation.
pub struct Scene {
    /// The simulation (dropped before the folder).
    pub sim: Engine,
    /// The folder holding the scene and its scripts.
    pub dir: TempDir,
}

impl Scene {
    /// Writes `toml` as `scene.toml` and each `(name, text)` of `files` next to it, loads
    /// it and builds the simulation with `limits` (not started).
    pub fn new(tag: &str, toml: &str, files: &[(&str, &str)], limits: ScriptLimits) -> Self {
        let dir = TempDir::new(tag);
        for (name, text) in files {
            dir.write(name, text);
        }
        let path = dir.write("scene.toml", toml);
        let sim = engine(load(&path), limits).expect("the simulation builds");
        Self { sim, dir }
    }

    /// BubbleRob's scene with `source` as the rover's script (`probe.lua`), started
    /// (so `sysCall_init` has run).
    pub fn rover(tag: &str, source: &str) -> Self {
        let mut s = Self::new(
            tag,
            &bubble_rob_toml(Some("probe.lua")),
            &[("probe.lua", source)],
            ScriptLimits::default(),
        );
        s.sim.start();
        s
    }

    /// `toml` with `body` plus [`LUA_ERR`] as `probe.lua`, default limits, started (so
    /// `sysCall_init` has run).
    pub fn probe(tag: &str, toml: &str, body: &str) -> Self {
        let source = format!("{body}\n{LUA_ERR}");
        let mut s = Self::new(tag, toml, &[("probe.lua", &source)], ScriptLimits::default());
        s.sim.start();
        s
    }

    /// Calls the script function `f` (see [`call`]).
    pub fn call(&mut self, f: &str, args: &[Value]) -> Vec<Value> {
        call(&mut self.sim, f, args)
    }

    /// Calls `sim.<name>` as a remote client would, expecting success.
    pub fn remote(&mut self, name: &str, args: &[Value]) -> Vec<Value> {
        self.sim
            .call(name, args)
            .unwrap_or_else(|e| panic!("remote sim.{name} failed: {e}"))
    }

    /// A handle by absolute path.
    pub fn find(&self, path: &str) -> Handle {
        find(&self.sim, path)
    }
}

/// Calls the global function `f` of the scripts, expecting a script to define it and
/// the call to succeed.
pub fn call(sim: &mut Engine, f: &str, args: &[Value]) -> Vec<Value> {
    match sim.call_script_function(f, args) {
        Ok(Some(v)) => v,
        Ok(None) => panic!("no running script defines {f}; scripts: {:?}", sim.scripts()),
        Err(e) => panic!("{f} raised: {e}"),
    }
}

/// A handle by absolute path, resolved by the world directly.
pub fn find(sim: &Engine, path: &str) -> Handle {
    sim.world().find(path, None, 0).expect(path)
}

/// A scene of one dummy, `/probe`, carrying `probe.lua`: for tests that only run a
/// script against the API.
pub const PROBE_ONLY_SCENE: &str = r#"
[[object]]
name = "probe"
kind = "dummy"
script = "probe.lua"
"#;

/// Lua source of `err(f, ...)`: calls `f` in protected mode, fails if it succeeds and
/// returns the error message otherwise. Append it to probe scripts.
pub const LUA_ERR: &str = "
function err(f, ...)
    local ok, e = pcall(f, ...)
    if ok then error('expected an error, the call succeeded', 2) end
    return tostring(e)
end
";

/// Every log line as `(source, verbosity, message)`.
pub fn log_lines(sim: &Engine) -> Vec<(String, i64, String)> {
    sim.world()
        .log
        .lines()
        .map(|l| (l.source.clone(), l.verbosity, l.message.clone()))
        .collect()
}

/// The messages logged by `source`, oldest first.
pub fn messages_from(sim: &Engine, source: &str) -> Vec<String> {
    log_lines(sim)
        .into_iter()
        .filter(|(s, _, _)| s == source)
        .map(|(_, _, m)| m)
        .collect()
}

/// The state of the script whose file name is `file`.
pub fn script_state(sim: &Engine, file: &str) -> ScriptState {
    sim.scripts()
        .into_iter()
        .find(|(p, _, _)| p.file_name().and_then(|n| n.to_str()) == Some(file))
        .map(|(_, _, s)| s)
        .unwrap_or_else(|| panic!("no script {file}"))
}

/// Fails with the script's error unless script `file` is running.
pub fn assert_running(sim: &Engine, file: &str) {
    assert_eq!(
        script_state(sim, file),
        ScriptState::Running,
        "{file}: {}",
        script_error(sim, file)
    );
}

/// The error text of an errored script, or a panic if it is running.
pub fn script_error(sim: &Engine, file: &str) -> String {
    match script_state(sim, file) {
        ScriptState::Errored(e) => e,
        ScriptState::Running => panic!("script {file} is still running"),
        ScriptState::Removed => panic!("script {file} was removed, not errored"),
    }
}

/// The value of the Int32 signal `name` (set by scripts with `sim.setInt32Signal`),
/// `None` when unset.
pub fn int32_signal(sim: &mut Engine, name: &str) -> Option<i64> {
    match sim.call("getInt32Signal", &[Value::Str(name.to_owned())]) {
        Ok(v) => match v.first() {
            Some(Value::Int(i)) => Some(*i),
            Some(Value::Nil) | None => None,
            Some(other) => panic!("signal {name} is {other:?}"),
        },
        Err(e) => panic!("getInt32Signal({name}) failed: {e}"),
    }
}

/// Position of `h` in the world frame, read from the world directly.
pub fn world_position(sim: &Engine, h: Handle) -> [f64; 3] {
    let w = sim.world();
    let p = w.object(h).expect("object exists").world.translation.vector;
    [p.x, p.y, p.z]
}
