//! Replanning the rest of one vehicle's mission while the fleet drives: from the
//! position it will have when the update reaches it, to its goal, for the fleet's arrival time,
//! with the other vehicles as moving obstacles (their trajectories as the coordinator predicts
//! them) and any new obstacle in the scenario.
//!
//! It is the follower problem of distributed AMP-PSO ([`VehicleProblem`], Zhi & Zuo 2024, eq. (9)–(12)
//! restricted to one vehicle) solved by A-PSO (Zhi & Zuo 2024, eq. (7) parameters) under a wall-time
//! budget, warm-started: the first particle is the current plan's remainder resampled onto the
//! M waypoints (pushed out of new obstacles), the second a coarse way round the hard obstacles
//! (`detour`) when there is one, a few more are jittered copies of these, the rest are
//! sampled as usual. The first particle alone is already the answer when the change does not
//! touch the vehicle's path.
//!
//! A vehicle under way cannot turn on the spot: the new path's first turn, from the course the
//! vehicle is on to the first leg, is held to the same limit as every other turn
//! ([`VehicleProblem::entering_along`]).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use rand::rngs::StdRng;
use rand::Rng;
use shoal_common::cost::FleetModel;
use shoal_common::coverage::reroute::CrawlerGround;
use shoal_common::geometry::{polyline_length, Vec3};
use shoal_common::refine::{refine_vehicle, RefineSettings};
use shoal_common::scenario::Scenario;
use shoal_common::swarm::pso::Pso;
use shoal_common::swarm::{Executor, Problem, SolverState};
use shoal_common::trajectory::Trajectory;
use shoal_common::vehicle_problem::{VehicleEvaluation, VehicleProblem};

/// Jittered copies of the warm particle in the first swarm.
const WARM_COPIES: usize = 8;
/// How far out [`push_out_of_obstacles`] moves a waypoint, in inflated radii.
const PUSH_OUT: f64 = 1.4;
/// The straight run along the vehicle's course a way round begins with, metres (a few
/// turning radii of the simulated AUV, 20 m).
const LEAD_IN_M: f64 = 60.0;
/// Particles of the replanning swarm.
const PARTICLES: usize = 30;

/// What to replan.
#[derive(Debug, Clone)]
pub struct Request<'a> {
    /// The scenario, with every obstacle known now.
    pub scenario: &'a Scenario,
    /// Which vehicle (scenario order).
    pub vehicle: usize,
    /// Mission time the new trajectory starts at.
    pub t0: f64,
    /// Where the vehicle will be then.
    pub p0: Vec3,
    /// The course it will be on then (`None`: stopped, e.g. holding).
    pub heading: Option<Vec3>,
    /// The trajectory it follows now (mission-timed).
    pub current: &'a Trajectory,
    /// The time on `current` from which its rest is still to be driven: where a holding
    /// vehicle stopped (its plan went on without it); `None`: `t0`.
    pub resume_s: Option<f64>,
    /// Every vehicle's predicted trajectory, mission-timed (this vehicle's is ignored).
    pub others: &'a [Trajectory],
    /// The fleet's arrival time, mission seconds.
    pub arrival_s: f64,
    /// Wall-time budget.
    pub budget: Duration,
    /// Metres over d_min the new trajectory is planned to keep from the others: the vehicles
    /// fly their trajectories only to within their tracking error (and their fixes carry
    /// noise), so a trajectory that grazes d_min is executed a few metres inside it.
    pub separation_buffer_m: f64,
    /// RNG seed.
    pub seed: u64,
    /// A coverage crawler's seabed, for its way round a new obstacle (`None`: there is none,
    /// and a blocked crawler holds).
    pub ground: Option<&'a CrawlerGround>,
    /// Raised: the swarm stops at its next iteration and the best so far is the answer, and the
    /// coarse way round (`detour`) gives up (a held vehicle's retry yields to a vehicle under
    /// way, `replan_queue`). A crawler's repair ignores it: its search on the seabed map takes
    /// tens of milliseconds, bounded by the budget.
    pub stop: Option<Arc<AtomicBool>>,
}

/// A replanned trajectory.
#[derive(Debug, Clone)]
pub struct Replanned {
    /// Mission-timed, from `(t0, p0)` to the goal (a coverage crawler's repair may end short of
    /// its finish: see `note`).
    pub trajectory: Trajectory,
    /// No hard-obstacle intrusion and every other vehicle kept at d_min or more.
    pub safe: bool,
    /// Hard-obstacle intrusions (leg × obstacle).
    pub hard_hits: usize,
    /// Smallest predicted distance to another vehicle, metres.
    pub min_separation_m: f64,
    /// Wall time spent.
    pub elapsed: Duration,
    /// Why no path was found at all (a repair with no way round), in plain words.
    pub no_way: Option<String>,
    /// What a safe repair gave up, in plain words (a crawler's finish inside a keep-out).
    pub note: Option<String>,
}

