//! The files a scenario names (a seabed grid, a current field, a coverage heightmap), and how a
//! scenario that came over the network is kept to a data directory.
//!
//! A scenario read from disk may name any file its author can read. A scenario submitted by a
//! network client must not: it could read `/etc/passwd` back through an error message, learn
//! which paths exist, or name `/dev/zero` and exhaust memory. [`Scenario::parse_submitted`]
//! therefore checks every file a submitted scenario names before anything is opened: after
//! canonicalisation (symbolic links and `..` followed) it must be a regular file under the
//! operator's data directory and no larger than [`limits::MAX_DATA_FILE_BYTES`]. The client is
//! told only [`OUTSIDE_DATA_DIR`]; what was wrong goes to the server log.

use std::path::{Path, PathBuf};

use super::error::ScenarioError;
use super::model::Scenario;
use crate::limits;

/// Every scenario field that names a file, as its TOML key path. A field added to the scenario
/// that names a file must be listed here (and in [`Scenario::named_files`]), or a submitted
/// scenario could read any file.
pub const FILE_FIELDS: [&[&str]; 3] = [
    &["seabed", "grid", "file"],
    &["currents", "file"],
    &["coverage", "heightmap"],
];

/// The one reason a client is given for a file it may not use, whatever the cause (missing,
/// outside, not a regular file): a different message would tell which paths exist.
pub const OUTSIDE_DATA_DIR: &str = "names a file outside the data directory";

/// The directory whose files submitted scenarios may name, canonicalised once.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DataDir {
    /// Canonical, so `starts_with` on a canonical path is a containment test.
    root: PathBuf,
}

/// Why a named file was refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FileRefusal {
    /// Missing, outside the data directory or not a regular file; the text is for the server
    /// log only.
    Hidden(String),
    /// Under the data directory but larger than the limit (bytes): safe to tell.
    TooLarge(u64),
}

impl DataDir {
    /// The data directory `dir`, which must exist.
    pub fn open(dir: &Path) -> std::io::Result<DataDir> {
        let root = std::fs::canonicalize(dir)?;
        if !root.is_dir() {
            return Err(std::io::Error::other(format!(
                "{} is not a directory",
                root.display()
            )));
        }
        Ok(DataDir { root })
    }

    /// The canonical directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The canonical path of `written` (a relative one is taken from the data directory) when
    /// it is a regular file under the data directory within the size limit.
    pub fn confine(&self, written: &Path) -> Result<PathBuf, FileRefusal> {
        let joined = self.root.join(written);
        let canon = std::fs::canonicalize(&joined)
            .map_err(|e| FileRefusal::Hidden(format!("{}: {e}", joined.display())))?;
        if !canon.starts_with(&self.root) {
            return Err(FileRefusal::Hidden(format!(
                "{} is outside {}",
                canon.display(),
                self.root.display()
            )));
        }
        let meta = std::fs::metadata(&canon)
            .map_err(|e| FileRefusal::Hidden(format!("{}: {e}", canon.display())))?;
        if !meta.is_file() {
            return Err(FileRefusal::Hidden(format!(
                "{} is not a regular file",
                canon.display()
            )));
        }
        if meta.len() > limits::MAX_DATA_FILE_BYTES {
            return Err(FileRefusal::TooLarge(meta.len()));
        }
        Ok(canon)
    }
}

impl Scenario {
    /// Parses and validates a scenario that came from a network client (`file` names it in
    /// errors): every file it names must lie under `data_dir` (none may without one). Returns
    /// the scenario and its text with those paths made canonical and absolute, which is what
    /// should be stored and loaded again: it reads exactly the files that were checked.
    pub fn parse_submitted(
        text: &str,
        file: &Path,
        data_dir: Option<&DataDir>,
    ) -> Result<(Scenario, String), ScenarioError> {
        let text = confine_files(text, file, data_dir)?;
        let scenario = Scenario::parse(&text, file)?;
        // Defence in depth: what was loaded is what was checked.
        for (field, path) in scenario.named_files() {
            let inside = data_dir.is_some_and(|d| path.starts_with(d.root()));
            if !inside {
                tracing::warn!(
                    "{}: {field} = {} escaped the check",
                    file.display(),
                    path.display()
                );
                return Err(refusal(file, field, path, OUTSIDE_DATA_DIR));
            }
        }
        Ok((scenario, text))
    }

