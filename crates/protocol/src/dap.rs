//! The Debug Adapter Protocol (DAP): `Content-Length` frames, requests, responses, events.
//!
//! A DAP client (VS Code, nvim-dap, ...) and a debug adapter exchange messages framed like
//! HTTP: a header of `Name: value` lines ending in CRLF, of which only `Content-Length` is
//! required (others, such as `Content-Type`, are ignored), then a blank line, then that many
//! bytes of UTF-8 JSON. This module splits frames out of a receive buffer
//! ([`decode_frame`]), turns a body into a typed [`Request`] ([`parse_request`]), and frames
//! the adapter's responses and events ([`Outgoing::encode`]). It does no I/O and knows
//! nothing of the debugger: the engine gives meaning to a [`Command`], and the transport
//! moves bytes and numbers outgoing messages.
//!
//! Only the requests the adapter implements are typed, and only the arguments it reads.
//! Other fields are ignored, since clients send many optional ones, and any other command
//! parses as [`Command::Unknown`], so it can get an error response instead of costing the
//! connection.
//!
//! Bounds: a header section is at most [`MAX_HEADER`] bytes and a body at most [`MAX_BODY`];
//! an oversize length is refused as soon as its header is complete, before any of the body
//! is buffered. JSON nesting is capped by serde_json's recursion limit (128 levels), so
//! parsing cannot exhaust the stack. The parsed `serde_json::Value` is larger than its
//! text (up to about 100 times for an adversarial array of one-key objects) but lives only
//! during [`parse_request`].
//!
//! ```
//! use gantry_protocol::dap::{self, Command, MessageError, Outgoing};
//! use serde_json::json;
//!
//! let body = br#"{"seq": 1, "type": "request", "command": "threads"}"#;
//! let mut buf = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
//! buf.extend_from_slice(body);
//!
//! let mut sent = Vec::new();
//! while let Some((body, consumed)) = dap::decode_frame(&buf)? {
//!     let reply = match dap::parse_request(body) {
//!         Ok(req) if req.command == Command::Threads => {
//!             Outgoing::ok(req.seq, "threads", json!({"threads": [{"id": 1, "name": "sim"}]}))
//!         }
//!         Ok(req) => Outgoing::error(req.seq, req.command.name(), "not handled in this example"),
//!         Err(MessageError::BadArguments { seq, command, why }) => Outgoing::error(seq, &command, why),
//!         Err(e @ MessageError::Malformed(_)) => Outgoing::error(0, "", e.to_string()),
//!     };
//!     sent.extend(reply.encode(1));
//!     buf.drain(..consumed);
//! }
//! assert!(buf.is_empty());
//! assert!(sent.starts_with(b"Content-Length: "));
//! # Ok::<(), dap::FrameError>(())
//! ```

use serde::Serialize;
use serde_json::{Map, Value};
use thiserror::Error;

/// Longest header section accepted (bytes, up to and including the blank line).
///
/// Real clients send one or two short lines; this leaves room for a few more while
/// bounding what is buffered before the length is known.
pub const MAX_HEADER: usize = 1024;
/// Largest body accepted (64 KiB). DAP requests are small (the largest a client sends
/// is a `setBreakpoints` for one file or an expression); the bound also caps what
/// parsing may allocate (see the module docs) at a few MiB.
pub const MAX_BODY: usize = 64 * 1024;

/// How much of an offending header line or value an error quotes, in characters.
const SNIPPET_LEN: usize = 40;

/// Why a byte stream is not a sequence of DAP frames.
///
/// None of these says where the next frame starts, so after any of them the framing is
/// lost: see [`FrameError::recoverable`].
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum FrameError {
    /// No blank line within the first [`MAX_HEADER`] bytes.
    #[error(
        "no blank line ending the header within {MAX_HEADER} bytes; a DAP message starts with \"Content-Length: <bytes>\\r\\n\\r\\n\""
    )]
    HeaderTooLong,
    /// A header line is not valid UTF-8.
    #[error("a header line is not valid UTF-8; header lines are `Name: value` in ASCII")]
    HeaderNotUtf8,
    /// A header line is not `Name: value` (no colon, or a name with spaces or symbols).
    #[error("header line {line:?} is not `Name: value`; e.g. \"Content-Length: 42\"")]
    MalformedHeaderLine {
        /// The start of the line.
        line: String,
    },
    /// The header ended without a `Content-Length` line.
    #[error("the header has no Content-Length; every DAP message starts with \"Content-Length: <bytes>\\r\\n\\r\\n\"")]
    MissingLength,
    /// The header has two `Content-Length` lines, so the body's extent is ambiguous.
    #[error("the header has more than one Content-Length line; send exactly one")]
    DuplicateLength,
    /// The `Content-Length` value is not a decimal number of bytes.
    #[error(
        "Content-Length {value:?} is not a number of bytes; write decimal digits only, e.g. \"Content-Length: 42\""
    )]
    BadLength {
        /// The start of the value, trimmed of surrounding blanks.
        value: String,
    },
    /// The `Content-Length` exceeds [`MAX_BODY`].
    #[error("Content-Length {length} exceeds the limit of {MAX_BODY} bytes; DAP requests are far smaller")]
    TooLarge {
        /// The length announced, saturated at `u64::MAX` when even that is exceeded.
        length: u64,
    },
}

impl FrameError {
    /// Whether the stream can go on after this error (false: the framing is lost, the
    /// transport must close the connection after answering).
    ///
    /// Every current variant is unrecoverable. A header error leaves the body's length
    /// unknown, and skipping an announced but oversize body would mean reading up to
    /// `u64::MAX` bytes, so there is no trustworthy point to resume from. The method exists
    /// so transports need not hard-code that, and the match below makes any new variant
    /// decide.
    pub fn recoverable(&self) -> bool {
        match self {
            FrameError::HeaderTooLong
            | FrameError::HeaderNotUtf8
            | FrameError::MalformedHeaderLine { .. }
            | FrameError::MissingLength
            | FrameError::DuplicateLength
            | FrameError::BadLength { .. }
            | FrameError::TooLarge { .. } => false,
        }
    }
}

/// Looks for one whole frame at the start of `buf`. Ok(None): need more bytes.
/// Ok(Some((body, consumed))): `body` is the JSON bytes (a sub-slice of buf), `consumed`
/// the bytes to drop from the front of buf. Allocates nothing (but an error's short
/// quote) and looks at most [`MAX_HEADER`] bytes into `buf`; refuses a Content-Length
/// above MAX_BODY as soon as its line is complete, before the body arrives.
///
/// Header lines end in CRLF (a bare LF is not a line end, as in the DAP specification);
/// names are matched case-insensitively and values trimmed of blanks. Every line is
/// checked as it completes, so a garbled header is refused without waiting for its blank
/// line. The result depends only on the bytes, never on how reads split them: for any
/// prefix of a buffer the answer is either `Ok(None)` or the buffer's own answer, so the
/// transport may call this after every read.
///
/// # Errors
///
/// A [`FrameError`] when the header is too long, garbled, or lacks a valid
/// `Content-Length` within [`MAX_BODY`]. The body is not inspected; [`parse_request`]
/// does that.
pub fn decode_frame(buf: &[u8]) -> Result<Option<(&[u8], usize)>, FrameError> {
    // Only the first MAX_HEADER bytes can hold the header, so a peer that never sends a
    // blank line is refused after MAX_HEADER bytes, and each call scans at most that much.
    let head = buf.get(..MAX_HEADER).unwrap_or(buf);
    let mut pos = 0;
    let mut length = None;
    let body_start = loop {
        let rest = head.get(pos..).unwrap_or_default();
        let Some(end) = rest.windows(2).position(|w| w == b"\r\n") else {
            return if buf.len() >= MAX_HEADER {
                Err(FrameError::HeaderTooLong)
            } else {
                Ok(None)
            };
        };
        let line = rest.get(..end).unwrap_or_default();
        pos += end + 2;
        if line.is_empty() {
            break pos;
        }
        let (name, value) = header_line(line)?;
        if name.eq_ignore_ascii_case("Content-Length") {
            if length.is_some() {
                return Err(FrameError::DuplicateLength);
            }
            length = Some(content_length(value)?);
        }
    };
    let length = length.ok_or(FrameError::MissingLength)?;
    // `length` is at most MAX_BODY and `body_start` at most MAX_HEADER: no overflow.
    let end = body_start + length;
    Ok(buf.get(body_start..end).map(|body| (body, end)))
}