impl Replanned {
    /// No path at all, for `why` (in plain words), after the time since `started`; its
    /// trajectory `trajectory` (the one the vehicle follows, or none) is not to be flown.
    pub fn not_found(trajectory: Trajectory, started: Instant, why: String) -> Replanned {
        Replanned {
            trajectory,
            safe: false,
            hard_hits: 0,
            min_separation_m: f64::INFINITY,
            elapsed: started.elapsed(),
            no_way: Some(why),
            note: None,
        }
    }

    /// Why the result is not safe, in plain words, for the hold events.
    pub fn shortfall(&self) -> String {
        self.no_way.clone().unwrap_or_else(|| {
            format!(
                "{} obstacle intrusions, closest vehicle {:.1} m",
                self.hard_hits, self.min_separation_m
            )
        })
    }
}

/// `t` from mission time `t0` on, re-based so `t0` is time 0.
pub(super) fn rebase(t: &Trajectory, t0: f64) -> Trajectory {
    let rest = t.since(t0);
    Trajectory {
        times: rest.times.iter().map(|s| s - t0).collect(),
        points: rest.points,
    }
}

/// The remainder of `current` after `t0`, from `p0`, as a chromosome of `m` waypoints (evenly
/// spaced by arc length) and the speeds the remainder flies.
pub fn warm_chromosome(
    current: &Trajectory,
    t0: f64,
    p0: Vec3,
    m: usize,
    v: (f64, f64),
) -> Vec<f64> {
    let rest = rebase(current, t0);
    let mut pts = rest.points.clone();
    pts[0] = p0;
    let cum: Vec<f64> = std::iter::once(0.0)
        .chain(pts.windows(2).scan(0.0, |acc, w| {
            *acc += (w[1] - w[0]).norm();
            Some(*acc)
        }))
        .collect();
    let total = cum.last().copied().unwrap_or(0.0);
    let duration = rest.arrival().max(1e-9);
    let speed = (total / duration).clamp(v.0, v.1);
    let mut genes = Vec::with_capacity(4 * m);
    for k in 1..=m {
        let s = total * k as f64 / (m + 1) as f64;
        let j = cum
            .partition_point(|&c| c < s)
            .clamp(1, pts.len().max(2) - 1);
        let p = if pts.len() < 2 {
            p0
        } else {
            let (c0, c1) = (cum[j - 1], cum[j]);
            let f = if c1 > c0 { (s - c0) / (c1 - c0) } else { 0.0 };
            pts[j - 1] + (pts[j] - pts[j - 1]) * f
        };
        genes.extend_from_slice(&[p.x, p.y, p.z]);
    }
    genes.extend(std::iter::repeat_n(speed, m));
    genes
}

/// The polyline `points` flown from mission time `t0` at the one speed that takes `duration`.
fn at_even_speed(points: &[Vec3], t0: f64, duration: f64) -> Trajectory {
    let length = polyline_length(points);
    let speed = (length / duration.max(1e-9)).max(1e-9);
    let mut t = t0;
    let mut times = Vec::with_capacity(points.len());
    for (k, p) in points.iter().enumerate() {
        if k > 0 {
            t += (p - points[k - 1]).norm() / speed;
        }
        times.push(t);
    }
    Trajectory {
        times,
        points: points.to_vec(),
    }
}

/// Moves every waypoint of `genes` (M waypoints, coordinates first) closer than
/// `PUSH_OUT` × a hard obstacle's inflated radius to its centre sideways — perpendicular to
/// the path there, horizontally when the path runs through the centre — to that distance: the
/// warm start then already goes round a new obstacle, and the swarm only has to smooth it. At
/// 1.4 r, the chord between two pushed neighbours up to 88° apart round the centre stays
/// outside r (1.4 cos 44° = 1.007).
pub fn push_out_of_obstacles(genes: &mut [f64], scenario: &Scenario, m: usize) {
    let m = m.min(genes.len() / 3);
    let at = |g: &[f64], k: usize| Vec3::new(g[3 * k], g[3 * k + 1], g[3 * k + 2]);
    for k in 0..m {
        let mut p = at(genes, k);
        let prev = if k > 0 { at(genes, k - 1) } else { p };
        let next = if k + 1 < m { at(genes, k + 1) } else { p };
        let tangent = (next - prev)
            .try_normalize(1e-9)
            .unwrap_or_else(|| Vec3::new(1.0, 0.0, 0.0));
        for o in scenario.hard_obstacles() {
            let c = o.centre();
            let r = o.inflated_radius();
            let d = p - c;
            if d.norm() >= PUSH_OUT * r {
                continue;
            }
            let along = d.dot(&tangent);
            let side = (d - tangent * along)
                .try_normalize(1e-6)
                .or_else(|| tangent.cross(&Vec3::new(0.0, 0.0, 1.0)).try_normalize(1e-9))
                .unwrap_or_else(|| Vec3::new(0.0, 1.0, 0.0));
            p = c + tangent * along + side * (PUSH_OUT * r);
        }
        genes[3 * k..3 * k + 3].copy_from_slice(&[p.x, p.y, p.z]);
    }
}

