//! The server on a real loopback socket: the page, the WebSocket's catch-up and updates, and
//! its bounds (client cap, oversized and too many messages, refused beyond loopback without
//! the fleet's keys or --insecure).

use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use serde_json::Value;
use tungstenite::{Message, WebSocket};

use super::*;
use crate::execute::live::LiveMessage;

type TestResult = Result<(), Box<dyn std::error::Error>>;

fn report(vehicle: &str, seq: u64) -> LiveMessage {
    crate::execute::live::test_report(vehicle, seq, seq as f64, [seq as f64, 2.0, 3.0])
}

fn server(feed: &Arc<LiveFeed>) -> anyhow::Result<ViewServer> {
    ViewServer::start(
        "127.0.0.1:0".parse()?,
        Transport::Plain,
        Source::Live(Arc::clone(feed)),
    )
}

type Socket = WebSocket<TcpStream>;

fn connect(s: &ViewServer) -> Result<Socket, Box<dyn std::error::Error>> {
    let stream = TcpStream::connect(s.addr())?;
    stream.set_read_timeout(Some(Duration::from_secs(5)))?;
    let url = format!("ws://{}/ws", s.addr());
    let (ws, _) = tungstenite::client(url.as_str(), stream).map_err(|e| e.to_string())?;
    Ok(ws)
}

/// The kinds of the messages of the next frame.
fn kinds(ws: &mut Socket) -> Result<Vec<Value>, Box<dyn std::error::Error>> {
    loop {
        if let Message::Text(t) = ws.read()? {
            let v: Vec<Value> = serde_json::from_str(t.as_str())?;
            return Ok(v);
        }
    }
}

fn kind_list(frame: &[Value]) -> Vec<String> {
    frame
        .iter()
        .map(|m| m["kind"].as_str().unwrap_or("?").to_string())
        .collect()
}

fn get(s: &ViewServer, request: &str) -> Result<String, Box<dyn std::error::Error>> {
    let mut stream = TcpStream::connect(s.addr())?;
    stream.set_read_timeout(Some(Duration::from_secs(5)))?;
    stream.write_all(request.as_bytes())?;
    let mut answer = String::new();
    stream.read_to_string(&mut answer)?;
    Ok(answer)
}

