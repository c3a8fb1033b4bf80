//! The message layer of CoppeliaSim's ZMQ remote API, protocol v2.
//!
//! Each ZMQ frame holds one CBOR map. The rules below follow the behaviour of the Python
//! client 2.0.4 and the Lua server add-on, as recorded in the project's ZMQ remote API
//! reference notes (wire spec and a decoded transcript of a real client session).
//! A client sends `{"func": "sim.getObject", "args": ["/foo"], "argsL": 1, "uuid": ...}`;
//! the server answers `{"ret": [...]}`, `{"err": "..."}`, or a control message
//! `{"func": "_*wait*_", "args": []}` that the client acknowledges with `_*executed*_`.
//! This module turns frames into [`Request`]s and builds the replies; sockets and
//! dispatch live in the server crate.

use thiserror::Error;

use crate::Value;
use crate::cbor::{self, CborError};

/// Control word: the server parks the client; it answers with [`FUNC_EXECUTED`].
pub const FUNC_WAIT: &str = "_*wait*_";
/// Control word: the client's answer to a wait or a callback (with the callback's results).
pub const FUNC_EXECUTED: &str = "_*executed*_";
/// Control word: the server is busy; the client re-sends its original request.
pub const FUNC_REPEAT: &str = "_*repeat*_";
/// Control word: the client is leaving (C++/Java/MATLAB clients); the reply is `{}`.
pub const FUNC_END: &str = "_*end*_";
/// An argument with this text stands for nil (the Lua server converts it; so do we).
pub const NIL_MARKER: &str = "_*NIL*_";
/// Largest `argsL` honoured. Padding allocates one value per missing argument, so without
/// a cap a 20-byte message could demand gigabytes; no `sim.*` function takes near this.
pub const MAX_ARGS_L: i64 = 1024;

/// One decoded client message.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Request {
    /// Dotted function name (`"sim.getObject"`) or a control word like [`FUNC_EXECUTED`].
    pub func: String,
    /// Positional arguments, padded with nil up to `argsL`.
    pub args: Vec<Value>,
    /// The client's session key; absent only for v1 clients, which the server refuses.
    pub uuid: Option<String>,
    /// Protocol version (2), sent on the first message only by the sync client.
    pub ver: Option<i64>,
    /// Client language (`"python"`), first message only; informational.
    pub lang: Option<String>,
    /// Idle seconds after which the server may drop this client's state.
    pub timeout: Option<f64>,
}

/// Why a frame is not an acceptable remote API message. Messages can be sent back in
/// `{"err": ...}`.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RequestError {
    /// The frame is not one well-formed CBOR item.
    #[error("message is not valid CBOR: {0}")]
    Cbor(#[from] CborError),
    /// The top-level item is not a map.
    #[error("message must be a CBOR map like {{\"func\": ..., \"args\": [...]}}, got {got}")]
    NotAMap {
        /// Type of what was received.
        got: &'static str,
    },
    /// The map has no `func` key.
    #[error("message has no \"func\" key naming the function to call")]
    MissingFunc,
    /// A known key holds a value of the wrong type.
    #[error("message key {key:?} must be {expected}, got {got}")]
    BadField {
        /// The key.
        key: &'static str,
        /// The type required.
        expected: &'static str,
        /// The type received.
        got: &'static str,
    },
    /// `argsL` is negative or above [`MAX_ARGS_L`].
    #[error("\"argsL\" is {value}; it must be between 0 and {max}")]
    ArgsLOutOfRange {
        /// The value received.
        value: i64,
        /// The limit.
        max: i64,
    },
    /// A reply map has none of `func`, `err`, `ret` and is not empty.
    #[error("reply has none of \"ret\", \"err\" or \"func\"")]
    UnknownReply,
}

