//! How the web view and the Foxglove server are reached, decided as the fleet's Zenoh router
//! decides it for its endpoints:
//!
//! | address | settings | served as |
//! |---|---|---|
//! | loopback | any | plain HTTP / ws, nobody authenticated (only this machine reaches it) |
//! | beyond loopback | the coordinator's TLS identity and the fleet CA | HTTPS / WSS, TLS 1.3, mutual TLS: only the coordinator and operators may watch |
//! | beyond loopback | `--insecure`, no TLS identity | plain, with a warning (a lab network nobody else reaches) |
//! | beyond loopback | neither | refused at start, saying how to fix it |
//!
//! The TLS files are the router's own ([`Security::server_tls`]: `--zenoh-config`'s
//! `transport/link/tls/...` keys, `--tls-*` flags over them). Who may watch: a client
//! certificate signed by the fleet CA whose common name is `coordinator` or whose
//! organizational unit is [`OPERATOR_UNIT`](crate::acl::OPERATOR_UNIT), which `shoal-coordinator keys` writes into every
//! operator's certificate. A vehicle's certificate is refused: a vehicle has no business
//! reading the whole fleet (the access-control rules deny it the same).

mod identity;
mod stream;

use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use std::time::Duration;

use shoal_common::wire::security::Security;

pub use identity::{may_watch, server_config};
pub use stream::{Conn, Refused};

/// How one server speaks to its clients.
#[derive(Clone)]
pub enum Transport {
    /// Plain TCP: loopback, or `--insecure`.
    Plain,
    /// TLS 1.3 with client certificates over the fleet CA.
    Tls(Arc<rustls::ServerConfig>),
}

impl Transport {
    /// The URL scheme a browser uses: `http` or `https` (`ws`/`wss` for sockets).
    pub fn scheme(&self, web: bool) -> &'static str {
        match (self, web) {
            (Transport::Plain, true) => "http",
            (Transport::Tls(_), true) => "https",
            (Transport::Plain, false) => "ws",
            (Transport::Tls(_), false) => "wss",
        }
    }
}

/// Makes an accepted socket a blocking connection of `transport`: as it is for plain TCP; for
/// TLS, after a handshake of at most `deadline` with a client that may watch ([`may_watch`]).
/// The socket's timeouts are the caller's to set afterwards.
pub fn accept(tcp: TcpStream, transport: &Transport, deadline: Duration) -> Result<Conn, Refused> {
    tcp.set_nonblocking(false)
        .map_err(|e| Refused::Handshake(e.to_string()))?;
    match transport {
        Transport::Plain => Ok(Conn::Plain(tcp)),
        Transport::Tls(config) => stream::handshake(tcp, config, deadline),
    }
}

/// Which of the four rows of the table above applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Loopback: plain.
    Loopback,
    /// Beyond loopback with the fleet's TLS identity: mutual TLS.
    MutualTls,
    /// Beyond loopback with `--insecure` and no TLS identity: plain.
    Insecure,
}

/// The rule alone: `None` (beyond loopback with neither TLS nor `--insecure`) is refused. With
/// both, TLS wins: `--insecure` permits plain traffic, it does not ask for it.
pub fn mode(addr: SocketAddr, has_tls: bool, insecure: bool) -> Option<Mode> {
    match (addr.ip().is_loopback(), has_tls, insecure) {
        (true, _, _) => Some(Mode::Loopback),
        (false, true, _) => Some(Mode::MutualTls),
        (false, false, true) => Some(Mode::Insecure),
        (false, false, false) => None,
    }
}

/// Decides how the server `flag` names (`--view`, `--foxglove`) serves at `addr` under the
/// fleet's `security`; `what` names it in messages. Reads the TLS files when they are needed.
pub fn choose(
    flag: &str,
    what: &str,
    addr: SocketAddr,
    security: &Security,
) -> anyhow::Result<Transport> {
    let files = if addr.ip().is_loopback() {
        None
    } else {
        security.server_tls()?
    };
    match (mode(addr, files.is_some(), security.insecure), files) {
        (Some(Mode::MutualTls), Some(files)) => Ok(Transport::Tls(server_config(&files)?)),
        (Some(Mode::Insecure), _) => {
            tracing::warn!(
                "{flag} {addr}: serving the {what} beyond loopback without TLS or \
                 authentication (--insecure): anyone who reaches the port sees the fleet"
            );
            Ok(Transport::Plain)
        }
        (Some(_), _) => Ok(Transport::Plain),
        (None, _) => Err(refusal(flag, what, addr)),
    }
}

/// The error for an address beyond loopback with neither TLS nor `--insecure`: the three ways
/// out.
fn refusal(flag: &str, what: &str, addr: SocketAddr) -> anyhow::Error {
    let port = addr.port();
    anyhow::anyhow!(
        "{flag} {addr}: beyond loopback the {what} is served only over mutual TLS with the \
         fleet's keys, and none are set. Either give the coordinator's TLS identity \
         (--zenoh-config keys/coordinator.json5, or --tls-ca/--tls-cert/--tls-key; \
         `shoal-coordinator keys` makes them, and operators present their own certificate), \
         or listen on loopback ({flag} 127.0.0.1:{port}) and reach it through an SSH tunnel \
         (ssh -L {port}:127.0.0.1:{port} HOST), or pass --insecure on a network nobody else \
         reaches"
    )
}

#[cfg(test)]
pub(crate) mod tests;
