//! What the view's threads share: what to show, the counters, the stop flag, and the bounds
//! every client is held to.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize};
use std::sync::Arc;

use crate::execute::live::LiveFeed;
use crate::web_tls::Transport;

use super::replay::ReplayLog;

/// Pages connected at once; the next one is answered HTTP 503.
pub const MAX_CLIENTS: usize = 16;
/// Connections being served at once (pages, assets, refusals); past it a connection is closed
/// unanswered.
pub const MAX_CONNECTIONS: usize = 64;
/// Largest WebSocket message (and frame) a page may send: it needs to send nothing.
pub const MAX_INCOMING_BYTES: usize = 1024;
/// WebSocket messages (pings included) a page may send per second before it is disconnected.
pub const MAX_INCOMING_PER_S: u32 = 20;
/// Largest HTTP request head read.
pub const MAX_REQUEST_BYTES: usize = 8192;

/// What the view shows.
#[derive(Clone)]
pub enum Source {
    /// A running execution (`run`, `serve`): its feed.
    Live(Arc<LiveFeed>),
    /// A finished mission log (`replay`), already shaped into the page's messages.
    Log(Arc<ReplayLog>),
}

/// What a server has refused and served, for tests and logs.
#[derive(Debug, Default)]
pub struct ViewStats {
    /// Pages connected now.
    pub clients: AtomicUsize,
    /// Connections open now (pages included).
    pub connections: AtomicUsize,
    /// Pages refused because [`MAX_CLIENTS`] were connected.
    pub refused_clients: AtomicU64,
    /// Bad requests: malformed, too long, not `GET`, unknown path, foreign origin.
    pub bad_requests: AtomicU64,
    /// Messages from pages dropped (oversized, over the rate, not expected).
    pub dropped_messages: AtomicU64,
    /// TLS clients dropped: a handshake that failed or took too long (no certificate, one the
    /// fleet CA did not sign, plain HTTP to the TLS port), or a member that may not watch.
    pub refused_tls: AtomicU64,
    /// Catch-ups sent (one per connection, and one more each time a slow page was cut off).
    pub catch_ups: AtomicU64,
}

/// What the connection threads share.
pub(super) struct Shared {
    /// What to show.
    pub source: Source,
    /// Plain or TLS.
    pub transport: Transport,
    /// Counters.
    pub stats: Arc<ViewStats>,
    /// Set when the server stops: every thread ends.
    pub stop: Arc<AtomicBool>,
}
