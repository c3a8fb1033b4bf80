//! The Debug Adapter Protocol listener (`gantry run --debug[=PORT]`): any DAP client
//! (VS Code, nvim-dap, dap-mode, Zed, JetBrains) attaches over TCP and debugs the
//! scene's Lua scripts.
//!
//! This module only translates: frames are decoded by `gantry_protocol::dap` (pure,
//! bounded, fuzzed), requests become [`DebugRequest`]s for the debugger inside the Lua
//! host (`gantry_lua::debugger`), its answers and events become DAP JSON.
//!
//! One client at a time: two editors stepping the same simulation would fight. DAP
//! threads: there is one, "simulation" (id 1), because every script runs on the one
//! simulation thread and all of them stop together; the stack shows which script and
//! hook stopped.

use std::path::PathBuf;

use gantry_lua::debugger::{BreakpointSpec, StopReason};
use gantry_lua::{DebugEvent, DebugReply, DebugRequest};
use gantry_protocol::dap::{self, Command, FrameError, MessageError, Outgoing};
use serde_json::{Value as Json, json};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{broadcast, watch};

use crate::debug::{DebugError, DebugHub, display_name};

/// The one DAP thread.
const THREAD_ID: i64 = 1;

/// Accepts DAP clients until shutdown.
pub async fn serve(listener: TcpListener, hub: DebugHub, mut shutdown: watch::Receiver<bool>) {
    loop {
        tokio::select! {
            _ = shutdown.changed() => break,
            accepted = listener.accept() => match accepted {
                Ok((sock, peer)) => {
                    let _ = sock.set_nodelay(true);
                    let hub = hub.clone();
                    let shutdown = shutdown.clone();
                    tokio::spawn(async move {
                        if hub.claim_client() {
                            tracing::info!("debugger attached from {peer}");
                            Session::new(sock, hub.clone()).run(shutdown).await;
                            // Whatever way the client left, the scripts run on free.
                            let _ = hub.request(DebugRequest::Detach).await;
                            hub.release_client();
                            tracing::info!("debugger from {peer} detached");
                        } else {
                            refuse(sock).await;
                        }
                    });
                }
                Err(e) => {
                    tracing::warn!("debugger: accept failed: {e}");
                    tokio::time::sleep(std::time::Duration::from_millis(100)).await;
                }
            }
        }
    }
}

/// Answers a second client's first request with an error, then closes.
async fn refuse(mut sock: TcpStream) {
    let mut buf = vec![0u8; 4096];
    let seq = match tokio::time::timeout(std::time::Duration::from_secs(5), sock.read(&mut buf)).await {
        Ok(Ok(n)) => dap::decode_frame(&buf[..n])
            .ok()
            .flatten()
            .and_then(|(body, _)| dap::parse_request(body).ok())
            .map_or(0, |r| r.seq),
        _ => 0,
    };
    let msg = Outgoing::error(
        seq,
        "",
        "another debugger client is attached to this gantry; detach it first",
    );
    let _ = sock.write_all(&msg.encode(1)).await;
}

/// One client's connection.
struct Session {
    sock: TcpStream,
    hub: DebugHub,
    events: broadcast::Receiver<DebugEvent>,
    seq: i64,
    /// The client counts lines from 0 (`linesStartAt1: false`).
    zero_based: bool,
}

/// What to do after a request.
enum Next {
    Go,
    Close,
}

impl Session {
    fn new(sock: TcpStream, hub: DebugHub) -> Self {
        let events = hub.subscribe();
        Self {
            sock,
            hub,
            events,
            seq: 0,
            zero_based: false,
        }
    }

