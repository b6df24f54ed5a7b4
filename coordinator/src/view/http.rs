//! The web view's HTTP side: reads one request head (at most [`MAX_REQUEST_BYTES`], within a
//! few seconds), answers `GET` of the page and its assets, and upgrades `GET /ws` to the
//! WebSocket `client` serves. One request per connection (`Connection: close`): the page loads
//! three files and then holds one WebSocket.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::Ordering;
use std::time::Duration;

use tungstenite::protocol::{Role, WebSocketConfig};
use tungstenite::WebSocket;

use super::shared::{Shared, MAX_CLIENTS, MAX_INCOMING_BYTES, MAX_REQUEST_BYTES};
use super::{assets, client};
use crate::web_tls::{self, Conn};

/// How long a connection may take to send its request head.
const HEAD_TIMEOUT: Duration = Duration::from_secs(5);
/// How long one write to a page may block before the page is dropped as too slow.
const WRITE_TIMEOUT: Duration = Duration::from_secs(5);
/// Headers read per request (a browser sends about fifteen).
const MAX_HEADERS: usize = 48;

/// A request head, read and checked.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Request {
    /// The path without its query.
    pub path: String,
    /// Lower-case names, values as sent.
    pub headers: Vec<(String, String)>,
}

impl Request {
    /// The value of header `name` (lower case).
    fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

/// An HTTP error answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Refusal {
    /// Malformed, or a WebSocket upgrade without its headers.
    BadRequest,
    /// A WebSocket from a page of another site.
    ForeignOrigin,
    /// No such path.
    NotFound,
    /// Not `GET`.
    NotGet,
    /// Head over [`MAX_REQUEST_BYTES`].
    TooLarge,
    /// [`MAX_CLIENTS`] pages connected.
    Full,
}

impl Refusal {
    fn status(self) -> &'static str {
        match self {
            Refusal::BadRequest => "400 Bad Request",
            Refusal::ForeignOrigin => "403 Forbidden",
            Refusal::NotFound => "404 Not Found",
            Refusal::NotGet => "405 Method Not Allowed",
            Refusal::TooLarge => "431 Request Header Fields Too Large",
            Refusal::Full => "503 Service Unavailable",
        }
    }
}

/// What a request asks for.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Route {
    /// A file of the page.
    Asset(&'static assets::Asset),
    /// The WebSocket, with the client's `Sec-WebSocket-Key`.
    Upgrade(String),
}

/// Parses a complete request head.
pub(super) fn parse(head: &[u8]) -> Result<Request, Refusal> {
    let mut headers = [httparse::EMPTY_HEADER; MAX_HEADERS];
    let mut req = httparse::Request::new(&mut headers);
    match req.parse(head) {
        Ok(httparse::Status::Complete(_)) => {}
        Err(httparse::Error::TooManyHeaders) => return Err(Refusal::TooLarge),
        _ => return Err(Refusal::BadRequest),
    }
    if req.method != Some("GET") {
        return Err(Refusal::NotGet);
    }
    let path = req.path.ok_or(Refusal::BadRequest)?;
    let path = path
        .split(['?', '#'])
        .next()
        .unwrap_or_default()
        .to_string();
    let headers = req
        .headers
        .iter()
        .map(|h| {
            let value = std::str::from_utf8(h.value).map_err(|_| Refusal::BadRequest)?;
            Ok((h.name.to_ascii_lowercase(), value.trim().to_string()))
        })
        .collect::<Result<_, Refusal>>()?;
    Ok(Request { path, headers })
}

