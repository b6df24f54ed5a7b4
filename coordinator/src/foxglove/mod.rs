//! A Foxglove WebSocket server (protocol `foxglove.websocket.v1`) showing a mission live in
//! Foxglove or Lichtblick, its open-source fork: `run --foxglove ADDR` (and `replay`, `serve`)
//! serves what the execution's live feed ([`crate::execute::live`]) publishes.
//!
//! Channels (JSON messages, each with a JSON Schema; see `channels`):
//!
//! | topic | schema | what |
//! |---|---|---|
//! | `/shoal/pose/<vehicle>` | `foxglove.PoseInFrame` | each report, in the scenario frame `shoal` |
//! | `/shoal/location/<vehicle>` | `foxglove.LocationFix` | each report on WGS-84 (scenarios with an `[origin]` only) |
//! | `/shoal/scene` | `foxglove.SceneUpdate` | bounds box, obstacles (spheres), planned paths; re-sent on each plan and obstacle |
//! | `/shoal/status` | `shoal.status` | the fleet status, once a second |
//! | `/shoal/events` | `shoal.event` | the coordinator's decisions and observations |
//!
//! A client that subscribes late first gets each channel's latest message (the latest events).
//!
//! **Why not the `foxglove` crate.** The official SDK (`foxglove` 0.30) runs its WebSocket
//! server on tokio-tungstenite with a process-wide context, always builds its protobuf message
//! types (prost) and offers no cap on clients or on the rate of their messages, which Shoal
//! needs on anything that listens. Its well-known schemas are served as protobuf, where Shoal's
//! logs and tools are JSON. The part of the protocol a server that only publishes needs is
//! small (`protocol`), so it is implemented here on `tungstenite` (the synchronous WebSocket
//! crate the SDK itself builds on), on threads of its own: the execution loop never waits for
//! a client.
//!
//! **Security.** The protocol has no authentication of its own. The server listens on loopback
//! by default, plain `ws://`; beyond loopback it follows the fleet's security settings as the
//! Zenoh router does ([`crate::web_tls`]): with the coordinator's TLS identity it serves
//! `wss://` with mutual TLS to the coordinator and the operators only (a vehicle's certificate
//! is refused, a refused client dropped and counted in [`Counters::tls_refused`]); with
//! `--insecure` alone plain `ws://`, with a warning; with neither it refuses to start.

mod channels;
mod client;
mod fanout;
mod hub;
mod limits;
pub mod pace;
mod protocol;
mod schemas;
mod server;
mod shaping;

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use crate::execute::live::LiveFeed;
use crate::execute::log;
use crate::web_tls::{self, Transport};
use shoal_common::wire::security::Security;

pub use limits::{Counters, MAX_CLIENTS};
pub use server::FoxgloveServer;

/// Foxglove's default port, where its "Open connection" dialog looks first.
pub const DEFAULT_PORT: u16 = 8765;

/// `--foxglove [ADDR]`, flattened into the commands that can serve a mission to Foxglove.
#[derive(Debug, Clone, Default, PartialEq, Eq, clap::Args)]
pub struct FoxgloveArgs {
    /// Serve the mission live to Foxglove (or Lichtblick) over its WebSocket protocol at ADDR:
    /// `PORT` or `IP:PORT` (loopback by default; beyond it, mutual TLS with the fleet's keys or
    /// --insecure). Without a value: 127.0.0.1:8765.
    #[arg(
        long,
        env = "SHOAL_FOXGLOVE",
        value_name = "ADDR",
        num_args = 0..=1,
        default_missing_value = "8765",
        value_parser = parse_address
    )]
    pub foxglove: Option<SocketAddr>,
}

impl FoxgloveArgs {
    /// Where and how to serve, if asked: plain on loopback, mutual TLS beyond it with the
    /// fleet's keys, plain with `--insecure`, refused otherwise (see [`crate::web_tls`]).
    pub fn settings(&self, security: &Security) -> anyhow::Result<Option<(SocketAddr, Transport)>> {
        let Some(addr) = self.foxglove else {
            return Ok(None);
        };
        let transport = web_tls::choose("--foxglove", "Foxglove server", addr, security)?;
        Ok(Some((addr, transport)))
    }
}

