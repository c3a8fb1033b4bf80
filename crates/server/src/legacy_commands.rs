//! What each legacy remote API command does: a thin converter from the `simx*` command
//! codes and their binary arguments to the registry's `sim.*` functions, and from their
//! results to the binary replies the client library reads. Nothing here acts on the
//! world itself: every command is one or more [`SimHandle`] requests.
//!
//! Layouts follow the client library: integers and floats are little-endian 32-bit,
//! strings NUL-terminated; a reply repeats the command's identifying data (the transport
//! does that) and carries the results as its pure data. A command that fails on the
//! server side replies with status bit 0 set, which the client reports as
//! `simx_return_remote_error_flag`; the reason is kept for `simxGetLastErrors`.
//! Commands gantry does not serve (the old 2D UIs, file transfer, dialogs' results)
//! fail that way, with a message naming them.

use std::path::PathBuf;

use gantry_engine::{ClientId, RemoteOp};
use gantry_protocol::legacy_remote_api::{Command, CommandId};
use gantry_sim_core::Value;
use gantry_sim_core::sim::Control;
use tokio::sync::oneshot;

use crate::sim_thread::{Request, SendError, SimHandle};

/// Most error messages kept for `simxGetLastErrors` between two calls.
const MAX_ERRORS: usize = 64;

/// Command codes (the client library's `simx_cmd_*`), by range.
mod code {
    pub const SYNCHRONOUS_ENABLE: i32 = 0x0001;
    pub const SYNCHRONOUS_DISABLE: i32 = 0x0002;
    pub const SYNCHRONOUS_NEXT: i32 = 0x0003;
    pub const GET_LAST_ERRORS: i32 = 0x0004;
    pub const CLOSE_SCENE: i32 = 0x0005;
    pub const GET_OBJECT_SELECTION: i32 = 0x0006;
    pub const CREATE_DUMMY: i32 = 0x0009;
    pub const KILL_CONNECTION: i32 = 0x000a;

    pub const GET_JOINT_POSITION: i32 = 0x1001;
    pub const SET_JOINT_POSITION: i32 = 0x1002;
    pub const GET_VISION_SENSOR_IMAGE_BW: i32 = 0x1003;
    pub const GET_VISION_SENSOR_IMAGE_RGB: i32 = 0x1004;
    pub const SET_VISION_SENSOR_IMAGE_BW: i32 = 0x1005;
    pub const SET_VISION_SENSOR_IMAGE_RGB: i32 = 0x1006;
    pub const START_PAUSE_STOP_SIMULATION: i32 = 0x1007;
    pub const SET_JOINT_TARGET_VELOCITY: i32 = 0x1008;
    pub const READ_PROXIMITY_SENSOR: i32 = 0x1009;
    pub const SET_JOINT_TARGET_POSITION: i32 = 0x100c;
    pub const GET_JOINT_FORCE: i32 = 0x100d;
    pub const SET_JOINT_FORCE: i32 = 0x100e;
    pub const READ_FORCE_SENSOR: i32 = 0x100f;
    pub const READ_VISION_SENSOR: i32 = 0x1011;
    pub const GET_OBJECT_PARENT: i32 = 0x1012;
    pub const AUX_CONSOLE_CLOSE: i32 = 0x1014;
    pub const AUX_CONSOLE_PRINT: i32 = 0x1015;
    pub const AUX_CONSOLE_SHOW: i32 = 0x1016;
    pub const GET_VISION_SENSOR_DEPTH_BUFFER: i32 = 0x1017;
    pub const GET_OBJECT_ORIENTATION: i32 = 0x1018;
    pub const GET_OBJECT_POSITION: i32 = 0x1019;
    pub const SET_OBJECT_ORIENTATION: i32 = 0x101a;
    pub const SET_OBJECT_POSITION: i32 = 0x101b;
    pub const SET_OBJECT_PARENT: i32 = 0x101c;
    pub const GET_BOOLEAN_PARAMETER: i32 = 0x101f;
    pub const SET_BOOLEAN_PARAMETER: i32 = 0x1020;
    pub const GET_INTEGER_PARAMETER: i32 = 0x1021;
    pub const SET_INTEGER_PARAMETER: i32 = 0x1022;
    pub const GET_FLOATING_PARAMETER: i32 = 0x1023;
    pub const SET_FLOATING_PARAMETER: i32 = 0x1024;
    pub const REMOVE_OBJECT: i32 = 0x1028;
    pub const GET_OBJECTS: i32 = 0x102a;
    pub const SET_OBJECT_SELECTION: i32 = 0x102f;
    pub const GET_OBJECT_VELOCITY: i32 = 0x1036;
    pub const GET_JOINT_MAX_FORCE: i32 = 0x1038;
    pub const SET_OBJECT_QUATERNION: i32 = 0x1801;

