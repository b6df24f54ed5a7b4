//! The operator's live web view: one page (HTML, JS and CSS shipped in the binary, nothing
//! fetched from elsewhere) and a WebSocket on the same port that pushes the mission as it goes —
//! the scene (bounds, obstacles, seabed), each plan, every report, event and published
//! obstacle, and the fleet status each second — from the execution's [`LiveFeed`], or a whole
//! finished log for `replay … --view`.
//!
//! The server runs on its own threads (one accepting, one per connection) and only reads the
//! feed: the execution loop never waits for it. A browser that falls behind is cut off by the
//! feed and gets a fresh catch-up (`client`). Everything a client sends is bounded: the request
//! head's size, only `GET` of the known paths, at most [`MAX_CLIENTS`] pages connected (the next
//! gets HTTP 503), WebSocket messages of at most [`MAX_INCOMING_BYTES`] and
//! [`MAX_INCOMING_PER_S`] a second; what breaks a rule is answered with an error, counted in
//! [`ViewStats`] and dropped.
//!
//! Reach ([`check_bind`], rules in [`crate::web_tls`]): bound to loopback by default, where it
//! serves plain HTTP to this machine; beyond loopback it follows the fleet's security settings
//! as the Zenoh router does. With the coordinator's TLS identity (`--zenoh-config
//! keys/coordinator.json5` or `--tls-*`) it serves HTTPS and WSS to the coordinator and the
//! operators only, who present their certificate from the fleet CA (a vehicle's is refused); with
//! `--insecure` alone it serves plain HTTP, with a warning; with neither it refuses to start. A
//! refused TLS client is dropped and counted ([`ViewStats::refused_tls`]); its handshake holds
//! one of the [`MAX_CONNECTIONS`] places and has the request head's deadline.

mod assets;
mod client;
mod http;
pub mod message;
pub mod replay;
mod shared;

use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::Context as _;

use crate::execute::live::LiveFeed;
use crate::web_tls::{self, Transport};
use shared::Shared;
pub use shared::{
    Source, ViewStats, MAX_CLIENTS, MAX_CONNECTIONS, MAX_INCOMING_BYTES, MAX_INCOMING_PER_S,
    MAX_REQUEST_BYTES,
};
use shoal_common::wire::security::Security;

/// A running view server; dropping it stops it.
pub struct ViewServer {
    /// Where it listens (the port resolved when 0 was asked).
    addr: SocketAddr,
    /// `http` or `https`.
    scheme: &'static str,
    /// Counters.
    stats: Arc<ViewStats>,
    /// Tells its threads to end.
    stop: Arc<AtomicBool>,
    /// The accepting thread.
    accept: Option<JoinHandle<()>>,
}

/// How the view is served at `addr` under the fleet's `security`: plain on loopback, mutual
/// TLS beyond it with the coordinator's keys, plain with `--insecure`, refused otherwise.
pub fn check_bind(addr: &SocketAddr, security: &Security) -> anyhow::Result<Transport> {
    web_tls::choose("--view", "web view", *addr, security)
}

impl ViewServer {
    /// Binds `addr` and serves `source` over `transport` (see [`check_bind`]) until dropped.
    pub fn start(
        addr: SocketAddr,
        transport: Transport,
        source: Source,
    ) -> anyhow::Result<ViewServer> {
        let listener =
            TcpListener::bind(addr).with_context(|| format!("--view {addr}: cannot listen"))?;
        let addr = listener.local_addr()?;
        // Non-blocking accept, polled: the thread sees the stop flag within a tick.
        listener.set_nonblocking(true)?;
        let stats = Arc::new(ViewStats::default());
        let stop = Arc::new(AtomicBool::new(false));
        let scheme = transport.scheme(true);
        let shared = Arc::new(Shared {
            source,
            transport,
            stats: Arc::clone(&stats),
            stop: Arc::clone(&stop),
        });
        let accept = std::thread::Builder::new()
            .name("view-accept".into())
            .spawn(move || accept_loop(&listener, &shared))?;
        Ok(ViewServer {
            addr,
            scheme,
            stats,
            stop,
            accept: Some(accept),
        })
    }

    /// Where it listens.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("{}://{}/", self.scheme, self.addr)
    }

    /// Its counters.
    pub fn stats(&self) -> &ViewStats {
        &self.stats
    }
}

/// For a command's `--view ADDR`: a server showing the execution's feed, reached as `security`
/// allows (see [`check_bind`]); `None` without the flag. The address is printed on stderr.
pub fn start_live(
    addr: Option<SocketAddr>,
    security: &Security,
    feed: &Arc<LiveFeed>,
) -> anyhow::Result<Option<ViewServer>> {
    let Some(addr) = addr else {
        return Ok(None);
    };
    let transport = check_bind(&addr, security)?;
    let server = ViewServer::start(addr, transport, Source::Live(Arc::clone(feed)))?;
    eprintln!("live view: {}", server.url());
    Ok(Some(server))
}

/// For `replay LOG --view ADDR`: serves the log at `path` until `shutdown`, reached as
/// `security` allows (see [`check_bind`]).
pub fn serve_log(
    addr: SocketAddr,
    security: &Security,
    path: &std::path::Path,
    shutdown: &AtomicBool,
) -> anyhow::Result<()> {
    let transport = check_bind(&addr, security)?;
    let log = crate::execute::log::read(path)?;
    let shaped = replay::ReplayLog::from_records(&log.records, path)?;
    let server = ViewServer::start(addr, transport, Source::Log(Arc::new(shaped)))?;
    eprintln!("replay view: {} (Ctrl-C to stop)", server.url());
    while !shutdown.load(Ordering::Relaxed) {
        std::thread::sleep(ACCEPT_TICK);
    }
    Ok(())
}

impl Drop for ViewServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(a) = self.accept.take() {
            let _ = a.join();
        }
    }
}

/// How often the accepting thread looks for a connection or the stop flag.
const ACCEPT_TICK: Duration = Duration::from_millis(50);

fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
    while !shared.stop.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((stream, _)) => admit(stream, shared),
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => std::thread::sleep(ACCEPT_TICK),
            Err(e) => {
                tracing::warn!("web view: accept failed: {e}");
                std::thread::sleep(ACCEPT_TICK);
            }
        }
    }
}

/// Serves one connection on a thread of its own, unless [`MAX_CONNECTIONS`] are open.
fn admit(stream: TcpStream, shared: &Arc<Shared>) {
    let open = shared.stats.connections.fetch_add(1, Ordering::SeqCst);
    if open >= MAX_CONNECTIONS {
        shared.stats.connections.fetch_sub(1, Ordering::SeqCst);
        shared.stats.bad_requests.fetch_add(1, Ordering::Relaxed);
        return;
    }
    let stats = Arc::clone(&shared.stats);
    let shared = Arc::clone(shared);
    let spawned = std::thread::Builder::new()
        .name("view-connection".into())
        .spawn(move || {
            http::serve_connection(stream, &shared);
            shared.stats.connections.fetch_sub(1, Ordering::SeqCst);
        });
    if let Err(e) = spawned {
        stats.connections.fetch_sub(1, Ordering::SeqCst);
        tracing::warn!("web view: cannot start a connection thread: {e}");
    }
}

#[cfg(test)]
mod tests;
