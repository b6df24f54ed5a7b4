//! The mission log, written as the execution goes, in two files with the same records:
//! `mission.ndjson`, one JSON object per line for scripts ([`ndjson`]), and `mission.mcap`
//! beside it for robotics tools ([`mcap`]; its channels and schemas: [`channels`]). Each loses
//! at most the record being written when the run is killed. `shoal-coordinator replay LOG`
//! reads either back (told apart by the MCAP magic, not by the name) and recomputes the figures
//! from the records alone.
//!
//! Records: `start` first, then `plan`, `telemetry`, `event` and `obstacle` records in the
//! order they happened, and `end` with the figures last.

pub mod channels;
pub mod mcap;
pub mod ndjson;
mod record;

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Context as _;

use self::mcap::McapWriter;
use self::ndjson::NdjsonWriter;
pub use self::record::{CutShort, Log, Record, Start};

/// The event kind of a vehicle declared lost (its `vehicles` names it).
pub const EVENT_LOST: &str = "vehicle_lost";
/// The event kind of a vehicle told to hold (its `vehicles` names it).
pub const EVENT_HOLD: &str = "hold";
/// The event kind of a vehicle whose link reports a fault (its `vehicles` names it).
pub const EVENT_FAULT: &str = "fault";

/// Kind of the event of a telemetry report refused as implausible (see [`super::plausible`]).
pub const EVENT_IMPLAUSIBLE: &str = "implausible_report";

/// Kind of the event of a published obstacle refused (out of scale, a known id, over the cap
/// or the rate limit).
pub const EVENT_OBSTACLE_DROPPED: &str = "obstacle_dropped";

/// Something that is shown every record as it is written; it must not block (the execution
/// loop writes the log).
pub trait RecordWatcher: Send + Sync {
    /// Takes record `r`.
    fn record(&self, r: &Record);
}

/// Appends records to both logs.
pub struct LogWriter {
    /// The NDJSON log (it cannot be created: the mission does not start).
    ndjson: NdjsonWriter,
    /// The MCAP log; `None` when it could not be created (a warning; the mission goes on).
    mcap: Option<McapWriter>,
    /// Who watches live: gets every record written (the live feed of the web view and the
    /// Foxglove server).
    watcher: Option<Arc<dyn RecordWatcher>>,
}

impl LogWriter {
    /// Creates (truncates) the NDJSON log `path` and the MCAP log at [`mcap_path`] of it.
    pub fn create(path: &Path) -> anyhow::Result<LogWriter> {
        let ndjson = NdjsonWriter::create(path)?;
        let mcap = McapWriter::create(&mcap_path(path))
            .map_err(|e| tracing::warn!("{e:#}; the mission goes on with the NDJSON log alone"))
            .ok();
        Ok(LogWriter {
            ndjson,
            mcap,
            watcher: None,
        })
    }

    /// Also hands every record written from now on to `watcher`.
    pub fn with_watcher(mut self, watcher: Option<Arc<dyn RecordWatcher>>) -> LogWriter {
        self.watcher = watcher;
        self
    }

    /// Writes one record (a failure is logged, not fatal: the mission goes on).
    pub fn write(&mut self, r: &Record) {
        self.ndjson.write(r);
        if let Some(m) = &mut self.mcap {
            m.write(r);
        }
        if let Some(w) = &self.watcher {
            w.record(r);
        }
    }

    /// Flushes to disk.
    pub fn flush(&mut self) {
        self.ndjson.flush();
        if let Some(m) = &mut self.mcap {
            m.flush();
        }
    }

    /// Flushes, and ends the MCAP log with its summary: after the last record.
    pub fn finish(&mut self) {
        self.ndjson.flush();
        if let Some(m) = &mut self.mcap {
            m.finish();
        }
    }
}

/// Where the MCAP log of the NDJSON log `path` goes: beside it, with the extension `.mcap`
/// (`mission.ndjson` → `mission.mcap`; a log named `….mcap` gets `….mcap.mcap`).
pub fn mcap_path(path: &Path) -> PathBuf {
    let beside = path.with_extension("mcap");
    if beside == path {
        let mut name = path.as_os_str().to_owned();
        name.push(".mcap");
        PathBuf::from(name)
    } else {
        beside
    }
}

/// Reads a whole log, NDJSON ([`ndjson::read`]) or MCAP ([`mcap::read`]), told apart by the
/// MCAP magic at its start.
pub fn read(path: &Path) -> anyhow::Result<Log> {
    if is_mcap(path)? {
        self::mcap::read(path)
    } else {
        ndjson::read(path)
    }
}

/// Whether the file at `path` starts with the MCAP magic.
pub fn is_mcap(path: &Path) -> anyhow::Result<bool> {
    let file = std::fs::File::open(path)
        .with_context(|| format!("cannot open the mission log {}", path.display()))?;
    let mut head = Vec::with_capacity(self::mcap::MAGIC.len());
    file.take(self::mcap::MAGIC.len() as u64)
        .read_to_end(&mut head)
        .with_context(|| format!("cannot read {}", path.display()))?;
    Ok(head == self::mcap::MAGIC)
}