    pub const GET_OBJECT_FLOAT_PARAMETER: i32 = 0x2007;
    pub const GET_OBJECT_INT_PARAMETER: i32 = 0x2008;
    pub const SET_OBJECT_FLOAT_PARAMETER: i32 = 0x2009;
    pub const SET_OBJECT_INT_PARAMETER: i32 = 0x200a;
    pub const GET_OBJECT_CHILD: i32 = 0x200b;
    pub const GET_OBJECT_ORIENTATION2: i32 = 0x200d;
    pub const GET_OBJECT_POSITION2: i32 = 0x200e;
    pub const CHECK_COLLISION: i32 = 0x200f;
    pub const GET_OBJECT_QUATERNION: i32 = 0x2801;

    pub const GET_OBJECT_HANDLE: i32 = 0x3001;
    pub const LOAD_SCENE: i32 = 0x3002;
    pub const LOAD_MODEL: i32 = 0x3003;
    pub const ADD_STATUSBAR_MESSAGE: i32 = 0x3008;
    pub const AUX_CONSOLE_OPEN: i32 = 0x3009;
    pub const CLEAR_FLOAT_SIGNAL: i32 = 0x300d;
    pub const CLEAR_INTEGER_SIGNAL: i32 = 0x300e;
    pub const CLEAR_STRING_SIGNAL: i32 = 0x300f;
    pub const GET_FLOAT_SIGNAL: i32 = 0x3010;
    pub const GET_INTEGER_SIGNAL: i32 = 0x3011;
    pub const GET_STRING_SIGNAL: i32 = 0x3012;
    pub const SET_FLOAT_SIGNAL: i32 = 0x3013;
    pub const SET_INTEGER_SIGNAL: i32 = 0x3014;
    pub const SET_STRING_SIGNAL: i32 = 0x3015;
    pub const APPEND_STRING_SIGNAL: i32 = 0x3016;
    pub const GET_AND_CLEAR_STRING_SIGNAL: i32 = 0x3017;
    pub const READ_STRING_STREAM: i32 = 0x3018;

    pub const CALL_SCRIPT_FUNCTION: i32 = 0x3401;
}

/// A client's state across its commands.
pub struct Session {
    client: ClientId,
    synchronous: bool,
    killed: bool,
    errors: Vec<String>,
    scene_id: u16,
}

/// What a command gave.
pub struct Outcome {
    /// It succeeded (status bit 0 clear).
    pub ok: bool,
    /// The reply's pure data.
    pub data: Vec<u8>,
    /// A streaming command that must not run again (CoppeliaSim's
    /// `simxGetAndClearStringSignal` stops streaming once it found the signal).
    pub ends_stream: bool,
}

impl Session {
    /// A new client's session.
    pub fn new(client: ClientId) -> Self {
        Self {
            client,
            synchronous: false,
            killed: false,
            errors: Vec::new(),
            scene_id: 0,
        }
    }

    /// Whether the client asked to close the connection (`simxFinish`).
    pub fn killed(&self) -> bool {
        self.killed
    }

    /// Changes when a command loaded another scene, so clients can notice.
    pub fn scene_id(&self) -> u16 {
        self.scene_id
    }

    /// The header's server state bits (0: not stopped, 1: paused) and the simulation
    /// time in ms (0 while stopped), as the reply's commands carry it.
    pub async fn clock(&mut self, sim: &SimHandle) -> (u8, i32) {
        let state = sim.call("getSimulationState", vec![]).await;
        let state = as_i32(state.as_ref().ok().and_then(|v| v.first())).unwrap_or(0);
        if state == 0 {
            return (0, 0);
        }
        let time = sim.call("getSimulationTime", vec![]).await;
        let t = time.ok().and_then(|v| v.first().and_then(Value::as_f64)).unwrap_or(0.0);
        let bits = if state == 8 { 0b11 } else { 0b01 };
        (bits, (t * 1000.0).round().clamp(0.0, f64::from(i32::MAX)) as i32)
    }

    fn fail(&mut self, cmd: &Command, why: impl Into<String>) -> Outcome {
        let why = why.into();
        tracing::debug!("legacy remote API command 0x{:04x}: {why}", cmd.code);
        if self.errors.len() < MAX_ERRORS {
            self.errors.push(why);
        }
        Outcome {
            ok: false,
            data: Vec::new(),
            ends_stream: false,
        }
    }
}

