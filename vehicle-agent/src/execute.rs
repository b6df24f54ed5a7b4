//! One execution in an agent: the vehicle drives its timed trajectory through its
//! [`VehicleLink`], and the agent reports its state at the telemetry rate. Replans (`Update`),
//! holds and the stop arrive on a channel; reports leave through a closure, so this loop knows
//! nothing of Zenoh.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use shoal_common::execution::{
    unix_us, CommandReport, CommandState, MissionClock, VehicleCommand, VehicleStatus,
};
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::open::{Telemetry, OPEN_VERSION};
use shoal_common::wire::WireTrajectory;

use crate::assignment::{parse_for, MissionReport, Unusable};
use crate::link::{LinkError, VehicleLink};

/// An `Execute` order, checked.
#[derive(Debug, Clone)]
pub struct Order {
    /// Mission id.
    pub mission: String,
    /// Our vehicle.
    pub vehicle: String,
    /// Its index in the scenario.
    pub index: usize,
    /// The scenario.
    pub scenario: Scenario,
    /// The trajectory to drive.
    pub plan: Trajectory,
    /// The fleet's mission clock.
    pub clock: MissionClock,
    /// Wall time between reports.
    pub period: Duration,
    /// Noise seed of a simulated vehicle.
    pub seed: u64,
}

impl Order {
    /// Reads an `Execute` message for `vehicle`; the error says what is wrong.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        mission: &str,
        vehicle: &str,
        scenario_toml: &str,
        wire: &WireTrajectory,
        epoch_unix_ms: u64,
        time_scale: f64,
        telemetry_hz: f64,
        seed: u64,
    ) -> Result<Order, Unusable> {
        let (scenario, index) = parse_for(mission, vehicle, scenario_toml)?;
        if !(time_scale.is_finite() && time_scale > 0.0) {
            return Err(Unusable::TimeScale(time_scale));
        }
        if !(telemetry_hz.is_finite() && telemetry_hz > 0.0 && telemetry_hz <= 100.0) {
            return Err(Unusable::TelemetryRate(telemetry_hz));
        }
        Ok(Order {
            mission: mission.to_string(),
            vehicle: vehicle.to_string(),
            index,
            scenario,
            plan: wire.checked()?,
            clock: MissionClock {
                epoch_unix_ms,
                scale: time_scale,
            },
            period: Duration::from_secs_f64(1.0 / telemetry_hz),
            seed,
        })
    }
}

/// How long a stop waits for the vehicle to confirm it (reporting meanwhile) before the
/// execution ends anyway.
pub const STOP_WAIT: Duration = Duration::from_secs(10);
/// The same for the hold an agent gives its vehicle when it shuts down.
pub const SHUTDOWN_WAIT: Duration = Duration::from_secs(3);

/// One execution under way: the order, the link, and what has been reported.
struct Driver<'a> {
    order: Order,
    link: &'a mut dyn VehicleLink,
    publish: &'a dyn Fn(&Telemetry),
    /// Next report number.
    seq: u64,
    /// Revision of the plan the vehicle confirmed, and the one sent to it, if newer.
    revision: u32,
    pending_revision: Option<u32>,
    /// The latest command and what the vehicle made of it, carried in every report.
    command: Option<CommandReport>,
    /// When the next periodic report is due.
    next: Instant,
    /// Whether the vehicle last reported itself arrived.
    arrived: bool,
}