/// A problem whose first samples are warm starts (inside the bounds), then jittered copies of
/// them.
struct WarmStart<'a> {
    inner: &'a VehicleProblem<'a>,
    warm: Vec<Vec<f64>>,
    drawn: AtomicUsize,
}

impl Problem for WarmStart<'_> {
    fn lower(&self) -> &[f64] {
        self.inner.lower()
    }
    fn upper(&self) -> &[f64] {
        self.inner.upper()
    }
    fn cost(&self, x: &[f64]) -> f64 {
        self.inner.cost(x)
    }
    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        self.inner.move_groups()
    }
    fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        let k = self.drawn.fetch_add(1, Ordering::Relaxed);
        let (lo, hi) = (self.lower(), self.upper());
        let clamp = |x: Vec<f64>| -> Vec<f64> {
            x.into_iter()
                .enumerate()
                .map(|(d, v)| v.clamp(lo[d], hi[d]))
                .collect()
        };
        let n = self.warm.len();
        match k {
            k if k < n => self.warm[k].clone(),
            k if k < n + WARM_COPIES => clamp(
                self.warm[k % n]
                    .iter()
                    .enumerate()
                    .map(|(d, v)| v + 0.03 * (hi[d] - lo[d]) * rng.random_range(-1.0..=1.0))
                    .collect(),
            ),
            _ => self.inner.sample(rng),
        }
    }
}

/// No hard-obstacle intrusion and every other vehicle kept at `d_min` or more.
fn is_safe(e: &VehicleEvaluation, d_min: f64) -> bool {
    e.terms.hard_hits == 0 && e.min_separation >= d_min
}

/// How much more turn and pitch penalty than the cleanest safe candidate a safe candidate may
/// carry and still be chosen for its lower cost: 2 is about one clear violation (each costs
/// `1 + excess / limit`).
const MOTION_SLACK: f64 = 2.0;

/// The answer among the swarm's best and the warm starts. The swarm's best is the cheapest
/// (the warm starts were in its swarm), but the penalties are finite, so in a short budget it
/// can trade a grazed obstacle or a string of reversals for a shorter, on-time path where a
/// warm start — the long way round, arriving late — is safe and flyable. So: a safe candidate
/// beats an unsafe one; among safe ones, one that breaks the turn and pitch limits by more
/// than [`MOTION_SLACK`] over the cleanest gives way; then the cheapest wins.
///
/// "Safe" is tried at each separation of `separations` in turn (d_min plus the tracking
/// buffer, then d_min itself): a candidate that keeps the buffer beats one that only keeps
/// d_min, and one that keeps d_min still beats an unsafe one.
fn choose(all: &[VehicleEvaluation], separations: &[f64]) -> usize {
    for &d in separations {
        let safe: Vec<usize> = (0..all.len()).filter(|k| is_safe(&all[*k], d)).collect();
        let cleanest = safe
            .iter()
            .map(|k| all[*k].terms.motion)
            .fold(f64::INFINITY, f64::min);
        if let Some(best) = safe
            .into_iter()
            .filter(|k| all[*k].terms.motion <= cleanest + MOTION_SLACK)
            .min_by(|a, b| all[*a].total.total_cmp(&all[*b].total))
        {
            return best;
        }
    }
    0
}

/// The chosen answer `genes` (scored `chosen`) pulled tight by the refinement
/// ([`refine_vehicle`]) until the request's budget ends, when the scenario asks for it; kept
/// only when it is at least as safe at every separation of `separations`.
fn tighten(
    problem: &VehicleProblem,
    genes: &[f64],
    chosen: VehicleEvaluation,
    r: &Request,
    started: Instant,
    separations: &[f64],
) -> VehicleEvaluation {
    if !r.scenario.optimizer.refine {
        return chosen;
    }
    let settings = RefineSettings {
        deadline: Some(started + r.budget),
        ..RefineSettings::default()
    };
    let arrival = problem.arrival();
    let refined = refine_vehicle(problem, genes, arrival, &settings, r.stop.as_ref());
    if refined.steps == 0 {
        return chosen;
    }
    let e = problem.evaluate(&refined.genes);
    let as_safe = separations
        .iter()
        .all(|d| is_safe(&e, *d) || !is_safe(&chosen, *d));
    if as_safe {
        e
    } else {
        chosen
    }
}

