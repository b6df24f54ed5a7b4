//! The execution loop driven against a link that records what it is asked (and can fail).

use super::*;
use crate::link::{CommandSerial, LinkError, LinkOutcome};
use shoal_common::execution::VehicleState;
use shoal_common::geometry::Vec3;
use std::sync::mpsc;
use std::sync::{Arc, Mutex};

/// A link that records what it is asked.
#[derive(Clone, Default)]
struct Recorder {
    calls: Arc<Mutex<Vec<String>>>,
    confirmed: Arc<Mutex<usize>>,
    /// Every hold fails to reach the vehicle.
    holds_fail: bool,
    /// The vehicle has no position fix: it reports no state.
    no_fix: bool,
    /// An update's upload (not the mission's first) is confirmed only once another command
    /// was given after it, as over a link whose vehicle answers after the agent's next order.
    uploads_answer_late: bool,
    /// The serials of the commands the vehicle gives up (the others it confirms).
    gives_up: Vec<CommandSerial>,
    /// The serials of the commands never answered, as over a link that loses an answer.
    silent: Vec<CommandSerial>,
}

impl Recorder {
    /// Records a command given; its serial (the commands given so far).
    fn record(&self, call: String) -> Result<CommandSerial, LinkError> {
        let mut calls = self
            .calls
            .lock()
            .map_err(|e| LinkError::Io(e.to_string()))?;
        calls.push(call);
        Ok(calls.len() as CommandSerial)
    }
}

impl VehicleLink for Recorder {
    fn name(&self) -> String {
        "recorder".into()
    }
    fn upload(&mut self, plan: &Trajectory) -> Result<CommandSerial, LinkError> {
        self.record(format!("upload {}", plan.times.len()))
    }
    fn state(&mut self, now: f64) -> Result<VehicleState, LinkError> {
        if self.no_fix {
            return Err(LinkError::Io("no position fix yet".into()));
        }
        Ok(VehicleState {
            t_s: now,
            position: [0.0; 3],
            velocity: [0.0; 3],
            heading_deg: 0.0,
            depth_m: None,
            altitude_m: None,
            battery: 1.0,
            status: VehicleStatus::Underway,
            arrived_s: None,
        })
    }
    fn hold(&mut self, _now: f64) -> Result<CommandSerial, LinkError> {
        if self.holds_fail {
            return Err(LinkError::Io("link down".into()));
        }
        self.record("hold".into())
    }
    fn stop(&mut self) -> Result<CommandSerial, LinkError> {
        self.record("stop".into())
    }
    /// Every command answered at once, as a simulator does (an update's upload, with
    /// `uploads_answer_late`, only once a command follows it), in the order given.
    fn outcomes(&mut self) -> Vec<LinkOutcome> {
        let mut calls = self.calls.lock().map(|c| c.clone()).unwrap_or_default();
        let update_last = calls.len() > 1 && calls.last().is_some_and(|c| c.starts_with("upload"));
        if self.uploads_answer_late && update_last {
            calls.pop();
        }
        let mut seen = self.confirmed.lock().map(|n| *n).unwrap_or(0);
        let done = calls
            .iter()
            .enumerate()
            .skip(seen)
            .filter(|(k, _)| !self.silent.contains(&(*k as CommandSerial + 1)))
            .map(|(k, c)| {
                let command = match c.as_str() {
                    "hold" => VehicleCommand::Hold,
                    "stop" => VehicleCommand::Stop,
                    _ => VehicleCommand::Upload,
                };
                let serial = k as CommandSerial + 1;
                let mut outcome = LinkOutcome::confirmed(serial, command, c.clone());
                if self.gives_up.contains(&serial) {
                    outcome.state = CommandState::GaveUp;
                }
                outcome
            })
            .collect();
        seen = calls.len();
        if let Ok(mut n) = self.confirmed.lock() {
            *n = seen;
        }
        done
    }
}

fn scenario_toml() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/amp-pso-1.toml"
    ))
    .unwrap_or_default()
}

fn wire(samples: Vec<[f64; 4]>) -> WireTrajectory {
    WireTrajectory {
        vehicle: "auv1".into(),
        samples,
    }
}