/// Splits a header line into name and value, checking the name is an HTTP token.
fn header_line(line: &[u8]) -> Result<(&str, &str), FrameError> {
    let line = std::str::from_utf8(line).map_err(|_| FrameError::HeaderNotUtf8)?;
    let malformed = || FrameError::MalformedHeaderLine { line: snippet(line) };
    let (name, value) = line.split_once(':').ok_or_else(malformed)?;
    // RFC 9110 token characters. Refusing anything else (notably spaces, as in
    // "Content-Length : 5") catches a desynchronised stream early instead of ignoring
    // body bytes as an unknown header.
    let token = |b: u8| b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b);
    if name.is_empty() || !name.bytes().all(token) {
        return Err(malformed());
    }
    Ok((name, value.trim_matches([' ', '\t'])))
}

/// Reads a `Content-Length` value, refusing lengths above [`MAX_BODY`].
fn content_length(value: &str) -> Result<usize, FrameError> {
    // `u64::from_str` would also take a leading '+'; a length is plain digits.
    if value.is_empty() || !value.bytes().all(|b| b.is_ascii_digit()) {
        return Err(FrameError::BadLength { value: snippet(value) });
    }
    // Only digits, so the one way parsing fails is overflow: a length, just far too large.
    let length = value.parse::<u64>().unwrap_or(u64::MAX);
    usize::try_from(length)
        .ok()
        .filter(|&n| n <= MAX_BODY)
        .ok_or(FrameError::TooLarge { length })
}

fn snippet(s: &str) -> String {
    s.chars().take(SNIPPET_LEN).collect()
}

/// A DAP request, decoded.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// The client's sequence number, echoed as `request_seq` in the response.
    pub seq: i64,
    /// What the client asks for.
    pub command: Command,
}

/// The requests this adapter understands, with the arguments it reads.
///
/// Line and column numbers are passed on as the client sent them, 1-based unless its
/// [`Command::Initialize`] said otherwise. Ids (`thread_id`, `frame_id`,
/// `variables_reference`, `source_reference`) are the adapter's own, echoed back by the
/// client, and are not validated here.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// `initialize`: the first request; the response carries the adapter's capabilities.
    Initialize {
        /// `clientName`: the client's human-readable name, for logs.
        client_name: Option<String>,
        /// `linesStartAt1`: whether line numbers are 1-based (DAP's default: true).
        lines_start_at1: bool,
        /// `columnsStartAt1`: whether column numbers are 1-based (DAP's default: true).
        columns_start_at1: bool,
    },
    /// `attach`: debug the running simulation. Its arguments are adapter-defined and this
    /// adapter reads none, so they are not inspected.
    Attach,
    /// `launch`: start debugging. Arguments are not inspected, as for [`Command::Attach`].
    Launch,
    /// `configurationDone`: the client has sent its breakpoints; execution may start.
    ConfigurationDone,
    /// `setBreakpoints`: replaces every breakpoint in one source.
    SetBreakpoints {
        /// `source`: the file the breakpoints are in.
        source: Source,
        /// `breakpoints` (or the deprecated `lines`); empty clears the source's breakpoints.
        breakpoints: Vec<SourceBreakpoint>,
    },
    /// `setExceptionBreakpoints`: which exception filters are on.
    SetExceptionBreakpoints {
        /// `filters`: ids from the `exceptionBreakpointFilters` capability.
        filters: Vec<String>,
    },
    /// `threads`: list the threads.
    Threads,
    /// `stackTrace`: a thread's frames, innermost first.
    StackTrace {
        /// `threadId`; 1 when absent, as the simulation has one thread.
        thread_id: i64,
        /// `startFrame`: how many frames to skip (default 0).
        start_frame: usize,
        /// `levels`: how many frames to return; `None` (absent or 0) means all.
        levels: Option<usize>,
    },
    /// `scopes`: the variable scopes of a stack frame.
    Scopes {
        /// `frameId`: from a [`Command::StackTrace`] response.
        frame_id: i64,
    },
    /// `variables`: the children of a scope or structured variable.
    Variables {
        /// `variablesReference`: from a scope or variable.
        variables_reference: i64,
        /// `start`: index of the first child to return (paging indexed children).
        start: Option<usize>,
        /// `count`: how many children to return; `None` (absent or 0) means all.
        count: Option<usize>,
    },
    /// `evaluate`: evaluate an expression (watch, hover, debug console).
    Evaluate {
        /// `expression`: the text to evaluate.
        expression: String,
        /// `frameId`: the frame whose scope to evaluate in; `None` means global scope.
        frame_id: Option<i64>,
        /// `context`: where the request comes from (`"watch"`, `"repl"`, `"hover"`, ...).
        context: Option<String>,
    },
    /// `setVariable`: assign to a variable in a container.
    SetVariable {
        /// `variablesReference`: the container holding the variable.
        variables_reference: i64,
        /// `name`: the variable's name in that container.
        name: String,
        /// `value`: the new value, as text to evaluate.
        value: String,
    },
    /// `continue`: resume execution.
    Continue {
        /// `threadId`; 1 when absent.
        thread_id: i64,
    },
    /// `next`: step over.
    Next {
        /// `threadId`; 1 when absent.
        thread_id: i64,
    },
    /// `stepIn`: step into a call.
    StepIn {
        /// `threadId`; 1 when absent.
        thread_id: i64,
    },
    /// `stepOut`: run until the current function returns.
    StepOut {
        /// `threadId`; 1 when absent.
        thread_id: i64,
    },
    /// `pause`: suspend execution.
    Pause {
        /// `threadId`; 1 when absent.
        thread_id: i64,
    },
    /// `disconnect`: the client is leaving.
    Disconnect {
        /// `terminateDebuggee`: stop the simulation too (default false: it keeps running).
        terminate_debuggee: bool,
    },
    /// `terminate`: ask the debuggee to stop.
    Terminate,
    /// `loadedSources`: list the scripts loaded.
    LoadedSources,
    /// `source`: the text of a source the client cannot read from disk.
    Source {
        /// `sourceReference` (or, from clients that omit it, `source.sourceReference`).
        source_reference: i64,
        /// `source.path`, when the client gave one.
        path: Option<String>,
    },
    /// A command this adapter does not implement: answered with an error response naming it.
    Unknown(String),
}

impl Command {
    /// The DAP command name (`"setBreakpoints"`), which the response must echo in its
    /// `command` field.
    pub fn name(&self) -> &str {
        match self {
            Command::Initialize { .. } => "initialize",
            Command::Attach => "attach",
            Command::Launch => "launch",
            Command::ConfigurationDone => "configurationDone",
            Command::SetBreakpoints { .. } => "setBreakpoints",
            Command::SetExceptionBreakpoints { .. } => "setExceptionBreakpoints",
            Command::Threads => "threads",
            Command::StackTrace { .. } => "stackTrace",
            Command::Scopes { .. } => "scopes",
            Command::Variables { .. } => "variables",
            Command::Evaluate { .. } => "evaluate",
            Command::SetVariable { .. } => "setVariable",
            Command::Continue { .. } => "continue",
            Command::Next { .. } => "next",
            Command::StepIn { .. } => "stepIn",
            Command::StepOut { .. } => "stepOut",
            Command::Pause { .. } => "pause",
            Command::Disconnect { .. } => "disconnect",
            Command::Terminate => "terminate",
            Command::LoadedSources => "loadedSources",
            Command::Source { .. } => "source",
            Command::Unknown(name) => name,
        }
    }
}

