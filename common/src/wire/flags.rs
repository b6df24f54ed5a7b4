//! The Zenoh flags every binary takes, declared once (as zenoh's examples share one
//! `CommonArgs`) and flattened into each command that opens a session: the endpoints a router
//! listens on ([`ZenohListen`]), the endpoints a client connects to ([`ZenohConnect`]) and how
//! members authenticate ([`ZenohSecurityArgs`]).

use std::path::{Path, PathBuf};

use super::security::{Security, TlsFiles, UserPassword};
use super::session::SessionError;

/// Largest password file read.
const MAX_PASSWORD_BYTES: u64 = 4096;

/// Where a Zenoh router is reached when nothing says otherwise: loopback, Zenoh's own port.
pub const DEFAULT_ENDPOINT: &str = "tcp/127.0.0.1:7447";

/// The endpoints a process's Zenoh router listens on (`router`, `serve`, and `plan`/`run` in
/// distributed mode). A command whose default differs (`plan` picks one from its agents' mode)
/// changes the default and the help with clap's `mut_arg`, so the flag's name, environment
/// variable and list syntax stay declared here alone.
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct ZenohListen {
    /// Endpoint(s) to listen on (comma-separated); beyond loopback needs authentication.
    #[arg(
        long,
        env = "SHOAL_LISTEN",
        value_delimiter = ',',
        default_value = DEFAULT_ENDPOINT
    )]
    pub listen: Vec<String>,
}

/// The endpoints a Zenoh client (an agent, `status`) connects to: the coordinator's router.
#[derive(Debug, Clone, PartialEq, Eq, clap::Args)]
pub struct ZenohConnect {
    /// The coordinator's Zenoh endpoint(s), e.g. tcp/coordinator:7447 (comma-separated).
    #[arg(
        long,
        env = "SHOAL_CONNECT",
        value_delimiter = ',',
        default_value = DEFAULT_ENDPOINT
    )]
    pub connect: Vec<String>,
}

/// How this process joins the fleet's Zenoh network securely (see `docs/guide/security.md`).
#[derive(Debug, Clone, Default, PartialEq, Eq, clap::Args)]
pub struct ZenohSecurityArgs {
    /// Zenoh JSON5 configuration to start from, as `zenohd -c` takes it (TLS, user/password,
    /// access control); `shoal-coordinator keys` writes one per fleet member.
    #[arg(long, env = "SHOAL_ZENOH_CONFIG", value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// TLS: the fleet CA's certificate (PEM); peers must present certificates it signed.
    #[arg(long, env = "SHOAL_TLS_CA", value_name = "FILE")]
    pub tls_ca: Option<PathBuf>,
    /// TLS: this member's certificate (PEM); with --tls-ca, mutual TLS.
    #[arg(
        long,
        env = "SHOAL_TLS_CERT",
        value_name = "FILE",
        requires_all = ["tls_key", "tls_ca"]
    )]
    pub tls_cert: Option<PathBuf>,
    /// TLS: this member's private key (PEM).
    #[arg(
        long,
        env = "SHOAL_TLS_KEY",
        value_name = "FILE",
        requires = "tls_cert"
    )]
    pub tls_key: Option<PathBuf>,
    /// User/password authentication: this member's user name.
    #[arg(
        long,
        env = "SHOAL_ZENOH_USER",
        value_name = "NAME",
        requires = "password_file"
    )]
    pub user: Option<String>,
    /// User/password authentication: a file holding this member's password (never a flag:
    /// command lines are visible to every user of the machine).
    #[arg(
        long,
        env = "SHOAL_ZENOH_PASSWORD_FILE",
        value_name = "FILE",
        requires = "user"
    )]
    pub password_file: Option<PathBuf>,
    /// Router: a `user:password` file per line; only those users may connect.
    #[arg(long, env = "SHOAL_ZENOH_USERS_FILE", value_name = "FILE")]
    pub users_file: Option<PathBuf>,
    /// Listen beyond loopback even though nobody who connects is authenticated (a lab network
    /// nobody else reaches; never on a ship's network).
    #[arg(long, env = "SHOAL_INSECURE")]
    pub insecure: bool,
}

