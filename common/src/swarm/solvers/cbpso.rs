//! CBPSO, Lu et al.'s chaos-based PSO baseline (Table 4 / Table 8: c1 = c2 = 2, ω from 0.9 down
//! to 0.4, μ = 4): the initial swarm comes from the logistic map `z ← μ z (1 − z)` instead of
//! uniform draws — one chaotic sequence per dimension, seeded from the run's RNG — and the
//! inertia weight falls linearly over the run. Moves are eq. (5) of the shared update.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::pso::PsoState;
use crate::swarm::core::population::{Coefficients, Particle, Population};
use crate::swarm::core::{Problem, Progress, Solver};

/// The CBPSO solver.
#[derive(Debug, Clone)]
pub struct Cbpso {
    /// Particles.
    pub particles: usize,
    /// c1 = c2.
    pub c: f64,
    /// ω at the first and at the last iteration.
    pub w: (f64, f64),
    /// Logistic-map parameter μ (4: fully chaotic).
    pub mu: f64,
    /// Velocity cap as a fraction of each dimension's range.
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl Cbpso {
    /// Table 8's settings.
    pub fn table8(particles: usize, seed: u64) -> Cbpso {
        Cbpso {
            particles,
            c: 2.0,
            w: (0.9, 0.4),
            mu: 4.0,
            max_velocity_fraction: 0.2,
            seed,
        }
    }

    /// `n` chaotic points in [0, 1] per dimension: the logistic map from a random start that
    /// avoids its fixed points and the 0/1 absorbing values.
    pub fn chaotic_unit_points(&self, n: usize, dim: usize, rng: &mut StdRng) -> Vec<Vec<f64>> {
        let mut z: Vec<f64> = (0..dim).map(|_| rng.random_range(0.01..0.99)).collect();
        (0..n)
            .map(|_| {
                for zd in &mut z {
                    *zd = self.mu * *zd * (1.0 - *zd);
                    if !(1e-9..=1.0 - 1e-9).contains(zd) || (*zd - 0.75).abs() < 1e-12 {
                        *zd = rng.random_range(0.01..0.99);
                    }
                }
                z.clone()
            })
            .collect()
    }
}

impl<P: Problem> Solver<P> for Cbpso {
    type State = PsoState;

    fn name(&self) -> &'static str {
        "cbpso"
    }

    fn init(&mut self, problem: &P) -> PsoState {
        let mut rng = StdRng::seed_from_u64(self.seed);
        let (lo, hi) = (problem.lower(), problem.upper());
        let particles: Vec<Particle> = self
            .chaotic_unit_points(self.particles.max(1), problem.dim(), &mut rng)
            .into_iter()
            .map(|z| {
                let x = z
                    .iter()
                    .zip(lo.iter().zip(hi))
                    .map(|(z, (l, h))| l + z * (h - l))
                    .collect();
                Particle::new(problem, x)
            })
            .collect();
        let population = Population::from_particles(problem, particles, rng);
        PsoState::of(problem, population, self.max_velocity_fraction)
    }

    fn step(&mut self, problem: &P, mut state: PsoState, progress: Progress) -> PsoState {
        let r = progress.fraction();
        let c = Coefficients {
            w: self.w.0 + (self.w.1 - self.w.0) * r,
            c1: self.c,
            c2: self.c,
            c3: 0.0,
        };
        state.evaluations += state.population.step(problem, c, None, &state.limits);
        state
    }
}

velocity_capped!(Cbpso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::{Executor, SolverState};
    use crate::swarm::testfns::ShiftedSphere;

    #[test]
    fn the_logistic_map_fills_the_unit_interval() {
        let c = Cbpso::table8(10, 1);
        let mut rng = StdRng::seed_from_u64(3);
        let pts = c.chaotic_unit_points(2000, 1, &mut rng);
        assert!(pts.iter().all(|p| p[0] > 0.0 && p[0] < 1.0));
        // μ = 4 visits the whole interval: every tenth of it is hit.
        for k in 0..10 {
            let lo = k as f64 / 10.0;
            assert!(pts.iter().any(|p| p[0] >= lo && p[0] < lo + 0.1), "bin {k}");
        }
        // One step of the map by hand: 4 · 0.3 · 0.7 = 0.84.
        let mut z = 0.3;
        z = c.mu * z * (1.0 - z);
        assert!((z - 0.84).abs() < 1e-12);
    }

    #[test]
    fn cbpso_converges_on_the_shifted_sphere() {
        let s = ShiftedSphere::new(5);
        let out = Executor::new(300).run(&s, &mut Cbpso::table8(30, 4), |_| {});
        assert!(out.state.best_cost() < 1e-6, "{}", out.state.best_cost());
    }
}