/// The share of a replan's budget the refinement keeps for itself when the scenario asks for
/// it: one refinement program of a 30-waypoint path takes about two milliseconds, so a tenth of
/// the 300 ms default is a dozen or more of them (the search keeps what it has when the time is
/// up), while the swarm keeps nearly all the time to find the way round.
const REFINE_SHARE: f64 = 0.1;

/// What of the request's budget the swarm may spend.
fn swarm_budget(r: &Request) -> Duration {
    if r.scenario.optimizer.refine {
        r.budget.mul_f64(1.0 - REFINE_SHARE)
    } else {
        r.budget
    }
}

/// Replans (see the module doc).
pub fn replan(r: &Request) -> Replanned {
    let started = Instant::now();
    let d_min = r.scenario.fleet.d_min_m;
    let mut scenario = r.scenario.clone();
    scenario.vehicles[r.vehicle].start = [r.p0.x, r.p0.y, r.p0.z];
    // The swarm's separation penalty (Zhi & Zuo 2024, eq. (11)) starts at d_min plus the buffer.
    scenario.fleet.d_min_m = d_min + r.separation_buffer_m.max(0.0);
    let model = FleetModel::new(&scenario);
    let context: Vec<Trajectory> = r.others.iter().map(|t| rebase(t, r.t0)).collect();
    let arrival = (r.arrival_s - r.t0).max(1.0);
    let mut problem =
        VehicleProblem::new(&model, r.vehicle, &context, arrival).early_arrival_allowed();
    if let Some(h) = r.heading {
        problem = problem.entering_along(h);
    }
    let v = &scenario.vehicles[r.vehicle];
    let m = scenario.optimizer.waypoints;
    let speeds = (v.speed_min_mps, v.speed_max_mps);
    let mut plan = warm_chromosome(r.current, r.t0, r.p0, m, speeds);
    push_out_of_obstacles(&mut plan, &scenario, m);
    let mut warm = vec![plan];
    // The way round starts with a straight run along the vehicle's course, so its first turn
    // comes after the vehicle has had room for it.
    let lead = r
        .heading
        .and_then(|h| Vec3::new(h.x, h.y, 0.0).try_normalize(1e-9))
        .map(|h| r.p0 + h * LEAD_IN_M)
        .filter(|q| {
            scenario
                .hard_obstacles()
                .all(|o| (q - o.centre()).norm() > o.inflated_radius())
        });
    let from = lead.unwrap_or(r.p0);
    if let Some(mut way) = super::detour::detour(
        &scenario,
        from,
        v.goal(),
        v.max_pitch_deg,
        super::detour::keep_off(&scenario, r.vehicle),
        r.stop.as_deref(),
    ) {
        if lead.is_some() {
            way.insert(0, r.p0);
        }
        if way.len() > 2 {
            // Timed for the arrival; `warm_chromosome` resamples it like a plan.
            let way = at_even_speed(&way, r.t0, arrival);
            warm.push(warm_chromosome(&way, r.t0, r.p0, m, speeds));
        }
    }
    // In the box, as every particle must be.
    let (lo, hi) = (problem.lower(), problem.upper());
    for w in &mut warm {
        for (d, v) in w.iter_mut().enumerate() {
            *v = v.clamp(lo[d], hi[d]);
        }
    }
    let warm_problem = WarmStart {
        inner: &problem,
        warm,
        drawn: AtomicUsize::new(0),
    };
    let executor = Executor {
        max_iterations: 10_000,
        // The warm starts (the A* way round) came out of the same budget, and the refinement
        // has the last part of it.
        time_limit: Some(swarm_budget(r).saturating_sub(started.elapsed())),
        stop: r.stop.clone(),
        ..Executor::default()
    };
    let mut solver = Pso::adaptive(PARTICLES, r.seed);
    let out = executor.run(&warm_problem, &mut solver, |_| {});
    let genes: Vec<&[f64]> = std::iter::once(out.state.best_position())
        .chain(warm_problem.warm.iter().map(|w| w.as_slice()))
        .collect();
    let all: Vec<VehicleEvaluation> = genes.iter().map(|g| problem.evaluate(g)).collect();
    let separations = [scenario.fleet.d_min_m, d_min];
    let k = choose(&all, &separations);
    let best = tighten(&problem, genes[k], all[k].clone(), r, started, &separations);
    let safe = is_safe(&best, d_min);
    let trajectory = Trajectory {
        times: best.trajectory.times.iter().map(|t| t + r.t0).collect(),
        points: best.trajectory.points,
    };
    Replanned {
        trajectory,
        safe,
        hard_hits: best.terms.hard_hits,
        min_separation_m: best.min_separation,
        elapsed: started.elapsed(),
        no_way: None,
        note: None,
    }
}

#[cfg(test)]
mod tests;
