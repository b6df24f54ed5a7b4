//! Who may join a fleet's Zenoh network, and how its links are protected. Everything here is
//! Zenoh's own machinery, configured the way its manual describes it (TLS and mutual TLS,
//! user/password authentication, access control by certificate common name or username); this
//! module only gathers the settings from Shoal's flags or a Zenoh JSON5 file and refuses the one
//! set-up that is unsafe by accident: a router listening beyond loopback that lets anyone in.
//!
//! A fleet made by `shoal-coordinator keys` uses mutual TLS: every member holds a certificate
//! from the fleet's own CA whose common name is its identity (`coordinator`, a vehicle id, or an
//! operator name), and the coordinator's router enforces the access-control rules of the
//! generated configuration (see `docs/guide/security.md`).

use std::path::{Path, PathBuf};

use zenoh::Config;

use super::session_error::{set, SessionError};

/// Largest Zenoh configuration file read (a generated one with a 100-vehicle ACL is ~60 kB).
pub const MAX_CONFIG_FILE_BYTES: u64 = 1 << 20;

/// How a fleet member authenticates and protects its links; `Default` is plain TCP.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Security {
    /// A Zenoh JSON5 configuration to start from, as `zenohd -c` takes it: TLS files,
    /// `transport/auth/usrpwd`, `access_control`. Shoal sets the mode, endpoints, scouting and
    /// message size on top of it; everything else in it is kept.
    pub config_file: Option<PathBuf>,
    /// TLS files given as flags (they override the file's).
    pub tls: Option<TlsFiles>,
    /// This member's user name and password (user/password authentication, as a client or as a
    /// router linking to another router).
    pub user: Option<UserPassword>,
    /// A router's `user:password` dictionary: with it, only listed users may connect.
    pub users_file: Option<PathBuf>,
    /// Allow a router to listen beyond loopback without authenticating who connects (a lab
    /// network nobody else reaches).
    pub insecure: bool,
}

/// The PEM files of one member's TLS identity.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TlsFiles {
    /// The fleet CA's certificate: peers must present a certificate it signed.
    pub ca: PathBuf,
    /// This member's certificate and key. A router with them and `ca` requires client
    /// certificates (mutual TLS); a client presents them.
    pub identity: Option<(PathBuf, PathBuf)>,
}

/// A user name and its password.
#[derive(Clone, PartialEq, Eq)]
pub struct UserPassword {
    /// The user name (an access-control subject).
    pub user: String,
    /// The password.
    pub password: String,
}

impl std::fmt::Debug for UserPassword {
    /// Never prints the password (configurations end up in logs).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("UserPassword")
            .field("user", &self.user)
            .field("password", &"<hidden>")
            .finish()
    }
}

impl Security {
    /// The starting configuration: the configuration file's, or Zenoh's defaults.
    pub(super) fn base(&self) -> Result<Config, SessionError> {
        let Some(path) = &self.config_file else {
            return Ok(Config::default());
        };
        let text = crate::limits::read_at_most(path, MAX_CONFIG_FILE_BYTES)
            .map_err(|e| config_file_error(path, &e.to_string()))?;
        Config::from_json5(&text).map_err(|e| config_file_error(path, &e.to_string()))
    }

    /// Applies the TLS and user flags; `router` also sets the listening side.
    pub(super) fn apply(&self, config: &mut Config, router: bool) -> Result<(), SessionError> {
        if let Some(tls) = &self.tls {
            set_path(config, "transport/link/tls/root_ca_certificate", &tls.ca)?;
            if let Some((cert, key)) = &tls.identity {
                // A router presents the same identity when it links to another router.
                set_path(config, "transport/link/tls/connect_certificate", cert)?;
                set_path(config, "transport/link/tls/connect_private_key", key)?;
                if router {
                    set_path(config, "transport/link/tls/listen_certificate", cert)?;
                    set_path(config, "transport/link/tls/listen_private_key", key)?;
                }
                set(config, "transport/link/tls/enable_mtls", "true")?;
            }
        }
        if let Some(u) = &self.user {
            set(config, "transport/auth/usrpwd/user", &json(&u.user))?;
            set(config, "transport/auth/usrpwd/password", &json(&u.password))?;
        }
        if let Some(users) = &self.users_file.as_ref().filter(|_| router) {
            set_path(config, "transport/auth/usrpwd/dictionary_file", users)?;
        }
        Ok(())
    }
}