/// Decodes one request frame.
///
/// Rules: the top level must be a map with a text `func`; `args`, if present, must be an
/// array (missing means no arguments); unknown keys (e.g. `eval`) are ignored; for
/// duplicate keys the first wins. Top-level arguments equal to [`NIL_MARKER`] become nil.
///
/// `argsL` restores trailing nils. Clients built on Lua tables, and the Lua CBOR encoder,
/// cannot represent trailing nils in an array (a table's length stops before them), so
/// `f(1, nil)` arrives as `args: [1]`; the client therefore also sends `argsL`, the
/// intended count, and the real server unpacks `args[1..argsL]`. When `argsL` exceeds the
/// array length we pad with nil. When it is smaller we keep the whole array rather than
/// silently dropping arguments the client did send (the real server would drop them);
/// `argsL` must be an integer in `0..=`[`MAX_ARGS_L`].
pub fn decode_request(bytes: &[u8]) -> Result<Request, RequestError> {
    let msg = cbor::decode(bytes)?;
    let Value::Map(_) = msg else {
        return Err(RequestError::NotAMap { got: msg.type_name() });
    };
    let func = match msg.get("func") {
        None => return Err(RequestError::MissingFunc),
        Some(Value::Str(s)) => s.clone(),
        Some(other) => return Err(bad("func", "text", other)),
    };
    let mut args = match msg.get("args") {
        None => Vec::new(),
        Some(Value::Array(a)) => a.clone(),
        Some(other) => return Err(bad("args", "an array", other)),
    };
    for a in &mut args {
        if a.as_str() == Some(NIL_MARKER) {
            *a = Value::Nil;
        }
    }
    if let Some(v) = msg.get("argsL") {
        let n = v.as_i64().ok_or_else(|| bad("argsL", "an integer", v))?;
        let len = usize::try_from(n)
            .ok()
            .filter(|_| n <= MAX_ARGS_L)
            .ok_or(RequestError::ArgsLOutOfRange {
                value: n,
                max: MAX_ARGS_L,
            })?;
        if len > args.len() {
            args.resize(len, Value::Nil);
        }
    }
    let uuid = match msg.get("uuid") {
        None => None,
        Some(Value::Str(s)) => Some(s.clone()),
        Some(other) => return Err(bad("uuid", "text", other)),
    };
    let ver = match msg.get("ver") {
        None => None,
        Some(v) => Some(v.as_i64().ok_or_else(|| bad("ver", "an integer", v))?),
    };
    let lang = match msg.get("lang") {
        None => None,
        Some(Value::Str(s)) => Some(s.clone()),
        Some(other) => return Err(bad("lang", "text", other)),
    };
    let timeout = match msg.get("timeout") {
        None => None,
        Some(v) => Some(v.as_f64().ok_or_else(|| bad("timeout", "a number", v))?),
    };
    Ok(Request {
        func,
        args,
        uuid,
        ver,
        lang,
        timeout,
    })
}

fn bad(key: &'static str, expected: &'static str, got: &Value) -> RequestError {
    RequestError::BadField {
        key,
        expected,
        got: got.type_name(),
    }
}

/// Encodes a request the way the Python client 2.0.4 does, for tests and our own clients.
///
/// Key order is `func, args, argsL, uuid, ver, lang, timeout`, absent options omitted;
/// `argsL` is `args.len()`. An integral `timeout` is sent as an integer, as Python does.
pub fn encode_request(req: &Request) -> Vec<u8> {
    let mut pairs = vec![
        (key("func"), Value::Str(req.func.clone())),
        (key("args"), Value::Array(req.args.clone())),
        (
            key("argsL"),
            Value::Int(i64::try_from(req.args.len()).unwrap_or(i64::MAX)),
        ),
    ];
    if let Some(u) = &req.uuid {
        pairs.push((key("uuid"), Value::Str(u.clone())));
    }
    if let Some(v) = req.ver {
        pairs.push((key("ver"), Value::Int(v)));
    }
    if let Some(l) = &req.lang {
        pairs.push((key("lang"), Value::Str(l.clone())));
    }
    if let Some(t) = req.timeout {
        let t = Value::Float(t);
        pairs.push((key("timeout"), t.as_i64().map_or(t, Value::Int)));
    }
    cbor::to_vec(&Value::Map(pairs))
}

fn key(k: &str) -> Value {
    Value::Str(k.to_owned())
}

/// `{"ret": [values...]}`: a successful call.
///
/// The client returns `None` for no values, the value itself for one, and a tuple for
/// several, so a single vector must be passed as one `Value::Array` element.
pub fn encode_ret(values: &[Value]) -> Vec<u8> {
    cbor::to_vec(&Value::Map(vec![(key("ret"), Value::Array(values.to_vec()))]))
}

