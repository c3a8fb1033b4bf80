//! The legacy remote API's binary layouts as the commands read and write them:
//! little-endian 32-bit integers and floats, NUL-terminated strings, and the two small
//! vocabularies the command table is written in, [`Arg`] (where a registry argument
//! comes from) and [`Reply`] (how a registry result becomes reply data).

use gantry_protocol::legacy_remote_api::{Command, CommandId};
use gantry_sim_core::Value;
use gantry_sim_core::api::CallError;

use crate::sim_thread::{HandleCallError, SendError};

/// Why a legacy remote API command failed. The text is what `simxGetLastErrors`
/// returns to the client, so it stays as CoppeliaSim users have read it.
#[derive(Debug, thiserror::Error)]
pub(super) enum CommandError {
    /// The arguments end before the integer at this byte offset.
    #[error("arguments too short: no integer at byte {0}")]
    NoInteger(usize),
    /// The arguments end before the float at this byte offset.
    #[error("arguments too short: no float at byte {0}")]
    NoFloat(usize),
    /// No NUL-terminated string at this byte offset.
    #[error("arguments too short: no string at byte {0}")]
    NoString(usize),
    /// A registry result that should be a table of numbers (the type found).
    #[error("expected a table of numbers, got {0}")]
    NotNumbers(&'static str),
    /// A table element that should be a number (the type found).
    #[error("expected a number, got {0}")]
    NotANumber(&'static str),
    /// A registry result that should be a 32-bit integer.
    #[error("expected an integer result")]
    NoIntegerResult,
    /// A registry result that should be a number.
    #[error("expected a number result")]
    NoNumberResult,
    /// The registry function failed: its message.
    #[error(transparent)]
    Call(#[from] HandleCallError),
    /// The simulation did not take the request.
    #[error(transparent)]
    Send(#[from] SendError),
    /// The simulation thread refused a client request (stepping, control, a scene).
    #[error(transparent)]
    Remote(#[from] CallError),
    /// The simulation ended before the triggered step.
    #[error("the simulation stopped before the step")]
    StoppedBeforeStep,
    /// `simxLoadScene`/`simxLoadModel` with a file on the client's side (the function).
    #[error("{0}: client-side files cannot be sent; name a file the server can read")]
    ClientFile(&'static str),
    /// `simxGetObjectHandle` of a name no object has.
    #[error("object '{0}' does not exist")]
    NoObject(String),
    /// The vision sensor has no image.
    #[error("no image")]
    NoImage,
    /// The vision sensor has no depth buffer.
    #[error("no depth buffer")]
    NoDepthBuffer,
    /// The vision sensor has not been handled yet.
    #[error("the vision sensor has no result yet")]
    NoVisionResult,
    /// A signal that is not set.
    #[error("no {kind} signal '{name}'")]
    NoSignal {
        /// `integer`, `float` or `string`.
        kind: &'static str,
        /// The signal's name.
        name: String,
    },
    /// `simxCallScriptFunction` whose identity is not (int, string, string).
    #[error("malformed simxCallScriptFunction")]
    MalformedScriptCall,
    /// `simxCallScriptFunction` naming no object (the function).
    #[error("simxCallScriptFunction('{0}'): name the object whose script to call (gantry has no main script)")]
    NoScriptObject(String),
    /// `simxCallScriptFunction` naming an object that does not exist.
    #[error("no object '{0}' for simxCallScriptFunction")]
    NoScriptCallObject(String),
    /// `simxCallScriptFunction` with negative or impossible array sizes.
    #[error("simxCallScriptFunction: bad array sizes")]
    BadArraySizes,
    /// `simxCallScriptFunction` whose buffer argument is cut short.
    #[error("simxCallScriptFunction: buffer too short")]
    ShortBuffer,
    /// The called function returned a non-number among its integers.
    #[error("returned integers must be numbers")]
    ReturnedIntegers,
    /// The called function returned a non-string among its strings (the type found).
    #[error("returned strings must be strings, got {0}")]
    ReturnedStrings(&'static str),
    /// `simxSynchronousTrigger` from a client not in synchronous mode.
    #[error("simxSynchronousTrigger: the client is not in synchronous mode")]
    NotSynchronous,
    /// `simxSynchronousTrigger` while the simulation is stopped or paused.
    #[error("simxSynchronousTrigger: the simulation is not running")]
    NotRunning,
    /// A simulation control code other than 0, 1, 2.
    #[error("unknown simulation command {0}")]
    UnknownControl(i32),
}

/// Where one argument of a registry call comes from in a command.
#[derive(Clone, Copy, Debug)]
pub(super) enum Arg {
    /// The integer identifying the command (an object handle, mostly).
    Id,
    /// The second integer identifying the command (a reference frame, a parameter,
    /// another object): streaming keeps commands with different ones apart.
    Id2,
    /// The string identifying the command (a signal's or an object's name).
    IdStr,
    /// A 32-bit float in the arguments at this byte offset.
    F32(usize),
    /// A 32-bit integer in the arguments at this byte offset.
    I32(usize),
    /// A 32-bit integer at this byte offset, read as true when not zero.
    Flag(usize),
    /// A table of this many 32-bit floats from this byte offset.
    F32s(usize, usize),
    /// The NUL-terminated string that is the whole argument, nil when there is none.
    Text,
}

impl Arg {
    /// The registry value this argument reads from `cmd`.
    pub(super) fn read(self, cmd: &Command) -> Result<Value, CommandError> {
        let d = Data(&cmd.data);
        Ok(match self {
            Arg::Id => Value::Int(i64::from(id_int(cmd))),
            Arg::Id2 => Value::Int(i64::from(id_int2(cmd))),
            Arg::IdStr => Value::Str(id_str(cmd)),
            Arg::F32(at) => Value::Float(d.f32(at)?),
            Arg::I32(at) => Value::Int(i64::from(d.i32(at)?)),
            Arg::Flag(at) => Value::Bool(d.i32(at)? != 0),
            Arg::F32s(at, n) => Value::Array(d.f32s(at, n)?),
            Arg::Text if cmd.data.is_empty() => Value::Nil,
            Arg::Text => Value::Str(d.string(0)?.0),
        })
    }
}

/// How the first result of a registry call becomes the reply's data.
#[derive(Clone, Copy, Debug)]
pub(super) enum Reply {
    /// No data: the command only acts.
    Empty,
    /// One 32-bit integer.
    Int,
    /// One 32-bit float.
    Float,
    /// A table of numbers as 32-bit floats, without a count (the client knows it).
    Floats,
    /// A boolean (or an integer read as one) as a 32-bit 0 or 1.
    Bool,
}

impl Reply {
    /// The reply data for a registry call's results.
    pub(super) fn encode(self, results: &[Value]) -> Result<Vec<u8>, CommandError> {
        let first = results.first();
        match self {
            Reply::Empty => Ok(Vec::new()),
            Reply::Int => int_reply(first),
            Reply::Float => float_reply(first),
            Reply::Floats => floats_reply(&numbers(first)?),
            Reply::Bool => {
                let b = matches!(first, Some(Value::Bool(true))) || as_i32(first).is_some_and(|i| i != 0);
                Ok(i32::from(b).to_le_bytes().to_vec())
            }
        }
    }
}

/// Little-endian readers of a command's arguments.
pub(super) struct Data<'a>(pub(super) &'a [u8]);

impl Data<'_> {
    pub(super) fn i32(&self, at: usize) -> Result<i32, CommandError> {
        self.0
            .get(at..at + 4)
            .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or(CommandError::NoInteger(at))
    }
    pub(super) fn f32(&self, at: usize) -> Result<f64, CommandError> {
        self.0
            .get(at..at + 4)
            .map(|b| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])))
            .ok_or(CommandError::NoFloat(at))
    }
    pub(super) fn f32s(&self, at: usize, n: usize) -> Result<Vec<Value>, CommandError> {
        (0..n).map(|i| self.f32(at + 4 * i).map(Value::Float)).collect()
    }
    /// The NUL-terminated string at `at` and the offset after its NUL.
    pub(super) fn string(&self, at: usize) -> Result<(String, usize), CommandError> {
        let rest = self.0.get(at..).unwrap_or_default();
        let end = rest.iter().position(|&c| c == 0).ok_or(CommandError::NoString(at))?;
        Ok((String::from_utf8_lossy(&rest[..end]).into_owned(), at + end + 1))
    }
}

/// One integer result, as most commands read it from the registry's reply.
pub(super) fn as_i32(v: Option<&Value>) -> Option<i32> {
    v.and_then(Value::as_i64).and_then(|i| i32::try_from(i).ok())
}

/// A table result's elements.
pub(super) fn numbers(v: Option<&Value>) -> Result<Vec<Value>, CommandError> {
    match v {
        Some(Value::Array(a)) => Ok(a.clone()),
        other => Err(CommandError::NotNumbers(other.map_or("nothing", Value::type_name))),
    }
}

/// A vector result made three long, missing components zero.
pub(super) fn pad3(mut v: Vec<Value>) -> Vec<Value> {
    v.resize(3, Value::Float(0.0));
    v
}

pub(super) fn put_f32s(out: &mut Vec<u8>, values: &[Value]) -> Result<(), CommandError> {
    for v in values {
        let f = v.as_f64().ok_or(CommandError::NotANumber(v.type_name()))?;
        out.extend_from_slice(&(f as f32).to_le_bytes());
    }
    Ok(())
}

/// A count as the client reads it: a 32-bit integer.
pub(super) fn put_count(out: &mut Vec<u8>, n: usize) {
    out.extend_from_slice(&(n as i32).to_le_bytes());
}

/// A string as the client reads it: its bytes up to a NUL, then the NUL.
pub(super) fn put_string(out: &mut Vec<u8>, s: &str) {
    out.extend(s.bytes().filter(|&b| b != 0));
    out.push(0);
}

pub(super) fn floats_reply(values: &[Value]) -> Result<Vec<u8>, CommandError> {
    let mut out = Vec::with_capacity(values.len() * 4);
    put_f32s(&mut out, values)?;
    Ok(out)
}

pub(super) fn int_reply(v: Option<&Value>) -> Result<Vec<u8>, CommandError> {
    let i = as_i32(v).ok_or(CommandError::NoIntegerResult)?;
    Ok(i.to_le_bytes().to_vec())
}

pub(super) fn float_reply(v: Option<&Value>) -> Result<Vec<u8>, CommandError> {
    let f = v.and_then(Value::as_f64).ok_or(CommandError::NoNumberResult)?;
    Ok((f as f32).to_le_bytes().to_vec())
}

/// The integer identifying a command (0 when its identity has none).
pub(super) fn id_int(cmd: &Command) -> i32 {
    match &cmd.id {
        CommandId::Int(a) | CommandId::IntInt(a, _) | CommandId::IntStrStr(a, ..) => *a,
        _ => 0,
    }
}

/// The second integer identifying a command (0 when its identity has none).
pub(super) fn id_int2(cmd: &Command) -> i32 {
    match &cmd.id {
        CommandId::IntInt(_, b) => *b,
        _ => 0,
    }
}

/// The string identifying a command (empty when its identity has none).
pub(super) fn id_str(cmd: &Command) -> String {
    match &cmd.id {
        CommandId::Str(s) => String::from_utf8_lossy(s).into_owned(),
        _ => String::new(),
    }
}
