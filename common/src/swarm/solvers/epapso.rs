//! EPA-PSO, Zhang et al. 2022, §3.2: PSO with a velocity jump that grows while the swarm stagnates
//! (eq. (14)), velocity limits (eq. (15)), a non-linear coefficient schedule with a constriction
//! factor (eq. (16)), re-initialisation around the stagnated swarm (eq. (17)), and a feasible
//! solution set from which the answer is finally chosen.
//!
//! Readings (the paper leaves these open):
//! - **Inertia.** Eq. (16) gives `w_p` as Clerc's constriction of `φ = c1 + c2 + c3`, while
//!   Table 2 lists `w_p = 1.2`, `w_pmin = 0.8` and `α_w = 10`. Both are kept: a schedule
//!   `w ← w − (w − w_min) t / (α_w T)` from 1.2 towards 0.8 (the same form as eq. (16)'s c-updates),
//!   scaled by the constriction factor `χ(φ)` of eq. (16) ("the compression factor is used to
//!   update the inertia weight").
//! - **The jump** `c3 r3 n_s / n_smax` is drawn per dimension with `r3 ∈ [−1, 1]`: the paper's
//!   `r3 ∈ [0, 1]` would push every coordinate the same way at every stagnation. It is in units of
//!   the paper's 100 m map, so it is scaled by each dimension's range / 100, as are the velocity
//!   limits `v_pmin = −20`, `v_pmax = 20` of Table 2 (20 % of the range).
//! - **Stagnation.** `n_s` counts consecutive iterations in which the global best cost did not
//!   improve; when it exceeds `n_smax` the global best goes into the solution set, every particle
//!   moves by its standardised position `sd(x) = (x − mean) / std` per dimension (eq. (17)), the
//!   personal and global memories restart from the moved swarm and `n_s` returns to 0.
//! - **The answer** is the best of the solution set and the current global best, feasible ones
//!   first ([`Problem::feasible`]), then by cost.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use crate::swarm::core::{Problem, Progress, Solver, SolverState};

/// The EPA-PSO solver, with Table 2's settings by default.
#[derive(Debug, Clone)]
pub struct EpaPso {
    /// Particles p_λ (Table 2: 50).
    pub particles: usize,
    /// Initial and lowest inertia weight (Table 2: 1.2, 0.8).
    pub w: (f64, f64),
    /// Initial c1, c2, c3 (Table 2: 1.5, 1.5, 2.5).
    pub c: [f64; 3],
    /// c1max, c2max, c3min (Table 2: 2.5, 2.5, 1.5).
    pub c_limits: [f64; 3],
    /// α_w, α_p, α_g, α_ju (Table 2: 10 each).
    pub alpha: [f64; 4],
    /// n_smax (Table 2: 15).
    pub n_smax: usize,
    /// |v| limit as a fraction of each dimension's range (Table 2: 20 on a 100 m map).
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl EpaPso {
    /// Table 2's settings.
    pub fn table2(particles: usize, seed: u64) -> EpaPso {
        EpaPso {
            particles,
            w: (1.2, 0.8),
            c: [1.5, 1.5, 2.5],
            c_limits: [2.5, 2.5, 1.5],
            alpha: [10.0; 4],
            n_smax: 15,
            max_velocity_fraction: 0.2,
            seed,
        }
    }
}

/// Clerc's constriction factor of eq. (16), `2 / |2 − φ − √(φ² − 4φ)|`, for `φ > 4`; 1 below
/// (where the root is not real and no constriction is needed).
pub fn constriction(phi: f64) -> f64 {
    if phi > 4.0 {
        2.0 / (2.0 - phi - (phi * phi - 4.0 * phi).sqrt()).abs()
    } else {
        1.0
    }
}

/// One member of the solution set.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Position.
    pub x: Vec<f64>,
    /// Its cost.
    pub cost: f64,
    /// Whether it meets the problem's hard constraints.
    pub feasible: bool,
}

impl Candidate {
    /// Feasible before infeasible, then cheaper first.
    fn better_than(&self, other: &Candidate) -> bool {
        (self.feasible && !other.feasible)
            || (self.feasible == other.feasible && self.cost < other.cost)
    }
}

/// State of an EPA-PSO run.
#[derive(Debug, Clone)]
pub struct EpaPsoState {
    /// Positions.
    pub x: Vec<Vec<f64>>,
    /// Velocities.
    pub v: Vec<Vec<f64>>,
    /// Personal bests and their costs.
    pub pbest: Vec<(Vec<f64>, f64)>,
    /// Global best of the swarm since the last re-initialisation.
    pub gbest: Candidate,
    /// The feasible solution set: the global bests the swarm stagnated on.
    pub archive: Vec<Candidate>,
    /// The answer so far (see the module doc).
    pub answer: Candidate,
    /// Current w (before constriction), c1, c2, c3.
    pub coefficients: [f64; 4],
    /// n_s: iterations without improvement of the global best.
    pub stagnation: usize,
    /// Re-initialisations so far.
    pub restarts: usize,
    /// Cost evaluations.
    pub evaluations: u64,
    rng: StdRng,
}

