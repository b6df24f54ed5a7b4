//! Particles, populations and the PSO update rules every variant shares: eq. (5) for a population
//! on its own and eq. (6) when a third attractor (the followers' best) is added, with either fixed
//! coefficients (Table 5) or the adaptive ones of eq. (7)–(8).
//!
//! Memories are kept block by block (see [`Problem::blocks`]): a particle's personal best is, for
//! each block, the best that block has been, and a population's global best takes each block from
//! the particle that remembers it best. For a problem of one block this is textbook PSO. Because
//! an assembled best was never evaluated as a whole, every population also keeps its *elite*: the
//! best position it has truly evaluated, which is what a run reports.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use super::problem::Problem;
use super::solver::Progress;
use crate::geometry::{larger, smaller};

/// Seed of population `k`: distinct streams from one user seed. Every multi-population solver
/// and the distributed followers and leader draw their streams from it, so a population gets
/// the same stream in-process and distributed.
pub fn stream_seed(seed: u64, k: u64) -> u64 {
    seed ^ (k + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// One particle: where it is, where it goes, and the best place each block of it has been.
#[derive(Debug, Clone, PartialEq)]
pub struct Particle {
    /// Position x_i(k).
    pub x: Vec<f64>,
    /// Velocity v_i(k).
    pub v: Vec<f64>,
    /// Cost of `x` (a true evaluation).
    pub cost: f64,
    /// Cost of `x` per block.
    pub parts: Vec<f64>,
    /// Personal best o_pbest, assembled block by block.
    pub best_x: Vec<f64>,
    /// Per-block cost of `best_x`'s blocks when they were evaluated.
    pub best_parts: Vec<f64>,
    /// Sum of `best_parts`.
    pub best_cost: f64,
}

impl Particle {
    /// A particle at `x` with zero velocity, evaluated.
    pub fn new<P: Problem>(problem: &P, x: Vec<f64>) -> Particle {
        let mut parts = vec![0.0; problem.blocks()];
        let cost = problem.cost_parts(&x, &mut parts);
        Particle {
            v: vec![0.0; x.len()],
            best_x: x.clone(),
            best_parts: parts.clone(),
            best_cost: cost,
            cost,
            parts,
            x,
        }
    }

    /// Re-evaluates after a move and keeps each block's personal best.
    pub fn evaluate<P: Problem>(&mut self, problem: &P) {
        self.cost = problem.cost_parts(&self.x, &mut self.parts);
        for b in 0..self.parts.len() {
            if self.parts[b] < self.best_parts[b] {
                self.best_parts[b] = self.parts[b];
                let r = problem.block_range(b);
                self.best_x[r.clone()].copy_from_slice(&self.x[r]);
            }
        }
        self.best_cost = self.best_parts.iter().sum();
    }
}

/// Global best assembled block by block from the personal bests of `particles`: each block comes
/// from the particle that remembers it best. Returns the position and its per-block costs.
pub fn assemble<'a, P: Problem>(
    problem: &P,
    particles: impl Iterator<Item = &'a Particle> + Clone,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let first = particles.clone().next()?;
    let mut x = first.best_x.clone();
    let mut parts = first.best_parts.clone();
    for p in particles.skip(1) {
        for (b, part) in parts.iter_mut().enumerate() {
            if p.best_parts[b] < *part {
                *part = p.best_parts[b];
                let r = problem.block_range(b);
                x[r.clone()].copy_from_slice(&p.best_x[r]);
            }
        }
    }
    Some((x, parts))
}

/// A global best the swarm may follow, with what it cost to find out.
#[derive(Debug, Clone, PartialEq)]
pub struct TrustedBest {
    /// The attractor o_gbest.
    pub x: Vec<f64>,
    /// Its true cost.
    pub cost: f64,
    /// Evaluations spent (0 or 1).
    pub evaluations: u64,
}

/// The global best a swarm should follow. Blocks remembered in different particles were scored
/// next to different partners, so for a coupled cost (two vehicles' separation) the assembled
/// best can hide a conflict no single memory saw. It is evaluated once, and followed only if it
/// is truly at least as good as `elite` (the best position truly evaluated so far); otherwise the
/// elite is followed. With a single block the assembled best *is* the best personal best.
pub fn trusted_best<'a, P: Problem>(
    problem: &P,
    particles: impl Iterator<Item = &'a Particle> + Clone,
    elite: &[f64],
    elite_cost: f64,
) -> Option<TrustedBest> {
    let (x, parts) = assemble(problem, particles)?;
    if problem.blocks() == 1 {
        // One block: the best personal best, whose cost was a true evaluation.
        let cost = parts.iter().sum();
        return Some(TrustedBest {
            x,
            cost,
            evaluations: 0,
        });
    }
    if x == elite {
        // The elite's own cost, not the sum of the remembered blocks: those were scored next to
        // other partners and can hide a conflict the elite has (a pair closer than d_min).
        return Some(TrustedBest {
            x,
            cost: elite_cost,
            evaluations: 0,
        });
    }
    let cost = problem.cost(&x);
    if cost <= elite_cost || elite.is_empty() {
        Some(TrustedBest {
            x,
            cost,
            evaluations: 1,
        })
    } else {
        Some(TrustedBest {
            x: elite.to_vec(),
            cost: elite_cost,
            evaluations: 1,
        })
    }
}

