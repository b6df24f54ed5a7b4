//! The rules (which settings give which mode, the refusal's text) and the handshake on a real
//! loopback socket with keys made by `shoal-coordinator keys`: an operator is let in, a vehicle,
//! a client without a certificate and a silent client are dropped, and a read timeout set on
//! the socket still works through TLS.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use rustls::pki_types::ServerName;
use rustls::{ClientConfig, ClientConnection, RootCertStore, StreamOwned};
use rustls_pki_types::pem::PemObject as _;
use rustls_pki_types::{CertificateDer, PrivateKeyDer};
use shoal_common::wire::security::{Security, TlsFiles};

use super::*;
use crate::commands::keys::{command as make_keys, KeysArgs};

type TestResult = Result<(), Box<dyn std::error::Error>>;

#[test]
fn each_setting_gives_its_mode() -> TestResult {
    let local: SocketAddr = "127.0.0.1:8080".parse()?;
    let open: SocketAddr = "0.0.0.0:8080".parse()?;
    for (tls, insecure) in [(false, false), (true, false), (false, true), (true, true)] {
        assert_eq!(mode(local, tls, insecure), Some(Mode::Loopback));
    }
    assert_eq!(mode(open, true, false), Some(Mode::MutualTls));
    assert_eq!(mode(open, true, true), Some(Mode::MutualTls));
    assert_eq!(mode(open, false, true), Some(Mode::Insecure));
    assert_eq!(mode(open, false, false), None);
    assert_eq!(mode("[::1]:1".parse()?, false, false), Some(Mode::Loopback));
    assert_eq!(mode("10.1.2.3:1".parse()?, false, false), None);
    Ok(())
}

#[test]
fn beyond_loopback_without_keys_or_insecure_is_refused_with_the_ways_out() -> TestResult {
    let open: SocketAddr = "0.0.0.0:8080".parse()?;
    let e = choose("--view", "web view", open, &Security::default())
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    for part in [
        "--view 0.0.0.0:8080",
        "mutual TLS",
        "--zenoh-config keys/coordinator.json5",
        "shoal-coordinator keys",
        "ssh -L 8080:127.0.0.1:8080",
        "--insecure",
    ] {
        assert!(e.contains(part), "{part:?} missing from: {e}");
    }
    let insecure = Security {
        insecure: true,
        ..Security::default()
    };
    assert!(matches!(
        choose("--view", "web view", open, &insecure)?,
        Transport::Plain
    ));
    let local = choose(
        "--view",
        "web view",
        "127.0.0.1:1".parse()?,
        &Security::default(),
    )?;
    assert_eq!(local.scheme(true), "http");
    Ok(())
}

/// A fleet's keys in a temporary directory: vehicle `auv1`, operator `operator`.
pub(crate) fn fleet() -> anyhow::Result<tempfile::TempDir> {
    let dir = tempfile::tempdir()?;
    make_keys(&KeysArgs {
        out: dir.path().join("keys"),
        vehicles: vec!["auv1".into()],
        scenario: None,
        operators: vec!["operator".into()],
        coordinator_hosts: vec!["localhost".into(), "127.0.0.1".into()],
        path_in_config: None,
        days: 2,
    })?;
    Ok(dir)
}

fn keys(dir: &Path) -> PathBuf {
    dir.join("keys")
}

#[test]
fn the_coordinators_keys_file_gives_a_tls_server() -> TestResult {
    let dir = fleet()?;
    let security = Security {
        config_file: Some(keys(dir.path()).join("coordinator.json5")),
        ..Security::default()
    };
    let t = choose(
        "--foxglove",
        "Foxglove server",
        "0.0.0.0:0".parse()?,
        &security,
    )?;
    assert_eq!(t.scheme(false), "wss");
    // A vehicle's file has no listening identity, but its connecting one serves as well.
    let bad = Security {
        tls: Some(TlsFiles {
            ca: keys(dir.path()).join("ca.pem"),
            identity: Some((
                keys(dir.path()).join("auv1.pem"),
                keys(dir.path()).join("coordinator.key"),
            )),
        }),
        ..Security::default()
    };
    let e = choose("--view", "web view", "0.0.0.0:0".parse()?, &bad).err();
    assert!(e.is_some_and(|e| e.to_string().contains("does not fit its key")));
    Ok(())
}

/// A TLS transport with the coordinator's keys of a [`fleet`] (kept while it is used).
pub(crate) fn tls(dir: &Path) -> anyhow::Result<Transport> {
    let k = keys(dir);
    Ok(Transport::Tls(server_config(&TlsFiles {
        ca: k.join("ca.pem"),
        identity: Some((k.join("coordinator.pem"), k.join("coordinator.key"))),
    })?))
}

/// A server accepting one connection with `accept` and the coordinator's keys; what `accept`
/// returned, and (when let in) the bytes it then reads within 200 ms, then after a second read.
fn serve_one(dir: &Path) -> anyhow::Result<(SocketAddr, std::thread::JoinHandle<Outcome>)> {
    let t = tls(dir)?;
    let listener = TcpListener::bind("127.0.0.1:0")?;
    let addr = listener.local_addr()?;
    let handle = std::thread::spawn(move || {
        let Ok((tcp, _)) = listener.accept() else {
            return Outcome::Refused(Refused::Handshake("accept".into()));
        };
        match accept(tcp, &t, Duration::from_millis(500)) {
            Err(r) => Outcome::Refused(r),
            Ok(conn) => Outcome::In(read_twice(conn)),
        }
    });
    Ok((addr, handle))
}