#[test]
fn bad_orders_are_refused_with_the_reason() {
    let ok = wire(vec![[0.0, 1.0, 2.0, 3.0], [10.0, 4.0, 5.0, 6.0]]);
    let s = scenario_toml();
    assert!(Order::new("m", "auv1", &s, &ok, 0, 50.0, 2.0, 1).is_ok());
    let e = |r: Result<Order, Unusable>| r.err().map(|e| e.to_string()).unwrap_or_default();
    assert!(e(Order::new("m", "auv9", &s, &ok, 0, 50.0, 2.0, 1)).contains("no vehicle \"auv9\""));
    assert!(e(Order::new("m", "auv1", &s, &ok, 0, 0.0, 2.0, 1)).contains("time scale 0"));
    assert!(e(Order::new("m", "auv1", &s, &ok, 0, 1.0, 500.0, 1)).contains("telemetry rate 500"));
    let backwards = wire(vec![[10.0, 1.0, 2.0, 3.0], [0.0, 4.0, 5.0, 6.0]]);
    assert!(
        e(Order::new("m", "auv1", &s, &backwards, 0, 1.0, 2.0, 1)).contains("not timed in order")
    );
    let nan = wire(vec![[0.0, f64::NAN, 2.0, 3.0]]);
    assert!(e(Order::new("m", "auv1", &s, &nan, 0, 1.0, 2.0, 1)).contains("not finite"));
}

#[test]
fn the_mission_clock_runs_scaled_from_its_epoch() {
    let now_ms = unix_us() / 1000;
    let c = MissionClock {
        epoch_unix_ms: now_ms - 2000,
        scale: 50.0,
    };
    // 2 s of wall time at 50×: about 100 s (the test itself takes a little).
    let t = c.now();
    assert!((100.0..110.0).contains(&t), "{t}");
    let future = MissionClock {
        epoch_unix_ms: now_ms + 60_000,
        scale: 50.0,
    };
    assert_eq!(future.now(), 0.0);
}

/// A two-sample order for auv1 starting now, in real time, reported at 50 Hz.
fn order_now() -> Order {
    let order = Order::new(
        "m",
        "auv1",
        &scenario_toml(),
        &wire(vec![[0.0, 1.0, 2.0, 3.0], [10.0, 4.0, 5.0, 6.0]]),
        unix_us() / 1000,
        1.0,
        50.0,
        1,
    );
    let Ok(order) = order else {
        panic!("{order:?}")
    };
    order
}

/// The coordinator's hold for auv1.
fn hold() -> CoordinatorToAgent {
    CoordinatorToAgent::Hold {
        mission: "m".into(),
        vehicle: "auv1".into(),
        reason: "test".into(),
    }
}

/// Runs [`order_now`] on `link` with `messages` already waiting, then the coordinator's stop,
/// checks that the mission ended on that stop, and returns every report sent.
fn run_to_the_stop(link: &mut Recorder, messages: Vec<CoordinatorToAgent>) -> Vec<Telemetry> {
    let (tx, rx) = mpsc::channel();
    for m in messages {
        let _ = tx.send(m);
    }
    let _ = tx.send(CoordinatorToAgent::Stop {
        mission: "m".into(),
        reason: "done".into(),
    });
    let sent = Mutex::new(Vec::<Telemetry>::new());
    let publish = |t: &Telemetry| {
        if let Ok(mut v) = sent.lock() {
            v.push(t.clone());
        }
    };
    let stop = AtomicBool::new(false);
    let report = run(
        order_now(),
        link,
        &rx,
        &publish,
        &stop,
        Duration::from_secs(30),
    );
    assert_eq!(report.outcome, "stopped: done");
    let reports = sent.lock().map(|s| s.clone()).unwrap_or_default();
    reports
}

#[test]
fn a_hold_the_link_cannot_give_is_reported_given_up_at_once() {
    let mut link = Recorder {
        holds_fail: true,
        ..Recorder::default()
    };
    let sent = run_to_the_stop(&mut link, vec![hold()]);
    let hold = sent
        .iter()
        .filter_map(|t| t.command.as_ref())
        .find(|c| c.command == VehicleCommand::Hold);
    let Some(hold) = hold else {
        panic!("no report carries the hold: {sent:?}")
    };
    assert_eq!(hold.state, CommandState::GaveUp, "{hold:?}");
    assert!(hold.detail.contains("link down"), "{hold:?}");
}