/// PSO coefficients for one iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Inertia weight ω.
    pub w: f64,
    /// Cognitive factor c1 (pull to the personal best).
    pub c1: f64,
    /// Social factor c2 (pull to the population best).
    pub c2: f64,
    /// Exchange factor c3 (pull to the followers' best), leader only.
    pub c3: f64,
}

/// How the coefficients evolve over a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Schedule {
    /// Constant (classic PSO, MP-PSO: ω = 0.15, c1 = c2 = c3 = 1.5 in Table 5).
    Fixed(Coefficients),
    /// Zhi & Zuo 2024, eq. (7)–(8): ω = 2 − 2a/b, c1 = 2 − a/b, c2 = 1 + a/b, c3 = 2 − a/b.
    Adaptive,
}

impl Schedule {
    /// Table 5's fixed coefficients for the comparison algorithms.
    pub const TABLE5_FIXED: Schedule = Schedule::Fixed(Coefficients {
        w: 0.15,
        c1: 1.5,
        c2: 1.5,
        c3: 1.5,
    });

    /// Coefficients at `progress`.
    pub fn at(&self, progress: Progress) -> Coefficients {
        match *self {
            Schedule::Fixed(c) => c,
            Schedule::Adaptive => {
                let r = sweep(progress).fraction();
                Coefficients {
                    w: -2.0 * r + 2.0,
                    c1: -r + 2.0,
                    c2: r + 1.0,
                    c3: -r + 2.0,
                }
            }
        }
    }
}

/// Iterations one sweep of the adaptive schedule spans when the budget is longer: Table 5's 200
/// (Zhi & Zuo 2024). A budget of at most this many is swept once, as eq. (7)–(8) say, with b the
/// budget. A longer budget sweeps again every `ADAPTIVE_SPAN` iterations from where the swarm is,
/// every memory kept: ω back at 2 sends the particles out of the basin the greedy end of the
/// last sweep (ω near 0) settled in. Stretching one sweep over the whole budget instead made
/// more budget worse (scenario 3, seeds 1–5: median fitness 1.824 at 1000 iterations against
/// 1.774 at 200), because a slow sweep explores long and refines late; with repeated sweeps the
/// first 200 iterations of any longer run are exactly the default run's, so the best it returns
/// can only be as good or better.
pub const ADAPTIVE_SPAN: usize = 200;

/// Where in its sweep of the adaptive schedule `progress` is (see [`ADAPTIVE_SPAN`]).
pub fn sweep(progress: Progress) -> Progress {
    if progress.max_iterations <= ADAPTIVE_SPAN {
        progress
    } else {
        Progress {
            iteration: progress.iteration % ADAPTIVE_SPAN,
            max_iterations: ADAPTIVE_SPAN,
        }
    }
}

/// Box and velocity limits every move respects.
#[derive(Debug, Clone)]
pub struct Limits {
    /// Lower bounds.
    pub lower: Vec<f64>,
    /// Upper bounds.
    pub upper: Vec<f64>,
    /// Largest |velocity| per dimension.
    pub vmax: Vec<f64>,
    /// 1 / vmax, so the update loop multiplies instead of dividing.
    pub inv_vmax: Vec<f64>,
    /// Dimensions that share their random factors and velocity scaling
    /// ([`Problem::move_groups`]).
    pub groups: Vec<std::ops::Range<usize>>,
}

