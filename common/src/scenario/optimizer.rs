//! The `[optimizer]` table of a scenario: which swarm, its budget, the objective weights, and
//! how a distributed run splits over the vehicle agents.

use serde::{Deserialize, Serialize};

use super::error::over;
use super::error::{Bad, ScenarioError};
use crate::limits::{MAX_ITERATIONS, MAX_PARTICLES, MAX_POPULATIONS, MAX_THREADS, MAX_WAYPOINTS};
// The algorithm names are the swarm catalog's: it alone maps them to solvers.
pub use crate::swarm::catalog::Algorithm;

/// Optimizer budget and objective weights. Defaults are Zhi & Zuo 2024, Table 5 and §4.1.4.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct OptimizerSettings {
    /// Which optimizer.
    pub algorithm: Algorithm,
    /// Follower populations for the multi-population algorithms (Table 5: 20).
    pub populations: usize,
    /// Particles per population (Table 5: 50).
    pub particles: usize,
    /// Original particles of the leader population, besides the immigrants (§3.2.2 leaves the
    /// number open; 20 keeps the leader as large as the set of immigrants).
    pub leader_particles: usize,
    /// Iterations (Table 5: 200).
    pub iterations: usize,
    /// Inner waypoints per vehicle, M (Table 4: 30).
    pub waypoints: usize,
    /// Leader/follower exchange period in iterations (§3.2.2 exchanges every iteration).
    pub exchange_every: usize,
    /// RNG seed; the same seed gives the same plan.
    pub seed: u64,
    /// λ1..λ5 of eq. (12): length, depth, soft threat, time, space (§4.1.4).
    pub weights: [f64; 5],
    /// Weight of the constraint penalties (hard obstacles, turn, pitch, separation) that turn the
    /// constrained problem into an unconstrained one (§3.3.1, ref. \[30\]).
    pub penalty_weight: f64,
    /// Velocity limit per dimension as a fraction of that dimension's range, for whichever
    /// algorithm plans. Unset, each algorithm keeps its own ([`OptimizerSettings::velocity_cap`]):
    /// 0.1 for Zhi & Zuo's (eq. (7) starts ω at 2, which diverges without a limit), 0.2 for
    /// Lu et al.'s, Zhang et al.'s and Hu et al.'s.
    pub max_velocity_fraction: Option<f64>,
    /// Worker threads for population steps (results do not depend on it).
    pub threads: usize,
    /// How the multi-population algorithms split over vehicle agents (distributed mode only).
    pub distributed: DistributedSettings,
    /// After the swarm, re-plan each vehicle still in a violation against the others' paths
    /// (`crate::touch_up`, not part of any seed's algorithm). `plan` does it by default
    /// (`--no-touch-up` or `touch_up = false` to see the swarm's own result); `compare` never.
    pub touch_up: bool,
    /// After the swarm (and the touch-up), pull every swimmer's path tight inside its limits
    /// and the fleet's separation by a local constrained search (`crate::refine`, not part of
    /// any seed's algorithm). `plan` does it by default (`--no-refine` or `refine = false` for
    /// the swarm's own result); `compare` reports the algorithm both with and without it.
    pub refine: bool,
}

/// Distributed AMP-PSO (`plan` without `--in-process`): each vehicle's agent runs follower
/// populations of that vehicle's chromosome; the coordinator holds the leader population.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct DistributedSettings {
    /// Follower populations each agent runs (of `particles` particles each). A vehicle
    /// chromosome scored against the others costs about half a fleet evaluation (its separation
    /// from every other vehicle, where the fleet shares each pair between two vehicles), so
    /// Table 5's 20 per agent would cost 2.5× the in-process run. Measured on scenario 3 (seeds
    /// 1–6, lockstep): 10 per agent gives median fitness 1.818 in 2.1 s, 14 gives 1.774 in
    /// 2.7 s, 20 gives 1.746 in 3.9 s, against 1.784 and 2.3 s in-process.
    pub agent_populations: usize,
    /// Iterations between leader/follower exchanges. Each exchange is a round trip between every
    /// agent and the coordinator, which waits for all of them. Measured (scenario 3, seeds
    /// 1–10, lockstep): every iteration, median 1.8097; every 2, 1.8021 with one plan over a
    /// turn limit; every 5, 1.7980; every 10, 1.8018 (all others feasible). In-process the
    /// paper's every-iteration exchange (`optimizer.exchange_every`) stays the best.
    pub exchange_every: usize,
    /// Exchange rounds between context updates: the followers re-score every memory in a new
    /// context (one evaluation per particle), so sending every improvement doubles their work.
    /// Measured (scenario 3, 4 seeds, 20 populations per agent): every round 5.7 s, median
    /// 1.752; every 5 rounds 4.0 s, 1.746; every 10, 3.6 s, 1.758.
    pub context_every: usize,
}

