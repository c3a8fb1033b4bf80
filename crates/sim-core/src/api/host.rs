//! The `sim.*` names that the core does not implement itself, because they need
//! something only a host has: the Lua state (script functions, blocking calls that
//! yield a threaded script) or the simulation loop and the client's session (starting,
//! stepping, locks, loading a scene). Together with [`super::MODULES`] this is the one
//! list of every name a script or client can call, with where it may run and what it
//! touches. The Lua host and the remote front ends each implement the entries assigned
//! to them; tests in each check that they implement exactly those, and docs/api.md and
//! the Python stubs are generated from here.

/// Whether scripts may call a host function, and from where.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InScripts {
    /// Not from scripts (a scene is loaded by the user or a client, not by a script).
    No,
    /// From any hook of any script.
    AnyHook,
    /// Only from a threaded script or a coroutine: the call blocks (yields) until a
    /// later step.
    ThreadedOnly,
}

/// Whether remote clients (ZMQ, the legacy remote API, the in-process Python client)
/// may call a host function, and who serves it. The variants carry the typed function,
/// so a front end that has resolved a name holds everything it needs and never
/// compares the name again.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Remote {
    /// Not remotely.
    No,
    /// The Lua host serves it for clients too: it needs the scripts.
    ByScriptHost(ScriptHostFn),
    /// The engine serves it: it concerns the client's session or the simulation loop.
    ByFrontEnd(FrontEndFn),
}

/// The host functions the Lua host serves for remote clients (it needs the scripts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScriptHostFn {
    /// `sim.callScriptFunction(name, scriptHandle, ...)`.
    CallScriptFunction,
    /// `sim.getScript(type, objectHandle|name)`.
    GetScript,
    /// `sim.getScriptAssociatedWithObject(objectHandle)` (4.0-4.5).
    GetScriptAssociatedWithObject,
    /// `sim.loadModel(path)`.
    LoadModel,
    /// `sim.removeScript(scriptHandle)`.
    RemoveScript,
    /// `sim.wait(dt, simulationTime=true)`: blocks (see [`ScriptHostFn::blocks`]).
    Wait,
    /// `sim.waitForSignal(name)`: blocks.
    WaitForSignal,
    /// `sim.moveToConfig(params)`: blocks while the joints move.
    MoveToConfig,
    /// `sim.moveToPose(params)`: blocks while the object moves.
    MoveToPose,
}

impl ScriptHostFn {
    /// Whether the call lasts several steps (a remote client's blocking call): the Lua
    /// host runs it as a coroutine the engine resumes after each step, and the client
    /// gets its answer when it returns. A stepping client's call takes the steps it
    /// needs, as `sim.step()` would.
    pub fn blocks(self) -> bool {
        matches!(
            self,
            Self::Wait | Self::WaitForSignal | Self::MoveToConfig | Self::MoveToPose
        )
    }
}

/// The host functions a remote client's session or the simulation loop serves: what
/// the engine between the front ends and the simulation carries out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FrontEndFn {
    /// `sim.acquireLock()`.
    AcquireLock,
    /// `sim.closeScene()`: an empty scene.
    CloseScene,
    /// `sim.loadScene(path)`.
    LoadScene,
    /// `sim.pauseSimulation()`.
    PauseSimulation,
    /// `sim.releaseLock()`.
    ReleaseLock,
    /// `sim.setStepping(enable)`.
    SetStepping,
    /// `sim.startSimulation()`.
    StartSimulation,
    /// `sim.step()`.
    Step,
    /// `sim.stopSimulation()`.
    StopSimulation,
}

/// What a host function acts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Touches {
    /// The simulation loop: running state, stepping levels, locks.
    Loop,
    /// The scripts: their functions, threads and time slices.
    Scripts,
    /// The scene as a whole: loading a scene or a model.
    Scene,
    /// The world, through a motion run by a threaded script over several steps.
    Motion,
    /// The front end's listeners: servers scripts start for remote clients.
    Listeners,
    /// The front end's ROS 2 network: publishers, subscriptions and services.
    Ros,
    /// Programs the host starts for scripts (`--allow-launch`).
    Programs,
}

/// One host function.
#[derive(Debug, Clone, Copy)]
pub struct HostFunction {
    /// Name without the `sim.` prefix.
    pub name: &'static str,
    /// From scripts.
    pub scripts: InScripts,
    /// From remote clients.
    pub remote: Remote,
    /// What it acts on.
    pub touches: Touches,
}

const fn f(name: &'static str, scripts: InScripts, remote: Remote, touches: Touches) -> HostFunction {
    HostFunction {
        name,
        scripts,
        remote,
        touches,
    }
}

use InScripts::{AnyHook, ThreadedOnly};
use Remote::{ByFrontEnd, ByScriptHost};
use Touches::{Loop, Motion, Scene, Scripts};

