//! IPSO, the improved PSO of Lu et al. 2023, §3.2 (eq. (19)–(26)), for the mining crawler's path and the
//! benchmark functions:
//! - a third attractor, the mean of the personal bests `s` (eq. (21)), with `c3 = 1 + t/t_max`
//!   (eq. (20)), in the velocity update of eq. (19)/(26);
//! - a non-linear dynamic inertia weight per particle from its fitness (eq. (22));
//! - asynchronously varying learning factors `c1`, `c2` (eq. (23)–(24));
//! - natural selection (eq. (25)): after each move the worst particles take the positions and
//!   velocities of the best ones, keeping their own memories.
//!
//! Two readings of the printed equations (the text is followed where the formula contradicts it):
//! - eq. (22) prints `ω_min − (ω_max − ω_min)(f − f_min)/(f_avg − f_min)`, which would give a
//!   particle of average fitness `2ω_min − ω_max` (−0.1 with Table 8's values) and make better
//!   particles *faster*; the text says particles better than average get a *small* weight that
//!   grows towards `ω_max` for worse ones. Shoal uses `ω_min + (ω_max − ω_min)(f − f_min)/(f_avg −
//!   f_min)` for `f ≤ f_avg` and `ω_max` above.
//! - eq. (25) prints `e = round(M − 1)/2` (half the swarm), while the text and Tables 4 and 8 give
//!   an elimination share `p = 5 %`; Shoal replaces `e = max(1, round(p·M))` particles.

use rand::Rng;

use super::pso::PsoState;
use crate::swarm::core::population::Particle;
use crate::swarm::core::{Problem, Progress, Solver};

/// The IPSO solver (Table 4 / Table 8 defaults).
#[derive(Debug, Clone)]
pub struct Ipso {
    /// Particles M.
    pub particles: usize,
    /// c1 at the first and at the last iteration (eq. (23)).
    pub c1: (f64, f64),
    /// c2 at the first and at the last iteration (eq. (24)).
    pub c2: (f64, f64),
    /// ω_min and ω_max of eq. (22).
    pub w: (f64, f64),
    /// Elimination share p of eq. (25).
    pub elimination: f64,
    /// Velocity cap as a fraction of each dimension's range (not in the paper: without one the
    /// three attractors can throw particles far outside the box).
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl Ipso {
    /// Table 8: c1 2 → 0.5, c2 2 → 0.5, ω ∈ [0.4, 0.9], p = 0.05.
    pub fn table8(particles: usize, seed: u64) -> Ipso {
        Ipso {
            particles,
            c1: (2.0, 0.5),
            c2: (2.0, 0.5),
            w: (0.4, 0.9),
            elimination: 0.05,
            max_velocity_fraction: 0.2,
            seed,
        }
    }

    /// Inertia weight of a particle of fitness `f` (eq. (22), as read above).
    pub fn inertia(&self, f: f64, f_min: f64, f_avg: f64) -> f64 {
        let (w_min, w_max) = self.w;
        if f > f_avg {
            w_max
        } else if f_avg - f_min <= 0.0 || !f.is_finite() {
            w_min
        } else {
            w_min + (w_max - w_min) * (f - f_min) / (f_avg - f_min)
        }
    }

    /// `(c1, c2, c3)` at `progress` (eq. (20), (23), (24)).
    pub fn factors(&self, progress: Progress) -> (f64, f64, f64) {
        let r = progress.fraction();
        (
            self.c1.0 + (self.c1.1 - self.c1.0) * r,
            self.c2.0 + (self.c2.1 - self.c2.0) * r,
            1.0 + r,
        )
    }

    /// How many particles eq. (25) replaces in a swarm of `m`.
    pub fn eliminated(&self, m: usize) -> usize {
        if m < 2 {
            return 0;
        }
        ((self.elimination * m as f64).round() as usize).clamp(1, m / 2)
    }
}

/// Natural selection (eq. (25)): the `e` particles of worst current fitness take the position,
/// velocity and current fitness of the `e` best, in rank order; memories stay their own.
pub fn natural_selection(particles: &mut [Particle], e: usize) {
    let m = particles.len();
    if e == 0 || 2 * e > m {
        return;
    }
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|a, b| particles[*a].cost.total_cmp(&particles[*b].cost));
    for r in 0..e {
        let (best, worst) = (order[r], order[m - e + r]);
        let (x, v, cost, parts) = {
            let b = &particles[best];
            (b.x.clone(), b.v.clone(), b.cost, b.parts.clone())
        };
        let w = &mut particles[worst];
        w.x = x;
        w.v = v;
        w.cost = cost;
        w.parts = parts;
    }
}

impl<P: Problem> Solver<P> for Ipso {
    type State = PsoState;