impl Limits {
    /// Limits of `problem`, with velocities capped at `fraction` of each dimension's range.
    pub fn of<P: Problem>(problem: &P, fraction: f64) -> Limits {
        let lower = problem.lower().to_vec();
        let upper = problem.upper().to_vec();
        let vmax: Vec<f64> = lower
            .iter()
            .zip(&upper)
            .map(|(l, u)| fraction * (u - l))
            .collect();
        let groups = problem.move_groups();
        Limits {
            inv_vmax: inverses(&vmax),
            lower,
            upper,
            vmax,
            groups,
        }
    }
}

fn inverses(v: &[f64]) -> Vec<f64> {
    v.iter()
        .map(|x| if *x > 0.0 { 1.0 / x } else { f64::INFINITY })
        .collect()
}

/// Moves `p` by eq. (5) — or eq. (6) when `exchange` gives the followers' best o_f_gbest — then
/// scales the velocity into its limits and clamps the position. A particle that hits a wall stops
/// in that dimension (absorbing boundary), so it does not keep pushing outwards.
///
/// `r1`, `r2`, `r3` are drawn per group of [`Limits::groups`]: per dimension in textbook PSO, once
/// per vehicle path for the fleet problem. A path's new velocity is then a linear combination of
/// whole paths (the old velocity, the personal and the global best), so smooth paths stay smooth
/// instead of picking up an independent kink at every waypoint; for the same reason a group's
/// velocity over its limit is scaled down as a whole (for a one-dimension group, a plain clamp).
pub fn update(
    p: &mut Particle,
    gbest: &[f64],
    exchange: Option<&[f64]>,
    c: Coefficients,
    limits: &Limits,
    rng: &mut StdRng,
) {
    for g in &limits.groups {
        let (r1, r2): (f64, f64) = (rng.random(), rng.random());
        let (a1, a2) = (c.c1 * r1, c.c2 * r2);
        let r = g.clone();
        let (x, v) = (&p.x[r.clone()], &mut p.v[r.clone()]);
        pull(v, x, (c.w, a1, a2), &p.best_x[r.clone()], &gbest[r.clone()]);
        if let Some(f) = exchange {
            let a3 = c.c3 * rng.random::<f64>();
            for ((v, x), fb) in v.iter_mut().zip(x).zip(&f[r.clone()]) {
                *v += a3 * (fb - x);
            }
        }
        let over = largest_ratio(v, &limits.inv_vmax[r.clone()]);
        let (lower, upper) = (&limits.lower[r.clone()], &limits.upper[r.clone()]);
        move_within(&mut p.x[r.clone()], &mut p.v[r], lower, upper, 1.0 / over);
    }
}

/// eq. (5)'s new velocity, `v ← ω v + a1 (best − x) + a2 (gbest − x)`, in place, two
/// dimensions per instruction (the compiler vectorises the loop).
#[inline]
fn pull(v: &mut [f64], x: &[f64], (w, a1, a2): (f64, f64, f64), best: &[f64], gbest: &[f64]) {
    for (((v, x), b), gb) in v.iter_mut().zip(x).zip(best).zip(gbest) {
        *v = w * *v + a1 * (b - x) + a2 * (gb - x);
    }
}

/// The largest `|v| · inv` over the pairs, and at least 1: how far a group's velocity is over
/// its limits. A NaN ratio is passed over, as `f64::max` passes it. Four running maxima in
/// turn rather than one, so the compiler vectorises the loop (a maximum is exact, so the order
/// does not change it); as one `f64::max` chain it was the update's costliest line.
#[inline]
fn largest_ratio(v: &[f64], inv: &[f64]) -> f64 {
    let n = v.len().min(inv.len());
    let (v, inv) = (&v[..n], &inv[..n]);
    let (v4, v_rest) = v.as_chunks::<4>();
    let (inv4, inv_rest) = inv.as_chunks::<4>();
    let mut m = [1.0f64; 4];
    for (v, inv) in v4.iter().zip(inv4) {
        for k in 0..4 {
            // `larger(ratio, m)` is `m` when the ratio is NaN, as `m.max(ratio)` is.
            m[k] = larger(v[k].abs() * inv[k], m[k]);
        }
    }
    let mut over = larger(larger(m[0], m[1]), larger(m[2], m[3]));
    for (v, inv) in v_rest.iter().zip(inv_rest) {
        over = larger(v.abs() * inv, over);
    }
    over
}

