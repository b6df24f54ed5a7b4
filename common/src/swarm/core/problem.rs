//! The problem a swarm minimises: a box, a cost, and the structure solvers may exploit (blocks
//! of a decomposable cost, groups of dimensions moved together, hard constraints).

use rand::rngs::StdRng;
use rand::Rng;

/// A box-bounded minimisation problem.
pub trait Problem: Sync {
    /// Lower bound of every dimension.
    fn lower(&self) -> &[f64];
    /// Upper bound of every dimension.
    fn upper(&self) -> &[f64];
    /// Cost of a position; lower is better. Must be finite for any in-bounds position.
    fn cost(&self, x: &[f64]) -> f64;
    /// Number of dimensions.
    fn dim(&self) -> usize {
        self.lower().len()
    }
    /// How many blocks the cost is a sum of (1: not decomposable). The fleet fitness, eq. (12),
    /// is a sum over vehicles, one block per chromosome; solvers keep their memories (o_pbest,
    /// o_gbest) block by block so a good chromosome is not forgotten because another vehicle of
    /// the same particle was bad.
    fn blocks(&self) -> usize {
        1
    }
    /// Dimensions of block `b`.
    fn block_range(&self, b: usize) -> std::ops::Range<usize> {
        let _ = b;
        0..self.dim()
    }
    /// Ranges of dimensions a solver moves as a whole: one random factor per range and one
    /// velocity scaling per range. The default, one range per dimension, is textbook PSO; a
    /// problem whose ranges are geometric objects (a vehicle's path) keeps them smooth this way.
    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        (0..self.dim()).map(|d| d..d + 1).collect()
    }
    /// Cost split by block: writes block `b`'s share into `parts[b]` and returns the total, which
    /// equals the sum of the parts and [`Problem::cost`].
    fn cost_parts(&self, x: &[f64], parts: &mut [f64]) -> f64 {
        let c = self.cost(x);
        if let Some(p) = parts.first_mut() {
            *p = c;
        }
        c
    }
    /// True when `x` meets every hard constraint of the problem. Solvers that keep a set of
    /// feasible solutions (EPA-PSO, Zhang et al. 2022, §3.2.2) ask it; the default calls everything
    /// feasible, which is right for unconstrained problems.
    fn feasible(&self, x: &[f64]) -> bool {
        let _ = x;
        true
    }
    /// An initial position. Default: uniform in the box (Zhi & Zuo 2024, §3.1, `g ~ U`).
    fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        self.lower()
            .iter()
            .zip(self.upper())
            .map(|(lo, hi)| rng.random_range(*lo..=*hi))
            .collect()
    }
}
