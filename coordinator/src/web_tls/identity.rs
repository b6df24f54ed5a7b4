//! The server's side of mutual TLS: its certificate and key, the fleet CA its clients'
//! certificates must chain to, and the rule of who, among the members, may watch.

use std::path::Path;
use std::sync::Arc;

use anyhow::Context as _;
use rustls::crypto::ring::default_provider;
use rustls::server::WebPkiClientVerifier;
use rustls::{RootCertStore, ServerConfig};
use rustls_pki_types::pem::PemObject as _;
use rustls_pki_types::{CertificateDer, PrivateKeyDer};
use shoal_common::wire::security::TlsFiles;

use crate::acl::{COORDINATOR, OPERATOR_UNIT};

/// Largest PEM file read (a certificate chain is a few kB).
const MAX_PEM_BYTES: u64 = 1 << 20;

/// A TLS 1.3 server configuration presenting `files`' identity and requiring a client
/// certificate signed by `files`' CA (ring, the provider zenoh's TLS link uses).
pub fn server_config(files: &TlsFiles) -> anyhow::Result<Arc<ServerConfig>> {
    let Some((cert, key)) = &files.identity else {
        anyhow::bail!("TLS: a server needs its certificate and key, not only the CA");
    };
    let chain = certificates(cert)?;
    let key_pem = read(key)?;
    let key = PrivateKeyDer::from_pem_slice(key_pem.as_bytes())
        .map_err(|e| anyhow::anyhow!("{}: not a PEM private key: {e}", key.display()))?;
    let mut roots = RootCertStore::empty();
    for ca in certificates(&files.ca)? {
        roots
            .add(ca)
            .with_context(|| format!("{}: not a usable CA certificate", files.ca.display()))?;
    }
    let provider = Arc::new(default_provider());
    let verifier =
        WebPkiClientVerifier::builder_with_provider(Arc::new(roots), Arc::clone(&provider))
            .build()
            .context("TLS: cannot verify clients against the fleet CA")?;
    let config = ServerConfig::builder_with_provider(provider)
        .with_protocol_versions(&[&rustls::version::TLS13])
        .context("TLS 1.3 is not available")?
        .with_client_cert_verifier(verifier)
        .with_single_cert(chain, key)
        .with_context(|| format!("{}: the certificate does not fit its key", cert.display()))?;
    Ok(Arc::new(config))
}

fn read(path: &Path) -> anyhow::Result<String> {
    shoal_common::limits::read_at_most(path, MAX_PEM_BYTES)
        .with_context(|| format!("TLS: cannot read {}", path.display()))
}

/// The certificates of a PEM file; at least one.
fn certificates(path: &Path) -> anyhow::Result<Vec<CertificateDer<'static>>> {
    let pem = read(path)?;
    let certs = CertificateDer::pem_slice_iter(pem.as_bytes())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| anyhow::anyhow!("{}: not PEM certificates: {e}", path.display()))?;
    if certs.is_empty() {
        anyhow::bail!("{}: no certificate in it", path.display());
    }
    Ok(certs)
}

/// Whether the member whose (already verified) certificate is `cert` may watch the fleet: the
/// coordinator, or an operator (organizational unit [`OPERATOR_UNIT`]). `Err` names who was
/// refused, for the log.
pub fn may_watch(cert: &CertificateDer<'_>) -> Result<(), String> {
    let (_, parsed) = x509_parser::parse_x509_certificate(cert.as_ref())
        .map_err(|e| format!("an unreadable certificate ({e})"))?;
    let subject = parsed.subject();
    let name = subject
        .iter_common_name()
        .next()
        .and_then(|n| n.as_str().ok())
        .unwrap_or_default();
    let operator = subject
        .iter_organizational_unit()
        .any(|u| u.as_str().is_ok_and(|u| u == OPERATOR_UNIT));
    if name == COORDINATOR || operator {
        return Ok(());
    }
    Err(format!("{name:?}, neither the coordinator nor an operator"))
}
