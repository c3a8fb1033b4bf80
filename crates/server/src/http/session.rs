//! One viewer page's WebSocket: the scene description, then frame deltas and panel
//! updates out, commands in.
//!
//! A single task serves the socket, so messages go out in order and at most one is in
//! flight; while it waits for a slow browser, new frames simply replace the one waiting
//! in the `watch` channel. Every send has a deadline ([`HttpConfig::send_timeout`]).

use std::sync::atomic::{AtomicI64, Ordering};

use axum::extract::ws::{Message, WebSocket};
use gantry_sim_core::Value;
use serde_json::{Value as Json, json};
use tokio::sync::{OwnedSemaphorePermit, watch};

use super::app_state::AppState;
use super::command::{self, Command};
use super::config::HttpConfig;
use super::frame::FrameDelta;
use super::panels::{self, PanelCursor};
use super::replay::{self, ReplayError, ReplayHub, ReplayPanels, ReplayStatus};
use super::scene;
use crate::debug::{DebugError, DebugHub, PausedAt};
use crate::sim_thread::{HandleCallError, SendError, SimHandle};

/// `packet.client` ids of viewer pages, far above the text channel's connection
/// counter so scripts can tell them apart.
static NEXT_CLIENT: AtomicI64 = AtomicI64::new(1 << 40);

/// Shortest time between two scene descriptions sent because the scene changed in place
/// (a colour, an alias, a joint mode): a script restyling objects every step must not
/// make the page download the scene, meshes included, at the frame rate. Changes of the
/// object list or order are described at once (the pose stream depends on them).
const RESEND_INTERVAL: std::time::Duration = std::time::Duration::from_millis(250);

/// The socket closed, broke, or the page stopped reading: end the session.
struct Gone;

