//! A last pass over a fleet plan the swarm left with a violation: each vehicle that takes part in
//! one is re-planned on its own, against the others' timed trajectories as the plan has them
//! ([`VehicleProblem`], the problem a vehicle agent solves in distributed AMP-PSO), starting
//! from its own chromosome, and its new chromosome is kept only if the whole fleet's fitness
//! (Zhi & Zuo 2024, eq. (12) plus the penalties) gets lower.
//!
//! Not part of any seed's algorithm: the paper's swarm ends where it ends. It exists because a
//! plan the swarm left a few metres inside an obstacle's margin, or half a degree over a pitch
//! limit, cannot be flown, and the vehicle-by-vehicle search that the distributed planner runs
//! anyway usually clears it in a few thousand evaluations of one vehicle. `compare` and the
//! benchmarks measure the algorithms without it; `plan` runs it unless told not to, and the plan
//! says what it changed.
//!
//! Each vehicle in violation gets two tries, cheapest first:
//! 1. *local*: one population started on its own chromosome (and eased and bent copies of it)
//!    with Table 5's fixed coefficients — what clears a path a few metres or degrees over;
//! 2. *fresh*, only when the local try leaves it in violation: the vehicle's own AMP-PSO from a
//!    new random start (a few follower populations and a leader, as a vehicle agent runs in
//!    distributed AMP-PSO). The fleet swarm sometimes leaves one vehicle on a long detour whose
//!    sharp corner no small change can ease (scenario 3, seeds 6 and 10: auv3 turning 39° and
//!    45° on a path 20–30 % longer than its pitch limit needs); a fresh search finds the
//!    shorter way round in a few tens of thousands of evaluations of one vehicle.
//!
//! Each try's result is kept when it lowers the fleet's fitness (the fresh one is weighed
//! against the plan as the local one left it).
//!
//! A raised stop flag (Ctrl-C, SIGTERM) ends every swarm at its next iteration and the pass
//! before its next vehicle: what was kept so far is returned, marked as interrupted. A
//! 500-vehicle fleet otherwise kept the touch-up going for minutes after the user asked it to
//! stop.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

use crate::cost::FleetModel;
use crate::geometry::Vec3;
use crate::swarm::multi::MultiPso;
use crate::swarm::population::{stream_seed, Particle, Population, Schedule};
use crate::swarm::pso::PsoState;
use crate::swarm::{Executor, Problem, Progress, Solver, SolverState};
use crate::vehicle_problem::VehicleProblem;

/// How hard the touch-up tries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TouchUpSettings {
    /// Passes over the vehicles (each pass re-plans every vehicle still in a violation).
    pub rounds: usize,
    /// Particles of each vehicle's swarm.
    pub particles: usize,
    /// Iterations of each vehicle's swarm.
    pub iterations: usize,
    /// Follower populations of the fresh try (0: no fresh try).
    pub fresh_populations: usize,
    /// Iterations of the fresh try.
    pub fresh_iterations: usize,
    /// Velocity cap, a fraction of each gene's range.
    pub max_velocity_fraction: f64,
    /// The run's seed (each vehicle and round draws its own stream from it).
    pub seed: u64,
}

impl TouchUpSettings {
    /// Two passes; per vehicle a local try of 50 particles × 100 iterations with Table 5's fixed
    /// coefficients (ω = 0.15, c1 = c2 = 1.5: a swarm that stays near its best, which starts as
    /// the plan's own chromosome) and, when that is not enough, a fresh AMP-PSO of 4 follower
    /// populations of 50 × 150 iterations (about 35 000 evaluations of one vehicle, a tenth of a
    /// second on scenario 3); the run's velocity cap.
    pub fn new(seed: u64, max_velocity_fraction: f64) -> TouchUpSettings {
        TouchUpSettings {
            rounds: 2,
            particles: 50,
            iterations: 100,
            fresh_populations: 4,
            fresh_iterations: 150,
            max_velocity_fraction,
            seed,
        }
    }
}

/// What a touch-up did.
#[derive(Debug, Clone, PartialEq)]
pub struct TouchUp {
    /// The fleet position after it (the input when nothing was kept).
    pub x: Vec<f64>,
    /// Vehicles (scenario order) whose new chromosome was kept, in the order they were kept.
    pub changed: Vec<usize>,
    /// Of those, the vehicles whose kept chromosome came from a fresh search.
    pub fresh: Vec<usize>,
    /// Penalty sum P of the plan before and after.
    pub penalty: (f64, f64),
    /// Fitness (objective + W · P) before and after.
    pub total: (f64, f64),
    /// Cost evaluations spent (of one vehicle or of the fleet).
    pub evaluations: u64,
    /// The stop flag was raised before every vehicle in violation had its tries.
    pub interrupted: bool,
}

