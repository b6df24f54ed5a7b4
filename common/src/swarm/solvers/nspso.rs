//! NSPSO, Lu et al.'s non-dominated sorting PSO baseline (ref. \[46\], Li 2003) with the settings of
//! Table 4 (functions: M = 30, t_max = 300) and Table 8 (crawler path: M = 50, t_max = 100):
//! c1 = c2 = 2 and an inertia weight falling linearly from ω_max = 0.9 to ω_min = 0.4. The seed
//! gives nothing more, so Shoal reads Li's algorithm as follows.
//!
//! Each particle keeps its own trajectory (x, v) and a memory, its personal best. One iteration:
//! 1. the N memories are sorted into non-dominated fronts, and the first front is ordered least
//!    crowded first (largest crowding distance); every particle draws its leader uniformly from
//!    the top `leader_share` of that front (at least one member);
//! 2. every particle moves by the shared PSO update (eq. (5) with c3 = 0) towards its memory and
//!    its leader, and is evaluated;
//! 3. the N memories and the N new positions (2N candidates) are sorted the same way (fronts,
//!    then crowding distance within a front, NSGA-II style) and the best N become the next
//!    memories. NSPSO's elitism lies in this step: a memory survives only while it ranks in the
//!    top N of the combined set, not just while its own particle fails to improve on it.
//!
//! Li does not say which of the N survivors becomes whose personal best. Shoal keeps them
//! personal where it can: a particle keeps the better of its own survivors (its old memory, its
//! new position), and a particle with no survivor inherits, in particle order, a survivor of a
//! particle that had two. (pagmo2's `nspso` instead hands memory k to particle k in rank order,
//! which makes the cognitive pull point at another particle's memory.)
//!
//! Objectives. The seed runs NSPSO on single-objective problems (the benchmark functions, the
//! crawler's weighted cost). By default the sort uses the one objective, the cost: fronts are
//! then cost levels, step 3 is an elitist (N + N) truncation, and the first front is the best
//! memory, so the leader is the global best — Li's algorithm reduced exactly to one objective,
//! with no second objective invented. With `block_objectives` and a problem of several blocks
//! (the fleet, one block per vehicle) each block's cost is an objective and the sort is truly
//! multi-objective; it is off by default because a Pareto sort over five vehicles keeps almost
//! every candidate in the first front and so puts little pressure on the sum the planner
//! minimises. Memories are whole positions with their true costs (not assembled block by block
//! as in `population.rs`), since the sort compares evaluated points.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use crate::swarm::core::population::{update, Coefficients, Limits, Particle};
use crate::swarm::core::{Problem, Progress, Solver, SolverState};

/// The NSPSO solver (Table 4 / Table 8 settings).
#[derive(Debug, Clone)]
pub struct Nspso {
    /// Particles M (Table 4: 30, Table 8: 50).
    pub particles: usize,
    /// Cognitive factor c1 (Tables 4 and 8: 2).
    pub c1: f64,
    /// Social factor c2 (Tables 4 and 8: 2).
    pub c2: f64,
    /// ω at the first and at the last iteration (ω_max = 0.9 → ω_min = 0.4).
    pub w: (f64, f64),
    /// Share of the first front, least crowded first, that leaders are drawn from (not in
    /// Lu et al. 2023; Li draws from "a top part" of the sorted front).
    pub leader_share: f64,
    /// Sort on per-block costs instead of the total when the problem has several blocks.
    pub block_objectives: bool,
    /// Velocity cap as a fraction of each dimension's range (not in the paper; the same cap as
    /// SPSO and CBPSO so the baselines differ only in what the seed says).
    pub max_velocity_fraction: f64,
    /// RNG seed.
    pub seed: u64,
}

impl Nspso {
    /// Table 8's settings (Table 4's are the same with M = 30).
    pub fn table8(particles: usize, seed: u64) -> Nspso {
        Nspso {
            particles,
            c1: 2.0,
            c2: 2.0,
            w: (0.9, 0.4),
            leader_share: 0.1,
            block_objectives: false,
            max_velocity_fraction: 0.2,
            seed,
        }
    }