/// Waits until `f` holds (the server's threads count asynchronously).
fn eventually(f: impl Fn() -> bool) -> bool {
    let end = Instant::now() + Duration::from_secs(5);
    while Instant::now() < end {
        if f() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    f()
}

#[test]
fn the_page_is_served_and_bad_requests_are_answered_and_counted() -> TestResult {
    let feed = LiveFeed::new();
    let s = server(&feed)?;
    let page = get(&s, "GET / HTTP/1.1\r\nHost: x\r\n\r\n")?;
    assert!(page.starts_with("HTTP/1.1 200 OK"), "{page}");
    assert!(page.contains("<script src=\"view.js\""), "{page}");
    let js = get(&s, "GET /view.js HTTP/1.1\r\nHost: x\r\n\r\n")?;
    assert!(js.contains("text/javascript"), "{js}");
    let e = get(&s, "DELETE / HTTP/1.1\r\nHost: x\r\n\r\n")?;
    assert!(e.starts_with("HTTP/1.1 405"), "{e}");
    let e = get(&s, "GET /../../etc/passwd HTTP/1.1\r\nHost: x\r\n\r\n")?;
    assert!(e.starts_with("HTTP/1.1 404"), "{e}");
    let huge = format!(
        "GET / HTTP/1.1\r\nX: {}\r\n\r\n",
        "a".repeat(MAX_REQUEST_BYTES)
    );
    let e = get(&s, &huge)?;
    assert!(e.starts_with("HTTP/1.1 431"), "{e}");
    assert_eq!(s.stats().bad_requests.load(Ordering::Relaxed), 3);
    Ok(())
}

#[test]
fn a_page_gets_the_catch_up_then_each_message() -> TestResult {
    let feed = LiveFeed::new();
    feed.publish(report("auv1", 0));
    let s = server(&feed)?;
    let mut ws = connect(&s)?;
    let first = kinds(&mut ws)?;
    assert_eq!(
        kind_list(&first),
        ["hello", "reset", "telemetry", "caught_up"]
    );
    assert!(eventually(|| feed.subscribers() == 1));
    feed.publish(report("auv1", 1));
    feed.publish(report("auv2", 1));
    let mut got = Vec::new();
    while got.len() < 2 {
        got.extend(kinds(&mut ws)?);
    }
    assert_eq!(got[1]["telemetry"]["vehicle"], "auv2");
    assert_eq!(got[1]["telemetry"]["state"]["position"][0], 1.0);
    Ok(())
}

#[test]
fn past_the_client_cap_a_page_gets_503() -> TestResult {
    let feed = LiveFeed::new();
    let s = server(&feed)?;
    let mut pages: Vec<Socket> = (0..MAX_CLIENTS)
        .map(|_| connect(&s))
        .collect::<Result<_, _>>()?;
    assert!(eventually(
        || s.stats().clients.load(Ordering::SeqCst) == MAX_CLIENTS
    ));
    let refused = connect(&s).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(refused.contains("503"), "{refused}");
    assert_eq!(s.stats().refused_clients.load(Ordering::Relaxed), 1);
    // A place frees when a page leaves.
    let mut one = pages.pop().ok_or("no page")?;
    one.close(None)?;
    while one.read().is_ok() {}
    assert!(eventually(
        || s.stats().clients.load(Ordering::SeqCst) < MAX_CLIENTS
    ));
    let _again = connect(&s)?;
    Ok(())
}

#[test]
fn an_oversized_message_ends_the_connection_and_is_counted() -> TestResult {
    let feed = LiveFeed::new();
    let s = server(&feed)?;
    let mut ws = connect(&s)?;
    kinds(&mut ws)?;
    ws.send(Message::text("x".repeat(MAX_INCOMING_BYTES + 1)))?;
    let closed = (0..10).any(|_| ws.read().is_err());
    assert!(closed, "the server kept the connection");
    assert!(eventually(|| s
        .stats()
        .dropped_messages
        .load(Ordering::Relaxed)
        == 1));
    assert!(eventually(|| s.stats().clients.load(Ordering::SeqCst) == 0));
    Ok(())
}

#[test]
fn a_page_sending_too_fast_is_disconnected() -> TestResult {
    let feed = LiveFeed::new();
    let s = server(&feed)?;
    let mut ws = connect(&s)?;
    kinds(&mut ws)?;
    for _ in 0..=MAX_INCOMING_PER_S {
        if ws.send(Message::text("hi")).is_err() {
            break;
        }
    }
    let closed = (0..10).any(|_| ws.read().is_err());
    assert!(closed, "the server kept the connection");
    assert!(eventually(|| {
        s.stats().dropped_messages.load(Ordering::Relaxed) as u32 == MAX_INCOMING_PER_S + 1
    }));
    Ok(())
}

#[test]
fn a_page_of_another_site_cannot_open_the_socket() -> TestResult {
    let feed = LiveFeed::new();
    let s = server(&feed)?;
    let e = get(
        &s,
        "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\
         Origin: http://evil.example\r\n\r\n",
    )?;
    assert!(e.starts_with("HTTP/1.1 403"), "{e}");
    Ok(())
}

#[test]
fn beyond_loopback_without_keys_is_refused_with_what_to_do() -> TestResult {
    let plain = Security::default();
    for addr in ["0.0.0.0:8080", "192.168.1.10:8080", "[::]:8080"] {
        let e = start_live(addr.parse().ok(), &plain, &LiveFeed::new())
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.contains("--view") && e.contains("mutual TLS") && e.contains("ssh -L"),
            "{addr}: {e}"
        );
    }
    assert!(check_bind(&"[::1]:8080".parse()?, &plain).is_ok());
    let insecure = Security {
        insecure: true,
        ..Security::default()
    };
    let open = start_live("0.0.0.0:0".parse().ok(), &insecure, &LiveFeed::new())?;
    assert!(open.is_some_and(|s| s.url().starts_with("http://")));
    Ok(())
}

#[test]
fn a_refused_tls_client_is_counted_and_frees_its_place() -> TestResult {
    let dir = crate::web_tls::tests::fleet()?;
    let tls = crate::web_tls::tests::tls(dir.path())?;
    let s = ViewServer::start("127.0.0.1:0".parse()?, tls, Source::Live(LiveFeed::new()))?;
    assert!(s.url().starts_with("https://"), "{}", s.url());
    let mut plain = TcpStream::connect(s.addr())?;
    plain.write_all(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")?;
    let _silent = TcpStream::connect(s.addr())?;
    let until = Instant::now() + Duration::from_secs(10);
    let settled = |s: &ViewServer| {
        s.stats().refused_tls.load(Ordering::SeqCst) == 2
            && s.stats().connections.load(Ordering::SeqCst) == 0
    };
    while !settled(&s) && Instant::now() < until {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(s.stats().refused_tls.load(Ordering::SeqCst), 2);
    assert_eq!(s.stats().connections.load(Ordering::SeqCst), 0);
    let mut answer = Vec::new();
    let _ = plain.read_to_end(&mut answer);
    assert!(!answer.starts_with(b"HTTP"), "plain HTTP was answered");
    Ok(())
}
