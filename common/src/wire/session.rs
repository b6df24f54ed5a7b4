//! The only place that builds a Zenoh [`Config`]: the coordinator embeds a router that listens,
//! every vehicle agent is a client that connects to it (a star; since Zenoh 1.9 peers no longer
//! relay for each other). Multicast scouting is off everywhere: endpoints are always explicit,
//! and multicast fails inside Docker networks and CI sandboxes.
//!
//! Endpoints come from users (CLI flags, `SHOAL_*` variables), so each is checked here and a bad
//! one is an error naming it. Only `tcp/<host>:<port>` and `tls/<host>:<port>` are accepted:
//! they are the transports built in, and a client waiting for its router would otherwise retry
//! a typo forever. How members authenticate is [`super::security`]'s; a router refuses to
//! listen beyond loopback unless whoever connects is authenticated (or `insecure` is set).
//!
//! Beware: in zenoh 1.10, `zenoh::open(config).await` (like every builder but `close`) resolves
//! synchronously inside `into_future`, so `tokio::time::timeout` around it bounds nothing. To
//! bound or cancel a client waiting for its router, open on a thread of its own (see the tests).

use std::str::FromStr;

use zenoh::config::EndPoint;
use zenoh::Config;

use super::codec::MAX_MESSAGE_BYTES;
use super::security::{self, Security};
use super::session_error::set;
pub use super::session_error::SessionError;

/// Transports compiled into zenoh (the workspace enables `transport_tcp` and `transport_tls`);
/// extend together with the zenoh features.
const SUPPORTED_PROTOCOLS: &[&str] = &["tcp", "tls"];

/// The coordinator's configuration: an embedded router listening on `listen`
/// (e.g. `tcp/0.0.0.0:7447`). Opening it fails at once if an endpoint cannot be bound.
///
/// `routers` (usually empty) are other routers this one links to, retrying until they answer:
/// a second coordinator joins the first one's network this way, so two missions share one
/// Zenoh network and the same agents.
///
/// `security` says who may connect; an endpoint beyond loopback that anyone could join is an
/// error ([`SessionError::Unauthenticated`]) unless `security.insecure`.
pub fn router_config(
    listen: &[String],
    routers: &[String],
    security: &Security,
) -> Result<Config, SessionError> {
    let mut config = base("router", security)?;
    security.apply(&mut config, true)?;
    let listen_json = endpoints("listen/endpoints", listen)?;
    set(&mut config, "listen/endpoints", &listen_json)?;
    for endpoint in listen {
        security::check_tls_ready(&config, endpoint, true)?;
        security::check_exposure(&config, endpoint, security.insecure)?;
    }
    if !routers.is_empty() {
        let connect = endpoints("connect/endpoints", routers)?;
        set(&mut config, "connect/endpoints", &connect)?;
        for endpoint in routers {
            security::check_tls_ready(&config, endpoint, false)?;
        }
    }
    Ok(config)
}

/// A vehicle agent's configuration: a client of the router at `connect`.
///
/// With `wait_for_router`, opening waits (retrying after 1 s, backing off to every 4 s) until a
/// router answers, so an agent may start before the coordinator. Without it, opening fails at
/// once when no router is up. Either way a client reconnects by itself if the router restarts.
pub fn client_config(
    connect: &[String],
    wait_for_router: bool,
    security: &Security,
) -> Result<Config, SessionError> {
    let mut config = base("client", security)?;
    security.apply(&mut config, false)?;
    let connect_json = endpoints("connect/endpoints", connect)?;
    set(&mut config, "connect/endpoints", &connect_json)?;
    for endpoint in connect {
        security::check_tls_ready(&config, endpoint, false)?;
    }
    // Whole connect phase, i64 ms: -1 = forever, 0 = one try (the client default). Clients take
    // zenoh's single-link path, which never reads `connect/exit_on_failure`.
    let timeout_ms = if wait_for_router { "-1" } else { "0" };
    set(&mut config, "connect/timeout_ms", timeout_ms)?;
    Ok(config)
}

