//! Why a Zenoh configuration could not be built, and the one setter that reports it, shared by
//! [`super::session`] and [`super::security`] without either depending on the other.

use zenoh::Config;

/// Why a Zenoh configuration could not be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SessionError {
    /// Nothing to listen on or connect to (multicast scouting is off, so nothing would be found).
    #[error("no endpoint given for {setting}: give at least one, e.g. tcp/127.0.0.1:7447")]
    NoEndpoints {
        /// `listen/endpoints` or `connect/endpoints`.
        setting: &'static str,
    },
    /// An endpoint string that cannot work.
    #[error("{setting}: {endpoint:?} is not a usable endpoint: {reason}")]
    BadEndpoint {
        /// `listen/endpoints` or `connect/endpoints`.
        setting: &'static str,
        /// The string as given.
        endpoint: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A Zenoh configuration file that cannot be read or parsed.
    #[error("Zenoh configuration {path}: {reason}")]
    ConfigFile {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A router endpoint beyond loopback that anyone could join.
    #[error(
        "refusing to listen on {endpoint} without authentication: anyone who reaches this \
         machine could join the fleet, read its plans and send its vehicles orders. Secure it: \
         `shoal-coordinator keys --out keys --vehicles auv1,auv2,...` writes certificates and \
         configurations; then listen on tls/HOST:PORT with --zenoh-config keys/coordinator.json5 \
         (see docs/guide/security.md). Or listen on 127.0.0.1 only, or pass --insecure on a lab \
         network nobody else reaches"
    )]
    Unauthenticated {
        /// The endpoint as given.
        endpoint: String,
    },
    /// Zenoh refused a setting (a bug here rather than bad input: inputs are checked first).
    #[error("zenoh refused {key} = {value}: {reason}")]
    Setting {
        /// Configuration key.
        key: &'static str,
        /// JSON5 value.
        value: String,
        /// Zenoh's message.
        reason: String,
    },
}

/// Sets one configuration key, reporting a refused value as [`SessionError::Setting`].
pub(super) fn set(config: &mut Config, key: &'static str, value: &str) -> Result<(), SessionError> {
    config
        .insert_json5(key, value)
        .map_err(|e| SessionError::Setting {
            key,
            value: value.to_string(),
            reason: e.to_string(),
        })
}
