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
use shoal_common::geometry::Vec3;
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
    let length: f64 = points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
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
fn choose(
    swarm: VehicleEvaluation,
    warm: impl Iterator<Item = VehicleEvaluation>,
    separations: &[f64],
) -> VehicleEvaluation {
    let all: Vec<VehicleEvaluation> = std::iter::once(swarm.clone()).chain(warm).collect();
    for &d in separations {
        let safe: Vec<&VehicleEvaluation> = all.iter().filter(|e| is_safe(e, d)).collect();
        let cleanest = safe
            .iter()
            .map(|e| e.terms.motion)
            .fold(f64::INFINITY, f64::min);
        if let Some(best) = safe
            .into_iter()
            .filter(|e| e.terms.motion <= cleanest + MOTION_SLACK)
            .min_by(|a, b| a.total.total_cmp(&b.total))
        {
            return best.clone();
        }
    }
    swarm
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
        // The warm starts (the A* way round) came out of the same budget.
        time_limit: Some(r.budget.saturating_sub(started.elapsed())),
        stop: r.stop.clone(),
        ..Executor::default()
    };
    let mut solver = Pso::adaptive(PARTICLES, r.seed);
    let out = executor.run(&warm_problem, &mut solver, |_| {});
    let best = choose(
        problem.evaluate(out.state.best_position()),
        warm_problem.warm.iter().map(|w| problem.evaluate(w)),
        &[scenario.fleet.d_min_m, d_min],
    );
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
mod tests {
    use super::*;

    fn line(t0: f64, t1: f64) -> Trajectory {
        Trajectory {
            times: vec![t0, t1],
            points: vec![Vec3::new(0.0, 0.0, 100.0), Vec3::new(1000.0, 0.0, 100.0)],
        }
    }

    #[test]
    fn the_warm_start_is_the_rest_of_the_plan_evenly_spaced() {
        // 1000 m in 1000 s; from t0 = 200 the rest is 800 m in 800 s from x = 200.
        let g = warm_chromosome(
            &line(0.0, 1000.0),
            200.0,
            Vec3::new(200.0, 0.0, 100.0),
            3,
            (0.5, 2.0),
        );
        assert_eq!(g.len(), 12);
        for (k, x) in [400.0, 600.0, 800.0].iter().enumerate() {
            assert!((g[3 * k] - x).abs() < 1e-9, "{g:?}");
            assert!(g[3 * k + 1].abs() < 1e-9);
        }
        // 1 m/s, inside the range.
        assert!(g[9..].iter().all(|v| (v - 1.0).abs() < 1e-9), "{g:?}");
    }

    #[test]
    fn a_raised_stop_flag_ends_the_swarm_long_before_its_budget(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
        let s = Scenario::load(std::path::Path::new(file))?;
        let plans: Vec<Trajectory> = s
            .vehicles
            .iter()
            .map(|v| Trajectory {
                times: vec![0.0, 2100.0],
                points: vec![v.start(), v.goal()],
            })
            .collect();
        let stop = Arc::new(AtomicBool::new(true));
        let r = Request {
            scenario: &s,
            vehicle: 0,
            t0: 100.0,
            p0: plans[0].position_at(100.0),
            heading: None,
            current: &plans[0],
            resume_s: None,
            others: &plans,
            arrival_s: 2100.0,
            budget: Duration::from_secs(5),
            separation_buffer_m: 10.0,
            seed: 1,
            ground: None,
            stop: Some(Arc::clone(&stop)),
        };
        let out = replan(&r);
        // It still answers: the warm start, the rest of the straight plan.
        assert_eq!(out.trajectory.points.len(), s.optimizer.waypoints + 2);
        // Not raised, the swarm runs to its budget or its iteration cap: 818 ms against 3.9 ms
        // stopped (266 ms when the flag stopped only the swarm: the coarse way round's search,
        // 263 ms of that, stops for it too).
        stop.store(false, Ordering::Relaxed);
        let full = replan(&r);
        assert!(
            out.elapsed * 20 < full.elapsed,
            "stopped {:?}, not stopped {:?}",
            out.elapsed,
            full.elapsed
        );
        Ok(())
    }

