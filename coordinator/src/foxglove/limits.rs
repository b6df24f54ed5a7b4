//! What the Foxglove server allows a client, and the counts of what it refused. A client is
//! anyone who reaches the port: each bound below keeps one from costing the coordinator more
//! than a fixed share of memory and time.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Clients connected at once; one more is closed at once and counted.
pub const MAX_CLIENTS: usize = 16;
/// Largest message (and frame) a client may send, bytes: a `subscribe` of every channel of the
/// largest fleet fits many times over.
pub const MAX_CLIENT_MESSAGE_BYTES: usize = 64 * 1024;
/// Messages a client may send per second, on average.
pub const CLIENT_MESSAGES_PER_S: f64 = 20.0;
/// Messages a client may send at once (a viewer subscribes its panels' channels together).
pub const CLIENT_BURST: f64 = 100.0;
/// Refused messages after which a client is dropped.
pub const MAX_REFUSED_PER_CLIENT: u32 = 100;
/// Subscriptions a client may hold.
pub const MAX_SUBSCRIPTIONS: usize = 1024;
/// Messages queued for a client before it is cut off as too slow (the hub never waits).
pub const CLIENT_QUEUE: usize = 8192;
/// Time a client has to finish the TLS handshake, and then the WebSocket handshake.
pub const HANDSHAKE_TIMEOUT: Duration = Duration::from_secs(5);
/// Time one write to a client may take before it is dropped as stuck.
pub const WRITE_TIMEOUT: Duration = Duration::from_secs(5);
/// How long a client's thread waits for its client's next message before it writes what is
/// queued: the latency the server adds.
pub const POLL: Duration = Duration::from_millis(20);

/// What the server refused, since it started.
#[derive(Debug, Default)]
pub struct Counters {
    /// Connections accepted as clients.
    pub clients_served: AtomicU64,
    /// Connections closed at once: [`MAX_CLIENTS`] were connected.
    pub clients_refused: AtomicU64,
    /// Connections whose WebSocket handshake failed (no `foxglove.websocket.v1`, not
    /// WebSocket, too slow).
    pub handshakes_failed: AtomicU64,
    /// TLS clients dropped: a handshake that failed or took longer than the handshake timeout
    /// (no certificate, one the fleet CA did not sign, plain ws to the TLS port), or a member
    /// that may not watch (a vehicle).
    pub tls_refused: AtomicU64,
    /// Client messages refused: over the rate, too large, malformed, unknown, binary, or a
    /// subscription that is not allowed.
    pub messages_refused: AtomicU64,
    /// Clients dropped: too many refused messages, a protocol violation, or too slow to read.
    pub clients_dropped: AtomicU64,
}

impl Counters {
    /// Adds one to `counter`.
    pub fn bump(&self, counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    /// The counts, in words (for the log when the server stops).
    pub fn summary(&self) -> String {
        let n = |c: &AtomicU64| c.load(Ordering::Relaxed);
        format!(
            "{} clients served, {} refused (over {MAX_CLIENTS}), {} refused by TLS, \
             {} failed handshakes, {} client messages refused, {} clients dropped",
            n(&self.clients_served),
            n(&self.clients_refused),
            n(&self.tls_refused),
            n(&self.handshakes_failed),
            n(&self.messages_refused),
            n(&self.clients_dropped),
        )
    }
}