    async fn run(mut self, mut shutdown: watch::Receiver<bool>) {
        let mut buf: Vec<u8> = Vec::with_capacity(4096);
        let mut chunk = vec![0u8; 16 * 1024];
        loop {
            // Whole frames already buffered first.
            loop {
                match dap::decode_frame(&buf) {
                    Ok(None) => break,
                    Ok(Some((body, used))) => {
                        let parsed = dap::parse_request(body);
                        buf.drain(..used);
                        if let Next::Close = self.handle(parsed).await {
                            return;
                        }
                    }
                    Err(e) => {
                        // The framing is lost (see FrameError::recoverable): answer, close.
                        self.frame_error(&e).await;
                        if !e.recoverable() {
                            return;
                        }
                        buf.clear();
                    }
                }
            }
            tokio::select! {
                _ = shutdown.changed() => return,
                read = self.sock.read(&mut chunk) => match read {
                    Ok(0) | Err(_) => return,
                    Ok(n) => buf.extend_from_slice(&chunk[..n]),
                },
                event = self.events.recv() => match event {
                    Ok(e) => {
                        if self.event(e).await.is_err() {
                            return;
                        }
                    }
                    Err(broadcast::error::RecvError::Lagged(n)) => {
                        tracing::warn!("debugger: the client missed {n} events");
                    }
                    Err(broadcast::error::RecvError::Closed) => return,
                },
            }
        }
    }

    async fn send(&mut self, msg: Outgoing) -> std::io::Result<()> {
        self.seq += 1;
        self.sock.write_all(&msg.encode(self.seq)).await
    }

    async fn frame_error(&mut self, e: &FrameError) {
        let _ = self.send(Outgoing::error(0, "", format!("bad DAP frame: {e}"))).await;
    }

    /// Line numbers as the client counts them.
    fn out_line(&self, line: u32) -> i64 {
        i64::from(line) - i64::from(self.zero_based)
    }

    fn in_line(&self, line: i64) -> u32 {
        u32::try_from(line + i64::from(self.zero_based)).unwrap_or(0)
    }

    async fn event(&mut self, e: DebugEvent) -> std::io::Result<()> {
        let msg = match e {
            DebugEvent::Stopped {
                reason,
                text,
                path,
                line,
            } => {
                let description = match reason {
                    StopReason::Breakpoint => "Paused on breakpoint".to_owned(),
                    StopReason::Step => "Paused after a step".to_owned(),
                    StopReason::Pause => "Paused".to_owned(),
                    StopReason::Exception => "Paused on a script error".to_owned(),
                };
                let mut body = json!({
                    "reason": reason.as_str(),
                    "threadId": THREAD_ID,
                    "allThreadsStopped": true,
                    "description": format!("{description} at {}:{line}", display_name(&path)),
                });
                if let Some(t) = text {
                    body["text"] = Json::String(t);
                }
                Outgoing::event("stopped", body)
            }
            DebugEvent::Continued => {
                Outgoing::event("continued", json!({"threadId": THREAD_ID, "allThreadsContinued": true}))
            }
            DebugEvent::Output { text, path, line } => Outgoing::event(
                "output",
                json!({
                    "category": "console",
                    "output": format!("{text}\n"),
                    "source": source_json(&path),
                    "line": self.out_line(line),
                }),
            ),
        };
        self.send(msg).await
    }

    async fn handle(&mut self, parsed: Result<dap::Request, MessageError>) -> Next {
        let request = match parsed {
            Ok(r) => r,
            Err(MessageError::Malformed(why)) => {
                let _ = self
                    .send(Outgoing::error(0, "", format!("malformed DAP message: {why}")))
                    .await;
                return Next::Go;
            }
            Err(MessageError::BadArguments { seq, command, why }) => {
                let _ = self
                    .send(Outgoing::error(
                        seq,
                        &command,
                        format!("bad arguments to '{command}': {why}"),
                    ))
                    .await;
                return Next::Go;
            }
        };
        let seq = request.seq;
        let name = request.command.name().to_owned();
        let (result, next) = self.answer(request.command).await;
        let msg = match result {
            Ok(body) => Outgoing::ok(seq, &name, body),
            Err(e) => Outgoing::error(seq, &name, e.to_string()),
        };
        if self.send(msg).await.is_err() {
            return Next::Close;
        }
        if name == "initialize" {
            // The client may configure breakpoints from now on.
            let _ = self.send(Outgoing::event("initialized", Json::Null)).await;
        }
        next
    }

