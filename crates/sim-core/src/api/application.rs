//! What scripts ask of the application around the simulation: which plugins it has
//! loaded (`sim.getModuleName`), which API functions it has (`sim.getApiFunc`).
//! Starting programs (`sim.launchExecutable`) is the Lua
//! host's, which knows what the command line allows.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::world::World;

/// The application functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "getApiFunc",
        call: ApiFn::World(get_api_func),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "getModuleName",
        call: ApiFn::World(get_module_name),
        cost: Cost::Quick,
    },
];

/// `sim.getApiFunc(scriptHandle, apiWord)` → the qualified names of the API functions
/// (every module's, older names included, sorted) that start with `apiWord` after a
/// leading `+` (`'+sim.get'`), or contain it without one. `scriptHandle` is accepted
/// (every script sees the same API).
fn get_api_func(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    a.int(0)?;
    let word = a.str(1)?;
    let (prefix, word) = match word.strip_prefix('+') {
        Some(w) => (true, w),
        None => (false, word),
    };
    let mut names: Vec<String> = super::Target::accepted_names()
        .into_iter()
        .chain(super::host::HOST_FUNCTIONS.iter().map(|h| format!("sim.{}", h.name)))
        .filter(|n| if prefix { n.starts_with(word) } else { n.contains(word) })
        .collect();
    names.sort_unstable();
    names.dedup();
    Ok(vec![Value::Array(names.into_iter().map(Value::Str).collect())])
}

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