/// Starts the server `args` ask for (reached as `security` allows) on a live feed, and says on
/// stderr where it listens; the feed is the execution's to fill.
pub fn start(
    args: &FoxgloveArgs,
    security: &Security,
    feed: &Arc<LiveFeed>,
) -> anyhow::Result<Option<FoxgloveServer>> {
    let Some((addr, transport)) = args.settings(security)? else {
        return Ok(None);
    };
    let scheme = transport.scheme(false);
    let server = FoxgloveServer::start(addr, transport, Arc::clone(feed))?;
    eprintln!(
        "Foxglove WebSocket server on {scheme}://{} (open it in Foxglove or Lichtblick)",
        server.local_addr()
    );
    Ok(Some(server))
}

/// Serves the mission log at `path` on `addr` over `transport`: waits for the first client,
/// then plays the log at `speed` times its recorded pace ([`pace::play`]) and stops. False when
/// `stop` cut it short.
pub fn stream_log(
    (addr, transport): (SocketAddr, Transport),
    path: &Path,
    speed: f64,
    stop: &AtomicBool,
) -> anyhow::Result<bool> {
    let records = log::read(path)?.records;
    // A status per wall second of the run, as it published them live.
    let statuses = crate::execute::replayed::Statuses::new(&records, path, 0.0)?;
    let feed = LiveFeed::new();
    let scheme = transport.scheme(false);
    let server = FoxgloveServer::start(addr, transport, Arc::clone(&feed))?;
    eprintln!(
        "Foxglove WebSocket server on {scheme}://{}: the log plays at {speed} × its pace once a \
         client connects",
        server.local_addr()
    );
    while server.counters().clients_served.load(Ordering::Relaxed) == 0 {
        if stop.load(Ordering::Relaxed) {
            return Ok(false);
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let played = pace::play(&records, Some(statuses), &feed, speed, stop);
    server.shutdown();
    Ok(played)
}

/// Reads `PORT` (on 127.0.0.1), `IP:PORT` or `localhost:PORT`.
pub fn parse_address(s: &str) -> Result<SocketAddr, String> {
    let s = s.trim();
    if let Ok(port) = s.parse::<u16>() {
        return Ok(SocketAddr::new(IpAddr::V4(Ipv4Addr::LOCALHOST), port));
    }
    if let Some(port) = s.strip_prefix("localhost:") {
        if let Ok(port) = port.parse::<u16>() {
            return Ok(SocketAddr::new(IpAddr::V4(Ipv4Addr::LOCALHOST), port));
        }
    }
    s.parse::<SocketAddr>()
        .map_err(|_| format!("{s:?}: expected PORT, IP:PORT or localhost:PORT"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        fox: FoxgloveArgs,
    }

    #[test]
    fn addresses_default_to_loopback_and_foxgloves_port() -> Result<(), clap::Error> {
        let at = |args: &[&str]| -> Result<Option<SocketAddr>, clap::Error> {
            Ok(Cli::try_parse_from(args)?.fox.foxglove)
        };
        assert_eq!(at(&["x"])?, None);
        assert_eq!(at(&["x", "--foxglove"])?, "127.0.0.1:8765".parse().ok());
        assert_eq!(
            at(&["x", "--foxglove", "9000"])?,
            "127.0.0.1:9000".parse().ok()
        );
        assert_eq!(
            at(&["x", "--foxglove", "localhost:9001"])?,
            "127.0.0.1:9001".parse().ok()
        );
        assert_eq!(
            at(&["x", "--foxglove", "[::1]:9002"])?,
            "[::1]:9002".parse().ok()
        );
        assert!(at(&["x", "--foxglove", "example.org:80"]).is_err());
        assert!(at(&["x", "--foxglove", "70000"]).is_err());
        Ok(())
    }

    #[test]
    fn beyond_loopback_is_refused_without_keys_or_insecure() {
        let open = FoxgloveArgs {
            foxglove: "0.0.0.0:8765".parse().ok(),
        };
        let e = open
            .settings(&Security::default())
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.contains("--foxglove 0.0.0.0:8765: beyond loopback"),
            "{e}"
        );
        assert!(e.contains("--insecure") && e.contains("mutual TLS"), "{e}");
        let insecure = Security {
            insecure: true,
            ..Security::default()
        };
        let addr = |s: anyhow::Result<Option<(SocketAddr, Transport)>>| {
            s.ok().flatten().map(|(a, t)| (a, t.scheme(false)))
        };
        assert_eq!(
            addr(open.settings(&insecure)),
            open.foxglove.map(|a| (a, "ws"))
        );
        let local = FoxgloveArgs {
            foxglove: "127.0.0.1:8765".parse().ok(),
        };
        assert_eq!(
            addr(local.settings(&Security::default())),
            local.foxglove.map(|a| (a, "ws"))
        );
        assert!(addr(FoxgloveArgs::default().settings(&Security::default())).is_none());
    }
}