impl SolverState for EpaPsoState {
    fn best_cost(&self) -> f64 {
        self.answer.cost
    }
    fn best_position(&self) -> &[f64] {
        &self.answer.x
    }
    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

fn candidate<P: Problem>(problem: &P, x: &[f64], cost: f64) -> Candidate {
    Candidate {
        x: x.to_vec(),
        cost,
        feasible: problem.feasible(x),
    }
}

impl EpaPsoState {
    /// Restarts the memories from the current positions (init and eq. (17)).
    fn remember_all<P: Problem>(&mut self, problem: &P) {
        self.pbest = self
            .x
            .iter()
            .map(|x| (x.clone(), problem.cost(x)))
            .collect();
        self.evaluations += self.x.len() as u64;
        let mut best = 0;
        for (i, (_, c)) in self.pbest.iter().enumerate() {
            if *c < self.pbest[best].1 {
                best = i;
            }
        }
        self.gbest = candidate(problem, &self.pbest[best].0, self.pbest[best].1);
        self.consider(self.gbest.clone());
        // Every fresh particle is a candidate while no feasible answer exists.
        if !self.answer.feasible {
            let fresh: Vec<Candidate> = self
                .pbest
                .iter()
                .map(|(x, c)| candidate(problem, x, *c))
                .collect();
            for c in fresh {
                self.consider(c);
            }
        }
    }

    fn consider(&mut self, c: Candidate) {
        if c.better_than(&self.answer) {
            self.answer = c;
        }
    }
}

impl<P: Problem> Solver<P> for EpaPso {
    type State = EpaPsoState;

    fn name(&self) -> &'static str {
        "epa-pso"
    }

    fn init(&mut self, problem: &P) -> EpaPsoState {
        let mut rng = StdRng::seed_from_u64(self.seed);
        let n = self.particles.max(1);
        let x: Vec<Vec<f64>> = (0..n).map(|_| problem.sample(&mut rng)).collect();
        let dim = problem.dim();
        let mut state = EpaPsoState {
            v: vec![vec![0.0; dim]; n],
            x,
            pbest: Vec::new(),
            gbest: Candidate {
                x: Vec::new(),
                cost: f64::INFINITY,
                feasible: false,
            },
            archive: Vec::new(),
            answer: Candidate {
                x: vec![0.0; dim],
                cost: f64::INFINITY,
                feasible: false,
            },
            coefficients: [self.w.0, self.c[0], self.c[1], self.c[2]],
            stagnation: 0,
            restarts: 0,
            evaluations: 0,
            rng,
        };
        state.remember_all(problem);
        state
    }

    fn step(&mut self, problem: &P, mut s: EpaPsoState, progress: Progress) -> EpaPsoState {
        let (lo, hi) = (problem.lower(), problem.upper());
        let range: Vec<f64> = lo.iter().zip(hi).map(|(l, h)| h - l).collect();
        // Zhang et al. 2022, eq. (16): c1, c2 rise towards their maxima, c3 falls towards its minimum,
        // each by the share t / (α T) of the remaining gap.
        let f = progress.iteration as f64 / progress.max_iterations.max(1) as f64;
        let [w, c1, c2, c3] = &mut s.coefficients;
        *w -= (*w - self.w.1) * f / self.alpha[0];
        *c1 += (self.c_limits[0] - *c1) * f / self.alpha[1];
        *c2 += (self.c_limits[1] - *c2) * f / self.alpha[2];
        *c3 -= (*c3 - self.c_limits[2]) * f / self.alpha[3];
        let [w, c1, c2, c3] = s.coefficients;
        let inertia = w * constriction(c1 + c2 + c3);
        let jump = c3 * s.stagnation as f64 / self.n_smax.max(1) as f64;
        let before = s.gbest.cost;
        for i in 0..s.x.len() {
            for d in 0..range.len() {
                let vmax = self.max_velocity_fraction * range[d];
                let (r1, r2): (f64, f64) = (s.rng.random(), s.rng.random());
                let r3: f64 = s.rng.random_range(-1.0..=1.0);
                // Zhang et al. 2022, eq. (14), the jump in units of a 100 m map.
                let v = inertia * s.v[i][d]
                    + c1 * r1 * (s.pbest[i].0[d] - s.x[i][d])
                    + c2 * r2 * (s.gbest.x[d] - s.x[i][d])
                    + jump * r3 * range[d] / 100.0;
                // Zhang et al. 2022, eq. (15).
                s.v[i][d] = v.clamp(-vmax, vmax);
                let moved = s.x[i][d] + s.v[i][d];
                if moved < lo[d] || moved > hi[d] {
                    s.x[i][d] = moved.clamp(lo[d], hi[d]);
                    s.v[i][d] = 0.0;
                } else {
                    s.x[i][d] = moved;
                }
            }
            let cost = problem.cost(&s.x[i]);
            s.evaluations += 1;
            if cost < s.pbest[i].1 {
                s.pbest[i] = (s.x[i].clone(), cost);
                if cost < s.gbest.cost {
                    s.gbest = candidate(problem, &s.x[i], cost);
                    s.consider(s.gbest.clone());
                } else if !s.answer.feasible {
                    // Until a feasible answer exists, every improving particle may be one.
                    let c = candidate(problem, &s.x[i], cost);
                    s.consider(c);
                }
            }
        }
        if s.gbest.cost < before {
            s.stagnation = 0;
        } else {
            s.stagnation += 1;
        }
        if s.stagnation > self.n_smax {
            // Zhang et al. 2022, eq. (17): keep the stagnated best, move every particle by its
            // standardised position and start the memories afresh.
            s.archive.push(s.gbest.clone());
            let n = s.x.len() as f64;
            for d in 0..range.len() {
                let mean = s.x.iter().map(|x| x[d]).sum::<f64>() / n;
                let var = s.x.iter().map(|x| (x[d] - mean).powi(2)).sum::<f64>() / n;
                let sd = var.sqrt();
                for x in s.x.iter_mut() {
                    let z = if sd > 1e-12 {
                        (x[d] - mean) / sd
                    } else {
                        s.rng.random_range(-1.0..=1.0)
                    };
                    x[d] = (x[d] + z * range[d] / 100.0).clamp(lo[d], hi[d]);
                }
            }
            s.remember_all(problem);
            s.stagnation = 0;
            s.restarts += 1;
        }
        s
    }
}

