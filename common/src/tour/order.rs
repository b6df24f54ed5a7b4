//! Visiting order: the swap-operator PSO of Hu et al. 2023, §III-B (eq. (11)–(13), Table 3) for a
//! closed tour from the base (node 0) through every other node and back.
//!
//! A particle is a permutation of the nodes 1..n; its velocity is a swap sequence (a list of
//! position swaps). One move, after Huang et al. (the seed's [32]):
//! - inertia: each swap of the old velocity is kept with probability ω and applied;
//! - `α = pbest − x` (eq. (11)), the basic swap sequence turning x into its personal best, each
//!   swap kept with probability c1 and applied;
//! - `β = gbest − x` (eq. (12)), likewise with probability c2;
//! - the new velocity is the concatenation of the kept swaps;
//! - ω decays after every iteration by eq. (13): `ω ← ω − (ω − 0.01)/M`.
//!
//! Additions, documented because the seed does not have them:
//! - a particle that lands exactly on the global best is mutated by one random swap (the
//!   "mutation" of the abstract), otherwise the swarm collapses onto it and stops searching;
//! - the final best tour is polished by 2-opt, so the answer is at least 2-opt optimal whatever
//!   the budget.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// Distance from `i` to `j`; a missing entry of a ragged matrix counts as unreachable.
pub fn dist_at(dist: &[Vec<f64>], i: usize, j: usize) -> f64 {
    dist.get(i)
        .and_then(|row| row.get(j))
        .copied()
        .unwrap_or(f64::INFINITY)
}

/// Length of the closed tour `0 → order[0] → … → order[last] → 0` (the base is implicit).
pub fn open_order_length(dist: &[Vec<f64>], order: &[usize]) -> f64 {
    let mut prev = 0;
    let mut sum = 0.0;
    for &k in order {
        sum += dist_at(dist, prev, k);
        prev = k;
    }
    sum + dist_at(dist, prev, 0)
}

/// Length of the node sequence `tour` as given (Hu et al. 2023, eq. (27) on a distance matrix).
pub fn tour_length(dist: &[Vec<f64>], tour: &[usize]) -> f64 {
    tour.windows(2).map(|w| dist_at(dist, w[0], w[1])).sum()
}

/// 2-opt on the closed tour `0 → order → 0`: reverses a stretch while that shortens the tour.
pub fn two_opt(dist: &[Vec<f64>], order: &mut [usize]) {
    let n = order.len();
    if n < 2 {
        return;
    }
    let node = |order: &[usize], k: isize| -> usize {
        if k < 0 || k as usize >= order.len() {
            0
        } else {
            order[k as usize]
        }
    };
    let mut improved = true;
    let mut rounds = 0;
    while improved && rounds < 1000 {
        improved = false;
        rounds += 1;
        for i in 0..n - 1 {
            for j in i + 1..n {
                // Edges (a→b) and (c→d) become (a→c) and (b→d) by reversing order[i..=j].
                let a = node(order, i as isize - 1);
                let b = order[i];
                let c = order[j];
                let d = node(order, j as isize + 1);
                let delta = dist_at(dist, a, c) + dist_at(dist, b, d)
                    - dist_at(dist, a, b)
                    - dist_at(dist, c, d);
                if delta < -1e-12 {
                    order[i..=j].reverse();
                    improved = true;
                }
            }
        }
    }
}

/// Basic swap sequence turning `from` into `to` (both permutations of the same values): the
/// "difference" `to − from` of eq. (11)/(12). Swaps are position pairs.
pub fn swap_sequence(from: &[usize], to: &[usize]) -> Vec<(usize, usize)> {
    let mut cur = from.to_vec();
    let max = cur.iter().copied().max().unwrap_or(0);
    let mut pos = vec![usize::MAX; max + 1];
    for (p, &v) in cur.iter().enumerate() {
        pos[v] = p;
    }
    let mut swaps = Vec::new();
    for i in 0..cur.len().min(to.len()) {
        if cur[i] == to[i] {
            continue;
        }
        let Some(&j) = pos.get(to[i]) else { continue };
        if j == usize::MAX || j >= cur.len() {
            continue;
        }
        swaps.push((i, j));
        let (vi, vj) = (cur[i], cur[j]);
        cur.swap(i, j);
        pos[vi] = j;
        pos[vj] = i;
    }
    swaps
}

