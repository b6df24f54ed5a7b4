//! One connected page: the catch-up, then every tick ([`TICK`]) what the feed queued since, as
//! one frame; meanwhile what the page sends is read within its bounds.
//!
//! A page that reads too slowly blocks this thread's writes, not the execution: its feed queue
//! fills, the feed cuts it off, and it gets a fresh catch-up here (a `reset` first) rather than a
//! backlog. A write blocked for longer than the socket's write timeout drops the page.

use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, TryRecvError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use tungstenite::{Error, Message, WebSocket};

use super::message::{push_json, Shaper, ViewMessage};
use super::replay::ReplayLog;
use super::shared::{Shared, Source, MAX_INCOMING_PER_S};
use crate::execute::live::{LiveFeed, LiveMessage};
use crate::web_tls::Conn;

/// How often a page gets what happened: also how long a read from it waits.
pub(super) const TICK: Duration = Duration::from_millis(100);
/// Feed messages sent in one frame at most (the rest go in the next).
const MAX_BATCH: usize = 4096;

/// Why a connection ends.
#[derive(Debug)]
pub(super) struct Ended;

/// Serves the page on `ws` until it leaves, breaks a rule, or the server stops.
pub(super) fn serve(ws: &mut WebSocket<Conn>, shared: &Shared) {
    let mut incoming = Incoming::default();
    let _ = match &shared.source {
        Source::Live(feed) => live(ws, feed, shared, &mut incoming),
        Source::Log(log) => replay(ws, log, shared, &mut incoming),
    };
    let _ = ws.close(None);
    let _ = ws.flush();
}

fn send(ws: &mut WebSocket<Conn>, text: String) -> Result<(), Ended> {
    ws.send(Message::text(text)).map_err(|_| Ended)
}

/// A live execution: a subscription, its catch-up, then its messages; a new subscription after
/// being cut off.
fn live(
    ws: &mut WebSocket<Conn>,
    feed: &LiveFeed,
    shared: &Shared,
    incoming: &mut Incoming,
) -> Result<(), Ended> {
    loop {
        let sub = feed.subscribe();
        shared.stats.catch_ups.fetch_add(1, Ordering::Relaxed);
        let mut shaper = Shaper::default();
        let mut out = String::from("[");
        push_json(&mut out, &ViewMessage::Hello { mode: "live" });
        push_json(&mut out, &ViewMessage::Reset);
        for m in sub.catch_up.messages() {
            shaper.push(&mut out, &m);
        }
        push_json(&mut out, &ViewMessage::CaughtUp);
        out.push(']');
        send(ws, out)?;
        loop {
            if shared.stop.load(Ordering::Relaxed) {
                return Ok(());
            }
            incoming.poll(ws, shared)?;
            let (batch, cut_off) = drain(&sub.messages);
            if !batch.is_empty() {
                let mut out = String::from("[");
                for m in &batch {
                    shaper.push(&mut out, m);
                }
                out.push(']');
                send(ws, out)?;
            }
            if cut_off {
                break;
            }
        }
    }
}

/// What the feed has queued (at most [`MAX_BATCH`]), and whether the subscription is over.
fn drain(rx: &Receiver<Arc<LiveMessage>>) -> (Vec<Arc<LiveMessage>>, bool) {
    let mut batch = Vec::new();
    while batch.len() < MAX_BATCH {
        match rx.try_recv() {
            Ok(m) => batch.push(m),
            Err(TryRecvError::Empty) => return (batch, false),
            Err(TryRecvError::Disconnected) => return (batch, true),
        }
    }
    (batch, false)
}

/// A finished log: all of it, then nothing but the page's own messages until it leaves.
fn replay(
    ws: &mut WebSocket<Conn>,
    log: &ReplayLog,
    shared: &Shared,
    incoming: &mut Incoming,
) -> Result<(), Ended> {
    shared.stats.catch_ups.fetch_add(1, Ordering::Relaxed);
    for frame in &log.frames {
        send(ws, frame.clone())?;
    }
    while !shared.stop.load(Ordering::Relaxed) {
        incoming.poll(ws, shared)?;
    }
    Ok(())
}

/// The page's messages within their bounds: the page needs to send nothing, so anything but
/// control frames is dropped and counted, and more than [`MAX_INCOMING_PER_S`] a second (or one
/// over the size limit, which tungstenite enforces) ends the connection.
#[derive(Default)]
pub(super) struct Incoming {
    /// Start of the current one-second window.
    window: Option<Instant>,
    /// Messages in it.
    count: u32,
}

impl Incoming {
    /// Counts one message; `Err` when the page is over the rate.
    fn count(&mut self, now: Instant) -> Result<(), Ended> {
        match self.window {
            Some(w) if now.duration_since(w) < Duration::from_secs(1) => self.count += 1,
            _ => {
                self.window = Some(now);
                self.count = 1;
            }
        }
        if self.count > MAX_INCOMING_PER_S {
            return Err(Ended);
        }
        Ok(())
    }

    /// Reads what the page sent, waiting up to [`TICK`] for the first message.
    fn poll(&mut self, ws: &mut WebSocket<Conn>, shared: &Shared) -> Result<(), Ended> {
        let dropped = || {
            shared
                .stats
                .dropped_messages
                .fetch_add(1, Ordering::Relaxed)
        };
        loop {
            match ws.read() {
                Ok(m) => {
                    if self.count(Instant::now()).is_err() {
                        dropped();
                        return Err(Ended);
                    }
                    match m {
                        Message::Close(_) => return Err(Ended),
                        // Pings are answered by tungstenite on the next write or read.
                        Message::Ping(_) | Message::Pong(_) | Message::Frame(_) => {}
                        Message::Text(_) | Message::Binary(_) => {
                            dropped();
                        }
                    }
                }
                Err(Error::Io(e))
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) =>
                {
                    return Ok(())
                }
                Err(Error::Capacity(_)) | Err(Error::Protocol(_)) | Err(Error::AttackAttempt) => {
                    dropped();
                    return Err(Ended);
                }
                Err(_) => return Err(Ended),
            }
        }
    }
}
