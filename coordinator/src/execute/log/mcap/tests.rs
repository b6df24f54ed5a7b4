use std::collections::BTreeSet;
use std::path::Path;

use shoal_common::execution::{VehicleState, VehicleStatus};
use shoal_common::scenario::{Obstacle, ObstacleKind, Scenario};
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::open::{MissionEvent, PlanNotice, Telemetry};

use super::super::ndjson::{self, NdjsonWriter};
use super::*;
use crate::execute::fleet::Fleet;

const SCENARIO: &str = include_str!("../../../../../scenarios/amp-pso-1.toml");
/// Mission time 0 of the sample log, Unix milliseconds.
const EPOCH_MS: u64 = 1_700_000_000_000;

fn report(vehicle: &str, seq: u64, t_s: f64, position: [f64; 3]) -> Record {
    // Received 2 wall seconds after the fix is for (time scale 10: 20 mission seconds).
    let received = EPOCH_MS * 1000 + (t_s / 10.0 * 1e6) as u64 + 2_000_000;
    Record::Telemetry {
        received_unix_us: received,
        telemetry: Telemetry {
            version: 1,
            mission: "m".into(),
            vehicle: vehicle.into(),
            seq,
            revision: 0,
            sent_unix_us: received - 1000,
            state: VehicleState {
                t_s,
                position,
                velocity: [1.0, 0.0, 0.0],
                heading_deg: 0.0,
                depth_m: Some(12.5),
                altitude_m: None,
                battery: 0.9,
                status: VehicleStatus::Underway,
                arrived_s: None,
            },
            command: None,
        },
    }
}

/// A log of every kind of record, the plan's trajectories long enough to make the plan the
/// largest message.
fn sample() -> anyhow::Result<Vec<Record>> {
    sample_of(200)
}

/// [`sample`] with `n` points per trajectory.
fn sample_of(n: usize) -> anyhow::Result<Vec<Record>> {
    let scenario = Scenario::parse(SCENARIO, Path::new("amp-pso-1.toml"))?;
    let ids: Vec<String> = scenario.vehicles.iter().map(|v| v.id.clone()).collect();
    let samples: Vec<[f64; 4]> = (0..n)
        .map(|k| [k as f64 * 5.0, k as f64, 2.0 * k as f64, 30.0])
        .collect();
    let plans: Vec<Trajectory> = ids
        .iter()
        .map(|_| Trajectory::from_samples(&samples))
        .collect();
    let fleet = Fleet::new(&ids, &plans, scenario.fleet.d_min_m, 180.0);
    Ok(vec![
        Record::Start(Start {
            mission: "m".into(),
            scenario_toml: SCENARIO.into(),
            common_arrival_s: 1000.0,
            arrival_window_s: 30.0,
            horizon_s: 180.0,
            time_scale: 10.0,
            epoch_unix_ms: EPOCH_MS,
        }),
        Record::Plan(PlanNotice {
            version: 1,
            mission: "m".into(),
            revision: 0,
            changed: ids.clone(),
            trajectories: ids.iter().map(|id| (id.clone(), samples.clone())).collect(),
        }),
        report(&ids[0], 0, 10.0, [1.0, 2.0, 3.0]),
        report(&ids[1], 0, 10.5, [4.0, 5.0, 6.0]),
        Record::Event(MissionEvent {
            version: 1,
            mission: "m".into(),
            t_s: 42.0,
            kind: "hold".into(),
            vehicles: vec![ids[0].clone()],
            detail: "because".into(),
        }),
        Record::Obstacle(Obstacle {
            id: "new1".into(),
            kind: ObstacleKind::Hard,
            centre: [10.0, 20.0, 30.0],
            radius_m: 5.0,
            inflation_m: 2.0,
        }),
        report(&ids[0], 1, 60.0, [7.0, 8.0, 9.0]),
        Record::End(fleet.figures_for(&scenario, 1000.0, 30.0)),
    ])
}

fn error_of(r: anyhow::Result<Log>) -> String {
    r.err().map(|e| format!("{e:#}")).unwrap_or_default()
}

