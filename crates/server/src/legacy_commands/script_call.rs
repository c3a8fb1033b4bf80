//! `simxCallScriptFunction`: a function of an object's script, called with four arrays
//! and answering four.

use gantry_protocol::legacy_remote_api::CommandId;
use gantry_sim_core::Value;

use super::layout::{CommandError, Data, as_i32, put_count, put_f32s, put_string};
use super::session::Ctx;

/// `simxCallScriptFunction`: identified by the script type and the script's object
/// name (or `function@object`), with four arrays in and four out, each array's length
/// first: integers, floats, NUL-terminated strings, one buffer.
pub(super) async fn call_script_function(cx: &mut Ctx<'_>) -> Result<Vec<u8>, CommandError> {
    let cmd = cx.cmd;
    let CommandId::IntStrStr(_, description, function) = &cmd.id else {
        return Err(CommandError::MalformedScriptCall);
    };
    let description = String::from_utf8_lossy(description).into_owned();
    let function = String::from_utf8_lossy(function).into_owned();
    let (function, object) = match function.split_once('@') {
        Some((f, o)) => (f.to_owned(), o.to_owned()),
        None => (function, description),
    };
    if object.is_empty() {
        return Err(CommandError::NoScriptObject(function));
    }
    let handle = cx.call("getObjectHandle", vec![Value::Str(object.clone())]).await?;
    let handle = as_i32(handle.first())
        .filter(|&x| x >= 0)
        .ok_or(CommandError::NoScriptCallObject(object))?;
    let d = Data(&cmd.data);
    let counts = [d.i32(0)?, d.i32(4)?, d.i32(8)?, d.i32(12)?];
    if counts.iter().any(|&c| c < 0 || c as usize > cmd.data.len()) {
        return Err(CommandError::BadArraySizes);
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
    let buffer = cmd.data.get(at..at + nb).ok_or(CommandError::ShortBuffer)?.to_vec();
    let out = cx
        .call(
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
        put_count(&mut reply, n);
    }
    for v in &ri {
        let x = v.as_f64().ok_or(CommandError::ReturnedIntegers)?;
        reply.extend_from_slice(&(x as i32).to_le_bytes());
    }
    put_f32s(&mut reply, &rf)?;
    for v in &rs {
        let s = match v {
            Value::Str(s) => s.clone(),
            other => return Err(CommandError::ReturnedStrings(other.type_name())),
        };
        put_string(&mut reply, &s);
    }
    reply.extend_from_slice(&rb);
    Ok(reply)
}