/// One integer result, as most commands read it from the registry's reply.
fn as_i32(v: Option<&Value>) -> Option<i32> {
    v.and_then(Value::as_i64).and_then(|i| i32::try_from(i).ok())
}

fn ok(data: Vec<u8>) -> Outcome {
    Outcome {
        ok: true,
        data,
        ends_stream: false,
    }
}

/// Little-endian readers of a command's arguments.
struct Data<'a>(&'a [u8]);

impl Data<'_> {
    fn i32(&self, at: usize) -> Result<i32, String> {
        self.0
            .get(at..at + 4)
            .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("arguments too short: no integer at byte {at}"))
    }
    fn f32(&self, at: usize) -> Result<f64, String> {
        self.0
            .get(at..at + 4)
            .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
            .ok_or_else(|| format!("arguments too short: no float at byte {at}"))
    }
    fn f32s(&self, at: usize, n: usize) -> Result<Vec<Value>, String> {
        (0..n).map(|i| self.f32(at + 4 * i).map(Value::Float)).collect()
    }
    /// The NUL-terminated string at `at` and the offset after its NUL.
    fn string(&self, at: usize) -> Result<(String, usize), String> {
        let rest = self.0.get(at..).unwrap_or_default();
        let end = rest
            .iter()
            .position(|&c| c == 0)
            .ok_or_else(|| format!("arguments too short: no string at byte {at}"))?;
        Ok((String::from_utf8_lossy(&rest[..end]).into_owned(), at + end + 1))
    }
}

fn put_f32s(out: &mut Vec<u8>, values: &[Value]) -> Result<(), String> {
    for v in values {
        let f = v
            .as_f64()
            .ok_or_else(|| format!("expected a number, got {}", v.type_name()))?;
        out.extend_from_slice(&(f as f32).to_le_bytes());
    }
    Ok(())
}

fn numbers(v: Option<&Value>) -> Result<Vec<Value>, String> {
    match v {
        Some(Value::Array(a)) => Ok(a.clone()),
        other => Err(format!(
            "expected a table of numbers, got {}",
            other.map_or("nothing", Value::type_name)
        )),
    }
}

fn floats_reply(values: &[Value]) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(values.len() * 4);
    put_f32s(&mut out, values)?;
    Ok(out)
}

fn int_reply(v: Option<&Value>) -> Result<Vec<u8>, String> {
    let i = as_i32(v).ok_or("expected an integer result")?;
    Ok(i.to_le_bytes().to_vec())
}

fn float_reply(v: Option<&Value>) -> Result<Vec<u8>, String> {
    let f = v.and_then(Value::as_f64).ok_or("expected a number result")?;
    Ok((f as f32).to_le_bytes().to_vec())
}

fn id_int(cmd: &Command) -> i32 {
    match &cmd.id {
        CommandId::Int(a) | CommandId::IntInt(a, _) | CommandId::IntStrStr(a, ..) => *a,
        _ => 0,
    }
}

fn id_int2(cmd: &Command) -> i32 {
    match &cmd.id {
        CommandId::IntInt(_, b) => *b,
        _ => 0,
    }
}

fn id_str(cmd: &Command) -> String {
    match &cmd.id {
        CommandId::Str(s) => String::from_utf8_lossy(s).into_owned(),
        _ => String::new(),
    }
}

async fn call(sim: &SimHandle, name: &str, args: Vec<Value>) -> Result<Vec<Value>, String> {
    sim.call(name, args).await
}

async fn remote(sim: &SimHandle, client: ClientId, op: RemoteOp) -> Result<Vec<Value>, String> {
    let (reply, rx) = oneshot::channel();
    sim.send(Request::Remote { client, op, reply })
        .map_err(|e| e.to_string())?;
    rx.await
        .map_err(|_| SendError::Closed.to_string())?
        .map_err(|e| e.to_string())
}

/// Runs one command for the session's client.
pub async fn execute(sim: &SimHandle, session: &mut Session, cmd: &Command) -> Outcome {
    match run(sim, session, cmd).await {
        Ok(o) => o,
        Err(why) => session.fail(cmd, why),
    }
}

