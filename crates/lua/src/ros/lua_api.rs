//! The `simROS2` table scripts call, and `simROS` (ROS 1's plugin) on the same graph.
//! Each function reports failure as `(false, message)` for the API's error wrapper,
//! which raises it from the caller's line as CoppeliaSim does.
//!
//! Messages are Lua tables with ROS's field names; fields left out take ROS's defaults,
//! `uint8[]` fields are Lua strings, and times are `{sec=, nanosec=}` tables (a number of
//! seconds is accepted too, as ROS 1's plugin took). Handles are integers.

use std::sync::atomic::{AtomicU64, Ordering};

use gantry_protocol::Value;
use gantry_protocol::ros::{
    MsgType, SrvType, message_type, service_reply_topic, service_request_topic, service_type, topic_name,
};
use gantry_ros::{Direction, EndpointId, RosQos};
use mlua::{Lua, MultiValue, Value as LuaValue};

use super::callback::Callback;
use super::error::RosError;
use super::host::{Endpoint, Kind, RosHost};
use super::wire::{encode, read_header, request_header, time_value};
use crate::app_state::state;
use crate::convert::{to_lua, to_value};
use crate::running::Running;
use crate::sim_cell::SimCell;

/// How long `simROS2.call` waits for a reply, s.
pub const CALL_TIMEOUT_S: f64 = 5.0;

/// What a `simROS2` function returns to the API's wrapper: its values, or why it failed.
pub(super) type Res = Result<Vec<LuaValue>, RosError>;

/// A value's type as Lua's `type()` names it (mlua tells integers from floats).
pub(super) fn lua_type(v: &LuaValue) -> &'static str {
    match v {
        LuaValue::Integer(_) | LuaValue::Number(_) => "number",
        other => other.type_name(),
    }
}

pub(super) fn arg(args: &MultiValue, i: usize) -> Option<&LuaValue> {
    args.get(i).filter(|v| !v.is_nil())
}

/// The [`RosError::WrongType`] of argument `i` (from 0), given `v`.
pub(super) fn wrong_type(i: usize, what: &'static str, expected: &'static str, v: &LuaValue) -> RosError {
    RosError::WrongType {
        arg: i + 1,
        what,
        expected,
        got: lua_type(v),
    }
}

/// The [`RosError::Missing`] of argument `i` (from 0).
pub(super) fn missing(i: usize, what: &'static str) -> RosError {
    RosError::Missing { arg: i + 1, what }
}

pub(super) fn string_arg(args: &MultiValue, i: usize, what: &'static str) -> Result<String, RosError> {
    match arg(args, i) {
        Some(LuaValue::String(s)) => s
            .to_str()
            .map(|s| s.to_string())
            .map_err(|_| RosError::NotUtf8 { arg: i + 1, what }),
        Some(v) => Err(wrong_type(i, what, "a string", v)),
        None => Err(missing(i, what)),
    }
}

pub(super) fn handle_arg(args: &MultiValue, i: usize) -> Result<i64, RosError> {
    match arg(args, i) {
        Some(LuaValue::Integer(h)) => Ok(*h),
        Some(LuaValue::Number(n)) if n.fract() == 0.0 => Ok(*n as i64),
        Some(v) => Err(RosError::Expected {
            arg: i + 1,
            expected: "a handle",
            got: lua_type(v).to_owned(),
        }),
        None => Err(missing(i, "the handle")),
    }
}

pub(super) fn table_value(args: &MultiValue, i: usize, what: &'static str) -> Result<Value, RosError> {
    match arg(args, i) {
        Some(v @ LuaValue::Table(_)) => to_value(v).map_err(|source| RosError::NotAMessage {
            arg: i + 1,
            what,
            source,
        }),
        Some(v) => Err(wrong_type(i, what, "a table", v)),
        None => Err(missing(i, what)),
    }
}

