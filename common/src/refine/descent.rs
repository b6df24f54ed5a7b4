//! Local descent after the swarm for the one-vehicle planners (crawler paths, energy paths,
//! inspection legs): the swarm finds the way round, a gradient search then settles the last
//! metres that a particle swarm converges to slowly.
//!
//! The method is the spectral projected gradient (Birgin, Martínez & Raydan 2000, "Nonmonotone
//! spectral projected gradient methods on convex sets", SIAM J. Optim. 10(4), Algorithm SPG2 in
//! its monotone form): a Barzilai–Borwein step along the negative gradient, projected on the
//! box bounds of the swarm's problem, with an Armijo backtracking line search. The gradient is
//! taken by central differences of the problem's own cost, so the search lowers exactly what the
//! swarm minimised, penalties included: a step is kept only when that cost gets lower, and the
//! search can never return a worse position than it was given. Where the gradient steps stall
//! (a penalty's jump at a limit the path presses against), a compass sweep (Kolda, Lewis &
//! Torczon 2003, "Optimization by direct search", SIAM Review 45(3)) moves one coordinate at a
//! time, and its probe shrinks until it finds nothing either.
//!
//! Hand-written rather than taken from `argmin`: its line searches do not keep a position inside
//! box bounds, and this search must also stop on a flag and within an evaluation budget; the
//! method is a hundred lines of `Run`.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::swarm::Problem;

/// How far the descent goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DescentSettings {
    /// Cost evaluations at most (gradients included: `2 × dim` each).
    pub max_evaluations: usize,
    /// Central-difference step, as a fraction of each dimension's bound range.
    pub difference_step: f64,
    /// The search ends when the projected gradient step moves no coordinate further than this
    /// fraction of its bound range.
    pub tolerance: f64,
}

impl Default for DescentSettings {
    /// 20 000 evaluations (callers with a swarm budget of their own set a share of it);
    /// differences of 10⁻⁷ of the range (about a millimetre on a kilometre: well above the
    /// rounding of the costs, well below any length the plans care about); tolerance 10⁻⁹.
    fn default() -> Self {
        DescentSettings {
            max_evaluations: 20_000,
            difference_step: 1e-7,
            tolerance: 1e-9,
        }
    }
}

/// What a descent did.
#[derive(Debug, Clone, PartialEq)]
pub struct Descent {
    /// The position it ends at (the start when no step lowered the cost).
    pub x: Vec<f64>,
    /// Cost before and after.
    pub cost: (f64, f64),
    /// Steps kept.
    pub steps: usize,
    /// Cost evaluations spent.
    pub evaluations: usize,
}

/// Armijo's sufficient-decrease constant (Birgin et al.'s γ).
const ARMIJO: f64 = 1e-4;
/// Halvings of one line search before the direction is given up (a kink of a penalty).
const MAX_HALVINGS: usize = 30;
/// Bounds of the spectral step, in units of cost per squared coordinate.
const SPECTRAL_MIN: f64 = 1e-30;
/// See [`SPECTRAL_MIN`].
const SPECTRAL_MAX: f64 = 1e30;

/// Descends from `x0` (clamped into the bounds) on `problem`'s cost; a raised `stop` ends it
/// after the current evaluation, with the best position so far.
pub fn descend(
    problem: &dyn Problem,
    x0: &[f64],
    settings: &DescentSettings,
    stop: Option<&AtomicBool>,
) -> Descent {
    let mut run = Run::new(problem, settings, stop);
    let mut x = run.project(x0);
    let mut f = run.cost(&x);
    let start = f;
    let mut steps = 0;
    let mut probe = FIRST_PROBE;
    while !run.spent() {
        steps += run.spectral_steps(&mut x, &mut f);
        if run.spent() {
            break;
        }
        // The gradient steps stalled: a penalty's kink, or a limit the position presses against.
        // A compass sweep may slide along it; when it cannot either, its probe shrinks.
        if run.compass(&mut x, &mut f, probe) {
            steps += 1;
        } else {
            probe *= 0.25;
            if probe < settings.tolerance {
                break;
            }
        }
    }
    Descent {
        x,
        cost: (start, f),
        steps,
        evaluations: run.evaluations,
    }
}

/// The first compass probe, as a fraction of each dimension's bound range.
const FIRST_PROBE: f64 = 1e-3;

/// One descent's problem, budget and count.
struct Run<'a> {
    problem: &'a dyn Problem,
    settings: &'a DescentSettings,
    stop: Option<&'a AtomicBool>,
    range: Vec<f64>,
    evaluations: usize,
}