impl ZenohSecurityArgs {
    /// The settings, reading the password file.
    pub fn security(&self) -> Result<Security, SessionError> {
        let tls = self.tls_ca.as_ref().map(|ca| TlsFiles {
            ca: ca.clone(),
            identity: self.tls_cert.clone().zip(self.tls_key.clone()),
        });
        let user = match (&self.user, &self.password_file) {
            (Some(user), Some(file)) => Some(UserPassword {
                user: user.clone(),
                password: read_password(file)?,
            }),
            _ => None,
        };
        Ok(Security {
            config_file: self.zenoh_config.clone(),
            tls,
            user,
            users_file: self.users_file.clone(),
            insecure: self.insecure,
        })
    }

    /// The `SHOAL_*` variables these flags read: a coordinator removes them from the
    /// environment of the agents it starts, which must not inherit its identity.
    pub const ENV: &'static [&'static str] = &[
        "SHOAL_ZENOH_CONFIG",
        "SHOAL_TLS_CA",
        "SHOAL_TLS_CERT",
        "SHOAL_TLS_KEY",
        "SHOAL_ZENOH_USER",
        "SHOAL_ZENOH_PASSWORD_FILE",
        "SHOAL_ZENOH_USERS_FILE",
        "SHOAL_INSECURE",
    ];
}

fn read_password(path: &Path) -> Result<String, SessionError> {
    let error = |reason: String| SessionError::ConfigFile {
        path: path.to_path_buf(),
        reason,
    };
    let text =
        crate::limits::read_at_most(path, MAX_PASSWORD_BYTES).map_err(|e| error(e.to_string()))?;
    let password = text.trim_end_matches(['\n', '\r']).to_string();
    if password.is_empty() {
        return Err(error("the password file is empty".to_string()));
    }
    Ok(password)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        zenoh: ZenohSecurityArgs,
        #[command(flatten)]
        listen: ZenohListen,
        #[command(flatten)]
        connect: ZenohConnect,
    }

    #[test]
    fn endpoints_default_to_loopback_and_split_on_commas() -> Result<(), clap::Error> {
        let cli = Cli::try_parse_from(["x"])?;
        assert_eq!(cli.listen.listen, [DEFAULT_ENDPOINT]);
        assert_eq!(cli.connect.connect, [DEFAULT_ENDPOINT]);
        let cli =
            Cli::try_parse_from(["x", "--listen", "tcp/a:1,tcp/b:2", "--connect", "tls/c:3"])?;
        assert_eq!(cli.listen.listen, ["tcp/a:1", "tcp/b:2"]);
        assert_eq!(cli.connect.connect, ["tls/c:3"]);
        Ok(())
    }

    #[test]
    fn flags_become_settings_and_the_password_comes_from_its_file(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let dir = tempfile::tempdir()?;
        let pw = dir.path().join("pw");
        std::fs::write(&pw, "hunter2\n")?;
        let pw_arg = pw.to_string_lossy().to_string();
        let cli = Cli::try_parse_from([
            "x",
            "--tls-ca",
            "ca.pem",
            "--tls-cert",
            "auv1.pem",
            "--tls-key",
            "auv1.key",
            "--user",
            "auv1",
            "--password-file",
            &pw_arg,
        ])?;
        let s = cli.zenoh.security()?;
        let tls = s.tls.ok_or("no tls")?;
        assert_eq!(tls.ca, PathBuf::from("ca.pem"));
        assert_eq!(
            tls.identity,
            Some((PathBuf::from("auv1.pem"), PathBuf::from("auv1.key")))
        );
        let user = s.user.ok_or("no user")?;
        assert_eq!(
            (user.user.as_str(), user.password.as_str()),
            ("auv1", "hunter2")
        );
        assert!(!s.insecure);
        Ok(())
    }

    #[test]
    fn a_certificate_without_its_key_or_ca_is_a_usage_error() {
        for args in [
            &["x", "--tls-cert", "a.pem", "--tls-ca", "ca.pem"][..],
            &["x", "--tls-cert", "a.pem", "--tls-key", "a.key"][..],
            &["x", "--user", "auv1"][..],
        ] {
            assert!(Cli::try_parse_from(args).is_err(), "{args:?}");
        }
    }

    #[test]
    fn an_empty_password_file_is_refused() -> std::io::Result<()> {
        let dir = tempfile::tempdir()?;
        let pw = dir.path().join("pw");
        std::fs::write(&pw, "\n")?;
        assert!(read_password(&pw).is_err());
        Ok(())
    }
}
