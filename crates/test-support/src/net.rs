//! Ports for tests that need a server address before the server runs.

use std::net::TcpListener;

/// A loopback TCP port that nothing listened on a moment ago: the system picks it for a
/// listener that is closed again at once. For the rare case where the address must be
/// known before the server binds (a scene's script that listens on a fixed port);
/// servers that report their address should bind port 0 instead.
///
/// # Panics
/// If no loopback port can be bound.
pub fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port()
}