    /// Inertia weight at `progress`: linear from `w.0` to `w.1`.
    pub fn inertia(&self, progress: Progress) -> f64 {
        self.w.0 + (self.w.1 - self.w.0) * progress.fraction()
    }

    fn objectives<P: Problem>(&self, problem: &P, cost: f64, parts: &[f64]) -> Vec<f64> {
        if self.block_objectives && problem.blocks() > 1 {
            parts.to_vec()
        } else {
            vec![cost]
        }
    }
}

/// Whether `a` Pareto-dominates `b` (minimisation): no worse in every objective, better in one.
pub fn dominates(a: &[f64], b: &[f64]) -> bool {
    let mut better = false;
    for (x, y) in a.iter().zip(b) {
        if x > y {
            return false;
        }
        better |= x < y;
    }
    better
}

/// Non-dominated fronts of `points` (Deb's fast non-dominated sort): front 0 holds the points no
/// other point dominates, front 1 those dominated only by front 0, and so on. Indices within a
/// front are in increasing order.
pub fn non_dominated_fronts(points: &[Vec<f64>]) -> Vec<Vec<usize>> {
    let n = points.len();
    let mut dominated_by = vec![0usize; n];
    let mut dominating: Vec<Vec<usize>> = vec![Vec::new(); n];
    for i in 0..n {
        for j in i + 1..n {
            if dominates(&points[i], &points[j]) {
                dominating[i].push(j);
                dominated_by[j] += 1;
            } else if dominates(&points[j], &points[i]) {
                dominating[j].push(i);
                dominated_by[i] += 1;
            }
        }
    }
    let mut fronts = Vec::new();
    let mut current: Vec<usize> = (0..n).filter(|i| dominated_by[*i] == 0).collect();
    while !current.is_empty() {
        let mut next = Vec::new();
        for &i in &current {
            for &j in &dominating[i] {
                dominated_by[j] -= 1;
                if dominated_by[j] == 0 {
                    next.push(j);
                }
            }
        }
        next.sort_unstable();
        fronts.push(current);
        current = next;
    }
    fronts
}

/// Crowding distance of each member of `front` (NSGA-II), aligned with `front`: per objective,
/// the front is sorted, its two ends get infinity, and every other member adds the gap between
/// its neighbours divided by the objective's range. An objective with zero range in the front
/// adds nothing (its members are equal in it), so a front of equal single costs is not split.
pub fn crowding_distances(points: &[Vec<f64>], front: &[usize]) -> Vec<f64> {
    let m = front.len();
    let mut d = vec![0.0; m];
    if m <= 2 {
        return vec![f64::INFINITY; m];
    }
    let objectives = points.get(front[0]).map_or(0, Vec::len);
    let mut order: Vec<usize> = (0..m).collect();
    for k in 0..objectives {
        let f: Vec<f64> = front
            .iter()
            .map(|&i| points.get(i).and_then(|p| p.get(k)).copied())
            .map(|v| v.unwrap_or(f64::NAN))
            .collect();
        order.sort_by(|a, b| f[*a].total_cmp(&f[*b]).then(a.cmp(b)));
        let range = f[order[m - 1]] - f[order[0]];
        if range.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        d[order[0]] = f64::INFINITY;
        d[order[m - 1]] = f64::INFINITY;
        for w in order.windows(3) {
            d[w[1]] += (f[w[2]] - f[w[0]]) / range;
        }
    }
    d
}

/// All indices of `points`, best first: by front, then by crowding distance (largest first),
/// then by index, so the order is deterministic.
pub fn nondominated_order(points: &[Vec<f64>]) -> Vec<usize> {
    let mut order = Vec::with_capacity(points.len());
    for front in non_dominated_fronts(points) {
        let crowd = crowding_distances(points, &front);
        let mut members: Vec<usize> = (0..front.len()).collect();
        members.sort_by(|a, b| crowd[*b].total_cmp(&crowd[*a]).then(a.cmp(b)));
        order.extend(members.into_iter().map(|k| front[k]));
    }
    order
}