/// `{"err": msg}`: a failed call; the client raises `Exception(msg)`.
///
/// Applies the real server's treatment of Lua error text: the message is cut before
/// `"\nstack traceback:"`, then newlines become `_=NL=_` and tabs `_=TB=_` (the client
/// does not undo this, so messages look exactly as under CoppeliaSim).
pub fn encode_err(msg: &str) -> Vec<u8> {
    let msg = msg
        .find("\nstack traceback:")
        .map_or(msg, |cut| msg.get(..cut).unwrap_or(msg));
    let escaped = msg.replace('\n', "_=NL=_").replace('\t', "_=TB=_");
    cbor::to_vec(&Value::Map(vec![(key("err"), Value::Str(escaped))]))
}

/// `{"func": func, "args": [args...]}`: a callback into the client (or a control word).
pub fn encode_call(func: &str, args: &[Value]) -> Vec<u8> {
    cbor::to_vec(&Value::Map(vec![
        (key("func"), Value::Str(func.to_owned())),
        (key("args"), Value::Array(args.to_vec())),
    ]))
}

/// `{"func": "_*wait*_", "args": []}`: park the client; it answers `_*executed*_`.
pub fn encode_wait() -> Vec<u8> {
    encode_call(FUNC_WAIT, &[])
}

/// `{"func": "_*repeat*_", "args": []}`: the client re-sends its request unchanged.
pub fn encode_repeat() -> Vec<u8> {
    encode_call(FUNC_REPEAT, &[])
}

/// `{}`: the reply to `_*end*_`.
pub fn encode_empty_map() -> Vec<u8> {
    cbor::to_vec(&Value::Map(Vec::new()))
}

/// A server reply as a client sees it, for tests and our own clients.
#[derive(Debug, Clone, PartialEq)]
pub enum Reply {
    /// `{"func": ..., "args": [...]}`: a control word or callback; checked first, as the
    /// client does.
    Call {
        /// The control word or callback name.
        func: String,
        /// Its arguments.
        args: Vec<Value>,
    },
    /// `{"err": msg}`.
    Err(String),
    /// `{"ret": [...]}`; `{"ret": {}}` (a Lua server's empty table) gives no values.
    Ret(Vec<Value>),
    /// `{}`, the reply to `_*end*_`.
    Empty,
}

