//! The NDJSON mission log: one JSON object per line, written as the execution goes, so a crash
//! loses at most the line being written.
//!
//! Lines: `{"record": "start", …}` first, then `plan`, `telemetry` and `event` records in the
//! order they happened, and `{"record": "end", …}` with the figures last.

use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::Context as _;
use shoal_common::limits::MAX_LOG_LINE_BYTES;

use super::record::{CutShort, Log, Record};

/// Appends records to an NDJSON log file.
pub struct NdjsonWriter {
    out: BufWriter<File>,
    path: PathBuf,
}

impl NdjsonWriter {
    /// Creates (truncates) `path`.
    pub fn create(path: &Path) -> anyhow::Result<NdjsonWriter> {
        let file = File::create(path)
            .with_context(|| format!("cannot create the mission log {}", path.display()))?;
        Ok(NdjsonWriter {
            out: BufWriter::new(file),
            path: path.to_path_buf(),
        })
    }

    /// Writes one record (a failure is logged, not fatal: the mission goes on).
    pub fn write(&mut self, r: &Record) {
        let line = match serde_json::to_string(r) {
            Ok(l) => l,
            Err(e) => return tracing::warn!("cannot serialise a log record: {e}"),
        };
        if let Err(e) = writeln!(self.out, "{line}") {
            tracing::warn!("cannot write {}: {e}", self.path.display());
        }
    }

    /// Flushes to disk.
    pub fn flush(&mut self) {
        if let Err(e) = self.out.flush() {
            tracing::warn!("cannot write {}: {e}", self.path.display());
        }
    }
}

/// Reads a whole log; a bad line is an error naming the file, the line and what is wrong. Only
/// a last line without its newline that is not a whole record is left out instead (and named
/// in [`Log::cut_short`]): that is what a run killed mid-write leaves, and the records before
/// it still tell the mission.
///
/// A line longer than [`MAX_LOG_LINE_BYTES`] is an error too, found before more of it is read:
/// no mission writes one, and a file without newlines (`/dev/zero`) would otherwise fill the
/// memory.
pub fn read(path: &Path) -> anyhow::Result<Log> {
    read_with_line_limit(path, MAX_LOG_LINE_BYTES)
}

/// [`read`] with lines of at most `max_line` bytes.
fn read_with_line_limit(path: &Path, max_line: usize) -> anyhow::Result<Log> {
    let file = File::open(path)
        .with_context(|| format!("cannot open the mission log {}", path.display()))?;
    let mut reader = BufReader::new(file);
    let mut records = Vec::new();
    let mut cut_short = None;
    let mut bytes = Vec::new();
    for n in 1.. {
        bytes.clear();
        let read = (&mut reader)
            .take(max_line as u64 + 1)
            .read_until(b'\n', &mut bytes)
            .with_context(|| format!("{}: cannot read line {n}", path.display()))?;
        if read == 0 {
            break;
        }
        if bytes.len() > max_line {
            anyhow::bail!(
                "{} line {n}: longer than the limit of {max_line} bytes (limits::MAX_LOG_LINE_BYTES): not a mission log",
                path.display()
            );
        }
        let Ok(line) = std::str::from_utf8(&bytes) else {
            anyhow::bail!(
                "{} line {n}: not UTF-8 text: not a mission log",
                path.display()
            );
        };
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<Record>(line) {
            Ok(r) => records.push(r),
            Err(_) if !line.ends_with('\n') => cut_short = Some(CutShort::Line(n)),
            Err(e) => anyhow::bail!("{} line {n}: not a mission-log record: {e}", path.display()),
        }
    }
    match records.first() {
        Some(Record::Start(_)) => Ok(Log { records, cut_short }),
        _ => anyhow::bail!(
            "{}: a mission log starts with a \"start\" record; this one does not",
            path.display()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::super::record::Start;
    use super::*;
    use shoal_common::wire::open::MissionEvent;

    #[test]
    fn a_log_reads_back_and_a_bad_line_is_named() -> anyhow::Result<()> {
        let dir = std::env::temp_dir().join(format!("shoal-log-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let path = dir.join("m.ndjson");
        let start = Record::Start(Start {
            mission: "m".into(),
            scenario_toml: "name = \"x\"".into(),
            common_arrival_s: 100.0,
            arrival_window_s: 10.0,
            horizon_s: 60.0,
            time_scale: 50.0,
            epoch_unix_ms: 7,
        });
        let event = Record::Event(MissionEvent {
            version: 1,
            mission: "m".into(),
            t_s: 3.5,
            kind: "hold".into(),
            vehicles: vec!["auv2".into()],
            detail: "because".into(),
        });
        let mut w = NdjsonWriter::create(&path)?;
        w.write(&start);
        w.write(&event);
        w.flush();
        assert_eq!(read(&path)?.records, vec![start.clone(), event.clone()]);
        let text = std::fs::read_to_string(&path)?;
        assert!(text
            .lines()
            .next()
            .unwrap_or("")
            .contains("\"record\":\"start\""));
        // Killed mid-write: the last line has no newline and is half a record.
        let cut = text.len() - 20;
        std::fs::write(&path, &text[..cut])?;
        let log = read(&path)?;
        assert_eq!(
            (log.records, log.cut_short),
            (vec![start.clone()], Some(CutShort::Line(2)))
        );
        // A whole last record without its newline is read.
        std::fs::write(&path, text.trim_end())?;
        assert_eq!(read(&path)?.records, vec![start, event]);
        // The same half record with a newline after it is no cut: an error naming the line.
        std::fs::write(&path, format!("{}\n{}", &text[..cut], text))?;
        let e = read(&path).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("line 2") && e.contains("m.ndjson"), "{e}");
        std::fs::write(&path, format!("{text}{{\"record\": \"nonsense\"}}\n"))?;
        let e = read(&path).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("line 3") && e.contains("m.ndjson"), "{e}");
        // A line over the limit is named with its number before the rest of it is read.
        let limit = text.lines().map(str::len).max().unwrap_or(0) + 1;
        std::fs::write(&path, &text)?;
        assert!(read_with_line_limit(&path, limit).is_ok());
        std::fs::write(&path, format!("{text}{}\n", "x".repeat(limit + 1)))?;
        let e = read_with_line_limit(&path, limit)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.contains("m.ndjson line 3") && e.contains(&format!("limit of {limit} bytes")),
            "{e}"
        );
        std::fs::write(&path, text.lines().nth(1).unwrap_or(""))?;
        let e = read(&path).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("starts with a \"start\" record"), "{e}");
        std::fs::remove_dir_all(&dir)?;
        Ok(())
    }
}