impl Security {
    /// The TLS files a server of this process presents beyond loopback (the web view, the
    /// Foxglove server), found where the router finds its own: the configuration file's
    /// `transport/link/tls/...` keys with the flags applied over them. The identity is the
    /// listening one, else the connecting one; `None` without a CA or an identity.
    pub fn server_tls(&self) -> Result<Option<TlsFiles>, SessionError> {
        let mut config = self.base()?;
        self.apply(&mut config, true)?;
        let get = |key: &str| {
            config
                .get_json(key)
                .ok()
                .and_then(|v| serde_json::from_str::<Option<String>>(&v).ok().flatten())
                .map(PathBuf::from)
        };
        let tls = "transport/link/tls";
        let pair = |side: &str| {
            get(&format!("{tls}/{side}_certificate")).zip(get(&format!("{tls}/{side}_private_key")))
        };
        let identity = pair("listen").or_else(|| pair("connect"));
        Ok(get(&format!("{tls}/root_ca_certificate"))
            .zip(identity)
            .map(|(ca, identity)| TlsFiles {
                ca,
                identity: Some(identity),
            }))
    }
}

/// What a second router of this process needs to link to the router built from `config`: the
/// same TLS identity and user, nothing of its listening side or access control. `serve` runs
/// each mission on a router of its own that listens on loopback for the mission's local agents
/// and links to the serving router as `coordinator`.
pub fn link_identity(config: &Config) -> Security {
    let get = |key: &str| {
        config
            .get_json(key)
            .ok()
            .and_then(|v| serde_json::from_str::<Option<String>>(&v).ok().flatten())
    };
    let tls = get("transport/link/tls/root_ca_certificate").map(|ca| TlsFiles {
        ca: PathBuf::from(ca),
        identity: get("transport/link/tls/connect_certificate")
            .map(PathBuf::from)
            .zip(get("transport/link/tls/connect_private_key").map(PathBuf::from)),
    });
    let user = get("transport/auth/usrpwd/user")
        .zip(get("transport/auth/usrpwd/password"))
        .map(|(user, password)| UserPassword { user, password });
    Security {
        tls,
        user,
        ..Security::default()
    }
}

/// Refuses a router endpoint beyond loopback that lets anyone connect: a `tls/` one needs
/// mutual TLS or a user dictionary, a `tcp/` one a user dictionary (and is still unencrypted).
/// `insecure` waives it. Called on the final configuration, so a file's settings count.
pub(super) fn check_exposure(
    config: &Config,
    endpoint: &str,
    insecure: bool,
) -> Result<(), SessionError> {
    let Some((protocol, address)) = endpoint.split_once('/') else {
        return Ok(()); // checked elsewhere
    };
    if insecure || is_loopback(address) {
        return Ok(());
    }
    let on = |key: &str| {
        config
            .get_json(key)
            .is_ok_and(|v| v != "null" && v != "false")
    };
    let users = on("transport/auth/usrpwd/dictionary_file");
    let mtls = on("transport/link/tls/enable_mtls");
    let authenticated = users || (protocol == "tls" && mtls);
    if authenticated {
        if protocol == "tcp" {
            tracing::warn!(
                "{endpoint}: members authenticate with passwords, but traffic is not encrypted; \
                 prefer a tls/ endpoint"
            );
        }
        return Ok(());
    }
    Err(SessionError::Unauthenticated {
        endpoint: endpoint.to_string(),
    })
}

/// Whether a `<host>:<port>` address is reachable only from this machine.
pub fn is_loopback(address: &str) -> bool {
    let host = address.rsplit_once(':').map_or(address, |(h, _)| h);
    let host = host.trim_start_matches('[').trim_end_matches(']');
    if host.eq_ignore_ascii_case("localhost") {
        return true;
    }
    host.parse::<std::net::IpAddr>()
        .is_ok_and(|ip| ip.is_loopback())
}

/// Checks that a `tls/` endpoint has what TLS needs before zenoh fails with a vaguer message.
pub(super) fn check_tls_ready(
    config: &Config,
    endpoint: &str,
    router: bool,
) -> Result<(), SessionError> {
    if !endpoint.starts_with("tls/") {
        return Ok(());
    }
    let has = |key: &str| config.get_json(key).is_ok_and(|v| v != "null");
    let needed: &[&str] = if router {
        &[
            "transport/link/tls/listen_certificate",
            "transport/link/tls/listen_private_key",
        ]
    } else {
        &["transport/link/tls/root_ca_certificate"]
    };
    match needed.iter().find(|k| !has(k)) {
        None => Ok(()),
        Some(missing) => Err(SessionError::BadEndpoint {
            setting: if router {
                "listen/endpoints"
            } else {
                "connect/endpoints"
            },
            endpoint: endpoint.to_string(),
            reason: format!(
                "a tls/ endpoint needs {missing}: give --tls-ca/--tls-cert/--tls-key or a \
                 --zenoh-config file that sets it (shoal-coordinator keys writes both)"
            ),
        }),
    }
}

fn config_file_error(path: &Path, reason: &str) -> SessionError {
    SessionError::ConfigFile {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    }
}