/// Where a parsed request goes. A WebSocket must come from the page itself: a browser sends
/// the page's origin, which must name the host it asked (another site's script is refused).
pub(super) fn route(req: &Request) -> Result<Route, Refusal> {
    if req.path == "/ws" {
        let has = |name: &str, word: &str| {
            req.header(name)
                .is_some_and(|v| v.split(',').any(|w| w.trim().eq_ignore_ascii_case(word)))
        };
        if !(has("upgrade", "websocket")
            && has("connection", "upgrade")
            && req.header("sec-websocket-version") == Some("13"))
        {
            return Err(Refusal::BadRequest);
        }
        let key = req.header("sec-websocket-key").ok_or(Refusal::BadRequest)?;
        if let Some(origin) = req.header("origin") {
            let host = req.header("host").unwrap_or_default();
            let same = ["http://", "https://"]
                .iter()
                .any(|scheme| origin.strip_prefix(scheme) == Some(host));
            if !same {
                return Err(Refusal::ForeignOrigin);
            }
        }
        return Ok(Route::Upgrade(key.to_string()));
    }
    assets::find(&req.path)
        .map(Route::Asset)
        .ok_or(Refusal::NotFound)
}

/// A request head and the bytes read after it.
type Head = (Vec<u8>, Vec<u8>);

/// Reads a request head: up to the blank line, at most [`MAX_REQUEST_BYTES`]. `Ok(None)`: the
/// connection closed or went quiet before sending anything (a browser's spare connection).
fn read_head(stream: &mut Conn) -> Result<Option<Head>, Refusal> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 1024];
    loop {
        let n = match stream.read(&mut chunk) {
            Ok(n) => n,
            Err(_) if buf.is_empty() => return Ok(None),
            Err(_) => return Err(Refusal::BadRequest),
        };
        if n == 0 {
            return if buf.is_empty() {
                Ok(None)
            } else {
                Err(Refusal::BadRequest)
            };
        }
        let searched_from = buf.len().saturating_sub(3);
        buf.extend_from_slice(&chunk[..n]);
        if let Some(end) = buf[searched_from..]
            .windows(4)
            .position(|w| w == b"\r\n\r\n")
        {
            let end = searched_from + end + 4;
            if end > MAX_REQUEST_BYTES {
                return Err(Refusal::TooLarge);
            }
            let rest = buf.split_off(end);
            return Ok(Some((buf, rest)));
        }
        if buf.len() > MAX_REQUEST_BYTES {
            return Err(Refusal::TooLarge);
        }
    }
}

/// Serves one connection: the TLS handshake if the view speaks TLS (a client refused there is
/// counted and dropped), one request, then the WebSocket if it asked for one.
pub(super) fn serve_connection(tcp: TcpStream, shared: &Shared) {
    let mut stream = match web_tls::accept(tcp, &shared.transport, HEAD_TIMEOUT) {
        Ok(s) => s,
        Err(refused) => {
            shared.stats.refused_tls.fetch_add(1, Ordering::Relaxed);
            tracing::debug!("web view: a client refused: {refused}");
            return;
        }
    };
    let _ = stream.set_read_timeout(Some(HEAD_TIMEOUT));
    let _ = stream.tcp().set_write_timeout(Some(WRITE_TIMEOUT));
    let routed = match read_head(&mut stream) {
        Ok(None) => return,
        Ok(Some((head, rest))) => parse(&head).and_then(|r| route(&r)).map(|r| (r, rest)),
        Err(e) => Err(e),
    };
    match routed {
        Ok((Route::Asset(a), _)) => {
            let _ = answer(&mut stream, "200 OK", a.content_type, a.body);
        }
        Ok((Route::Upgrade(key), rest)) => upgrade(stream, &key, rest, shared),
        Err(refusal) => refuse(&mut stream, refusal, shared),
    }
}

/// Answers an error and counts it.
fn refuse(stream: &mut Conn, refusal: Refusal, shared: &Shared) {
    let counter = match refusal {
        Refusal::Full => &shared.stats.refused_clients,
        _ => &shared.stats.bad_requests,
    };
    counter.fetch_add(1, Ordering::Relaxed);
    let body = refusal.status().as_bytes();
    let _ = answer(stream, refusal.status(), "text/plain; charset=utf-8", body);
}

/// Writes a whole response and closes.
fn answer(stream: &mut Conn, status: &str, content_type: &str, body: &[u8]) -> std::io::Result<()> {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n\
         Content-Security-Policy: default-src 'self'; connect-src 'self'; img-src 'self' data:; frame-ancestors 'none'\r\n\
         Connection: close\r\n\r\n",
        body.len()
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(body)?;
    stream.flush()
}

