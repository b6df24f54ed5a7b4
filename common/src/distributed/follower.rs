//! One vehicle's follower populations (Zhi & Zuo 2024, §3.2.1): each moves by eq. (5) with the
//! coefficients of eq. (7) (AMP-PSO) or fixed ones (MP-PSO), on that vehicle's chromosome alone,
//! scored against the other vehicles as the current [`Context`] has them.
//!
//! When a new context arrives every personal best is re-scored in it: a memory scored next to
//! other vehicles that have since moved would otherwise keep pulling the swarm towards a place
//! that may now be in someone's way (or keep it away from one that is now free).

use std::sync::Arc;

use super::{Chromosome, Context};
use crate::cost::FleetModel;
use crate::scenario::OptimizerSettings;
use crate::swarm::catalog;
use crate::swarm::multi::AMP_PSO_VELOCITY_CAP;
use crate::swarm::parallel;
use crate::swarm::population::{stream_seed, Limits, Particle, Population, Schedule};
use crate::swarm::{Problem, Progress};
use crate::vehicle_problem::VehicleProblem;

/// What a vehicle's followers need to know besides the model.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowerSettings {
    /// Follower populations for this vehicle.
    pub populations: usize,
    /// Particles per population.
    pub particles: usize,
    /// Adaptive (AMP-PSO, eq. 7) or fixed (MP-PSO, Table 5) coefficients.
    pub schedule: Schedule,
    /// Velocity cap as a fraction of each gene's range.
    pub max_velocity_fraction: f64,
    /// Threads stepping the populations (results do not depend on it).
    pub threads: usize,
    /// The run's seed; each vehicle and population draws its own stream from it.
    pub seed: u64,
}

impl FollowerSettings {
    /// The followers' settings a scenario's optimizer settings give: each vehicle runs
    /// `distributed.agent_populations` populations.
    pub fn of(o: &OptimizerSettings) -> FollowerSettings {
        FollowerSettings {
            populations: o.distributed.agent_populations,
            particles: o.particles,
            schedule: catalog::schedule(o.algorithm),
            max_velocity_fraction: o.velocity_cap(AMP_PSO_VELOCITY_CAP),
            threads: o.threads,
            seed: o.seed,
        }
    }
}

/// Seed of population `k` of vehicle `vehicle`: distinct from every other vehicle's and from the
/// leader's streams.
fn population_seed(seed: u64, vehicle: usize, k: usize) -> u64 {
    stream_seed(seed, 1_000_003 * (vehicle as u64 + 1) + k as u64)
}

/// Vehicle `vehicle`'s chromosome against `context`.
fn problem_of<'a>(model: &'a FleetModel, vehicle: usize, context: &Context) -> VehicleProblem<'a> {
    VehicleProblem::new(model, vehicle, &context.trajectories, context.arrival)
}

/// A vehicle's follower populations and the context they are scored in.
#[derive(Debug, Clone)]
pub struct Followers {
    model: Arc<FleetModel>,
    vehicle: usize,
    settings: FollowerSettings,
    context: Context,
    populations: Vec<Population>,
    limits: Limits,
    /// Cost evaluations so far.
    pub evaluations: u64,
    /// Iterations stepped so far.
    pub iterations: usize,
}

impl Followers {
    /// Samples and scores `settings.populations` populations for vehicle `vehicle` (scenario
    /// order) in `context`.
    pub fn new(
        model: Arc<FleetModel>,
        vehicle: usize,
        settings: FollowerSettings,
        context: Context,
    ) -> Followers {
        let problem = problem_of(&model, vehicle, &context);
        let limits = Limits::of(&problem, settings.max_velocity_fraction);
        let ks: Vec<usize> = (0..settings.populations.max(1)).collect();
        let populations = parallel::map(&ks, settings.threads, |&k| {
            Population::sample(
                &problem,
                settings.particles.max(1),
                population_seed(settings.seed, vehicle, k),
            )
        });
        let evaluations = populations.iter().map(|p| p.evaluations).sum();
        Followers {
            model,
            vehicle,
            settings,
            context,
            populations,
            limits,
            evaluations,
            iterations: 0,
        }
    }

    /// Followers that take over from an agent that is gone (degraded mode): fresh populations
    /// whose first particles are the chromosomes the agent last sent.
    pub fn resume(
        model: Arc<FleetModel>,
        vehicle: usize,
        settings: FollowerSettings,
        context: Context,
        last_elites: &[Chromosome],
        iterations_done: usize,
    ) -> Followers {
        let mut f = Followers::new(model, vehicle, settings, context);
        f.iterations = iterations_done;
        f.immigrate_all(last_elites.iter().cloned().enumerate());
        f
    }

