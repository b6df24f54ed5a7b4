//! What a one-shot mission plans: the fleet's job and one vehicle's result, apart from the loop
//! that collects them so that a seat can hold a result without depending on that loop.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use shoal_common::coverage::fleet::{FleetCoverage, StripPlan};
use shoal_common::coverage::TerrainMap25;
use shoal_common::tour::{FleetTours, TourPlan};
use shoal_common::wire::agent_to_coordinator::{tour_from_wire, AgentToCoordinator};

/// What the agents of a one-shot mission plan.
pub enum ShareJob {
    /// Inspection tours (Hu et al. 2023).
    Tours(Box<FleetTours>),
    /// Coverage strips (CPP-DSMV) on the seabed map.
    Strips(Box<FleetCoverage>, Box<TerrainMap25>),
}

/// One vehicle's result.
#[derive(Debug, Clone)]
pub enum Share {
    /// Its inspection tour.
    Tour(TourPlan),
    /// Its strip's coverage plan.
    Strip(Box<StripPlan>),
    /// The coordinator could not plan it either.
    Failed(String),
}

impl ShareJob {
    /// Plans vehicle `i`'s share in this process. A raised `stop` cuts a tour's swarms short
    /// (the tour is still complete) or a strip's tracking simulation (the strip is planned
    /// whole).
    pub(super) fn plan_here(&self, i: usize, stop: Option<&Arc<AtomicBool>>) -> Share {
        match self {
            ShareJob::Tours(job) => Share::Tour(job.plan_vehicle(i, stop)),
            ShareJob::Strips(job, map) => {
                match job.plan_vehicle(map, i, stop.map(|s| &**s), &mut |_, _| {}) {
                    Ok(p) => Share::Strip(Box::new(p)),
                    Err(e) => Share::Failed(e.to_string()),
                }
            }
        }
    }

    /// The share a result message carries for vehicle `i`, checked; `None` when the message
    /// is not this job's kind of result.
    pub(super) fn read(&self, i: usize, m: AgentToCoordinator) -> Option<Result<Share, String>> {
        match (self, m) {
            (ShareJob::Tours(job), m) => {
                let share = job.shares.get(i).map_or(0, Vec::len);
                tour_from_wire(&m, share).map(|t| t.map(Share::Tour))
            }
            (ShareJob::Strips(job, _), AgentToCoordinator::Coverage { strip, plan, .. }) => {
                Some(match job.strips.get(i) {
                    _ if strip as usize != i => Err(format!("strip {strip} for vehicle {i}")),
                    Some(rect) => plan
                        .check(*rect)
                        .map(|()| Share::Strip(plan))
                        .map_err(|e| e.to_string()),
                    None => Err(format!("no strip for vehicle {i}")),
                })
            }
            _ => None,
        }
    }

    /// What the agents send, in words.
    pub(super) fn noun(&self) -> &'static str {
        match self {
            ShareJob::Tours(_) => "tour",
            ShareJob::Strips(..) => "strip plan",
        }
    }
}

impl Share {
    /// Its length, metres (the progress line's figure).
    pub(super) fn length_m(&self) -> f64 {
        match self {
            Share::Tour(t) => t.tour_length_m,
            Share::Strip(p) => p.path.length(),
            Share::Failed(_) => 0.0,
        }
    }

    /// Whether a stop cut it short: a tour's swarms, or a strip's tracking simulation.
    pub(super) fn interrupted(&self) -> bool {
        match self {
            Share::Tour(t) => t.interrupted,
            Share::Strip(p) => p.report.tracking.as_ref().is_some_and(|t| t.interrupted),
            Share::Failed(_) => false,
        }
    }
}