impl Driver<'_> {
    /// Gives `command` to the vehicle (`plan` for an upload); the error if it could not even
    /// be given.
    fn give(
        &mut self,
        command: VehicleCommand,
        plan: Option<&Trajectory>,
    ) -> Result<(), LinkError> {
        let now = self.order.clock.now();
        let given = match (command, plan) {
            (VehicleCommand::Upload, Some(plan)) => self.link.upload(plan),
            (VehicleCommand::Stop, _) => self.link.stop(),
            _ => self.link.hold(now),
        };
        given?;
        self.command = Some(CommandReport {
            command,
            state: CommandState::Pending,
            detail: "sent".into(),
            given_s: now,
        });
        Ok(())
    }

    /// Takes what the vehicle made of the commands, reporting each change at once (a refusal
    /// and the fallback's confirmation a few milliseconds later are two reports).
    fn collect(&mut self) {
        for outcome in self.link.outcomes() {
            let Some(report) = self
                .command
                .as_mut()
                .filter(|c| c.command == outcome.command)
            else {
                continue; // of a command given before the latest one
            };
            if outcome.command == VehicleCommand::Upload && outcome.state == CommandState::Confirmed
            {
                self.revision = self.pending_revision.take().unwrap_or(self.revision);
            }
            let mission = &self.order.mission;
            tracing::info!(
                "mission {mission}: {:?} {:?}: {}",
                outcome.command,
                outcome.state,
                outcome.detail
            );
            (report.state, report.detail) = (outcome.state, outcome.detail);
            self.report();
        }
    }

    /// Reports the vehicle's state now (nothing if the link has no state yet).
    fn report(&mut self) {
        match self.link.state(self.order.clock.now()) {
            Ok(state) => {
                self.arrived = state.status == VehicleStatus::Arrived;
                (self.publish)(&Telemetry {
                    version: OPEN_VERSION,
                    mission: self.order.mission.clone(),
                    vehicle: self.order.vehicle.clone(),
                    seq: self.seq,
                    revision: self.revision,
                    sent_unix_us: unix_us(),
                    state,
                    command: self.command.clone(),
                });
                self.seq += 1;
            }
            Err(e) => tracing::warn!("mission {}: no state: {e}", self.order.mission),
        }
    }

    /// Reports if a report is due; returns how long until the next one.
    fn tick(&mut self) -> Duration {
        self.collect();
        let now = Instant::now();
        if now >= self.next {
            self.next += self.order.period;
            if self.next < now {
                self.next = now + self.order.period; // fell behind: do not burst
            }
            self.report();
        }
        self.next.saturating_duration_since(Instant::now())
    }

    /// Goes on reporting until the latest command is confirmed or given up, or `wait` passes;
    /// says which.
    fn settle(&mut self, wait: Duration) -> String {
        let deadline = Instant::now() + wait;
        loop {
            let pause = self.tick();
            match &self.command {
                Some(c) if matches!(c.state, CommandState::Confirmed) => return "confirmed".into(),
                Some(c) if matches!(c.state, CommandState::GaveUp) => {
                    return format!("NOT confirmed: {}", c.detail)
                }
                _ if Instant::now() >= deadline => {
                    return format!("not confirmed in {:.0} s", wait.as_secs_f64())
                }
                _ => std::thread::sleep(pause.min(Duration::from_millis(20))),
            }
        }
    }

    /// Acts on one message of the coordinator; `Some(outcome)` ends the execution.
    fn obey(&mut self, message: CoordinatorToAgent) -> Option<String> {
        let mission = self.order.mission.clone();
        match message {
            CoordinatorToAgent::Update {
                revision: r,
                trajectory: t,
                ..
            } if r > self.revision && self.pending_revision.is_none_or(|p| r > p) => {
                match t.checked() {
                    Ok(plan) => match self.give(VehicleCommand::Upload, Some(&plan)) {
                        Ok(()) => self.pending_revision = Some(r),
                        Err(e) => tracing::warn!("mission {mission}: revision {r}: {e}"),
                    },
                    Err(why) => tracing::warn!("mission {mission}: dropped an update: {why}"),
                }
            }
            CoordinatorToAgent::Hold { reason, .. } => {
                tracing::warn!("mission {mission}: hold: {reason}");
                if let Err(e) = self.give(VehicleCommand::Hold, None) {
                    tracing::warn!("mission {mission}: hold not given: {e}");
                }
                self.report();
            }
            CoordinatorToAgent::Stop { reason, .. } => {
                let given = self.give(VehicleCommand::Stop, None);
                let stopped = match given {
                    Ok(()) => self.settle(STOP_WAIT),
                    Err(e) => format!("not given: {e}"),
                };
                return Some(format!("stopped: {reason}{}", suffix(&stopped)));
            }
            _ => {}
        }
        None
    }

    /// Holds the vehicle as the agent leaves, waiting a little for it to confirm.
    fn leave(&mut self) -> String {
        let held = match self.give(VehicleCommand::Hold, None) {
            Ok(()) => self.settle(SHUTDOWN_WAIT),
            Err(e) => format!("not given: {e}"),
        };
        format!(
            "the agent is shutting down: vehicle told to hold{}",
            suffix(&held)
        )
    }
}

/// Nothing for a confirmed command, else what became of it.
fn suffix(result: &str) -> String {
    match result {
        "confirmed" => String::new(),
        other => format!(" ({other})"),
    }
}

