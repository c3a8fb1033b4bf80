//! The browser viewer and control page (issue 7): HTTP and WebSocket on one port.
//!
//! The page (`crates/server/web/`, embedded in the binary: no CDN, no build step) opens
//! `/ws` and gets, in order: the scene description once ([`describe`]), the triangle
//! meshes (and textured shapes' images and parts) as binary messages, then a stream of deltas ([`FrameDelta`]) and, a few times
//! a second, the slower panels ([`PanelCursor`]: scripts, log, custom UIs, graphs,
//! vision images). It sends commands back as JSON ([`ClientMessage`]): simulation controls, text
//! packets (the FK/IK panels send exactly what a TCP client would, through the same
//! `sysCall_packet` path), custom-UI interactions (`simUI.interact`) and script
//! reloads.
//!
//! Nothing here touches the world directly: poses come from the [`FramePublisher`]
//! that the simulation thread runs as its [`Observer`](gantry_engine::Observer),
//! everything else goes through [`SimHandle`] requests. Viewers are capped
//! ([`HttpConfig::max_viewers`]), every incoming message is bounded, a malformed one
//! gets an error reply, and a browser that stops reading is dropped after
//! [`HttpConfig::send_timeout`] rather than holding memory.
//!
//! Plain HTTP routes, for scripts and tests:
//! * `GET /api/status`: `{"time", "steps", "state", "viewers"}` as JSON;
//! * `GET /api/ros2`: the ROS 2 topics gantry publishes and subscribes to, with counts;
//! * `GET /api/graph/HANDLE.csv`: a graph's streams as CSV (the page's download link).
//!
//! Access: the listener binds loopback by default, like the other channels. With an
//! access token (`--token`) every route, the page, its assets, the WebSocket, the CSV
//! downloads and the API, requires it (`access`: `?token=` then a cookie, or a bearer
//! header). In every mode a WebSocket handshake from another site's page is refused.
//!
//! Replay mode ([`serve_replay`], `gantry replay FILE`): the same page and pose stream
//! over a recording instead of a simulation ([`replay`]): a timeline instead of the
//! simulation controls, the recorded graphs, log and images in the panels.
//!
//! Non-goals: TLS (put gantry behind an SSH tunnel or a reverse proxy for that), user
//! accounts, and editing the scene from the page.

mod access;
mod app_state;
mod assets;
mod command;
mod config;
mod frame;
mod panels;
pub mod replay;
mod scene;
mod session;

use std::sync::Arc;