    async fn ask(&self, request: DebugRequest) -> Result<DebugReply, DebugError> {
        self.hub.request(request).await
    }

    async fn answer(&mut self, command: Command) -> (Result<Json, DapError>, Next) {
        let done = |r: Result<DebugReply, DebugError>| r.map(|_| Json::Null).map_err(DapError::from);
        let result = match command {
            Command::Initialize { lines_start_at1, .. } => {
                self.zero_based = !lines_start_at1;
                Ok(capabilities())
            }
            Command::Attach | Command::Launch => done(self.ask(DebugRequest::Attach).await),
            Command::ConfigurationDone => Ok(Json::Null),
            Command::SetBreakpoints { source, breakpoints } => {
                let Some(path) = source.path.clone() else {
                    return (Err(DapError::NoSourcePath), Next::Go);
                };
                let specs: Vec<BreakpointSpec> = breakpoints
                    .iter()
                    .map(|b| BreakpointSpec {
                        line: self.in_line(b.line),
                        condition: b.condition.clone(),
                        hit_condition: b.hit_condition.clone(),
                        log_message: b.log_message.clone(),
                    })
                    .collect();
                match self
                    .ask(DebugRequest::SetBreakpoints {
                        path: PathBuf::from(path),
                        breakpoints: specs,
                    })
                    .await
                {
                    Ok(DebugReply::Breakpoints(list)) => {
                        let list: Vec<Json> = list
                            .iter()
                            .map(|b| {
                                let mut v = json!({"verified": b.verified, "line": self.out_line(b.line)});
                                if let Some(m) = &b.message {
                                    v["message"] = Json::String(m.clone());
                                }
                                v
                            })
                            .collect();
                        Ok(json!({ "breakpoints": list }))
                    }
                    other => unexpected(other),
                }
            }
            Command::SetExceptionBreakpoints { filters } => done(
                self.ask(DebugRequest::BreakOnError(filters.iter().any(|f| f == "error")))
                    .await,
            ),
            Command::Threads => Ok(json!({"threads": [{"id": THREAD_ID, "name": "simulation"}]})),
            Command::StackTrace {
                start_frame, levels, ..
            } => match self.ask(DebugRequest::StackTrace).await {
                Ok(DebugReply::Frames(frames)) => {
                    let total = frames.len();
                    let take = levels.filter(|&l| l > 0).unwrap_or(usize::MAX);
                    let list: Vec<Json> = frames
                        .iter()
                        .skip(start_frame)
                        .take(take)
                        .map(|f| {
                            json!({
                                "id": f.id,
                                "name": f.name,
                                "source": source_json(&f.path),
                                "line": self.out_line(f.line),
                                "column": i64::from(!self.zero_based),
                            })
                        })
                        .collect();
                    Ok(json!({"stackFrames": list, "totalFrames": total}))
                }
                other => unexpected(other),
            },
            Command::Scopes { frame_id } => {
                let frame = usize::try_from(frame_id).unwrap_or(0);
                match self.ask(DebugRequest::Scopes { frame }).await {
                    Ok(DebugReply::Scopes(scopes)) => {
                        let list: Vec<Json> = scopes
                            .iter()
                            .map(|s| {
                                json!({
                                    "name": s.name,
                                    "variablesReference": s.reference,
                                    "expensive": false,
                                    "presentationHint": if s.name == "Locals" { "locals" } else { "" },
                                })
                            })
                            .collect();
                        Ok(json!({ "scopes": list }))
                    }
                    other => unexpected(other),
                }
            }
            Command::Variables {
                variables_reference,
                start,
                count,
            } => match self
                .ask(DebugRequest::Variables {
                    reference: variables_reference,
                })
                .await
            {
                Ok(DebugReply::Variables(vars)) => {
                    let list: Vec<Json> = vars
                        .iter()
                        .skip(start.unwrap_or(0))
                        .take(count.filter(|&c| c > 0).unwrap_or(usize::MAX))
                        .map(|v| {
                            json!({
                                "name": v.name,
                                "value": v.value,
                                "type": v.type_name,
                                "variablesReference": v.reference,
                            })
                        })
                        .collect();
                    Ok(json!({ "variables": list }))
                }
                other => unexpected(other),
            },
            Command::Evaluate {
                expression, frame_id, ..
            } => {
                let frame = frame_id.and_then(|f| usize::try_from(f).ok());
                match self.ask(DebugRequest::Evaluate { frame, expression }).await {
                    Ok(DebugReply::Value(v)) => Ok(json!({
                        "result": v.value,
                        "type": v.type_name,
                        "variablesReference": v.reference,
                    })),
                    other => unexpected(other),
                }
            }
            Command::SetVariable {
                variables_reference,
                name,
                value,
            } => match self
                .ask(DebugRequest::SetVariable {
                    reference: variables_reference,
                    name,
                    value,
                })
                .await
            {
                Ok(DebugReply::Value(v)) => Ok(json!({
                    "value": v.value,
                    "type": v.type_name,
                    "variablesReference": v.reference,
                })),
                other => unexpected(other),
            },
            Command::Continue { .. } => self
                .ask(DebugRequest::Continue)
                .await
                .map(|_| json!({"allThreadsContinued": true}))
                .map_err(DapError::from),
            Command::Next { .. } => done(self.ask(DebugRequest::StepOver).await),
            Command::StepIn { .. } => done(self.ask(DebugRequest::StepIn).await),
            Command::StepOut { .. } => done(self.ask(DebugRequest::StepOut).await),
            Command::Pause { .. } => done(self.ask(DebugRequest::Pause).await),
            Command::Disconnect { .. } | Command::Terminate => {
                // gantry keeps running: detaching resumes a stopped script.
                let r = done(self.ask(DebugRequest::Detach).await);
                return (r, Next::Close);
            }
            Command::LoadedSources => match self.ask(DebugRequest::Sources).await {
                Ok(DebugReply::Sources(paths)) => {
                    let list: Vec<Json> = paths.iter().map(|p| source_json(p)).collect();
                    Ok(json!({ "sources": list }))
                }
                other => unexpected(other),
            },
            Command::Source { .. } => Err(DapError::SourceByReference),
            Command::Unknown(name) => Err(DapError::UnknownCommand(name)),
        };
        (result, Next::Go)
    }
}

