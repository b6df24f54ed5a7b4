//! LCPSO, Hu et al. 2023, §III-A-3 (after Nkwanyana and Wang): the inertia weight blends a linearly
//! decreasing weight `w^l` (eq. (5)) and a chaotic one `w^c` (eq. (6)–(8)) driven by the logistic
//! map `u ← ρ u (1 − u)` (eq. (4)), as `w^ζ = ζ (w^l + w^c)` (eq. (9)), and particles move by
//! eq. (10) (the shared update of [`update`](crate::swarm::core::population::update) with ω = w^ζ).
//!
//! Choices the seed leaves open:
//! - ζ is not given. With ω_max = 0.9 and ω_min = 0.4, `w^l + w^c` runs from `1.4 + 0.4u` down to
//!   `0.4 + 0.4u`; ζ = 0.5 maps that onto the usual PSO range (0.7–0.9 at the start, 0.2–0.4 at
//!   the end).
//! - ρ = 4 (fully chaotic; eq. (4) requires 3.57 < ρ ≤ 4). One chaotic value `u` per iteration,
//!   shared by the swarm (ω is one number per iteration), started at a random value in (0, 1).
//! - Only the first line of eq. (9) is used: its last line is not an identity (it gives
//!   `2ω_max − ω_min u` where expanding the first line gives `ω_max + ω_min u + …`).

use rand::rngs::StdRng;
use rand::Rng;

use super::pso::PsoState;
use crate::swarm::core::population::{Coefficients, Limits, Population};
use crate::swarm::core::{Problem, Progress, Solver, SolverState};

/// The LCPSO solver.
#[derive(Debug, Clone)]
pub struct Lcpso {
    /// Swarm size M (Table 5: 60).
    pub particles: usize,
    /// Cognitive factor c1 (Table 5: 2.0).
    pub c1: f64,
    /// Social factor c2 (Table 5: 1.5).
    pub c2: f64,
    /// `(w_max, w_min)` of eq. (5)–(8) (Table 5: 0.9, 0.4).
    pub w: (f64, f64),
    /// Logistic-map parameter ρ of eq. (4).
    pub rho: f64,
    /// Blend factor ζ of eq. (9).
    pub zeta: f64,
    /// Velocity cap as a fraction of each dimension's range (not in the seed; 0.2 as for LDIW-PSO).
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl Lcpso {
    /// Table 5's PSO settings with ρ = 4 and ζ = 0.5 (see the module notes).
    pub fn table5(particles: usize, seed: u64) -> Lcpso {
        Lcpso {
            particles,
            c1: 2.0,
            c2: 1.5,
            w: (0.9, 0.4),
            rho: 4.0,
            zeta: 0.5,
            max_velocity_fraction: 0.2,
            seed,
        }
    }

    /// `w^ζ` of eq. (9) at `progress` for the chaotic value `u`:
    /// `ζ · [(w_max − Δw·t/t_max) + (Δw·(t_max − t)/t_max + w_min·u)]`.
    pub fn weight(&self, progress: Progress, u: f64) -> f64 {
        let (w_max, w_min) = self.w;
        let dw = w_max - w_min; // Hu et al. 2023, eq. (8)
        let r = progress.fraction(); // t / t_max
        let wl = w_max - dw * r; // Hu et al. 2023, eq. (5)
        let wc = dw * (1.0 - r) + w_min * u; // Hu et al. 2023, eq. (6)–(7)
        self.zeta * (wl + wc) // Hu et al. 2023, eq. (9)
    }

    /// One logistic-map step (Hu et al. 2023, eq. (4)). A value that falls onto 0, 1 or the fixed point
    /// `1 − 1/ρ` (where the map would stay forever) is replaced by a fresh random start.
    pub fn logistic(&self, u: f64, rng: &mut StdRng) -> f64 {
        let next = self.rho * u * (1.0 - u);
        let fixed = 1.0 - 1.0 / self.rho;
        if !(1e-9..=1.0 - 1e-9).contains(&next) || (next - fixed).abs() < 1e-12 {
            rng.random_range(0.01..0.99)
        } else {
            next
        }
    }
}

/// State of an LCPSO run: the swarm and the chaotic variable `u` of eq. (4).
#[derive(Debug, Clone)]
pub struct LcpsoState {
    /// The swarm, as for plain PSO.
    pub pso: PsoState,
    /// Current logistic-map value u ∈ (0, 1).
    pub u: f64,
}

impl SolverState for LcpsoState {
    fn best_cost(&self) -> f64 {
        self.pso.best_cost()
    }
    fn best_position(&self) -> &[f64] {
        self.pso.best_position()
    }
    fn evaluations(&self) -> u64 {
        self.pso.evaluations()
    }
}

impl<P: Problem> Solver<P> for Lcpso {
    type State = LcpsoState;

