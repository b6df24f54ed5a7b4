//! A mission log folded back, record by record, into the fleet picture the live run had: what
//! `replay` recomputes its figures from, and what a replayed mission's statuses are rebuilt
//! from ([`Statuses`], for the web view and the Foxglove server: the log holds no statuses).

use std::path::Path;

use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::open::{FleetStatus, MissionEvent};

use super::fleet::{ExecutionFigures, Fleet};
use super::log::{self, Record, Start};

/// A log being replayed.
pub struct Replayed {
    /// The log's start record.
    pub start: Start,
    /// The scenario, with the obstacles published so far.
    pub scenario: Scenario,
    /// The fleet picture so far.
    pub fleet: Fleet,
    /// The first plan, in the scenario's vehicle order.
    pub planned: Vec<Trajectory>,
    /// Every event so far, in order.
    pub events: Vec<MissionEvent>,
    /// The figures the run wrote at its end, once that record is replayed.
    pub logged: Option<ExecutionFigures>,
}

impl Replayed {
    /// The picture at the start of `records` (a start record, a plan of revision 0 somewhere);
    /// `path` names the log in errors.
    pub fn new(records: &[Record], path: &Path) -> anyhow::Result<Replayed> {
        let Some(Record::Start(start)) = records.first() else {
            anyhow::bail!("{}: no start record", path.display());
        };
        let origin = format!("{} (start record)", path.display());
        let scenario = Scenario::parse(&start.scenario_toml, Path::new(&origin))?;
        let ids: Vec<String> = scenario.vehicles.iter().map(|v| v.id.clone()).collect();
        let first = records.iter().find_map(|r| match r {
            Record::Plan(p) if p.revision == 0 => Some(p),
            _ => None,
        });
        let Some(first) = first else {
            anyhow::bail!("{}: no plan record of revision 0", path.display());
        };
        let planned: Vec<Trajectory> = ids
            .iter()
            .map(|id| {
                first
                    .trajectories
                    .iter()
                    .find(|(v, _)| v == id)
                    .map(|(_, s)| Trajectory::from_samples(s))
                    .ok_or_else(|| {
                        anyhow::anyhow!("{}: the plan has no trajectory for {id}", path.display())
                    })
            })
            .collect::<anyhow::Result<_>>()?;
        let fleet = Fleet::new(&ids, &planned, scenario.fleet.d_min_m, start.horizon_s);
        Ok(Replayed {
            start: start.clone(),
            scenario,
            fleet,
            planned,
            events: Vec::new(),
            logged: None,
        })
    }

    /// Applies one record as the live run did.
    pub fn apply(&mut self, r: &Record) {
        let fleet = &mut self.fleet;
        match r {
            Record::Plan(p) if p.revision > 0 => {
                for (id, s) in &p.trajectories {
                    if let Some(i) = fleet.index(id) {
                        if p.changed.contains(id) {
                            // As live: a new plan ends a hold.
                            fleet.vehicles[i].plan = Trajectory::from_samples(s);
                            fleet.vehicles[i].revision = p.revision;
                            fleet.vehicles[i].holding = false;
                            fleet.vehicles[i].held_since_s = None;
                        }
                    }
                }
            }
            Record::Telemetry {
                received_unix_us,
                telemetry,
            } => {
                fleet.report(telemetry.clone(), *received_unix_us);
            }
            Record::Event(e) => {
                // The live run marks a vehicle lost or holding just before it logs the event,
                // and a holding vehicle's distance from its plan is no tracking error.
                for v in &e.vehicles {
                    if let Some(i) = fleet.index(v) {
                        match e.kind.as_str() {
                            log::EVENT_LOST => fleet.vehicles[i].lost = true,
                            // Held since the event: the live run stamps it with the
                            // mission time it sent the hold at.
                            log::EVENT_HOLD => {
                                fleet.vehicles[i].holding = true;
                                fleet.vehicles[i].held_since_s = Some(e.t_s);
                            }
                            _ => {}
                        }
                    }
                }
                self.events.push(e.clone());
            }
            Record::Obstacle(o) => {
                self.scenario.obstacles.push(o.clone());
                fleet.obstacle_published();
            }
            Record::End(f) => self.logged = Some(f.clone()),
            Record::Start(_) | Record::Plan(_) => {}
        }
    }
}