/// Serves one page until it leaves or gantry shuts down. `_permit` is its viewer slot.
///
/// With the debugger, a script may stop and hold the simulation thread: the page then
/// gets `{"t":"debug","paused":{"script","line","reason"}}` (and `"paused":null` when it
/// resumes), its banner's buttons are answered by the debugger directly, and its other
/// commands wait in order in a worker task so the socket keeps being served.
pub(super) async fn run(mut socket: WebSocket, st: AppState, _permit: OwnedSemaphorePermit) {
    let client = NEXT_CLIENT.fetch_add(1, Ordering::Relaxed);
    let mut frames = st.frames.subscribe();
    let mut shutdown = st.shutdown.clone();
    let mut delta = FrameDelta::default();
    let mut paused = st.debug.as_ref().map(DebugHub::paused);
    if let Some(p) = &paused {
        let now = p.borrow().clone();
        if send(&mut socket, &st.cfg, debug_message(now.as_ref())).await.is_err() {
            return;
        }
    }
    // A page opened while a script is stopped: the scene cannot be read before it
    // resumes, but the banner's buttons work.
    while let Some(p) = paused.as_mut().filter(|p| p.borrow().is_some()) {
        let step = tokio::select! {
            _ = shutdown.changed() => Err(Gone),
            changed = p.changed() => match changed {
                Err(_) => Err(Gone),
                Ok(()) => {
                    let now = p.borrow_and_update().clone();
                    send(&mut socket, &st.cfg, debug_message(now.as_ref())).await
                }
            },
            msg = socket.recv() => match msg {
                None | Some(Err(_)) | Some(Ok(Message::Close(_))) => Err(Gone),
                Some(Ok(Message::Text(text))) => {
                    let reply = match command::parse(text.as_str()) {
                        Ok(m) => match m.command {
                            Command::Debug { action } => reply(m.id, debug(st.debug.as_ref(), action).await),
                            _ => reply(m.id, Err(ViewerCommandError::Paused)),
                        },
                        Err(e) => reply(None, Err(e.into())),
                    };
                    send(&mut socket, &st.cfg, Message::Text(reply.to_string().into())).await
                }
                Some(Ok(_)) => Ok(()),
            },
        };
        if step.is_err() {
            return;
        }
    }
    let Ok(mut described) = send_scene(&mut socket, &st.sim, &st.cfg).await else {
        return;
    };
    // A replay: the page learns it is one (and where the clock is) before any frame.
    let mut replay_status = st.replay.as_ref().map(ReplayHub::status);
    let mut replay_panels = ReplayPanels::default();
    if let Some(hub) = &st.replay
        && send(&mut socket, &st.cfg, Message::Text(hub.hello().to_string().into()))
            .await
            .is_err()
    {
        return;
    }
    // Commands that go to the simulation run one after another, in the order sent,
    // in a worker, whose replies come back here.
    let (work_tx, mut work_rx) = tokio::sync::mpsc::channel::<(Option<u64>, Command)>(64);
    let (reply_tx, mut replies) = tokio::sync::mpsc::channel::<Json>(64);
    let worker = {
        let sim = st.sim.clone();
        let hub = st.replay.clone();
        tokio::spawn(async move {
            while let Some((id, cmd)) = work_rx.recv().await {
                let r = reply(id, execute(cmd, client, &sim, hub.as_ref()).await);
                if reply_tx.send(r).await.is_err() {
                    break;
                }
            }
        })
    };
    let mut described_at = std::time::Instant::now();
    let mut cursor = PanelCursor::default();
    let mut poll = tokio::time::interval(st.cfg.panel_interval);
    poll.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Skip);
    // The frame waiting in the channel is already current: send it without waiting.
    frames.mark_changed();
    loop {
        let step = tokio::select! {
            _ = shutdown.changed() => Err(Gone),
            changed = frames.changed() => match changed {
                Err(_) => Err(Gone),
                Ok(()) => {
                    let frame = frames.borrow_and_update().clone();
                    let (objects, revision, structure) = described;
                    if frame.poses.is_empty() && objects > 0 {
                        // Nothing published yet.
                        Ok(())
                    } else if frame.poses.len() != objects
                        || frame.structure_revision != structure
                        || (frame.scene_revision != revision && described_at.elapsed() >= RESEND_INTERVAL)
                    {
                        // Objects were added, removed or changed: describe the scene again.
                        delta.reset();
                        described_at = std::time::Instant::now();
                        send_scene(&mut socket, &st.sim, &st.cfg).await.map(|d| described = d)
                    } else {
                        let m = delta.update(&frame);
                        send_frame(&mut socket, &st.cfg, m.tick, m.binary).await
                    }
                }
            },
            _ = poll.tick() => match &st.replay {
                Some(hub) => {
                    let now = hub.status().borrow().clone();
                    send_replay_panels(&mut socket, &st.cfg, hub, &mut replay_panels, &now).await
                }
                None => send_panels(&mut socket, &st, &mut cursor).await,
            },
            now = replay_change(&mut replay_status) => {
                let text = replay::status_json(&now).to_string();
                match send(&mut socket, &st.cfg, Message::Text(text.into())).await {
                    Ok(()) => match &st.replay {
                        // The log and images follow the clock at once, not at the next poll.
                        Some(hub) => send_replay_panels(&mut socket, &st.cfg, hub, &mut replay_panels, &now).await,
                        None => Ok(()),
                    },
                    Err(g) => Err(g),
                }
            }
            now = pause_change(&mut paused) => send(&mut socket, &st.cfg, debug_message(now.as_ref())).await,
            Some(r) = replies.recv() => send(&mut socket, &st.cfg, Message::Text(r.to_string().into())).await,
            msg = socket.recv() => match msg {
                None | Some(Err(_)) | Some(Ok(Message::Close(_))) => Err(Gone),
                Some(Ok(Message::Text(text))) => match command::parse(text.as_str()) {
                    Ok(m) => match m.command {
                        // Not queued: the worker may be waiting on a stopped simulation.
                        Command::Debug { action } => {
                            let r = reply(m.id, debug(st.debug.as_ref(), action).await);
                            send(&mut socket, &st.cfg, Message::Text(r.to_string().into())).await
                        }
                        cmd => match work_tx.try_send((m.id, cmd)) {
                            Ok(()) => Ok(()),
                            Err(_) => {
                                let r = reply(m.id, Err(ViewerCommandError::Queued));
                                send(&mut socket, &st.cfg, Message::Text(r.to_string().into())).await
                            }
                        },
                    },
                    Err(e) => {
                        let r = reply(None, Err(e.into()));
                        send(&mut socket, &st.cfg, Message::Text(r.to_string().into())).await
                    }
                },
                Some(Ok(Message::Binary(_))) => {
                    let reply = json!({"t": "reply", "id": null, "ok": false,
                        "text": "binary messages are not understood; send JSON text"});
                    send(&mut socket, &st.cfg, Message::Text(reply.to_string().into())).await
                }
                // Pings are answered by the WebSocket layer.
                Some(Ok(_)) => Ok(()),
            },
        };
        if step.is_err() {
            break;
        }
    }
    worker.abort();
    let _ = tokio::time::timeout(st.cfg.send_timeout, socket.send(Message::Close(None))).await;
}