#[test]
fn reports_flow_updates_load_holds_hold_and_stop_ends() {
    let order = order_now();
    let mut link = Recorder::default();
    let calls = Arc::clone(&link.calls);
    let (tx, rx) = mpsc::channel();
    let sent = Arc::new(Mutex::new(Vec::<Telemetry>::new()));
    let out = Arc::clone(&sent);
    let stop = AtomicBool::new(false);
    let feeder = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(150));
        let traj = Trajectory {
            times: vec![5.0, 20.0, 30.0],
            points: vec![Vec3::zeros(); 3],
        };
        let _ = tx.send(CoordinatorToAgent::Update {
            mission: "m".into(),
            vehicle: "auv1".into(),
            revision: 2,
            trajectory: WireTrajectory::new("auv1", &traj),
        });
        // A stale revision is ignored.
        let _ = tx.send(CoordinatorToAgent::Update {
            mission: "m".into(),
            vehicle: "auv1".into(),
            revision: 1,
            trajectory: WireTrajectory::new("auv1", &traj),
        });
        std::thread::sleep(Duration::from_millis(150));
        let _ = tx.send(CoordinatorToAgent::Hold {
            mission: "m".into(),
            vehicle: "auv1".into(),
            reason: "test".into(),
        });
        std::thread::sleep(Duration::from_millis(150));
        let _ = tx.send(CoordinatorToAgent::Stop {
            mission: "m".into(),
            reason: "done".into(),
        });
    });
    let report = run(
        order,
        &mut link,
        &rx,
        &|t| {
            if let Ok(mut v) = out.lock() {
                v.push(t.clone());
            }
        },
        &stop,
        Duration::from_secs(30),
    );
    let _ = feeder.join();
    assert_eq!(report.outcome, "stopped: done");
    let calls = calls.lock().map(|c| c.clone()).unwrap_or_default();
    assert_eq!(calls, ["upload 2", "upload 3", "hold", "stop"]);
    let sent = sent.lock().map(|s| s.clone()).unwrap_or_default();
    // 50 Hz for about 0.45 s.
    assert!(sent.len() >= 10, "{} reports", sent.len());
    assert!(sent.windows(2).all(|w| w[1].seq == w[0].seq + 1));
    assert_eq!(sent.first().map(|t| t.revision), Some(0));
    assert_eq!(sent.last().map(|t| t.revision), Some(2));
    assert_eq!(report.iterations as usize, sent.len());
}

#[test]
fn a_plan_confirmed_after_a_later_hold_is_the_revision_reported() {
    let mut link = Recorder {
        uploads_answer_late: true,
        ..Recorder::default()
    };
    let traj = Trajectory {
        times: vec![5.0, 20.0],
        points: vec![Vec3::zeros(); 2],
    };
    let update = CoordinatorToAgent::Update {
        mission: "m".into(),
        vehicle: "auv1".into(),
        revision: 3,
        trajectory: WireTrajectory::new("auv1", &traj),
    };
    let sent = run_to_the_stop(&mut link, vec![update, hold()]);
    // The upload's answer came after the hold was given: the hold is what the reports carry,
    // and from then on the revision is the uploaded plan's.
    let held = sent.iter().find(|t| {
        t.command.as_ref().is_some_and(|c| {
            c.command == VehicleCommand::Hold && c.state == CommandState::Confirmed
        })
    });
    let Some(held) = held else {
        panic!("no report confirms the hold: {sent:?}")
    };
    assert_eq!(held.revision, 3, "{held:?}");
    assert_eq!(sent.last().map(|t| t.revision), Some(3));
}

/// An update of auv1's plan to `revision`.
fn update(revision: u32) -> CoordinatorToAgent {
    let traj = Trajectory {
        times: vec![5.0, 20.0],
        points: vec![Vec3::zeros(); 2],
    };
    CoordinatorToAgent::Update {
        mission: "m".into(),
        vehicle: "auv1".into(),
        revision,
        trajectory: WireTrajectory::new("auv1", &traj),
    }
}