    fn name(&self) -> &'static str {
        "ipso"
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
        let (c1, c2, c3) = self.factors(progress);
        let pop = &mut state.population;
        let m = pop.particles.len();
        let dim = problem.dim();
        // s(t): the mean of the personal bests (eq. (21)).
        let mut s = vec![0.0; dim];
        for p in &pop.particles {
            for (sd, b) in s.iter_mut().zip(&p.best_x) {
                *sd += b / m as f64;
            }
        }
        let f_min = pop
            .particles
            .iter()
            .map(|p| p.cost)
            .fold(f64::INFINITY, f64::min);
        let f_avg = pop.particles.iter().map(|p| p.cost).sum::<f64>() / m as f64;
        let limits = &state.limits;
        let gbest = pop.gbest.clone();
        for p in &mut pop.particles {
            let w = self.inertia(p.cost, f_min, f_avg);
            for g in &limits.groups {
                let (r1, r2, r3): (f64, f64, f64) =
                    (pop.rng.random(), pop.rng.random(), pop.rng.random());
                let mut over = 1.0f64;
                for d in g.clone() {
                    let x = p.x[d];
                    let v = w * p.v[d]
                        + c1 * r1 * (p.best_x[d] - x)
                        + c2 * r2 * (gbest[d] - x)
                        + c3 * r3 * (s[d] - x);
                    p.v[d] = v;
                    over = over.max(v.abs() * limits.inv_vmax[d]);
                }
                for d in g.clone() {
                    let v = p.v[d] / over;
                    let x = p.x[d] + v;
                    let (x, v) = if x < limits.lower[d] {
                        (limits.lower[d], 0.0)
                    } else if x > limits.upper[d] {
                        (limits.upper[d], 0.0)
                    } else {
                        (x, v)
                    };
                    p.x[d] = x;
                    p.v[d] = v;
                }
            }
            p.evaluate(problem);
        }
        pop.evaluations += m as u64;
        state.evaluations += m as u64;
        natural_selection(&mut pop.particles, self.eliminated(m));
        state.evaluations += pop.refresh(problem);
        state
    }
}

velocity_capped!(Ipso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::{Executor, SolverState};
    use crate::swarm::testfns::{Rastrigin, ShiftedSphere};
    use approx::assert_abs_diff_eq;

    #[test]
    fn inertia_and_factors_follow_eq_20_to_24_by_hand() {
        let ipso = Ipso::table8(50, 1);
        // f_min = 1, f_avg = 3: f = 1 → 0.4, f = 2 → 0.65, f = 3 → 0.9, f = 4 → 0.9.
        assert_abs_diff_eq!(ipso.inertia(1.0, 1.0, 3.0), 0.4);
        assert_abs_diff_eq!(ipso.inertia(2.0, 1.0, 3.0), 0.65);
        assert_abs_diff_eq!(ipso.inertia(3.0, 1.0, 3.0), 0.9);
        assert_abs_diff_eq!(ipso.inertia(4.0, 1.0, 3.0), 0.9);
        assert_abs_diff_eq!(ipso.inertia(5.0, 5.0, 5.0), 0.4);
        let at = |t| Progress {
            iteration: t,
            max_iterations: 100,
        };
        assert_eq!(ipso.factors(at(0)), (2.0, 2.0, 1.0));
        let (c1, c2, c3) = ipso.factors(at(40));
        assert_abs_diff_eq!(c1, 1.4);
        assert_abs_diff_eq!(c2, 1.4);
        assert_abs_diff_eq!(c3, 1.4);
        assert_eq!(ipso.factors(at(100)), (0.5, 0.5, 2.0));
        // p = 5 %: 50 particles → round(2.5) = 3 replaced; never more than half, at least one.
        assert_eq!(ipso.eliminated(50), 3);
        assert_eq!(ipso.eliminated(30), 2);
        assert_eq!(ipso.eliminated(4), 1);
        assert_eq!(ipso.eliminated(1), 0);
    }

    #[test]
    fn natural_selection_copies_the_best_over_the_worst_and_keeps_memories() {
        let mk = |x: f64, cost: f64| Particle {
            x: vec![x],
            v: vec![x / 10.0],
            cost,
            parts: vec![cost],
            best_x: vec![-x],
            best_parts: vec![cost],
            best_cost: cost,
        };
        let mut ps = vec![
            mk(1.0, 5.0),
            mk(2.0, 1.0),
            mk(3.0, 9.0),
            mk(4.0, 2.0),
            mk(5.0, 7.0),
        ];
        natural_selection(&mut ps, 2);
        // Ranks by cost: 2 (1.0), 4 (2.0), 1 (5.0), 5 (7.0), 3 (9.0). The worst two (5.0→7.0 at
        // index 4, 9.0 at index 2) take the best two in order: index 4 ← index 1, index 2 ← index 3.
        assert_eq!((ps[4].x.clone(), ps[4].cost), (vec![2.0], 1.0));
        assert_eq!((ps[2].x.clone(), ps[2].cost), (vec![4.0], 2.0));
        assert_eq!(ps[2].best_x, vec![-3.0], "memories stay");
        assert_eq!(ps[0].x, vec![1.0]);
    }

    #[test]
    fn ipso_converges_on_the_shifted_sphere_and_rastrigin() {
        let sphere = ShiftedSphere::new(10);
        let out = Executor::new(300).run(&sphere, &mut Ipso::table8(30, 3), |_| {});
        assert!(
            out.state.best_cost() < 1e-8,
            "sphere {}",
            out.state.best_cost()
        );
        for (a, b) in out.state.best_position().iter().zip(&sphere.shift) {
            assert!((a - b).abs() < 1e-3);
        }
        assert!(out.convergence.windows(2).all(|w| w[1] <= w[0]));
        // Rastrigin 2-D: the global minimum 0 at the origin.
        let r = Rastrigin::new(2);
        let out = Executor::new(300).run(&r, &mut Ipso::table8(30, 5), |_| {});
        // In the global basin (any other local minimum of Rastrigin costs about 1 or more).
        assert!(
            out.state.best_cost() < 1e-4,
            "rastrigin {}",
            out.state.best_cost()
        );
        assert!(out.state.best_position().iter().all(|x| x.abs() < 1e-3));
        // Same seed, same run.
        let again = Executor::new(300).run(&r, &mut Ipso::table8(30, 5), |_| {});
        assert_eq!(again.convergence, out.convergence);
    }
}