async fn run(sim: &SimHandle, session: &mut Session, cmd: &Command) -> Result<Outcome, String> {
    use code::*;
    let d = Data(&cmd.data);
    let h = Value::Int(i64::from(id_int(cmd)));
    let data = match cmd.code {
        SYNCHRONOUS_ENABLE | SYNCHRONOUS_DISABLE => {
            let enable = cmd.code == SYNCHRONOUS_ENABLE;
            // One level per client, however often it asks.
            if enable != session.synchronous {
                remote(sim, session.client, RemoteOp::SetStepping(enable)).await?;
                session.synchronous = enable;
            }
            Vec::new()
        }
        SYNCHRONOUS_NEXT => {
            if !session.synchronous {
                return Err("simxSynchronousTrigger: the client is not in synchronous mode".into());
            }
            let running = call(sim, "getSimulationState", vec![]).await?;
            if as_i32(running.first()).is_none_or(|s| s == 0 || s == 8) {
                return Err("simxSynchronousTrigger: the simulation is not running".into());
            }
            let (done, rx) = oneshot::channel();
            sim.send(Request::Step {
                client: session.client,
                done,
            })
            .map_err(|e| e.to_string())?;
            // Answered once the step is done, so the client's next command sees it.
            rx.await
                .map_err(|_| "the simulation stopped before the step".to_owned())?;
            Vec::new()
        }
        GET_LAST_ERRORS => {
            let errors = std::mem::take(&mut session.errors);
            let mut out = (errors.len() as i32).to_le_bytes().to_vec();
            for e in errors {
                out.extend(e.bytes().filter(|&b| b != 0));
                out.push(0);
            }
            // Reading them is not itself an error to report.
            return Ok(ok(out));
        }
        CLOSE_SCENE => {
            load_scene(sim, None).await?;
            session.scene_id = session.scene_id.wrapping_add(1);
            Vec::new()
        }
        GET_OBJECT_SELECTION => {
            let sel = call(sim, "getObjectSel", vec![]).await?;
            let handles = numbers(sel.first())?;
            let mut out = (handles.len() as i32).to_le_bytes().to_vec();
            for v in &handles {
                out.extend_from_slice(&as_i32(Some(v)).unwrap_or(-1).to_le_bytes());
            }
            out
        }
        CREATE_DUMMY => int_reply(call(sim, "createDummy", vec![Value::Float(d.f32(0)?)]).await?.first())?,
        KILL_CONNECTION => {
            session.killed = true;
            Vec::new()
        }
        GET_JOINT_POSITION => float_reply(call(sim, "getJointPosition", vec![h]).await?.first())?,
        SET_JOINT_POSITION => {
            call(sim, "setJointPosition", vec![h, Value::Float(d.f32(0)?)]).await?;
            Vec::new()
        }
        SET_JOINT_TARGET_VELOCITY => {
            call(sim, "setJointTargetVelocity", vec![h, Value::Float(d.f32(0)?)]).await?;
            Vec::new()
        }
        SET_JOINT_TARGET_POSITION => {
            call(sim, "setJointTargetPosition", vec![h, Value::Float(d.f32(0)?)]).await?;
            Vec::new()
        }
        GET_JOINT_FORCE => float_reply(call(sim, "getJointForce", vec![h]).await?.first())?,
        SET_JOINT_FORCE => {
            call(sim, "setJointMaxForce", vec![h, Value::Float(d.f32(0)?)]).await?;
            Vec::new()
        }
        GET_JOINT_MAX_FORCE => float_reply(call(sim, "getJointMaxForce", vec![h]).await?.first())?,
        GET_VISION_SENSOR_IMAGE_BW | GET_VISION_SENSOR_IMAGE_RGB => {
            let r = call(sim, "getVisionSensorImg", vec![h]).await?;
            let (Some(Value::Bytes(img)), Some(res)) = (r.first(), r.get(1)) else {
                return Err("no image".into());
            };
            let res = numbers(Some(res))?;
            let (x, y) = (as_i32(res.first()).unwrap_or(0), as_i32(res.get(1)).unwrap_or(0));
            let mut out = x.to_le_bytes().to_vec();
            out.extend_from_slice(&y.to_le_bytes());
            if cmd.code == GET_VISION_SENSOR_IMAGE_RGB {
                out.extend_from_slice(img);
            } else {
                // Grey as CoppeliaSim computes it: the mean of the three channels.
                out.extend(
                    img.chunks_exact(3)
                        .map(|p| ((u16::from(p[0]) + u16::from(p[1]) + u16::from(p[2])) / 3) as u8),
                );
            }
            out
        }
        SET_VISION_SENSOR_IMAGE_BW | SET_VISION_SENSOR_IMAGE_RGB => {
            let img = if cmd.code == SET_VISION_SENSOR_IMAGE_RGB {
                cmd.data.clone()
            } else {
                cmd.data.iter().flat_map(|&g| [g, g, g]).collect()
            };
            call(sim, "setVisionSensorImg", vec![h, Value::Bytes(img)]).await?;
            Vec::new()
        }
        GET_VISION_SENSOR_DEPTH_BUFFER => {
            let r = call(sim, "getVisionSensorDepth", vec![h]).await?;
            let (Some(Value::Bytes(depth)), Some(res)) = (r.first(), r.get(1)) else {
                return Err("no depth buffer".into());
            };
            let res = numbers(Some(res))?;
            let mut out = as_i32(res.first()).unwrap_or(0).to_le_bytes().to_vec();
            out.extend_from_slice(&as_i32(res.get(1)).unwrap_or(0).to_le_bytes());
            out.extend_from_slice(depth);
            out
        }
        START_PAUSE_STOP_SIMULATION => {
            let control = match id_int(cmd) {
                0 => Control::Start,
                1 => Control::Pause,
                2 => Control::Stop,
                other => return Err(format!("unknown simulation command {other}")),
            };
            remote(sim, session.client, RemoteOp::Control(control)).await?;
            Vec::new()
        }
        READ_PROXIMITY_SENSOR => {
            let r = call(sim, "readProximitySensor", vec![h]).await?;
            let detected = as_i32(r.first()).unwrap_or(0);
            let point = r.get(2).map(|p| numbers(Some(p))).transpose()?.unwrap_or_default();
            let normal = r.get(4).map(|p| numbers(Some(p))).transpose()?.unwrap_or_default();
            let mut out = vec![u8::from(detected > 0)];
            put_f32s(&mut out, &pad3(point))?;
            out.extend_from_slice(&as_i32(r.get(3)).unwrap_or(-1).to_le_bytes());
            put_f32s(&mut out, &pad3(normal))?;
            out
        }
        READ_FORCE_SENSOR => {
            let r = call(sim, "readForceSensor", vec![h]).await?;
            let mut out = vec![as_i32(r.first()).unwrap_or(0).clamp(0, 255) as u8];
            put_f32s(&mut out, &pad3(numbers(r.get(1)).unwrap_or_default()))?;
            put_f32s(&mut out, &pad3(numbers(r.get(2)).unwrap_or_default()))?;
            out
        }
        READ_VISION_SENSOR => {
            let r = call(sim, "readVisionSensor", vec![h]).await?;
            let detected = as_i32(r.first()).unwrap_or(-1);
            if detected < 0 {
                return Err("the vision sensor has no result yet".into());
            }
            let packets: Vec<Vec<Value>> = r[1..].iter().map(|p| numbers(Some(p))).collect::<Result<_, _>>()?;
            let mut out = vec![u8::from(detected > 0)];
            out.extend_from_slice(&(packets.len() as i32).to_le_bytes());
            for p in &packets {
                out.extend_from_slice(&(p.len() as i32).to_le_bytes());
            }
            for p in &packets {
                put_f32s(&mut out, p)?;
            }
            out
        }
        GET_OBJECT_PARENT => int_reply(call(sim, "getObjectParent", vec![h]).await?.first())?,
        GET_OBJECT_CHILD => int_reply(
            call(sim, "getObjectChild", vec![h, Value::Int(i64::from(id_int2(cmd)))])
                .await?
                .first(),
        )?,
        GET_OBJECT_POSITION
        | GET_OBJECT_ORIENTATION
        | GET_OBJECT_POSITION2
        | GET_OBJECT_ORIENTATION2
        | GET_OBJECT_QUATERNION => {
            // The oldest clients put the reference frame in the arguments, later ones in
            // the command's identity (so that two frames can stream side by side).
            let rel = match cmd.code {
                GET_OBJECT_POSITION | GET_OBJECT_ORIENTATION => d.i32(0)?,
                _ => id_int2(cmd),
            };
            let name = match cmd.code {
                GET_OBJECT_POSITION | GET_OBJECT_POSITION2 => "getObjectPosition",
                GET_OBJECT_QUATERNION => "getObjectQuaternion",
                _ => "getObjectOrientation",
            };
            let r = call(sim, name, vec![h, Value::Int(i64::from(rel))]).await?;
            floats_reply(&numbers(r.first())?)?
        }
        SET_OBJECT_POSITION | SET_OBJECT_ORIENTATION | SET_OBJECT_QUATERNION => {
            let (name, n) = match cmd.code {
                SET_OBJECT_POSITION => ("setObjectPosition", 3),
                SET_OBJECT_QUATERNION => ("setObjectQuaternion", 4),
                _ => ("setObjectOrientation", 3),
            };
            let rel = Value::Int(i64::from(d.i32(0)?));
            call(sim, name, vec![h, rel, Value::Array(d.f32s(4, n)?)]).await?;
            Vec::new()
        }
        SET_OBJECT_PARENT => {
            let parent = Value::Int(i64::from(d.i32(0)?));
            let keep = Value::Bool(cmd.data.get(4).copied().unwrap_or(1) != 0);
            call(sim, "setObjectParent", vec![h, parent, keep]).await?;
            Vec::new()
        }
        GET_OBJECT_VELOCITY => {
            let r = call(sim, "getObjectVelocity", vec![h]).await?;
            let mut out = floats_reply(&pad3(numbers(r.first())?))?;
            out.extend(floats_reply(&pad3(numbers(r.get(1))?))?);
            out
        }
        GET_BOOLEAN_PARAMETER => {
            let r = call(sim, "getBoolParam", vec![h]).await?;
            let b = matches!(r.first(), Some(Value::Bool(true))) || as_i32(r.first()).is_some_and(|i| i != 0);
            i32::from(b).to_le_bytes().to_vec()
        }
        SET_BOOLEAN_PARAMETER => {
            call(sim, "setBoolParam", vec![h, Value::Bool(d.i32(0)? != 0)]).await?;
            Vec::new()
        }
        GET_INTEGER_PARAMETER => int_reply(call(sim, "getInt32Param", vec![h]).await?.first())?,
        SET_INTEGER_PARAMETER => {
            call(sim, "setInt32Param", vec![h, Value::Int(i64::from(d.i32(0)?))]).await?;
            Vec::new()
        }
        GET_FLOATING_PARAMETER => float_reply(call(sim, "getFloatParam", vec![h]).await?.first())?,
        SET_FLOATING_PARAMETER => {
            call(sim, "setFloatParam", vec![h, Value::Float(d.f32(0)?)]).await?;
            Vec::new()
        }
        GET_OBJECT_FLOAT_PARAMETER => float_reply(
            call(sim, "getObjectFloatParam", vec![h, Value::Int(i64::from(id_int2(cmd)))])
                .await?
                .first(),
        )?,
        GET_OBJECT_INT_PARAMETER => int_reply(
            call(sim, "getObjectInt32Param", vec![h, Value::Int(i64::from(id_int2(cmd)))])
                .await?
                .first(),
        )?,
        SET_OBJECT_FLOAT_PARAMETER => {
            let p = Value::Int(i64::from(id_int2(cmd)));
            call(sim, "setObjectFloatParam", vec![h, p, Value::Float(d.f32(0)?)]).await?;
            Vec::new()
        }
        SET_OBJECT_INT_PARAMETER => {
            let p = Value::Int(i64::from(id_int2(cmd)));
            call(sim, "setObjectInt32Param", vec![h, p, Value::Int(i64::from(d.i32(0)?))]).await?;
            Vec::new()
        }
        CHECK_COLLISION => {
            let other = Value::Int(i64::from(id_int2(cmd)));
            int_reply(call(sim, "checkCollision", vec![h, other]).await?.first())?
        }
        REMOVE_OBJECT => {
            call(sim, "removeObject", vec![h]).await?;
            Vec::new()
        }
        GET_OBJECTS => {
            // sim.getObjects(index, type) until it answers -1, as the server does.
            let mut handles = Vec::new();
            for i in 0..100_000i64 {
                let r = call(sim, "getObjects", vec![Value::Int(i), h.clone()]).await?;
                match as_i32(r.first()) {
                    Some(x) if x >= 0 => handles.push(x),
                    _ => break,
                }
            }
            let mut out = (handles.len() as i32).to_le_bytes().to_vec();
            handles.iter().for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
            out
        }
        SET_OBJECT_SELECTION => {
            let handles = (0..cmd.data.len() / 4)
                .map(|i| d.i32(4 * i).map(|x| Value::Int(i64::from(x))))
                .collect::<Result<Vec<_>, _>>()?;
            call(sim, "setObjectSel", vec![Value::Array(handles)]).await?;
            Vec::new()
        }
        AUX_CONSOLE_OPEN => {
            let title = Value::Str(id_str(cmd));
            let r = call(
                sim,
                "auxiliaryConsoleOpen",
                vec![
                    title,
                    Value::Int(i64::from(d.i32(0)?)),
                    Value::Int(i64::from(d.i32(4)?)),
                ],
            )
            .await?;
            int_reply(r.first())?
        }
        AUX_CONSOLE_PRINT => {
            let text = match cmd.data.is_empty() {
                true => Value::Nil,
                false => Value::Str(d.string(0)?.0),
            };
            call(sim, "auxiliaryConsolePrint", vec![h, text]).await?;
            Vec::new()
        }
        AUX_CONSOLE_CLOSE => {
            call(sim, "auxiliaryConsoleClose", vec![h]).await?;
            Vec::new()
        }
        AUX_CONSOLE_SHOW => {
            call(sim, "auxiliaryConsoleShow", vec![h, Value::Bool(d.i32(0)? != 0)]).await?;
            Vec::new()
        }
        GET_OBJECT_HANDLE => {
            // The 4.0-4.2 lookup by name (`name#n`, `@silentError` as in CoppeliaSim).
            let r = call(sim, "getObjectHandle", vec![Value::Str(id_str(cmd))]).await?;
            match as_i32(r.first()) {
                Some(x) if x >= 0 => x.to_le_bytes().to_vec(),
                _ => return Err(format!("object '{}' does not exist", id_str(cmd))),
            }
        }
        LOAD_SCENE => {
            if cmd.data.first().is_some_and(|&o| o & 1 != 0) {
                return Err("simxLoadScene: client-side files cannot be sent; name a file the server can read".into());
            }
            load_scene(sim, Some(PathBuf::from(id_str(cmd)))).await?;
            session.scene_id = session.scene_id.wrapping_add(1);
            Vec::new()
        }
        LOAD_MODEL => {
            if cmd.data.first().is_some_and(|&o| o & 1 != 0) {
                return Err("simxLoadModel: client-side files cannot be sent; name a file the server can read".into());
            }
            int_reply(call(sim, "loadModel", vec![Value::Str(id_str(cmd))]).await?.first())?
        }
        ADD_STATUSBAR_MESSAGE => {
            call(sim, "addStatusbarMessage", vec![Value::Str(id_str(cmd))]).await?;
            Vec::new()
        }
        CLEAR_FLOAT_SIGNAL | CLEAR_INTEGER_SIGNAL | CLEAR_STRING_SIGNAL => {
            let name = match cmd.code {
                CLEAR_FLOAT_SIGNAL => "clearFloatSignal",
                CLEAR_INTEGER_SIGNAL => "clearInt32Signal",
                _ => "clearStringSignal",
            };
            call(sim, name, vec![Value::Str(id_str(cmd))]).await?;
            Vec::new()
        }
        GET_FLOAT_SIGNAL => match call(sim, "getFloatSignal", vec![Value::Str(id_str(cmd))])
            .await?
            .first()
        {
            Some(Value::Nil) | None => return Err(format!("no float signal '{}'", id_str(cmd))),
            v => float_reply(v)?,
        },
        GET_INTEGER_SIGNAL => match call(sim, "getInt32Signal", vec![Value::Str(id_str(cmd))])
            .await?
            .first()
        {
            Some(Value::Nil) | None => return Err(format!("no integer signal '{}'", id_str(cmd))),
            v => int_reply(v)?,
        },
        GET_STRING_SIGNAL | GET_AND_CLEAR_STRING_SIGNAL | READ_STRING_STREAM => {
            let name = Value::Str(id_str(cmd));
            let value = string_signal(sim, name.clone()).await?;
            match value {
                Some(bytes) => {
                    if cmd.code != GET_STRING_SIGNAL {
                        call(sim, "clearStringSignal", vec![name]).await?;
                    }
                    return Ok(Outcome {
                        ok: true,
                        data: bytes,
                        ends_stream: cmd.code == GET_AND_CLEAR_STRING_SIGNAL,
                    });
                }
                // A stream with nothing new is not an error.
                None if cmd.code == READ_STRING_STREAM => Vec::new(),
                None => return Err(format!("no string signal '{}'", id_str(cmd))),
            }
        }
        SET_FLOAT_SIGNAL => {
            call(
                sim,
                "setFloatSignal",
                vec![Value::Str(id_str(cmd)), Value::Float(d.f32(0)?)],
            )
            .await?;
            Vec::new()
        }
        SET_INTEGER_SIGNAL => {
            let v = Value::Int(i64::from(d.i32(0)?));
            call(sim, "setInt32Signal", vec![Value::Str(id_str(cmd)), v]).await?;
            Vec::new()
        }
        SET_STRING_SIGNAL | APPEND_STRING_SIGNAL => {
            let name = Value::Str(id_str(cmd));
            let mut value = match cmd.code {
                APPEND_STRING_SIGNAL => string_signal(sim, name.clone()).await?.unwrap_or_default(),
                _ => Vec::new(),
            };
            value.extend_from_slice(&cmd.data);
            call(sim, "setStringSignal", vec![name, Value::Bytes(value)]).await?;
            Vec::new()
        }
        CALL_SCRIPT_FUNCTION => call_script_function(sim, cmd).await?,
        other => {
            return Err(format!(
                "command 0x{other:04x} is not served by gantry's legacy remote API (see docs/legacy-remote-api.md)"
            ));
        }
    };
    Ok(ok(data))
}