/// Updates 3 and 4 at once, then the stop: every report, and the revisions they carry.
fn updates_3_and_4(link: &mut Recorder) -> (Vec<Telemetry>, Vec<u32>) {
    let sent = run_to_the_stop(link, vec![update(3), update(4)]);
    let revisions = sent.iter().map(|t| t.revision).collect();
    (sent, revisions)
}

#[test]
fn of_two_quick_updates_the_first_answered_is_the_revision_reported() {
    // Updates 3 and 4 come at once; the vehicle answers the upload of 3 only once 4 is given,
    // and the upload of 4 only once the stop is: the reports go 0, 3, 4, and 4 only with the
    // stop (the answer to the upload of 3 is not the vehicle taking 4).
    let mut link = Recorder {
        uploads_answer_late: true,
        ..Recorder::default()
    };
    let (sent, revisions) = updates_3_and_4(&mut link);
    assert!(revisions.windows(2).all(|w| w[0] <= w[1]), "{revisions:?}");
    assert!(revisions.contains(&3), "{revisions:?}");
    let first_4 = sent.iter().find(|t| t.revision == 4);
    let stop_given = first_4
        .and_then(|t| t.command.as_ref())
        .is_some_and(|c| c.command == VehicleCommand::Stop);
    assert!(stop_given, "{sent:?}");
}

#[test]
fn an_update_the_vehicle_gives_up_leaves_the_revision_it_confirmed() {
    // As above, but the vehicle gives up the upload of 4 (the link's third command): it
    // drives 3, and the reports never say 4.
    let mut link = Recorder {
        uploads_answer_late: true,
        gives_up: vec![3],
        ..Recorder::default()
    };
    let (_, revisions) = updates_3_and_4(&mut link);
    assert_eq!(revisions.last(), Some(&3), "{revisions:?}");
    assert!(!revisions.contains(&4), "{revisions:?}");
}

#[test]
fn an_upload_never_answered_is_passed_over_by_the_next_one_answered() {
    // The upload of 3 (the link's second command) is never answered (a link that loses it); the
    // upload of 4 is confirmed: the reports go from 0 to 4 and never say 3.
    let mut link = Recorder {
        silent: vec![2],
        ..Recorder::default()
    };
    let (_, revisions) = updates_3_and_4(&mut link);
    assert_eq!(revisions.last(), Some(&4), "{revisions:?}");
    assert!(!revisions.contains(&3), "{revisions:?}");
}

/// The commands `link` was given for `messages`, then the stop.
fn given(mut link: Recorder, messages: Vec<CoordinatorToAgent>) -> Vec<String> {
    let calls = Arc::clone(&link.calls);
    run_to_the_stop(&mut link, messages);
    let given = calls.lock().map(|c| c.clone()).unwrap_or_default();
    given
}

#[test]
fn a_hold_repeated_before_the_first_fix_is_given_once() {
    // The coordinator repeats a hold every second until the vehicle's first report, which a
    // MAVLink vehicle sends only once it has a fix: the vehicle confirmed the first hold, so
    // the repeats are not given (nor is the hold after an update, twice).
    let no_fix = || Recorder {
        no_fix: true,
        ..Recorder::default()
    };
    assert_eq!(
        given(no_fix(), vec![hold(), hold(), hold()]),
        ["upload 2", "hold", "stop"]
    );
    assert_eq!(
        given(no_fix(), vec![hold(), update(3), hold(), hold()]),
        ["upload 2", "hold", "upload 2", "hold", "stop"]
    );
}

#[test]
fn a_repeated_hold_is_given_again_to_a_vehicle_that_moves_or_gave_it_up() {
    // This vehicle reports itself under way although it confirmed the hold.
    assert_eq!(
        given(Recorder::default(), vec![hold(), hold()]),
        ["upload 2", "hold", "hold", "stop"]
    );
    // The first hold (the link's second command) was given up.
    let gave_up = Recorder {
        no_fix: true,
        gives_up: vec![2],
        ..Recorder::default()
    };
    assert_eq!(
        given(gave_up, vec![hold(), hold()]),
        ["upload 2", "hold", "hold", "stop"]
    );
}