    /// Which vehicle (scenario order).
    pub fn vehicle(&self) -> usize {
        self.vehicle
    }

    /// The context the followers are scored in.
    pub fn context(&self) -> &Context {
        &self.context
    }

    /// One eq. (5) iteration of every population.
    pub fn step(&mut self, progress: Progress) {
        let problem = problem_of(&self.model, self.vehicle, &self.context);
        let c = self.settings.schedule.at(progress);
        let limits = &self.limits;
        let before: u64 = self.populations.iter().map(|p| p.evaluations).sum();
        parallel::for_each_mut(&mut self.populations, self.settings.threads, |pop| {
            pop.step(&problem, c, None, limits);
        });
        let after: u64 = self.populations.iter().map(|p| p.evaluations).sum();
        self.evaluations += after - before;
        self.iterations += 1;
    }

    /// Each population's best chromosome (its global best o_gbest), the emigrants of Fig. 5a.
    pub fn emigrants(&self) -> Vec<Chromosome> {
        self.populations
            .iter()
            .filter_map(|pop| {
                pop.particles
                    .iter()
                    .min_by(|a, b| a.best_cost.total_cmp(&b.best_cost))
                    .map(|p| Chromosome {
                        x: p.best_x.clone(),
                        v: p.v.clone(),
                    })
            })
            .collect()
    }

    /// An updated immigrant returns to population `k` (Fig. 5c): scored in the current context,
    /// it replaces the population's worst particle. Out-of-range genes are clamped to the box.
    pub fn immigrate(&mut self, k: usize, c: Chromosome) {
        self.immigrate_all([(k, c)]);
    }

    /// Immigrants `(population, chromosome)` in one go: the problem in the current context is
    /// built once for the whole batch (an exchange returns one migrant per population).
    pub fn immigrate_all(&mut self, migrants: impl IntoIterator<Item = (usize, Chromosome)>) {
        let problem = problem_of(&self.model, self.vehicle, &self.context);
        let dim = problem.dim();
        let n = self.populations.len();
        for (k, c) in migrants {
            if c.x.len() != dim || c.v.len() != dim || n == 0 {
                continue;
            }
            let x: Vec<f64> =
                c.x.iter()
                    .zip(problem.lower().iter().zip(problem.upper()))
                    .map(|(g, (lo, hi))| {
                        if g.is_finite() {
                            g.clamp(*lo, *hi)
                        } else {
                            *lo
                        }
                    })
                    .collect();
            let mut p = Particle::new(&problem, x);
            p.v =
                c.v.iter()
                    .zip(&self.limits.vmax)
                    .map(|(v, m)| if v.is_finite() { v.clamp(-m, *m) } else { 0.0 })
                    .collect();
            let pop = &mut self.populations[k % n];
            let worst = pop.worst();
            pop.particles[worst] = p;
            pop.evaluations += 1;
            self.evaluations += 1 + pop.refresh(&problem);
        }
    }

    /// Scores every memory in a new context (see the module notes). A context from an older
    /// round than the current one is ignored.
    pub fn set_context(&mut self, context: Context) {
        if context.round < self.context.round
            || context.trajectories.len() != self.context.trajectories.len()
        {
            return;
        }
        self.context = context;
        let problem = problem_of(&self.model, self.vehicle, &self.context);
        let before: u64 = self.populations.iter().map(|p| p.evaluations).sum();
        parallel::for_each_mut(&mut self.populations, self.settings.threads, |pop| {
            for p in &mut pop.particles {
                let best = problem.cost(&p.best_x);
                p.best_parts = vec![best];
                p.best_cost = best;
                // The current position is scored again at the next move; until then it ranks
                // (for replacement by an immigrant) no better than its memory.
                p.cost = p.cost.max(best);
            }
            pop.evaluations += pop.particles.len() as u64;
            pop.elite_cost = f64::INFINITY;
            pop.refresh(&problem);
        });
        let after: u64 = self.populations.iter().map(|p| p.evaluations).sum();
        self.evaluations += after - before;
    }

