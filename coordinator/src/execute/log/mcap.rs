//! The MCAP mission log (`mission.mcap`): the records of the NDJSON log as MCAP messages, for
//! robotics tools (Foxglove, the `mcap` command-line tool and libraries). Channels, topics and
//! schemas are in the sibling `channels` module.
//!
//! The file is unchunked: each record goes to disk as it is written (at the next flush, every
//! second), so a run that is killed leaves whole records up to its last flush, as the NDJSON
//! log does, and no compression codec is needed. The summary (schemas, channels, statistics)
//! is written when the mission ends.
//!
//! Log time is mission time, in nanoseconds: a report's is when it was received, an event's is
//! its `t_s`, the start record's is 0, and a plan, an obstacle or the end record, which carry
//! no time of their own, take the latest log time before them (they are logged as they happen,
//! so that is at most one report interval early). A report's publish time is when its agent
//! sent it; every other record's is its log time. So the same records always make the same
//! file, whether `run` writes it or `export` converts an NDJSON log. Log times may run a little
//! backwards from one message to the next (a report is stamped when it arrived, an event when
//! the loop made it, which can be before it got to the report): a message's sequence number is
//! its place in the file, from 1.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Read};
use std::path::{Path, PathBuf};

use ::mcap::records::{op, MessageHeader, Record as McapRecord};
use ::mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use ::mcap::McapError;
use anyhow::Context as _;
use shoal_common::limits::{MAX_LOG_BYTES, MAX_LOG_LINE_BYTES};

use super::channels::{self, Kind, MESSAGE_ENCODING, SCHEMA_ENCODING};
use super::record::{CutShort, Log, Record, Start};

/// The first bytes of every MCAP file.
pub const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Room for a message record's header (channel, sequence, two times) and a schema's name and
/// encoding beside the [`MAX_LOG_LINE_BYTES`] of its data.
const RECORD_OVERHEAD: usize = 4096;

/// Writes records to an MCAP file. A failure is logged, not fatal: the mission goes on, and so
/// does its NDJSON log.
pub struct McapWriter {
    /// `None` once finished, or after a failure (the MCAP log stops there).
    out: Option<::mcap::Writer<BufWriter<File>>>,
    /// For the messages.
    path: PathBuf,
    /// Channel id of each topic written so far.
    channels: BTreeMap<String, u16>,
    /// Schema id of each record kind written so far.
    schemas: BTreeMap<Kind, u16>,
    /// Messages written (each message's sequence number is its place in the file, from 1).
    messages: u32,
    /// The start record, for the mission clock of the reports' receipt times.
    start: Option<Start>,
    /// Latest log time so far, for the records without a time of their own.
    latest_ns: u64,
}

impl McapWriter {
    /// Creates (truncates) `path` and writes the MCAP header.
    pub fn create(path: &Path) -> anyhow::Result<McapWriter> {
        let file = File::create(path)
            .with_context(|| format!("cannot create the MCAP log {}", path.display()))?;
        let options = ::mcap::WriteOptions::new()
            .use_chunks(false)
            .library(format!("shoal-coordinator {}", env!("CARGO_PKG_VERSION")));
        let out = options
            .create(BufWriter::new(file))
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(McapWriter {
            out: Some(out),
            path: path.to_path_buf(),
            channels: BTreeMap::new(),
            schemas: BTreeMap::new(),
            messages: 0,
            start: None,
            latest_ns: 0,
        })
    }

    /// Writes one record as a message on its channel (declared with its schema the first time).
    pub fn write(&mut self, r: &Record) {
        if self.out.is_none() {
            return;
        }
        if let Err(e) = self.try_write(r) {
            tracing::warn!(
                "cannot write {}: {e:#}; the MCAP log stops here (the NDJSON log goes on)",
                self.path.display()
            );
            // Dropping the writer tries to finish the file with the records before the failure.
            self.out = None;
        }
    }

    fn try_write(&mut self, r: &Record) -> anyhow::Result<()> {
        let data = channels::message(r).context("cannot serialise a log record")?;
        let (log_time, publish_time) = self.times(r);
        let channel = self.channel(r)?;
        let Some(out) = self.out.as_mut() else {
            return Ok(());
        };
        self.messages += 1;
        out.write_to_known_channel(
            &MessageHeader {
                channel_id: channel,
                sequence: self.messages,
                log_time,
                publish_time,
            },
            &data,
        )?;
        Ok(())
    }

