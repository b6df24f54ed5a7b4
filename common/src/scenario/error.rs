//! Why a scenario could not be used, and the small reporters every check is handed, apart from
//! the scenario model so that each table's checks depend on them and not on the model.

use std::path::{Path, PathBuf};

/// Why a scenario could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read at all.
    /// The reason is in the message and deliberately not a `source`: a chained report (`{:#}`)
    /// would print it twice.
    #[error("{file}: cannot read: {error}")]
    Io {
        /// The file.
        file: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
    },
    /// TOML syntax, an unknown key, a missing key or a value of the wrong type.
    #[error("{file}: {message}")]
    Parse {
        /// The file.
        file: PathBuf,
        /// The TOML parser's message, with the path of the field.
        message: String,
    },
    /// A value that parses but makes no sense for a mission.
    #[error("{file}: field `{field}` = {value}: {reason}")]
    Invalid {
        /// The file.
        file: PathBuf,
        /// The field's path (`vehicles[0].speed`).
        field: String,
        /// The value, as written.
        value: String,
        /// Why it makes no sense.
        reason: String,
    },
}

/// Reports a bad value (field, value, reason) of the scenario file: what every check is handed.
pub(super) type Bad<'a> = &'a dyn Fn(String, String, &str) -> ScenarioError;

/// The [`Bad`] reporter of scenario `file`.
pub(super) fn invalid_in(file: &Path) -> impl Fn(String, String, &str) -> ScenarioError + '_ {
    move |field, value, reason| ScenarioError::Invalid {
        file: file.to_path_buf(),
        field,
        value,
        reason: reason.to_string(),
    }
}

/// A data file a scenario names (`field`): a regular file of at most
/// [`crate::limits::MAX_DATA_FILE_BYTES`]. A device such as `/dev/zero`, a pipe or a directory
/// is refused before anything reads it.
pub(super) fn check_data_file(path: &Path, field: &str, bad: Bad) -> Result<(), ScenarioError> {
    let shown = format!("{:?}", path.display().to_string());
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) => return Err(bad(field.into(), shown, &format!("cannot be read: {e}"))),
    };
    if !meta.is_file() {
        return Err(bad(field.into(), shown, "is not a regular file"));
    }
    let limit = crate::limits::MAX_DATA_FILE_BYTES;
    if meta.len() > limit {
        return Err(bad(
            field.into(),
            shown,
            &format!(
                "is {} bytes, over the limit {limit} (limits::MAX_DATA_FILE_BYTES)",
                meta.len()
            ),
        ));
    }
    Ok(())
}

/// `field = value is over the limit bound`, with the constant that sets the bound.
pub(super) fn over(bad: Bad, field: &str, value: usize, bound: usize, name: &str) -> ScenarioError {
    bad(
        field.into(),
        value.to_string(),
        &format!("is over the limit {bound} (limits::{name})"),
    )
}

/// `Err` unless `v` lies in `range`; the reason names the range and the unit.
pub(super) fn in_range(
    bad: Bad,
    field: &str,
    v: f64,
    range: std::ops::RangeInclusive<f64>,
    unit: &str,
) -> Result<(), ScenarioError> {
    if range.contains(&v) {
        return Ok(());
    }
    Err(bad(
        field.into(),
        v.to_string(),
        &format!("must be in [{}, {}] {unit}", range.start(), range.end()),
    ))
}
