//! Single-population PSO: classic PSO (fixed ω = 0.15, c1 = c2 = 1.5, Zhi & Zuo 2024, Table 5) and
//! A-PSO (the adaptive coefficients of eq. (7)), both updating by eq. (5).

use crate::swarm::core::population::{Limits, Population, Schedule};
use crate::swarm::core::{Problem, Progress, Solver, SolverState};

/// Single-population PSO.
#[derive(Debug, Clone)]
pub struct Pso {
    /// Particles in the population (Table 5: 50).
    pub particles: usize,
    /// Fixed or adaptive coefficients.
    pub schedule: Schedule,
    /// Velocity cap as a fraction of each dimension's range.
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl Pso {
    /// Classic PSO with Table 5's coefficients.
    pub fn classic(particles: usize, seed: u64) -> Pso {
        Pso {
            particles,
            schedule: Schedule::TABLE5_FIXED,
            max_velocity_fraction: super::multi::AMP_PSO_VELOCITY_CAP,
            seed,
        }
    }

    /// SPSO, Lu et al.'s standard PSO baseline (Table 4 / Table 8): ω = 0.5, c1 = c2 = 2.
    pub fn spso(particles: usize, seed: u64) -> Pso {
        Pso {
            schedule: Schedule::Fixed(crate::swarm::core::population::Coefficients {
                w: 0.5,
                c1: 2.0,
                c2: 2.0,
                c3: 0.0,
            }),
            max_velocity_fraction: 0.2,
            ..Pso::classic(particles, seed)
        }
    }

    /// A-PSO: one population with eq. (7).
    pub fn adaptive(particles: usize, seed: u64) -> Pso {
        Pso {
            schedule: Schedule::Adaptive,
            ..Pso::classic(particles, seed)
        }
    }
}

/// State of a single-population run.
#[derive(Debug, Clone)]
pub struct PsoState {
    /// The population.
    pub population: Population,
    /// Box and velocity limits.
    pub limits: Limits,
    /// Evaluations so far.
    pub evaluations: u64,
}

impl PsoState {
    /// A population of `particles` (at least one) from the problem's sampler, evaluated, with
    /// velocities capped at `max_velocity_fraction` of each range: the start every
    /// single-population variant shares.
    pub fn sampled<P: Problem>(
        problem: &P,
        particles: usize,
        seed: u64,
        max_velocity_fraction: f64,
    ) -> PsoState {
        PsoState::of(
            problem,
            Population::sample(problem, particles.max(1), seed),
            max_velocity_fraction,
        )
    }

    /// The state of an evaluated `population` (a chaotic start, a run's own start), with
    /// velocities capped at `max_velocity_fraction` of each range.
    pub fn of<P: Problem>(
        problem: &P,
        population: Population,
        max_velocity_fraction: f64,
    ) -> PsoState {
        PsoState {
            evaluations: population.evaluations,
            population,
            limits: Limits::of(problem, max_velocity_fraction),
        }
    }
}

impl SolverState for PsoState {
    fn best_cost(&self) -> f64 {
        self.population.elite_cost
    }
    fn best_position(&self) -> &[f64] {
        &self.population.elite_x
    }
    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

impl<P: Problem> Solver<P> for Pso {
    type State = PsoState;

    fn name(&self) -> &'static str {
        match self.schedule {
            Schedule::Adaptive => "a-pso",
            Schedule::Fixed(_) => "pso",
        }
    }

    fn init(&mut self, problem: &P) -> PsoState {
        PsoState::sampled(
            problem,
            self.particles,
            self.seed,
            self.max_velocity_fraction,
        )
    }

    fn step(&mut self, problem: &P, mut state: PsoState, progress: Progress) -> PsoState {
        let c = self.schedule.at(progress);
        state.evaluations += state.population.step(problem, c, None, &state.limits);
        state
    }
}

velocity_capped!(Pso);