/// Every host function of module `sim`, sorted by name.
pub const HOST_FUNCTIONS: &[HostFunction] = &[
    f("acquireLock", AnyHook, ByFrontEnd(FrontEndFn::AcquireLock), Loop),
    f("broadcastMsg", AnyHook, Remote::No, Scripts),
    f(
        "callScriptFunction",
        AnyHook,
        ByScriptHost(ScriptHostFn::CallScriptFunction),
        Scripts,
    ),
    f("closeScene", InScripts::No, ByFrontEnd(FrontEndFn::CloseScene), Scene),
    f("followPath", ThreadedOnly, Remote::No, Motion),
    f("getAutoYieldDelay", AnyHook, Remote::No, Scripts),
    f("getScript", AnyHook, ByScriptHost(ScriptHostFn::GetScript), Scripts),
    f(
        "getScriptAssociatedWithObject",
        AnyHook,
        ByScriptHost(ScriptHostFn::GetScriptAssociatedWithObject),
        Scripts,
    ),
    f("getStepping", AnyHook, Remote::No, Scripts),
    f("getThreadAutomaticSwitch", AnyHook, Remote::No, Scripts),
    // V-REP 3's in-place inverse of a matrix table the script holds.
    f("invertMatrix", AnyHook, Remote::No, Scripts),
    f("isScriptRunningInThread", AnyHook, Remote::No, Scripts),
    f("launchExecutable", AnyHook, Remote::No, Touches::Programs),
    f("loadModel", AnyHook, ByScriptHost(ScriptHostFn::LoadModel), Scene),
    f("loadScene", InScripts::No, ByFrontEnd(FrontEndFn::LoadScene), Scene),
    f(
        "moveToConfig",
        ThreadedOnly,
        ByScriptHost(ScriptHostFn::MoveToConfig),
        Motion,
    ),
    f("moveToConfig_cleanup", AnyHook, Remote::No, Motion),
    f("moveToConfig_init", AnyHook, Remote::No, Motion),
    f("moveToConfig_step", AnyHook, Remote::No, Motion),
    f(
        "moveToPose",
        ThreadedOnly,
        ByScriptHost(ScriptHostFn::MoveToPose),
        Motion,
    ),
    f("moveToPose_cleanup", AnyHook, Remote::No, Motion),
    f("moveToPose_init", AnyHook, Remote::No, Motion),
    f("moveToPose_step", AnyHook, Remote::No, Motion),
    f("moveToPosition", ThreadedOnly, Remote::No, Motion),
    f(
        "pauseSimulation",
        AnyHook,
        ByFrontEnd(FrontEndFn::PauseSimulation),
        Loop,
    ),
    f("releaseLock", AnyHook, ByFrontEnd(FrontEndFn::ReleaseLock), Loop),
    f(
        "removeScript",
        AnyHook,
        ByScriptHost(ScriptHostFn::RemoveScript),
        Scripts,
    ),
    f("rmlMoveToJointPositions", ThreadedOnly, Remote::No, Motion),
    f("setAutoYieldDelay", AnyHook, Remote::No, Scripts),
    f("setStepping", AnyHook, ByFrontEnd(FrontEndFn::SetStepping), Loop),
    f("setThreadAutomaticSwitch", AnyHook, Remote::No, Scripts),
    f("setThreadIsFree", AnyHook, Remote::No, Scripts),
    f("setThreadSwitchTiming", AnyHook, Remote::No, Scripts),
    f("startRecording", AnyHook, Remote::No, Loop),
    f(
        "startSimulation",
        AnyHook,
        ByFrontEnd(FrontEndFn::StartSimulation),
        Loop,
    ),
    f("step", ThreadedOnly, ByFrontEnd(FrontEndFn::Step), Loop),
    f("stopRecording", AnyHook, Remote::No, Loop),
    f("stopSimulation", AnyHook, ByFrontEnd(FrontEndFn::StopSimulation), Loop),
    f("switchThread", ThreadedOnly, Remote::No, Scripts),
    f("wait", ThreadedOnly, ByScriptHost(ScriptHostFn::Wait), Loop),
    f(
        "waitForSignal",
        ThreadedOnly,
        ByScriptHost(ScriptHostFn::WaitForSignal),
        Loop,
    ),
];

/// A module whose every function a host implements (no core function behind it).
#[derive(Debug, Clone, Copy)]
pub struct HostModule {
    /// Its name, the Lua global and `require` name.
    pub name: &'static str,
    /// Its functions, sorted by name.
    pub functions: &'static [HostFunction],
}