fn pad3(mut v: Vec<Value>) -> Vec<Value> {
    v.resize(3, Value::Float(0.0));
    v
}

async fn string_signal(sim: &SimHandle, name: Value) -> Result<Option<Vec<u8>>, String> {
    Ok(
        match call(sim, "getStringSignal", vec![name]).await?.into_iter().next() {
            Some(Value::Str(s)) => Some(s.into_bytes()),
            Some(Value::Bytes(b)) => Some(b),
            _ => None,
        },
    )
}

async fn load_scene(sim: &SimHandle, path: Option<PathBuf>) -> Result<(), String> {
    let (reply, rx) = oneshot::channel();
    sim.send(Request::LoadScene { path, reply })
        .map_err(|e| e.to_string())?;
    rx.await
        .map_err(|_| SendError::Closed.to_string())?
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// `simxCallScriptFunction`: identified by the script type and the script's object
/// name (or `function@object`), with four arrays in and four out, each array's length
/// first: integers, floats, NUL-terminated strings, one buffer.
async fn call_script_function(sim: &SimHandle, cmd: &Command) -> Result<Vec<u8>, String> {
    let CommandId::IntStrStr(_, description, function) = &cmd.id else {
        return Err("malformed simxCallScriptFunction".into());
    };
    let description = String::from_utf8_lossy(description).into_owned();
    let function = String::from_utf8_lossy(function).into_owned();
    let (function, object) = match function.split_once('@') {
        Some((f, o)) => (f.to_owned(), o.to_owned()),
        None => (function, description),
    };
    if object.is_empty() {
        return Err(format!(
            "simxCallScriptFunction('{function}'): name the object whose script to call (gantry has no main script)"
        ));
    }
    let handle = call(sim, "getObjectHandle", vec![Value::Str(object.clone())]).await?;
    let handle = as_i32(handle.first())
        .filter(|&x| x >= 0)
        .ok_or_else(|| format!("no object '{object}' for simxCallScriptFunction"))?;
    let d = Data(&cmd.data);
    let counts = [d.i32(0)?, d.i32(4)?, d.i32(8)?, d.i32(12)?];
    if counts.iter().any(|&c| c < 0 || c as usize > cmd.data.len()) {
        return Err("simxCallScriptFunction: bad array sizes".into());
    }
    let [ni, nf, ns, nb] = counts.map(|c| c as usize);
    let mut at = 16;
    let ints = (0..ni)
        .map(|i| d.i32(at + 4 * i).map(|x| Value::Int(i64::from(x))))
        .collect::<Result<Vec<_>, _>>()?;
    at += 4 * ni;
    let floats = d.f32s(at, nf)?;
    at += 4 * nf;
    let mut strings = Vec::with_capacity(ns);
    for _ in 0..ns {
        let (s, next) = d.string(at)?;
        strings.push(Value::Str(s));
        at = next;
    }
    let buffer = cmd
        .data
        .get(at..at + nb)
        .ok_or("simxCallScriptFunction: buffer too short")?
        .to_vec();
    let out = call(
        sim,
        "callScriptFunction",
        vec![
            Value::Str(function),
            Value::Int(i64::from(handle)),
            Value::Array(ints),
            Value::Array(floats),
            Value::Array(strings),
            Value::Bytes(buffer),
        ],
    )
    .await?;
    // The function returns up to four values; a missing one is empty.
    let list = |i: usize| match out.get(i) {
        Some(Value::Array(a)) => a.clone(),
        _ => Vec::new(),
    };
    let (ri, rf, rs) = (list(0), list(1), list(2));
    let rb = match out.get(3) {
        Some(Value::Str(s)) => s.clone().into_bytes(),
        Some(Value::Bytes(b)) => b.clone(),
        _ => Vec::new(),
    };
    let mut reply = Vec::new();
    for n in [ri.len(), rf.len(), rs.len(), rb.len()] {
        reply.extend_from_slice(&(n as i32).to_le_bytes());
    }
    for v in &ri {
        let x = v.as_f64().ok_or("returned integers must be numbers")?;
        reply.extend_from_slice(&(x as i32).to_le_bytes());
    }
    put_f32s(&mut reply, &rf)?;
    for v in &rs {
        let s = match v {
            Value::Str(s) => s.clone(),
            other => return Err(format!("returned strings must be strings, got {}", other.type_name())),
        };
        reply.extend(s.bytes().filter(|&b| b != 0));
        reply.push(0);
    }
    reply.extend_from_slice(&rb);
    Ok(reply)
}
