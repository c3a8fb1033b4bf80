//! The viewer server's limits and how it treats a port it cannot bind.

use std::time::Duration;

/// Limits of the viewer server.
#[derive(Debug, Clone)]
pub struct HttpConfig {
    /// Most viewer pages connected at once; the next gets HTTP 503.
    pub max_viewers: usize,
    /// How often each page's slower panels are refreshed.
    pub panel_interval: Duration,
    /// A page that does not take a message within this time is disconnected.
    pub send_timeout: Duration,
    /// When the port cannot be bound, warn and run without the viewer instead of
    /// failing. For the default port: a second gantry (or a test run next to a
    /// viewer) must still start, while a port the user asked for fails loudly.
    pub optional: bool,
}

impl Default for HttpConfig {
    fn default() -> Self {
        Self {
            max_viewers: 32,
            panel_interval: Duration::from_millis(250),
            send_timeout: Duration::from_secs(10),
            optional: false,
        }
    }
}
