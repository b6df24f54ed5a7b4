//! A new way for a vehicle the refinement leaves late: a local search keeps the way round the
//! obstacles the swarm chose, and some of those ways are longer than the vehicle can swim by
//! the mission time. A fresh search of that one vehicle (its own AMP-PSO of four follower
//! populations, as the touch-up's fresh try and a vehicle agent run) against the others timed
//! for the target arrival, with lateness past it paid like a breach, finds another way round;
//! the refinement then pulls that one tight too.

use rand::rngs::StdRng;

use crate::cost::FleetModel;
use crate::swarm::multi::MultiPso;
use crate::swarm::population::stream_seed;
use crate::swarm::{Executor, Problem, SolverState};
use crate::trajectory::{retime, Trajectory};
use crate::vehicle_problem::VehicleProblem;

/// Follower populations of the fresh search.
const POPULATIONS: usize = 4;
/// Its iterations: about 35 000 evaluations of one vehicle, as the touch-up's fresh try.
const ITERATIONS: usize = 150;

/// Vehicle `i`'s chromosome against the others, with `weight × lateness / target` added.
struct OnTime<'a> {
    inner: VehicleProblem<'a>,
    target: f64,
    weight: f64,
}

impl Problem for OnTime<'_> {
    fn lower(&self) -> &[f64] {
        self.inner.lower()
    }

    fn upper(&self) -> &[f64] {
        self.inner.upper()
    }

    fn cost(&self, x: &[f64]) -> f64 {
        let e = self.inner.evaluate(x);
        let late = (e.trajectory.arrival() - self.target).max(0.0) / self.target;
        e.total + self.weight * late
    }

    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        self.inner.move_groups()
    }

    fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        self.inner.sample(rng)
    }
}

/// A fresh chromosome for vehicle `i` of fleet position `x`, aiming at `target`; returns it
/// and the evaluations spent.
pub fn fresh_route(
    model: &FleetModel,
    x: &[f64],
    i: usize,
    target: f64,
    executor: &Executor,
) -> (Vec<f64>, u64) {
    let s = &model.scenario;
    // The others as they would swim if the fleet arrived on time.
    let context: Vec<Trajectory> = (0..model.layout.vehicles)
        .map(|j| {
            let path = model.decode(j, &x[model.layout.chromosome(j)]);
            retime(&path, &s.vehicles[j], target)
        })
        .collect();
    let problem = OnTime {
        inner: VehicleProblem::new(model, i, &context, target),
        target,
        weight: s.optimizer.penalty_weight,
    };
    let mut solver = MultiPso {
        populations: POPULATIONS,
        max_velocity_fraction: s
            .optimizer
            .velocity_cap(crate::swarm::multi::AMP_PSO_VELOCITY_CAP),
        ..MultiPso::amp(stream_seed(s.optimizer.seed, 9_000_001 + i as u64))
    };
    let executor = Executor {
        max_iterations: ITERATIONS,
        ..executor.clone()
    };
    let out = executor.run(&problem, &mut solver, |_| {});
    (out.state.best_position().to_vec(), out.state.evaluations())
}
