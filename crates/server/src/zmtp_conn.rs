//! A ZMTP 3 ROUTER socket on a TCP listener: the accept loop and one task per
//! connection, which owns the socket's read side and the receive buffer.
//!
//! Each connection sends its greeting and `READY` (socket type ROUTER) at once, then
//! feeds what it reads to a [`zmtp::Decoder`] and hands each whole message to the
//! [`Router`], named by the connection's routing id. Replies go out through the
//! connection's [`Outgoing`], from whichever thread has them (see
//! [`crate::zmtp_reply`]). A connection takes one request at a time: while a reply is
//! owed, later bytes stay in the buffer (and reading stops once it holds
//! [`zmtp::MAX_BUFFERED`] bytes), so a peer can neither pipeline work into the
//! simulation queue nor grow memory.
//!
//! A peer that breaks ZMTP or the limits gets a warning naming it and its connection
//! closed (with an `ERROR` command first if it was in the handshake); nobody else
//! notices. Non-goals: connecting out, the routing ids peers propose (each connection
//! gets its own, so no peer can take another's), and heartbeats of our own (`PING` is
//! answered, never sent).

use std::io;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use bytes::{Bytes, BytesMut};
use gantry_protocol::zmtp::{self, Command, Decoder, Event, Ready, SocketType};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{Semaphore, watch};

use crate::zmtp_reply::Outgoing;

/// Bytes read from a socket at a time, at most.
const READ_CHUNK: usize = 16 * 1024;

/// One connection, as the [`Router`] sees it.
pub struct Peer {
    /// The routing id: unique among this listener's connections, never reused.
    pub id: Bytes,
    /// Where its replies go.
    pub out: Arc<Outgoing>,
}

/// What is done with the messages of every connection.
pub trait Router: Send + Sync + 'static {
    /// `frames` (at least one) came from `peer`. A reply, now or later, goes through
    /// `peer.out` (`reply` or `reply_when_ready`).
    fn message(&self, peer: &Peer, frames: Vec<Bytes>);
    /// `peer` finished its handshake: messages from it may follow.
    fn connected(&self, peer: &Peer);
    /// `peer`'s connection closed, for whatever reason, after [`Router::connected`].
    fn disconnected(&self, peer: &Peer);
}

/// Accepts connections on `listener` and serves each in a task of its own, at most
/// `max_connections` at once, until `shutdown` turns true (open connections end then
/// too).
pub async fn serve(
    listener: TcpListener,
    router: Arc<impl Router>,
    max_connections: usize,
    shutdown: watch::Receiver<bool>,
) {
    let limit = Arc::new(Semaphore::new(max_connections));
    let mut next_id = 0u64;
    let mut stop = shutdown.clone();
    loop {
        tokio::select! {
            _ = stop.changed() => break,
            accepted = listener.accept() => match accepted {
                Ok((stream, peer)) => {
                    let Ok(permit) = limit.clone().try_acquire_owned() else {
                        tracing::warn!("zmq remote API: refusing {peer}: {max_connections} connections are open");
                        continue;
                    };
                    next_id += 1;
                    let router = router.clone();
                    let shutdown = shutdown.clone();
                    tokio::spawn(async move {
                        connection(stream, peer, Bytes::copy_from_slice(&next_id.to_be_bytes()), router, shutdown).await;
                        drop(permit);
                    });
                }
                Err(e) => {
                    // Out of file descriptors, usually: back off rather than spin.
                    tracing::warn!("zmq remote API: accept failed: {e}");
                    tokio::time::sleep(Duration::from_millis(10)).await;
                }
            }
        }
    }
}

/// Why a connection ended.
enum End {
    /// The peer closed, the socket failed, or the server stops: nothing to report.
    Quiet,
    /// The peer refused us with an `ERROR` command.
    Refused(Bytes),
    /// The peer broke ZMTP or a limit.
    Violation(zmtp::Violation),
}

