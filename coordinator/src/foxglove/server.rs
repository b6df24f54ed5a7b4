//! The server's threads: the hub's, which follows the live feed and hands every change to each
//! client's bounded queue without waiting (a client that falls a whole queue behind is cut
//! off), the listener's, which accepts up to [`MAX_CLIENTS`] clients, and one per client (the
//! sibling `client` module). The execution loop only ever touches the live feed, which never
//! waits either.

use std::net::{SocketAddr, TcpListener};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::RecvTimeoutError;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use anyhow::Context as _;

use super::client::{self, Context};
use super::fanout::{dispatch, Shared};
use super::limits::{Counters, MAX_CLIENTS};
use crate::execute::live::LiveFeed;
use crate::web_tls::Transport;

/// How often the listener and the hub look at the stop flags.
const STOP_POLL: Duration = Duration::from_millis(50);

/// A running Foxglove server; it stops when dropped (after sending the clients what the feed
/// had published).
pub struct FoxgloveServer {
    /// Where it listens.
    addr: SocketAddr,
    /// Set to stop the hub (after it has taken in what the feed published).
    stop_hub: Arc<AtomicBool>,
    /// Set after the hub stopped: the listener and the clients end.
    stop_clients: Arc<AtomicBool>,
    /// The hub's thread.
    hub: Option<JoinHandle<()>>,
    /// The listener's thread.
    listener: Option<JoinHandle<()>>,
    /// The clients' threads, joined at the end.
    clients: Arc<Mutex<Vec<JoinHandle<()>>>>,
    /// What was refused.
    counters: Arc<Counters>,
}

impl FoxgloveServer {
    /// Binds `addr` and serves what `feed` publishes over `transport`. The address is not
    /// checked here: see [`super::FoxgloveArgs::settings`].
    pub fn start(
        addr: SocketAddr,
        transport: Transport,
        feed: Arc<LiveFeed>,
    ) -> anyhow::Result<FoxgloveServer> {
        let listener = TcpListener::bind(addr)
            .with_context(|| format!("cannot listen on {addr} for Foxglove"))?;
        let addr = listener.local_addr()?;
        listener.set_nonblocking(true)?;
        let shared = Arc::new(Mutex::new(Shared::default()));
        let counters = Arc::new(Counters::default());
        let stop_hub = Arc::new(AtomicBool::new(false));
        let stop_clients = Arc::new(AtomicBool::new(false));
        let hub = {
            let (shared, stop) = (Arc::clone(&shared), Arc::clone(&stop_hub));
            std::thread::Builder::new()
                .name("foxglove-hub".into())
                .spawn(move || follow(&feed, &shared, &stop))?
        };
        let clients = Arc::new(Mutex::new(Vec::new()));
        let cx = Context {
            shared,
            counters: Arc::clone(&counters),
            stop: Arc::clone(&stop_clients),
            session: session_id().into(),
            transport,
        };
        let listener = {
            let clients = Arc::clone(&clients);
            std::thread::Builder::new()
                .name("foxglove-listen".into())
                .spawn(move || accept(&listener, &cx, &clients))?
        };
        Ok(FoxgloveServer {
            addr,
            stop_hub,
            stop_clients,
            hub: Some(hub),
            listener: Some(listener),
            clients,
            counters,
        })
    }

    /// Where it listens (the port the system chose for port 0).
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// What it refused so far.
    pub fn counters(&self) -> &Counters {
        &self.counters
    }

    /// Sends the clients everything published so far, closes their connections and stops.
    pub fn shutdown(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        self.stop_hub.store(true, Ordering::Relaxed);
        if let Some(h) = self.hub.take() {
            let _ = h.join();
        }
        self.stop_clients.store(true, Ordering::Relaxed);
        if let Some(h) = self.listener.take() {
            let _ = h.join();
        }
        let clients = match self.clients.lock() {
            Ok(mut c) => std::mem::take(&mut *c),
            Err(_) => Vec::new(),
        };
        for h in clients {
            let _ = h.join();
        }
        tracing::info!(
            "Foxglove server on {}: {}",
            self.addr,
            self.counters.summary()
        );
    }
}

impl Drop for FoxgloveServer {
    fn drop(&mut self) {
        if self.hub.is_some() || self.listener.is_some() {
            self.stop();
        }
    }
}

/// The hub's thread: takes in the feed (the catch-up first) until stopped with nothing left.
fn follow(feed: &LiveFeed, shared: &Mutex<Shared>, stop: &AtomicBool) {
    let mut sub = feed.subscribe();
    let mut pending = sub.catch_up.messages();
    loop {
        for m in pending.drain(..) {
            dispatch(shared, &m);
        }
        match sub.messages.recv_timeout(STOP_POLL) {
            Ok(m) => dispatch(shared, &m),
            Err(RecvTimeoutError::Timeout) if stop.load(Ordering::Relaxed) => return,
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                // Cut off by the feed for falling behind: start again from a fresh catch-up
                // (its start record makes the hub begin the mission anew).
                tracing::warn!("Foxglove: the server fell behind the execution; catching up");
                sub = feed.subscribe();
                pending = sub.catch_up.messages();
            }
        }
    }
}

/// The listener's thread: a thread per client, up to [`MAX_CLIENTS`] at once.
fn accept(listener: &TcpListener, cx: &Context, threads: &Mutex<Vec<JoinHandle<()>>>) {
    let active = Arc::new(AtomicUsize::new(0));
    while !cx.stop.load(Ordering::Relaxed) {
        let stream = match listener.accept() {
            Ok((stream, _)) => stream,
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(STOP_POLL);
                continue;
            }
            Err(e) => {
                tracing::warn!("Foxglove: cannot accept a connection: {e}");
                std::thread::sleep(STOP_POLL);
                continue;
            }
        };
        // The TLS handshake, if any, runs on the client's thread and holds one of the places.
        if active.load(Ordering::Relaxed) >= MAX_CLIENTS || stream.set_nonblocking(false).is_err() {
            cx.counters.bump(&cx.counters.clients_refused);
            continue; // dropping the stream closes it
        }
        cx.counters.bump(&cx.counters.clients_served);
        active.fetch_add(1, Ordering::Relaxed);
        let (client_cx, left) = (cx.clone(), Arc::clone(&active));
        let spawned = std::thread::Builder::new()
            .name("foxglove-client".into())
            .spawn(move || {
                client::serve(stream, &client_cx);
                left.fetch_sub(1, Ordering::Relaxed);
            });
        match (spawned, threads.lock()) {
            (Ok(h), Ok(mut t)) => {
                t.retain(|h| !h.is_finished());
                t.push(h);
            }
            (Err(e), _) => {
                active.fetch_sub(1, Ordering::Relaxed);
                tracing::warn!("Foxglove: cannot start a client's thread: {e}");
            }
            (Ok(_), Err(_)) => {}
        }
    }
}

/// A session id for `serverInfo`: the start time, so a client sees a restarted server as new.
fn session_id() -> String {
    let ms = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis());
    format!("shoal-{ms}")
}

#[cfg(test)]
mod tests;