/// The swap-operator PSO (Hu et al. 2023, §III-B).
#[derive(Debug, Clone)]
pub struct SwapPso {
    /// Population size M (Table 3: 100).
    pub particles: usize,
    /// Iterations (Table 3: 2000).
    pub iterations: usize,
    /// Initial inertia weight w0 (Table 3: 0.9), decayed by eq. (13).
    pub w0: f64,
    /// Probability of keeping a swap of `pbest − x` (Table 3: c1 = 0.7).
    pub c1: f64,
    /// Probability of keeping a swap of `gbest − x` (Table 3: c2 = 0.7).
    pub c2: f64,
    /// RNG seed.
    pub seed: u64,
    /// Raised to end the search before its budget (Ctrl-C, shutdown): the best order found so
    /// far is kept (and still polished by 2-opt).
    pub stop: Option<Arc<AtomicBool>>,
}

/// What [`SwapPso::order_counted`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct Ordered {
    /// The closed tour `[0, …, 0]` (`[]` for no node).
    pub tour: Vec<usize>,
    /// Tour lengths the swarm evaluated.
    pub evaluations: u64,
    /// The stop flag ended the search before its iteration budget.
    pub interrupted: bool,
}

impl SwapPso {
    /// Table 3's settings.
    pub fn table3(seed: u64) -> SwapPso {
        SwapPso {
            particles: 100,
            iterations: 2000,
            w0: 0.9,
            c1: 0.7,
            c2: 0.7,
            seed,
            stop: None,
        }
    }

    /// A short closed tour over the nodes of `dist` (a square matrix, node 0 the base): the node
    /// sequence, starting and ending with 0 (`[0, …, 0]`, length n + 1; `[]` for no node).
    pub fn order(&self, dist: &[Vec<f64>]) -> Vec<usize> {
        self.order_counted(dist).tour
    }

    /// [`SwapPso::order`], the tour lengths the swarm evaluated (the 2-opt pass after it
    /// compares edge pairs, not tours, and is not counted) and whether `stop` cut it short.
    pub fn order_counted(&self, dist: &[Vec<f64>]) -> Ordered {
        let n = dist.len();
        if n == 0 {
            return Ordered {
                tour: Vec::new(),
                evaluations: 0,
                interrupted: false,
            };
        }
        let (mut best, evaluations, interrupted) = self.search(dist, (1..n).collect());
        two_opt(dist, &mut best);
        let mut tour = Vec::with_capacity(n + 1);
        tour.push(0);
        tour.extend(best);
        tour.push(0);
        Ordered {
            tour,
            evaluations,
            interrupted,
        }
    }