    /// Every file the scenario names, with its field (as written, or absolute once loaded).
    pub fn named_files(&self) -> Vec<(&'static str, &Path)> {
        let mut files = Vec::new();
        if let Some(g) = self.seabed.as_ref().and_then(|s| s.grid.as_ref()) {
            files.push(("seabed.grid.file", g.file.as_path()));
        }
        if let Some(f) = self.currents.as_ref().and_then(|c| c.file.as_ref()) {
            files.push(("currents.file", f.as_path()));
        }
        if let Some(h) = self.coverage.as_ref().and_then(|c| c.heightmap.as_ref()) {
            files.push(("coverage.heightmap", h.as_path()));
        }
        files
    }
}

/// The error a client sees for field `field` naming `written`.
fn refusal(file: &Path, field: &str, written: &Path, reason: &str) -> ScenarioError {
    ScenarioError::Invalid {
        file: file.to_path_buf(),
        field: field.to_string(),
        value: format!("{:?}", written.display().to_string()),
        reason: reason.to_string(),
    }
}

/// `text` with every file field ([`FILE_FIELDS`]) checked against `data_dir` and replaced by
/// its canonical path; unchanged when it names none. Text that is not TOML is left for
/// [`Scenario::parse`] to refuse with its own message.
fn confine_files(
    text: &str,
    file: &Path,
    data_dir: Option<&DataDir>,
) -> Result<String, ScenarioError> {
    let Ok(mut table) = text.parse::<toml::Table>() else {
        return Ok(text.to_string());
    };
    let mut changed = false;
    for path in FILE_FIELDS {
        let Some(value) = lookup(&mut table, path) else {
            continue;
        };
        let Some(written) = value.as_str().map(PathBuf::from) else {
            continue; // the wrong type: Scenario::parse names it
        };
        let field = path.join(".");
        let Some(dir) = data_dir else {
            tracing::warn!(
                "{}: {field} = {:?} refused: no data directory",
                file.display(),
                written
            );
            return Err(refusal(
                file,
                &field,
                &written,
                "names a file, and this server takes none (start it with --data-dir)",
            ));
        };
        match dir.confine(&written) {
            Ok(canon) => {
                *value = toml::Value::String(canon.display().to_string());
                changed = true;
            }
            Err(FileRefusal::Hidden(detail)) => {
                tracing::warn!("{}: {field} refused: {detail}", file.display());
                return Err(refusal(file, &field, &written, OUTSIDE_DATA_DIR));
            }
            Err(FileRefusal::TooLarge(bytes)) => {
                let reason = format!(
                    "the file is {bytes} bytes, over the limit {}",
                    limits::MAX_DATA_FILE_BYTES
                );
                return Err(refusal(file, &field, &written, &reason));
            }
        }
    }
    if !changed {
        return Ok(text.to_string());
    }
    toml::to_string(&table).map_err(|e| ScenarioError::Parse {
        file: file.to_path_buf(),
        message: format!("cannot write the checked scenario back: {e}"),
    })
}