velocity_capped!(EpaPso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::Executor;
    use crate::swarm::testfns::{Rastrigin, ShiftedSphere};

    #[test]
    fn constriction_of_table_2() {
        // φ = 1.5 + 1.5 + 2.5 = 5.5: 2 / |2 − 5.5 − √(30.25 − 22)| = 2 / (3.5 + √8.25).
        assert!((constriction(5.5) - 2.0 / (3.5 + 8.25f64.sqrt())).abs() < 1e-12);
        // Clerc's classic φ = 4.1 gives 0.7298.
        assert!((constriction(4.1) - 0.729_843_788).abs() < 1e-6);
        assert_eq!(constriction(3.0), 1.0);
    }

    #[test]
    fn converges_on_the_shifted_sphere() {
        let problem = ShiftedSphere::new(5);
        // The restarts trade precision for exploration: close, not exact, from a start near 100.
        let out = Executor::new(400).run(&problem, &mut EpaPso::table2(30, 3), |_| {});
        assert!(out.state.best_cost() < 1e-3, "{}", out.state.best_cost());
        for (a, b) in out.state.best_position().iter().zip(&problem.shift) {
            assert!((a - b).abs() < 3e-2, "{a} vs {b}");
        }
    }

    #[test]
    fn same_seed_same_run_and_stagnation_restarts() {
        let problem = Rastrigin::new(4);
        let run = || Executor::new(150).run(&problem, &mut EpaPso::table2(20, 9), |_| {});
        let (a, b) = (run(), run());
        assert_eq!(a.convergence, b.convergence);
        // On a multimodal function the swarm stagnates, restarts, and archives what it found;
        // the answer is never worse than anything archived.
        assert!(a.state.restarts > 0 && !a.state.archive.is_empty());
        assert!(a
            .state
            .archive
            .iter()
            .all(|c| a.state.answer.cost <= c.cost));
        // The reported best never gets worse.
        assert!(a.convergence.windows(2).all(|w| w[1] <= w[0]));
    }

    /// A bowl whose optimum is infeasible: the answer must be the best feasible point seen.
    struct Fenced;
    impl Problem for Fenced {
        fn lower(&self) -> &[f64] {
            &[-5.0, -5.0]
        }
        fn upper(&self) -> &[f64] {
            &[5.0, 5.0]
        }
        fn cost(&self, x: &[f64]) -> f64 {
            x[0] * x[0] + x[1] * x[1]
        }
        fn feasible(&self, x: &[f64]) -> bool {
            x[0] >= 1.0
        }
    }

    #[test]
    fn answer_prefers_feasible_solutions() {
        let out = Executor::new(100).run(&Fenced, &mut EpaPso::table2(20, 1), |_| {});
        assert!(out.state.answer.feasible);
        assert!(out.state.best_position()[0] >= 1.0);
        // The swarm's own best is the infeasible bottom of the bowl, which is not the answer.
        assert!(out.state.gbest.cost < 1.0 && !out.state.gbest.feasible);
        assert!(out.state.best_cost() >= 1.0);
    }
}
