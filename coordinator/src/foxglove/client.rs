//! One client's connection, on a thread of its own: the WebSocket handshake (the client must ask
//! for `foxglove.websocket.v1`), then a loop that reads the client's messages (bounded in size by
//! the WebSocket layer, in rate by a token bucket, in subscriptions by a cap) and writes what the
//! hub queued for it, only the channels it subscribed to. A client that keeps sending what is
//! refused, or that cannot keep up, is dropped; nothing it sends can stop the server.

use std::collections::BTreeMap;
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tungstenite::protocol::frame::coding::CloseCode;
use tungstenite::protocol::{CloseFrame, WebSocketConfig};
use tungstenite::{Message, WebSocket};

use super::fanout::{Shared, ToClient};
use super::limits::{
    Counters, CLIENT_BURST, CLIENT_MESSAGES_PER_S, CLIENT_QUEUE, HANDSHAKE_TIMEOUT,
    MAX_CLIENT_MESSAGE_BYTES, MAX_REFUSED_PER_CLIENT, MAX_SUBSCRIPTIONS, POLL, WRITE_TIMEOUT,
};
use super::protocol::{self, ClientMessage, Level};
use crate::web_tls::{self, Conn, Transport};

/// What every client thread shares.
#[derive(Clone)]
pub struct Context {
    /// The hub and the clients' queues.
    pub shared: Arc<Mutex<Shared>>,
    /// What was refused, for the server's report.
    pub counters: Arc<Counters>,
    /// Set when the server stops: send what is queued, close.
    pub stop: Arc<AtomicBool>,
    /// This server's session id (`serverInfo`).
    pub session: Arc<str>,
    /// Plain or TLS.
    pub transport: Transport,
}

/// Serves one client until it leaves, misbehaves or the server stops.
pub fn serve(stream: TcpStream, cx: &Context) {
    let Some(ws) = handshake(stream, cx) else {
        return;
    };
    let (tx, rx) = mpsc::sync_channel(CLIENT_QUEUE);
    let advertised = match cx.shared.lock() {
        Ok(mut s) => {
            s.clients.push(tx);
            protocol::advertise(s.hub.channels())
        }
        Err(_) => return,
    };
    let mut c = Connection {
        ws,
        cx: cx.clone(),
        subscriptions: BTreeMap::new(),
        bucket: Bucket::new(),
        refused: 0,
    };
    let greeting = [protocol::server_info(&cx.session), advertised];
    if greeting.into_iter().all(|t| c.send(Message::text(t))) {
        c.run(&rx);
    }
}

/// Accepts the WebSocket if the client gets through TLS (when the server speaks it) and speaks
/// the protocol; `None` otherwise (refused by TLS, refused with HTTP 400, or the handshake
/// failed or took too long).
fn handshake(tcp: TcpStream, cx: &Context) -> Option<WebSocket<Conn>> {
    let stream = web_tls::accept(tcp, &cx.transport, HANDSHAKE_TIMEOUT)
        .map_err(|refused| {
            cx.counters.bump(&cx.counters.tls_refused);
            tracing::debug!("Foxglove: a client refused: {refused}");
        })
        .ok()?;
    let ok = stream.set_read_timeout(Some(HANDSHAKE_TIMEOUT)).is_ok()
        && stream.tcp().set_write_timeout(Some(WRITE_TIMEOUT)).is_ok()
        && stream.tcp().set_nodelay(true).is_ok();
    if !ok {
        return None;
    }
    let config = WebSocketConfig::default()
        .max_message_size(Some(MAX_CLIENT_MESSAGE_BYTES))
        .max_frame_size(Some(MAX_CLIENT_MESSAGE_BYTES));
    let ws = tungstenite::accept_hdr_with_config(stream, choose_subprotocol, Some(config))
        .map_err(|e| {
            cx.counters.bump(&cx.counters.handshakes_failed);
            tracing::debug!("Foxglove: a handshake failed: {e}");
        })
        .ok()?;
    if ws.get_ref().set_read_timeout(Some(POLL)).is_err() {
        return None;
    }
    Some(ws)
}