/// Settings both sides share, over the configuration file's.
fn base(mode: &str, security: &Security) -> Result<Config, SessionError> {
    let mut config = security.base()?;
    set(&mut config, "mode", &format!("{mode:?}"))?;
    set(&mut config, "scouting/multicast/enabled", "false")?;
    // Largest message zenoh reassembles (default 1 GiB): the codec refuses anything over
    // MAX_MESSAGE_BYTES anyway, so don't let a peer make us buffer more than twice that.
    let max = (2 * MAX_MESSAGE_BYTES).to_string();
    set(&mut config, "transport/link/rx/max_message_size", &max)?;
    Ok(config)
}

/// Checks every endpoint and returns them as a JSON array (quoted by serde, never by hand).
fn endpoints(setting: &'static str, given: &[String]) -> Result<String, SessionError> {
    if given.is_empty() {
        return Err(SessionError::NoEndpoints { setting });
    }
    for endpoint in given {
        check_endpoint(endpoint).map_err(|reason| SessionError::BadEndpoint {
            setting,
            endpoint: endpoint.clone(),
            reason,
        })?;
    }
    Ok(serde_json::Value::from(given.to_vec()).to_string())
}

fn check_endpoint(s: &str) -> Result<(), String> {
    let endpoint = EndPoint::from_str(s).map_err(|e| e.to_string())?;
    let protocol = endpoint.protocol().as_str();
    if !SUPPORTED_PROTOCOLS.contains(&protocol) {
        return Err(format!(
            "transport {protocol:?} is not built in (supported: {SUPPORTED_PROTOCOLS:?})"
        ));
    }
    match endpoint.address().as_str().rsplit_once(':') {
        Some((host, port)) if !host.is_empty() && port.parse::<u16>().is_ok() => Ok(()),
        _ => Err("the address must be <host>:<port>, e.g. tcp/127.0.0.1:7447".to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::agent_to_coordinator::AgentToCoordinator;
    use crate::wire::{codec, topics, Envelope};
    use std::future::IntoFuture;
    use std::slice::from_ref;
    use std::time::Duration;
    use tokio::sync::oneshot;
    use zenoh::handlers::FifoChannelHandler;
    use zenoh::pubsub::Subscriber;
    use zenoh::qos::CongestionControl;
    use zenoh::sample::{Sample, SampleKind};
    use zenoh::{Session, Wait};

    type TestResult = Result<(), Box<dyn std::error::Error + Send + Sync>>;

    const LIMIT: Duration = Duration::from_secs(10);

    /// Plain TCP, as on loopback.
    fn plain() -> Security {
        Security::default()
    }

    /// `f` under the test time limit; the error names the step that hung. (Zenoh builders
    /// other than `close` resolve synchronously, so for them this is a label, not a bound.)
    async fn within<F: IntoFuture>(step: &str, f: F) -> Result<F::Output, String> {
        tokio::time::timeout(LIMIT, f)
            .await
            .map_err(|_| format!("{step}: no result within {LIMIT:?}"))
    }

    /// Opens on a detached thread, so that waiting for it can be bounded and a hung open cannot
    /// block the runtime's shutdown.
    fn open_in_thread(config: Config) -> oneshot::Receiver<zenoh::Result<Session>> {
        let (tx, rx) = oneshot::channel();
        std::thread::spawn(move || tx.send(zenoh::open(config).wait()));
        rx
    }

    async fn open(step: &str, config: Config) -> zenoh::Result<Session> {
        within(step, open_in_thread(config)).await??
    }

    /// A loopback endpoint on a port that was free a moment ago.
    fn free_endpoint() -> std::io::Result<String> {
        let listener = std::net::TcpListener::bind("127.0.0.1:0")?;
        Ok(format!("tcp/127.0.0.1:{}", listener.local_addr()?.port()))
    }

    async fn router_and_client() -> zenoh::Result<(Session, Session)> {
        let endpoint = free_endpoint()?;
        let router = open(
            "router open",
            router_config(from_ref(&endpoint), &[], &plain())?,
        )
        .await?;
        let client = open("client open", client_config(&[endpoint], false, &plain())?).await?;
        Ok((router, client))
    }

    #[test]
    fn settings_read_back() -> TestResult {
        let wait = client_config(&["tcp/coordinator:7447".into()], true, &plain())?;
        let once = client_config(&["tcp/10.0.0.1:7447".into()], false, &plain())?;
        // A quote in a user string stays inside its endpoint (a bad host, found at open).
        let router = router_config(
            &["tcp/[::]:7447".into(), r#"tcp/a",b:1"#.into()],
            &["tcp/first:7447".into()],
            &Security {
                insecure: true,
                ..Security::default()
            },
        )?;
        let expected = [
            (&wait, "mode", r#""client""#),
            (&wait, "connect/endpoints", r#"["tcp/coordinator:7447"]"#),
            (&wait, "connect/timeout_ms", "-1"),
            (&once, "connect/timeout_ms", "0"),
            (&router, "mode", r#""router""#),
            (
                &router,
                "listen/endpoints",
                r#"["tcp/[::]:7447","tcp/a\",b:1"]"#,
            ),
            (&router, "connect/endpoints", r#"["tcp/first:7447"]"#),
        ];
        for (config, key, value) in expected {
            assert_eq!(config.get_json(key)?, value, "{key}");
        }
        for config in [&wait, &once, &router] {
            assert_eq!(config.get_json("scouting/multicast/enabled")?, "false");
            assert_eq!(
                config.get_json("transport/link/rx/max_message_size")?,
                "8388608"
            );
        }
        Ok(())
    }

    #[test]
    fn bad_endpoints_are_errors_naming_them() {
        let bad = [
            "not an endpoint",
            "tcp/nonsense",
            "tcp/:7447",
            "tcp/127.0.0.1:99999",
        ];
        for s in bad
            .into_iter()
            .chain(["udp/127.0.0.1:7447", "tls/127.0.0.1:7447"])
        {
            let results = [
                client_config(&[s.into()], false, &plain()),
                client_config(&["tcp/127.0.0.1:7447".into(), s.into()], true, &plain()),
                router_config(&[s.into()], &[], &plain()),
            ];
            for result in results {
                match result {
                    Err(e @ SessionError::BadEndpoint { .. }) => {
                        assert!(e.to_string().contains(&format!("{s:?}")), "{e}")
                    }
                    other => panic!("{s:?} gave {other:?}"),
                }
            }
        }
        let e = client_config(&[], true, &plain())
            .err()
            .map(|e| e.to_string());
        assert!(e.is_some_and(|e| e.contains("connect/endpoints")));
        let e = router_config(&[], &[], &plain())
            .err()
            .map(|e| e.to_string());
        assert!(e.is_some_and(|e| e.contains("listen/endpoints")));
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn open_fails_on_a_busy_port_or_a_missing_router() -> TestResult {
        // Both errors are zenoh's, at open time; each names the endpoint.
        let busy = std::net::TcpListener::bind("127.0.0.1:0")?;
        let endpoint = format!("tcp/127.0.0.1:{}", busy.local_addr()?.port());
        let router = open(
            "router on a busy port",
            router_config(from_ref(&endpoint), &[], &plain())?,
        )
        .await;
        let e = router.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains(&endpoint), "router on a busy port: {e:?}");
        let endpoint = free_endpoint()?;
        let client = open(
            "client, no router",
            client_config(from_ref(&endpoint), false, &plain())?,
        )
        .await;
        let e = client.err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains(&endpoint), "client without a router: {e:?}");
        Ok(())
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn a_waiting_client_connects_once_the_router_starts() -> TestResult {
        let endpoint = free_endpoint()?;
        let mut client = open_in_thread(client_config(from_ref(&endpoint), true, &plain())?);
        tokio::time::sleep(Duration::from_millis(500)).await;
        assert!(client.try_recv().is_err(), "the client did not wait");
        let router = open("router open", router_config(&[endpoint], &[], &plain())?).await?;
        let client = within("client open", client).await???;
        within("client close", client.close()).await??;
        within("router close", router.close()).await??;
        Ok(())
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn an_agent_message_reaches_the_coordinator() -> TestResult {
        let (router, client) = router_and_client().await?;
        let inbox = router.declare_subscriber(topics::coordinator_inbox("m1")?);
        let inbox = within("subscribe", inbox).await??;
        let sent = Envelope::new(AgentToCoordinator::Done {
            mission: "m1".into(),
            vehicle: "auv1".into(),
            iterations: 200,
            elites_sent: 12,
            evaluations: 100_000,
            dropped: 0,
        });
        let bytes = codec::encode(&sent)?;
        let key = topics::to_coordinator("m1", "auv1")?;
        // The subscription may not have reached the client yet: resend until one arrives.
        let sample = within("first message", async {
            loop {
                let put = client.put(key.as_str(), bytes.clone());
                put.congestion_control(CongestionControl::Block).await?;
                let wait = tokio::time::timeout(Duration::from_millis(100), inbox.recv_async());
                if let Ok(Ok(sample)) = wait.await {
                    return Ok::<_, zenoh::Error>(sample);
                }
            }
        });
        let sample = sample.await??;
        let key = sample.key_expr().as_str();
        assert_eq!(topics::mission_and_vehicle(key), Some(("m1", "auv1")));
        let received = codec::decode::<AgentToCoordinator>(&sample.payload().to_bytes())?;
        assert_eq!(received, sent);
        within("client close", client.close()).await??;
        within("router close", router.close()).await??;
        Ok(())
    }

    /// Kind and vehicle of the next liveliness change.
    async fn next_change(
        alive: &Subscriber<FifoChannelHandler<Sample>>,
        step: &str,
    ) -> zenoh::Result<(SampleKind, String)> {
        let change = within(step, alive.recv_async()).await??;
        let key = change.key_expr().as_str();
        let vehicle = topics::vehicle_of_liveliness(key).ok_or(format!("not a token: {key}"))?;
        Ok((change.kind(), vehicle.to_string()))
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn liveliness_shows_agents_coming_and_going() -> TestResult {
        let (router, client) = router_and_client().await?;
        let alive = router.liveliness();
        let alive = alive
            .declare_subscriber(topics::ALL_LIVELINESS)
            .history(true);
        let alive = within("liveliness subscribe", alive).await??;
        let (put, delete) = (SampleKind::Put, SampleKind::Delete);
        let liveliness = client.liveliness();
        let token = liveliness.declare_token(topics::liveliness("auv1")?);
        let token = within("token", token).await??;
        assert_eq!(next_change(&alive, "token").await?, (put, "auv1".into()));
        drop(token);
        assert_eq!(next_change(&alive, "drop").await?, (delete, "auv1".into()));
        // An agent whose session ends (exit, crash) disappears the same way.
        let token = liveliness.declare_token(topics::liveliness("auv2")?);
        let _token = within("second token", token).await??;
        assert_eq!(next_change(&alive, "token 2").await?, (put, "auv2".into()));
        within("client close", client.close()).await??;
        assert_eq!(next_change(&alive, "close").await?, (delete, "auv2".into()));
        within("router close", router.close()).await??;
        Ok(())
    }

    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn with_a_user_dictionary_only_listed_users_with_their_password_connect() -> TestResult {
        use crate::wire::security::UserPassword;
        let dir = tempfile::tempdir()?;
        let users = dir.path().join("users.txt");
        std::fs::write(&users, "auv1:right-password\n")?;
        let endpoint = free_endpoint()?;
        let router = Security {
            users_file: Some(users),
            ..Security::default()
        };
        let router = router_config(from_ref(&endpoint), &[], &router)?;
        let router = open("router open", router).await?;
        let as_user = |user: &str, password: &str| Security {
            user: Some(UserPassword {
                user: user.into(),
                password: password.into(),
            }),
            ..Security::default()
        };
        let listed = as_user("auv1", "right-password");
        let client = client_config(from_ref(&endpoint), false, &listed)?;
        let client = open("listed user", client).await?;
        within("client close", client.close()).await??;
        for (user, password) in [("auv1", "wrong"), ("auv9", "right-password")] {
            let config = client_config(from_ref(&endpoint), false, &as_user(user, password))?;
            let refused = open("unlisted user", config).await;
            assert!(refused.is_err(), "{user}/{password} connected");
        }
        let anonymous = open(
            "anonymous",
            client_config(from_ref(&endpoint), false, &plain())?,
        );
        assert!(
            anonymous.await.is_err(),
            "a client without a password connected"
        );
        within("router close", router.close()).await??;
        Ok(())
    }
}