/// Holds one of the [`MAX_CLIENTS`] places while a page is connected.
struct Place<'a>(&'a Shared);

impl<'a> Place<'a> {
    fn take(shared: &'a Shared) -> Option<Place<'a>> {
        let before = shared.stats.clients.fetch_add(1, Ordering::SeqCst);
        if before >= MAX_CLIENTS {
            shared.stats.clients.fetch_sub(1, Ordering::SeqCst);
            return None;
        }
        Some(Place(shared))
    }
}

impl Drop for Place<'_> {
    fn drop(&mut self) {
        self.0.stats.clients.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The WebSocket limits: what a page may send.
fn config() -> WebSocketConfig {
    WebSocketConfig::default()
        .max_message_size(Some(MAX_INCOMING_BYTES))
        .max_frame_size(Some(MAX_INCOMING_BYTES))
}

/// Completes the handshake (RFC 6455 §4.2.2) and hands the socket to `client`.
fn upgrade(mut stream: Conn, key: &str, rest: Vec<u8>, shared: &Shared) {
    let Some(_place) = Place::take(shared) else {
        refuse(&mut stream, Refusal::Full, shared);
        return;
    };
    let accept = tungstenite::handshake::derive_accept_key(key.as_bytes());
    let head = format!(
        "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Accept: {accept}\r\n\r\n"
    );
    if stream.write_all(head.as_bytes()).is_err() {
        return;
    }
    // From here the socket's read timeout is the client loop's tick.
    let _ = stream.set_read_timeout(Some(client::TICK));
    let mut ws = WebSocket::from_partially_read(stream, rest, Role::Server, Some(config()));
    client::serve(&mut ws, shared);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(text: &str) -> Result<Route, Refusal> {
        parse(text.as_bytes()).and_then(|r| route(&r))
    }

    const UPGRADE: &str = "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nUpgrade: websocket\r\n\
        Connection: keep-alive, Upgrade\r\nSec-WebSocket-Version: 13\r\n\
        Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n";

    #[test]
    fn the_page_its_files_and_the_socket_are_served() {
        for path in ["/", "/index.html", "/view.js", "/view.css", "/?x=1"] {
            let r = request(&format!("GET {path} HTTP/1.1\r\nHost: h\r\n\r\n"));
            assert!(matches!(r, Ok(Route::Asset(_))), "{path}: {r:?}");
        }
        let same = format!("{UPGRADE}Origin: http://127.0.0.1:8080\r\n\r\n");
        assert_eq!(
            request(&same),
            Ok(Route::Upgrade("dGhlIHNhbXBsZSBub25jZQ==".into()))
        );
        // RFC 6455 §1.3's example key and answer.
        assert_eq!(
            tungstenite::handshake::derive_accept_key(b"dGhlIHNhbXBsZSBub25jZQ=="),
            "s3pPLMBiTxaQ9kYGzzhZRbK+xOo="
        );
    }

    #[test]
    fn bad_requests_are_named() {
        assert_eq!(
            request("POST / HTTP/1.1\r\nHost: h\r\n\r\n"),
            Err(Refusal::NotGet)
        );
        assert_eq!(
            request("GET /etc/passwd HTTP/1.1\r\nHost: h\r\n\r\n"),
            Err(Refusal::NotFound)
        );
        assert_eq!(
            request("GET /ws HTTP/1.1\r\nHost: h\r\n\r\n"),
            Err(Refusal::BadRequest)
        );
        assert_eq!(request("nonsense\r\n\r\n"), Err(Refusal::BadRequest));
        let foreign = format!("{UPGRADE}Origin: http://evil.example\r\n\r\n");
        assert_eq!(request(&foreign), Err(Refusal::ForeignOrigin));
        let many: String = (0..MAX_HEADERS + 1)
            .map(|i| format!("X-{i}: y\r\n"))
            .collect();
        assert_eq!(
            request(&format!("GET / HTTP/1.1\r\n{many}\r\n")),
            Err(Refusal::TooLarge)
        );
    }
}
