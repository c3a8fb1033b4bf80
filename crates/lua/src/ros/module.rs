//! The `simROS2` and `simROS` tables: each name scripts call, mapped to its function
//! (topics, services and times in `lua_api.rs`, actions in `action_api.rs`), with the
//! API's error wrapper and the policy constants.

use mlua::{Function, Lua, MultiValue, Table, Value as LuaValue};

use super::action_api;
use super::lua_api::{self, Res, notice_ros1};
use super::params;

/// The functions of `simROS2`, sorted (the registry lists the same names; a test checks
/// that the two agree).
pub const FUNCTIONS: &[&str] = &[
    "actionClientTreatUInt8ArrayAsString",
    "actionServerActionAbort",
    "actionServerActionCanceled",
    "actionServerActionExecute",
    "actionServerActionIsActive",
    "actionServerActionIsCanceling",
    "actionServerActionIsExecuting",
    "actionServerActionSucceed",
    "actionServerPublishFeedback",
    "actionServerTreatUInt8ArrayAsString",
    "advertise",
    "advertiseService",
    "call",
    "cancelLastGoal",
    "createActionClient",
    "createActionServer",
    "createClient",
    "createInterface",
    "createPublisher",
    "createService",
    "createSubscription",
    "getSimulationTime",
    "getSystemTime",
    "getTime",
    "imageTransportCreatePublisher",
    "imageTransportPublish",
    "imageTransportShutdownPublisher",
    "publish",
    "publisherTreatUInt8ArrayAsString",
    "sendGoal",
    "sendTransform",
    "sendTransforms",
    "serviceClient",
    "shutdownActionClient",
    "shutdownActionServer",
    "shutdownClient",
    "shutdownPublisher",
    "shutdownService",
    "shutdownServiceClient",
    "shutdownServiceServer",
    "shutdownSubscriber",
    "shutdownSubscription",
    "subscribe",
    "subscriberTreatUInt8ArrayAsString",
    "subscriptionTreatUInt8ArrayAsString",
    "timeFromFloat",
    "timeToFloat",
    "waitForService",
];

/// The functions of `simROS` (ROS 1's plugin), sorted: served on the ROS 2 graph.
pub const ROS1_FUNCTIONS: &[&str] = &[
    "advertise",
    "deleteParam",
    "getParamBool",
    "getParamDouble",
    "getParamInt",
    "getParamString",
    "getTime",
    "hasParam",
    "publish",
    "publisherTreatUInt8ArrayAsString",
    "sendTransform",
    "sendTransforms",
    "setParamBool",
    "setParamDouble",
    "setParamInt",
    "setParamString",
    "shutdownPublisher",
    "shutdownSubscriber",
    "subscribe",
    "subscriberTreatUInt8ArrayAsString",
];

/// Adds `f` to `table` as `name`, reporting its errors through `wrap`: the one place a
/// `RosError` (`error.rs`) becomes the text a script sees, `(false, message)`
/// for the wrapper, which raises it from the caller's line.
fn add(
    lua: &Lua,
    table: &Table,
    wrap: &Function,
    module: &'static str,
    name: &'static str,
    f: fn(&Lua, &MultiValue) -> Res,
) -> mlua::Result<()> {
    let func = lua.create_function(move |lua, args: MultiValue| {
        if module == "simROS" {
            notice_ros1(lua);
        }
        match f(lua, &args) {
            Ok(values) => {
                let mut out = MultiValue::from_iter(values);
                out.push_front(LuaValue::Boolean(true));
                Ok(out)
            }
            Err(e) => Ok(MultiValue::from_iter([
                LuaValue::Boolean(false),
                LuaValue::String(lua.create_string(format!("{e} (in function '{module}.{name}')"))?),
            ])),
        }
    })?;
    table.set(name, wrap.call::<Function>(func)?)
}

fn policy_table(lua: &Lua, entries: &[(&str, i64)]) -> mlua::Result<Table> {
    let t = lua.create_table()?;
    for (k, v) in entries {
        t.set(*k, *v)?;
    }
    Ok(t)
}

type LuaApiFn = fn(&Lua, &MultiValue) -> Res;