/// Touches up fleet position `x`; `None` when its plan has no violation to clear. A raised
/// `stop` ends it early with what it kept so far.
pub fn touch_up(
    model: &FleetModel,
    x: &[f64],
    settings: TouchUpSettings,
    stop: Option<&Arc<AtomicBool>>,
) -> Option<TouchUp> {
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let executor = |iterations| Executor {
        max_iterations: iterations,
        stop: stop.cloned(),
        ..Executor::default()
    };
    let mut eval = model.evaluate(x);
    if eval.penalty <= 0.0 {
        return None;
    }
    let before = (eval.penalty, eval.total);
    let mut x = x.to_vec();
    let mut changed = Vec::new();
    let mut from_fresh = Vec::new();
    let mut evaluations = 1;
    let mut interrupted = false;
    'rounds: for round in 0..settings.rounds {
        for v in 0..model.layout.vehicles {
            if eval.penalty <= 0.0 {
                break 'rounds;
            }
            if stopped() {
                interrupted = true;
                break 'rounds;
            }
            let range = model.layout.chromosome(v);
            let others = eval.trajectories.to_vec();
            let problem = VehicleProblem::new(model, v, &others, eval.common_arrival);
            if !in_violation(&problem, &x[range.clone()]) {
                continue;
            }
            let vehicle = &model.scenario.vehicles[v];
            let mut solver = Started {
                start: x[range.clone()].to_vec(),
                ends: (vehicle.start(), vehicle.goal()),
                particles: settings.particles,
                max_velocity_fraction: settings.max_velocity_fraction,
                seed: stream_seed(settings.seed, 7_000_001 + (round * 1000 + v) as u64),
            };
            let out = executor(settings.iterations).run(&problem, &mut solver, |_| {});
            evaluations += out.state.evaluations();
            let local = out.state.best_position().to_vec();
            let fresh =
                (settings.fresh_populations > 0 && in_violation(&problem, &local)).then(|| {
                    let mut solver = MultiPso {
                        populations: settings.fresh_populations,
                        max_velocity_fraction: settings.max_velocity_fraction,
                        ..MultiPso::amp(stream_seed(
                            settings.seed,
                            8_000_001 + (round * 1000 + v) as u64,
                        ))
                    };
                    let f = executor(settings.fresh_iterations).run(&problem, &mut solver, |_| {});
                    evaluations += f.state.evaluations();
                    f.state.best_position().to_vec()
                });
            for (k, genes) in std::iter::once(local).chain(fresh).enumerate() {
                let mut candidate = x.clone();
                candidate[range.clone()].copy_from_slice(&genes);
                let e = model.evaluate(&candidate);
                evaluations += 1;
                if e.total < eval.total {
                    x = candidate;
                    eval = e;
                    if changed.last() != Some(&v) {
                        changed.push(v);
                    }
                    if k == 1 && !from_fresh.contains(&v) {
                        from_fresh.push(v);
                    }
                }
            }
        }
    }
    Some(TouchUp {
        x,
        changed,
        fresh: from_fresh,
        penalty: (before.0, eval.penalty),
        total: (before.1, eval.total),
        evaluations,
        interrupted: interrupted || stopped(),
    })
}

/// True when the vehicle has a penalty (hard obstacle, turn, pitch, separation) in the context.
fn in_violation(problem: &VehicleProblem<'_>, genes: &[f64]) -> bool {
    let t = problem.evaluate(genes).terms;
    t.hard + t.motion + t.separation > 0.0
}

/// `genes` (M waypoints as x, y, z, then M speeds) with each waypoint moved `strength` of the
/// way to the midpoint of its neighbours, `passes` times; the path's start and goal (`ends`)
/// stay. A corner's turn and a leg's pitch shrink; the speeds are kept.
pub fn smoothed(genes: &[f64], ends: (Vec3, Vec3), strength: f64, passes: usize) -> Vec<f64> {
    let m = genes.len() / crate::trajectory::GENES_PER_WAYPOINT;
    let mut points: Vec<Vec3> = std::iter::once(ends.0)
        .chain(
            genes[..3 * m]
                .chunks_exact(3)
                .map(|g| Vec3::new(g[0], g[1], g[2])),
        )
        .chain(std::iter::once(ends.1))
        .collect();
    for _ in 0..passes {
        let before = points.clone();
        for k in 1..points.len() - 1 {
            let mid = (before[k - 1] + before[k + 1]) / 2.0;
            points[k] = before[k] + (mid - before[k]) * strength;
        }
    }
    let mut out: Vec<f64> = points[1..points.len() - 1]
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .collect();
    out.extend_from_slice(&genes[3 * m..]);
    out
}