/// Scales the velocity `v` by `scale`, moves the position `x` by it and clamps it into
/// `[lower, upper]`; a dimension that hits a wall stops there (its velocity becomes zero).
/// Written without branches, two dimensions per instruction (the compiler vectorises the loop):
/// which particles hit a wall is random, so branches mispredict. The clamp is
/// `smaller(upper, larger(lower, to))`, one `maxpd` and one `minpd`, which gives what
/// `if to < lower { lower } else if to > upper { upper } else { to }` gives for every `to`, NaN
/// included (for `lower <= upper`, as every problem's bounds are).
#[inline]
fn move_within(x: &mut [f64], v: &mut [f64], lower: &[f64], upper: &[f64], scale: f64) {
    let n = x.len();
    // All four the same length, so the indexing below needs no checks and vectorises.
    let (v, lower, upper) = (&mut v[..n], &lower[..n], &upper[..n]);
    for k in 0..n {
        let moved = v[k] * scale;
        let to = x[k] + moved;
        let hits = (to < lower[k]) | (to > upper[k]);
        x[k] = smaller(upper[k], larger(lower[k], to));
        v[k] = if hits { 0.0 } else { moved };
    }
}

/// A population with its own RNG, so populations can step on different threads and still give
/// the same result for the same seed.
#[derive(Debug, Clone)]
pub struct Population {
    /// Its particles.
    pub particles: Vec<Particle>,
    /// o_gbest (see [`trusted_best`]).
    pub gbest: Vec<f64>,
    /// Best position this population has truly evaluated.
    pub elite_x: Vec<f64>,
    /// Its cost.
    pub elite_cost: f64,
    /// This population's random stream.
    pub rng: StdRng,
    /// Cost evaluations this population has made.
    pub evaluations: u64,
}

impl Population {
    /// `size` particles sampled from `problem`, with the RNG seeded from `seed`.
    pub fn sample<P: Problem>(problem: &P, size: usize, seed: u64) -> Population {
        let mut rng = StdRng::seed_from_u64(seed);
        let particles: Vec<Particle> = (0..size)
            .map(|_| {
                let x = problem.sample(&mut rng);
                Particle::new(problem, x)
            })
            .collect();
        Population::from_particles(problem, particles, rng)
    }

    /// A population of given particles.
    pub fn from_particles<P: Problem>(
        problem: &P,
        particles: Vec<Particle>,
        rng: StdRng,
    ) -> Population {
        let mut pop = Population {
            particles,
            gbest: Vec::new(),
            elite_x: Vec::new(),
            elite_cost: f64::INFINITY,
            rng,
            evaluations: 0,
        };
        pop.evaluations = pop.particles.len() as u64;
        pop.refresh(problem);
        pop
    }

    /// Recomputes o_gbest and the elite after particles moved or were replaced.
    pub fn refresh<P: Problem>(&mut self, problem: &P) -> u64 {
        for p in &self.particles {
            if p.cost < self.elite_cost {
                self.elite_cost = p.cost;
                self.elite_x.clone_from(&p.x);
            }
        }
        let Some(best) = trusted_best(
            problem,
            self.particles.iter(),
            &self.elite_x,
            self.elite_cost,
        ) else {
            return 0;
        };
        if best.cost < self.elite_cost {
            self.elite_cost = best.cost;
            self.elite_x.clone_from(&best.x);
        }
        self.gbest = best.x;
        self.evaluations += best.evaluations;
        best.evaluations
    }

    /// The particle an exchange sends to the leader: the population's best, positioned at its
    /// global best.
    pub fn emigrant<P: Problem>(&self, problem: &P) -> Option<Particle> {
        if problem.blocks() > 1 {
            return Some(Particle::new(problem, self.gbest.clone()));
        }
        self.particles
            .iter()
            .min_by(|a, b| a.best_cost.total_cmp(&b.best_cost))
            .cloned()
    }

    /// Index of the particle whose current cost is worst.
    pub fn worst(&self) -> usize {
        self.particles
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.cost.total_cmp(&b.1.cost))
            .map_or(0, |(i, _)| i)
    }

    /// One eq. (5) / (6) iteration of every particle, then evaluation. Returns evaluations made.
    pub fn step<P: Problem>(
        &mut self,
        problem: &P,
        c: Coefficients,
        exchange: Option<&[f64]>,
        limits: &Limits,
    ) -> u64 {
        for p in &mut self.particles {
            update(p, &self.gbest, exchange, c, limits, &mut self.rng);
            p.evaluate(problem);
        }
        self.evaluations += self.particles.len() as u64;
        self.particles.len() as u64 + self.refresh(problem)
    }
}

#[cfg(test)]
mod tests;