/// Serves one connection until it closes.
async fn connection(
    stream: TcpStream,
    addr: SocketAddr,
    id: Bytes,
    router: Arc<impl Router>,
    shutdown: watch::Receiver<bool>,
) {
    // Each request and reply is one small write; Nagle would hold them back.
    if let Err(e) = stream.set_nodelay(true) {
        tracing::debug!("zmq remote API: TCP_NODELAY for {addr}: {e}");
    }
    let stream = Arc::new(stream);
    let peer = Peer {
        id,
        out: Outgoing::new(stream.clone()),
    };
    let mut hello = Vec::new();
    zmtp::encode_greeting(&mut hello, false);
    Command::Ready(Ready {
        socket_type: SocketType::Router,
        identity: Bytes::new(),
    })
    .encode(&mut hello);
    peer.out.write(&hello);

    let mut decoder = Decoder::new(SocketType::Router);
    let end = run(&stream, &peer, &mut decoder, &*router, shutdown).await;
    match end {
        End::Quiet => {}
        End::Refused(reason) => tracing::debug!(
            "zmq remote API: {addr} refused the connection: {}",
            String::from_utf8_lossy(&reason)
        ),
        End::Violation(v) => {
            tracing::warn!("zmq remote API: closing the connection from {addr}: {v}");
            if decoder.in_handshake() {
                // Tell a ZMQ peer why (libzmq logs it); the greeting is behind us, so
                // it can read commands.
                let mut error = Vec::new();
                Command::Error {
                    reason: Bytes::from(v.to_string()),
                }
                .encode(&mut error);
                peer.out.write(&error);
            }
        }
    }
    if decoder.is_ready() {
        router.disconnected(&peer);
    }
    // The socket closes when the last reference goes: this task's, once `Outgoing`
    // has let go of its own.
    peer.out.close();
}

/// The connection's loop: decode and hand over what the buffer holds, then wait for
/// bytes, for the socket to take pending bytes, or for the owed reply.
async fn run(
    stream: &TcpStream,
    peer: &Peer,
    decoder: &mut Decoder,
    router: &impl Router,
    mut shutdown: watch::Receiver<bool>,
) -> End {
    let mut buf = BytesMut::new();
    loop {
        // An empty buffer has nothing to decode: the usual case right after a request,
        // when asking whether the connection is free would only arrange a wake-up for
        // when its reply is written, which nobody needs (the next bytes wake the task).
        while !buf.is_empty() && peer.out.ready_for_request() {
            match decoder.decode(&mut buf) {
                Ok(Some(Event::Message(frames))) => router.message(peer, frames),
                Ok(Some(Event::Command(command))) => match command {
                    Command::Ready(_) => router.connected(peer),
                    Command::Ping { context, .. } => {
                        let mut pong = Vec::new();
                        Command::Pong { context }.encode(&mut pong);
                        peer.out.write(&pong);
                    }
                    Command::Error { reason } => return End::Refused(reason),
                    // PONG answers a PING we never send; SUBSCRIBE and the like mean
                    // nothing to a ROUTER.
                    Command::Pong { .. } | Command::Other { .. } => {}
                },
                Ok(None) => break,
                Err(v) => return End::Violation(v),
            }
        }
        let read = buf.len() < zmtp::MAX_BUFFERED;
        let flush = peer.out.has_pending();
        tokio::select! {
            _ = shutdown.changed() => return End::Quiet,
            () = peer.out.woken() => {}
            flushed = peer.out.flush(), if flush => if flushed.is_err() {
                return End::Quiet;
            },
            ready = stream.readable(), if read => {
                if ready.is_err() {
                    return End::Quiet;
                }
                buf.reserve(READ_CHUNK);
                match stream.try_read_buf(&mut buf) {
                    Ok(0) => return End::Quiet,
                    Ok(_) => {}
                    Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
                    Err(_) => return End::Quiet,
                }
            }
        }
    }
}
