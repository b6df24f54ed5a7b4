//! DE-PSO, Hu et al. 2023, §IV-A: PSO with a differential-evolution pass after every move.
//!
//! One iteration:
//! 1. every particle moves by eq. (18)–(19) with the LDIW inertia of eq. (3) (Table 5: ω 0.9 →
//!    0.4, c1 = 2.0, c2 = 1.5 — the c3, c4 of eq. (18)) and is evaluated;
//! 2. for every particle a mutant is built by DE/best/1 (eq. (15)) with a *separate* random pair
//!    of particles per axis (eq. (20): `x_a1 − x_b1` for x, `x_a2 − x_b2` for y, …);
//! 3. binomial crossover per axis (Step 5: one random number `C` per axis, the mutant's axis taken
//!    when `C < CR`);
//! 4. greedy selection (eq. (17)): the trial replaces the particle when its cost is not worse;
//!    personal and global bests are then updated (Step 6).
//!
//! An "axis" is one group of [`Problem::move_groups`]: one dimension for a textbook function, one
//! coordinate axis of a whole path for the tours' `LegProblem` (its x's, its y's, its z's),
//! which is eq. (20) literally.
//!
//! Boundary absorption (eq. (30), second case): a coordinate that leaves the box is put on the
//! boundary. The seed says nothing of the velocity; it is zeroed, as the shared PSO update does,
//! so an absorbed particle does not keep pushing outwards.
//!
//! Choices the seed leaves open:
//! - Eq. (15) names DE/best/1/bin, eq. (20) writes the particle itself as the base vector; the
//!   base is a field ([`MutationBase`]) and Table 5's solver uses the best (eq. (15)).
//! - Standard binomial crossover forces one axis from the mutant (`j_rand`), so a trial is never a
//!   copy of its target; Step 5 does not mention it, but without it a third of the three-axis
//!   trials at CR = 0.6 would waste an evaluation.
//! - The random pair of an axis is two distinct particles other than the target (eq. (20) draws
//!   "six particles" without saying whether they may repeat); with fewer than three particles the
//!   DE pass is skipped.

use rand::Rng;

use super::ldiwpso::ldiw_move;
use super::pso::PsoState;
use crate::swarm::core::population::Population;
use crate::swarm::core::{Problem, Progress, Solver};

/// Base vector of the DE mutation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MutationBase {
    /// The swarm's global best, DE/best/1 (Hu et al. 2023, eq. (15)).
    Best,
    /// The target particle itself (Hu et al. 2023, eq. (20) as printed).
    Target,
}

/// The DE-PSO solver.
#[derive(Debug, Clone)]
pub struct DePso {
    /// Swarm size M (Table 5: 60).
    pub particles: usize,
    /// Cognitive factor (c3 of eq. (18); Table 5's c1 = 2.0).
    pub c1: f64,
    /// Social factor (c4 of eq. (18); Table 5's c2 = 1.5).
    pub c2: f64,
    /// `(w_init, w_end)` of the inertia schedule, eq. (3) (Table 5: 0.9 → 0.4).
    pub w: (f64, f64),
    /// Scaling factor F of eq. (15)/(20) (Table 5: 0.8).
    pub f: f64,
    /// Crossover rate CR of Step 5 (Table 5: 0.6).
    pub cr: f64,
    /// Base vector of the mutation.
    pub base: MutationBase,
    /// Velocity cap as a fraction of each dimension's range (not in the seed; 0.2 as for the
    /// other baselines).
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl DePso {
    /// Table 5's settings (Hu et al. 2023): c1 = 2.0, c2 = 1.5, ω 0.9 → 0.4, F = 0.8, CR = 0.6,
    /// DE/best/1/bin. The table's M = 60 and 400 iterations are the caller's `particles` and the
    /// executor's budget.
    pub fn table5(particles: usize, seed: u64) -> DePso {
        DePso {
            particles,
            c1: 2.0,
            c2: 1.5,
            w: (0.9, 0.4),
            f: 0.8,
            cr: 0.6,
            base: MutationBase::Best,
            max_velocity_fraction: 0.2,
            seed,
        }
    }

    /// Mutation, crossover and selection for every particle (Steps 4–6). Returns evaluations.
    fn de_pass<P: Problem>(&self, problem: &P, state: &mut PsoState) -> u64 {
        let limits = &state.limits;
        let pop: &mut Population = &mut state.population;
        let n = pop.particles.len();
        if n < 3 || limits.groups.is_empty() {
            return 0;
        }
        let mut evaluations = 0;
        for i in 0..n {
            let target = &pop.particles[i];
            let base = match self.base {
                MutationBase::Best if pop.gbest.len() == target.x.len() => &pop.gbest,
                _ => &target.x,
            };
            let mut trial = target.x.clone();
            let forced = pop.rng.random_range(0..limits.groups.len());
            for (g, range) in limits.groups.iter().enumerate() {
                // Step 5: one crossover draw per axis.
                let crossed = pop.rng.random::<f64>() < self.cr || g == forced;
                if !crossed {
                    continue;
                }
                let a = pick_other(&mut pop.rng, n, &[i]);
                let b = pick_other(&mut pop.rng, n, &[i, a]);
                let (xa, xb) = (&pop.particles[a].x, &pop.particles[b].x);
                for d in range.clone() {
                    // Hu et al. 2023, eq. (15) / (20)
                    trial[d] = base[d] + self.f * (xa[d] - xb[d]);
                }
            }
            // Hu et al. 2023, eq. (30), feasible-area case: absorb onto the box.
            let mut absorbed = Vec::new();
            for (d, x) in trial.iter_mut().enumerate() {
                if *x < limits.lower[d] {
                    *x = limits.lower[d];
                    absorbed.push(d);
                } else if *x > limits.upper[d] {
                    *x = limits.upper[d];
                    absorbed.push(d);
                }
            }
            let mut candidate = pop.particles[i].clone();
            candidate.x = trial;
            candidate.evaluate(problem);
            evaluations += 1;
            // Hu et al. 2023, eq. (17): keep the trial unless it is worse.
            if candidate.cost <= pop.particles[i].cost {
                for d in absorbed {
                    candidate.v[d] = 0.0;
                }
                pop.particles[i] = candidate;
            }
        }
        pop.evaluations += evaluations;
        evaluations + pop.refresh(problem)
    }
}

/// A uniformly random index in `0..n` not in `exclude` (`n > exclude.len()` is required; when it
/// does not hold the first index is returned).
fn pick_other(rng: &mut rand::rngs::StdRng, n: usize, exclude: &[usize]) -> usize {
    let free = n.saturating_sub(exclude.len());
    if free == 0 {
        return 0;
    }
    let mut k = rng.random_range(0..free);
    // Walk past the excluded indices in increasing order.
    let mut sorted = exclude.to_vec();
    sorted.sort_unstable();
    for e in sorted {
        if k >= e {
            k += 1;
        }
    }
    k
}

impl<P: Problem> Solver<P> for DePso {
    type State = PsoState;

