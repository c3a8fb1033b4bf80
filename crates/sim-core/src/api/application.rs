//! What scripts ask of the application around the simulation: which plugins it has
//! loaded (`sim.getModuleName`) and starting programs (`sim.launchExecutable`).

use super::{ApiFn, ApiFunction, Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The application functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getModuleName",
        call: ApiFn::World(get_module_name),
    },
    ApiFunction {
        name: "launchExecutable",
        call: ApiFn::World(launch_executable),
    },
];

/// The plugins gantry stands in for, by the names CoppeliaSim's plugins give
/// themselves: scripts look them up before using their functions (V-REP's ROS 1 plugin
/// called itself `RosInterface`, CoppeliaSim 4's `ROS`; both are served on the ROS 2
/// graph, see docs/ros2.md).
const MODULES: &[&str] = &["ROS2", "ROS", "RosInterface", "IK", "CustomUI", "Vision", "RemoteApi"];

/// Plugin version reported for each (the API level gantry follows).
const MODULE_VERSION: i64 = 4;

/// `sim.getModuleName(index)`: the name and version of plugin `index`, `nil` past the
/// last, so that the usual `while moduleName do ... end` loop ends.
fn get_module_name(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let i = a.int(0)?;
    Ok(match usize::try_from(i).ok().and_then(|i| MODULES.get(i)) {
        Some(name) => vec![Value::Str((*name).to_owned()), Value::Int(MODULE_VERSION)],
        None => vec![Value::Nil],
    })
}

/// `sim.launchExecutable(path, arguments, showStatus)`: gantry does not start
/// programs from scripts (a scene file should not run code outside its sandbox, see
/// SECURITY.md), so it logs why and returns -1, CoppeliaSim's "could not launch", and the
/// script goes on as it would without the program. Start such programs (ROS nodes,
/// drivers) beside gantry instead.
fn launch_executable(w: &mut World, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    const WARNING: i64 = 300;
    let path = a.str(0)?;
    let t = w.time();
    w.log.push(
        t,
        WARNING,
        ctx.source,
        &format!(
            "sim.launchExecutable('{path}'): scripts do not start programs in gantry; start it beside gantry instead"
        ),
    );
    Ok(vec![Value::Int(-1)])
}
