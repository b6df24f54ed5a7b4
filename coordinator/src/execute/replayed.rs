//! A mission log folded back, record by record, into the fleet picture the live run had: what
//! `replay` recomputes its figures from, and what the web view rebuilds a replayed mission's
//! statuses from.

use std::path::Path;

use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;
use shoal_common::wire::open::MissionEvent;

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
                            log::EVENT_HOLD => fleet.vehicles[i].holding = true,
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