/// The next change of where a script is stopped; never, without the debugger.
async fn pause_change(paused: &mut Option<watch::Receiver<Option<PausedAt>>>) -> Option<PausedAt> {
    match paused {
        Some(p) => {
            if p.changed().await.is_err() {
                std::future::pending::<()>().await;
            }
            p.borrow_and_update().clone()
        }
        None => std::future::pending().await,
    }
}

/// The next move of a replay's clock; never, in a live run.
async fn replay_change(status: &mut Option<watch::Receiver<ReplayStatus>>) -> ReplayStatus {
    match status {
        Some(s) => {
            if s.changed().await.is_err() {
                std::future::pending::<()>().await;
            }
            s.borrow_and_update().clone()
        }
        None => std::future::pending().await,
    }
}

/// A replay's panels at the clock's time `now`.
async fn send_replay_panels(
    socket: &mut WebSocket,
    cfg: &HttpConfig,
    hub: &ReplayHub,
    panels: &mut ReplayPanels,
    now: &ReplayStatus,
) -> Result<(), Gone> {
    let (json, images) = panels.update(hub, now);
    if let Some(j) = json {
        send(socket, cfg, Message::Text(j.to_string().into())).await?;
    }
    for img in images {
        send(socket, cfg, Message::Binary(img.into())).await?;
    }
    Ok(())
}

/// Resolves once a script is stopped in the debugger; never, without it.
async fn until_paused(debug: Option<&DebugHub>) {
    let Some(hub) = debug else {
        return std::future::pending().await;
    };
    let mut p = hub.paused();
    if p.wait_for(Option::is_some).await.is_err() {
        std::future::pending::<()>().await;
    }
}

fn debug_message(paused: Option<&PausedAt>) -> Message {
    let body = match paused {
        Some(p) => json!({"t": "debug", "paused": {"script": p.script, "line": p.line, "reason": p.reason}}),
        None => json!({"t": "debug", "paused": null}),
    };
    Message::Text(body.to_string().into())
}

/// A banner button: to the debugger directly.
async fn debug(hub: Option<&DebugHub>, action: command::DebugAction) -> Result<String, ViewerCommandError> {
    let hub = hub.ok_or(ViewerCommandError::DebuggerOff)?;
    Ok(hub.request(action.into()).await.map(|_| String::new())?)
}

async fn send(socket: &mut WebSocket, cfg: &HttpConfig, msg: Message) -> Result<(), Gone> {
    match tokio::time::timeout(cfg.send_timeout, socket.send(msg)).await {
        Ok(Ok(())) => Ok(()),
        Ok(Err(_)) => Err(Gone),
        Err(_) => {
            tracing::info!("viewer: a page stopped reading; disconnecting it");
            Err(Gone)
        }
    }
}