/// The QoS of `createPublisher(topic, type, queueSize|qos, latch)` and
/// `createSubscription(topic, type, callback, queueSize|qos)`: a number is the history
/// depth; a table holds `history`, `depth`, `reliability`, `durability` with the values
/// of `simROS2.qos_*_policy`; `latch` makes a publisher transient-local.
fn qos_arg(v: Option<&LuaValue>, latch: bool) -> Result<RosQos, RosError> {
    let mut q = RosQos {
        transient_local: latch,
        ..RosQos::default()
    };
    match v {
        None => {}
        Some(LuaValue::Integer(d)) => q.depth = u32::try_from(*d).map_err(|_| RosError::QueueSize(*d))?.max(1),
        Some(LuaValue::Number(d)) if d.fract() == 0.0 && *d >= 0.0 => q.depth = (*d as u32).max(1),
        Some(LuaValue::Table(t)) => {
            let int = |k: &'static str| -> Result<Option<i64>, RosError> {
                match t.get::<LuaValue>(k)? {
                    LuaValue::Nil => Ok(None),
                    LuaValue::Integer(i) => Ok(Some(i)),
                    LuaValue::Number(n) if n.fract() == 0.0 => Ok(Some(n as i64)),
                    other => Err(RosError::QosNotAnInteger {
                        key: k,
                        got: lua_type(&other),
                    }),
                }
            };
            let policy = |policy, value| RosError::QosPolicy { policy, value };
            if let Some(d) = int("depth")? {
                q.depth = u32::try_from(d).map_err(|_| RosError::QosDepth(d))?.max(1);
            }
            match int("history")? {
                // keep_all: the deepest queue gantry keeps.
                Some(2) => q.depth = q.depth.max(1000),
                None | Some(0..=1) => {}
                Some(h) => return Err(policy("history", h)),
            }
            match int("reliability")? {
                None | Some(0 | 1) => q.reliable = true,
                Some(2) => q.reliable = false,
                Some(r) => return Err(policy("reliability", r)),
            }
            match int("durability")? {
                None | Some(0) => {}
                Some(1) => q.transient_local = true,
                Some(2) => q.transient_local = false,
                Some(d) => return Err(policy("durability", d)),
            }
        }
        Some(other) => return Err(RosError::QosKind { got: lua_type(other) }),
    }
    Ok(q)
}

/// Argument `i` (from 0) as a callback.
pub(super) fn callback_arg(lua: &Lua, args: &MultiValue, i: usize) -> Result<Callback, RosError> {
    match arg(args, i) {
        Some(LuaValue::Function(f)) => lua
            .create_registry_value(f.clone())
            .map(Callback::Function)
            .map_err(|source| RosError::CallbackNotKept { arg: i + 1, source }),
        Some(LuaValue::String(s)) => Ok(Callback::Name(s.to_string_lossy())),
        Some(other) => Err(wrong_type(i, "the callback", "a function or its name", other)),
        None => Err(missing(i, "the callback")),
    }
}

pub(super) fn running_object(lua: &Lua) -> Option<gantry_sim_core::Handle> {
    state::<Running>(lua).object.get()
}

/// Simulation time, s.
pub(crate) fn sim_time(lua: &Lua) -> f64 {
    state::<SimCell>(lua)
        .try_borrow()
        .map(|s| s.world.time())
        .unwrap_or(0.0)
}

fn time_lua(lua: &Lua, t: f64) -> mlua::Result<LuaValue> {
    to_lua(lua, &time_value(t))
}

pub(super) fn create_publisher(lua: &Lua, args: &MultiValue) -> Res {
    let topic = string_arg(args, 0, "the topic name")?;
    let type_name = string_arg(args, 1, "the message type")?;
    let ty = message_type(&type_name)?;
    let latch = matches!(arg(args, 3), Some(LuaValue::Boolean(true)));
    let qos = qos_arg(arg(args, 2), latch)?;
    open_publisher(lua, &topic, ty, qos)
}

/// A publisher of `ty` on `topic` for the running script; its handle.
fn open_publisher(lua: &Lua, topic: &str, ty: &'static MsgType, qos: RosQos) -> Res {
    let dds_topic = topic_name(topic)?;
    let host = state::<RosHost>(lua);
    let id = host.open(Direction::Publish, dds_topic, ty.dds_type_name(), qos)?;
    let h = host.insert(Endpoint {
        script: running_object(lua),
        kind: Kind::Publisher { id, ty },
    });
    Ok(vec![LuaValue::Integer(h)])
}

pub(super) fn publish(lua: &Lua, args: &MultiValue) -> Res {
    let h = handle_arg(args, 0)?;
    let msg = table_value(args, 1, "the message")?;
    publish_value(lua, h, &msg)
}