/// A DAP `Source`: where a script's text comes from.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Source {
    /// `name`: short name shown in the UI.
    pub name: Option<String>,
    /// `path`: the file path.
    pub path: Option<String>,
    /// `sourceReference`: when positive, the text is fetched with a `source` request.
    pub source_reference: Option<i64>,
}

/// A DAP `SourceBreakpoint`: one breakpoint as the client asks for it.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceBreakpoint {
    /// `line`, numbered as the client's [`Command::Initialize`] said.
    pub line: i64,
    /// `condition`: an expression; the breakpoint stops only when it is true.
    pub condition: Option<String>,
    /// `hitCondition`: an expression on the hit count (e.g. `">= 3"`).
    pub hit_condition: Option<String>,
    /// `logMessage`: log this (with `{expr}` interpolated) instead of stopping.
    pub log_message: Option<String>,
}

/// Why a frame's body is not an acceptable request.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MessageError {
    /// Not JSON, or not an object, or not a request (`"type"` other than "request";
    /// responses/events from a client are refused), or no integer `seq`/string `command`:
    /// the request cannot be identified, so it is answered with request_seq 0.
    #[error("malformed DAP message: {0}")]
    Malformed(String),
    /// A known command whose arguments are missing or of the wrong type (e.g.
    /// setBreakpoints without `source`, a breakpoint without an integer `line`): answerable
    /// with its seq and command.
    #[error("bad arguments to {command:?}: {why}")]
    BadArguments {
        /// The request's `seq`.
        seq: i64,
        /// The request's `command`.
        command: String,
        /// Which argument is wrong, by path (`arguments.breakpoints[0].line ...`).
        why: String,
    },
}

/// Which argument of a known command is wrong, by its full path in the message
/// (`arguments.breakpoints[2].line`), so a client learns exactly what to fix.
/// [`MessageError::BadArguments`] carries its text.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ArgumentError {
    /// A field that must hold an object (`arguments`, a breakpoint) holds something else.
    #[error("{path} must be an object, got {got}")]
    NotAnObject {
        /// Where the value is (`arguments`, `arguments.breakpoints[0]`).
        path: String,
        /// A short description of the value sent.
        got: String,
    },
    /// A required field is absent or null.
    #[error("{path} is required ({expected})")]
    Missing {
        /// The field's path.
        path: String,
        /// What it must hold (`an integer`, `a string`).
        expected: &'static str,
    },
    /// A field holds a value of the wrong type.
    #[error("{path} must be {expected}, got {got}")]
    Wrong {
        /// The field's path.
        path: String,
        /// What it must hold (`an integer`, `true or false`).
        expected: &'static str,
        /// A short description of the value sent.
        got: String,
    },
}

/// Parses one body into a request. Total: any bytes give Ok or Err, never a panic. Missing
/// optional arguments take DAP's defaults; unknown extra fields are ignored (clients send
/// many).
///
/// Command names match exactly (DAP's are camelCase). JSON `null` counts as absent, as
/// some clients send it for unset options. Integers must be JSON integers: `3.0` is
/// refused, which no JavaScript client produces. Responses are refused because this
/// adapter sends no reverse requests (`runInTerminal`, `startDebugging`) that a client
/// would answer; supporting those would start here.
///
/// # Errors
///
/// [`MessageError::Malformed`] when the body cannot be identified as a request;
/// [`MessageError::BadArguments`] when it can but a known command's arguments are wrong.
pub fn parse_request(body: &[u8]) -> Result<Request, MessageError> {
    let malformed = MessageError::Malformed;
    let msg: Value = serde_json::from_slice(body).map_err(|e| malformed(format!("the body is not valid JSON: {e}")))?;
    let Value::Object(mut msg) = msg else {
        return Err(malformed(format!(
            "the body must be a JSON object, got {}",
            describe(&msg)
        )));
    };
    match msg.get("type") {
        Some(Value::String(t)) if t == "request" => {}
        Some(Value::String(t)) => {
            return Err(malformed(format!(
                "message type {:?} is not accepted: a client sends only requests",
                snippet(t)
            )));
        }
        Some(other) => {
            return Err(malformed(format!(
                "\"type\" must be \"request\", got {}",
                describe(other)
            )));
        }
        None => {
            return Err(malformed(
                "the message has no \"type\"; a request has \"type\": \"request\"".into(),
            ));
        }
    }
    let seq = match msg.get("seq") {
        Some(v) => v
            .as_i64()
            .ok_or_else(|| malformed(format!("\"seq\" must be an integer, got {}", describe(v))))?,
        None => return Err(malformed("the request has no \"seq\"".into())),
    };
    let command = match msg.remove("command") {
        Some(Value::String(c)) => c,
        Some(other) => {
            return Err(malformed(format!(
                "\"command\" must be a string, got {}",
                describe(&other)
            )));
        }
        None => return Err(malformed("the request has no \"command\"".into())),
    };
    match parse_command(&command, msg.remove("arguments")) {
        Ok(command) => Ok(Request { seq, command }),
        Err(why) => Err(MessageError::BadArguments {
            seq,
            command,
            why: why.to_string(),
        }),
    }
}

/// Builds the command from its name and `arguments`, or says which argument is wrong.
fn parse_command(name: &str, arguments: Option<Value>) -> Result<Command, ArgumentError> {
    // Only the arms that read arguments look at them: commands whose arguments are unused
    // (attach, launch, threads, ...) or unknown accept whatever the client sent.
    let args = move || Fields::new(arguments, "arguments".to_owned());
    Ok(match name {
        "initialize" => {
            let mut a = args()?;
            Command::Initialize {
                client_name: a.opt_string("clientName")?,
                lines_start_at1: a.opt_bool("linesStartAt1")?.unwrap_or(true),
                columns_start_at1: a.opt_bool("columnsStartAt1")?.unwrap_or(true),
            }
        }
        "attach" => Command::Attach,
        "launch" => Command::Launch,
        "configurationDone" => Command::ConfigurationDone,
        "setBreakpoints" => {
            let mut a = args()?;
            let source = source(a.object("source")?)?;
            let breakpoints = match a.opt_array("breakpoints")? {
                Some(items) => a.each("breakpoints", items, |v, path| {
                    source_breakpoint(Fields::new(Some(v), path)?)
                })?,
                // DAP's deprecated form: line numbers only. Old clients send it.
                None => match a.opt_array("lines")? {
                    Some(items) => a.each("lines", items, |v, path| {
                        let line = v.as_i64().ok_or_else(|| wrong(&path, "an integer", &v))?;
                        Ok(SourceBreakpoint {
                            line,
                            condition: None,
                            hit_condition: None,
                            log_message: None,
                        })
                    })?,
                    None => Vec::new(),
                },
            };
            Command::SetBreakpoints { source, breakpoints }
        }
        "setExceptionBreakpoints" => {
            let mut a = args()?;
            let items = a
                .opt_array("filters")?
                .ok_or_else(|| a.missing("filters", "an array of strings"))?;
            let filters = a.each("filters", items, |v, path| match v {
                Value::String(s) => Ok(s),
                other => Err(wrong(&path, "a string", &other)),
            })?;
            Command::SetExceptionBreakpoints { filters }
        }
        "threads" => Command::Threads,
        "stackTrace" => {
            let mut a = args()?;
            Command::StackTrace {
                thread_id: a.thread_id()?,
                start_frame: a.opt_usize("startFrame")?.unwrap_or(0),
                levels: a.opt_usize("levels")?.filter(|&n| n != 0),
            }
        }
        "scopes" => Command::Scopes {
            frame_id: args()?.i64("frameId")?,
        },
        "variables" => {
            let mut a = args()?;
            Command::Variables {
                variables_reference: a.i64("variablesReference")?,
                start: a.opt_usize("start")?,
                // DAP: "If count is omitted or 0, all variables are returned"; one spelling
                // of "all" for the engine, as for `levels`.
                count: a.opt_usize("count")?.filter(|&n| n != 0),
            }
        }
        "evaluate" => {
            let mut a = args()?;
            Command::Evaluate {
                expression: a.string("expression")?,
                frame_id: a.opt_i64("frameId")?,
                context: a.opt_string("context")?,
            }
        }
        "setVariable" => {
            let mut a = args()?;
            Command::SetVariable {
                variables_reference: a.i64("variablesReference")?,
                name: a.string("name")?,
                value: a.string("value")?,
            }
        }
        "continue" => Command::Continue {
            thread_id: args()?.thread_id()?,
        },
        "next" => Command::Next {
            thread_id: args()?.thread_id()?,
        },
        "stepIn" => Command::StepIn {
            thread_id: args()?.thread_id()?,
        },
        "stepOut" => Command::StepOut {
            thread_id: args()?.thread_id()?,
        },
        "pause" => Command::Pause {
            thread_id: args()?.thread_id()?,
        },
        "disconnect" => Command::Disconnect {
            terminate_debuggee: args()?.opt_bool("terminateDebuggee")?.unwrap_or(false),
        },
        "terminate" => Command::Terminate,
        "loadedSources" => Command::LoadedSources,
        "source" => {
            let mut a = args()?;
            let mut nested = a.opt_object("source")?;
            let path = match &mut nested {
                Some(s) => s.opt_string("path")?,
                None => None,
            };
            // DAP requires the top-level field, kept for clients older than `source`; the
            // nested one holds the same value, so it stands in when the other is missing.
            let source_reference = match a.opt_i64("sourceReference")? {
                Some(r) => r,
                None => match &mut nested {
                    Some(s) => s.opt_i64("sourceReference")?,
                    None => None,
                }
                .ok_or_else(|| a.missing("sourceReference", "an integer"))?,
            };
            Command::Source { source_reference, path }
        }
        other => Command::Unknown(other.to_owned()),
    })
}

