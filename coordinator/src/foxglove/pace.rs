//! A finished mission log played into a live feed at its recorded pace (or faster, or slower),
//! so `replay --foxglove` shows a past mission as `run --foxglove` showed it live. Each record
//! comes when it came in the run: a report when it was received, an event at its `t_s`, and a
//! plan, an obstacle or the end with the record before it; the mission clock runs at the log's
//! time scale times the speed. The log has no status records: they are rebuilt as the run
//! published them ([`Statuses`]), one per wall second of the run and one at its end.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use crate::execute::live::{LiveFeed, LiveMessage};
use crate::execute::log::channels::mission_s;
use crate::execute::log::{Record, Start};
use crate::execute::replayed::Statuses;

/// Fastest and slowest `--speed`: past a million times real time a whole mission is one burst,
/// below a thousandth one report an hour.
pub const SPEED_RANGE: std::ops::RangeInclusive<f64> = 0.001..=1_000_000.0;
/// How often a wait looks at the stop flag.
const STOP_POLL: Duration = Duration::from_millis(100);

/// Checks a `--speed` factor: within [`SPEED_RANGE`].
pub fn check_speed(speed: f64) -> anyhow::Result<f64> {
    if speed.is_finite() && SPEED_RANGE.contains(&speed) {
        return Ok(speed);
    }
    anyhow::bail!(
        "--speed {speed}: must be a factor from {} to {}",
        SPEED_RANGE.start(),
        SPEED_RANGE.end()
    )
}

/// Mission seconds of `r`, or `None` for a record that comes with the one before it.
fn mission_time(start: &Start, r: &Record) -> Option<f64> {
    match r {
        Record::Start(_) => Some(0.0),
        Record::Telemetry {
            received_unix_us, ..
        } => Some(mission_s(start, *received_unix_us)),
        Record::Event(e) => Some(e.t_s),
        Record::Plan(_) | Record::Obstacle(_) | Record::End(_) => None,
    }
}

/// Plays `records` (a log that starts with its start record) into `feed`, `speed` times the
/// log's own pace, with the statuses `statuses` rebuilds; returns false when `stop` cut it
/// short.
pub fn play(
    records: &[Record],
    mut statuses: Option<Statuses>,
    feed: &LiveFeed,
    speed: f64,
    stop: &AtomicBool,
) -> bool {
    let Some(Record::Start(start)) = records.first() else {
        return true;
    };
    // Wall seconds per mission second.
    let rate = 1.0 / (start.time_scale.max(f64::MIN_POSITIVE) * speed);
    let begun = Instant::now();
    let mut latest = 0.0f64;
    for r in records {
        if let Some(t) = mission_time(start, r) {
            // Times run a little backwards between neighbours: never wait for the past.
            latest = latest.max(t);
        }
        let due = begun + Duration::try_from_secs_f64(latest * rate).unwrap_or(Duration::MAX);
        if !wait_until(due, stop) {
            return false;
        }
        feed.publish(LiveMessage::Record(r.clone()));
        if let Some(status) = statuses.as_mut().and_then(|s| s.apply(r)) {
            feed.publish(LiveMessage::Status(status));
        }
    }
    true
}

/// Sleeps until `due`; false when `stop` was set first.
fn wait_until(due: Instant, stop: &AtomicBool) -> bool {
    loop {
        if stop.load(Ordering::Relaxed) {
            return false;
        }
        let now = Instant::now();
        if now >= due {
            return true;
        }
        std::thread::sleep((due - now).min(STOP_POLL));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::wire::open::{MissionEvent, OPEN_VERSION};

    fn log(time_scale: f64) -> Vec<Record> {
        let event = |t_s: f64| {
            Record::Event(MissionEvent {
                version: OPEN_VERSION,
                mission: "m".into(),
                t_s,
                kind: "hold".into(),
                vehicles: vec![],
                detail: String::new(),
            })
        };
        vec![
            Record::Start(Start {
                mission: "m".into(),
                scenario_toml: String::new(),
                common_arrival_s: 1.0,
                arrival_window_s: 1.0,
                horizon_s: 1.0,
                time_scale,
                epoch_unix_ms: 0,
            }),
            event(10.0),
            event(5.0),
            event(40.0),
        ]
    }

    #[test]
    fn a_log_plays_at_its_pace_times_the_speed_and_in_order() {
        let feed = LiveFeed::new();
        let sub = feed.subscribe();
        let t0 = Instant::now();
        // 40 mission seconds at 100× real time, twice as fast: 0.2 s.
        assert!(play(&log(100.0), None, &feed, 2.0, &AtomicBool::new(false)));
        let took = t0.elapsed();
        assert!(took >= Duration::from_millis(195), "{took:?}");
        assert!(took < Duration::from_secs(2), "{took:?}");
        let got: Vec<LiveMessage> = sub.messages.try_iter().map(|m| (*m).clone()).collect();
        let want: Vec<LiveMessage> = log(100.0).into_iter().map(LiveMessage::Record).collect();
        assert_eq!(got, want);
    }

    #[test]
    fn a_stop_cuts_the_play_short_and_speeds_are_bounded() {
        let feed = LiveFeed::new();
        assert!(!play(&log(0.001), None, &feed, 1.0, &AtomicBool::new(true)));
        assert!(check_speed(1.0).is_ok());
        for bad in [0.0, -1.0, f64::NAN, 1e7] {
            let e = check_speed(bad)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(e.contains("--speed"), "{bad}: {e}");
        }
    }
}
