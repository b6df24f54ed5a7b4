//! Distributed AMP-PSO in one process: every vehicle's [`Followers`] and the [`Leader`] exchange
//! round by round exactly as the agents and the coordinator do over the network (the same
//! order: followers step, emigrants go up, the leader exchanges, the new context and then the
//! migrants come back). The network run with every agent answering in time gives the same plan
//! for the same seed; this is the reference it is tested against.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use super::follower::{FollowerSettings, Followers};
use super::leader::Leader;
use super::{round_iterations, rounds, Chromosome};
use crate::cost::FleetModel;
use crate::scenario::Scenario;
use crate::swarm::{IterationReport, Progress};

/// What a lockstep run leaves behind.
#[derive(Debug, Clone)]
pub struct LockstepOutcome {
    /// Best fleet position (a true evaluation).
    pub best_x: Vec<f64>,
    /// Its fitness.
    pub best_cost: f64,
    /// Best fitness after each iteration.
    pub convergence: Vec<f64>,
    /// Evaluations: fleet evaluations of the leader plus vehicle evaluations of the followers.
    pub evaluations: u64,
    /// Exchanges done.
    pub exchanges: u32,
    /// Wall time, seconds.
    pub runtime_s: f64,
    /// True when `stop` ended the run early.
    pub interrupted: bool,
}

/// Runs distributed AMP-PSO (or MP-PSO, by the scenario's algorithm) on `scenario` in this
/// process. `observe` sees every iteration.
pub fn run(
    scenario: &Scenario,
    stop: Option<&AtomicBool>,
    observe: &mut dyn FnMut(&IterationReport),
) -> LockstepOutcome {
    let started = Instant::now();
    let o = &scenario.optimizer;
    let model = Arc::new(FleetModel::new(scenario));
    let settings = FollowerSettings::of(o);
    let mut leader = Leader::new(Arc::clone(&model), o, settings.schedule);
    let mut context = leader.context(0);
    let mut followers: Vec<Followers> = (0..model.layout.vehicles)
        .map(|i| Followers::new(Arc::clone(&model), i, settings.clone(), context.clone()))
        .collect();
    let mut convergence = Vec::with_capacity(o.iterations);
    let mut iteration = 0;
    let mut interrupted = false;
    // The best plan improved since the followers' context was last set.
    let mut stale = false;
    for round in 0..rounds(o.iterations, o.distributed.exchange_every) {
        if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            interrupted = true;
            break;
        }
        for _ in 0..round_iterations(o.iterations, o.distributed.exchange_every, round) {
            let progress = Progress {
                iteration,
                max_iterations: o.iterations,
            };
            for f in &mut followers {
                f.step(progress);
            }
            iteration += 1;
            convergence.push(leader.best_cost());
        }
        let elites: Vec<Vec<Chromosome>> = followers.iter().map(Followers::emigrants).collect();
        let progress = Progress {
            iteration: iteration.saturating_sub(1),
            max_iterations: o.iterations,
        };
        let (migrants, improved) = leader.exchange(&elites, progress);
        stale |= improved;
        if stale && context_due(round, o.distributed.context_every) {
            stale = false;
            context = leader.context(round as u32 + 1);
            for f in &mut followers {
                f.set_context(context.clone());
            }
        }
        for (f, ms) in followers.iter_mut().zip(migrants) {
            f.immigrate_all(ms.into_iter().enumerate());
        }
        if let Some(last) = convergence.last_mut() {
            *last = leader.best_cost();
        }
        observe(&IterationReport {
            iteration,
            max_iterations: o.iterations,
            best_cost: leader.best_cost(),
            evaluations: leader.evaluations + followers.iter().map(|f| f.evaluations).sum::<u64>(),
        });
    }
    LockstepOutcome {
        best_x: leader.best_x().to_vec(),
        best_cost: leader.best_cost(),
        convergence,
        evaluations: leader.evaluations + followers.iter().map(|f| f.evaluations).sum::<u64>(),
        exchanges: leader.exchanges,
        runtime_s: started.elapsed().as_secs_f64(),
        interrupted,
    }
}

/// Whether the context is sent after exchange round `round` (0-based): every `every` rounds.
pub fn context_due(round: usize, every: usize) -> bool {
    (round + 1).is_multiple_of(every.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;

    #[test]
    fn two_crossing_vehicles_get_a_separated_plan() -> Result<(), Box<dyn std::error::Error>> {
        let mut s = fixtures::scenario(
            800.0,
            "",
            &[
                fixtures::vehicle_toml("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0]),
                fixtures::vehicle_toml("b", [500.0, 100.0, 250.0], [500.0, 900.0, 250.0]),
            ],
        )?;
        s.optimizer.populations = 3;
        s.optimizer.particles = 15;
        s.optimizer.leader_particles = 4;
        s.optimizer.iterations = 40;
        s.optimizer.distributed.exchange_every = 4;
        let mut seen = 0;
        let out = run(&s, None, &mut |r| seen = r.iteration);
        assert_eq!((seen, out.convergence.len(), out.exchanges), (40, 40, 10));
        assert!(out.convergence.windows(2).all(|w| w[1] <= w[0]));
        let model = FleetModel::new(&s);
        let e = model.evaluate(&out.best_x);
        assert!((e.total - out.best_cost).abs() < 1e-9);
        assert_eq!(e.penalty, 0.0, "{e:?}");
        // Same seed, same plan.
        let again = run(&s, None, &mut |_| {});
        assert_eq!(again.best_x, out.best_x);
        Ok(())
    }
}