fn source(mut s: Fields) -> Result<Source, ArgumentError> {
    Ok(Source {
        name: s.opt_string("name")?,
        path: s.opt_string("path")?,
        source_reference: s.opt_i64("sourceReference")?,
    })
}

fn source_breakpoint(mut b: Fields) -> Result<SourceBreakpoint, ArgumentError> {
    Ok(SourceBreakpoint {
        line: b.i64("line")?,
        condition: b.opt_string("condition")?,
        hit_condition: b.opt_string("hitCondition")?,
        log_message: b.opt_string("logMessage")?,
    })
}

/// A JSON object read field by field into typed values.
///
/// Fields are taken out (not cloned), and each error names the field by its full path
/// (`arguments.breakpoints[2].line must be an integer, got "3"`), so a client learns
/// exactly what to fix from the error response.
struct Fields {
    map: Map<String, Value>,
    /// Where this object is in the message, for error messages.
    path: String,
}

impl Fields {
    /// `value` as an object; absent or null reads as empty, since DAP lets clients omit
    /// `arguments` when all of them are optional.
    fn new(value: Option<Value>, path: String) -> Result<Self, ArgumentError> {
        match value {
            None | Some(Value::Null) => Ok(Fields { map: Map::new(), path }),
            Some(Value::Object(map)) => Ok(Fields { map, path }),
            Some(other) => Err(ArgumentError::NotAnObject {
                got: describe(&other),
                path,
            }),
        }
    }

    fn path(&self, key: &str) -> String {
        format!("{}.{key}", self.path)
    }

    fn missing(&self, key: &str, expected: &'static str) -> ArgumentError {
        ArgumentError::Missing {
            path: self.path(key),
            expected,
        }
    }

    /// The field `key` converted by `read`, which hands back the value it refuses; `None`
    /// when absent or null.
    fn opt<T>(
        &mut self,
        key: &str,
        expected: &'static str,
        read: impl FnOnce(Value) -> Result<T, Value>,
    ) -> Result<Option<T>, ArgumentError> {
        match self.map.remove(key) {
            None | Some(Value::Null) => Ok(None),
            Some(v) => read(v).map(Some).map_err(|v| wrong(&self.path(key), expected, &v)),
        }
    }

    fn opt_i64(&mut self, key: &str) -> Result<Option<i64>, ArgumentError> {
        // `as_i64` is None for floats and for integers beyond i64, so no lossy cast.
        self.opt(key, "an integer", |v| v.as_i64().ok_or(v))
    }

    fn opt_usize(&mut self, key: &str) -> Result<Option<usize>, ArgumentError> {
        self.opt(key, "a non-negative integer", |v| {
            v.as_u64().and_then(|n| usize::try_from(n).ok()).ok_or(v)
        })
    }

    fn opt_bool(&mut self, key: &str) -> Result<Option<bool>, ArgumentError> {
        self.opt(key, "true or false", |v| v.as_bool().ok_or(v))
    }

    fn opt_string(&mut self, key: &str) -> Result<Option<String>, ArgumentError> {
        self.opt(key, "a string", |v| match v {
            Value::String(s) => Ok(s),
            other => Err(other),
        })
    }

    fn opt_array(&mut self, key: &str) -> Result<Option<Vec<Value>>, ArgumentError> {
        self.opt(key, "an array", |v| match v {
            Value::Array(items) => Ok(items),
            other => Err(other),
        })
    }

    fn opt_object(&mut self, key: &str) -> Result<Option<Fields>, ArgumentError> {
        let path = self.path(key);
        self.opt(key, "an object", |v| match v {
            Value::Object(map) => Ok(Fields { map, path }),
            other => Err(other),
        })
    }

    fn i64(&mut self, key: &str) -> Result<i64, ArgumentError> {
        self.opt_i64(key)?.ok_or_else(|| self.missing(key, "an integer"))
    }

    fn string(&mut self, key: &str) -> Result<String, ArgumentError> {
        self.opt_string(key)?.ok_or_else(|| self.missing(key, "a string"))
    }

    fn object(&mut self, key: &str) -> Result<Fields, ArgumentError> {
        self.opt_object(key)?.ok_or_else(|| self.missing(key, "an object"))
    }

    /// `threadId`, or 1 when absent: the simulation runs its scripts on one thread, so
    /// there is no other the client could mean.
    fn thread_id(&mut self) -> Result<i64, ArgumentError> {
        Ok(self.opt_i64("threadId")?.unwrap_or(1))
    }

    /// Converts each element of the array field `key` with `read`, which gets the
    /// element's path (`arguments.key[i]`) for its errors.
    fn each<T>(
        &self,
        key: &str,
        items: Vec<Value>,
        mut read: impl FnMut(Value, String) -> Result<T, ArgumentError>,
    ) -> Result<Vec<T>, ArgumentError> {
        let path = self.path(key);
        items
            .into_iter()
            .enumerate()
            .map(|(i, v)| read(v, format!("{path}[{i}]")))
            .collect()
    }
}

fn wrong(path: &str, expected: &'static str, got: &Value) -> ArgumentError {
    ArgumentError::Wrong {
        path: path.to_owned(),
        expected,
        got: describe(got),
    }
}

/// A short description of a JSON value for error messages: numbers and booleans in full
/// (for a number the value is the point: `3.5`, `-1`, `1e+300`), strings quoted up to
/// [`SNIPPET_LEN`] characters, containers by kind only.
fn describe(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(s) => format!("{:?}", snippet(s)),
        Value::Array(_) => "an array".into(),
        Value::Object(_) => "an object".into(),
    }
}

/// Outgoing messages. The transport numbers them (`seq`) in send order.
#[derive(Debug, Clone, PartialEq)]
pub enum Outgoing {
    /// The answer to one request.
    Response {
        /// The `seq` of the request answered (0 when it could not be identified).
        request_seq: i64,
        /// The request's command, echoed.
        command: String,
        /// Whether the request was carried out.
        success: bool,
        /// On failure, the reason in short form (clients may show or interpret it).
        message: Option<String>,
        /// The command-specific result; `Null` sends no body.
        body: Value,
    },
    /// Something the adapter reports unasked (`stopped`, `output`, `terminated`, ...).
    Event {
        /// The event's name.
        event: String,
        /// The event-specific data; `Null` sends no body.
        body: Value,
    },
}