/// The handshake's answer: `foxglove.websocket.v1` if the client offers it, HTTP 400 otherwise.
// The signature is tungstenite's handshake callback's.
#[allow(clippy::result_large_err)]
fn choose_subprotocol(req: &Request, mut response: Response) -> Result<Response, ErrorResponse> {
    let offered = req
        .headers()
        .get_all("Sec-WebSocket-Protocol")
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(','))
        .any(|p| p.trim() == protocol::SUBPROTOCOL);
    if !offered {
        let mut refusal = ErrorResponse::new(Some(format!(
            "ask for the WebSocket subprotocol {}",
            protocol::SUBPROTOCOL
        )));
        *refusal.status_mut() = tungstenite::http::StatusCode::BAD_REQUEST;
        return Err(refusal);
    }
    response.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        tungstenite::http::HeaderValue::from_static(protocol::SUBPROTOCOL),
    );
    Ok(response)
}

/// How fast a client may send: [`CLIENT_BURST`] messages at once, [`CLIENT_MESSAGES_PER_S`]
/// on average.
struct Bucket {
    tokens: f64,
    last: Instant,
}

impl Bucket {
    fn new() -> Bucket {
        Bucket {
            tokens: CLIENT_BURST,
            last: Instant::now(),
        }
    }

    /// Whether one more message may come now.
    fn take(&mut self, now: Instant) -> bool {
        let refill = now.duration_since(self.last).as_secs_f64() * CLIENT_MESSAGES_PER_S;
        self.tokens = (self.tokens + refill).min(CLIENT_BURST);
        self.last = now;
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            true
        } else {
            false
        }
    }
}

/// Why the loop ends.
enum End {
    /// The client closed, or the connection broke.
    Gone,
    /// The client was dropped (counted): the connection closes with this code.
    Dropped(CloseCode),
    /// The server stops.
    Stop,
}

struct Connection {
    ws: WebSocket<Conn>,
    cx: Context,
    /// Channel → the client's id of its subscription to it (one per channel).
    subscriptions: BTreeMap<u32, u32>,
    bucket: Bucket,
    /// Messages refused so far.
    refused: u32,
}

impl Connection {
    fn run(&mut self, rx: &Receiver<ToClient>) {
        let end = loop {
            if let Some(end) = self.read_one() {
                break end;
            }
            if let Some(end) = self.write_queued(rx) {
                break end;
            }
            if self.cx.stop.load(Ordering::Relaxed) {
                // Everything the hub had is queued by now: send it, then close.
                let _ = self.write_queued(rx);
                break End::Stop;
            }
        };
        let code = match end {
            End::Gone => return,
            End::Dropped(code) => code,
            End::Stop => CloseCode::Away,
        };
        let _ = self.ws.close(Some(CloseFrame {
            code,
            reason: "".into(),
        }));
        let _ = self.ws.flush();
    }

