//! The coordinator's side of the network: the embedded Zenoh router, the mission's inbox
//! (`shoal/<mission>/vehicle/*/out`), the agents' liveliness tokens, and sending.
//!
//! Every message is decoded here. One that does not decode, has another protocol version, or
//! names another mission or an unknown vehicle is dropped, counted and logged once per kind —
//! never a panic, never a stall.

use std::collections::HashSet;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use anyhow::Context as _;
use shoal_common::wire::agent_to_coordinator::AgentToCoordinator;
use shoal_common::wire::codec::{self, DecodeError};
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::security::Security;
use shoal_common::wire::{session, topics, Envelope};
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

/// Something that happened on the network.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A well-formed message of this mission from a known vehicle's agent.
    Message(AgentToCoordinator),
    /// The agent of a known vehicle is up (its liveliness token appeared).
    Alive(String),
    /// The agent of a known vehicle is gone (its token disappeared: exit, crash, cut link).
    Gone(String),
}

/// Raw input from the Zenoh callbacks (they must not do any work themselves).
enum Raw {
    Sample(String, Vec<u8>),
    Liveliness(SampleKind, String),
}

/// The coordinator's Zenoh session for one mission.
pub struct Network {
    session: Session,
    mission: String,
    vehicles: Vec<String>,
    rx: Receiver<Raw>,
    _inbox: Subscriber<()>,
    _alive: Subscriber<()>,
    _token: LivelinessToken,
    /// Where agents can connect (the listen endpoints with port 0 resolved).
    pub endpoints: Vec<String>,
    /// Messages dropped so far.
    pub dropped: u64,
    logged: HashSet<&'static str>,
    /// The last order number stamped on a message sent (see [`Envelope::seq`]). It starts at
    /// the opening's unix time in microseconds, so a coordinator restarted under the same
    /// mission id still counts up past what the agents took from the first.
    last_seq: AtomicU64,
}

