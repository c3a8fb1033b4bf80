//! Delivers what the ROS 2 graph sent to the scripts' `simROS2` callbacks: once per
//! step, before actuation, on the simulation thread, in the script that opened the
//! subscription or service (never from a network thread). A service's callback returns
//! its response, which is sent back at once.

use std::borrow::Cow;

use gantry_protocol::Value;
use gantry_protocol::ros::SrvType;
use gantry_sim_core::Handle;
use mlua::{Function, MultiValue, Value as LuaValue};

use crate::app_state::state;
use crate::convert::{to_lua, to_value};
use crate::host::LuaHost;
use crate::ros::EndpointId;
use crate::ros::callback::Callback;
use crate::ros::host::{Kind, RosHost};
use crate::ros::wire::{read_header, request_header};
use crate::scripts::ScriptState;

/// Messages delivered per subscription and step, at most: a flood waits for the next
/// steps (and the inbox's depth drops the oldest) instead of stalling one step.
pub const MAX_PER_STEP: usize = 256;

/// Where a service callback's response goes.
struct Reply {
    replies: EndpointId,
    header: (u64, i64),
    ty: &'static SrvType,
}

/// One callback to call.
struct Delivery {
    script: Option<Handle>,
    callback: mlua::Result<Resolved>,
    message: Value,
    reply: Option<Reply>,
}

impl LuaHost {
    /// Calls the callbacks of every message and request received (see the module docs).
    pub(crate) fn dispatch_ros(&mut self) {
        let deliveries = {
            let host = state::<RosHost>(&self.lua);
            if host.endpoints.borrow().is_empty() {
                return;
            }
            let Ok(net) = host.network() else { return };
            let mut out = Vec::new();
            for e in host.endpoints.borrow().values() {
                let (id, callback) = match &e.kind {
                    Kind::Subscription { id, callback, .. } => (*id, callback),
                    Kind::Service { requests, callback, .. } => (*requests, callback),
                    _ => continue,
                };
                let samples = net.take(id, MAX_PER_STEP);
                for s in samples {
                    let decoded = match &e.kind {
                        Kind::Subscription { ty, warned, .. } => match ty.decode_body(&s.body, s.little_endian, 0) {
                            Ok(v) => Some((v, None)),
                            Err(err) => {
                                if !warned.replace(true) {
                                    tracing::warn!("simROS2: dropped a malformed {} message: {err}", ty.name());
                                }
                                None
                            }
                        },
                        Kind::Service { replies, ty, .. } => {
                            let header = read_header(&s.body, s.little_endian);
                            match (header, ty.request().decode_body(&s.body, s.little_endian, 16)) {
                                (Some(header), Ok(v)) => Some((
                                    v,
                                    Some(Reply {
                                        replies: *replies,
                                        header,
                                        ty,
                                    }),
                                )),
                                (_, Err(err)) => {
                                    tracing::warn!("simROS2: dropped a malformed {} request: {err}", ty.name());
                                    None
                                }
                                (None, _) => None,
                            }
                        }
                        _ => None,
                    };
                    let Some((message, reply)) = decoded else { continue };
                    let callback = resolve(&self.lua, callback);
                    out.push(Delivery {
                        script: e.script,
                        callback,
                        message,
                        reply,
                    });
                }
            }
            out
        };
        for d in deliveries {
            self.deliver(d);
        }
        self.dispatch_ros_actions();
    }

    fn deliver(&mut self, d: Delivery) {
        let Some((response, name)) = self.call_ros_callback(d.script, d.callback, &[d.message]) else {
            return;
        };
        let Some(reply) = d.reply else { return };
        let value = match to_value(&response) {
            Ok(Value::Nil) => Value::Map(Vec::new()),
            Ok(v) => v,
            Err(e) => {
                self.core.log(
                    200,
                    &name,
                    &format!("simROS2: the service response is not a table: {e}"),
                );
                return;
            }
        };
        let mut body = request_header(reply.header.0, reply.header.1);
        if let Err(e) = reply.ty.response().encode_into(&value, &mut body, 0) {
            self.core
                .log(200, &name, &format!("simROS2: the service response is not valid: {e}"));
            return;
        }
        let host = state::<RosHost>(&self.lua);
        if let Err(e) = host.network().and_then(|n| n.write(reply.replies, body)) {
            self.core
                .log(200, &name, &format!("simROS2: the reply was not sent: {e}"));
        }
    }

    /// Calls a `simROS2` callback (as [`resolve`] found it) in the running script of
    /// object `script` with `args`; its first return value and the script's name. `None`
    /// when the script is gone or stopped, the callback is not a function (logged), or
    /// the call failed (the script fails, as from any hook).
    pub(crate) fn call_ros_callback(
        &mut self,
        script: Option<Handle>,
        callback: mlua::Result<Resolved>,
        args: &[Value],
    ) -> Option<(LuaValue, String)> {
        let scripts = &mut self.scripts;
        let i = scripts
            .list
            .iter()
            .position(|s| Some(s.object) == script && s.state == ScriptState::Running)?;
        let name = scripts.list[i].name.clone();
        let (f, label) = match callback {
            Ok(Resolved::Function(f)) => (f, "ROS callback".to_owned()),
            Ok(Resolved::Global(fname)) => match scripts.list[i].env.get::<Option<Function>>(fname.as_str()) {
                Ok(Some(f)) => (f, fname),
                _ => {
                    let msg = format!("simROS2 callback '{fname}' is not a function of this script");
                    self.core.log(300, &name, &msg);
                    return None;
                }
            },
            Err(e) => {
                self.core.log(300, &name, &format!("simROS2 callback not found: {e}"));
                return None;
            }
        };
        let mut lua_args = MultiValue::new();
        for a in args {
            match to_lua(&self.lua, a) {
                Ok(v) => lua_args.push_back(v),
                Err(e) => {
                    self.core.log(200, &name, &format!("simROS2: message dropped: {e}"));
                    return None;
                }
            }
        }
        scripts.enter(i, Cow::Owned(label));
        let r = scripts.call_script::<LuaValue>(&f, lua_args);
        scripts.leave();
        match r {
            Ok(v) => Some((v, name.to_string())),
            Err(e) => {
                scripts.fail(i, e);
                None
            }
        }
    }
}

/// A [`Callback`] ready to call once the endpoints are no longer borrowed.
#[derive(Clone)]
pub(crate) enum Resolved {
    /// The function, taken from the registry.
    Function(Function),
    /// The name of a global of the owning script, looked up when called.
    Global(String),
}

/// What `callback` calls; an error only if its registry entry cannot be read.
pub(crate) fn resolve(lua: &mlua::Lua, callback: &Callback) -> mlua::Result<Resolved> {
    Ok(match callback {
        Callback::Function(key) => Resolved::Function(lua.registry_value::<Function>(key)?),
        Callback::Name(n) => Resolved::Global(n.clone()),
    })
}