    /// The PSO itself over permutations of `nodes`; returns the best order found, the
    /// evaluations made (none for fewer than two nodes: there is only one order) and whether
    /// the stop flag ended it before its budget.
    fn search(&self, dist: &[Vec<f64>], nodes: Vec<usize>) -> (Vec<usize>, u64, bool) {
        if nodes.len() < 2 {
            return (nodes, 0, false);
        }
        let mut rng = StdRng::seed_from_u64(self.seed);
        let m = self.particles.max(1);
        let mut xs: Vec<Vec<usize>> = (0..m)
            .map(|_| {
                let mut x = nodes.clone();
                shuffle(&mut x, &mut rng);
                x
            })
            .collect();
        let mut vs: Vec<Vec<(usize, usize)>> = vec![Vec::new(); m];
        let mut costs: Vec<f64> = xs.iter().map(|x| open_order_length(dist, x)).collect();
        let mut evaluations = m as u64;
        let mut pbest = xs.clone();
        let mut pcost = costs.clone();
        let (mut gbest, mut gcost) = (xs[0].clone(), costs[0]);
        for (x, &c) in xs.iter().zip(&costs) {
            if c < gcost {
                (gbest, gcost) = (x.clone(), c);
            }
        }
        let mut w = self.w0;
        for _ in 0..self.iterations {
            if self
                .stop
                .as_ref()
                .is_some_and(|s| s.load(Ordering::Relaxed))
            {
                return (gbest, evaluations, true);
            }
            for i in 0..m {
                let x = &mut xs[i];
                let mut v = Vec::new();
                for &s in &vs[i] {
                    if rng.random::<f64>() < w {
                        x.swap(s.0, s.1);
                        v.push(s);
                    }
                }
                for (target, keep) in [(&pbest[i], self.c1), (&gbest, self.c2)] {
                    // Hu et al. 2023, eq. (11) / (12)
                    for s in swap_sequence(x, target) {
                        if rng.random::<f64>() < keep {
                            x.swap(s.0, s.1);
                            v.push(s);
                        }
                    }
                }
                if *x == gbest {
                    let a = rng.random_range(0..x.len());
                    let b = rng.random_range(0..x.len());
                    x.swap(a, b);
                }
                vs[i] = v;
                costs[i] = open_order_length(dist, x);
                evaluations += 1;
                if costs[i] < pcost[i] {
                    pcost[i] = costs[i];
                    pbest[i].clone_from(x);
                }
                if costs[i] < gcost {
                    gcost = costs[i];
                    gbest.clone_from(x);
                }
            }
            // Hu et al. 2023, eq. (13)
            w -= (w - 0.01) / m as f64;
        }
        (gbest, evaluations, false)
    }
}

/// Fisher–Yates shuffle from the run's RNG.
fn shuffle(x: &mut [usize], rng: &mut StdRng) {
    for i in (1..x.len()).rev() {
        let j = rng.random_range(0..=i);
        x.swap(i, j);
    }
}

/// Euclidean distance matrix of `nodes`.
pub fn distance_matrix(nodes: &[crate::geometry::Vec3]) -> Vec<Vec<f64>> {
    nodes
        .iter()
        .map(|a| nodes.iter().map(|b| (a - b).norm()).collect())
        .collect()
}

/// Most points [`optimal_tour_length`] takes: its table holds `2ⁿ · n` lengths (16: about a
/// million, 8 MB).
pub const MAX_EXACT_POINTS: usize = 16;