use axum::Router;
use axum::extract::ws::WebSocketUpgrade;
use axum::extract::{Path, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::serve::ListenerExt;
use tokio::net::TcpListener;
use tokio::sync::{Semaphore, watch};

use app_state::AppState;
pub use command::{
    ClientMessage, Command, CommandError, ControlAction, DebugAction, MAX_MESSAGE, MAX_PACKET, ReplayAction, parse,
};
pub use config::HttpConfig;
pub use frame::{
    DRAWING_REMOVED, DeltaMessages, DrawingFrame, Frame, FrameDelta, FramePublisher, FrameSender, IDLE_FRAME_RATE,
    MAX_CLOUD_POINTS, MAX_DRAWING_VERTICES, MAX_FRAME_CLOUD_POINTS, MAX_FRAME_RATE, MAX_FRAME_VERTICES, MSG_FRAME,
    PointCloudFrame, SelectedOrientation, SharedPublisher, frame_channel,
};
pub use panels::{
    MAX_GRAPH_SAMPLES, MAX_LOG_LINES, MAX_LOG_MESSAGE, MAX_POLL_SAMPLES, MSG_IMAGE, PanelCursor, PanelUpdate, collect,
};
pub use scene::{MAX_MESH_TRIANGLES, MSG_MESH, SceneDescription, describe};

use crate::auth::AccessToken;
use crate::debug::DebugHub;
use crate::sim_thread::SimHandle;

/// What a live run's page shows beside the simulation.
#[derive(Clone, Default)]
pub struct Sidecars {
    /// With `--debug`: the script debugger, for the "paused in SCRIPT:LINE" banner.
    pub debug: Option<DebugHub>,
    /// The ROS 2 network, for the list of topics.
    pub ros2: Option<Arc<gantry_ros2::DdsNetwork>>,
}

/// Serves the page, its assets, the WebSocket and the HTTP API until `shutdown`
/// turns true. With `token`, every route requires it (see the `access` module).
pub async fn serve(
    listener: TcpListener,
    sim: SimHandle,
    frames: FrameSender,
    cfg: HttpConfig,
    token: Option<AccessToken>,
    shutdown: watch::Receiver<bool>,
    sidecars: Sidecars,
) {
    let state = AppState {
        sim,
        frames,
        viewers: Arc::new(Semaphore::new(cfg.max_viewers)),
        cfg,
        shutdown: shutdown.clone(),
        debug: sidecars.debug,
        replay: None,
        ros2: sidecars.ros2,
    };
    serve_state(listener, state, token, shutdown).await;
}

/// [`serve`] for `gantry replay`: the page shows `replay`'s recording (see [`replay`]);
/// the simulation behind `sim` is never stepped.
pub async fn serve_replay(
    listener: TcpListener,
    sim: SimHandle,
    frames: FrameSender,
    replay: replay::ReplayHub,
    cfg: HttpConfig,
    token: Option<AccessToken>,
    shutdown: watch::Receiver<bool>,
) {
    let state = AppState {
        sim,
        frames,
        viewers: Arc::new(Semaphore::new(cfg.max_viewers)),
        cfg,
        shutdown: shutdown.clone(),
        debug: None,
        replay: Some(replay),
        ros2: None,
    };
    serve_state(listener, state, token, shutdown).await;
}

async fn serve_state(
    listener: TcpListener,
    state: AppState,
    token: Option<AccessToken>,
    shutdown: watch::Receiver<bool>,
) {
    let replaying = state.replay.is_some();
    let app = assets::routes(Router::new())
        .route("/favicon.ico", get(|| async { StatusCode::NO_CONTENT }))
        .route("/ws", get(websocket))
        .route("/api/status", get(status))
        .route("/api/ros2", get(ros2_topics))
        .route("/api/graph/{file}", get(graph_csv))
        .fallback(|| async { (StatusCode::NOT_FOUND, "not found: the viewer is at /\n") })
        .with_state(state);
    // Layered last, so it wraps every route and the fallback.
    let app = match (token, listener.local_addr()) {
        (Some(token), Ok(local)) => app.layer(axum::middleware::from_fn_with_state(
            access::Gate::new(token, local.port()),
            access::check,
        )),
        (Some(_), Err(e)) => {
            // Serving without the gate is not an option; without the port the cookie
            // cannot be named, so refuse to serve at all.
            tracing::error!("viewer not started: cannot read its address: {e}");
            return;
        }
        (None, _) => app,
    };
    let mut stop = shutdown;
    let until_stopped = async move {
        while !*stop.borrow_and_update() {
            if stop.changed().await.is_err() {
                break;
            }
        }
    };
    let result = if replaying {
        // A scrub's answer is a few small messages (poses, tick, status); without
        // TCP_NODELAY the later ones wait for the browser's delayed ACK, 40 ms on Linux.
        let listener = listener.tap_io(|s| {
            let _ = s.set_nodelay(true);
        });
        axum::serve(listener, app).with_graceful_shutdown(until_stopped).await
    } else {
        axum::serve(listener, app).with_graceful_shutdown(until_stopped).await
    };
    if let Err(e) = result {
        tracing::error!("viewer server failed: {e}");
    }
}

async fn websocket(ws: WebSocketUpgrade, headers: HeaderMap, State(st): State<AppState>) -> Response {
    if !access::same_origin(&headers) {
        tracing::warn!("viewer: refusing a WebSocket opened by a page of another site");
        return (
            StatusCode::FORBIDDEN,
            "WebSocket refused: it was opened by a page of another site; open the viewer from its own address\n",
        )
            .into_response();
    }
    let Ok(permit) = st.viewers.clone().try_acquire_owned() else {
        tracing::warn!("viewer: refusing a page: {} already connected", st.cfg.max_viewers);
        return (
            StatusCode::SERVICE_UNAVAILABLE,
            format!("too many viewers ({}); close a page and retry\n", st.cfg.max_viewers),
        )
            .into_response();
    };
    ws.max_message_size(MAX_MESSAGE)
        .max_frame_size(MAX_MESSAGE)
        .on_upgrade(move |socket| session::run(socket, st, permit))
}

async fn status(State(st): State<AppState>) -> Response {
    if let Some(r) = &st.replay {
        // A replay: the clock's state (time, start, end, playing, speed, frame).
        let mut j = replay::status_json(&r.status().borrow());
        j["viewers"] = serde_json::json!(st.cfg.max_viewers - st.viewers.available_permits());
        return json_response(&j);
    }
    // A script stopped in the debugger holds the simulation thread: say so at once
    // rather than leave the request waiting.
    if let Some(p) = st.debug.as_ref().and_then(|d| d.paused().borrow().clone()) {
        return (
            StatusCode::SERVICE_UNAVAILABLE,
            format!(
                "paused in debugger at {}:{} ({}): continue from the editor or the viewer\n",
                p.script, p.line, p.reason
            ),
        )
            .into_response();
    }
    let viewers = st.cfg.max_viewers - st.viewers.available_permits();
    let result = st
        .sim
        .read(|v| {
            let s = v.sim;
            (s.world.time(), s.world.steps(), s.state.code())
        })
        .await;
    match result {
        Ok((time, steps, state)) => json_response(&serde_json::json!({
            "time": time,
            "steps": steps,
            "state": state,
            "viewers": viewers,
        })),
        Err(e) => (StatusCode::SERVICE_UNAVAILABLE, format!("{e}\n")).into_response(),
    }
}

/// `GET /api/ros2`: `{"topics": [{"id", "topic", "type", "direction", "messages",
/// "dropped"}]}`, every endpoint gantry has open on the ROS 2 graph (none without it), with
/// ROS names (`/cmd_vel`, `geometry_msgs/msg/Twist`); the page derives rates from two
/// readings.
async fn ros2_topics(State(st): State<AppState>) -> Response {
    let topics: Vec<serde_json::Value> = st
        .ros2
        .as_ref()
        .map(|n| n.stats())
        .unwrap_or_default()
        .into_iter()
        .map(|s| {
            serde_json::json!({
                "id": s.id,
                "topic": gantry_protocol::ros::ros_topic_name(&s.dds_topic).unwrap_or(s.dds_topic),
                "type": ros_type_name(&s.dds_type),
                "direction": match s.direction {
                    gantry_lua::ros::Direction::Publish => "publish",
                    gantry_lua::ros::Direction::Subscribe => "subscribe",
                },
                "messages": s.messages,
                "dropped": s.dropped,
            })
        })
        .collect();
    json_response(&serde_json::json!({ "topics": topics }))
}

/// `geometry_msgs/msg/Twist` of the DDS name `geometry_msgs::msg::dds_::Twist_`.
fn ros_type_name(dds: &str) -> String {
    dds.replace("::dds_::", "::").trim_end_matches('_').replace("::", "/")
}

/// `GET /api/graph/HANDLE.csv` (or without `.csv`).
async fn graph_csv(Path(file): Path<String>, State(st): State<AppState>) -> Response {
    let Ok(handle) = file.trim_end_matches(".csv").parse::<i64>() else {
        return (StatusCode::BAD_REQUEST, "expected /api/graph/HANDLE.csv\n").into_response();
    };
    let result = st
        .sim
        .read(move |v| {
            let s = v.sim;
            let alias = s.world.object(handle).map(|o| o.alias.clone()).ok()?;
            s.graphs
                .graphs()
                .contains(&handle)
                .then(|| (alias, s.graphs.to_csv(handle)))
        })
        .await;
    match result {
        Ok(Some((alias, csv))) => {
            // Aliases are letters, digits and `_` in practice; anything else is
            // replaced so the header stays valid.
            let name: String = alias
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' })
                .collect();
            (
                [
                    (header::CONTENT_TYPE, "text/csv; charset=utf-8".to_owned()),
                    (
                        header::CONTENT_DISPOSITION,
                        format!("attachment; filename=\"{name}.csv\""),
                    ),
                ],
                csv,
            )
                .into_response()
        }
        Ok(None) => (StatusCode::NOT_FOUND, format!("no graph with handle {handle}\n")).into_response(),
        Err(e) => (StatusCode::SERVICE_UNAVAILABLE, format!("{e}\n")).into_response(),
    }
}

fn json_response(v: &serde_json::Value) -> Response {
    ([(header::CONTENT_TYPE, "application/json")], v.to_string()).into_response()
}