/// NDJSON → MCAP (`export`) → records: the same records; `run`'s writer makes the same bytes,
/// with one channel per kind and per reporting vehicle, each with a JSON Schema, and mission
/// time as log time.
#[test]
fn an_ndjson_log_converted_to_mcap_reads_back_the_same() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let records = sample()?;
    let ndjson_path = dir.path().join("mission.ndjson");
    let mut w = NdjsonWriter::create(&ndjson_path)?;
    for r in &records {
        w.write(r);
    }
    w.flush();
    let from_ndjson = ndjson::read(&ndjson_path)?.records;
    assert_eq!(from_ndjson, records);
    let exported = dir.path().join("exported.mcap");
    write_all(&exported, &from_ndjson)?;
    let back = read(&exported)?;
    assert_eq!((back.records, back.cut_short), (records.clone(), None));

    // What `run` writes: the NDJSON log and the MCAP one beside it, byte for byte the export.
    let live = dir.path().join("live.ndjson");
    let mut both = crate::execute::log::LogWriter::create(&live)?;
    for r in &records {
        both.write(r);
    }
    both.finish();
    let live_mcap = crate::execute::log::mcap_path(&live);
    assert_eq!(live_mcap, dir.path().join("live.mcap"));
    let bytes = std::fs::read(&live_mcap)?;
    assert_eq!(bytes, std::fs::read(&exported)?);
    assert!(bytes.starts_with(MAGIC));
    assert!(crate::execute::log::is_mcap(&live_mcap)? && !crate::execute::log::is_mcap(&live)?);
    assert_eq!(crate::execute::log::read(&live_mcap)?.records, records);

    // Read with the crate's own reader: topics, schemas, log times.
    let mut topics = BTreeSet::new();
    let mut log_times = Vec::new();
    for m in ::mcap::MessageStream::new(&bytes)? {
        let m = m?;
        let schema = m.channel.schema.clone();
        let Some(schema) = schema else {
            anyhow::bail!("{} has no schema", m.channel.topic);
        };
        assert_eq!(
            (
                schema.encoding.as_str(),
                m.channel.message_encoding.as_str()
            ),
            ("jsonschema", "json")
        );
        let schema: serde_json::Value = serde_json::from_slice(&schema.data)?;
        assert!(schema["$schema"]
            .as_str()
            .is_some_and(|s| s.contains("json-schema.org")));
        topics.insert(m.channel.topic.clone());
        log_times.push((m.log_time, m.publish_time));
    }
    let expected: BTreeSet<String> = [
        "/shoal/start",
        "/shoal/plan",
        "/shoal/telemetry/auv1",
        "/shoal/telemetry/auv2",
        "/shoal/event",
        "/shoal/obstacle",
        "/shoal/end",
    ]
    .into_iter()
    .map(String::from)
    .collect();
    assert_eq!(topics, expected);
    // Reports: received 20 mission seconds after their fix, sent 10 ms (mission) before that.
    let s = 1_000_000_000;
    assert_eq!(
        log_times,
        vec![
            (0, 0),
            (0, 0),
            (30 * s, 30 * s - 10_000_000),
            (30 * s + s / 2, 30 * s + s / 2 - 10_000_000),
            (42 * s, 42 * s),
            (42 * s, 42 * s),
            (80 * s, 80 * s - 10_000_000),
            (80 * s, 80 * s),
        ]
    );
    Ok(())
}

/// Every prefix of a log left by a killed run (no summary, no footer) reads as the records
/// whole in it; one cut inside a record says so.
#[test]
fn a_truncated_mcap_gives_the_records_before_the_cut() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    // Short trajectories: the file is read once per length.
    let records = sample_of(3)?;
    let path = dir.path().join("m.mcap");
    let mut w = McapWriter::create(&path)?;
    for r in &records {
        w.write(r);
    }
    w.flush();
    // Not finished: what a killed run leaves after its last flush.
    let whole = std::fs::read(&path)?;
    drop(w);
    let mut seen = BTreeSet::new();
    for len in MAGIC.len()..=whole.len() {
        let cut = &whole[..len];
        match read_stream("cut.mcap", cut, MAX_LOG_BYTES, MAX_LOG_LINE_BYTES) {
            Ok(log) => {
                let n = log.records.len();
                assert_eq!(log.records[..], records[..n], "cut at {len}");
                if let Some(CutShort::AfterMessage(m)) = log.cut_short {
                    assert_eq!(m, n, "cut at {len}");
                }
                seen.insert((n, log.cut_short.is_some()));
            }
            Err(e) => {
                let e = format!("{e:#}");
                assert!(
                    e.contains("starts with a message on /shoal/start"),
                    "cut at {len}: {e}"
                );
                assert!(e.contains("cut.mcap"), "{e}");
            }
        }
    }
    // Every number of records, each both cut mid-record and at a record's end (the last:
    // the whole file, no cut).
    for n in 1..records.len() {
        assert!(
            seen.contains(&(n, true)) && seen.contains(&(n, false)),
            "{n}: {seen:?}"
        );
    }
    assert!(seen.contains(&(records.len(), false)));
    // The same from a file.
    let cut_path = dir.path().join("cut.mcap");
    std::fs::write(&cut_path, &whole[..whole.len() - 3])?;
    let log = read(&cut_path)?;
    assert_eq!(
        (log.records.len(), log.cut_short),
        (
            records.len() - 1,
            Some(CutShort::AfterMessage(records.len() - 1))
        )
    );
    Ok(())
}

