//! The signal commands that are more than one registry call: reading a signal that may
//! be unset, and the string signals, which carry bytes and can be read and cleared in
//! one command. Setting and clearing are plain rows of the command table.

use gantry_sim_core::Value;

use super::layout::{CommandError, Reply, id_str};
use super::session::{Ctx, Outcome};

/// `simxGetFloatSignal`, `simxGetIntegerSignal`: `function`'s value encoded by `reply`;
/// an unset signal is an error naming the `kind` of signal.
pub(super) async fn number(
    cx: &mut Ctx<'_>,
    function: &str,
    kind: &'static str,
    reply: Reply,
) -> Result<Vec<u8>, CommandError> {
    let name = id_str(cx.cmd);
    let r = cx.call(function, vec![Value::Str(name.clone())]).await?;
    match r.first() {
        Some(Value::Nil) | None => Err(CommandError::NoSignal { kind, name }),
        _ => reply.encode(&r),
    }
}

/// How a command reads a string signal.
#[derive(Clone, Copy, Debug)]
pub(super) enum Read {
    /// `simxGetStringSignal`: leaves it set; unset is an error.
    Get,
    /// `simxGetAndClearStringSignal`: clears it and, when streaming, stops once found;
    /// unset is an error.
    GetAndClear,
    /// `simxReadStringStream`: clears it; unset is only nothing new.
    Stream,
}

/// A string signal's bytes, read as `read` says.
pub(super) async fn string(cx: &mut Ctx<'_>, read: Read) -> Result<Outcome, CommandError> {
    let name = id_str(cx.cmd);
    match (string_value(cx, &name).await?, read) {
        (Some(bytes), _) => {
            if !matches!(read, Read::Get) {
                cx.call("clearStringSignal", vec![Value::Str(name)]).await?;
            }
            Ok(Outcome {
                ok: true,
                data: bytes,
                ends_stream: matches!(read, Read::GetAndClear),
            })
        }
        (None, Read::Stream) => Ok(super::session::ok(Vec::new())),
        (None, _) => Err(CommandError::NoSignal { kind: "string", name }),
    }
}

/// `simxSetStringSignal`, `simxAppendStringSignal`: the arguments are the bytes, set as
/// the value or appended to it.
pub(super) async fn set_string(cx: &mut Ctx<'_>, append: bool) -> Result<Vec<u8>, CommandError> {
    let name = id_str(cx.cmd);
    let mut value = match append {
        true => string_value(cx, &name).await?.unwrap_or_default(),
        false => Vec::new(),
    };
    value.extend_from_slice(&cx.cmd.data);
    cx.call("setStringSignal", vec![Value::Str(name), Value::Bytes(value)])
        .await?;
    Ok(Vec::new())
}

/// A string signal's bytes, `None` when unset (a string or a buffer, as Lua set it).
async fn string_value(cx: &Ctx<'_>, name: &str) -> Result<Option<Vec<u8>>, CommandError> {
    Ok(
        match cx
            .call("getStringSignal", vec![Value::Str(name.to_owned())])
            .await?
            .into_iter()
            .next()
        {
            Some(Value::Str(s)) => Some(s.into_bytes()),
            Some(Value::Bytes(b)) => Some(b),
            _ => None,
        },
    )
}
