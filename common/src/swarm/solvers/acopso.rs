//! ACO-PSO, Lu et al.'s ant colony + PSO hybrid baseline (ref. \[7\], Shi, Bu & Li 2008) with the
//! settings of Table 4 (functions: M = 30, t_max = 300) and Table 8 (crawler path: M = 50,
//! t_max = 100): c1 = c2 = 2, ω = 0.5, α = 1, β = 5, ρ = 0.5. Ref. \[7\] plans on a 2-D grid,
//! where ants walk from cell to cell; the seed gives no more detail and its problems are
//! continuous, so Shoal reads the hybrid with a continuous ant colony (ACO_R-style sampling,
//! Socha & Dorigo 2008) beside the swarm:
//!
//! - The swarm moves by the shared PSO update (eq. (5), ω = 0.5, c1 = c2 = 2), exactly SPSO.
//! - A pheromone archive holds the best `archive` distinct positions evaluated so far, sorted by
//!   cost; each trail j has a pheromone τ_j (new trails start at τ_0 = 1) and a heuristic
//!   desirability η_j = 1/j, j its rank. The rank, not the raw cost, because costs differ in
//!   scale and sign between the benchmark functions and the path costs (ACO_R weights by rank
//!   too); 1/j is the analogue of the 1/distance heuristic of grid ACO.
//! - Every iteration, `ant_share` of the swarm, its worst particles, each get an ant: it picks
//!   trail j with probability `p_j = τ_j^α η_j^β / Σ_k τ_k^α η_k^β` (the ant system's rule) and
//!   samples a point around it, per dimension `N(s_j, σ_j)` with `σ_j = ξ · mean_k |s_k − s_j|`
//!   (ACO_R's width: it shrinks as the archive converges). The particle jumps there only if the
//!   point is better than where it is, and keeps its velocity: zeroing it stalls the moved
//!   particles (on 2-D Rastrigin, 9 runs in 20 reached the global basin with zeroing, 17 without).
//! - Pheromone: every trail evaporates, `τ ← (1 − ρ) τ`, and each accepted ant deposits Q = 1
//!   on the trail it sampled; τ never falls below `tau_min` (a MAX–MIN ant system floor, so a
//!   trail stays selectable). Trails near which sampling pays off are chosen more often; with
//!   α = 1, β = 5 the rank still dominates, as the seed's large β implies.
//!
//! Cost: `particles + ants` evaluations per iteration (the seed compares by iterations).

use rand::rngs::StdRng;
use rand::Rng;

use super::pso::PsoState;
use crate::swarm::core::population::{Coefficients, Population};
use crate::swarm::core::{Problem, Progress, Solver, SolverState};