    #[test]
    fn a_waypoint_inside_an_obstacle_is_pushed_sideways() -> Result<(), Box<dyn std::error::Error>>
    {
        let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
        let mut s = Scenario::load(std::path::Path::new(file))?;
        s.obstacles = vec![shoal_common::scenario::Obstacle {
            id: "new".into(),
            kind: shoal_common::scenario::ObstacleKind::Hard,
            centre: [500.0, 0.0, 100.0],
            radius_m: 40.0,
            inflation_m: 50.0,
        }];
        let mut g = vec![
            250.0, 0.0, 100.0, 500.0, 0.0, 100.0, 750.0, 0.0, 100.0, 1.0, 1.0, 1.0,
        ];
        push_out_of_obstacles(&mut g, &s, 3);
        // The middle one is on the path through the centre: pushed horizontally across it, to
        // 1.4 × 90 m from the centre; the others are outside 1.4 r and stay.
        let p = Vec3::new(g[3], g[4], g[5]);
        assert!(
            ((p - Vec3::new(500.0, 0.0, 100.0)).norm() - 126.0).abs() < 1e-9,
            "{p}"
        );
        assert!(
            (p.x - 500.0).abs() < 1e-9 && (p.z - 100.0).abs() < 1e-9,
            "{p}"
        );
        assert_eq!(&g[0..3], &[250.0, 0.0, 100.0]);
        assert_eq!(&g[6..9], &[750.0, 0.0, 100.0]);
        Ok(())
    }

    fn candidate(hits: usize, separation: f64, motion: f64, total: f64) -> VehicleEvaluation {
        VehicleEvaluation {
            trajectory: line(0.0, 1.0),
            terms: shoal_common::cost::VehicleTerms {
                hard_hits: hits,
                motion,
                ..Default::default()
            },
            min_separation: separation,
            total,
        }
    }

    #[test]
    fn the_answer_is_safe_then_flyable_then_cheapest() {
        // (swarm's best, the one warm start, which wins), each as (hits, separation, motion
        // penalty, cost); d_min 50 m.
        let cases = [
            // The swarm's best is safe and clean: it is the answer.
            ((0, 80.0, 0.0, 1.0), (0, 80.0, 0.0, 3.0), 1.0),
            // It grazes an obstacle, or comes within d_min: the safe warm start wins.
            ((1, 80.0, 0.0, 1.0), (0, 80.0, 0.0, 3.0), 3.0),
            ((0, 49.0, 0.0, 1.0), (0, 80.0, 0.0, 3.0), 3.0),
            // Safe with one slight turn violation (1.1): within the slack of the clean one.
            ((0, 80.0, 1.1, 1.0), (0, 80.0, 0.0, 3.0), 1.0),
            // Safe but a string of reversals (9.0): the clean warm start wins.
            ((0, 80.0, 9.0, 1.0), (0, 80.0, 0.0, 3.0), 3.0),
            // Nothing safe: the swarm's best, reported unsafe by the caller.
            ((2, 80.0, 0.0, 1.0), (1, 80.0, 0.0, 3.0), 1.0),
        ];
        for (swarm, warm, expected) in cases {
            let c = |(h, s, m, t)| candidate(h, s, m, t);
            let got = choose(c(swarm), std::iter::once(c(warm)), &[50.0]).total;
            assert_eq!(got, expected, "swarm {swarm:?}, warm {warm:?}");
        }
    }

    #[test]
    fn a_candidate_that_keeps_the_buffer_beats_one_that_only_keeps_d_min() {
        // d_min 50 m, buffer 10 m: (swarm's best, warm start) as (separation, cost).
        let c = |s: f64, t: f64| candidate(0, s, 0.0, t);
        let pick = |swarm: (f64, f64), warm: (f64, f64)| {
            choose(
                c(swarm.0, swarm.1),
                std::iter::once(c(warm.0, warm.1)),
                &[60.0, 50.0],
            )
            .total
        };
        // The cheaper answer grazes d_min (52 m); the dearer one keeps 61 m: it wins.
        assert_eq!(pick((52.0, 1.0), (61.0, 3.0)), 3.0);
        // Both keep the buffer: the cheaper wins.
        assert_eq!(pick((65.0, 1.0), (61.0, 3.0)), 1.0);
        // Neither keeps it; both keep d_min: the cheaper wins rather than nothing.
        assert_eq!(pick((52.0, 1.0), (55.0, 3.0)), 1.0);
        // Only one keeps d_min: it wins.
        assert_eq!(pick((49.0, 1.0), (55.0, 3.0)), 3.0);
    }
}