/// Encodes `msg` for publisher `h` and queues it.
fn publish_value(lua: &Lua, h: i64, msg: &Value) -> Res {
    let host = state::<RosHost>(lua);
    let (id, ty) = match host.endpoints.borrow().get(&h).map(|e| &e.kind) {
        Some(Kind::Publisher { id, ty }) => (*id, *ty),
        _ => {
            return Err(RosError::WrongHandle {
                handle: h,
                expected: "a publisher",
            });
        }
    };
    let body = encode(ty, msg)?;
    host.network().and_then(|n| n.write(id, body))?;
    Ok(vec![])
}

/// `simROS2.imageTransportCreatePublisher(topic [, queueSize])`: a `sensor_msgs/Image`
/// publisher for [`image_transport_publish`] (the raw transport only).
pub(super) fn image_transport_create_publisher(lua: &Lua, args: &MultiValue) -> Res {
    let topic = string_arg(args, 0, "the topic name")?;
    let qos = qos_arg(arg(args, 1), false)?;
    open_publisher(lua, &topic, message_type("sensor_msgs/msg/Image")?, qos)
}

/// `simROS2.imageTransportPublish(publisher, data, width, height, frameId)`: an `rgb8`
/// image of `width` x `height` pixels, rows as given (3 bytes a pixel), stamped with
/// simulation time.
pub(super) fn image_transport_publish(lua: &Lua, args: &MultiValue) -> Res {
    let h = handle_arg(args, 0)?;
    let data = match arg(args, 1) {
        Some(LuaValue::String(s)) => s.as_bytes().to_vec(),
        Some(v) => return Err(wrong_type(1, "the image", "a string (buffer)", v)),
        None => return Err(missing(1, "the image")),
    };
    let size = |i: usize, what: &'static str| -> Result<u32, RosError> {
        match arg(args, i) {
            Some(LuaValue::Integer(n)) => u32::try_from(*n).map_err(|_| RosError::OutOfRange {
                arg: i + 1,
                what,
                value: *n,
            }),
            Some(LuaValue::Number(n)) if n.fract() == 0.0 && *n >= 0.0 && *n <= f64::from(u32::MAX) => Ok(*n as u32),
            Some(v) => Err(wrong_type(i, what, "an integer", v)),
            None => Err(missing(i, what)),
        }
    };
    let (w, hgt) = (size(2, "the width")?, size(3, "the height")?);
    let frame = match arg(args, 4) {
        Some(LuaValue::String(s)) => s.to_string_lossy(),
        _ => String::new(),
    };
    let expected = 3 * u64::from(w) * u64::from(hgt);
    if data.len() as u64 != expected {
        return Err(RosError::ImageSize {
            width: w,
            height: hgt,
            expected,
            got: data.len(),
        });
    }
    let key = |k: &str| Value::Str(k.to_owned());
    let msg = Value::Map(vec![
        (
            key("header"),
            Value::Map(vec![
                (key("stamp"), time_value(sim_time(lua))),
                (key("frame_id"), Value::Str(frame)),
            ]),
        ),
        (key("height"), Value::Int(i64::from(hgt))),
        (key("width"), Value::Int(i64::from(w))),
        (key("encoding"), Value::Str("rgb8".to_owned())),
        (key("step"), Value::Int(3 * i64::from(w))),
        (key("data"), Value::Bytes(data)),
    ]);
    publish_value(lua, h, &msg)
}

/// Closes the endpoint of argument 1, which must be of the kind `expected` names
/// (with its article, for [`RosError::WrongHandle`]).
fn shutdown(lua: &Lua, args: &MultiValue, expected: &'static str, is: fn(&Kind) -> bool) -> Res {
    let h = handle_arg(args, 0)?;
    let host = state::<RosHost>(lua);
    let ok = host.endpoints.borrow().get(&h).is_some_and(|e| is(&e.kind));
    if !ok {
        return Err(RosError::WrongHandle { handle: h, expected });
    }
    host.remove(h);
    Ok(vec![])
}

pub(super) fn create_subscription(lua: &Lua, args: &MultiValue) -> Res {
    let topic = string_arg(args, 0, "the topic name")?;
    let type_name = string_arg(args, 1, "the message type")?;
    let ty = message_type(&type_name)?;
    let callback = callback_arg(lua, args, 2)?;
    let qos = qos_arg(arg(args, 3), false)?;
    let dds_topic = topic_name(&topic)?;
    let host = state::<RosHost>(lua);
    let id = host.open(Direction::Subscribe, dds_topic, ty.dds_type_name(), qos)?;
    let h = host.insert(Endpoint {
        script: running_object(lua),
        kind: Kind::Subscription {
            id,
            ty,
            callback,
            warned: std::cell::Cell::new(false),
        },
    });
    Ok(vec![LuaValue::Integer(h)])
}

