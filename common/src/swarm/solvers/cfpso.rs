//! Constriction-factor PSO: Clerc, M. and Kennedy, J. (2002), "The particle swarm — explosion,
//! stability, and convergence in a multidimensional complex space", IEEE Transactions on
//! Evolutionary Computation 6(1), 58–73, doi:10.1109/4235.985692.
//!
//! The whole velocity update is multiplied by the constriction coefficient
//! χ = 2κ / |2 − φ − √(φ² − 4φ)| with κ = 1 and φ = c1 + c2 > 4:
//! v ← χ [v + c1 r1 (p − x) + c2 r2 (g − x)]. Their analysis shows the swarm then converges
//! without a velocity clamp; the usual setting c1 = c2 = 2.05 (φ = 4.1) gives χ ≈ 0.7298. It is
//! run here as the shared eq. (5) update with ω = χ and χ·c1, χ·c2, which is the same map
//! written out, and a velocity cap of the whole range (Eberhart and Shi 2000 found
//! V_max = X_max a safe companion to χ).

use crate::swarm::core::population::Coefficients;
use crate::swarm::core::{Problem, Progress, Solver};

use super::pso::PsoState;

/// φ = c1 + c2 at or below 4: χ of Clerc and Kennedy is only defined, and the swarm only
/// constricted, for φ > 4.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("constriction needs c1 + c2 > 4, got {0}")]
pub struct PhiTooSmall(pub f64);

/// Constriction-factor PSO.
#[derive(Debug, Clone)]
pub struct CfPso {
    /// Particles in the population.
    pub particles: usize,
    /// Acceleration coefficients c1, c2 before constriction (φ = c1 + c2 > 4).
    c: (f64, f64),
    /// Velocity cap as a fraction of each dimension's range.
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

/// χ = 2κ / |2 − φ − √(φ² − 4φ)| with κ = 1, for φ > 4.
pub fn constriction(phi: f64) -> f64 {
    2.0 / (2.0 - phi - (phi * phi - 4.0 * phi).sqrt()).abs()
}

impl CfPso {
    /// Clerc and Kennedy's setting: c1 = c2 = 2.05, so χ ≈ 0.7298.
    pub fn clerc_kennedy(particles: usize, seed: u64) -> CfPso {
        CfPso {
            particles,
            c: (2.05, 2.05),
            max_velocity_fraction: 1.0,
            seed,
        }
    }

    /// The same swarm with acceleration coefficients `c1`, `c2`; refused unless c1 + c2 > 4.
    pub fn with_acceleration(mut self, c1: f64, c2: f64) -> Result<CfPso, PhiTooSmall> {
        let phi = c1 + c2;
        if !(phi > 4.0 && phi.is_finite()) {
            return Err(PhiTooSmall(phi));
        }
        self.c = (c1, c2);
        Ok(self)
    }

    /// The constricted update as eq. (5) coefficients: ω = χ, χ·c1, χ·c2.
    pub fn coefficients(&self) -> Coefficients {
        let chi = constriction(self.c.0 + self.c.1);
        Coefficients {
            w: chi,
            c1: chi * self.c.0,
            c2: chi * self.c.1,
            c3: 0.0,
        }
    }
}

impl<P: Problem> Solver<P> for CfPso {
    type State = PsoState;

    fn name(&self) -> &'static str {
        "cf-pso"
    }

    fn init(&mut self, problem: &P) -> PsoState {
        PsoState::sampled(
            problem,
            self.particles,
            self.seed,
            self.max_velocity_fraction,
        )
    }

    fn step(&mut self, problem: &P, mut state: PsoState, _progress: Progress) -> PsoState {
        let c = self.coefficients();
        state.evaluations += state.population.step(problem, c, None, &state.limits);
        state
    }
}

velocity_capped!(CfPso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::{Executor, SolverState};
    use crate::swarm::testfns::ShiftedSphere;
    use approx::assert_abs_diff_eq;

    #[test]
    fn phi_of_4_1_gives_the_papers_chi() {
        assert_abs_diff_eq!(constriction(4.1), 0.7298, epsilon = 1e-4);
        let c = CfPso::clerc_kennedy(10, 1).coefficients();
        assert_abs_diff_eq!(c.w, 0.7298, epsilon = 1e-4);
        assert_abs_diff_eq!(c.c1, 0.7298 * 2.05, epsilon = 1e-3);
    }

    #[test]
    fn phi_at_or_below_4_is_refused() {
        let s = CfPso::clerc_kennedy(10, 1);
        assert_eq!(
            s.clone().with_acceleration(2.0, 2.0).err(),
            Some(PhiTooSmall(4.0))
        );
        assert!(s.clone().with_acceleration(f64::NAN, 2.0).is_err());
        assert!(s.with_acceleration(2.1, 2.1).is_ok());
    }

    #[test]
    fn converges_on_the_shifted_sphere() {
        let problem = ShiftedSphere::new(10);
        let out = Executor::new(300).run(&problem, &mut CfPso::clerc_kennedy(30, 7), |_| {});
        assert!(out.state.best_cost() < 1e-6, "{}", out.state.best_cost());
        for (a, b) in out.state.best_position().iter().zip(&problem.shift) {
            assert_abs_diff_eq!(*a, *b, epsilon = 1e-3);
        }
    }
}