/// Modules besides `sim` that only the Lua host implements.
pub const HOST_MODULES: &[HostModule] = &[
    HostModule {
        // CoppeliaSim's legacy remote API plugin: scripts start servers for `simx*` clients.
        name: "simRemoteApi",
        functions: &[
            f("reset", AnyHook, Remote::No, Touches::Listeners),
            f("start", AnyHook, Remote::No, Touches::Listeners),
            f("status", AnyHook, Remote::No, Touches::Listeners),
            f("stop", AnyHook, Remote::No, Touches::Listeners),
        ],
    },
    HostModule {
        // CoppeliaSim's ROS 2 plugin, on gantry's own DDS transport (docs/ros2.md).
        name: "simROS2",
        functions: &[
            f("actionClientTreatUInt8ArrayAsString", AnyHook, Remote::No, Touches::Ros),
            f("actionServerActionAbort", AnyHook, Remote::No, Touches::Ros),
            f("actionServerActionCanceled", AnyHook, Remote::No, Touches::Ros),
            f("actionServerActionExecute", AnyHook, Remote::No, Touches::Ros),
            f("actionServerActionIsActive", AnyHook, Remote::No, Touches::Ros),
            f("actionServerActionIsCanceling", AnyHook, Remote::No, Touches::Ros),
            f("actionServerActionIsExecuting", AnyHook, Remote::No, Touches::Ros),
            f("actionServerActionSucceed", AnyHook, Remote::No, Touches::Ros),
            f("actionServerPublishFeedback", AnyHook, Remote::No, Touches::Ros),
            f("actionServerTreatUInt8ArrayAsString", AnyHook, Remote::No, Touches::Ros),
            f("advertise", AnyHook, Remote::No, Touches::Ros),
            f("advertiseService", AnyHook, Remote::No, Touches::Ros),
            f("call", AnyHook, Remote::No, Touches::Ros),
            f("cancelLastGoal", AnyHook, Remote::No, Touches::Ros),
            f("createActionClient", AnyHook, Remote::No, Touches::Ros),
            f("createActionServer", AnyHook, Remote::No, Touches::Ros),
            f("createClient", AnyHook, Remote::No, Touches::Ros),
            f("createInterface", AnyHook, Remote::No, Touches::Ros),
            f("createPublisher", AnyHook, Remote::No, Touches::Ros),
            f("createService", AnyHook, Remote::No, Touches::Ros),
            f("createSubscription", AnyHook, Remote::No, Touches::Ros),
            f("getSimulationTime", AnyHook, Remote::No, Touches::Ros),
            f("getSystemTime", AnyHook, Remote::No, Touches::Ros),
            f("getTime", AnyHook, Remote::No, Touches::Ros),
            f("imageTransportCreatePublisher", AnyHook, Remote::No, Touches::Ros),
            f("imageTransportPublish", AnyHook, Remote::No, Touches::Ros),
            f("imageTransportShutdownPublisher", AnyHook, Remote::No, Touches::Ros),
            f("publish", AnyHook, Remote::No, Touches::Ros),
            f("publisherTreatUInt8ArrayAsString", AnyHook, Remote::No, Touches::Ros),
            f("sendGoal", AnyHook, Remote::No, Touches::Ros),
            f("sendTransform", AnyHook, Remote::No, Touches::Ros),
            f("sendTransforms", AnyHook, Remote::No, Touches::Ros),
            f("serviceClient", AnyHook, Remote::No, Touches::Ros),
            f("shutdownActionClient", AnyHook, Remote::No, Touches::Ros),
            f("shutdownActionServer", AnyHook, Remote::No, Touches::Ros),
            f("shutdownClient", AnyHook, Remote::No, Touches::Ros),
            f("shutdownPublisher", AnyHook, Remote::No, Touches::Ros),
            f("shutdownService", AnyHook, Remote::No, Touches::Ros),
            f("shutdownServiceClient", AnyHook, Remote::No, Touches::Ros),
            f("shutdownServiceServer", AnyHook, Remote::No, Touches::Ros),
            f("shutdownSubscriber", AnyHook, Remote::No, Touches::Ros),
            f("shutdownSubscription", AnyHook, Remote::No, Touches::Ros),
            f("subscribe", AnyHook, Remote::No, Touches::Ros),
            f("subscriberTreatUInt8ArrayAsString", AnyHook, Remote::No, Touches::Ros),
            f("subscriptionTreatUInt8ArrayAsString", AnyHook, Remote::No, Touches::Ros),
            f("timeFromFloat", AnyHook, Remote::No, Touches::Ros),
            f("timeToFloat", AnyHook, Remote::No, Touches::Ros),
            f("waitForService", AnyHook, Remote::No, Touches::Ros),
        ],
    },
    HostModule {
        // ROS 1's plugin: old scripts, served on the ROS 2 graph.
        name: "simROS",
        functions: &[
            f("advertise", AnyHook, Remote::No, Touches::Ros),
            f("deleteParam", AnyHook, Remote::No, Touches::Ros),
            f("getParamBool", AnyHook, Remote::No, Touches::Ros),
            f("getParamDouble", AnyHook, Remote::No, Touches::Ros),
            f("getParamInt", AnyHook, Remote::No, Touches::Ros),
            f("getParamString", AnyHook, Remote::No, Touches::Ros),
            f("getTime", AnyHook, Remote::No, Touches::Ros),
            f("hasParam", AnyHook, Remote::No, Touches::Ros),
            f("publish", AnyHook, Remote::No, Touches::Ros),
            f("publisherTreatUInt8ArrayAsString", AnyHook, Remote::No, Touches::Ros),
            f("sendTransform", AnyHook, Remote::No, Touches::Ros),
            f("sendTransforms", AnyHook, Remote::No, Touches::Ros),
            f("setParamBool", AnyHook, Remote::No, Touches::Ros),
            f("setParamDouble", AnyHook, Remote::No, Touches::Ros),
            f("setParamInt", AnyHook, Remote::No, Touches::Ros),
            f("setParamString", AnyHook, Remote::No, Touches::Ros),
            f("shutdownPublisher", AnyHook, Remote::No, Touches::Ros),
            f("shutdownSubscriber", AnyHook, Remote::No, Touches::Ros),
            f("subscribe", AnyHook, Remote::No, Touches::Ros),
            f("subscriberTreatUInt8ArrayAsString", AnyHook, Remote::No, Touches::Ros),
        ],
    },
];

