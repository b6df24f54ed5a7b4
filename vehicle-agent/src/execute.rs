//! One execution in an agent: the vehicle drives its timed trajectory through its
//! [`VehicleLink`], and the agent reports its state at the telemetry rate. Replans (`Update`),
//! holds and the stop arrive on a channel; reports leave through a closure, so this loop knows
//! nothing of Zenoh.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use shoal_common::execution::{unix_us, MissionClock, VehicleStatus};
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::coordinator_to_agent::CoordinatorToAgent;
use shoal_common::wire::open::{Telemetry, OPEN_VERSION};
use shoal_common::wire::WireTrajectory;

use crate::link::VehicleLink;
use crate::mission::MissionReport;

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
    ) -> Result<Order, String> {
        let origin = format!("<scenario of mission {mission}>");
        let scenario =
            Scenario::parse(scenario_toml, Path::new(&origin)).map_err(|e| e.to_string())?;
        let index = scenario
            .vehicles
            .iter()
            .position(|v| v.id == vehicle)
            .ok_or_else(|| format!("mission {mission} has no vehicle {vehicle:?}"))?;
        if !(time_scale.is_finite() && time_scale > 0.0) {
            return Err(format!("time scale {time_scale} is not a positive number"));
        }
        if !(telemetry_hz.is_finite() && telemetry_hz > 0.0 && telemetry_hz <= 100.0) {
            return Err(format!(
                "telemetry rate {telemetry_hz} Hz is not in (0, 100]"
            ));
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

/// Drives the vehicle until the coordinator stops the mission (or `stop`, or the coordinator
/// stays silent for `idle` after the vehicle arrived). `publish` sends one report.
pub fn run(
    order: Order,
    link: &mut dyn VehicleLink,
    inbox: &Receiver<CoordinatorToAgent>,
    publish: &dyn Fn(&Telemetry),
    stop: &AtomicBool,
    idle: Duration,
) -> MissionReport {
    let mut revision = 0u32;
    let mut seq = 0u64;
    if let Err(e) = link.upload(&order.plan) {
        return MissionReport {
            iterations: 0,
            elites_sent: 0,
            outcome: format!("the vehicle did not take its trajectory: {e}"),
        };
    }
    tracing::info!(
        "mission {}: {} drives {} samples through {} ({}× real time)",
        order.mission,
        order.vehicle,
        order.plan.times.len(),
        link.name(),
        order.clock.scale
    );
    let mut next = Instant::now();
    let mut heard = Instant::now();
    let outcome = loop {
        if stop.load(Ordering::Relaxed) {
            let _ = link.hold(order.clock.now());
            break "the agent is shutting down: vehicle told to hold".to_string();
        }
        let now = Instant::now();
        if now >= next {
            next += order.period;
            if next < now {
                next = now + order.period; // fell behind: do not burst
            }
            match link.state(order.clock.now()) {
                Ok(state) => {
                    let arrived = state.status == VehicleStatus::Arrived;
                    publish(&Telemetry {
                        version: OPEN_VERSION,
                        mission: order.mission.clone(),
                        vehicle: order.vehicle.clone(),
                        seq,
                        revision,
                        sent_unix_us: unix_us(),
                        state,
                    });
                    seq += 1;
                    if arrived && heard.elapsed() > idle {
                        break format!(
                            "arrived; the coordinator was silent for {:.0} s",
                            idle.as_secs_f64()
                        );
                    }
                }
                Err(e) => tracing::warn!("mission {}: no state: {e}", order.mission),
            }
        }
        let wait = next.saturating_duration_since(Instant::now());
        match inbox.recv_timeout(wait.min(Duration::from_millis(100))) {
            Ok(m) => {
                heard = Instant::now();
                match m {
                    CoordinatorToAgent::Update {
                        revision: r,
                        trajectory: t,
                        ..
                    } if r > revision => match t.checked() {
                        Ok(plan) => match link.upload(&plan) {
                            Ok(()) => {
                                revision = r;
                                tracing::info!("mission {}: revision {r} loaded", order.mission);
                            }
                            Err(e) => {
                                tracing::warn!("mission {}: revision {r}: {e}", order.mission)
                            }
                        },
                        Err(why) => {
                            tracing::warn!("mission {}: dropped an update: {why}", order.mission)
                        }
                    },
                    CoordinatorToAgent::Hold { reason, .. } => {
                        tracing::warn!("mission {}: hold: {reason}", order.mission);
                        if let Err(e) = link.hold(order.clock.now()) {
                            tracing::warn!("mission {}: hold failed: {e}", order.mission);
                        }
                    }
                    CoordinatorToAgent::Stop { reason, .. } => {
                        let _ = link.stop();
                        break format!("stopped: {reason}");
                    }
                    _ => {}
                }
            }
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                let _ = link.hold(order.clock.now());
                break "the agent is shutting down: vehicle told to hold".to_string();
            }
        }
    };
    MissionReport {
        iterations: seq as u32,
        elites_sent: 0,
        outcome,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::LinkError;
    use shoal_common::execution::VehicleState;
    use shoal_common::geometry::Vec3;
    use std::sync::mpsc;
    use std::sync::{Arc, Mutex};

    /// A link that records what it is asked.
    #[derive(Clone, Default)]
    struct Recorder {
        calls: Arc<Mutex<Vec<String>>>,
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
        let e = |r: Result<Order, String>| r.err().unwrap_or_default();
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