    /// The best chromosome of all populations with its cost in the current context.
    pub fn best(&self) -> Option<(Vec<f64>, f64)> {
        self.populations
            .iter()
            .flat_map(|p| p.particles.iter())
            .min_by(|a, b| a.best_cost.total_cmp(&b.best_cost))
            .map(|p| (p.best_x.clone(), p.best_cost))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;
    use crate::scenario::Scenario;

    fn crossing() -> Result<Scenario, crate::scenario::ScenarioError> {
        fixtures::scenario(
            800.0,
            "",
            &[
                fixtures::vehicle_toml("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0]),
                fixtures::vehicle_toml("b", [500.0, 100.0, 250.0], [500.0, 900.0, 250.0]),
            ],
        )
    }

    fn settings(seed: u64) -> FollowerSettings {
        FollowerSettings {
            populations: 3,
            particles: 15,
            schedule: Schedule::Adaptive,
            max_velocity_fraction: 0.1,
            threads: 2,
            seed,
        }
    }

    fn straight_context(model: &FleetModel) -> Context {
        Context::of(0, &model.evaluate(&fixtures::straight_particle(model)))
    }

    #[test]
    fn followers_improve_their_vehicle_against_the_context(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let model = Arc::new(FleetModel::new(&crossing()?));
        let ctx = straight_context(&model);
        let mut f = Followers::new(Arc::clone(&model), 0, settings(4), ctx.clone());
        let start = f.best().map_or(f64::INFINITY, |b| b.1);
        for i in 0..60 {
            f.step(Progress {
                iteration: i,
                max_iterations: 60,
            });
        }
        let (x, cost) = f.best().ok_or("no particles")?;
        assert!(cost <= start, "{cost} > {start}");
        // The memory's cost is the true cost of its chromosome in the context, and the vehicle
        // keeps out of b's way (b crosses the centre on its straight line).
        let p = VehicleProblem::new(&model, 0, &ctx.trajectories, ctx.arrival);
        let e = p.evaluate(&x);
        assert!((e.total - cost).abs() < 1e-9);
        assert!(e.min_separation >= 50.0, "{}", e.min_separation);
        assert_eq!(f.iterations, 60);
        assert_eq!(f.emigrants().len(), 3);
        Ok(())
    }

    #[test]
    fn same_seed_same_followers_whatever_the_threads() -> Result<(), Box<dyn std::error::Error>> {
        let model = Arc::new(FleetModel::new(&crossing()?));
        let ctx = straight_context(&model);
        let run = |threads| {
            let mut s = settings(8);
            s.threads = threads;
            let mut f = Followers::new(Arc::clone(&model), 1, s, ctx.clone());
            for i in 0..10 {
                f.step(Progress {
                    iteration: i,
                    max_iterations: 10,
                });
            }
            f.emigrants()
        };
        assert_eq!(run(1), run(3));
        Ok(())
    }

    #[test]
    fn a_new_context_rescores_the_memories() -> Result<(), Box<dyn std::error::Error>> {
        let model = Arc::new(FleetModel::new(&crossing()?));
        // Context 1: b far away in time (it is the straight plan, so a and b meet at the centre).
        let meet = straight_context(&model);
        let mut f = Followers::new(Arc::clone(&model), 0, settings(2), meet.clone());
        // Context 2: b's trajectory moved 300 m east, out of a's straight path's way... except
        // that a's chromosome is unchanged, so only the coupling terms of the memories change.
        let mut away = meet.clone();
        away.round = 1;
        for p in &mut away.trajectories[1].points {
            p.x += 300.0;
        }
        let before = f.best().ok_or("empty")?;
        f.set_context(away.clone());
        let after = f.best().ok_or("empty")?;
        let p = VehicleProblem::new(&model, 0, &away.trajectories, away.arrival);
        assert!((p.cost(&after.0) - after.1).abs() < 1e-9);
        assert_ne!(before.1, after.1);
        // An older context is ignored.
        f.set_context(meet);
        assert_eq!(f.context().round, 1);
        Ok(())
    }

    #[test]
    fn an_immigrant_replaces_the_worst_and_bad_genes_are_clamped(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let model = Arc::new(FleetModel::new(&crossing()?));
        let ctx = straight_context(&model);
        let mut f = Followers::new(Arc::clone(&model), 0, settings(5), ctx.clone());
        let dim = model.layout.chromosome_len();
        // The straight chromosome of vehicle a, with one NaN and one far-out gene.
        let mut x = fixtures::straight_particle(&model)[..dim].to_vec();
        let good = x.clone();
        x[0] = f64::NAN;
        x[1] = 1e9;
        f.immigrate(
            0,
            Chromosome {
                x,
                v: vec![f64::INFINITY; dim],
            },
        );
        let pop = &f.populations[0];
        let found = pop
            .particles
            .iter()
            .find(|p| p.x[2..] == good[2..])
            .ok_or("immigrant not in population 0")?;
        assert!(found.x.iter().all(|g| g.is_finite()));
        assert!(found.v.iter().all(|v| v.is_finite()));
        assert_eq!(found.x[1], model.upper[1]);
        // A chromosome of the wrong length is ignored.
        let n = f.evaluations;
        f.immigrate(
            1,
            Chromosome {
                x: vec![0.0; 3],
                v: vec![0.0; 3],
            },
        );
        assert_eq!(f.evaluations, n);
        Ok(())
    }
}