/// `simROS2`'s functions by name (sorted as [`FUNCTIONS`]). The plugin's names from before
/// its renames (`subscribe`, `advertise`, `serviceClient`, ...) only log "renamed" in
/// CoppeliaSim; here they do what the new names do, so scripts that kept them work.
const ROS2_TABLE: &[(&str, LuaApiFn)] = &[
    (
        "actionClientTreatUInt8ArrayAsString",
        lua_api::treat_uint8_array_as_string,
    ),
    ("actionServerActionAbort", action_api::abort),
    ("actionServerActionCanceled", action_api::canceled),
    ("actionServerActionExecute", action_api::execute),
    ("actionServerActionIsActive", action_api::is_active),
    ("actionServerActionIsCanceling", action_api::is_canceling),
    ("actionServerActionIsExecuting", action_api::is_executing),
    ("actionServerActionSucceed", action_api::succeed),
    ("actionServerPublishFeedback", action_api::publish_feedback),
    (
        "actionServerTreatUInt8ArrayAsString",
        lua_api::treat_uint8_array_as_string,
    ),
    ("advertise", lua_api::create_publisher),
    ("advertiseService", lua_api::create_service),
    ("call", lua_api::call),
    ("cancelLastGoal", action_api::cancel_last_goal),
    ("createActionClient", action_api::create_action_client),
    ("createActionServer", action_api::create_action_server),
    ("createClient", lua_api::create_client),
    ("createInterface", lua_api::create_interface),
    ("createPublisher", lua_api::create_publisher),
    ("createService", lua_api::create_service),
    ("createSubscription", lua_api::create_subscription),
    ("getSimulationTime", lua_api::ros_time),
    ("getSystemTime", lua_api::system_time),
    ("getTime", lua_api::ros_time),
    (
        "imageTransportCreatePublisher",
        lua_api::image_transport_create_publisher,
    ),
    ("imageTransportPublish", lua_api::image_transport_publish),
    ("imageTransportShutdownPublisher", lua_api::shutdown_publisher),
    ("publish", lua_api::publish),
    ("publisherTreatUInt8ArrayAsString", lua_api::treat_uint8_array_as_string),
    ("sendGoal", action_api::send_goal),
    ("sendTransform", lua_api::send_transform),
    ("sendTransforms", lua_api::send_transform_list),
    ("serviceClient", lua_api::create_client),
    ("shutdownActionClient", lua_api::shutdown_action_client),
    ("shutdownActionServer", lua_api::shutdown_action_server),
    ("shutdownClient", lua_api::shutdown_client),
    ("shutdownPublisher", lua_api::shutdown_publisher),
    ("shutdownService", lua_api::shutdown_service),
    ("shutdownServiceClient", lua_api::shutdown_client),
    ("shutdownServiceServer", lua_api::shutdown_service),
    ("shutdownSubscriber", lua_api::shutdown_subscription),
    ("shutdownSubscription", lua_api::shutdown_subscription),
    ("subscribe", lua_api::create_subscription),
    (
        "subscriberTreatUInt8ArrayAsString",
        lua_api::treat_uint8_array_as_string,
    ),
    (
        "subscriptionTreatUInt8ArrayAsString",
        lua_api::treat_uint8_array_as_string,
    ),
    ("timeFromFloat", lua_api::time_from_float),
    ("timeToFloat", lua_api::time_to_float),
    ("waitForService", lua_api::wait_for_service),
];

/// `simROS`'s functions by name (sorted as [`ROS1_FUNCTIONS`]): ROS 1's names for the
/// same work.
const ROS1_TABLE: &[(&str, LuaApiFn)] = &[
    ("advertise", lua_api::create_publisher),
    ("deleteParam", params::delete_param),
    ("getParamBool", params::get_bool),
    ("getParamDouble", params::get_double),
    ("getParamInt", params::get_int),
    ("getParamString", params::get_string),
    ("getTime", lua_api::ros1_time),
    ("hasParam", params::has_param),
    ("publish", lua_api::publish),
    ("publisherTreatUInt8ArrayAsString", lua_api::treat_uint8_array_as_string),
    ("sendTransform", lua_api::send_transform),
    ("sendTransforms", lua_api::send_transform_list),
    ("setParamBool", params::set_bool),
    ("setParamDouble", params::set_double),
    ("setParamInt", params::set_int),
    ("setParamString", params::set_string),
    ("shutdownPublisher", lua_api::shutdown_publisher),
    ("shutdownSubscriber", lua_api::shutdown_subscription),
    ("subscribe", lua_api::create_subscription),
    (
        "subscriberTreatUInt8ArrayAsString",
        lua_api::treat_uint8_array_as_string,
    ),
];

/// Creates the `simROS2` and `simROS` tables.
pub(crate) fn install(lua: &Lua, wrap: &Function) -> mlua::Result<(Table, Table)> {
    let r2 = lua.create_table()?;
    for (name, f) in ROS2_TABLE {
        add(lua, &r2, wrap, "simROS2", name, *f)?;
    }
    r2.set(
        "qos_history_policy",
        policy_table(lua, &[("system_default", 0), ("keep_last", 1), ("keep_all", 2)])?,
    )?;
    r2.set(
        "qos_reliability_policy",
        policy_table(lua, &[("system_default", 0), ("reliable", 1), ("best_effort", 2)])?,
    )?;
    r2.set(
        "qos_durability_policy",
        policy_table(lua, &[("system_default", 0), ("transient_local", 1), ("volatile", 2)])?,
    )?;
    action_api::add_constants(lua, &r2)?;
    let r1 = lua.create_table()?;
    for (name, f) in ROS1_TABLE {
        add(lua, &r1, wrap, "simROS", name, *f)?;
    }
    Ok((r2, r1))
}
