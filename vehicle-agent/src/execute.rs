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
use crate::link::{CommandSerial, LinkError, VehicleLink};

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
/// Most uploads remembered while unanswered: every link answers each command it was given
/// (one a newer command supersedes comes back given up), so this only bounds what a link that
/// loses an answer costs.
const UNANSWERED_UPLOADS: usize = 8;

/// One execution under way: the order, the link, and what has been reported.
struct Driver<'a> {
    order: Order,
    link: &'a mut dyn VehicleLink,
    publish: &'a dyn Fn(&Telemetry),
    /// Next report number.
    seq: u64,
    /// Revision of the plan the vehicle confirmed.
    revision: u32,
    /// Uploads given and not answered yet, oldest first: each one's serial and revision.
    unanswered: Vec<(CommandSerial, u32)>,
    /// The latest command and what the vehicle made of it, carried in every report.
    command: Option<CommandReport>,
    /// The latest command's serial (none when it could not be given).
    latest: Option<CommandSerial>,
    /// When the next periodic report is due.
    next: Instant,
    /// Whether the vehicle last reported itself arrived.
    arrived: bool,
}

impl Driver<'_> {
    /// Gives `command` to the vehicle (`plan` for an upload); the error if it could not even
    /// be given. Either way the next report says so: a command the link could not take is
    /// given up at once, so the coordinator does not wait out its patience to learn it.
    fn give(
        &mut self,
        command: VehicleCommand,
        plan: Option<&Trajectory>,
    ) -> Result<CommandSerial, LinkError> {
        let now = self.order.clock.now();
        let given = match (command, plan) {
            (VehicleCommand::Upload, Some(plan)) => self.link.upload(plan),
            (VehicleCommand::Stop, _) => self.link.stop(),
            _ => self.link.hold(now),
        };
        let (state, detail) = match &given {
            Ok(_) => (CommandState::Pending, "sent".to_string()),
            Err(e) => (CommandState::GaveUp, format!("not given: {e}")),
        };
        self.latest = given.as_ref().ok().copied();
        self.command = Some(CommandReport {
            command,
            state,
            detail,
            given_s: now,
        });
        given
    }

    /// Gives the plan of `revision` to the vehicle, remembering which upload carries it.
    fn upload(&mut self, plan: &Trajectory, revision: u32) -> Result<(), LinkError> {
        let serial = self.give(VehicleCommand::Upload, Some(plan))?;
        if self.unanswered.len() >= UNANSWERED_UPLOADS {
            self.unanswered.remove(0);
        }
        self.unanswered.push((serial, revision));
        Ok(())
    }

    /// The revision an upload's answer settles: a confirmed upload's plan is the vehicle's,
    /// whatever was given since (a hold given after it holds on it). A link answers in the
    /// order it was given, so the uploads before it are forgotten. Whether it is news.
    fn settle_upload(&mut self, serial: CommandSerial, confirmed: bool) -> bool {
        let Some(k) = self.unanswered.iter().position(|(s, _)| *s == serial) else {
            return false;
        };
        let (_, revision) = self.unanswered[k];
        self.unanswered.drain(..=k);
        let news = confirmed && revision > self.revision;
        if news {
            self.revision = revision;
        }
        news
    }

    /// Takes what the vehicle made of the commands, reporting each change at once (a refusal
    /// and the fallback's confirmation a few milliseconds later are two reports).
    fn collect(&mut self) {
        for outcome in self.link.outcomes() {
            let new_revision = outcome.command == VehicleCommand::Upload
                && outcome.is_final()
                && self.settle_upload(outcome.serial, outcome.state == CommandState::Confirmed);
            let latest = self.latest == Some(outcome.serial);
            let Some(report) = self.command.as_mut().filter(|_| latest) else {
                // Of a command given before the latest one: only a new revision is news.
                if new_revision {
                    self.report();
                }
                continue;
            };
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
            } if r > self.revision && self.unanswered.last().is_none_or(|&(_, p)| r > p) => {
                match t.checked() {
                    Ok(plan) => {
                        if let Err(e) = self.upload(&plan, r) {
                            tracing::warn!("mission {mission}: revision {r}: {e}");
                            self.report();
                        }
                    }
                    Err(why) => tracing::warn!("mission {mission}: dropped an update: {why}"),
                }
            }
            CoordinatorToAgent::Hold { reason, .. } => {
                if self.keeps_its_hold() {
                    tracing::debug!("mission {mission}: hold repeated; the vehicle keeps it");
                } else {
                    tracing::warn!("mission {mission}: hold: {reason}");
                    if let Err(e) = self.give(VehicleCommand::Hold, None) {
                        tracing::warn!("mission {mission}: hold not given: {e}");
                    }
                }
                self.report();
            }
            CoordinatorToAgent::Stop { reason, .. } => {
                let given = self.give(VehicleCommand::Stop, None);
                let stopped = match given {
                    Ok(_) => self.settle(STOP_WAIT),
                    Err(e) => format!("not given: {e}"),
                };
                return Some(format!("stopped: {reason}{}", suffix(&stopped)));
            }
            _ => {}
        }
        None
    }

    /// Whether the vehicle keeps the hold it was given last: it confirmed it, nothing was given
    /// since, and it does not report itself moving (before its first fix it reports nothing).
    /// A hold the coordinator repeats then is not given again: the coordinator repeats its
    /// orders every second until the vehicle's first report, and a MAVLink vehicle would be put
    /// back in its hold mode each time, over any mode its operator chose meanwhile.
    fn keeps_its_hold(&mut self) -> bool {
        let confirmed = self.command.as_ref().is_some_and(|c| {
            c.command == VehicleCommand::Hold && c.state == CommandState::Confirmed
        });
        confirmed
            && self.link.state(self.order.clock.now()).map_or(true, |s| {
                matches!(s.status, VehicleStatus::Holding | VehicleStatus::Stopped)
            })
    }

    /// Holds the vehicle as the agent leaves, waiting a little for it to confirm.
    fn leave(&mut self) -> String {
        let held = match self.give(VehicleCommand::Hold, None) {
            Ok(_) => self.settle(SHUTDOWN_WAIT),
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
        unanswered: Vec::new(),
        command: None,
        latest: None,
        arrived: false,
    };
    let plan = d.order.plan.clone();
    if let Err(e) = d.upload(&plan, 0) {
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
mod tests;