impl Outgoing {
    /// A successful response to request `request_seq`; `body` may be `Null` for none.
    pub fn ok(request_seq: i64, command: &str, body: Value) -> Self {
        Outgoing::Response {
            request_seq,
            command: command.to_owned(),
            success: true,
            message: None,
            body,
        }
    }

    /// A failed response: `success` false, `message` set, and body
    /// `{"error": {"id": 1, "format": message}}`, DAP's `ErrorResponse`, which is what
    /// clients show the user.
    ///
    /// Clients substitute `{name}` in `format` from a `variables` map; none is sent, and
    /// VS Code leaves placeholders it cannot resolve as written, so braces in `message`
    /// are shown verbatim.
    pub fn error(request_seq: i64, command: &str, message: impl Into<String>) -> Self {
        let message = message.into();
        let body = serde_json::json!({"error": {"id": 1, "format": message}});
        Outgoing::Response {
            request_seq,
            command: command.to_owned(),
            success: false,
            message: Some(message),
            body,
        }
    }

    /// An event; `body` may be `Null` for none.
    pub fn event(event: &str, body: Value) -> Self {
        Outgoing::Event {
            event: event.to_owned(),
            body,
        }
    }

    /// The framed bytes: header + JSON with `"seq": seq, "type": "response"|"event"`.
    ///
    /// A `message` of `None` and a `Null` body are left out, as DAP marks both optional.
    pub fn encode(&self, seq: i64) -> Vec<u8> {
        let json = match self {
            Outgoing::Response {
                request_seq,
                command,
                success,
                message,
                body,
            } => serde_json::to_vec(&WireResponse {
                seq,
                kind: "response",
                request_seq: *request_seq,
                success: *success,
                command,
                message: message.as_deref(),
                body,
            }),
            Outgoing::Event { event, body } => serde_json::to_vec(&WireEvent {
                seq,
                kind: "event",
                event,
                body,
            }),
        };
        // serde_json refuses only non-string map keys and non-finite floats; a `Value`
        // holds neither (its maps are keyed by String, and it stores NaN as null), and
        // writing to a Vec cannot fail, so this is unreachable.
        let json = json.expect("a DAP message of strings, integers and Values always serializes");
        let mut out = format!("Content-Length: {}\r\n\r\n", json.len()).into_bytes();
        out.extend_from_slice(&json);
        out
    }
}

/// A response as sent, borrowing from [`Outgoing`] so encoding copies no body.
#[derive(Serialize)]
struct WireResponse<'a> {
    seq: i64,
    #[serde(rename = "type")]
    kind: &'static str,
    // DAP spells this one field in snake case.
    request_seq: i64,
    success: bool,
    command: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    message: Option<&'a str>,
    #[serde(skip_serializing_if = "is_null")]
    body: &'a Value,
}

/// An event as sent.
#[derive(Serialize)]
struct WireEvent<'a> {
    seq: i64,
    #[serde(rename = "type")]
    kind: &'static str,
    event: &'a str,
    #[serde(skip_serializing_if = "is_null")]
    body: &'a Value,
}