    /// Log time and publish time of `r` (see the module's header).
    fn times(&mut self, r: &Record) -> (u64, u64) {
        let (log, publish) = match r {
            Record::Start(s) => {
                self.start = Some(s.clone());
                (0, 0)
            }
            Record::Telemetry {
                received_unix_us,
                telemetry,
            } => match &self.start {
                Some(s) => (
                    channels::mission_ns(channels::mission_s(s, *received_unix_us)),
                    channels::mission_ns(channels::mission_s(s, telemetry.sent_unix_us)),
                ),
                None => (self.latest_ns, self.latest_ns),
            },
            Record::Event(e) => {
                let t = channels::mission_ns(e.t_s);
                (t, t)
            }
            Record::Plan(_) | Record::Obstacle(_) | Record::End(_) => {
                (self.latest_ns, self.latest_ns)
            }
        };
        self.latest_ns = self.latest_ns.max(log);
        (log, publish)
    }

    /// The channel of `r`, declared (with its kind's schema) if it is the first on it.
    fn channel(&mut self, r: &Record) -> anyhow::Result<u16> {
        let topic = channels::topic(r);
        if let Some(&id) = self.channels.get(&topic) {
            return Ok(id);
        }
        let Some(out) = self.out.as_mut() else {
            return Ok(0);
        };
        let kind = Kind::of(r);
        let schema = match self.schemas.get(&kind) {
            Some(&id) => id,
            None => {
                let text = serde_json::to_vec(&kind.schema())?;
                let id = out.add_schema(&kind.schema_name(), SCHEMA_ENCODING, &text)?;
                self.schemas.insert(kind, id);
                id
            }
        };
        let id = out.add_channel(schema, &topic, MESSAGE_ENCODING, &BTreeMap::new())?;
        self.channels.insert(topic, id);
        Ok(id)
    }

    /// Flushes to disk what is written.
    pub fn flush(&mut self) {
        if let Some(out) = self.out.as_mut() {
            if let Err(e) = out.flush() {
                tracing::warn!("cannot write {}: {e}", self.path.display());
            }
        }
    }

    /// Writes the summary and the footer; nothing can be written after.
    pub fn finish(&mut self) {
        if let Some(mut out) = self.out.take() {
            if let Err(e) = out.finish() {
                tracing::warn!("cannot finish {}: {e}", self.path.display());
            }
        }
    }
}

