//! An accepted connection, plain or TLS, as the blocking `Read + Write` stream both servers'
//! threads (and tungstenite) use. The TLS handshake runs on the connection's own thread, so it
//! holds one of the server's connection places, and it has a deadline: a client that connects
//! and says nothing is dropped when it passes. Timeouts set on the TCP socket keep working
//! through TLS: a read that times out returns `WouldBlock`/`TimedOut` and rustls keeps any
//! partial record for the next read.

use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rustls::{ServerConfig, ServerConnection, StreamOwned};

use super::identity::may_watch;

/// One accepted connection.
pub enum Conn {
    /// Plain TCP.
    Plain(TcpStream),
    /// TLS over TCP, handshake done and the client allowed.
    Tls(Box<StreamOwned<ServerConnection, TcpStream>>),
}

/// Why a TLS client was dropped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Refused {
    /// The handshake did not finish within its deadline.
    TimedOut,
    /// The handshake failed: no certificate, one the fleet CA did not sign, not TLS 1.3, not
    /// TLS at all, or the connection closed.
    Handshake(String),
    /// A fleet member that may not watch (a vehicle).
    NotAllowed(String),
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refused::TimedOut => write!(f, "the TLS handshake took too long"),
            Refused::Handshake(e) => write!(f, "the TLS handshake failed: {e}"),
            Refused::NotAllowed(who) => write!(f, "{who} may not watch the fleet"),
        }
    }
}

impl Conn {
    /// The TCP socket under it, for its timeouts.
    pub fn tcp(&self) -> &TcpStream {
        match self {
            Conn::Plain(s) => s,
            Conn::Tls(s) => &s.sock,
        }
    }

    /// Sets the socket's read timeout (a read through TLS waits the same).
    pub fn set_read_timeout(&self, t: Option<Duration>) -> std::io::Result<()> {
        self.tcp().set_read_timeout(t)
    }
}

impl Read for Conn {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Conn::Plain(s) => s.read(buf),
            Conn::Tls(s) => s.read(buf),
        }
    }
}

impl Write for Conn {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match self {
            Conn::Plain(s) => s.write(buf),
            Conn::Tls(s) => s.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        match self {
            Conn::Plain(s) => s.flush(),
            Conn::Tls(s) => s.flush(),
        }
    }
}

/// The TLS handshake on a blocking socket, within `deadline`, and the check that the client
/// may watch.
pub(super) fn handshake(
    mut tcp: TcpStream,
    config: &Arc<ServerConfig>,
    deadline: Duration,
) -> Result<Conn, Refused> {
    let io = |e: std::io::Error| Refused::Handshake(e.to_string());
    let mut conn =
        ServerConnection::new(Arc::clone(config)).map_err(|e| Refused::Handshake(e.to_string()))?;
    let until = Instant::now() + deadline;
    tcp.set_write_timeout(Some(deadline)).map_err(io)?;
    while conn.is_handshaking() {
        // Checked before each read, so a client trickling bytes cannot stretch it either.
        let left = until
            .checked_duration_since(Instant::now())
            .filter(|d| !d.is_zero())
            .ok_or(Refused::TimedOut)?;
        tcp.set_read_timeout(Some(left)).map_err(io)?;
        while conn.wants_write() {
            conn.write_tls(&mut tcp).map_err(io)?;
        }
        if !conn.is_handshaking() {
            break;
        }
        match conn.read_tls(&mut tcp) {
            Ok(0) => return Err(Refused::Handshake("the client closed".into())),
            Ok(_) => {}
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                return Err(Refused::TimedOut)
            }
            Err(e) => return Err(io(e)),
        }
        if let Err(e) = conn.process_new_packets() {
            // Tell the client why (the alert rustls queued), then drop it.
            let _ = conn.write_tls(&mut tcp);
            return Err(Refused::Handshake(e.to_string()));
        }
    }
    let allowed = match conn.peer_certificates().and_then(|c| c.first()) {
        Some(cert) => may_watch(cert),
        None => Err("a client without a certificate".to_string()),
    };
    if let Err(who) = allowed {
        conn.send_close_notify();
        let _ = conn.write_tls(&mut tcp);
        return Err(Refused::NotAllowed(who));
    }
    while conn.wants_write() {
        conn.write_tls(&mut tcp).map_err(io)?;
    }
    Ok(Conn::Tls(Box::new(StreamOwned::new(conn, tcp))))
}