async fn send_frame(
    socket: &mut WebSocket,
    cfg: &HttpConfig,
    tick: Option<Json>,
    binary: Option<Vec<u8>>,
) -> Result<(), Gone> {
    // Poses first, so the tick's time labels what the page already shows.
    if let Some(b) = binary {
        send(socket, cfg, Message::Binary(b.into())).await?;
    }
    if let Some(t) = tick {
        send(socket, cfg, Message::Text(t.to_string().into())).await?;
    }
    Ok(())
}

/// Sends the scene description and its meshes; returns the number of objects and the
/// scene and structure revisions it describes.
async fn send_scene(socket: &mut WebSocket, sim: &SimHandle, cfg: &HttpConfig) -> Result<(usize, u64, u64), Gone> {
    let desc = match sim.read(|v| scene::describe(&v.sim.world)).await {
        Ok(d) => d,
        Err(e) => {
            let msg = json!({"t": "error", "text": e.to_string()});
            let _ = send(socket, cfg, Message::Text(msg.to_string().into())).await;
            return Err(Gone);
        }
    };
    let objects = desc.json["objects"].as_array().map_or(0, Vec::len);
    let revision = desc.json["revision"].as_u64().unwrap_or(0);
    let structure = desc.json["structure"].as_u64().unwrap_or(0);
    send(socket, cfg, Message::Text(desc.json.to_string().into())).await?;
    for m in desc.meshes {
        send(socket, cfg, Message::Binary(m.into())).await?;
    }
    Ok((objects, revision, structure))
}

async fn send_panels(socket: &mut WebSocket, st: &AppState, cursor: &mut PanelCursor) -> Result<(), Gone> {
    let mut next = cursor.clone();
    let collect = st.sim.read(move |view| {
        let u = panels::collect(view, &mut next);
        (next, u)
    });
    // A stopped script holds the simulation: give up this refresh (the request runs
    // later, its answer is dropped, and the cursor stays) rather than stall the page.
    let result = tokio::select! {
        r = collect => r,
        () = until_paused(st.debug.as_ref()) => return Ok(()),
    };
    let update = match result {
        Ok((next, u)) => {
            *cursor = next;
            u
        }
        // Busy: try again at the next tick with the same cursor. Closed: the run ended.
        Err(crate::sim_thread::SendError::Busy) => return Ok(()),
        Err(crate::sim_thread::SendError::Closed) => return Err(Gone),
    };
    if let Some(j) = update.json {
        send(socket, &st.cfg, Message::Text(j.to_string().into())).await?;
    }
    for img in update.images {
        send(socket, &st.cfg, Message::Binary(img.into())).await?;
    }
    Ok(())
}

/// The reply `{"t":"reply","id","ok","text"}` to a command.
fn reply(id: Option<u64>, result: Result<String, ViewerCommandError>) -> Json {
    match result {
        Ok(text) => json!({"t": "reply", "id": id, "ok": true, "text": text}),
        Err(e) => json!({"t": "reply", "id": id, "ok": false, "text": e.to_string()}),
    }
}