impl<'a> Run<'a> {
    fn new(
        problem: &'a dyn Problem,
        settings: &'a DescentSettings,
        stop: Option<&'a AtomicBool>,
    ) -> Run<'a> {
        let range = problem
            .lower()
            .iter()
            .zip(problem.upper())
            .map(|(l, u)| (u - l).abs().max(f64::MIN_POSITIVE))
            .collect();
        Run {
            problem,
            settings,
            stop,
            range,
            evaluations: 0,
        }
    }

    /// Spectral projected gradient steps from `x` until one fails; the number kept.
    fn spectral_steps(&mut self, x: &mut Vec<f64>, f: &mut f64) -> usize {
        let mut steps = 0;
        let mut g = self.gradient(x);
        let mut spectral = 1.0 / self.projected_step(x, &g, 1.0).max(f64::MIN_POSITIVE);
        while !self.spent() {
            let direction = self.direction(x, &g, spectral);
            let tolerance = self.settings.tolerance;
            if direction
                .iter()
                .zip(&self.range)
                .all(|(d, r)| d.abs() <= tolerance * r)
            {
                break;
            }
            let slope: f64 = g.iter().zip(&direction).map(|(a, b)| a * b).sum();
            let Some((next, f_next)) = self.line_search(x, *f, &direction, slope) else {
                break;
            };
            let g_next = self.gradient(&next);
            let s: Vec<f64> = next.iter().zip(x.iter()).map(|(a, b)| a - b).collect();
            let sy: f64 = s
                .iter()
                .zip(g_next.iter().zip(&g))
                .map(|(s, (a, b))| s * (a - b))
                .sum();
            let ss: f64 = s.iter().map(|v| v * v).sum();
            spectral = if sy > 0.0 {
                (ss / sy).clamp(SPECTRAL_MIN, SPECTRAL_MAX)
            } else {
                SPECTRAL_MAX
            };
            (*x, *f, g) = (next, f_next, g_next);
            steps += 1;
        }
        steps
    }

    /// One compass sweep: each coordinate moved by `probe` of its range up, else down, kept
    /// where it lowers the cost. Whether any move was kept.
    fn compass(&mut self, x: &mut [f64], f: &mut f64, probe: f64) -> bool {
        let problem = self.problem;
        let (lo, hi) = (problem.lower(), problem.upper());
        let mut kept = false;
        for d in 0..x.len() {
            let here = x[d];
            for to in [here + probe * self.range[d], here - probe * self.range[d]] {
                if self.spent() {
                    return kept;
                }
                x[d] = to.clamp(lo[d], hi[d]);
                let trial = self.cost(x);
                if trial < *f {
                    *f = trial;
                    kept = true;
                    break;
                }
                x[d] = here;
            }
        }
        kept
    }

    fn spent(&self) -> bool {
        self.evaluations >= self.settings.max_evaluations
            || self.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }

    fn cost(&mut self, x: &[f64]) -> f64 {
        self.evaluations += 1;
        self.problem.cost(x)
    }

    fn project(&self, x: &[f64]) -> Vec<f64> {
        let (lo, hi) = (self.problem.lower(), self.problem.upper());
        x.iter()
            .zip(lo.iter().zip(hi))
            .map(|(v, (l, u))| v.clamp(*l, *u))
            .collect()
    }

    /// Central differences, one-sided at a bound.
    fn gradient(&mut self, x: &[f64]) -> Vec<f64> {
        let problem = self.problem;
        let (lo, hi) = (problem.lower(), problem.upper());
        let mut probe = x.to_vec();
        let mut g = vec![0.0; x.len()];
        for d in 0..x.len() {
            let h = self.settings.difference_step * self.range[d];
            let (a, b) = ((x[d] - h).max(lo[d]), (x[d] + h).min(hi[d]));
            if b <= a {
                continue;
            }
            probe[d] = b;
            let up = self.cost(&probe);
            probe[d] = a;
            let down = self.cost(&probe);
            probe[d] = x[d];
            g[d] = (up - down) / (b - a);
        }
        g
    }

    /// `P(x − λ g) − x`, the projected step.
    fn direction(&self, x: &[f64], g: &[f64], lambda: f64) -> Vec<f64> {
        let moved: Vec<f64> = x.iter().zip(g).map(|(v, d)| v - lambda * d).collect();
        self.project(&moved)
            .iter()
            .zip(x)
            .map(|(p, v)| p - v)
            .collect()
    }

    /// The largest coordinate move of the unit projected step, for the first spectral step.
    fn projected_step(&self, x: &[f64], g: &[f64], lambda: f64) -> f64 {
        self.direction(x, g, lambda)
            .iter()
            .fold(0.0, |m, d| m.max(d.abs()))
    }

    /// Armijo backtracking along `direction` (within the box by construction): the first
    /// point that lowers the cost enough, or `None` when none does (a kink, or the budget).
    fn line_search(
        &mut self,
        x: &[f64],
        f: f64,
        direction: &[f64],
        slope: f64,
    ) -> Option<(Vec<f64>, f64)> {
        let mut t = 1.0;
        for _ in 0..MAX_HALVINGS {
            if self.spent() {
                return None;
            }
            let trial: Vec<f64> = x.iter().zip(direction).map(|(v, d)| v + t * d).collect();
            let f_trial = self.cost(&trial);
            if f_trial < f && f_trial <= f + ARMIJO * t * slope.min(0.0) {
                return Some((trial, f_trial));
            }
            t *= 0.5;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box-bounded problem from a closure.
    struct Boxed<F: Fn(&[f64]) -> f64 + Sync> {
        lower: Vec<f64>,
        upper: Vec<f64>,
        f: F,
    }

    impl<F: Fn(&[f64]) -> f64 + Sync> Problem for Boxed<F> {
        fn lower(&self) -> &[f64] {
            &self.lower
        }
        fn upper(&self) -> &[f64] {
            &self.upper
        }
        fn cost(&self, x: &[f64]) -> f64 {
            (self.f)(x)
        }
    }

    #[test]
    fn an_ill_conditioned_quadratic_reaches_its_minimum_on_a_bound() {
        // Minimum of Σ w_i (x_i − c_i)² over [−10, 10]ⁿ with c_0 = 14 outside the box: the
        // constrained optimum is x_0 = 10, x_i = c_i elsewhere, cost 16 w_0 = 16.
        let c = [14.0, -3.0, 2.5, 7.0, -9.0];
        let w = [1.0, 100.0, 0.01, 10.0, 3.0];
        let p = Boxed {
            lower: vec![-10.0; 5],
            upper: vec![10.0; 5],
            f: |x: &[f64]| (0..5).map(|i| w[i] * (x[i] - c[i]).powi(2)).sum(),
        };
        let d = descend(&p, &[0.0; 5], &DescentSettings::default(), None);
        assert!((d.cost.1 - 16.0).abs() < 1e-6, "{d:?}");
        assert!((d.x[0] - 10.0).abs() < 1e-9, "{d:?}");
        for (x, c) in d.x.iter().zip(c).skip(1) {
            assert!((x - c).abs() < 1e-3, "{x} vs {c}");
        }
    }

    #[test]
    fn rosenbrock_is_descended_to_its_valley_floor() {
        let p = Boxed {
            lower: vec![-5.0; 2],
            upper: vec![5.0; 2],
            f: |x: &[f64]| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2),
        };
        let d = descend(&p, &[-1.2, 1.0], &DescentSettings::default(), None);
        assert!(d.cost.0 > 24.0 && d.cost.1 < 1e-6, "{d:?}");
        assert!(
            (d.x[0] - 1.0).abs() < 1e-3 && (d.x[1] - 1.0).abs() < 2e-3,
            "{d:?}"
        );
    }

    #[test]
    fn a_kink_stops_the_search_and_it_never_ends_worse() {
        // |x − 1| + |y + 2|: central differences at the kink see zero slope or a wrong one;
        // whatever happens, the end is no worse than the start and stays in the box.
        let p = Boxed {
            lower: vec![-3.0; 2],
            upper: vec![3.0; 2],
            f: |x: &[f64]| (x[0] - 1.0).abs() + (x[1] + 2.0).abs(),
        };
        for start in [[0.0, 0.0], [1.0, -2.0], [3.0, 3.0], [-3.0, 1.5]] {
            let d = descend(&p, &start, &DescentSettings::default(), None);
            assert!(d.cost.1 <= d.cost.0, "{start:?}: {d:?}");
            assert!(d.cost.1 < 1e-3, "{start:?}: {d:?}");
            assert!(d.x.iter().all(|v| (-3.0..=3.0).contains(v)), "{d:?}");
        }
    }

    #[test]
    fn the_budget_and_the_stop_flag_end_it_with_what_it_has() {
        let p = Boxed {
            lower: vec![-5.0; 2],
            upper: vec![5.0; 2],
            f: |x: &[f64]| 100.0 * (x[1] - x[0] * x[0]).powi(2) + (1.0 - x[0]).powi(2),
        };
        let few = DescentSettings {
            max_evaluations: 50,
            ..DescentSettings::default()
        };
        let d = descend(&p, &[-1.2, 1.0], &few, None);
        assert!(d.evaluations <= 50 + 4, "{d:?}");
        assert!(d.cost.1 < d.cost.0, "{d:?}");
        assert!(
            (p.cost(&d.x) - d.cost.1).abs() < 1e-12,
            "the cost is the position's"
        );
        let stop = AtomicBool::new(true);
        let d = descend(&p, &[-1.2, 1.0], &DescentSettings::default(), Some(&stop));
        assert_eq!((d.x, d.steps), (vec![-1.2, 1.0], 0));
    }
}