/// A log's statuses, rebuilt as the live run published them: one per wall second of the run
/// (with the first report at least that many mission seconds after the last status), and one
/// with the end record (the picture as the mission ended, as the run's last status).
pub struct Statuses {
    /// The picture so far.
    pub replayed: Replayed,
    /// Mission seconds between two statuses.
    every: f64,
    /// When the next is due, mission seconds.
    next: f64,
    /// The latest mission time of a report or an event so far.
    latest: f64,
}

impl Statuses {
    /// Statuses of `records` (see [`Replayed::new`]), a wall second of the run apart (the log's
    /// time scale in mission seconds, at least one), or `at_least` mission seconds when that is
    /// longer (a reader that thins them).
    pub fn new(records: &[Record], path: &Path, at_least: f64) -> anyhow::Result<Statuses> {
        let replayed = Replayed::new(records, path)?;
        Ok(Statuses {
            every: replayed.start.time_scale.max(at_least).max(1.0),
            replayed,
            next: f64::NEG_INFINITY,
            latest: 0.0,
        })
    }

    /// Applies `r` ([`Replayed::apply`]); the status it makes due, if any.
    pub fn apply(&mut self, r: &Record) -> Option<FleetStatus> {
        self.replayed.apply(r);
        match r {
            Record::Telemetry { telemetry, .. } => {
                let t = telemetry.state.t_s;
                self.latest = self.latest.max(t);
                (t >= self.next).then(|| {
                    self.next = t + self.every;
                    self.status(t)
                })
            }
            Record::Event(e) => {
                self.latest = self.latest.max(e.t_s);
                None
            }
            Record::End(_) => Some(self.status(self.latest)),
            Record::Start(_) | Record::Plan(_) | Record::Obstacle(_) => None,
        }
    }

    /// The status at mission time `t`.
    fn status(&self, t: f64) -> FleetStatus {
        self.replayed.fleet.status(&self.replayed.start.mission, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::wire::open::{PlanNotice, OPEN_VERSION};

    fn plan(revision: u32, changed: &[&str]) -> Record {
        let line = |y: f64| vec![[0.0, 0.0, y, 50.0], [1000.0, 1000.0, y, 50.0]];
        Record::Plan(PlanNotice {
            version: OPEN_VERSION,
            mission: "m".into(),
            revision,
            changed: changed.iter().map(|v| v.to_string()).collect(),
            trajectories: vec![("auv1".into(), line(0.0)), ("auv2".into(), line(500.0))],
        })
    }

    fn event(kind: &str, t_s: f64) -> Record {
        Record::Event(MissionEvent {
            version: OPEN_VERSION,
            mission: "m".into(),
            t_s,
            kind: kind.into(),
            vehicles: vec!["auv1".into()],
            detail: String::new(),
        })
    }

    /// A logged hold is replayed as the live run held: since the event's mission time (where
    /// the vehicle stands and where its retry resumes are reckoned from it), until a new plan.
    /// Scenario 1 has the two vehicles the plans name, auv1 and auv2.
    #[test]
    fn a_logged_hold_holds_from_its_time_until_a_new_plan() -> anyhow::Result<()> {
        let toml = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenarios/amp-pso-1.toml"
        ))?;
        let records = vec![
            Record::Start(Start {
                mission: "m".into(),
                scenario_toml: toml,
                common_arrival_s: 1000.0,
                arrival_window_s: 30.0,
                horizon_s: 120.0,
                time_scale: 10.0,
                epoch_unix_ms: 0,
            }),
            plan(0, &[]),
        ];
        let mut r = Replayed::new(&records, Path::new("log.ndjson"))?;
        r.apply(&event(log::EVENT_HOLD, 240.0));
        let v = &r.fleet.vehicles[0];
        assert!(v.holding);
        assert_eq!(v.held_since_s, Some(240.0));
        assert_eq!(r.fleet.vehicles[1].held_since_s, None);
        r.apply(&plan(1, &["auv1"]));
        let v = &r.fleet.vehicles[0];
        assert!(!v.holding);
        assert_eq!(v.held_since_s, None);
        Ok(())
    }
}