fn unexpected(r: Result<DebugReply, DebugError>) -> Result<Json, DapError> {
    match r {
        Ok(other) => Err(DapError::UnexpectedReply(other)),
        Err(e) => Err(e.into()),
    }
}

/// Why a DAP request is answered with an error response; the text is its message.
#[derive(Debug, thiserror::Error)]
enum DapError {
    /// The debugger refused, or the simulation has ended.
    #[error(transparent)]
    Debug(#[from] DebugError),
    /// setBreakpoints for a source given without a path.
    #[error("setBreakpoints needs source.path (the script file)")]
    NoSourcePath,
    /// A `source` request: the editor opens scripts by path.
    #[error("gantry's scripts are files: open the source by its path")]
    SourceByReference,
    /// A command the adapter does not implement.
    #[error("unknown command '{0}': gantry's debug adapter does not implement it")]
    UnknownCommand(String),
    /// The debugger answered with a reply of another request's kind (a bug).
    #[error("unexpected answer from the debugger: {0:?}")]
    UnexpectedReply(DebugReply),
}

/// What the adapter supports, as DAP's `Capabilities`.
fn capabilities() -> Json {
    json!({
        "supportsConfigurationDoneRequest": true,
        "supportsConditionalBreakpoints": true,
        "supportsHitConditionalBreakpoints": true,
        "supportsLogPoints": true,
        "supportsEvaluateForHovers": true,
        "supportsSetVariable": true,
        "supportsLoadedSourcesRequest": true,
        "supportsTerminateRequest": true,
        "exceptionBreakpointFilters": [
            {"filter": "error", "label": "Script errors", "default": true,
             "description": "Stop where an error no script catches is raised"}
        ],
    })
}

fn source_json(path: &std::path::Path) -> Json {
    json!({"name": display_name(path), "path": path.display().to_string()})
}