/// Which candidate becomes each particle's memory. Candidates `0..n` are the old memories of
/// particles `0..n`, candidates `n..2n` their new positions; `selected` are the survivors, best
/// first. A particle takes its own best survivor; particles with none take the leftovers (the
/// second survivors of particles that had two) in particle order.
pub fn assign_memories(selected: &[usize], n: usize) -> Vec<usize> {
    let mut slot: Vec<Option<usize>> = vec![None; n];
    let mut spare = Vec::new();
    for &k in selected {
        match slot.get_mut(k % n.max(1)) {
            Some(s @ None) => *s = Some(k),
            _ => spare.push(k),
        }
    }
    let mut spare = spare.into_iter();
    slot.iter()
        .enumerate()
        .map(|(i, s)| s.or_else(|| spare.next()).unwrap_or(i))
        .collect()
}

/// State of an NSPSO run.
#[derive(Debug, Clone)]
pub struct NspsoState {
    /// The particles: `x`, `v`, `cost`, `parts` are where they are; `best_*` is the memory.
    pub particles: Vec<Particle>,
    /// Box and velocity limits.
    pub limits: Limits,
    /// The run's random stream (leaders, r1, r2).
    pub rng: StdRng,
    /// Best position truly evaluated so far (what the run reports; with block objectives the
    /// memories need not contain it).
    pub elite_x: Vec<f64>,
    /// Its cost.
    pub elite_cost: f64,
    /// Evaluations so far.
    pub evaluations: u64,
}

impl NspsoState {
    fn keep_elite(&mut self) {
        for p in &self.particles {
            if p.cost < self.elite_cost {
                self.elite_cost = p.cost;
                self.elite_x.clone_from(&p.x);
            }
        }
    }
}

impl SolverState for NspsoState {
    fn best_cost(&self) -> f64 {
        self.elite_cost
    }
    fn best_position(&self) -> &[f64] {
        &self.elite_x
    }
    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

impl<P: Problem> Solver<P> for Nspso {
    type State = NspsoState;

    fn name(&self) -> &'static str {
        "nspso"
    }

    fn init(&mut self, problem: &P) -> NspsoState {
        let mut rng = StdRng::seed_from_u64(self.seed);
        let particles: Vec<Particle> = (0..self.particles.max(1))
            .map(|_| {
                let x = problem.sample(&mut rng);
                Particle::new(problem, x)
            })
            .collect();
        let mut state = NspsoState {
            evaluations: particles.len() as u64,
            particles,
            limits: Limits::of(problem, self.max_velocity_fraction),
            rng,
            elite_x: Vec::new(),
            elite_cost: f64::INFINITY,
        };
        state.keep_elite();
        state
    }

    fn step(&mut self, problem: &P, mut state: NspsoState, progress: Progress) -> NspsoState {
        let n = state.particles.len();
        if n == 0 {
            return state;
        }
        // 1. Leaders: the least crowded top of the memories' first front.
        let memories: Vec<Vec<f64>> = state
            .particles
            .iter()
            .map(|p| self.objectives(problem, p.best_cost, &p.best_parts))
            .collect();
        let first = non_dominated_fronts(&memories)
            .into_iter()
            .next()
            .unwrap_or_default();
        let crowd = crowding_distances(&memories, &first);
        let mut leaders: Vec<usize> = (0..first.len()).collect();
        leaders.sort_by(|a, b| crowd[*b].total_cmp(&crowd[*a]).then(a.cmp(b)));
        let top = ((self.leader_share * first.len() as f64).ceil() as usize).clamp(1, n);
        let leaders: Vec<usize> = leaders.iter().take(top).map(|k| first[*k]).collect();
        // 2. Move and evaluate.
        let c = Coefficients {
            w: self.inertia(progress),
            c1: self.c1,
            c2: self.c2,
            c3: 0.0,
        };
        let leader_x: Vec<Vec<f64>> = (0..n)
            .map(|_| {
                let l = leaders[state.rng.random_range(0..leaders.len().max(1))];
                state.particles[l].best_x.clone()
            })
            .collect();
        for (p, g) in state.particles.iter_mut().zip(&leader_x) {
            update(p, g, None, c, &state.limits, &mut state.rng);
            p.cost = problem.cost_parts(&p.x, &mut p.parts);
        }
        state.evaluations += n as u64;
        state.keep_elite();
        // 3. The best N of memories ∪ new positions become the memories.
        let mut candidates = memories;
        candidates.extend(
            state
                .particles
                .iter()
                .map(|p| self.objectives(problem, p.cost, &p.parts)),
        );
        let order = nondominated_order(&candidates);
        let chosen = assign_memories(&order[..n], n);
        let next: Vec<(Vec<f64>, Vec<f64>, f64)> = chosen
            .iter()
            .map(|&k| {
                let p = &state.particles[k % n];
                if k < n {
                    (p.best_x.clone(), p.best_parts.clone(), p.best_cost)
                } else {
                    (p.x.clone(), p.parts.clone(), p.cost)
                }
            })
            .collect();
        for (p, (x, parts, cost)) in state.particles.iter_mut().zip(next) {
            p.best_x = x;
            p.best_parts = parts;
            p.best_cost = cost;
        }
        state
    }
}