fn json(s: &str) -> String {
    serde_json::Value::from(s).to_string()
}

fn set_path(config: &mut Config, key: &'static str, path: &Path) -> Result<(), SessionError> {
    set(config, key, &json(&path.to_string_lossy()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_is_only_this_machine() {
        for a in [
            "127.0.0.1:7447",
            "127.3.4.5:1",
            "[::1]:7447",
            "localhost:7447",
        ] {
            assert!(is_loopback(a), "{a}");
        }
        for a in [
            "0.0.0.0:7447",
            "[::]:7447",
            "10.0.0.1:7447",
            "coordinator:7447",
        ] {
            assert!(!is_loopback(a), "{a}");
        }
    }

    #[test]
    fn a_password_never_appears_in_debug_output() {
        let u = UserPassword {
            user: "auv1".into(),
            password: "s3cret".into(),
        };
        let shown = format!("{u:?}");
        assert!(
            shown.contains("auv1") && !shown.contains("s3cret"),
            "{shown}"
        );
    }

    #[test]
    fn an_open_endpoint_beyond_loopback_is_refused_unless_authenticated() -> Result<(), SessionError>
    {
        let plain = Config::default();
        assert!(check_exposure(&plain, "tcp/127.0.0.1:7447", false).is_ok());
        let e = check_exposure(&plain, "tcp/0.0.0.0:7447", false);
        assert!(
            matches!(e, Err(SessionError::Unauthenticated { .. })),
            "{e:?}"
        );
        assert!(check_exposure(&plain, "tcp/0.0.0.0:7447", true).is_ok());
        // Mutual TLS protects a tls/ endpoint, not a tcp/ one beside it.
        let mut mtls = Config::default();
        set(&mut mtls, "transport/link/tls/enable_mtls", "true")?;
        assert!(check_exposure(&mtls, "tls/0.0.0.0:7447", false).is_ok());
        assert!(check_exposure(&mtls, "tcp/0.0.0.0:7448", false).is_err());
        let mut users = Config::default();
        set(
            &mut users,
            "transport/auth/usrpwd/dictionary_file",
            r#""/x/users.txt""#,
        )?;
        assert!(check_exposure(&users, "tcp/0.0.0.0:7447", false).is_ok());
        Ok(())
    }

    #[test]
    fn a_servers_tls_files_come_from_the_file_and_the_flags_override_them(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let dir = tempfile::tempdir()?;
        let file = dir.path().join("coordinator.json5");
        std::fs::write(
            &file,
            r#"{ transport: { link: { tls: {
                root_ca_certificate: "/k/ca.pem",
                listen_certificate: "/k/coordinator.pem",
                listen_private_key: "/k/coordinator.key",
                connect_certificate: "/k/other.pem",
                connect_private_key: "/k/other.key",
                enable_mtls: true } } } }"#,
        )?;
        let from_file = Security {
            config_file: Some(file.clone()),
            ..Security::default()
        };
        let tls = from_file.server_tls()?.ok_or("no TLS from the file")?;
        assert_eq!(tls.ca, PathBuf::from("/k/ca.pem"));
        let pair = |c: &str, k: &str| Some((PathBuf::from(c), PathBuf::from(k)));
        assert_eq!(
            tls.identity,
            pair("/k/coordinator.pem", "/k/coordinator.key")
        );
        let flags = Security {
            config_file: Some(file),
            tls: Some(TlsFiles {
                ca: "/f/ca.pem".into(),
                identity: pair("/f/c.pem", "/f/c.key"),
            }),
            ..Security::default()
        };
        let tls = flags.server_tls()?.ok_or("no TLS from the flags")?;
        assert_eq!(tls.ca, PathBuf::from("/f/ca.pem"));
        assert_eq!(tls.identity, pair("/f/c.pem", "/f/c.key"));
        assert_eq!(Security::default().server_tls()?, None);
        let ca_only = Security {
            tls: Some(TlsFiles {
                ca: "/f/ca.pem".into(),
                identity: None,
            }),
            ..Security::default()
        };
        assert_eq!(ca_only.server_tls()?, None);
        Ok(())
    }

    #[test]
    fn a_config_file_too_large_or_missing_is_an_error_naming_it() -> std::io::Result<()> {
        let dir = tempfile::tempdir()?;
        let big = dir.path().join("big.json5");
        std::fs::write(&big, vec![b' '; MAX_CONFIG_FILE_BYTES as usize + 1])?;
        let missing = dir.path().join("missing.json5");
        for path in [big, missing] {
            let s = Security {
                config_file: Some(path.clone()),
                ..Security::default()
            };
            let e = s.base().err().map(|e| e.to_string()).unwrap_or_default();
            assert!(e.contains(&path.display().to_string()), "{e}");
        }
        Ok(())
    }
}