    /// Reads one message if one comes within [`POLL`].
    fn read_one(&mut self) -> Option<End> {
        match self.ws.read() {
            Ok(Message::Text(t)) => self.on_text(t.as_str()),
            Ok(Message::Binary(_)) => self.refuse("Shoal takes no client channels"),
            Ok(Message::Close(_)) => {
                // Sends the close reply the WebSocket layer queued.
                let _ = self.ws.flush();
                Some(End::Gone)
            }
            Ok(_) => None, // ping, pong: answered by the WebSocket layer
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                None
            }
            Err(tungstenite::Error::Capacity(e)) => {
                self.cx.counters.bump(&self.cx.counters.messages_refused);
                self.drop_client(CloseCode::Size, &format!("a message too large ({e})"))
            }
            Err(tungstenite::Error::Protocol(e)) => {
                self.cx.counters.bump(&self.cx.counters.messages_refused);
                self.drop_client(CloseCode::Protocol, &format!("a protocol violation ({e})"))
            }
            Err(_) => Some(End::Gone),
        }
    }

    fn on_text(&mut self, text: &str) -> Option<End> {
        if !self.bucket.take(Instant::now()) {
            // Over the rate: counted, not answered (an answer would feed a flood).
            self.cx.counters.bump(&self.cx.counters.messages_refused);
            self.refused += 1;
            return (self.refused > MAX_REFUSED_PER_CLIENT)
                .then(|| self.drop_client(CloseCode::Policy, "too many refused messages"))
                .flatten();
        }
        match ClientMessage::parse(text) {
            Ok(ClientMessage::Subscribe { subscriptions }) => {
                for s in subscriptions {
                    if let Some(end) = self.subscribe(s.id, s.channel) {
                        return Some(end);
                    }
                }
                None
            }
            Ok(ClientMessage::Unsubscribe { ids }) => {
                self.subscriptions.retain(|_, id| !ids.contains(id));
                None
            }
            Err(_) => self.refuse("not a subscribe or unsubscribe message"),
        }
    }

    /// Subscribes channel `channel` as `id`, and sends its latest messages.
    fn subscribe(&mut self, id: u32, channel: u32) -> Option<End> {
        if self.subscriptions.len() >= MAX_SUBSCRIPTIONS {
            return self.refuse("too many subscriptions");
        }
        if self.subscriptions.values().any(|s| *s == id) {
            return self.refuse("a subscription id already in use");
        }
        if self.subscriptions.contains_key(&channel) {
            return self.refuse("a channel already subscribed");
        }
        let latched = match self.cx.shared.lock() {
            Ok(s) => s.hub.has_channel(channel).then(|| s.hub.latched(channel)),
            Err(_) => return Some(End::Gone),
        };
        let Some(latched) = latched else {
            return self.refuse("no such channel");
        };
        self.subscriptions.insert(channel, id);
        for d in latched {
            if !self.send(Message::binary(protocol::message_data(id, &d))) {
                return Some(End::Gone);
            }
        }
        None
    }

    /// Refuses a message: counted, told to the client; dropped after too many.
    fn refuse(&mut self, why: &str) -> Option<End> {
        self.cx.counters.bump(&self.cx.counters.messages_refused);
        self.refused += 1;
        if self.refused > MAX_REFUSED_PER_CLIENT {
            return self.drop_client(CloseCode::Policy, "too many refused messages");
        }
        let text = protocol::status(Level::Warning, &format!("refused: {why}"));
        (!self.send(Message::text(text))).then_some(End::Gone)
    }

    fn drop_client(&mut self, code: CloseCode, why: &str) -> Option<End> {
        self.cx.counters.bump(&self.cx.counters.clients_dropped);
        tracing::info!("Foxglove: a client dropped for {why}");
        let text = protocol::status(Level::Error, &format!("disconnected: {why}"));
        let _ = self.ws.send(Message::text(text));
        Some(End::Dropped(code))
    }

    /// Writes what the hub queued; `Some` when the client is gone or too slow.
    fn write_queued(&mut self, rx: &Receiver<ToClient>) -> Option<End> {
        let mut wrote = false;
        loop {
            let m = match rx.try_recv() {
                Ok(m) => m,
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => {
                    // The hub cut this client off: it fell a whole queue behind.
                    self.cx.counters.bump(&self.cx.counters.clients_dropped);
                    return Some(End::Dropped(CloseCode::Again));
                }
            };
            let message = match m {
                ToClient::Advertise(text) => Message::text(text.as_ref()),
                ToClient::Unadvertise(ids, text) => {
                    self.subscriptions
                        .retain(|channel, _| !ids.contains(channel));
                    Message::text(text.as_ref())
                }
                ToClient::Data(d) => match self.subscriptions.get(&d.channel) {
                    Some(id) => Message::binary(protocol::message_data(*id, &d)),
                    None => continue,
                },
            };
            if self.ws.write(message).is_err() {
                return Some(End::Gone);
            }
            wrote = true;
        }
        (wrote && self.ws.flush().is_err()).then_some(End::Gone)
    }

    /// Sends one message now; false when the connection is gone.
    fn send(&mut self, m: Message) -> bool {
        self.ws.send(m).is_ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn the_bucket_allows_a_burst_then_the_rate() {
        let mut b = Bucket::new();
        let t0 = b.last;
        let burst = (0..1000).take_while(|_| b.take(t0)).count();
        assert_eq!(burst as f64, CLIENT_BURST);
        assert!(!b.take(t0));
        let later = t0 + Duration::from_secs(1);
        let refilled = (0..1000).take_while(|_| b.take(later)).count();
        assert_eq!(refilled as f64, CLIENT_MESSAGES_PER_S);
    }
}
