//! `shoal-coordinator keys`: everything a secured fleet needs, so securing one is two commands
//! rather than a PKI project. It writes a local certificate authority, one X.509 v3 certificate
//! per member (the coordinator, each vehicle, each operator client) whose common name is the
//! member's identity, and one Zenoh JSON5 configuration per member: mutual TLS for everyone,
//! plus, in the coordinator's, the access-control rules its router enforces
//! ([`crate::acl`]). Keys are ECDSA P-256 (rcgen over ring, the backend zenoh's TLS already
//! uses). Existing files are never overwritten: a CA key is not something to lose by a re-run.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use rcgen::{
    BasicConstraints, CertificateParams, DnType, ExtendedKeyUsagePurpose, IsCa, Issuer, KeyPair,
    KeyUsagePurpose,
};
use serde_json::json;
use shoal_common::wire::topics;

use crate::acl::{self, Members, COORDINATOR, OPERATOR_UNIT};

/// `shoal-coordinator keys`.
#[derive(Debug, Clone, clap::Args)]
pub struct KeysArgs {
    /// Directory for the CA, the certificates, the keys and the Zenoh configurations (created;
    /// must not hold any of them already).
    #[arg(long, default_value = "keys")]
    pub out: PathBuf,
    /// The vehicles' ids (comma-separated); with --scenario, added to its vehicles.
    #[arg(long, value_delimiter = ',')]
    pub vehicles: Vec<String>,
    /// A scenario whose vehicles get certificates.
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Operator clients (comma-separated): they may publish obstacles, submit missions and
    /// read every open key.
    #[arg(long, value_delimiter = ',', default_value = "operator")]
    pub operators: Vec<String>,
    /// Names and addresses agents and operators reach the coordinator at (comma-separated):
    /// its certificate is valid for them, and TLS checks the name connected to.
    #[arg(long, value_delimiter = ',', default_value = "localhost,127.0.0.1")]
    pub coordinator_hosts: Vec<String>,
    /// Where the files will be on the machines that use them, as written into the
    /// configurations (default: --out, absolute). The compose fleet mounts them at /keys.
    #[arg(long)]
    pub path_in_config: Option<PathBuf>,
    /// Days the certificates stay valid.
    #[arg(long, default_value_t = 365)]
    pub days: u32,
}

/// Longest validity accepted, days (ten years).
const MAX_DAYS: u32 = 3650;