/// Decodes a server reply with the client's precedence: `func`, then `err`, then `ret`.
pub fn decode_reply(bytes: &[u8]) -> Result<Reply, RequestError> {
    let msg = cbor::decode(bytes)?;
    let Value::Map(pairs) = &msg else {
        return Err(RequestError::NotAMap { got: msg.type_name() });
    };
    if let Some(f) = msg.get("func") {
        let func = f.as_str().ok_or_else(|| bad("func", "text", f))?.to_owned();
        let args = match msg.get("args") {
            None => Vec::new(),
            Some(Value::Array(a)) => a.clone(),
            Some(other) => return Err(bad("args", "an array", other)),
        };
        return Ok(Reply::Call { func, args });
    }
    if let Some(e) = msg.get("err") {
        return Ok(Reply::Err(e.as_str().ok_or_else(|| bad("err", "text", e))?.to_owned()));
    }
    match msg.get("ret") {
        Some(Value::Array(a)) => Ok(Reply::Ret(a.clone())),
        Some(Value::Map(m)) if m.is_empty() => Ok(Reply::Ret(Vec::new())),
        Some(other) => Err(bad("ret", "an array", other)),
        None if pairs.is_empty() => Ok(Reply::Empty),
        None => Err(RequestError::UnknownReply),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const UUID: &str = "2a55ee71-0d5c-4d2e-9d8e-3b0f2c1a4b5c";

    fn hex(s: &str) -> Vec<u8> {
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
            .collect()
    }

    fn req(func: &str, args: Vec<Value>) -> Request {
        Request {
            func: func.into(),
            args,
            uuid: Some(UUID.into()),
            ..Request::default()
        }
    }

    #[test]
    fn get_object_bytes_match_the_reference() {
        // Reference §6: raw bytes of the first getObject request, up to the uuid text.
        let prefix = hex("a46466756e636d73696d2e6765744f626a656374646172677381642f666f6f65617267734c0164757569647824");
        let bytes = encode_request(&req("sim.getObject", vec!["/foo".into()]));
        assert_eq!(&bytes[..prefix.len()], &prefix[..]);
        assert_eq!(&bytes[prefix.len()..], UUID.as_bytes());
        let mut frame = prefix;
        frame.extend_from_slice(UUID.as_bytes());
        assert_eq!(
            decode_request(&frame).unwrap(),
            req("sim.getObject", vec!["/foo".into()])
        );
    }

    #[test]
    fn first_message_of_the_transcript() {
        // {"func":"zmqRemoteApi.require","args":["sim"],"argsL":1,"uuid":...,"ver":2,
        //  "lang":"python","timeout":600}, built key by key as the Python client does.
        let m = Value::Map(vec![
            (key("func"), "zmqRemoteApi.require".into()),
            (key("args"), Value::Array(vec!["sim".into()])),
            (key("argsL"), Value::Int(1)),
            (key("uuid"), UUID.into()),
            (key("ver"), Value::Int(2)),
            (key("lang"), "python".into()),
            (key("timeout"), Value::Int(600)),
        ]);
        let bytes = cbor::to_vec(&m);
        let r = decode_request(&bytes).unwrap();
        let want = Request {
            func: "zmqRemoteApi.require".into(),
            args: vec!["sim".into()],
            uuid: Some(UUID.into()),
            ver: Some(2),
            lang: Some("python".into()),
            timeout: Some(600.0),
        };
        assert_eq!(r, want);
        assert_eq!(encode_request(&want), bytes);
    }

    #[test]
    fn transcript_requests() {
        let cases = [
            req("sim.getSimulationTime", vec![]),
            req("sim.setJointTargetVelocity", vec![17.into(), 1.5.into()]),
            req("sim.getObjectPosition", vec![17.into(), (-1).into()]),
            req("sim.setStepping", vec![true.into()]),
            req(FUNC_EXECUTED, vec![]),
            req("sim.bogus", vec![1.into(), Value::Nil]),
            req("sim.testCB", vec![2.into(), "myCb_7f1e6233eca0@func".into(), 40.into()]),
        ];
        for r in cases {
            assert_eq!(decode_request(&encode_request(&r)).unwrap(), r);
        }
    }

    fn frame(pairs: Vec<(&str, Value)>) -> Vec<u8> {
        cbor::to_vec(&Value::Map(pairs.into_iter().map(|(k, v)| (key(k), v)).collect()))
    }

    #[test]
    fn args_l_pads_trailing_nils() {
        // A Lua-table client sends f(1, nil, nil) as args [1] with argsL 3.
        let f = frame(vec![
            ("func", "sim.bogus".into()),
            ("args", vec![1.into()].into()),
            ("argsL", 3.into()),
        ]);
        assert_eq!(
            decode_request(&f).unwrap().args,
            [Value::Int(1), Value::Nil, Value::Nil]
        );
        // Missing args and integral float argsL.
        let f = frame(vec![("func", "f".into()), ("argsL", 2.0.into())]);
        assert_eq!(decode_request(&f).unwrap().args, [Value::Nil, Value::Nil]);
        // A smaller argsL keeps what was sent.
        let f = frame(vec![
            ("func", "f".into()),
            ("args", vec![1.into(), 2.into()].into()),
            ("argsL", 1.into()),
        ]);
        assert_eq!(decode_request(&f).unwrap().args.len(), 2);
        // The nil marker.
        let f = frame(vec![("func", "f".into()), ("args", vec![NIL_MARKER.into()].into())]);
        assert_eq!(decode_request(&f).unwrap().args, [Value::Nil]);
    }

    #[test]
    fn rejects() {
        use RequestError as E;
        let cases: Vec<(Vec<u8>, RequestError)> = vec![
            (vec![], E::Cbor(CborError::Truncated { offset: 0 })),
            (cbor::to_vec(&Value::Array(vec![])), E::NotAMap { got: "array" }),
            (frame(vec![("args", Value::Array(vec![]))]), E::MissingFunc),
            (
                frame(vec![("func", 1.into())]),
                E::BadField {
                    key: "func",
                    expected: "text",
                    got: "number",
                },
            ),
            (
                frame(vec![("func", "f".into()), ("args", Value::Nil)]),
                E::BadField {
                    key: "args",
                    expected: "an array",
                    got: "nil",
                },
            ),
            (
                frame(vec![("func", "f".into()), ("argsL", "2".into())]),
                E::BadField {
                    key: "argsL",
                    expected: "an integer",
                    got: "string",
                },
            ),
            (
                frame(vec![("func", "f".into()), ("argsL", 1.5.into())]),
                E::BadField {
                    key: "argsL",
                    expected: "an integer",
                    got: "number",
                },
            ),
            (
                frame(vec![("func", "f".into()), ("argsL", 1025.into())]),
                E::ArgsLOutOfRange {
                    value: 1025,
                    max: MAX_ARGS_L,
                },
            ),
            (
                frame(vec![("func", "f".into()), ("argsL", (-1).into())]),
                E::ArgsLOutOfRange {
                    value: -1,
                    max: MAX_ARGS_L,
                },
            ),
            (
                frame(vec![("func", "f".into()), ("uuid", 5.into())]),
                E::BadField {
                    key: "uuid",
                    expected: "text",
                    got: "number",
                },
            ),
            (
                frame(vec![("func", "f".into()), ("ver", "2".into())]),
                E::BadField {
                    key: "ver",
                    expected: "an integer",
                    got: "string",
                },
            ),
            (
                frame(vec![("func", "f".into()), ("lang", Value::Nil)]),
                E::BadField {
                    key: "lang",
                    expected: "text",
                    got: "nil",
                },
            ),
            (
                frame(vec![("func", "f".into()), ("timeout", Value::Nil)]),
                E::BadField {
                    key: "timeout",
                    expected: "a number",
                    got: "nil",
                },
            ),
        ];
        for (bytes, want) in cases {
            assert_eq!(decode_request(&bytes), Err(want.clone()), "{want}");
        }
    }

    #[test]
    fn other_keys_are_ignored() {
        let f = frame(vec![
            ("eval", "os.exit()".into()),
            ("func", "f".into()),
            ("x", Value::Nil),
        ]);
        let r = decode_request(&f).unwrap();
        assert_eq!(r.func, "f");
        assert_eq!(r.uuid, None);
    }

    #[test]
    fn reply_encodings() {
        // {"ret":[]}
        assert_eq!(encode_ret(&[]), hex("a16372657480"));
        // {"ret":[17]}
        assert_eq!(encode_ret(&[17.into()]), hex("a1637265748111"));
        // {"ret":[[0.5,-0.25,1.0]]}: one wrapped vector, floats as doubles.
        let v = encode_ret(&[Value::floats(&[0.5, -0.25, 1.0])]);
        assert_eq!(
            v,
            hex("a1637265748183fb3fe0000000000000fbbfd0000000000000fb3ff0000000000000")
        );
        // {"func":"_*wait*_","args":[]}
        assert_eq!(encode_wait(), hex("a26466756e63685f2a776169742a5f646172677380"));
        assert_eq!(encode_empty_map(), hex("a0"));
        assert_eq!(
            decode_reply(&encode_repeat()).unwrap(),
            Reply::Call {
                func: FUNC_REPEAT.into(),
                args: vec![]
            }
        );
        assert_eq!(
            decode_reply(&encode_call("myCb_7f1e6233eca0", &[2.into(), 40.into()])).unwrap(),
            Reply::Call {
                func: "myCb_7f1e6233eca0".into(),
                args: vec![2.into(), 40.into()]
            }
        );
    }

    #[test]
    fn err_escaping() {
        let msg = "Object does not exist. (in function 'sim.getObject')";
        assert_eq!(decode_reply(&encode_err(msg)).unwrap(), Reply::Err(msg.into()));
        let lua = "[string \"x\"]:1: Object does not exist.\n\tmore\nstack traceback:\n\t[C]: in ?";
        assert_eq!(
            decode_reply(&encode_err(lua)).unwrap(),
            Reply::Err("[string \"x\"]:1: Object does not exist._=NL=__=TB=_more".into())
        );
    }

    #[test]
    fn reply_decoding() {
        assert_eq!(
            decode_reply(&encode_ret(&[1.into()])).unwrap(),
            Reply::Ret(vec![1.into()])
        );
        assert_eq!(decode_reply(&hex("a163726574a0")).unwrap(), Reply::Ret(vec![]));
        assert_eq!(decode_reply(&encode_empty_map()).unwrap(), Reply::Empty);
        assert_eq!(
            decode_reply(&frame(vec![("x", 1.into())])),
            Err(RequestError::UnknownReply)
        );
    }
}
