//! LDIW-PSO, Hu et al. 2023, §III-A-2: PSO whose inertia weight falls linearly from `w_ini` to `w_end`
//! over the run (eq. (3), after Shi and Eberhart), moving by the shared update of
//! [`update`](crate::swarm::core::population::update). It is the seed's baseline for leg planning (Table 6) and the
//! inertia schedule DE-PSO reuses.
//!
//! The seed gives no separate settings for its baselines; [`LdiwPso::table5`] uses the PSO part of
//! Table 5 (c1 = 2.0, c2 = 1.5, ω 0.9 → 0.4) so the three leg planners differ only in their
//! mechanism.

use super::pso::PsoState;
use crate::swarm::core::population::Coefficients;
use crate::swarm::core::{Problem, Progress, Solver};

/// Inertia weight of Hu et al. 2023, eq. (3): `w(k) = (T_max − T)/T_max · (w_ini − w_end) + w_end`,
/// with `T / T_max` taken from `progress` (so `w_ini` at the first iteration, approaching `w_end`
/// at the last).
pub fn ldiw_weight(w_ini: f64, w_end: f64, progress: Progress) -> f64 {
    // Hu et al. 2023, eq. (3)
    (1.0 - progress.fraction()) * (w_ini - w_end) + w_end
}

/// The LDIW-PSO solver.
#[derive(Debug, Clone)]
pub struct LdiwPso {
    /// Swarm size M (Table 5: 60).
    pub particles: usize,
    /// Cognitive factor c1 (Table 5: 2.0).
    pub c1: f64,
    /// Social factor c2 (Table 5: 1.5).
    pub c2: f64,
    /// `(w_ini, w_end)` of eq. (3) (Table 5: 0.9 → 0.4).
    pub w: (f64, f64),
    /// Velocity cap as a fraction of each dimension's range. Not in the seed; 0.2 as for the
    /// other baselines (CBPSO, IPSO), so a particle cannot cross the box in one step.
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl LdiwPso {
    /// Table 5's PSO settings (Hu et al. 2023): c1 = 2.0, c2 = 1.5, ω 0.9 → 0.4.
    pub fn table5(particles: usize, seed: u64) -> LdiwPso {
        LdiwPso {
            particles,
            c1: 2.0,
            c2: 1.5,
            w: (0.9, 0.4),
            max_velocity_fraction: 0.2,
            seed,
        }
    }
}

/// One PSO move of the whole population with the eq. (3) inertia (`w` from its start to its
/// end value) and learning factors `c`; the move DE-PSO also makes before its DE pass.
pub fn ldiw_move<P: Problem>(
    problem: &P,
    state: &mut PsoState,
    w: (f64, f64),
    (c1, c2): (f64, f64),
    progress: Progress,
) {
    let c = Coefficients {
        w: ldiw_weight(w.0, w.1, progress),
        c1,
        c2,
        c3: 0.0,
    };
    state.evaluations += state.population.step(problem, c, None, &state.limits);
}

impl<P: Problem> Solver<P> for LdiwPso {
    type State = PsoState;

    fn name(&self) -> &'static str {
        "ldiw-pso"
    }

    fn init(&mut self, problem: &P) -> PsoState {
        // Hu et al. 2023, eq. (14): uniform initial positions (or the problem's own sampler).
        PsoState::sampled(
            problem,
            self.particles,
            self.seed,
            self.max_velocity_fraction,
        )
    }

    fn step(&mut self, problem: &P, mut state: PsoState, progress: Progress) -> PsoState {
        ldiw_move(problem, &mut state, self.w, (self.c1, self.c2), progress);
        state
    }
}

velocity_capped!(LdiwPso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::{Executor, SolverState};
    use crate::swarm::testfns::ShiftedSphere;
    use approx::assert_abs_diff_eq;

    fn at(iteration: usize, max_iterations: usize) -> Progress {
        Progress {
            iteration,
            max_iterations,
        }
    }

    #[test]
    fn inertia_falls_linearly_by_eq_3() {
        assert_abs_diff_eq!(ldiw_weight(0.9, 0.4, at(0, 400)), 0.9, epsilon = 1e-12);
        // A quarter of the way: 0.75 · 0.5 + 0.4 = 0.775.
        assert_abs_diff_eq!(ldiw_weight(0.9, 0.4, at(100, 400)), 0.775, epsilon = 1e-12);
        assert_abs_diff_eq!(ldiw_weight(0.9, 0.4, at(400, 400)), 0.4, epsilon = 1e-12);
    }

    #[test]
    fn ldiw_pso_converges_on_the_shifted_sphere() {
        let s = ShiftedSphere::new(5);
        let out = Executor::new(300).run(&s, &mut LdiwPso::table5(30, 4), |_| {});
        assert!(out.state.best_cost() < 1e-6, "{}", out.state.best_cost());
        for (x, opt) in out.state.best_position().iter().zip(&s.shift) {
            assert_abs_diff_eq!(*x, *opt, epsilon = 1e-3);
        }
        assert_eq!(out.state.evaluations(), 30 * 301);
    }

    #[test]
    fn ldiw_pso_same_seed_same_result() {
        let s = ShiftedSphere::new(4);
        let run = |seed| Executor::new(40).run(&s, &mut LdiwPso::table5(20, seed), |_| {});
        let (a, b, c) = (run(9), run(9), run(10));
        assert_eq!(a.convergence, b.convergence);
        assert_eq!(a.state.best_position(), b.state.best_position());
        assert_ne!(a.state.best_position(), c.state.best_position());
    }
}