/// Writes the fleet's keys; the process exit code.
pub fn command(args: &KeysArgs) -> anyhow::Result<i32> {
    let members = members(args)?;
    if !(1..=MAX_DAYS).contains(&args.days) {
        anyhow::bail!("--days = {}: must be 1 to {MAX_DAYS}", args.days);
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let out = args
        .out
        .canonicalize()
        .with_context(|| format!("cannot resolve {}", args.out.display()))?;
    let names = file_names(&members);
    if let Some(existing) = names.iter().find(|n| out.join(n).exists()) {
        anyhow::bail!(
            "{} already exists: keys never overwrites a fleet's files (choose another --out)",
            out.join(existing).display()
        );
    }
    let in_config = args.path_in_config.clone().unwrap_or_else(|| out.clone());
    let ca_key = KeyPair::generate()?;
    let ca_params = ca_params(args.days)?;
    let ca_cert = ca_params.self_signed(&ca_key)?;
    write(&out, "ca.pem", &ca_cert.pem(), false)?;
    write(&out, "ca.key", &ca_key.serialize_pem(), true)?;
    let issuer = Issuer::new(ca_params, ca_key);
    let mut identities = vec![(
        COORDINATOR.to_string(),
        args.coordinator_hosts.clone(),
        None,
    )];
    identities.extend(
        members
            .vehicles
            .iter()
            .map(|v| (v.clone(), Vec::new(), None)),
    );
    identities
        .extend((members.operators.iter()).map(|o| (o.clone(), Vec::new(), Some(OPERATOR_UNIT))));
    for (name, hosts, unit) in &identities {
        let key = KeyPair::generate()?;
        let cert = member_params(name, hosts, *unit, args.days)?.signed_by(&key, &issuer)?;
        write(&out, &format!("{name}.pem"), &cert.pem(), false)?;
        write(&out, &format!("{name}.key"), &key.serialize_pem(), true)?;
        let config = member_config(&in_config, name, &members);
        let text = serde_json::to_string_pretty(&config)?;
        write(&out, &format!("{name}.json5"), &text, true)?;
    }
    println!(
        "wrote a CA and {} member identities to {}:\n  coordinator: --zenoh-config {}\n  \
         agents:      --zenoh-config {}\n  operators:   --zenoh-config {}\n\
         Listen on tls/HOST:PORT (HOST among {}); keep ca.key offline.",
        identities.len(),
        out.display(),
        in_config.join("coordinator.json5").display(),
        in_config.join("<vehicle>.json5").display(),
        in_config.join("<operator>.json5").display(),
        args.coordinator_hosts.join(", ")
    );
    Ok(crate::commands::exit::EXIT_FEASIBLE)
}

/// The members to certify, checked: ids usable as key chunks, none twice, none `coordinator`.
fn members(args: &KeysArgs) -> anyhow::Result<Members> {
    let mut vehicles = Vec::new();
    if let Some(path) = &args.scenario {
        let scenario = shoal_common::scenario::Scenario::load(path)?;
        vehicles.extend(scenario.vehicles.iter().map(|v| v.id.clone()));
    }
    vehicles.extend(args.vehicles.iter().cloned());
    if vehicles.is_empty() {
        anyhow::bail!("no vehicles: give --vehicles auv1,auv2,... or --scenario FILE");
    }
    let members = Members {
        vehicles,
        operators: args.operators.clone(),
    };
    let mut seen = std::collections::HashSet::new();
    for id in members.vehicles.iter().chain(&members.operators) {
        topics::check_id("member", id)?;
        if id == COORDINATOR || !seen.insert(id.as_str()) {
            anyhow::bail!("member id {id:?} is given twice or is reserved (\"{COORDINATOR}\")");
        }
    }
    if members.vehicles.len() > shoal_common::limits::MAX_VEHICLES {
        anyhow::bail!(
            "{} vehicles: over the limit {}",
            members.vehicles.len(),
            shoal_common::limits::MAX_VEHICLES
        );
    }
    Ok(members)
}

fn file_names(members: &Members) -> Vec<String> {
    let mut names = vec!["ca.pem".to_string(), "ca.key".to_string()];
    let all = std::iter::once(COORDINATOR)
        .chain(members.vehicles.iter().map(String::as_str))
        .chain(members.operators.iter().map(String::as_str));
    for m in all {
        names.extend(["pem", "key", "json5"].map(|ext| format!("{m}.{ext}")));
    }
    names
}

/// Valid from an hour ago (clock skew between machines) for `days` days.
fn set_validity(p: &mut CertificateParams, days: u32) {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let epoch = rcgen::date_time_ymd(1970, 1, 1);
    p.not_before = epoch + std::time::Duration::from_secs(now.saturating_sub(3600));
    p.not_after = epoch + std::time::Duration::from_secs(now + u64::from(days) * 86_400);
}

fn ca_params(days: u32) -> anyhow::Result<CertificateParams> {
    let mut p = CertificateParams::new(Vec::<String>::new())?;
    p.distinguished_name
        .push(DnType::CommonName, "Shoal fleet CA");
    p.is_ca = IsCa::Ca(BasicConstraints::Constrained(0));
    p.key_usages = vec![KeyUsagePurpose::KeyCertSign, KeyUsagePurpose::CrlSign];
    set_validity(&mut p, days);
    Ok(p)
}

/// A member's certificate: its id as common name (what access control matches), usable for
/// both ends of a TLS link (a coordinator's router also links to other routers). An operator's
/// also names [`OPERATOR_UNIT`], by which the web view and the Foxglove server let it watch.
fn member_params(
    name: &str,
    hosts: &[String],
    unit: Option<&str>,
    days: u32,
) -> anyhow::Result<CertificateParams> {
    let mut p = CertificateParams::new(hosts.to_vec())
        .with_context(|| format!("a coordinator host is not a DNS name or address: {hosts:?}"))?;
    p.distinguished_name.push(DnType::CommonName, name);
    if let Some(unit) = unit {
        p.distinguished_name
            .push(DnType::OrganizationalUnitName, unit);
    }
    p.is_ca = IsCa::ExplicitNoCa;
    p.key_usages = vec![KeyUsagePurpose::DigitalSignature];
    p.extended_key_usages = vec![
        ExtendedKeyUsagePurpose::ServerAuth,
        ExtendedKeyUsagePurpose::ClientAuth,
    ];
    p.use_authority_key_identifier_extension = true;
    set_validity(&mut p, days);
    Ok(p)
}

/// A member's Zenoh configuration: mutual TLS with its own certificate; the coordinator's
/// also listens with it and carries the access-control rules.
pub fn member_config(dir: &Path, name: &str, members: &Members) -> serde_json::Value {
    let file = |f: String| dir.join(f).to_string_lossy().to_string();
    let mut tls = json!({
        "root_ca_certificate": file("ca.pem".into()),
        "connect_certificate": file(format!("{name}.pem")),
        "connect_private_key": file(format!("{name}.key")),
        "enable_mtls": true,
    });
    if name == COORDINATOR {
        tls["listen_certificate"] = json!(file(format!("{name}.pem")));
        tls["listen_private_key"] = json!(file(format!("{name}.key")));
        return json!({
            "transport": { "link": { "tls": tls } },
            "access_control": acl::rules(members),
        });
    }
    json!({ "transport": { "link": { "tls": tls } } })
}

fn write(dir: &Path, name: &str, text: &str, private: bool) -> anyhow::Result<()> {
    use std::io::Write as _;
    let path = dir.join(name);
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    if private {
        use std::os::unix::fs::OpenOptionsExt as _;
        options.mode(0o600);
    }
    #[cfg(not(unix))]
    let _ = private;
    let mut f = options
        .open(&path)
        .with_context(|| format!("cannot create {}", path.display()))?;
    f.write_all(text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(out: &Path) -> KeysArgs {
        KeysArgs {
            out: out.to_path_buf(),
            vehicles: vec!["auv1".into(), "auv2".into()],
            scenario: None,
            operators: vec!["operator".into()],
            coordinator_hosts: vec!["localhost".into(), "127.0.0.1".into()],
            path_in_config: Some(PathBuf::from("/keys")),
            days: 30,
        }
    }

    #[test]
    fn every_member_gets_a_certificate_a_private_key_and_a_configuration_zenoh_reads(
    ) -> anyhow::Result<()> {
        let dir = tempfile::tempdir()?;
        assert_eq!(
            command(&args(dir.path()))?,
            crate::commands::exit::EXIT_FEASIBLE
        );
        for m in ["coordinator", "auv1", "auv2", "operator"] {
            let pem = std::fs::read_to_string(dir.path().join(format!("{m}.pem")))?;
            assert!(pem.starts_with("-----BEGIN CERTIFICATE-----"), "{m}");
            let text = std::fs::read_to_string(dir.path().join(format!("{m}.json5")))?;
            let config = zenoh::Config::from_json5(&text).map_err(|e| anyhow::anyhow!("{e}"))?;
            let cert = config
                .get_json("transport/link/tls/connect_certificate")
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            assert_eq!(cert, format!("\"/keys/{m}.pem\""));
            #[cfg(unix)]
            {
                use std::os::unix::fs::PermissionsExt as _;
                let key = std::fs::metadata(dir.path().join(format!("{m}.key")))?;
                assert_eq!(key.permissions().mode() & 0o777, 0o600, "{m}.key");
            }
        }
        let coordinator = std::fs::read_to_string(dir.path().join("coordinator.json5"))?;
        assert!(coordinator.contains("\"default_permission\": \"deny\""));
        let vehicle = std::fs::read_to_string(dir.path().join("auv1.json5"))?;
        assert!(!vehicle.contains("access_control"));
        Ok(())
    }

    #[test]
    fn a_second_run_never_overwrites_a_fleets_keys() -> anyhow::Result<()> {
        let dir = tempfile::tempdir()?;
        command(&args(dir.path()))?;
        let ca = std::fs::read(dir.path().join("ca.key"))?;
        let e = command(&args(dir.path())).err().map(|e| e.to_string());
        assert!(e.is_some_and(|e| e.contains("already exists")));
        assert_eq!(std::fs::read(dir.path().join("ca.key"))?, ca);
        Ok(())
    }

    #[test]
    fn a_reserved_repeated_or_bad_member_id_is_refused() {
        let dir = std::path::Path::new("/nonexistent-shoal-keys");
        for (vehicles, operators) in [
            (vec!["coordinator"], vec![]),
            (vec!["auv1", "auv1"], vec![]),
            (vec!["auv1"], vec!["auv1"]),
            (vec!["a/b"], vec![]),
            (vec![], vec!["operator"]),
        ] {
            let mut a = args(dir);
            a.vehicles = vehicles.iter().map(|s| s.to_string()).collect();
            a.operators = operators.iter().map(|s| s.to_string()).collect();
            assert!(command(&a).is_err(), "{vehicles:?} {operators:?}");
        }
    }
}