    fn name(&self) -> &'static str {
        "de-pso"
    }

    fn init(&mut self, problem: &P) -> PsoState {
        // Step 1, Hu et al. 2023, eq. (14): random initial positions (the problem's sampler).
        PsoState::sampled(
            problem,
            self.particles,
            self.seed,
            self.max_velocity_fraction,
        )
    }

    fn step(&mut self, problem: &P, mut state: PsoState, progress: Progress) -> PsoState {
        // Step 3, Hu et al. 2023, eq. (18)–(19) with the eq. (3) inertia.
        ldiw_move(problem, &mut state, self.w, (self.c1, self.c2), progress);
        // Steps 4–6.
        state.evaluations += self.de_pass(problem, &mut state);
        state
    }
}

velocity_capped!(DePso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::{Executor, SolverState};
    use crate::swarm::testfns::{Rastrigin, ShiftedSphere};
    use approx::assert_abs_diff_eq;
    use rand::SeedableRng;

    #[test]
    fn pick_other_skips_the_excluded_and_is_uniform_over_the_rest() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let mut seen = [0usize; 5];
        for _ in 0..5000 {
            let k = pick_other(&mut rng, 5, &[3, 1]);
            assert!(k != 1 && k != 3 && k < 5, "{k}");
            seen[k] += 1;
        }
        for k in [0, 2, 4] {
            assert!((1500..1850).contains(&seen[k]), "{seen:?}");
        }
    }

    #[test]
    fn de_pso_converges_on_the_shifted_sphere() {
        let s = ShiftedSphere::new(5);
        let out = Executor::new(200).run(&s, &mut DePso::table5(30, 4), |_| {});
        assert!(out.state.best_cost() < 1e-8, "{}", out.state.best_cost());
        for (x, opt) in out.state.best_position().iter().zip(&s.shift) {
            assert_abs_diff_eq!(*x, *opt, epsilon = 1e-4);
        }
        // M evaluations at init, then 2M per iteration (the move and the DE trial).
        assert_eq!(out.state.evaluations(), 30 + 200 * 60);
    }

    #[test]
    fn de_pso_finds_the_global_minimum_of_rastrigin() {
        // Hu et al. 2023, Table 2: DE-PSO converged on f4 in 50/50 runs.
        let r = Rastrigin::new(2);
        for seed in 0..5 {
            let out = Executor::new(200).run(&r, &mut DePso::table5(30, seed), |_| {});
            assert!(
                out.state.best_cost() < 1e-6,
                "seed {seed}: {}",
                out.state.best_cost()
            );
        }
    }

    #[test]
    fn the_target_based_mutation_of_eq_20_also_converges() {
        let s = ShiftedSphere::new(5);
        let mut de = DePso {
            base: MutationBase::Target,
            ..DePso::table5(30, 4)
        };
        let out = Executor::new(300).run(&s, &mut de, |_| {});
        assert!(out.state.best_cost() < 1e-6, "{}", out.state.best_cost());
    }

    #[test]
    fn de_pso_same_seed_same_result() {
        let s = ShiftedSphere::new(4);
        let run = |seed| Executor::new(40).run(&s, &mut DePso::table5(20, seed), |_| {});
        let (a, b, c) = (run(9), run(9), run(10));
        assert_eq!(a.convergence, b.convergence);
        assert_eq!(a.state.best_position(), b.state.best_position());
        assert_ne!(a.state.best_position(), c.state.best_position());
    }

    #[test]
    fn absorbed_positions_stay_in_the_box() {
        // The optimum (1.5, −2.5, …) lies inside; shrink the box so it lies outside in dim 0:
        // every particle must stay in the box and the best sits on the wall x0 = 1.
        let mut s = ShiftedSphere::new(3);
        s.upper[0] = 1.0;
        let out = Executor::new(100).run(&s, &mut DePso::table5(20, 2), |_| {});
        for p in &out.state.population.particles {
            for (d, x) in p.x.iter().enumerate() {
                assert!(*x >= s.lower[d] && *x <= s.upper[d], "{x} out of dim {d}");
            }
        }
        assert_abs_diff_eq!(out.state.best_position()[0], 1.0, epsilon = 1e-6);
    }
}