/// A service's two endpoints, for a server (`serving`: requests in, replies out) or a
/// client (the other way round): `(requests, replies)`, after the name and type are
/// checked.
fn open_service(host: &RosHost, name: &str, ty: &SrvType, serving: bool) -> Result<(EndpointId, EndpointId), RosError> {
    let rq = service_request_topic(name)?;
    let rr = service_reply_topic(name)?;
    open_service_topics(host, (rq, rr), ty, serving)
}

/// [`open_service`] on DDS topics already mapped: `(request topic, reply topic)`.
pub(super) fn open_service_topics(
    host: &RosHost,
    (rq, rr): (String, String),
    ty: &SrvType,
    serving: bool,
) -> Result<(EndpointId, EndpointId), RosError> {
    let (inward, outward) = if serving {
        (Direction::Subscribe, Direction::Publish)
    } else {
        (Direction::Publish, Direction::Subscribe)
    };
    let requests = host.open(inward, rq, ty.dds_request_type_name(), RosQos::default())?;
    match host.open(outward, rr, ty.dds_response_type_name(), RosQos::default()) {
        Ok(replies) => Ok((requests, replies)),
        Err(e) => {
            if let Ok(n) = host.network() {
                n.close(requests);
            }
            Err(e.into())
        }
    }
}

pub(super) fn create_service(lua: &Lua, args: &MultiValue) -> Res {
    let name = string_arg(args, 0, "the service name")?;
    let type_name = string_arg(args, 1, "the service type")?;
    let ty = service_type(&type_name)?;
    let callback = callback_arg(lua, args, 2)?;
    let host = state::<RosHost>(lua);
    let (requests, replies) = open_service(&host, &name, ty, true)?;
    let h = host.insert(Endpoint {
        script: running_object(lua),
        kind: Kind::Service {
            requests,
            replies,
            ty,
            callback,
        },
    });
    Ok(vec![LuaValue::Integer(h)])
}

/// Client ids: distinct per client in this process, and unlikely to meet another
/// process's (the process id in the high bits).
pub(super) fn next_guid() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    (u64::from(std::process::id()) << 32) | NEXT.fetch_add(1, Ordering::Relaxed)
}

pub(super) fn create_client(lua: &Lua, args: &MultiValue) -> Res {
    let name = string_arg(args, 0, "the service name")?;
    let type_name = string_arg(args, 1, "the service type")?;
    let ty = service_type(&type_name)?;
    let host = state::<RosHost>(lua);
    let (requests, replies) = open_service(&host, &name, ty, false)?;
    let h = host.insert(Endpoint {
        script: running_object(lua),
        kind: Kind::Client {
            requests,
            replies,
            ty,
            guid: next_guid(),
            seq: std::cell::Cell::new(0),
        },
    });
    Ok(vec![LuaValue::Integer(h)])
}