fn is_null(v: &&Value) -> bool {
    v.is_null()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Every command name the adapter types, as DAP spells it.
    const COMMANDS: [&str; 21] = [
        "initialize",
        "attach",
        "launch",
        "configurationDone",
        "setBreakpoints",
        "setExceptionBreakpoints",
        "threads",
        "stackTrace",
        "scopes",
        "variables",
        "evaluate",
        "setVariable",
        "continue",
        "next",
        "stepIn",
        "stepOut",
        "pause",
        "disconnect",
        "terminate",
        "loadedSources",
        "source",
    ];

    const INITIALIZE: &str = r#"{"seq":1,"type":"request","command":"initialize","arguments":{"clientID":"vscode","clientName":"Visual Studio Code","adapterID":"gantry","pathFormat":"path","linesStartAt1":true,"columnsStartAt1":true,"supportsVariableType":true,"locale":"en"}}"#;
    const SET_BREAKPOINTS: &str = r#"{"seq":4,"type":"request","command":"setBreakpoints","arguments":{"source":{"name":"arm.lua","path":"/scripts/arm.lua"},"lines":[3,10],"breakpoints":[{"line":3},{"line":10,"column":4,"condition":"x > 2","hitCondition":">= 3","logMessage":"x is {x}"}],"sourceModified":false}}"#;
    const THREADS: &str = r#"{"seq":2,"type":"request","command":"threads"}"#;

    /// `body` framed the way clients frame it.
    fn frame(body: &str) -> Vec<u8> {
        let mut f = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
        f.extend_from_slice(body.as_bytes());
        f
    }

    /// Feeds `chunks` to the decoder one after another, as a transport would (append,
    /// decode until `Ok(None)`, drop what was consumed); returns the bodies and what is
    /// left in the buffer.
    fn feed<'a>(chunks: impl IntoIterator<Item = &'a [u8]>) -> (Vec<Vec<u8>>, Vec<u8>) {
        let mut buf = Vec::new();
        let mut bodies = Vec::new();
        for chunk in chunks {
            buf.extend_from_slice(chunk);
            while let Some((body, consumed)) = decode_frame(&buf).unwrap() {
                bodies.push(body.to_vec());
                buf.drain(..consumed);
            }
        }
        (bodies, buf)
    }

    fn frame_error(bytes: &[u8]) -> FrameError {
        let e = decode_frame(bytes).expect_err(&String::from_utf8_lossy(bytes));
        assert!(!e.recoverable(), "{e:?}");
        e
    }

    /// Parses a request with `seq` 7 and these arguments (`Null`: no `arguments` key).
    fn request(command: &str, arguments: Value) -> Result<Command, MessageError> {
        let mut msg = json!({"seq": 7, "type": "request", "command": command});
        if !arguments.is_null() {
            msg["arguments"] = arguments;
        }
        parse_request(msg.to_string().as_bytes()).map(|r| {
            assert_eq!(r.seq, 7);
            r.command
        })
    }

    /// The `why` of the BadArguments that `command` with `arguments` must give.
    fn bad_arguments(command: &str, arguments: Value) -> String {
        match request(command, arguments) {
            Err(MessageError::BadArguments {
                seq: 7,
                command: c,
                why,
            }) if c == command => why,
            other => panic!("{command}: expected BadArguments, got {other:?}"),
        }
    }

    /// Parses an encoded message back: the frame must be whole and exactly the output.
    fn decode_own(bytes: &[u8]) -> Value {
        let (body, consumed) = decode_frame(bytes).unwrap().unwrap();
        assert_eq!(consumed, bytes.len());
        serde_json::from_slice(body).unwrap()
    }

    #[test]
    fn split_at_every_point() {
        let (a, b) = (frame(INITIALIZE), frame(THREADS));
        let stream = [a.as_slice(), b.as_slice()].concat();
        let want = [INITIALIZE.as_bytes().to_vec(), THREADS.as_bytes().to_vec()];
        for k in 0..=stream.len() {
            let (head, tail) = stream.split_at(k);
            // What is whole in the first read comes out, the rest waits.
            let (bodies, _) = feed([head]);
            assert_eq!(
                bodies.len(),
                usize::from(k >= a.len()) + usize::from(k == stream.len()),
                "split {k}"
            );
            let (bodies, rest) = feed([head, tail]);
            assert_eq!(bodies, want, "split {k}");
            assert!(rest.is_empty());
        }
        let (bodies, rest) = feed(stream.chunks(1));
        assert_eq!(bodies, want);
        assert!(rest.is_empty());
    }

    #[test]
    fn two_frames_back_to_back() {
        let (a, b) = (frame(INITIALIZE), frame(THREADS));
        let stream = [a.as_slice(), b.as_slice(), b"Content-Le"].concat();
        let (body, consumed) = decode_frame(&stream).unwrap().unwrap();
        assert_eq!((body, consumed), (INITIALIZE.as_bytes(), a.len()));
        let rest = &stream[consumed..];
        let (body, consumed) = decode_frame(rest).unwrap().unwrap();
        assert_eq!((body, consumed), (THREADS.as_bytes(), b.len()));
        assert_eq!(decode_frame(&rest[consumed..]), Ok(None));
    }

    #[test]
    fn extra_headers_and_any_case() {
        for header in [
            "Content-Type: application/vscode-jsonrpc; charset=utf-8\r\nContent-Length: 2\r\n",
            "content-length: 2\r\n",
            "CONTENT-LENGTH:2\r\n",
            "Content-Length: \t2 \r\nX-Empty:\r\nX-Odd: caf\u{e9} :: \r\n",
            "Content-Length: 0002\r\n",
        ] {
            let bytes = format!("{header}\r\n{{}}Content-Length: 1");
            let got = decode_frame(bytes.as_bytes()).unwrap();
            assert_eq!(got, Some((&b"{}"[..], header.len() + 4)), "{header:?}");
        }
        let empty = b"Content-Length: 0\r\n\r\n";
        assert_eq!(decode_frame(empty), Ok(Some((&b""[..], empty.len()))));
    }

    #[test]
    fn missing_length() {
        assert_eq!(frame_error(b"Content-Type: x\r\n\r\n{}"), FrameError::MissingLength);
        assert_eq!(frame_error(b"\r\n{}"), FrameError::MissingLength);
    }

    #[test]
    fn non_numeric_length() {
        for value in ["abc", "+2", "-1", "2.0", "0x10", "1 2", "", "\u{663}"] {
            let bytes = format!("Content-Length: {value}\r\n\r\n{{}}");
            assert_eq!(
                frame_error(bytes.as_bytes()),
                FrameError::BadLength { value: value.into() },
                "{value:?}"
            );
        }
    }

    #[test]
    fn huge_length_refused_before_the_body() {
        // No body follows: the refusal must not wait for it.
        let e = frame_error(b"Content-Length: 99999999999\r\n\r\n");
        assert_eq!(e, FrameError::TooLarge { length: 99_999_999_999 });
        assert!(e.to_string().contains("99999999999"), "{e}");
        // Lines are checked as they complete, so not even the blank line is needed.
        assert_eq!(frame_error(b"Content-Length: 99999999999\r\n"), e);
        // Beyond u64: still a length, saturated.
        assert_eq!(
            frame_error(b"Content-Length: 123456789012345678901234567890\r\n"),
            FrameError::TooLarge { length: u64::MAX }
        );
        let at_limit = format!("Content-Length: {MAX_BODY}\r\n\r\n");
        assert_eq!(decode_frame(at_limit.as_bytes()), Ok(None));
        let over = format!("Content-Length: {}\r\n\r\n", MAX_BODY + 1);
        assert_eq!(
            frame_error(over.as_bytes()),
            FrameError::TooLarge {
                length: MAX_BODY as u64 + 1
            }
        );
    }

    #[test]
    fn header_too_long() {
        // A header of exactly MAX_HEADER bytes, blank line included, is accepted...
        let start = "Content-Length: 2\r\nX-Pad: ";
        let pad = "a".repeat(MAX_HEADER - start.len() - 4);
        let header = format!("{start}{pad}\r\n\r\n");
        assert_eq!(header.len(), MAX_HEADER);
        let bytes = format!("{header}{{}}");
        assert_eq!(decode_frame(bytes.as_bytes()), Ok(Some((&b"{}"[..], MAX_HEADER + 2))));
        // ...one byte more is not, and is refused once MAX_HEADER bytes are in.
        let bytes = format!("{start}{pad}a\r\n\r\n{{}}");
        assert_eq!(frame_error(bytes.as_bytes()), FrameError::HeaderTooLong);
        assert_eq!(frame_error(&bytes.as_bytes()[..MAX_HEADER]), FrameError::HeaderTooLong);
        assert_eq!(decode_frame(&bytes.as_bytes()[..MAX_HEADER - 1]), Ok(None));
        // A peer that never sends a line end is cut off too.
        assert_eq!(frame_error(&[b'a'; 5000]), FrameError::HeaderTooLong);
    }

    #[test]
    fn garbled_header_lines() {
        for (line, quoted) in [
            ("Content-Length 2", "Content-Length 2"),
            ("Content-Length : 2", "Content-Length : 2"),
            (": 2", ": 2"),
            // A body sent without a header.
            (
                r#"{"seq":1,"type":"request","command":"threads","arguments":{}}"#,
                r#"{"seq":1,"type":"request","command":"thr"#,
            ),
        ] {
            let bytes = format!("{line}\r\n");
            assert_eq!(
                frame_error(bytes.as_bytes()),
                FrameError::MalformedHeaderLine { line: quoted.into() },
                "{line:?}"
            );
        }
        assert_eq!(
            frame_error(b"X-\xff: 1\r\nContent-Length: 2\r\n\r\n{}"),
            FrameError::HeaderNotUtf8
        );
        assert_eq!(
            frame_error(b"Content-Length: 2\r\ncontent-length: 2\r\n\r\n{}"),
            FrameError::DuplicateLength
        );
        // DAP lines end in CRLF; a bare LF is part of the line, so this is still waiting.
        assert_eq!(decode_frame(b"Content-Length: 2\n\n{}"), Ok(None));
    }

    #[test]
    fn malformed_bodies() {
        let deep = "[".repeat(100_000);
        for (body, says) in [
            ("{", "not valid JSON"),
            ("", "not valid JSON"),
            ("\u{feff}{}", "not valid JSON"),
            (r#"{"seq":1,"type":"request","command":"threads"} x"#, "not valid JSON"),
            (&deep, "recursion limit"),
            ("[1]", "must be a JSON object, got an array"),
            (
                r#"{"seq":1,"type":"response","command":"threads"}"#,
                r#""response" is not accepted"#,
            ),
            (
                r#"{"seq":1,"type":"event","event":"stopped"}"#,
                r#""event" is not accepted"#,
            ),
            (
                r#"{"seq":1,"type":1,"command":"threads"}"#,
                r#""type" must be "request", got 1"#,
            ),
            (r#"{"seq":1,"command":"threads"}"#, r#"no "type""#),
            (r#"{"type":"request","command":"threads"}"#, r#"no "seq""#),
            (
                r#"{"seq":"1","type":"request","command":"threads"}"#,
                r#""seq" must be an integer, got "1""#,
            ),
            (r#"{"seq":1.5,"type":"request","command":"threads"}"#, "got 1.5"),
            (r#"{"seq":1e300,"type":"request","command":"threads"}"#, "got 1e+300"),
            (
                r#"{"seq":9223372036854775808,"type":"request","command":"threads"}"#,
                "got 9223372036854775808",
            ),
            (r#"{"seq":1,"type":"request"}"#, r#"no "command""#),
            (
                r#"{"seq":1,"type":"request","command":null}"#,
                r#""command" must be a string, got null"#,
            ),
        ] {
            match parse_request(body.as_bytes()) {
                Err(MessageError::Malformed(m)) => assert!(m.contains(says), "{m:?} should say {says:?}"),
                other => panic!("{body:.60}: {other:?}"),
            }
        }
        assert!(matches!(parse_request(b"\xff"), Err(MessageError::Malformed(_))));
    }

    #[test]
    fn unknown_command() {
        assert_eq!(
            request("stepBack", Value::Null),
            Ok(Command::Unknown("stepBack".into()))
        );
        // Names match exactly: DAP's are camelCase.
        assert_eq!(
            request("Initialize", json!({})),
            Ok(Command::Unknown("Initialize".into()))
        );
        // Its arguments are not ours to judge.
        assert_eq!(
            request("restartFrame", json!(5)),
            Ok(Command::Unknown("restartFrame".into()))
        );
        assert_eq!(Command::Unknown("restartFrame".into()).name(), "restartFrame");
    }

    #[test]
    fn set_breakpoints_with_conditions() {
        let req = parse_request(SET_BREAKPOINTS.as_bytes()).unwrap();
        assert_eq!(req.seq, 4);
        assert_eq!(
            req.command,
            Command::SetBreakpoints {
                source: Source {
                    name: Some("arm.lua".into()),
                    path: Some("/scripts/arm.lua".into()),
                    source_reference: None,
                },
                breakpoints: vec![
                    SourceBreakpoint {
                        line: 3,
                        condition: None,
                        hit_condition: None,
                        log_message: None,
                    },
                    SourceBreakpoint {
                        line: 10,
                        condition: Some("x > 2".into()),
                        hit_condition: Some(">= 3".into()),
                        log_message: Some("x is {x}".into()),
                    },
                ],
            }
        );
    }

    #[test]
    fn set_breakpoints_old_and_empty_forms() {
        let line = |line| SourceBreakpoint {
            line,
            condition: None,
            hit_condition: None,
            log_message: None,
        };
        let source = Source {
            source_reference: Some(3),
            ..Source::default()
        };
        assert_eq!(
            request(
                "setBreakpoints",
                json!({"source": {"sourceReference": 3}, "lines": [5, 8]})
            ),
            Ok(Command::SetBreakpoints {
                source: source.clone(),
                breakpoints: vec![line(5), line(8)],
            })
        );
        // No breakpoints: clear them all.
        assert_eq!(
            request("setBreakpoints", json!({"source": {"sourceReference": 3}})),
            Ok(Command::SetBreakpoints {
                source,
                breakpoints: vec![],
            })
        );
    }

    #[test]
    fn every_command() {
        let cases = [
            (
                "initialize",
                json!({"adapterID": "gantry", "clientName": "nvim-dap", "linesStartAt1": false, "columnsStartAt1": false}),
                Command::Initialize {
                    client_name: Some("nvim-dap".into()),
                    lines_start_at1: false,
                    columns_start_at1: false,
                },
            ),
            ("attach", json!({"port": 23000, "__sessionId": "x"}), Command::Attach),
            ("launch", json!({"noDebug": true}), Command::Launch),
            ("configurationDone", Value::Null, Command::ConfigurationDone),
            (
                "setExceptionBreakpoints",
                json!({"filters": ["error"], "filterOptions": []}),
                Command::SetExceptionBreakpoints {
                    filters: vec!["error".into()],
                },
            ),
            ("threads", Value::Null, Command::Threads),
            (
                "stackTrace",
                json!({"threadId": 1, "startFrame": 20, "levels": 20, "format": {}}),
                Command::StackTrace {
                    thread_id: 1,
                    start_frame: 20,
                    levels: Some(20),
                },
            ),
            ("scopes", json!({"frameId": 1000}), Command::Scopes { frame_id: 1000 }),
            (
                "variables",
                json!({"variablesReference": 12, "filter": "indexed", "start": 100, "count": 50}),
                Command::Variables {
                    variables_reference: 12,
                    start: Some(100),
                    count: Some(50),
                },
            ),
            (
                "evaluate",
                json!({"expression": "sim.getObject('/arm')", "frameId": 1000, "context": "repl"}),
                Command::Evaluate {
                    expression: "sim.getObject('/arm')".into(),
                    frame_id: Some(1000),
                    context: Some("repl".into()),
                },
            ),
            (
                "setVariable",
                json!({"variablesReference": 12, "name": "speed", "value": "0.5"}),
                Command::SetVariable {
                    variables_reference: 12,
                    name: "speed".into(),
                    value: "0.5".into(),
                },
            ),
            ("continue", json!({"threadId": 1}), Command::Continue { thread_id: 1 }),
            (
                "next",
                json!({"threadId": 2, "granularity": "line"}),
                Command::Next { thread_id: 2 },
            ),
            ("stepIn", json!({"threadId": 3}), Command::StepIn { thread_id: 3 }),
            ("stepOut", json!({"threadId": -4}), Command::StepOut { thread_id: -4 }),
            ("pause", json!({"threadId": 5}), Command::Pause { thread_id: 5 }),
            (
                "disconnect",
                json!({"restart": false, "terminateDebuggee": true}),
                Command::Disconnect {
                    terminate_debuggee: true,
                },
            ),
            ("terminate", json!({"restart": false}), Command::Terminate),
            ("loadedSources", json!({}), Command::LoadedSources),
            (
                "source",
                json!({"source": {"path": "/scripts/arm.lua", "sourceReference": 9}, "sourceReference": 9}),
                Command::Source {
                    source_reference: 9,
                    path: Some("/scripts/arm.lua".into()),
                },
            ),
        ];
        for (name, args, want) in cases {
            assert_eq!(request(name, args), Ok(want.clone()), "{name}");
            assert_eq!(want.name(), name);
        }
    }

    #[test]
    fn names_agree_with_the_parser() {
        // Every known name parses to its own variant (or, lacking required arguments, to
        // BadArguments naming it), never to Unknown.
        for name in COMMANDS {
            match request(
                name,
                json!({"source": {}, "filters": [], "frameId": 1, "variablesReference": 1, "expression": "x", "name": "x", "value": "1", "sourceReference": 1}),
            ) {
                Ok(c) => assert_eq!(c.name(), name),
                other => panic!("{name}: {other:?}"),
            }
        }
    }

    #[test]
    fn defaults() {
        assert_eq!(
            request("initialize", Value::Null),
            Ok(Command::Initialize {
                client_name: None,
                lines_start_at1: true,
                columns_start_at1: true,
            })
        );
        let all_frames = Command::StackTrace {
            thread_id: 1,
            start_frame: 0,
            levels: None,
        };
        assert_eq!(request("stackTrace", Value::Null), Ok(all_frames.clone()));
        assert_eq!(request("stackTrace", json!({"levels": 0})), Ok(all_frames.clone()));
        // Null is absent.
        assert_eq!(
            request(
                "stackTrace",
                json!({"threadId": null, "startFrame": null, "levels": null})
            ),
            Ok(all_frames)
        );
        assert_eq!(request("continue", Value::Null), Ok(Command::Continue { thread_id: 1 }));
        assert_eq!(request("pause", json!(null)), Ok(Command::Pause { thread_id: 1 }));
        assert_eq!(
            request("disconnect", Value::Null),
            Ok(Command::Disconnect {
                terminate_debuggee: false
            })
        );
        assert_eq!(
            request("variables", json!({"variablesReference": 3, "count": 0})),
            Ok(Command::Variables {
                variables_reference: 3,
                start: None,
                count: None,
            })
        );
        assert_eq!(
            request("evaluate", json!({"expression": "x"})),
            Ok(Command::Evaluate {
                expression: "x".into(),
                frame_id: None,
                context: None,
            })
        );
        // Only the nested reference given: it is the same value, so it is used.
        assert_eq!(
            request("source", json!({"source": {"sourceReference": 4}})),
            Ok(Command::Source {
                source_reference: 4,
                path: None,
            })
        );
    }

    #[test]
    fn bad_arguments_name_the_field() {
        for (command, args, why) in [
            ("setBreakpoints", json!({}), "arguments.source is required (an object)"),
            (
                "setBreakpoints",
                Value::Null,
                "arguments.source is required (an object)",
            ),
            (
                "setBreakpoints",
                json!({"source": {}, "breakpoints": [{"line": 1}, {"condition": "x"}]}),
                "arguments.breakpoints[1].line is required (an integer)",
            ),
            (
                "setBreakpoints",
                json!({"source": {}, "breakpoints": [{"line": "3"}]}),
                r#"arguments.breakpoints[0].line must be an integer, got "3""#,
            ),
            (
                "setBreakpoints",
                json!({"source": {}, "breakpoints": [{"line": 3, "logMessage": 3}]}),
                "arguments.breakpoints[0].logMessage must be a string, got 3",
            ),
            (
                "setBreakpoints",
                json!({"source": "arm.lua"}),
                r#"arguments.source must be an object, got "arm.lua""#,
            ),
            (
                "setBreakpoints",
                json!({"source": {"path": ["a"]}}),
                "arguments.source.path must be a string, got an array",
            ),
            (
                "setBreakpoints",
                json!({"source": {}, "breakpoints": {}}),
                "arguments.breakpoints must be an array, got an object",
            ),
            (
                "setBreakpoints",
                json!({"source": {}, "breakpoints": [7]}),
                "arguments.breakpoints[0] must be an object, got 7",
            ),
            (
                "setBreakpoints",
                json!({"source": {}, "lines": [1, "2"]}),
                r#"arguments.lines[1] must be an integer, got "2""#,
            ),
            (
                "stackTrace",
                json!({"threadId": 1e300}),
                "arguments.threadId must be an integer, got 1e+300",
            ),
            (
                "stackTrace",
                json!({"startFrame": -1}),
                "arguments.startFrame must be a non-negative integer, got -1",
            ),
            ("scopes", json!({}), "arguments.frameId is required (an integer)"),
            ("scopes", Value::Null, "arguments.frameId is required (an integer)"),
            (
                "variables",
                json!({"variablesReference": 3.0}),
                "arguments.variablesReference must be an integer, got 3.0",
            ),
            (
                "variables",
                json!({"variablesReference": u64::MAX}),
                "arguments.variablesReference must be an integer, got 18446744073709551615",
            ),
            (
                "evaluate",
                json!({"expression": null}),
                "arguments.expression is required (a string)",
            ),
            (
                "setVariable",
                json!({"variablesReference": 1, "name": "x"}),
                "arguments.value is required (a string)",
            ),
            (
                "setExceptionBreakpoints",
                json!({}),
                "arguments.filters is required (an array of strings)",
            ),
            (
                "setExceptionBreakpoints",
                json!({"filters": ["raised", 1]}),
                "arguments.filters[1] must be a string, got 1",
            ),
            ("continue", json!([1]), "arguments must be an object, got an array"),
            (
                "disconnect",
                json!({"terminateDebuggee": "yes"}),
                r#"arguments.terminateDebuggee must be true or false, got "yes""#,
            ),
            (
                "initialize",
                json!({"linesStartAt1": 0}),
                "arguments.linesStartAt1 must be true or false, got 0",
            ),
            (
                "source",
                json!({"source": {"path": "/a.lua"}}),
                "arguments.sourceReference is required (an integer)",
            ),
        ] {
            assert_eq!(bad_arguments(command, args), why, "{command}");
        }
        let e = MessageError::BadArguments {
            seq: 7,
            command: "scopes".into(),
            why: "arguments.frameId is required (an integer)".into(),
        };
        assert_eq!(
            e.to_string(),
            r#"bad arguments to "scopes": arguments.frameId is required (an integer)"#
        );
    }

    #[test]
    fn response_round_trip() {
        let body = json!({"threads": [{"id": 1, "name": "sim"}]});
        let bytes = Outgoing::ok(5, "threads", body.clone()).encode(12);
        assert_eq!(
            decode_own(&bytes),
            json!({"seq": 12, "type": "response", "request_seq": 5, "success": true, "command": "threads", "body": body})
        );
        // No body: no `body` key (nor `message`).
        let bytes = Outgoing::ok(6, "configurationDone", Value::Null).encode(13);
        assert_eq!(
            decode_own(&bytes),
            json!({"seq": 13, "type": "response", "request_seq": 6, "success": true, "command": "configurationDone"})
        );
    }

    #[test]
    fn error_response_round_trip() {
        let msg = "no variable named {speed} in \"arm\"";
        let bytes = Outgoing::error(9, "evaluate", msg).encode(1);
        assert_eq!(
            decode_own(&bytes),
            json!({
                "seq": 1, "type": "response", "request_seq": 9, "success": false, "command": "evaluate",
                "message": msg, "body": {"error": {"id": 1, "format": msg}},
            })
        );
    }

    #[test]
    fn event_round_trip() {
        let body = json!({"category": "stdout", "output": "caf\u{e9} \u{1f916} \"ok\"\n"});
        let bytes = Outgoing::event("output", body.clone()).encode(3);
        // The length counts bytes, not characters.
        let text = std::str::from_utf8(&bytes).unwrap();
        let (header, json_text) = text.split_once("\r\n\r\n").unwrap();
        assert_eq!(header, format!("Content-Length: {}", json_text.len()));
        assert_ne!(json_text.len(), json_text.chars().count());
        assert_eq!(
            decode_own(&bytes),
            json!({"seq": 3, "type": "event", "event": "output", "body": body})
        );
        let bytes = Outgoing::event("initialized", Value::Null).encode(4);
        assert_eq!(
            decode_own(&bytes),
            json!({"seq": 4, "type": "event", "event": "initialized"})
        );
    }

    /// The decoder's contracts on one buffer, frame after frame: a prefix of any length
    /// gives "need more" or the whole buffer's answer (so the result never depends on how
    /// reads split the stream), and a frame's body is the tail of what it consumes.
    fn check_stream(buf: &[u8]) {
        let mut rest = buf;
        loop {
            let whole = decode_frame(rest);
            for k in 0..rest.len() {
                let part = decode_frame(&rest[..k]);
                assert!(part == Ok(None) || part == whole, "{part:?} vs {whole:?} at {k}");
                if let Ok(Some((_, consumed))) = whole {
                    assert_eq!(part == Ok(None), k < consumed);
                }
            }
            let Ok(Some((body, consumed))) = whole else {
                return;
            };
            assert!(body.len() <= MAX_BODY && body.len() < consumed && consumed <= rest.len());
            assert_eq!(body, &rest[consumed - body.len()..consumed]);
            check_request(body);
            rest = &rest[consumed..];
        }
    }

    /// `parse_request` agrees with serde_json's own reading of `body`: Ok and BadArguments
    /// exactly when it is an object with `"type": "request"`, an i64 `seq` and a string
    /// `command`, both echoed; BadArguments only for known commands.
    fn check_request(body: &[u8]) {
        let json: Option<Value> = serde_json::from_slice(body).ok();
        let field = |k| json.as_ref().and_then(|j| j.get(k));
        let seq = field("seq").and_then(Value::as_i64);
        let command = field("command").and_then(Value::as_str);
        let identified = field("type").and_then(Value::as_str) == Some("request") && seq.is_some() && command.is_some();
        match parse_request(body) {
            Ok(req) => {
                assert!(identified);
                assert_eq!((Some(req.seq), Some(req.command.name())), (seq, command));
            }
            Err(MessageError::BadArguments { seq: s, command: c, .. }) => {
                assert!(identified);
                assert_eq!((Some(s), Some(c.as_str())), (seq, command));
                assert!(COMMANDS.contains(&c.as_str()), "{c}");
            }
            Err(MessageError::Malformed(_)) => assert!(!identified),
        }
    }

    #[test]
    fn every_one_byte_edit_of_a_stream() {
        // Exhaustive over one-byte edits (replace, insert, delete) of a two-frame stream,
        // with bytes that matter to the header and to JSON; check_stream covers every
        // truncation of each.
        let stream = [
            b"content-type: x\r\ncontent-length: 47\r\n\r\n".as_slice(),
            THREADS.as_bytes(),
            &frame(r#"{"seq":3,"type":"request","command":"stackTrace","arguments":{"threadId":1,"levels":2}}"#),
        ]
        .concat();
        let alphabet = b"\r\n: 09aC{}[]\",\xff";
        for i in 0..=stream.len() {
            for &b in alphabet {
                let mut edited = stream.clone();
                edited.insert(i, b);
                check_stream(&edited);
                if i < stream.len() {
                    edited.remove(i);
                    edited[i] = b;
                    check_stream(&edited);
                }
            }
            if i < stream.len() {
                let mut edited = stream.clone();
                edited.remove(i);
                check_stream(&edited);
            }
        }
    }

    #[test]
    fn every_one_byte_edit_of_a_request() {
        let alphabet = b"\"{}[],:-.019etnrx \\\xff";
        for body in [INITIALIZE, SET_BREAKPOINTS] {
            let body = body.as_bytes();
            for i in 0..body.len() {
                for &b in alphabet {
                    let mut edited = body.to_vec();
                    edited[i] = b;
                    check_request(&edited);
                }
                check_request(&[&body[..i], &body[i + 1..]].concat());
            }
        }
    }
}
