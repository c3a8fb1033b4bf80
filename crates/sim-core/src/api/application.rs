//! What scripts ask of the application around the simulation: which plugins it has
//! loaded (`sim.getModuleName`). Starting programs (`sim.launchExecutable`) is the Lua
//! host's, which knows what the command line allows.

use super::{ApiFn, ApiFunction, Args, CallContext, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The application functions.
pub const FUNCTIONS: &[ApiFunction] = &[ApiFunction {
    name: "getModuleName",
    call: ApiFn::World(get_module_name),
}];

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