impl Network {
    /// Opens the embedded router on `listen` (a port 0 is replaced by a free port), optionally
    /// linked to other `routers`, and subscribes to `mission`'s inbox and to every agent's token.
    pub fn open(
        listen: &[String],
        routers: &[String],
        security: &Security,
        mission: &str,
        vehicles: &[String],
    ) -> anyhow::Result<Network> {
        let endpoints = listen
            .iter()
            .map(|e| resolve_port_zero(e))
            .collect::<anyhow::Result<Vec<_>>>()?;
        let config = session::router_config(&endpoints, routers, security)?;
        let session = zenoh::open(config).wait().map_err(|e| {
            anyhow::anyhow!(
                "cannot open the coordinator's Zenoh router on {}: {e}",
                endpoints.join(", ")
            )
        })?;
        let (tx, rx) = mpsc::channel();
        let inbox_key = topics::coordinator_inbox(mission)?;
        let tx_in = tx.clone();
        let inbox = session
            .declare_subscriber(inbox_key.as_str())
            .callback(move |s| {
                let _ = tx_in.send(Raw::Sample(
                    s.key_expr().as_str().to_string(),
                    s.payload().to_bytes().into_owned(),
                ));
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot subscribe to {inbox_key}: {e}"))?;
        let alive = session
            .liveliness()
            .declare_subscriber(topics::ALL_LIVELINESS)
            .history(true)
            .callback(move |s| {
                let _ = tx.send(Raw::Liveliness(s.kind(), s.key_expr().as_str().to_string()));
            })
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot watch the agents' liveliness: {e}"))?;
        let token_key = topics::coordinator_liveliness(mission)?;
        let token = session
            .liveliness()
            .declare_token(token_key.as_str())
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot declare {token_key}: {e}"))?;
        Ok(Network {
            session,
            mission: mission.to_string(),
            vehicles: vehicles.to_vec(),
            rx,
            _inbox: inbox,
            _alive: alive,
            _token: token,
            endpoints: endpoints
                .iter()
                .map(|e| e.replace("/0.0.0.0:", "/127.0.0.1:"))
                .collect(),
            dropped: 0,
            logged: HashSet::new(),
            last_seq: AtomicU64::new(shoal_common::execution::unix_us()),
        })
    }

    fn drop_message(&mut self, kind: &'static str, detail: &str) {
        self.dropped += 1;
        if self.logged.insert(kind) {
            tracing::warn!(
                "dropped a message ({kind}): {detail}; further ones of this kind are only counted"
            );
        }
    }

    /// The next event, waiting until `deadline` at most.
    pub fn next(&mut self, deadline: Instant) -> Option<Event> {
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let raw = match self.rx.recv_timeout(left) {
                Ok(r) => r,
                Err(RecvTimeoutError::Timeout | RecvTimeoutError::Disconnected) => return None,
            };
            if let Some(event) = self.read(raw) {
                return Some(event);
            }
        }
    }

    fn read(&mut self, raw: Raw) -> Option<Event> {
        match raw {
            Raw::Liveliness(kind, key) => {
                let v = topics::vehicle_of_liveliness(&key)?;
                if !self.vehicles.iter().any(|x| x == v) {
                    return None; // another mission's agent: not ours to count
                }
                Some(match kind {
                    SampleKind::Put => Event::Alive(v.to_string()),
                    SampleKind::Delete => Event::Gone(v.to_string()),
                })
            }
            Raw::Sample(key, bytes) => {
                let message = match codec::decode::<AgentToCoordinator>(&bytes) {
                    Ok(m) => m.body,
                    Err(e @ DecodeError::Version { .. }) => {
                        self.drop_message("wrong protocol version", &format!("{key}: {e}"));
                        return None;
                    }
                    Err(e) => {
                        self.drop_message("malformed", &format!("{key}: {e}"));
                        return None;
                    }
                };
                let from_key = topics::mission_and_vehicle(&key);
                if message.mission() != self.mission
                    || from_key != Some((message.mission(), message.vehicle()))
                {
                    self.drop_message(
                        "mission or vehicle differs from its key",
                        &format!(
                            "{key} carries mission {:?}, vehicle {:?}",
                            message.mission(),
                            message.vehicle()
                        ),
                    );
                    return None;
                }
                if !self.vehicles.iter().any(|v| v == message.vehicle()) {
                    self.drop_message(
                        "unknown vehicle",
                        &format!("{key}: mission {} has no such vehicle", self.mission),
                    );
                    return None;
                }
                Some(Event::Message(message))
            }
        }
    }

    /// Counts a well-formed message that came at the wrong time (an old round).
    pub fn out_of_turn(&mut self, detail: &str) {
        self.drop_message("out of turn", detail);
    }

    fn put(&self, key: &str, message: CoordinatorToAgent) -> anyhow::Result<()> {
        let seq = self.last_seq.fetch_add(1, Ordering::Relaxed) + 1;
        let bytes = codec::encode(&Envelope::sequenced(message, seq))?;
        self.session
            .put(key, bytes)
            .congestion_control(CongestionControl::Block)
            .wait()
            .map_err(|e| anyhow::anyhow!("cannot publish on {key}: {e}"))
    }

    /// Sends `message` to the agent of `vehicle`.
    pub fn send(&self, vehicle: &str, message: CoordinatorToAgent) -> anyhow::Result<()> {
        self.put(&topics::to_agent(&self.mission, vehicle)?, message)
    }

    /// Sends `message` to every agent of the mission.
    pub fn broadcast(&self, message: CoordinatorToAgent) -> anyhow::Result<()> {
        self.put(&topics::fleet(&self.mission)?, message)
    }

    /// The Zenoh session, for the execution's open-interface keys.
    pub fn session(&self) -> &Session {
        &self.session
    }

    /// Closes the session (agents see the router go).
    pub fn close(self) {
        if let Err(e) = self.session.close().wait() {
            tracing::warn!("closing the Zenoh session: {e}");
        }
    }
}

/// Runs a bare router on `listen` until `shutdown` is raised (`shoal-coordinator router`).
pub fn serve_router(
    listen: &[String],
    security: &Security,
    shutdown: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<()> {
    let config = session::router_config(listen, &[], security)?;
    let session = zenoh::open(config)
        .wait()
        .map_err(|e| anyhow::anyhow!("cannot open a Zenoh router on {}: {e}", listen.join(", ")))?;
    eprintln!("router listening on {}; Ctrl-C to stop", listen.join(", "));
    while !shutdown.load(std::sync::atomic::Ordering::Relaxed) {
        std::thread::sleep(POLL);
    }
    if let Err(e) = session.close().wait() {
        tracing::warn!("closing the router: {e}");
    }
    Ok(())
}

/// `tcp/HOST:0` → `tcp/HOST:<a port free right now>`; other endpoints unchanged. (Zenoh 1.10
/// reports the bound port only through an unstable API, and agents need to know it.)
pub fn resolve_port_zero(endpoint: &str) -> anyhow::Result<String> {
    let Some(rest) = endpoint.strip_prefix("tcp/") else {
        return Ok(endpoint.to_string());
    };
    let Some((host, "0")) = rest.rsplit_once(':') else {
        return Ok(endpoint.to_string());
    };
    let bare = host.trim_start_matches('[').trim_end_matches(']');
    let listener = std::net::TcpListener::bind((bare, 0))
        .with_context(|| format!("cannot find a free port for {endpoint}"))?;
    let port = listener.local_addr()?.port();
    Ok(format!("tcp/{host}:{port}"))
}

/// How long to wait for something in a loop that also watches a flag.
pub const POLL: Duration = Duration::from_millis(100);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn port_zero_is_resolved_and_others_are_kept() -> anyhow::Result<()> {
        let e = resolve_port_zero("tcp/127.0.0.1:0")?;
        let port: u16 = e.rsplit_once(':').map_or(Ok(0), |(_, p)| p.parse())?;
        assert!(e.starts_with("tcp/127.0.0.1:") && port > 0, "{e}");
        assert_eq!(resolve_port_zero("tcp/0.0.0.0:7447")?, "tcp/0.0.0.0:7447");
        assert_eq!(
            resolve_port_zero("tcp/coordinator:7447")?,
            "tcp/coordinator:7447"
        );
        Ok(())
    }
}