/// Largest share of a deformation added to the start to seed the other particles.
const MAX_BEND: f64 = 0.3;

/// One population with Table 5's fixed coefficients whose first particle is `start` and whose
/// others are `start` bent a little.
struct Started {
    start: Vec<f64>,
    /// The vehicle's start and goal, which the chromosome leaves out.
    ends: (Vec3, Vec3),
    particles: usize,
    max_velocity_fraction: f64,
    seed: u64,
}

impl<P: Problem> Solver<P> for Started {
    type State = PsoState;

    fn name(&self) -> &'static str {
        "touch-up"
    }

    fn init(&mut self, problem: &P) -> PsoState {
        let mut rng = StdRng::seed_from_u64(self.seed);
        let mut particles = vec![Particle::new(problem, self.start.clone())];
        let (lower, upper) = (problem.lower(), problem.upper());
        while particles.len() < self.particles.max(1) {
            let x = if particles.len() % 2 == 1 {
                // The start with its corners eased: what takes a turn or a pitch back under
                // its limit.
                let strength = rng.random_range(0.05..0.5);
                let passes = rng.random_range(1..=3);
                smoothed(&self.start, self.ends, strength, passes)
            } else {
                // The start bent a little: the difference of two samples is a smooth
                // deformation (each is a straight line bent by a few harmonics), so a small
                // share of it moves the path off an obstacle or another vehicle without kinks.
                let (a, b) = (problem.sample(&mut rng), problem.sample(&mut rng));
                let share: f64 = rng.random_range(0.0..MAX_BEND);
                (0..self.start.len())
                    .map(|d| self.start[d] + share * (a[d] - b[d]))
                    .collect()
            };
            let x = x
                .iter()
                .enumerate()
                .map(|(d, g)| g.clamp(lower[d], upper[d]))
                .collect();
            particles.push(Particle::new(problem, x));
        }
        let population = Population::from_particles(problem, particles, rng);
        PsoState::of(problem, population, self.max_velocity_fraction)
    }

    fn step(&mut self, problem: &P, mut state: PsoState, progress: Progress) -> PsoState {
        let c = Schedule::TABLE5_FIXED.at(progress);
        state.evaluations += state.population.step(problem, c, None, &state.limits);
        state
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;
    use approx::assert_abs_diff_eq;

    #[test]
    fn smoothing_moves_a_corner_towards_its_neighbours_midpoint_and_keeps_the_speeds() {
        // One waypoint at (10, 10, 0) between (0, 0, 0) and (20, 0, 0), speed gene 1.2: the
        // neighbours' midpoint is (10, 0, 0); half the way there is (10, 5, 0).
        let ends = (Vec3::zeros(), Vec3::new(20.0, 0.0, 0.0));
        let once = smoothed(&[10.0, 10.0, 0.0, 1.2], ends, 0.5, 1);
        assert_eq!(once.len(), 4);
        assert_abs_diff_eq!(once[1], 5.0);
        assert_abs_diff_eq!(once[0], 10.0);
        assert_abs_diff_eq!(once[3], 1.2);
        // Two passes: 10 → 5 → 2.5.
        assert_abs_diff_eq!(smoothed(&[10.0, 10.0, 0.0, 1.2], ends, 0.5, 2)[1], 2.5);
        // Two waypoints, one pass of strength 1 from the old positions (Jacobi, not in place):
        // (5, 10, 0) → mid of (0, 0, 0) and (15, 10, 0) = (7.5, 5, 0);
        // (15, 10, 0) → mid of (5, 10, 0) and (20, 0, 0) = (12.5, 5, 0).
        let two = smoothed(&[5.0, 10.0, 0.0, 15.0, 10.0, 0.0, 1.0, 1.0], ends, 1.0, 1);
        for (got, want) in two.iter().zip([7.5, 5.0, 0.0, 12.5, 5.0, 0.0, 1.0, 1.0]) {
            assert_abs_diff_eq!(*got, want);
        }
        // A straight line stays where it is.
        let line = smoothed(&[10.0, 0.0, 0.0, 1.0], ends, 0.4, 3);
        assert_abs_diff_eq!(line[1], 0.0);
    }

    /// Two AUVs on straight lines that meet head-on at the centre of the box at t = 400 s.
    fn crossing() -> FleetModel {
        let s = fixtures::scenario(
            800.0,
            "",
            &[
                fixtures::vehicle_toml("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0]),
                fixtures::vehicle_toml("b", [500.0, 100.0, 250.0], [500.0, 900.0, 250.0]),
            ],
        )
        .unwrap_or_else(|e| panic!("{e}"));
        FleetModel::new(&s)
    }

    #[test]
    fn a_plan_with_a_violation_is_cleared_vehicle_by_vehicle_and_a_clean_one_is_left_alone() {
        let model = crossing();
        let x = fixtures::straight_particle(&model);
        let before = model.evaluate(&x);
        assert!(before.penalty > 0.0, "the straight lines collide");
        let settings = TouchUpSettings::new(3, 0.1);
        let t = touch_up(&model, &x, settings, None).unwrap_or_else(|| panic!("nothing to clear?"));
        assert!(!t.interrupted);
        assert_eq!(t.penalty.0, before.penalty);
        assert_eq!(t.total.0, before.total);
        assert_eq!(t.penalty.1, 0.0, "the crossing is cleared: {t:?}");
        assert!(t.total.1 < t.total.0);
        assert!(!t.changed.is_empty());
        // What it reports is what its position gives.
        let after = model.evaluate(&t.x);
        assert_eq!(after.total, t.total.1);
        let sep = crate::separation::pair_separation(
            &after.trajectories.trajectory(0),
            &after.trajectories.trajectory(1),
            50.0,
        );
        assert!(sep.min_distance >= 50.0, "{}", sep.min_distance);
        // Only the vehicles it kept a change for moved.
        for v in 0..2 {
            let r = model.layout.chromosome(v);
            assert_eq!(
                t.x[r.clone()] != x[r],
                t.changed.contains(&v),
                "vehicle {v}"
            );
        }
        // The same seed, the same touch-up.
        assert_eq!(touch_up(&model, &x, settings, None), Some(t.clone()));
        // A plan with nothing to clear is left alone.
        assert_eq!(touch_up(&model, &t.x, settings, None), None);
    }

    #[test]
    fn a_fresh_search_clears_what_the_local_try_cannot_and_says_so() {
        // A local try of one particle that never moves cannot change anything; without a
        // fresh try the crossing stays, with one it is cleared and marked as fresh.
        let model = crossing();
        let x = fixtures::straight_particle(&model);
        let stuck = TouchUpSettings {
            particles: 1,
            iterations: 1,
            fresh_populations: 0,
            ..TouchUpSettings::new(5, 0.1)
        };
        let t = touch_up(&model, &x, stuck, None).unwrap_or_else(|| panic!("nothing to clear?"));
        assert!(t.changed.is_empty() && t.fresh.is_empty(), "{t:?}");
        assert_eq!(t.penalty.1, t.penalty.0);
        assert_eq!(t.x, x);
        let fresh = TouchUpSettings {
            fresh_populations: 3,
            fresh_iterations: 60,
            ..stuck
        };
        let t = touch_up(&model, &x, fresh, None).unwrap_or_else(|| panic!("nothing to clear?"));
        assert_eq!(
            t.penalty.1, 0.0,
            "the fresh search clears the crossing: {t:?}"
        );
        assert!(!t.fresh.is_empty());
        assert!(t.fresh.iter().all(|v| t.changed.contains(v)));
        assert_eq!(model.evaluate(&t.x).total, t.total.1);
    }

    #[test]
    fn a_raised_stop_flag_ends_the_touch_up_at_once_and_keeps_the_plan_it_had() {
        // With the flag up before it starts, no vehicle gets a try: the plan comes back as it
        // went in, marked as interrupted, after the one evaluation that found the violation.
        let model = crossing();
        let x = fixtures::straight_particle(&model);
        let stop = Arc::new(AtomicBool::new(true));
        let started = std::time::Instant::now();
        let t = touch_up(&model, &x, TouchUpSettings::new(3, 0.1), Some(&stop))
            .unwrap_or_else(|| panic!("nothing to clear?"));
        assert!(started.elapsed() < std::time::Duration::from_secs(1));
        assert!(t.interrupted);
        assert!(t.changed.is_empty(), "{t:?}");
        assert_eq!(t.x, x);
        assert_eq!(t.evaluations, 1);
        assert_eq!(t.penalty.0, t.penalty.1);
    }
}