/// The value at `path` in `table`, if every table on the way is there.
fn lookup<'a>(table: &'a mut toml::Table, path: &[&str]) -> Option<&'a mut toml::Value> {
    let (last, tables) = path.split_last()?;
    let mut t = table;
    for key in tables {
        t = t.get_mut(*key)?.as_table_mut()?;
    }
    t.get_mut(*last)
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = include_str!("../../../scenarios/amp-pso-2.toml");
    const UNIFORM: &str = "x,y,z,u,v,w\n1,2,3,0.5,-0.5,0\n";

    fn grid_currents(file: &str) -> String {
        format!("{BASE}\n[currents]\nmodel = \"grid\"\nfile = {file:?}\n")
    }

    fn message(r: Result<(Scenario, String), ScenarioError>) -> String {
        match r {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        }
    }

    fn sub() -> &'static Path {
        Path::new("<submitted scenario>")
    }

    #[test]
    fn a_submission_naming_etc_passwd_is_refused_without_echoing_it() -> std::io::Result<()> {
        let tmp = tempfile::tempdir()?;
        let data = DataDir::open(tmp.path())?;
        let e = message(Scenario::parse_submitted(
            &grid_currents("/etc/passwd"),
            sub(),
            Some(&data),
        ));
        assert_eq!(
            e,
            "<submitted scenario>: field `currents.file` = \"/etc/passwd\": names a file outside the data directory"
        );
        Ok(())
    }

    #[test]
    fn missing_outside_and_escaping_files_get_the_same_message() -> std::io::Result<()> {
        let tmp = tempfile::tempdir()?;
        let data = DataDir::open(tmp.path())?;
        std::os::unix::fs::symlink("/etc/hostname", tmp.path().join("link.csv"))?;
        for written in [
            "/nonexistent/x.csv",
            "missing.csv",
            "../../etc/passwd",
            "link.csv",
            "/dev/zero",
            ".",
        ] {
            let e = message(Scenario::parse_submitted(
                &grid_currents(written),
                sub(),
                Some(&data),
            ));
            assert!(
                e.ends_with(": names a file outside the data directory"),
                "{written}: {e}"
            );
        }
        Ok(())
    }

    #[test]
    fn without_a_data_directory_any_named_file_is_refused() {
        for text in [
            grid_currents("uniform.csv"),
            format!("{BASE}\n[seabed.grid]\nfile = \"g.asc\"\n"),
        ] {
            let e = message(Scenario::parse_submitted(&text, sub(), None));
            assert!(e.contains("start it with --data-dir"), "{e}");
        }
    }

    #[test]
    fn a_file_under_the_data_directory_is_read_from_its_canonical_path() -> std::io::Result<()> {
        let tmp = tempfile::tempdir()?;
        std::fs::create_dir(tmp.path().join("sub"))?;
        std::fs::write(tmp.path().join("sub/uniform.csv"), UNIFORM)?;
        let data = DataDir::open(tmp.path())?;
        let (s, text) =
            Scenario::parse_submitted(&grid_currents("sub/../sub/uniform.csv"), sub(), Some(&data))
                .map_err(std::io::Error::other)?;
        let canon = data.root().join("sub/uniform.csv");
        assert_eq!(s.named_files(), vec![("currents.file", canon.as_path())]);
        assert!(text.contains(&canon.display().to_string()), "{text}");
        assert!(s.currents.is_some_and(|c| c.grid.is_some()));
        Ok(())
    }

    #[test]
    fn a_file_over_the_size_limit_is_refused_with_its_size() -> std::io::Result<()> {
        let tmp = tempfile::tempdir()?;
        let big = std::fs::File::create(tmp.path().join("big.csv"))?;
        big.set_len(limits::MAX_DATA_FILE_BYTES + 1)?; // sparse: no disk used
        let data = DataDir::open(tmp.path())?;
        let e = message(Scenario::parse_submitted(
            &grid_currents("big.csv"),
            sub(),
            Some(&data),
        ));
        assert_eq!(
            e,
            "<submitted scenario>: field `currents.file` = \"big.csv\": the file is 67108865 bytes, over the limit 67108864"
        );
        Ok(())
    }

    #[test]
    fn a_scenario_naming_no_file_is_kept_as_written() -> Result<(), ScenarioError> {
        let (_, text) = Scenario::parse_submitted(BASE, sub(), None)?;
        assert_eq!(text, BASE);
        Ok(())
    }

    #[test]
    fn every_file_field_is_checked() {
        // Each entry of FILE_FIELDS, set to /etc/passwd in an otherwise empty table, is refused
        // (the text need not be a valid scenario: files are checked first).
        for path in FILE_FIELDS {
            let Some((last, tables)) = path.split_last() else {
                continue;
            };
            let text = format!("[{}]\n{last} = \"/etc/passwd\"\n", tables.join("."));
            let e = match confine_files(&text, sub(), None) {
                Ok(t) => panic!("{path:?} passed: {t}"),
                Err(e) => e.to_string(),
            };
            assert!(e.contains(&path.join(".")), "{e}");
        }
    }
}