/// The host function named `name` (without `sim.`).
pub fn host_function(name: &str) -> Option<&'static HostFunction> {
    HOST_FUNCTIONS.iter().find(|h| h.name == name)
}

/// Names scripts may call beyond the core registry.
pub fn script_host_names() -> impl Iterator<Item = &'static str> {
    HOST_FUNCTIONS
        .iter()
        .filter(|h| h.scripts != InScripts::No)
        .map(|h| h.name)
}

/// Names remote clients may call beyond the core registry.
pub fn remote_names() -> impl Iterator<Item = &'static str> {
    HOST_FUNCTIONS.iter().filter(|h| h.remote != Remote::No).map(|h| h.name)
}

/// The host functions the Lua host serves for remote clients, with their names.
pub fn script_host_functions() -> impl Iterator<Item = (&'static str, ScriptHostFn)> {
    HOST_FUNCTIONS.iter().filter_map(|h| match h.remote {
        Remote::ByScriptHost(f) => Some((h.name, f)),
        _ => None,
    })
}

/// The host functions the engine serves for remote clients, with their names.
pub fn front_end_functions() -> impl Iterator<Item = (&'static str, FrontEndFn)> {
    HOST_FUNCTIONS.iter().filter_map(|h| match h.remote {
        Remote::ByFrontEnd(f) => Some((h.name, f)),
        _ => None,
    })
}

impl ScriptHostFn {
    /// The function's name without `sim.`.
    pub fn name(self) -> &'static str {
        name_of(Remote::ByScriptHost(self))
    }
}

impl FrontEndFn {
    /// The function's name without `sim.`.
    pub fn name(self) -> &'static str {
        name_of(Remote::ByFrontEnd(self))
    }
}

/// The name of the one entry serving `remote` (each typed function has exactly one
/// entry; a unit test checks it).
fn name_of(remote: Remote) -> &'static str {
    HOST_FUNCTIONS
        .iter()
        .find(|h| h.remote == remote)
        .map_or("?", |h| h.name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorted_unique_and_not_in_the_core() {
        for pair in HOST_FUNCTIONS.windows(2) {
            assert!(pair[0].name < pair[1].name, "{} before {}", pair[0].name, pair[1].name);
        }
        for h in HOST_FUNCTIONS {
            assert!(
                super::super::function(h.name).is_none(),
                "{} is implemented twice",
                h.name
            );
            assert!(
                h.scripts != InScripts::No || h.remote != Remote::No,
                "{} is callable from nowhere",
                h.name
            );
        }
    }

    #[test]
    fn each_typed_function_has_one_entry_and_its_name() {
        let mut seen = std::collections::HashSet::new();
        for h in HOST_FUNCTIONS.iter().filter(|h| h.remote != Remote::No) {
            assert!(seen.insert(h.remote), "{} serves {:?} twice", h.name, h.remote);
            let name = match h.remote {
                Remote::ByScriptHost(f) => f.name(),
                Remote::ByFrontEnd(f) => f.name(),
                Remote::No => unreachable!("filtered"),
            };
            assert_eq!(name, h.name);
        }
        assert_eq!(script_host_functions().count(), 9);
        assert_eq!(front_end_functions().count(), 9);
    }
}