/// Writes `records` to a new MCAP log at `path` (what `export --format mcap` does with a
/// mission log): an error here is the command's, not a warning.
pub fn write_all(path: &Path, records: &[Record]) -> anyhow::Result<()> {
    let mut w = McapWriter::create(path)?;
    for r in records {
        w.try_write(r)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(mut out) = w.out.take() {
        out.finish()
            .with_context(|| format!("cannot finish {}", path.display()))?;
    }
    Ok(())
}

/// Reads an MCAP mission log: the messages on the `/shoal/…` topics, in file order. A file that
/// is not MCAP, a record that does not parse or a message that is not a record of its channel's
/// kind is an error naming the file and what is wrong. A file that ends before its data section
/// does (what a killed run leaves) gives the records before the end; one cut inside a record
/// says so in [`Log::cut_short`].
///
/// The file is at most [`MAX_LOG_BYTES`] and each record at most [`MAX_LOG_LINE_BYTES`] (its
/// NDJSON line's bound), checked before more of it is read.
pub fn read(path: &Path) -> anyhow::Result<Log> {
    read_with_limits(path, MAX_LOG_BYTES, MAX_LOG_LINE_BYTES)
}

/// A channel of a file being read.
struct Channel {
    topic: String,
    encoding: String,
    /// `None`: a topic not ours, skipped.
    kind: Option<Kind>,
}

/// [`read`] with a file of at most `max_file` bytes and messages of at most `max_message`.
fn read_with_limits(path: &Path, max_file: u64, max_message: usize) -> anyhow::Result<Log> {
    let name = path.display().to_string();
    let file = File::open(path).with_context(|| format!("cannot open the mission log {name}"))?;
    let size = file
        .metadata()
        .with_context(|| format!("cannot read {name}"))?
        .len();
    if size > max_file {
        return Err(over_size(&name, size, max_file));
    }
    read_stream(&name, file, max_file, max_message)
}

fn over_size(name: &str, size: u64, max_file: u64) -> anyhow::Error {
    anyhow::anyhow!(
        "{name}: {size} bytes or more, over the limit of {max_file} bytes for an MCAP mission log (limits::MAX_LOG_BYTES)"
    )
}

/// [`read_with_limits`] of the file `name` open as `input`.
fn read_stream(
    name: &str,
    input: impl Read,
    max_file: u64,
    max_message: usize,
) -> anyhow::Result<Log> {
    // A device or a growing file may say less than it holds: the count of bytes read is checked too.
    let mut file = input.take(max_file + 1);
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default().with_record_length_limit(max_message + RECORD_OVERHEAD),
    );
    let mut channels: BTreeMap<u16, Channel> = BTreeMap::new();
    let mut records = Vec::new();
    let mut messages = 0usize;
    let mut cut_short = None;
    // Bytes read from the file, and bytes of the records yielded (the magic's 8 first).
    let (mut fed, mut consumed) = (0u64, MAGIC.len() as u64);
    while let Some(event) = reader.next_event() {
        match event {
            Ok(LinearReadEvent::ReadRequest(need)) => {
                let n = file
                    .read(reader.insert(need))
                    .with_context(|| format!("cannot read {name}"))?;
                reader.notify_read(n);
                fed += n as u64;
                if fed > max_file {
                    return Err(over_size(name, fed, max_file));
                }
            }
            Ok(LinearReadEvent::Record { opcode, data }) => {
                consumed += 9 + data.len() as u64;
                if opcode == op::DATA_END {
                    // The data section is whole; the summary is an index replay does not need.
                    break;
                }
                let record = ::mcap::parse_record(opcode, data).map_err(|e| {
                    anyhow::anyhow!("{name}: a bad record after message {messages}: {e}")
                })?;
                match record {
                    McapRecord::Channel(c) => {
                        channels.insert(
                            c.id,
                            Channel {
                                kind: Kind::of_topic(&c.topic),
                                topic: c.topic,
                                encoding: c.message_encoding,
                            },
                        );
                    }
                    McapRecord::Message { header, data } => {
                        messages += 1;
                        let Some(c) = channels.get(&header.channel_id) else {
                            anyhow::bail!(
                                "{name}: message {messages} is on channel {}, which no channel record declares",
                                header.channel_id
                            );
                        };
                        let Some(kind) = c.kind else { continue };
                        if c.encoding != MESSAGE_ENCODING {
                            anyhow::bail!(
                                "{name}: message {messages} on {} is encoded {:?}, not {MESSAGE_ENCODING:?}",
                                c.topic,
                                c.encoding
                            );
                        }
                        if data.len() > max_message {
                            anyhow::bail!(
                                "{name}: message {messages} on {} is {} bytes, over the limit of {max_message} bytes (limits::MAX_LOG_LINE_BYTES)",
                                c.topic,
                                data.len()
                            );
                        }
                        let r = channels::record(kind, &c.topic, &data).map_err(|e| {
                            anyhow::anyhow!(
                                "{name}: message {messages} on {} is not a mission-log {} record: {e}",
                                c.topic,
                                kind.name()
                            )
                        })?;
                        records.push(r);
                    }
                    _ => {}
                }
            }
            Err(McapError::UnexpectedEof) => {
                // A killed run: the data section never ended. A record it was writing is left out.
                if fed > consumed {
                    cut_short = Some(CutShort::AfterMessage(messages));
                }
                break;
            }
            Err(McapError::BadMagic) => {
                anyhow::bail!("{name}: not an MCAP file (it does not start with the MCAP magic)")
            }
            Err(McapError::RecordTooLarge { opcode, len }) => anyhow::bail!(
                "{name}: a record (opcode {opcode:#04x}) of {len} bytes after message {messages}, over the limit of {max_message} bytes for one message (limits::MAX_LOG_LINE_BYTES): not a mission log"
            ),
            Err(e) => anyhow::bail!("{name}: not a readable MCAP file after message {messages}: {e}"),
        }
    }
    match records.first() {
        Some(Record::Start(_)) => Ok(Log { records, cut_short }),
        _ => anyhow::bail!(
            "{name}: a mission log starts with a message on /shoal/start; this one does not"
        ),
    }
}

#[cfg(test)]
mod tests;