/// The ACO-PSO solver (Table 4 / Table 8 settings).
#[derive(Debug, Clone)]
pub struct AcoPso {
    /// Particles M (Table 4: 30, Table 8: 50).
    pub particles: usize,
    /// Inertia weight ω (0.5).
    pub w: f64,
    /// Cognitive factor c1 (2).
    pub c1: f64,
    /// Social factor c2 (2).
    pub c2: f64,
    /// Pheromone exponent α (1).
    pub alpha: f64,
    /// Heuristic exponent β (5).
    pub beta: f64,
    /// Evaporation rate ρ (0.5).
    pub rho: f64,
    /// Trails in the pheromone archive (not in the seed: one per particle).
    pub archive: usize,
    /// Share of the swarm, worst first, that gets an ant each iteration (not in the seed).
    pub ant_share: f64,
    /// ACO_R's width factor ξ (Socha & Dorigo's 0.85).
    pub xi: f64,
    /// Pheromone floor (not in the seed; MAX–MIN style).
    pub tau_min: f64,
    /// Velocity cap as a fraction of each dimension's range (the same as SPSO's).
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl AcoPso {
    /// Table 8's settings (Table 4's are the same with M = 30).
    pub fn table8(particles: usize, seed: u64) -> AcoPso {
        AcoPso {
            particles,
            w: 0.5,
            c1: 2.0,
            c2: 2.0,
            alpha: 1.0,
            beta: 5.0,
            rho: 0.5,
            archive: particles.max(2),
            ant_share: 0.2,
            xi: 0.85,
            tau_min: 0.01,
            max_velocity_fraction: 0.2,
            seed,
        }
    }

    /// Ants per iteration in a swarm of `m`: `ceil(ant_share · m)`, at most `m`.
    pub fn ants(&self, m: usize) -> usize {
        ((self.ant_share * m as f64).ceil().max(0.0) as usize).min(m)
    }
}

/// One pheromone trail: a good position, its cost and its pheromone.
#[derive(Debug, Clone, PartialEq)]
pub struct Trail {
    /// Position s_j.
    pub x: Vec<f64>,
    /// Its cost.
    pub cost: f64,
    /// Pheromone τ_j.
    pub tau: f64,
}

/// Pheromone a new trail starts with.
pub const TAU_0: f64 = 1.0;

/// Probabilities of choosing each trail of `archive` (sorted by cost): `τ_j^α η_j^β`, η_j = 1/j
/// for rank j (1-based), normalised. Uniform if every weight is zero.
pub fn selection_probabilities(archive: &[Trail], alpha: f64, beta: f64) -> Vec<f64> {
    let weights: Vec<f64> = archive
        .iter()
        .enumerate()
        .map(|(j, t)| t.tau.max(0.0).powf(alpha) * (1.0 / (j + 1) as f64).powf(beta))
        .collect();
    let total: f64 = weights.iter().sum();
    if total > 0.0 && total.is_finite() {
        weights.iter().map(|w| w / total).collect()
    } else {
        vec![1.0 / archive.len().max(1) as f64; archive.len()]
    }
}

/// Index whose cumulative probability first exceeds `u` in [0, 1) (roulette wheel); the last
/// index if rounding leaves the total short of `u`.
pub fn roulette(p: &[f64], u: f64) -> usize {
    let mut acc = 0.0;
    for (j, pj) in p.iter().enumerate() {
        acc += pj;
        if u < acc {
            return j;
        }
    }
    p.len().saturating_sub(1)
}

/// Evaporation and deposit: `τ_j ← max(τ_min, (1 − ρ) τ_j + deposit_j)`.
pub fn update_pheromone(archive: &mut [Trail], deposit: &[f64], rho: f64, tau_min: f64) {
    for (j, t) in archive.iter_mut().enumerate() {
        let d = deposit.get(j).copied().unwrap_or(0.0);
        t.tau = ((1.0 - rho) * t.tau + d).max(tau_min);
    }
}

/// Merges evaluated `points` into `archive`: new distinct positions enter with [`TAU_0`], the
/// archive is re-sorted by cost (stable, so older trails win ties) and cut to `size`.
pub fn merge(
    archive: &mut Vec<Trail>,
    points: impl IntoIterator<Item = (Vec<f64>, f64)>,
    size: usize,
) {
    for (x, cost) in points {
        if cost.is_finite() && !archive.iter().any(|t| t.x == x) {
            archive.push(Trail {
                x,
                cost,
                tau: TAU_0,
            });
        }
    }
    archive.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    archive.truncate(size.max(1));
}

/// ACO_R's sampling width around trail `j`, per dimension: `ξ · Σ_k |s_k − s_j| / (K − 1)`.
pub fn widths(archive: &[Trail], j: usize, xi: f64) -> Vec<f64> {
    let Some(centre) = archive.get(j) else {
        return Vec::new();
    };
    let others = archive.len().saturating_sub(1).max(1) as f64;
    (0..centre.x.len())
        .map(|d| {
            let spread: f64 = archive.iter().map(|t| (t.x[d] - centre.x[d]).abs()).sum();
            xi * spread / others
        })
        .collect()
}

/// A standard normal draw (Box–Muller; `rand` has no normal distribution without `rand_distr`).
fn standard_normal(rng: &mut StdRng) -> f64 {
    let u1 = 1.0 - rng.random::<f64>(); // (0, 1]: ln is finite
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// State of an ACO-PSO run: the swarm and the pheromone archive.
#[derive(Debug, Clone)]
pub struct AcoPsoState {
    /// The swarm (shared single-population state, as SPSO).
    pub swarm: PsoState,
    /// Pheromone trails, best first.
    pub archive: Vec<Trail>,
}

impl SolverState for AcoPsoState {
    fn best_cost(&self) -> f64 {
        self.swarm.best_cost()
    }
    fn best_position(&self) -> &[f64] {
        self.swarm.best_position()
    }
    fn evaluations(&self) -> u64 {
        self.swarm.evaluations
    }
}

impl<P: Problem> Solver<P> for AcoPso {
    type State = AcoPsoState;

    fn name(&self) -> &'static str {
        "aco-pso"
    }

    fn init(&mut self, problem: &P) -> AcoPsoState {
        let population = Population::sample(problem, self.particles.max(1), self.seed);
        let mut archive = Vec::new();
        let points = population.particles.iter().map(|p| (p.x.clone(), p.cost));
        merge(&mut archive, points, self.archive);
        AcoPsoState {
            swarm: PsoState::of(problem, population, self.max_velocity_fraction),
            archive,
        }
    }

    fn step(&mut self, problem: &P, mut state: AcoPsoState, _progress: Progress) -> AcoPsoState {
        let c = Coefficients {
            w: self.w,
            c1: self.c1,
            c2: self.c2,
            c3: 0.0,
        };
        let swarm = &mut state.swarm;
        let limits = &swarm.limits;
        swarm.evaluations += swarm.population.step(problem, c, None, limits);
        let pop = &mut swarm.population;
        let moved = pop.particles.iter().map(|p| (p.x.clone(), p.cost));
        merge(&mut state.archive, moved, self.archive);

        // Ants for the worst particles.
        let p = selection_probabilities(&state.archive, self.alpha, self.beta);
        let mut order: Vec<usize> = (0..pop.particles.len()).collect();
        order.sort_by(|a, b| pop.particles[*b].cost.total_cmp(&pop.particles[*a].cost));
        let ants = self.ants(order.len());
        let mut deposit = vec![0.0; state.archive.len()];
        let mut samples = Vec::with_capacity(ants);
        for &i in order.iter().take(ants) {
            let j = roulette(&p, pop.rng.random());
            let (Some(trail), sigma) = (state.archive.get(j), widths(&state.archive, j, self.xi))
            else {
                continue;
            };
            let x: Vec<f64> = trail
                .x
                .iter()
                .zip(&sigma)
                .enumerate()
                .map(|(d, (s, sd))| {
                    (s + sd * standard_normal(&mut pop.rng))
                        .max(limits.lower[d])
                        .min(limits.upper[d])
                })
                .collect();
            let particle = &mut pop.particles[i];
            let (old_x, old_cost, old_parts) =
                (particle.x.clone(), particle.cost, particle.parts.clone());
            particle.x = x;
            // Evaluating also updates the memories: right whether or not the particle stays.
            particle.evaluate(problem);
            samples.push((particle.x.clone(), particle.cost));
            if particle.cost < old_cost {
                deposit[j] += 1.0;
            } else {
                (particle.x, particle.cost, particle.parts) = (old_x, old_cost, old_parts);
            }
        }
        pop.evaluations += samples.len() as u64;
        swarm.evaluations += samples.len() as u64;
        update_pheromone(&mut state.archive, &deposit, self.rho, self.tau_min);
        merge(&mut state.archive, samples, self.archive);
        swarm.evaluations += pop.refresh(problem);
        state
    }
}

velocity_capped!(AcoPso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::Executor;
    use crate::swarm::testfns::{Rastrigin, ShiftedSphere};
    use approx::assert_abs_diff_eq;

    fn trail(x: f64, cost: f64, tau: f64) -> Trail {
        Trail {
            x: vec![x],
            cost,
            tau,
        }
    }

    #[test]
    fn pheromone_weights_evaporation_and_selection_by_hand() {
        let s = AcoPso::table8(50, 1);
        let mut archive = vec![
            trail(0.0, 1.0, 1.0),
            trail(2.0, 2.0, 1.0),
            trail(6.0, 4.0, 1.0),
        ];
        // Equal pheromone: weights 1, (1/2)^5, (1/3)^5 — β = 5 makes rank dominate.
        let p = selection_probabilities(&archive, s.alpha, s.beta);
        let total = 1.0 + 1.0 / 32.0 + 1.0 / 243.0;
        assert_abs_diff_eq!(p[0], 1.0 / total, epsilon = 1e-12);
        assert_abs_diff_eq!(p[1], (1.0 / 32.0) / total, epsilon = 1e-12);
        assert_abs_diff_eq!(p[2], (1.0 / 243.0) / total, epsilon = 1e-12);
        // Two ants succeeded from trail 1: τ = 0.5·(1, 1, 1) + (0, 2, 0) = (0.5, 2.5, 0.5).
        update_pheromone(&mut archive, &[0.0, 2.0], s.rho, s.tau_min);
        let taus: Vec<f64> = archive.iter().map(|t| t.tau).collect();
        assert_eq!(taus, vec![0.5, 2.5, 0.5]);
        let p = selection_probabilities(&archive, s.alpha, s.beta);
        let total = 0.5 + 2.5 / 32.0 + 0.5 / 243.0;
        assert_abs_diff_eq!(p[0], 0.5 / total, epsilon = 1e-12);
        assert_abs_diff_eq!(p[1], (2.5 / 32.0) / total, epsilon = 1e-12);
        assert_abs_diff_eq!(p[1], 0.134_656, epsilon = 1e-6);
        assert_abs_diff_eq!(p.iter().sum::<f64>(), 1.0, epsilon = 1e-12);
        // Roulette over (0.2, 0.5, 0.3): [0, 0.2) → 0, [0.2, 0.7) → 1, [0.7, 1) → 2.
        let wheel = [0.2, 0.5, 0.3];
        assert_eq!(
            [0.0, 0.19, 0.2, 0.69, 0.7, 0.999].map(|u| roulette(&wheel, u)),
            [0, 0, 1, 1, 2, 2]
        );
        assert_eq!(roulette(&[0.5, 0.4999], 0.99995), 1, "short total → last");
        // Evaporation alone halves; the floor holds: 0.015 / 2 → 0.01.
        let mut a = vec![trail(0.0, 1.0, 0.015), trail(1.0, 2.0, 3.0)];
        update_pheromone(&mut a, &[], s.rho, s.tau_min);
        assert_eq!((a[0].tau, a[1].tau), (0.01, 1.5));
        // ACO_R width around trail 0 of {0, 2, 6}: 0.85 · (2 + 6) / 2 = 3.4; around 6: 0.85 · 5.
        assert_abs_diff_eq!(widths(&archive, 0, s.xi)[0], 3.4, epsilon = 1e-12);
        assert_abs_diff_eq!(widths(&archive, 2, s.xi)[0], 0.85 * 5.0, epsilon = 1e-12);
        // Merging: a duplicate is ignored, a better point enters first with τ_0, the worst drops.
        merge(&mut archive, [(vec![2.0], 2.0), (vec![9.0], 0.5)], 3);
        let xs: Vec<f64> = archive.iter().map(|t| t.x[0]).collect();
        assert_eq!(xs, vec![9.0, 0.0, 2.0]);
        assert_eq!((archive[0].tau, archive[2].tau), (TAU_0, 2.5));
        assert_eq!((s.ants(50), s.ants(30), s.ants(1)), (10, 6, 1));
    }

    #[test]
    fn aco_pso_converges_on_the_shifted_sphere_and_is_deterministic() {
        let sphere = ShiftedSphere::new(8);
        let run = |seed| Executor::new(300).run(&sphere, &mut AcoPso::table8(30, seed), |_| {});
        let out = run(3);
        assert!(out.state.best_cost() < 1e-6, "{}", out.state.best_cost());
        for (a, b) in out.state.best_position().iter().zip(&sphere.shift) {
            assert!((a - b).abs() < 1e-3, "{a} vs optimum {b}");
        }
        assert!(out.convergence.windows(2).all(|w| w[1] <= w[0]));
        // 30 particles + 6 ants per iteration.
        assert_eq!(out.state.evaluations(), 30 + 300 * 36);
        assert!(out.state.archive.windows(2).all(|w| w[0].cost <= w[1].cost));
        assert_eq!(out.state.archive[0].cost, out.state.best_cost());
        let again = run(3);
        assert_eq!(again.convergence, out.convergence);
        assert_eq!(again.state.best_position(), out.state.best_position());
        assert_ne!(run(4).convergence, out.convergence);
        // Rastrigin 2-D: the global basin (other minima cost about 1 or more) in most runs. The
        // ants pull the worst particles into the best trails' basins, so ACO-PSO is greedier than
        // SPSO (8 runs in 10 here, SPSO 10).
        let r = Rastrigin::new(2);
        let found = (0..10)
            .filter(|seed| {
                let out = Executor::new(300).run(&r, &mut AcoPso::table8(30, *seed), |_| {});
                out.state.best_cost() < 1e-4
            })
            .count();
        assert!(found >= 7, "{found} of 10");
    }
}