velocity_capped!(Nspso);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::core::Executor;
    use crate::swarm::testfns::{Rastrigin, ShiftedSphere};
    use approx::assert_abs_diff_eq;

    /// Two objectives: a 4-point first front, a dominated point, and one dominated by it.
    fn points() -> Vec<Vec<f64>> {
        vec![
            vec![3.0, 4.0], // 0: D, dominated by B only → front 1
            vec![1.0, 5.0], // 1: A
            vec![5.0, 5.0], // 2: E, dominated by everyone → front 2
            vec![2.0, 3.0], // 3: B
            vec![4.0, 1.0], // 4: C
            vec![3.0, 2.0], // 5: F
        ]
    }

    #[test]
    fn fronts_and_crowding_distances_by_hand() {
        let p = points();
        assert!(dominates(&p[3], &p[0]));
        assert!(!dominates(&p[1], &p[3]) && !dominates(&p[3], &p[1]));
        assert!(!dominates(&p[0], &p[0]), "a point does not dominate itself");
        assert_eq!(
            non_dominated_fronts(&p),
            vec![vec![1, 3, 4, 5], vec![0], vec![2]]
        );
        // Front 0 = A(1,5) B(2,3) C(4,1) F(3,2); ranges 3 (f1) and 4 (f2).
        // f1 order A B F C: B += (3−1)/3, F += (4−2)/3. f2 order C F B A: F += (3−1)/4,
        // B += (5−2)/4. A and C are ends: infinite.
        let d = crowding_distances(&p, &[1, 3, 4, 5]);
        assert!(d[0].is_infinite() && d[2].is_infinite());
        assert_abs_diff_eq!(d[1], 2.0 / 3.0 + 3.0 / 4.0, epsilon = 1e-12);
        assert_abs_diff_eq!(d[3], 2.0 / 3.0 + 2.0 / 4.0, epsilon = 1e-12);
        // Best first: the ends (A, C), then B (17/12) before F (7/6), then D, then E.
        assert_eq!(nondominated_order(&p), vec![1, 4, 3, 5, 0, 2]);
        // Fronts of one or two points are all ends; equal costs are one front, not split.
        assert!(crowding_distances(&p, &[0, 2])
            .iter()
            .all(|d| d.is_infinite()));
        let ties = vec![vec![1.0], vec![0.5], vec![1.0], vec![1.0]];
        assert_eq!(non_dominated_fronts(&ties), vec![vec![1], vec![0, 2, 3]]);
        assert_eq!(crowding_distances(&ties, &[0, 2, 3]), vec![0.0; 3]);
    }

    #[test]
    fn memories_stay_personal_and_elitism_reassigns_the_rest() {
        // One objective. Memories cost (1, 5, 3), new positions (4, 0.5, 6): the best three are
        // candidates 4 (0.5), 0 (1), 2 (3) — each particle keeps its own better one.
        let costs = [1.0, 5.0, 3.0, 4.0, 0.5, 6.0].map(|c| vec![c]);
        let order = nondominated_order(&costs);
        assert_eq!(order, vec![4, 0, 2, 3, 1, 5]);
        assert_eq!(assign_memories(&order[..3], 3), vec![0, 4, 2]);
        // Memories (1, 5, 9), positions (2, 6, 10): survivors 0 (1), 3 (2), 1 (5). Particle 0
        // has two (keeps 0), particle 2 has none and inherits particle 0's new position (3).
        let costs = [1.0, 5.0, 9.0, 2.0, 6.0, 10.0].map(|c| vec![c]);
        let order = nondominated_order(&costs);
        assert_eq!(assign_memories(&order[..3], 3), vec![0, 1, 3]);
    }

    #[test]
    fn inertia_falls_linearly_from_0_9_to_0_4() {
        let s = Nspso::table8(50, 1);
        let at = |t| Progress {
            iteration: t,
            max_iterations: 100,
        };
        assert_abs_diff_eq!(s.inertia(at(0)), 0.9);
        assert_abs_diff_eq!(s.inertia(at(50)), 0.65, epsilon = 1e-12);
        assert_abs_diff_eq!(s.inertia(at(100)), 0.4, epsilon = 1e-12);
    }

    #[test]
    fn nspso_converges_on_the_shifted_sphere_and_is_deterministic() {
        let sphere = ShiftedSphere::new(8);
        let run = |seed| Executor::new(300).run(&sphere, &mut Nspso::table8(30, seed), |_| {});
        let out = run(3);
        assert!(out.state.best_cost() < 1e-6, "{}", out.state.best_cost());
        for (a, b) in out.state.best_position().iter().zip(&sphere.shift) {
            assert!((a - b).abs() < 1e-3, "{a} vs optimum {b}");
        }
        assert!(out.convergence.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(out.state.evaluations(), 30 * 301);
        let again = run(3);
        assert_eq!(again.convergence, out.convergence);
        assert_eq!(again.state.best_position(), out.state.best_position());
        let other = run(4);
        assert_ne!(other.convergence, out.convergence);
        // Rastrigin 2-D, Table 4's budget: reaches the global basin (other minima cost ≥ ~1).
        let r = Rastrigin::new(2);
        let out = Executor::new(300).run(&r, &mut Nspso::table8(30, 5), |_| {});
        assert!(out.state.best_cost() < 1e-4, "{}", out.state.best_cost());
    }

    /// Two independent blocks: f = (x0 − 1)² + (x1 + 2)², one objective per block.
    struct TwoBowls;
    impl Problem for TwoBowls {
        fn lower(&self) -> &[f64] {
            &[-10.0, -10.0]
        }
        fn upper(&self) -> &[f64] {
            &[10.0, 10.0]
        }
        fn cost(&self, x: &[f64]) -> f64 {
            (x[0] - 1.0).powi(2) + (x[1] + 2.0).powi(2)
        }
        fn blocks(&self) -> usize {
            2
        }
        fn block_range(&self, b: usize) -> std::ops::Range<usize> {
            b..b + 1
        }
        fn cost_parts(&self, x: &[f64], parts: &mut [f64]) -> f64 {
            parts[0] = (x[0] - 1.0).powi(2);
            parts[1] = (x[1] + 2.0).powi(2);
            parts[0] + parts[1]
        }
    }

    #[test]
    fn block_objectives_sort_on_two_objectives_and_still_find_the_ideal_point() {
        let mut s = Nspso::table8(20, 2);
        s.block_objectives = true;
        let out = Executor::new(200).run(&TwoBowls, &mut s, |_| {});
        // The blocks do not conflict, so the Pareto front is the single point (1, −2). The sort
        // keeps each objective's extremes (infinite crowding), so it closes in more slowly than
        // on the sum (about 1e-4 here against 1e-18), but it does close in from a cost of ~70.
        assert!(out.state.best_cost() < 1e-2, "{}", out.state.best_cost());
    }
}