/// Not MCAP, corrupt, or a message that is not its channel's record: an error naming the file
/// and what is wrong.
#[test]
fn a_file_that_is_not_a_mission_mcap_is_named() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let records = sample()?;
    let path = dir.path().join("m.mcap");
    write_all(&path, &records)?;
    let whole = std::fs::read(&path)?;

    let text = dir.path().join("text.mcap");
    std::fs::write(&text, "{\"record\":\"start\"}\n")?;
    let e = error_of(read(&text));
    assert!(e.contains("text.mcap: not an MCAP file"), "{e}");
    // By its content, not its name: the NDJSON reader takes it (and says what is wrong).
    let e = error_of(crate::execute::log::read(&text));
    assert!(
        e.contains("text.mcap line 1: not a mission-log record"),
        "{e}"
    );

    // The event's kind spelled as a number: valid JSON, not an event.
    let at = find(&whole, b"\"kind\":\"hold\"")?;
    let mut bad = whole.clone();
    bad[at + 8..at + 14].copy_from_slice(b"123456");
    let corrupt = dir.path().join("corrupt.mcap");
    std::fs::write(&corrupt, &bad)?;
    let e = error_of(read(&corrupt));
    assert!(
        e.contains("corrupt.mcap: message 5 on /shoal/event is not a mission-log event record"),
        "{e}"
    );

    // A report of auv1 on auv2's topic.
    let at = find(&whole, b"/shoal/telemetry/auv2")?;
    let mut bad = whole.clone();
    bad[at + 20] = b'1';
    std::fs::write(&corrupt, &bad)?;
    let e = error_of(read(&corrupt));
    assert!(e.contains("message 4 on /shoal/telemetry/auv1"), "{e}");

    // A record length running past any sane size.
    let mut bad = whole;
    let first = MAGIC.len() + 1;
    bad[first..first + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    std::fs::write(&corrupt, &bad)?;
    let e = error_of(read(&corrupt));
    assert!(e.contains("corrupt.mcap: a record (opcode 0x01)"), "{e}");
    Ok(())
}

/// The file and each message have upper bounds, checked before more is read.
#[test]
fn an_mcap_over_the_limits_is_refused_with_the_limit() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let records = sample()?;
    let path = dir.path().join("m.mcap");
    write_all(&path, &records)?;
    let size = std::fs::metadata(&path)?.len();
    assert!(read_with_limits(&path, size, MAX_LOG_LINE_BYTES).is_ok());
    let e = error_of(read_with_limits(&path, size - 1, MAX_LOG_LINE_BYTES));
    assert!(
        e.contains("m.mcap") && e.contains(&format!("limit of {} bytes", size - 1)),
        "{e}"
    );
    // The plan is the largest message; the start record (the scenario) the next.
    let plan = channels::message(&records[1])?.len();
    let start = channels::message(&records[0])?.len();
    assert!(plan > start + RECORD_OVERHEAD);
    assert!(read_with_limits(&path, size, plan).is_ok());
    let e = error_of(read_with_limits(&path, size, plan - 1));
    assert!(
        e.contains("message 2 on /shoal/plan")
            && e.contains(&format!("over the limit of {} bytes", plan - 1)),
        "{e}"
    );
    // Under the record bound, the reader stops before loading the record.
    let e = error_of(read_with_limits(&path, size, plan - RECORD_OVERHEAD - 100));
    assert!(
        e.contains("after message 1") && e.contains("MAX_LOG_LINE_BYTES"),
        "{e}"
    );
    Ok(())
}

fn find(haystack: &[u8], needle: &[u8]) -> anyhow::Result<usize> {
    haystack
        .windows(needle.len())
        .position(|w| w == needle)
        .ok_or_else(|| anyhow::anyhow!("{} not found", String::from_utf8_lossy(needle)))
}