/// Drives the vehicle until the coordinator stops the mission (or `stop`, or the coordinator
/// stays silent for `idle` after the vehicle arrived). `publish` sends one report. No command
/// to the vehicle holds the reports up: each is given at once and its outcome is collected as
/// it comes, and carried in every report from then on.
pub fn run(
    order: Order,
    link: &mut dyn VehicleLink,
    inbox: &Receiver<CoordinatorToAgent>,
    publish: &dyn Fn(&Telemetry),
    stop: &AtomicBool,
    idle: Duration,
) -> MissionReport {
    let mut d = Driver {
        next: Instant::now(),
        order,
        link,
        publish,
        seq: 0,
        revision: 0,
        pending_revision: None,
        command: None,
        arrived: false,
    };
    let plan = d.order.plan.clone();
    if let Err(e) = d.give(VehicleCommand::Upload, Some(&plan)) {
        return MissionReport {
            iterations: 0,
            elites_sent: 0,
            outcome: format!("the vehicle did not take its trajectory: {e}"),
        };
    }
    tracing::info!(
        "mission {}: {} drives {} samples through {} ({}× real time)",
        d.order.mission,
        d.order.vehicle,
        d.order.plan.times.len(),
        d.link.name(),
        d.order.clock.scale
    );
    let mut heard = Instant::now();
    let outcome = loop {
        if stop.load(Ordering::Relaxed) {
            break d.leave();
        }
        let wait = d.tick();
        if d.arrived && heard.elapsed() > idle {
            let silent = idle.as_secs_f64();
            break format!("arrived; the coordinator was silent for {silent:.0} s");
        }
        match inbox.recv_timeout(wait.min(Duration::from_millis(50))) {
            Ok(m) => {
                heard = Instant::now();
                if let Some(end) = d.obey(m) {
                    break end;
                }
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => break d.leave(),
        }
    };
    MissionReport {
        iterations: d.seq as u32,
        elites_sent: 0,
        outcome,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::{LinkError, LinkOutcome};
    use shoal_common::execution::VehicleState;
    use shoal_common::geometry::Vec3;
    use std::sync::mpsc;
    use std::sync::{Arc, Mutex};

    /// A link that records what it is asked.
    #[derive(Clone, Default)]
    struct Recorder {
        calls: Arc<Mutex<Vec<String>>>,
        confirmed: Arc<Mutex<usize>>,
    }

    impl VehicleLink for Recorder {
        fn name(&self) -> String {
            "recorder".into()
        }
        fn upload(&mut self, plan: &Trajectory) -> Result<(), LinkError> {
            self.calls
                .lock()
                .map_err(|e| LinkError::Io(e.to_string()))?
                .push(format!("upload {}", plan.times.len()));
            Ok(())
        }
        fn state(&mut self, now: f64) -> Result<VehicleState, LinkError> {
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
        fn hold(&mut self, _now: f64) -> Result<(), LinkError> {
            self.calls
                .lock()
                .map_err(|e| LinkError::Io(e.to_string()))?
                .push("hold".into());
            Ok(())
        }
        fn stop(&mut self) -> Result<(), LinkError> {
            self.calls
                .lock()
                .map_err(|e| LinkError::Io(e.to_string()))?
                .push("stop".into());
            Ok(())
        }
        /// Every command confirmed at once, as a simulator does.
        fn outcomes(&mut self) -> Vec<LinkOutcome> {
            let calls = self.calls.lock().map(|c| c.clone()).unwrap_or_default();
            let mut seen = self.confirmed.lock().map(|n| *n).unwrap_or(0);
            let done = calls[seen.min(calls.len())..]
                .iter()
                .map(|c| {
                    let command = match c.as_str() {
                        "hold" => VehicleCommand::Hold,
                        "stop" => VehicleCommand::Stop,
                        _ => VehicleCommand::Upload,
                    };
                    LinkOutcome::confirmed(command, c.clone())
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
        assert!(
            e(Order::new("m", "auv9", &s, &ok, 0, 50.0, 2.0, 1)).contains("no vehicle \"auv9\"")
        );
        assert!(e(Order::new("m", "auv1", &s, &ok, 0, 0.0, 2.0, 1)).contains("time scale 0"));
        assert!(
            e(Order::new("m", "auv1", &s, &ok, 0, 1.0, 500.0, 1)).contains("telemetry rate 500")
        );
        let backwards = wire(vec![[10.0, 1.0, 2.0, 3.0], [0.0, 4.0, 5.0, 6.0]]);
        assert!(e(Order::new("m", "auv1", &s, &backwards, 0, 1.0, 2.0, 1))
            .contains("not timed in order"));
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

    #[test]
    fn reports_flow_updates_load_holds_hold_and_stop_ends() {
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
}