/// `simROS2.call(client, request)`: sends the request and waits for its reply, at most
/// [`CALL_TIMEOUT_S`] of wall time (CoppeliaSim's call blocks the same way; the
/// simulation is not stepped meanwhile).
pub(super) fn call(lua: &Lua, args: &MultiValue) -> Res {
    let h = handle_arg(args, 0)?;
    let req = table_value(args, 1, "the request")?;
    let host = state::<RosHost>(lua);
    let (requests, replies, ty, guid, seq) = match host.endpoints.borrow().get(&h).map(|e| &e.kind) {
        Some(Kind::Client {
            requests,
            replies,
            ty,
            guid,
            seq,
        }) => {
            seq.set(seq.get() + 1);
            (*requests, *replies, *ty, *guid, seq.get())
        }
        _ => return Err(not_a_client(h)),
    };
    let mut body = request_header(guid, seq);
    ty.request().encode_into(&req, &mut body, 0)?;
    let net = host.network()?;
    drop(host);
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs_f64(CALL_TIMEOUT_S);
    // A request written before discovery has matched the server would be lost
    // (requests are volatile, as in ROS): wait for the match first.
    if !(wait_matched(net.as_ref(), requests, deadline) && wait_matched(net.as_ref(), replies, deadline)) {
        return Err(RosError::NoServer {
            service: ty.name().to_owned(),
            timeout_s: CALL_TIMEOUT_S,
        });
    }
    net.write(requests, body)?;
    while std::time::Instant::now() < deadline {
        for s in net.take(replies, usize::MAX) {
            if read_header(&s.body, s.little_endian) == Some((guid, seq)) {
                let v = ty
                    .response()
                    .decode_body(&s.body, s.little_endian, 16)
                    .map_err(RosError::MalformedReply)?;
                return Ok(vec![to_lua(lua, &v)?]);
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    Err(RosError::NoReply {
        service: ty.name().to_owned(),
        timeout_s: CALL_TIMEOUT_S,
    })
}

fn not_a_client(handle: i64) -> RosError {
    RosError::WrongHandle {
        handle,
        expected: "a client",
    }
}

/// Waits (wall time, until `deadline`) for publisher `id` to match a subscription;
/// whether it did.
pub(super) fn wait_matched(net: &dyn gantry_ros::RosNetwork, id: EndpointId, deadline: std::time::Instant) -> bool {
    loop {
        if net.matched(id) > 0 {
            return true;
        }
        if std::time::Instant::now() >= deadline {
            return false;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
}

/// `simROS2.waitForService(client, timeout)`: whether a server of the client's service
/// is on the graph, waiting at most `timeout` s of wall time (default and cap
/// [`CALL_TIMEOUT_S`]); the simulation waits meanwhile, as in CoppeliaSim.
pub(super) fn wait_for_service(lua: &Lua, args: &MultiValue) -> Res {
    let h = handle_arg(args, 0)?;
    let timeout = match arg(args, 1) {
        None => CALL_TIMEOUT_S,
        Some(LuaValue::Integer(t)) => *t as f64,
        Some(LuaValue::Number(t)) => *t,
        Some(v) => return Err(wrong_type(1, "the timeout", "a number of seconds", v)),
    };
    let timeout = if timeout.is_finite() {
        timeout.clamp(0.0, CALL_TIMEOUT_S)
    } else {
        CALL_TIMEOUT_S
    };
    let host = state::<RosHost>(lua);
    let (requests, replies) = match host.endpoints.borrow().get(&h).map(|e| &e.kind) {
        Some(Kind::Client { requests, replies, .. }) => (*requests, *replies),
        _ => return Err(not_a_client(h)),
    };
    let net = host.network()?;
    drop(host);
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs_f64(timeout);
    // Both ways: the server reads our requests, and we read its replies.
    let ready = wait_matched(net.as_ref(), requests, deadline) && wait_matched(net.as_ref(), replies, deadline);
    Ok(vec![LuaValue::Boolean(ready)])
}

fn transform_stamped() -> &'static MsgType {
    // Known to the codec: a missing entry is a bug caught by the tests.
    message_type("tf2_msgs/msg/TFMessage").expect("tf2_msgs/msg/TFMessage is a known type")
}

fn send_transforms(lua: &Lua, transforms: Vec<Value>) -> Res {
    let host = state::<RosHost>(lua);
    let id = match host.tf.get() {
        Some(id) => id,
        None => {
            let id = host.open(
                Direction::Publish,
                "rt/tf".to_owned(),
                transform_stamped().dds_type_name(),
                RosQos {
                    depth: 100,
                    ..RosQos::default()
                },
            )?;
            host.tf.set(Some(id));
            id
        }
    };
    let msg = Value::Map(vec![(Value::Str("transforms".into()), Value::Array(transforms))]);
    let body = encode(transform_stamped(), &msg)?;
    host.network().and_then(|n| n.write(id, body))?;
    Ok(vec![])
}

pub(super) fn create_interface(lua: &Lua, args: &MultiValue) -> Res {
    let type_name = string_arg(args, 0, "the message type")?;
    let ty = message_type(&type_name)?;
    Ok(vec![to_lua(lua, &ty.default_value())?])
}

fn time_arg(args: &MultiValue, i: usize) -> Result<f64, RosError> {
    match arg(args, i) {
        Some(LuaValue::Integer(n)) => Ok(*n as f64),
        Some(LuaValue::Number(n)) => Ok(*n),
        Some(LuaValue::Table(t)) => {
            let sec: f64 = t.get::<Option<f64>>("sec").ok().flatten().unwrap_or(0.0);
            let ns: f64 = t.get::<Option<f64>>("nanosec").ok().flatten().unwrap_or(0.0);
            Ok(sec + ns * 1e-9)
        }
        Some(v) => Err(RosError::Expected {
            arg: i + 1,
            expected: "a time",
            got: lua_type(v).to_owned(),
        }),
        None => Err(missing(i, "the time")),
    }
}

/// Whether a script's source calls ROS 1's plugin (`simROS.`, not `simROS2.`): its
/// load gives the notice below.
pub(crate) fn uses_ros1(source: &str) -> bool {
    source.contains("simROS.") || source.contains("'simROS'") || source.contains("\"simROS\"")
}

/// Logs, once per Lua state, that ROS 1 calls go to the ROS 2 graph.
pub(crate) fn notice_ros1(lua: &Lua) {
    let host = state::<RosHost>(lua);
    if !host.ros1_noticed.replace(true) {
        tracing::warn!(
            "simROS: ROS 1 is end-of-life; gantry serves this script's simROS calls on the ROS 2 graph \
             (types such as geometry_msgs/Twist become geometry_msgs/msg/Twist)"
        );
    }
}

pub(super) fn shutdown_publisher(lua: &Lua, a: &MultiValue) -> Res {
    shutdown(lua, a, "a publisher", |k| matches!(k, Kind::Publisher { .. }))
}

pub(super) fn shutdown_subscription(lua: &Lua, a: &MultiValue) -> Res {
    shutdown(lua, a, "a subscription", |k| matches!(k, Kind::Subscription { .. }))
}

pub(super) fn shutdown_service(lua: &Lua, a: &MultiValue) -> Res {
    shutdown(lua, a, "a service", |k| matches!(k, Kind::Service { .. }))
}

pub(super) fn shutdown_client(lua: &Lua, a: &MultiValue) -> Res {
    shutdown(lua, a, "a client", |k| matches!(k, Kind::Client { .. }))
}

// "a action server" and "a action client": the text scripts have seen since these
// functions came (other calls say "an action server"); kept as it was.
pub(super) fn shutdown_action_server(lua: &Lua, a: &MultiValue) -> Res {
    shutdown(lua, a, "a action server", |k| matches!(k, Kind::ActionServer(_)))
}

pub(super) fn shutdown_action_client(lua: &Lua, a: &MultiValue) -> Res {
    shutdown(lua, a, "a action client", |k| matches!(k, Kind::ActionClient(_)))
}

pub(super) fn send_transform(lua: &Lua, a: &MultiValue) -> Res {
    let t = table_value(a, 0, "the transform")?;
    send_transforms(lua, vec![t])
}

pub(super) fn send_transform_list(lua: &Lua, a: &MultiValue) -> Res {
    match table_value(a, 0, "the transforms")? {
        Value::Array(ts) => send_transforms(lua, ts),
        Value::Map(m) if m.is_empty() => send_transforms(lua, Vec::new()),
        _ => Err(RosError::TransformsNotAnArray),
    }
}

/// `uint8[]` fields are always Lua strings here: the `...TreatUInt8ArrayAsString`
/// switches check their handle and change nothing.
pub(super) fn treat_uint8_array_as_string(_: &Lua, a: &MultiValue) -> Res {
    handle_arg(a, 0)?;
    Ok(vec![])
}

/// gantry's ROS clock is the simulation's (`/clock`): stamps agree with `use_sim_time`
/// nodes.
pub(super) fn ros_time(lua: &Lua, _: &MultiValue) -> Res {
    Ok(vec![time_lua(lua, sim_time(lua))?])
}

pub(super) fn system_time(lua: &Lua, _: &MultiValue) -> Res {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64());
    Ok(vec![time_lua(lua, now)?])
}

pub(super) fn time_from_float(lua: &Lua, a: &MultiValue) -> Res {
    let t = time_arg(a, 0)?;
    Ok(vec![time_lua(lua, t)?])
}

pub(super) fn time_to_float(_: &Lua, a: &MultiValue) -> Res {
    Ok(vec![LuaValue::Number(time_arg(a, 0)?)])
}

/// ROS 1's plugin returned time as a number of seconds.
pub(super) fn ros1_time(lua: &Lua, _: &MultiValue) -> Res {
    Ok(vec![LuaValue::Number(sim_time(lua))])
}