/// Why a viewer command failed; the text is the reply's `text`.
#[derive(Debug, thiserror::Error)]
enum ViewerCommandError {
    /// The message is not a command the page sends.
    #[error(transparent)]
    Parse(#[from] command::CommandError),
    /// A script is stopped in the debugger: only the debugger's buttons are served.
    #[error("paused in debugger: continue or step first")]
    Paused,
    /// The session's queue of commands for the simulation is full.
    #[error("too many commands waiting; retry")]
    Queued,
    /// A debugger button while gantry runs without `--debug`.
    #[error("the debugger is off: start gantry with --debug")]
    DebuggerOff,
    /// The debugger refused, or the simulation has ended.
    #[error(transparent)]
    Debug(#[from] DebugError),
    /// The simulation could not take the request.
    #[error(transparent)]
    Send(#[from] SendError),
    /// A registry call failed: its message.
    #[error(transparent)]
    Call(#[from] HandleCallError),
    /// A debugger action reached the worker (a bug: the session answers those).
    #[error("{0:?} is answered by the session, not the worker")]
    DebugInWorker(command::DebugAction),
    /// A reload of a script index the scene does not have.
    #[error("no script {0}")]
    NoScript(usize),
    /// The text channel's `<ERR#...>` reply to a packet.
    #[error("{0}")]
    Packet(String),
    /// A timeline command to a live run.
    #[error("no recording is being replayed: replay commands work in the viewer of `gantry replay FILE`")]
    NotReplaying,
    /// A command that drives the simulation, sent to a replay.
    #[error(
        "this is a replay of a recording: simulation controls, packets, custom UIs, script reloads and keys are off (use the timeline)"
    )]
    Replaying,
    /// The replay could not carry out a timeline command.
    #[error(transparent)]
    Replay(#[from] ReplayError),
}

async fn execute(
    cmd: Command,
    client: i64,
    sim: &SimHandle,
    replay: Option<&ReplayHub>,
) -> Result<String, ViewerCommandError> {
    if let Some(hub) = replay {
        return match cmd {
            Command::Replay {
                action,
                time,
                speed,
                frames,
            } => {
                let s = hub.command(action, time, speed, frames).await?;
                Ok(replay::status_json(&s).to_string())
            }
            // Picking an object only looks at the scene.
            Command::Select { .. } => Box::pin(execute(cmd, client, sim, None)).await,
            _ => Err(ViewerCommandError::Replaying),
        };
    }
    match cmd {
        Command::Replay { .. } => Err(ViewerCommandError::NotReplaying),
        Command::Control { action } => {
            let state = sim.control(action.into()).await?;
            Ok(format!("{state:?}").to_lowercase())
        }
        Command::Packet { text } => packet(&text, client, sim).await,
        Command::Ui { ui, widget, value } => {
            let args = vec![Value::Int(ui), Value::Int(widget), command::ui_value(&value)];
            sim.call("simUI.interact", args)
                .await
                .map(|_| String::new())
                .map_err(ViewerCommandError::Call)
        }
        Command::Debug { action } => Err(ViewerCommandError::DebugInWorker(action)),
        Command::Select { handles } => {
            let handles = Value::Array(handles.into_iter().map(Value::Int).collect());
            sim.call("setObjectSel", vec![handles])
                .await
                .map(|_| String::new())
                .map_err(ViewerCommandError::Call)
        }
        // The registry's call turns the mask on (and checks the handle); its reply, the
        // mask itself, reaches the page with the next panel poll.
        Command::Mask { sensor } => sim
            .call("getVisionSensorMask", vec![Value::Int(sensor)])
            .await
            .map(|_| String::new())
            .map_err(ViewerCommandError::Call),
        Command::Key { key, mods } => sim
            .with(move |s| s.sim_mut().messages.post_key(key, mods))
            .await
            .map(|()| String::new())
            .map_err(ViewerCommandError::from),
        Command::Reload { script } => {
            let found = sim
                .with(move |s| {
                    let n = s.scripts().len();
                    if script < n {
                        s.reload(script);
                    }
                    script < n
                })
                .await?;
            if found {
                Ok(String::new())
            } else {
                Err(ViewerCommandError::NoScript(script))
            }
        }
    }
}

/// A text packet, through the same `sysCall_packet` path and with the same reply as the
/// TCP text channel (`<ERR#...>` replies count as failures here).
async fn packet(text: &str, client: i64, sim: &SimHandle) -> Result<String, ViewerCommandError> {
    let reply = crate::text::deliver(text.trim(), client, sim).await;
    if reply.starts_with("<ERR#") {
        Err(ViewerCommandError::Packet(reply))
    } else {
        Ok(reply)
    }
}