#[derive(Debug)]
enum Outcome {
    Refused(Refused),
    /// Whether the first read timed out; the bytes of the second.
    In((bool, Vec<u8>)),
}

/// A first read that must time out (the client waits), then one that gets the client's bytes.
fn read_twice(mut conn: Conn) -> (bool, Vec<u8>) {
    let _ = conn.set_read_timeout(Some(Duration::from_millis(200)));
    let mut buf = [0u8; 64];
    let timed_out = matches!(
        conn.read(&mut buf),
        Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut)
    );
    let _ = conn.set_read_timeout(Some(Duration::from_secs(5)));
    let n = conn.read(&mut buf).unwrap_or(0);
    let _ = conn.write_all(b"bye");
    let _ = conn.flush();
    (timed_out, buf[..n].to_vec())
}

/// A rustls client presenting `member`'s certificate (none: `None`).
pub(crate) fn client(dir: &Path, member: Option<&str>) -> anyhow::Result<ClientConfig> {
    let k = keys(dir);
    let mut roots = RootCertStore::empty();
    for c in CertificateDer::pem_file_iter(k.join("ca.pem"))? {
        roots.add(c?)?;
    }
    let provider = std::sync::Arc::new(rustls::crypto::ring::default_provider());
    let builder = ClientConfig::builder_with_provider(provider)
        .with_safe_default_protocol_versions()?
        .with_root_certificates(roots);
    Ok(match member {
        None => builder.with_no_client_auth(),
        Some(m) => {
            let chain = CertificateDer::pem_file_iter(k.join(format!("{m}.pem")))?
                .collect::<Result<Vec<_>, _>>()?;
            let key = PrivateKeyDer::from_pem_file(k.join(format!("{m}.key")))?;
            builder.with_client_auth_cert(chain, key)?
        }
    })
}

/// Connects as `member`, waits 400 ms, sends `hello`, and reads the answer (empty on failure).
fn talk(dir: &Path, addr: SocketAddr, member: Option<&str>) -> anyhow::Result<Vec<u8>> {
    let config = std::sync::Arc::new(client(dir, member)?);
    let conn = ClientConnection::new(config, ServerName::try_from("localhost")?)?;
    let tcp = TcpStream::connect(addr)?;
    tcp.set_read_timeout(Some(Duration::from_secs(5)))?;
    let mut s = StreamOwned::new(conn, tcp);
    let _ = s.conn.complete_io(&mut s.sock);
    std::thread::sleep(Duration::from_millis(400));
    let _ = s.write_all(b"hello");
    let _ = s.flush();
    let mut answer = Vec::new();
    let _ = s.read_to_end(&mut answer);
    Ok(answer)
}

#[test]
fn an_operator_is_let_in_and_read_timeouts_work_through_tls() -> TestResult {
    let dir = fleet()?;
    let (addr, server) = serve_one(dir.path())?;
    let answer = talk(dir.path(), addr, Some("operator"))?;
    let outcome = server.join().map_err(|_| "server thread panicked")?;
    assert!(
        matches!(&outcome, Outcome::In((true, got)) if got == b"hello"),
        "{outcome:?}"
    );
    assert_eq!(answer, b"bye");
    Ok(())
}

#[test]
fn a_vehicle_and_a_client_without_a_certificate_are_refused() -> TestResult {
    let dir = fleet()?;
    for (member, want) in [(Some("auv1"), "NotAllowed"), (None, "Handshake")] {
        let (addr, server) = serve_one(dir.path())?;
        let answer = talk(dir.path(), addr, member)?;
        let outcome = server.join().map_err(|_| "server thread panicked")?;
        assert!(
            format!("{outcome:?}").contains(want),
            "{member:?}: {outcome:?}"
        );
        assert!(answer.is_empty(), "{member:?} got {answer:?}");
    }
    Ok(())
}

#[test]
fn a_silent_or_plain_client_is_dropped_within_the_deadline() -> TestResult {
    let dir = fleet()?;
    let (addr, server) = serve_one(dir.path())?;
    let started = Instant::now();
    let _silent = TcpStream::connect(addr)?;
    let outcome = server.join().map_err(|_| "server thread panicked")?;
    assert!(
        matches!(outcome, Outcome::Refused(Refused::TimedOut)),
        "{outcome:?}"
    );
    assert!(started.elapsed() < Duration::from_secs(3));
    let (addr, server) = serve_one(dir.path())?;
    let mut plain = TcpStream::connect(addr)?;
    plain.write_all(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")?;
    let outcome = server.join().map_err(|_| "server thread panicked")?;
    assert!(
        matches!(outcome, Outcome::Refused(Refused::Handshake(_))),
        "{outcome:?}"
    );
    Ok(())
}
