//! What the mission loop shares between its steps (joining, rounds, one-shot shares): the run
//! itself, its patience and the progress it reports.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use shoal_common::cost::FleetModel;
use shoal_common::scenario::Scenario;

use super::super::network::Network;
use super::seat::Seat;
use super::share::ShareJob;

/// How patient the coordinator is.
#[derive(Debug, Clone)]
pub struct Timing {
    /// How long agents have to join.
    pub join: Duration,
    /// How long one round may wait for an agent's elites before planning its vehicle here.
    pub round: Duration,
}

/// Progress of a distributed run, for stderr.
#[derive(Debug, Clone, Copy)]
pub struct Status {
    /// Iterations done.
    pub iteration: usize,
    /// Iteration budget.
    pub max_iterations: usize,
    /// Best fitness so far.
    pub best_cost: f64,
    /// Agents planning their own vehicle.
    pub alive: usize,
    /// Vehicles.
    pub vehicles: usize,
}

/// How long a vehicle whose agent was seen to go keeps its seat: Zenoh sends declarations
/// (the liveliness token's end) ahead of queued data, so an agent that leaves right after its
/// last elites can be "gone" before they arrive, and an agent whose link blinked may be back.
pub(super) const GONE_GRACE: Duration = Duration::from_secs(1);

/// Everything the loop shares.
pub(super) struct Run<'a> {
    pub(super) scenario: &'a Scenario,
    pub(super) model: Arc<FleetModel>,
    pub(super) net: &'a mut Network,
    pub(super) seats: Vec<Seat>,
    pub(super) timing: Timing,
    pub(super) mission: String,
    /// One-shot missions: the fleet's job (to check the results agents send).
    pub(super) job: Option<Arc<ShareJob>>,
    /// One-shot missions: the stop flag; a share planned here is cut short when it is raised.
    pub(super) stop: Option<Arc<AtomicBool>>,
}