    fn name(&self) -> &'static str {
        "lcpso"
    }

    fn init(&mut self, problem: &P) -> LcpsoState {
        let mut population = Population::sample(problem, self.particles.max(1), self.seed);
        // "u was initialized to a random value of (0, 1)" (§III-A-3); kept off the map's
        // absorbing and fixed points by `logistic` afterwards.
        let u = population.rng.random_range(0.01..0.99);
        LcpsoState {
            pso: PsoState {
                evaluations: population.evaluations,
                population,
                limits: Limits::of(problem, self.max_velocity_fraction),
            },
            u,
        }
    }

    fn step(&mut self, problem: &P, mut state: LcpsoState, progress: Progress) -> LcpsoState {
        state.u = self.logistic(state.u, &mut state.pso.population.rng);
        let c = Coefficients {
            w: self.weight(progress, state.u),
            c1: self.c1,
            c2: self.c2,
            c3: 0.0,
        };
        let pso = &mut state.pso;
        // Hu et al. 2023, eq. (10): the usual update with ω = w^ζ.
        pso.evaluations += pso.population.step(problem, c, None, &pso.limits);
        state
    }
}

velocity_capped!(Lcpso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::Executor;
    use crate::swarm::testfns::ShiftedSphere;
    use approx::assert_abs_diff_eq;
    use rand::SeedableRng;

    #[test]
    fn blended_weight_by_hand() {
        let l = Lcpso::table5(10, 0);
        let at = |iteration| Progress {
            iteration,
            max_iterations: 400,
        };
        // t = 0, u = 0.5: w^l = 0.9, w^c = 0.5 + 0.2 = 0.7 → 0.5 · 1.6 = 0.8.
        assert_abs_diff_eq!(l.weight(at(0), 0.5), 0.8, epsilon = 1e-12);
        // t = 100: w^l = 0.9 − 0.125 = 0.775, w^c = 0.375 + 0.4·0.25 = 0.475 → 0.625.
        assert_abs_diff_eq!(l.weight(at(100), 0.25), 0.625, epsilon = 1e-12);
        // t = t_max: w^l = 0.4, w^c = 0.4 u → 0.5 (0.4 + 0.4) = 0.4 at u = 1.
        assert_abs_diff_eq!(l.weight(at(400), 1.0), 0.4, epsilon = 1e-12);
    }

    #[test]
    fn logistic_map_by_hand_and_off_its_traps() {
        let l = Lcpso::table5(10, 0);
        let mut rng = StdRng::seed_from_u64(1);
        // 4 · 0.3 · 0.7 = 0.84.
        assert_abs_diff_eq!(l.logistic(0.3, &mut rng), 0.84, epsilon = 1e-12);
        // 0.5 maps to 1 and then 0 forever; the fixed point 0.75 maps to itself: both re-drawn.
        for trap in [0.5, 0.75] {
            let u = l.logistic(trap, &mut rng);
            assert!((0.01..0.99).contains(&u) && (u - 0.75).abs() > 1e-12, "{u}");
        }
    }

    #[test]
    fn lcpso_converges_on_the_shifted_sphere() {
        let s = ShiftedSphere::new(5);
        let out = Executor::new(300).run(&s, &mut Lcpso::table5(30, 4), |_| {});
        assert!(out.state.best_cost() < 1e-6, "{}", out.state.best_cost());
        for (x, opt) in out.state.best_position().iter().zip(&s.shift) {
            assert_abs_diff_eq!(*x, *opt, epsilon = 1e-3);
        }
    }

    #[test]
    fn lcpso_same_seed_same_result() {
        let s = ShiftedSphere::new(4);
        let run = |seed| Executor::new(40).run(&s, &mut Lcpso::table5(20, seed), |_| {});
        let (a, b, c) = (run(9), run(9), run(10));
        assert_eq!(a.convergence, b.convergence);
        assert_eq!(a.state.best_position(), b.state.best_position());
        assert_eq!(a.state.u, b.state.u);
        assert_ne!(a.state.best_position(), c.state.best_position());
    }
}
