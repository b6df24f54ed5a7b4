//! The server in process, with `tungstenite`'s client on loopback: the greeting, a late
//! subscription's latest message, the bounds (clients, refused messages), and TLS.

use std::net::TcpStream;
use std::sync::atomic::Ordering;

use tungstenite::client::IntoClientRequest;
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

use super::*;
use crate::execute::live::LiveMessage;
use crate::execute::log::{Record, Start};
use crate::foxglove::limits::MAX_REFUSED_PER_CLIENT;
use crate::foxglove::protocol;

type Client = WebSocket<MaybeTlsStream<TcpStream>>;
type TestResult = Result<(), Box<dyn std::error::Error>>;

const SCENARIO: &str = include_str!("../../../../scenarios/amp-pso-3.toml");

fn mission(feed: &LiveFeed) {
    feed.publish(LiveMessage::Record(Record::Start(Start {
        mission: "m".into(),
        scenario_toml: SCENARIO.into(),
        common_arrival_s: 2700.0,
        arrival_window_s: 30.0,
        horizon_s: 60.0,
        time_scale: 200.0,
        epoch_unix_ms: 1_700_000_000_000,
    })));
    feed.publish(crate::execute::live::test_report(
        "auv1",
        0,
        3.5,
        [10.0, 20.0, 30.0],
    ));
}

fn connect(addr: SocketAddr, subprotocol: bool) -> Result<Client, Box<dyn std::error::Error>> {
    let mut req = format!("ws://{addr}").into_client_request()?;
    if subprotocol {
        req.headers_mut()
            .insert("Sec-WebSocket-Protocol", protocol::SUBPROTOCOL.parse()?);
    }
    Ok(tungstenite::connect(req)?.0)
}

fn json(m: Message) -> serde_json::Value {
    match m {
        Message::Text(t) => serde_json::from_str(t.as_str()).unwrap_or_default(),
        _ => serde_json::Value::Null,
    }
}

/// The server, once its hub has taken in the sample mission.
fn started() -> Result<(FoxgloveServer, Arc<LiveFeed>), Box<dyn std::error::Error>> {
    let feed = LiveFeed::new();
    mission(&feed);
    let server = FoxgloveServer::start(
        "127.0.0.1:0".parse()?,
        crate::web_tls::Transport::Plain,
        Arc::clone(&feed),
    )?;
    Ok((server, feed))
}

/// Reads the greeting, subscribes to auv1's pose as subscription 42 and returns the first
/// message data frame.
fn first_pose<S: std::io::Read + std::io::Write>(
    c: &mut WebSocket<S>,
) -> Result<tungstenite::Bytes, Box<dyn std::error::Error>> {
    assert_eq!(json(c.read()?)["op"], "serverInfo");
    // The hub may take in the start record after this client registered: then the vehicles'
    // channels come in an advertise of their own.
    let mut pose = None;
    while pose.is_none() {
        let m = json(c.read()?);
        assert_eq!(m["op"], "advertise", "{m}");
        let channels = m["channels"].as_array().cloned().unwrap_or_default();
        pose = channels
            .iter()
            .find(|ch| ch["topic"] == "/shoal/pose/auv1")
            .and_then(|ch| ch["id"].as_u64());
    }
    let sub =
        serde_json::json!({"op": "subscribe", "subscriptions": [{"id": 42, "channelId": pose}]});
    c.send(Message::text(sub.to_string()))?;
    let Message::Binary(frame) = c.read()? else {
        return Err("no message data".into());
    };
    Ok(frame)
}

#[test]
fn a_client_is_greeted_and_gets_the_latest_pose_when_it_subscribes() -> TestResult {
    let (server, _feed) = started()?;
    let mut c = connect(server.local_addr(), true)?;
    let frame = first_pose(&mut c)?;
    assert_eq!(frame[0], 1);
    assert_eq!(frame[1..5], 42u32.to_le_bytes());
    let stamp = u64::from_le_bytes(frame[5..13].try_into()?);
    assert_eq!(stamp, 1_700_000_000_000 * 1_000_000 + 3_500_000_000);
    let message: serde_json::Value = serde_json::from_slice(&frame[13..])?;
    assert_eq!(message["pose"]["position"]["x"], 10.0);
    server.shutdown();
    Ok(())
}