impl Default for DistributedSettings {
    fn default() -> Self {
        DistributedSettings {
            agent_populations: 10,
            exchange_every: 5,
            context_every: 5,
        }
    }
}

impl Default for OptimizerSettings {
    fn default() -> Self {
        OptimizerSettings {
            algorithm: Algorithm::AmpPso,
            populations: 20,
            particles: 50,
            leader_particles: 20,
            iterations: 200,
            waypoints: 30,
            exchange_every: 1,
            seed: 1,
            weights: [0.2, 0.1, 0.3, 0.1, 0.3],
            penalty_weight: 10.0,
            max_velocity_fraction: None,
            threads: 2,
            distributed: DistributedSettings::default(),
            touch_up: true,
            refine: true,
        }
    }
}

impl OptimizerSettings {
    /// Checks every setting; `bad(field, value, reason)` builds the error naming the file.
    pub(super) fn validate(&self, bad: Bad) -> Result<(), ScenarioError> {
        let o = self;
        let positive = [
            ("optimizer.populations", o.populations),
            ("optimizer.particles", o.particles),
            ("optimizer.iterations", o.iterations),
            ("optimizer.waypoints", o.waypoints),
            ("optimizer.exchange_every", o.exchange_every),
            ("optimizer.threads", o.threads),
            (
                "optimizer.distributed.agent_populations",
                o.distributed.agent_populations,
            ),
            (
                "optimizer.distributed.context_every",
                o.distributed.context_every,
            ),
        ];
        for (field, value) in positive {
            if value == 0 {
                return Err(bad(field.into(), "0".into(), "must be at least 1"));
            }
        }
        let bounded = [
            (
                "optimizer.populations",
                o.populations,
                MAX_POPULATIONS,
                "MAX_POPULATIONS",
            ),
            (
                "optimizer.particles",
                o.particles,
                MAX_PARTICLES,
                "MAX_PARTICLES",
            ),
            (
                "optimizer.leader_particles",
                o.leader_particles,
                MAX_PARTICLES,
                "MAX_PARTICLES",
            ),
            (
                "optimizer.iterations",
                o.iterations,
                MAX_ITERATIONS,
                "MAX_ITERATIONS",
            ),
            (
                "optimizer.waypoints",
                o.waypoints,
                MAX_WAYPOINTS,
                "MAX_WAYPOINTS",
            ),
            (
                "optimizer.exchange_every",
                o.exchange_every,
                MAX_ITERATIONS,
                "MAX_ITERATIONS",
            ),
            ("optimizer.threads", o.threads, MAX_THREADS, "MAX_THREADS"),
            (
                "optimizer.distributed.agent_populations",
                o.distributed.agent_populations,
                MAX_POPULATIONS,
                "MAX_POPULATIONS",
            ),
            (
                "optimizer.distributed.exchange_every",
                o.distributed.exchange_every,
                MAX_ITERATIONS,
                "MAX_ITERATIONS",
            ),
            (
                "optimizer.distributed.context_every",
                o.distributed.context_every,
                MAX_ITERATIONS,
                "MAX_ITERATIONS",
            ),
        ];
        for (field, value, bound, name) in bounded {
            if value > bound {
                return Err(over(bad, field, value, bound, name));
            }
        }
        if let Some(k) = o.weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
            return Err(bad(
                format!("optimizer.weights[{k}]"),
                o.weights[k].to_string(),
                "must be a finite weight >= 0",
            ));
        }
        if !(o.penalty_weight.is_finite() && o.penalty_weight > 0.0) {
            return Err(bad(
                "optimizer.penalty_weight".into(),
                o.penalty_weight.to_string(),
                "must be positive",
            ));
        }
        if let Some(cap) = o.max_velocity_fraction {
            if !crate::swarm::is_valid_velocity_cap(cap) {
                return Err(bad(
                    "optimizer.max_velocity_fraction".into(),
                    cap.to_string(),
                    "must be in (0, 1]",
                ));
            }
        }
        Ok(())
    }

    /// The velocity cap an algorithm whose own cap is `own` runs with: the scenario's when it
    /// sets one, else `own`.
    pub fn velocity_cap(&self, own: f64) -> f64 {
        self.max_velocity_fraction.unwrap_or(own)
    }
}
