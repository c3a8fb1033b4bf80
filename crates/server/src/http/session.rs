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
use tokio::sync::OwnedSemaphorePermit;

use super::command::{self, Command};
use super::frame::FrameDelta;
use super::panels::{self, PanelCursor};
use super::scene;
use super::{AppState, HttpConfig};
use crate::sim_thread::SimHandle;

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
pub(super) async fn run(mut socket: WebSocket, st: AppState, _permit: OwnedSemaphorePermit) {
    let client = NEXT_CLIENT.fetch_add(1, Ordering::Relaxed);
    let mut frames = st.frames.subscribe();
    let mut shutdown = st.shutdown.clone();
    let mut delta = FrameDelta::default();
    let Ok(mut described) = send_scene(&mut socket, &st.sim, &st.cfg).await else {
        return;
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
            _ = poll.tick() => send_panels(&mut socket, &st, &mut cursor).await,
            msg = socket.recv() => match msg {
                None | Some(Err(_)) | Some(Ok(Message::Close(_))) => Err(Gone),
                Some(Ok(Message::Text(text))) => {
                    let reply = handle(text.as_str(), client, &st.sim).await;
                    send(&mut socket, &st.cfg, Message::Text(reply.to_string().into())).await
                }
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
    let _ = tokio::time::timeout(st.cfg.send_timeout, socket.send(Message::Close(None))).await;
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
    let desc = match sim.with(|s| scene::describe(&s.world())).await {
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
    let update = match st
        .sim
        .with(move |sim| {
            let u = panels::collect(sim, &mut next);
            (next, u)
        })
        .await
    {
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

/// Carries out one command and returns the reply `{"t":"reply","id","ok","text"}`.
async fn handle(text: &str, client: i64, sim: &SimHandle) -> Json {
    let (id, result) = match command::parse(text) {
        Err(e) => (None, Err(e.to_string())),
        Ok(msg) => (msg.id, execute(msg.command, client, sim).await),
    };
    match result {
        Ok(text) => json!({"t": "reply", "id": id, "ok": true, "text": text}),
        Err(text) => json!({"t": "reply", "id": id, "ok": false, "text": text}),
    }
}

async fn execute(cmd: Command, client: i64, sim: &SimHandle) -> Result<String, String> {
    match cmd {
        Command::Control { action } => {
            let state = sim.control(action.into()).await.map_err(|e| e.to_string())?;
            Ok(format!("{state:?}").to_lowercase())
        }
        Command::Packet { text } => packet(&text, client, sim).await,
        Command::Ui { ui, widget, value } => {
            let args = vec![Value::Int(ui), Value::Int(widget), command::ui_value(&value)];
            sim.call("simUI.interact", args).await.map(|_| String::new())
        }
        Command::Reload { script } => {
            let found = sim
                .with(move |s| {
                    let n = s.scripts().len();
                    if script < n {
                        s.reload(script);
                    }
                    script < n
                })
                .await
                .map_err(|e| e.to_string())?;
            if found {
                Ok(String::new())
            } else {
                Err(format!("no script {script}"))
            }
        }
    }
}

/// A text packet, through the same `sysCall_packet` path and with the same reply as the
/// TCP text channel (`<ERR#...>` replies count as failures here).
async fn packet(text: &str, client: i64, sim: &SimHandle) -> Result<String, String> {
    let reply = crate::text::deliver(text.trim(), client, sim).await;
    if reply.starts_with("<ERR#") {
        Err(reply)
    } else {
        Ok(reply)
    }
}
