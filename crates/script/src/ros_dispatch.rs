//! Delivers what the ROS 2 graph sent to the scripts' `simROS2` callbacks: once per
//! step, before actuation, on the simulation thread, in the script that opened the
//! subscription or service (never from a network thread). A service's callback returns
//! its response, which is sent back at once.

use std::borrow::Cow;

use gantry_protocol::Value;
use gantry_protocol::ros::SrvType;
use gantry_sim_core::Handle;
use mlua::{Function, Value as LuaValue};

use crate::app_state::state;
use crate::convert::{to_lua, to_value};
use crate::ros::EndpointId;
use crate::ros::host::{Callback, Kind, RosHost};
use crate::ros::lua_api::{read_header, request_header};
use crate::scripts::ScriptState;
use crate::simulation::Simulation;

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
    callback: Result<Function, String>,
    message: Value,
    reply: Option<Reply>,
}

impl Simulation {
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
                    let callback = match callback {
                        Callback::Function(key) => self.lua.registry_value::<Function>(key).map_err(|e| e.to_string()),
                        Callback::Name(n) => Err(n.clone()),
                    };
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
    }

    fn deliver(&mut self, d: Delivery) {
        let scripts = &mut self.scripts;
        let Some(i) = scripts
            .list
            .iter()
            .position(|s| Some(s.object) == d.script && s.state == ScriptState::Running)
        else {
            return;
        };
        let name = scripts.list[i].name.clone();
        let (f, label) = match d.callback {
            Ok(f) => (f, "ROS callback".to_owned()),
            Err(fname) => match scripts.list[i].env.get::<Option<Function>>(fname.as_str()) {
                Ok(Some(f)) => (f, fname),
                _ => {
                    let msg = format!("simROS2 callback '{fname}' is not a function of this script");
                    self.core.log(300, &name, &msg);
                    return;
                }
            },
        };
        let arg = match to_lua(&self.lua, &d.message) {
            Ok(a) => a,
            Err(e) => {
                self.core.log(200, &name, &format!("simROS2: message dropped: {e}"));
                return;
            }
        };
        scripts.enter(i, Cow::Owned(label));
        let r = scripts.call_script::<LuaValue>(&f, arg);
        scripts.leave();
        let response = match r {
            Ok(v) => v,
            Err(e) => {
                scripts.fail(i, e);
                return;
            }
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
}