#[test]
fn over_tls_an_operator_is_served_and_plain_ws_is_refused_and_counted() -> TestResult {
    use crate::web_tls::tests as keys;
    let dir = keys::fleet()?;
    let feed = LiveFeed::new();
    mission(&feed);
    let server = FoxgloveServer::start(
        "127.0.0.1:0".parse()?,
        keys::tls(dir.path())?,
        Arc::clone(&feed),
    )?;
    let addr = server.local_addr();
    assert!(connect(addr, true).is_err(), "plain ws was served");
    let config = Arc::new(keys::client(dir.path(), Some("operator"))?);
    let tls = rustls::ClientConnection::new(config, "localhost".try_into()?)?;
    let stream = rustls::StreamOwned::new(tls, TcpStream::connect(addr)?);
    let mut req = format!("wss://{addr}").into_client_request()?;
    req.headers_mut()
        .insert("Sec-WebSocket-Protocol", protocol::SUBPROTOCOL.parse()?);
    let (mut c, _) = tungstenite::client(req, stream)?;
    // The server's 20 ms read polls time out through TLS many times while the client waits.
    std::thread::sleep(std::time::Duration::from_millis(300));
    let frame = first_pose(&mut c)?;
    assert_eq!(frame[1..5], 42u32.to_le_bytes());
    assert_eq!(server.counters().tls_refused.load(Ordering::SeqCst), 1);
    server.shutdown();
    Ok(())
}

#[test]
fn silent_tls_handshakes_hold_client_places_until_their_deadline() -> TestResult {
    let dir = crate::web_tls::tests::fleet()?;
    let server = FoxgloveServer::start(
        "127.0.0.1:0".parse()?,
        crate::web_tls::tests::tls(dir.path())?,
        LiveFeed::new(),
    )?;
    let addr = server.local_addr();
    let silent: Vec<TcpStream> = (0..MAX_CLIENTS)
        .map(|_| TcpStream::connect(addr))
        .collect::<Result<_, _>>()?;
    let counters = server.counters();
    let until = std::time::Instant::now() + std::time::Duration::from_secs(3);
    while counters.clients_served.load(Ordering::SeqCst) < MAX_CLIENTS as u64
        && std::time::Instant::now() < until
    {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let _one_more = TcpStream::connect(addr)?;
    while counters.clients_refused.load(Ordering::SeqCst) == 0 && std::time::Instant::now() < until
    {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert_eq!(counters.clients_refused.load(Ordering::SeqCst), 1);
    // Past the handshake's deadline every silent client is dropped and counted.
    let until = std::time::Instant::now() + std::time::Duration::from_secs(10);
    while counters.tls_refused.load(Ordering::SeqCst) < MAX_CLIENTS as u64
        && std::time::Instant::now() < until
    {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    assert_eq!(
        counters.tls_refused.load(Ordering::SeqCst),
        MAX_CLIENTS as u64
    );
    drop(silent);
    server.shutdown();
    Ok(())
}

#[test]
fn clients_over_the_cap_and_without_the_subprotocol_are_turned_away() -> TestResult {
    let (server, _feed) = started()?;
    let addr = server.local_addr();
    assert!(connect(addr, false).is_err(), "no subprotocol");
    let mut clients = Vec::new();
    for _ in 0..MAX_CLIENTS {
        let mut c = connect(addr, true)?;
        assert_eq!(json(c.read()?)["op"], "serverInfo");
        clients.push(c);
    }
    assert!(connect(addr, true).is_err(), "one over the cap");
    let counters = server.counters();
    assert_eq!(counters.clients_refused.load(Ordering::Relaxed), 1);
    assert_eq!(counters.handshakes_failed.load(Ordering::Relaxed), 1);
    // One leaves: another gets its place.
    drop(clients.pop());
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    loop {
        match connect(addr, true) {
            Ok(_) => break,
            Err(e) if std::time::Instant::now() > deadline => return Err(e),
            Err(_) => std::thread::sleep(std::time::Duration::from_millis(50)),
        }
    }
    server.shutdown();
    Ok(())
}

#[test]
fn a_client_that_keeps_sending_nonsense_is_dropped_and_counted() -> TestResult {
    let (server, _feed) = started()?;
    let mut c = connect(server.local_addr(), true)?;
    for _ in 0..=MAX_REFUSED_PER_CLIENT {
        c.send(Message::text("nonsense"))?;
    }
    let mut warnings = 0;
    let closed = loop {
        match c.read() {
            Ok(Message::Text(t)) => {
                let m: serde_json::Value = serde_json::from_str(t.as_str())?;
                warnings += usize::from(m["op"] == "status" && m["level"] == 1);
            }
            Ok(Message::Close(frame)) => break frame.map(|f| u16::from(f.code)),
            Ok(_) => {}
            Err(e) => return Err(e.into()),
        }
    };
    assert_eq!(warnings, MAX_REFUSED_PER_CLIENT as usize);
    assert_eq!(closed, Some(1008), "policy violation");
    let counters = server.counters();
    assert_eq!(
        counters.messages_refused.load(Ordering::Relaxed),
        u64::from(MAX_REFUSED_PER_CLIENT) + 1
    );
    assert_eq!(counters.clients_dropped.load(Ordering::Relaxed), 1);
    server.shutdown();
    Ok(())
}