/// The length of the shortest closed tour from node 0 through every other node of `dist` and
/// back (Held & Karp 1962's dynamic programme): the reference the swap-operator PSO's order is
/// measured against. `None` over [`MAX_EXACT_POINTS`] points.
pub fn optimal_tour_length(dist: &[Vec<f64>]) -> Option<f64> {
    let n = dist.len().checked_sub(1)?;
    if n > MAX_EXACT_POINTS {
        return None;
    }
    if n == 0 {
        return Some(0.0);
    }
    // best[set · n + last]: shortest path from node 0 through the points of `set` (bit k is
    // node k + 1), ending at node `last + 1`.
    let full = 1usize << n;
    let mut best = vec![f64::INFINITY; full * n];
    for k in 0..n {
        best[(1 << k) * n + k] = dist_at(dist, 0, k + 1);
    }
    for set in 1..full {
        for last in 0..n {
            let here = best[set * n + last];
            if set & (1 << last) == 0 || !here.is_finite() {
                continue;
            }
            for next in (0..n).filter(|k| set & (1 << k) == 0) {
                let to = (set | (1 << next)) * n + next;
                best[to] = best[to].min(here + dist_at(dist, last + 1, next + 1));
            }
        }
    }
    let shortest = (0..n)
        .map(|last| best[(full - 1) * n + last] + dist_at(dist, last + 1, 0))
        .fold(f64::INFINITY, f64::min);
    Some(shortest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;
    use approx::assert_abs_diff_eq;

    /// Shortest closed tour by trying every order of nodes 1..n.
    fn brute_force(dist: &[Vec<f64>]) -> f64 {
        fn rec(dist: &[Vec<f64>], rest: &mut Vec<usize>, k: usize, best: &mut f64) {
            if k == rest.len() {
                *best = best.min(open_order_length(dist, rest));
                return;
            }
            for i in k..rest.len() {
                rest.swap(k, i);
                rec(dist, rest, k + 1, best);
                rest.swap(k, i);
            }
        }
        let mut rest: Vec<usize> = (1..dist.len()).collect();
        let mut best = f64::INFINITY;
        rec(dist, &mut rest, 0, &mut best);
        best
    }

    fn random_instance(n: usize, seed: u64) -> Vec<Vec<f64>> {
        let mut rng = StdRng::seed_from_u64(seed);
        let pts: Vec<Vec3> = (0..n)
            .map(|_| {
                Vec3::new(
                    rng.random_range(0.0..500.0),
                    rng.random_range(0.0..500.0),
                    rng.random_range(0.0..500.0),
                )
            })
            .collect();
        distance_matrix(&pts)
    }

    #[test]
    fn tour_length_of_a_square_by_hand() {
        let sq = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(3.0, 4.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        ];
        let d = distance_matrix(&sq);
        // Around the rectangle: 3 + 4 + 3 + 4 = 14.
        assert_abs_diff_eq!(tour_length(&d, &[0, 1, 2, 3, 0]), 14.0, epsilon = 1e-12);
        assert_abs_diff_eq!(open_order_length(&d, &[1, 2, 3]), 14.0, epsilon = 1e-12);
        // Crossing the diagonals: 5 + 4 + 5 + 4 = 18.
        assert_abs_diff_eq!(tour_length(&d, &[0, 2, 1, 3, 0]), 18.0, epsilon = 1e-12);
        // 2-opt uncrosses it.
        let mut o = vec![2, 1, 3];
        two_opt(&d, &mut o);
        assert_abs_diff_eq!(open_order_length(&d, &o), 14.0, epsilon = 1e-12);
        let tour = SwapPso::table3(1).order(&d);
        assert_eq!((tour[0], tour[4], tour.len()), (0, 0, 5));
        assert_abs_diff_eq!(tour_length(&d, &tour), 14.0, epsilon = 1e-12);
    }

    #[test]
    fn swap_sequence_turns_one_permutation_into_another() {
        let (a, b) = (vec![1, 2, 3, 4, 5], vec![3, 1, 5, 4, 2]);
        let ss = swap_sequence(&a, &b);
        let mut x = a.clone();
        for (i, j) in &ss {
            x.swap(*i, *j);
        }
        assert_eq!(x, b);
        assert!(ss.len() <= 4);
        assert!(swap_sequence(&b, &b).is_empty());
    }

    #[test]
    fn swap_pso_finds_the_brute_force_optimum_on_small_instances() {
        for (n, seed) in [(4, 1), (5, 2), (6, 3), (7, 4), (8, 5), (8, 6), (8, 7)] {
            let d = random_instance(n, seed);
            let tour = SwapPso::table3(seed).order(&d);
            let mut seen = tour[1..n].to_vec();
            seen.sort_unstable();
            assert_eq!(seen, (1..n).collect::<Vec<_>>(), "n {n}: {tour:?}");
            assert_eq!((tour[0], tour[n]), (0, 0));
            assert_abs_diff_eq!(tour_length(&d, &tour), brute_force(&d), epsilon = 1e-9);
        }
    }

    #[test]
    fn swap_pso_without_2_opt_already_finds_the_optimum() {
        // The PSO alone (the polish disabled by calling the search directly) on 8 nodes.
        let d = random_instance(8, 11);
        let (best, evaluations, interrupted) = SwapPso::table3(11).search(&d, (1..8).collect());
        assert!(!interrupted);
        // Table 3: 100 particles evaluated at the start and once in each of 2000 iterations.
        assert_eq!(evaluations, 100 * 2001);
        assert_abs_diff_eq!(
            open_order_length(&d, &best),
            brute_force(&d),
            epsilon = 1e-9
        );
    }

    #[test]
    fn swap_pso_is_deterministic_and_total() {
        let d = random_instance(10, 9);
        let p = SwapPso {
            iterations: 200,
            ..SwapPso::table3(5)
        };
        assert_eq!(p.order(&d), p.order(&d));
        assert_eq!(p.order(&[]), Vec::<usize>::new());
        assert_eq!(p.order(&[vec![0.0]]), vec![0, 0]);
        // A ragged matrix does not panic; its missing entries are unreachable.
        let ragged = vec![vec![0.0, 1.0], vec![1.0]];
        assert_eq!(p.order(&ragged), vec![0, 1, 0]);
        // Counted: 100 × (200 + 1) tours for 9 points; none when there is one order only.
        assert_eq!(
            p.order_counted(&d),
            Ordered {
                tour: p.order(&d),
                evaluations: 100 * 201,
                interrupted: false
            }
        );
        assert_eq!(p.order_counted(&[vec![0.0]]).evaluations, 0);
        assert_eq!(p.order_counted(&ragged).evaluations, 0);
    }

    #[test]
    fn a_raised_stop_ends_the_search_at_once_with_a_complete_polished_tour() {
        let d = random_instance(8, 4);
        let stop = Arc::new(AtomicBool::new(true));
        let p = SwapPso {
            stop: Some(Arc::clone(&stop)),
            ..SwapPso::table3(4)
        };
        let cut = p.order_counted(&d);
        // Only the 100 initial tours were evaluated; the answer still visits every node once
        // and is 2-opt optimal.
        assert_eq!((cut.evaluations, cut.interrupted), (100, true));
        let mut seen = cut.tour[1..8].to_vec();
        seen.sort_unstable();
        assert_eq!(seen, (1..8).collect::<Vec<_>>());
        let mut polished = cut.tour[1..8].to_vec();
        two_opt(&d, &mut polished);
        assert_eq!(polished, cut.tour[1..8].to_vec());
        // Lowered, the same solver runs its whole budget.
        stop.store(false, Ordering::Relaxed);
        let full = p.order_counted(&d);
        assert_eq!((full.evaluations, full.interrupted), (100 * 2001, false));
    }

    #[test]
    fn the_exact_tour_is_the_shortest_of_every_order() {
        // Four points on a square's corners and one off it: the exact length equals the best of
        // all 4! orders, computed by brute force, and a hand value for the square.
        let square = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
        let matrix = |p: &[[f64; 2]]| -> Vec<Vec<f64>> {
            p.iter()
                .map(|a| p.iter().map(|b| d(*a, *b)).collect())
                .collect()
        };
        assert_eq!(optimal_tour_length(&matrix(&square)), Some(40.0));
        let pts = [
            [0.0, 0.0],
            [7.0, 1.0],
            [3.0, 9.0],
            [9.0, 8.0],
            [1.0, 4.0],
            [5.0, 5.0],
        ];
        let m = matrix(&pts);
        let mut brute = f64::INFINITY;
        let mut order: Vec<usize> = (1..pts.len()).collect();
        permute(&mut order, 0, &mut |o| {
            let tour: Vec<usize> = std::iter::once(0)
                .chain(o.iter().copied())
                .chain([0])
                .collect();
            brute = brute.min(tour_length(&m, &tour));
        });
        let exact = optimal_tour_length(&m).unwrap_or(f64::NAN);
        assert!((exact - brute).abs() < 1e-9, "{exact} vs {brute}");
        assert_eq!(optimal_tour_length(&[vec![0.0]]), Some(0.0));
        let big = vec![vec![1.0; MAX_EXACT_POINTS + 2]; MAX_EXACT_POINTS + 2];
        assert_eq!(optimal_tour_length(&big), None);
    }

    fn permute(v: &mut Vec<usize>, k: usize, visit: &mut dyn FnMut(&[usize])) {
        if k == v.len() {
            return visit(v);
        }
        for i in k..v.len() {
            v.swap(k, i);
            permute(v, k + 1, visit);
            v.swap(k, i);
        }
    }
}
