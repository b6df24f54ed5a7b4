//! Independent checker of `plan.json`.
//!
//! This crate deliberately does not depend on `shoal-common` or `shoal-coordinator`: it reads the
//! scenario TOML and the plan JSON with its own minimal serde structs and recomputes every figure
//! from the timed trajectories with its own geometry. A bug shared by the planner and its own
//! assessment therefore shows up here as a mismatch.
//!
//! Semantics (the `plan.json` contract):
//! * a vehicle moves in a straight line at constant speed between consecutive samples
//!   `[t_s, x, y, z]`, holds at its first sample before it and at its last sample after it;
//! * turn = heading change in the horizontal (x–y) plane at each inner sample, degrees; a leg with
//!   no horizontal extent has no heading and gives no turn;
//! * pitch = `atan2(dz, horizontal length)` of a leg, degrees (absolute value);
//! * a hard collision is a (leg, hard obstacle) pair whose segment comes strictly closer than
//!   `radius_m + inflation_m` to the obstacle centre;
//! * clearance = segment distance to a hard obstacle's centre minus its `radius_m`;
//! * separation = distance between two vehicles at the same instant, over `[0, last arrival]`.

use std::fmt;

use serde::Deserialize;

/// Absolute slack for float noise (metres, seconds, degrees, m/s); also used as relative slack.
pub const TOL: f64 = 1e-6;

/// Absolute slack for separation figures, metres (and seconds for the breach time).
pub const SEPARATION_TOL: f64 = 1e-3;

/// Largest arrival spread of a feasible plan, seconds.
pub const MAX_ARRIVAL_SPREAD_S: f64 = 1.0;

// ---------------------------------------------------------------------------------------------
// Input: minimal views of the scenario TOML and plan JSON.
// ---------------------------------------------------------------------------------------------

/// The parts of a scenario file the checker needs (unknown keys are ignored).
#[derive(Debug, Clone, Deserialize)]
pub struct Scenario {
    /// Scenario name.
    pub name: String,
    /// Navigation box.
    pub bounds: Bounds,
    /// Spheres to avoid (hard) or to limit exposure to (soft).
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// The fleet.
    pub vehicles: Vec<Vehicle>,
    /// Fleet coupling.
    pub fleet: Fleet,
}

/// Axis-aligned box, metres.
#[derive(Debug, Clone, Deserialize)]
pub struct Bounds {
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
}

/// Hard or soft obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ObstacleKind {
    /// Must not be entered (radius plus inflation).
    Hard,
    /// May be crossed at a cost.
    Soft,
}

/// A sphere with an inflation margin.
#[derive(Debug, Clone, Deserialize)]
pub struct Obstacle {
    /// Name.
    pub id: String,
    /// Hard or soft.
    pub kind: ObstacleKind,
    /// Centre, metres.
    pub centre: [f64; 3],
    /// Physical radius, metres.
    pub radius_m: f64,
    /// Safety margin, metres.
    pub inflation_m: f64,
}

/// One vehicle and its limits.
#[derive(Debug, Clone, Deserialize)]
pub struct Vehicle {
    /// Unique id.
    pub id: String,
    /// Start, metres.
    pub start: [f64; 3],
    /// Goal, metres.
    pub goal: [f64; 3],
    /// Slowest leg speed, m/s.
    pub speed_min_mps: f64,
    /// Fastest leg speed, m/s.
    pub speed_max_mps: f64,
    /// Largest heading change, degrees.
    pub max_turn_deg: f64,
    /// Largest |pitch|, degrees.
    pub max_pitch_deg: f64,
}

/// Fleet coupling.
#[derive(Debug, Clone, Deserialize)]
pub struct Fleet {
    /// Minimum separation, metres.
    pub d_min_m: f64,
    /// Mission time, seconds.
    pub mission_time_s: f64,
}

/// `plan.json` as the checker reads it.
#[derive(Debug, Clone, Deserialize)]
pub struct Plan {
    /// Scenario name.
    pub scenario: String,
    /// Optimizer.
    pub algorithm: String,
    /// `in-process` or `distributed`.
    pub mode: String,
    /// RNG seed.
    pub seed: u64,
    /// Wall time, seconds.
    pub runtime_s: f64,
    /// Final fitness.
    pub fitness: f64,
    /// True when no constraint is broken.
    pub feasible: bool,
    /// Broken constraints, in words.
    pub violations: Vec<String>,
    /// Informational notes.
    pub notices: Vec<String>,
    /// Mission time echoed from the scenario, seconds.
    pub mission_time_s: f64,
    /// Arrival time the vehicles are timed for, seconds.
    pub common_arrival_s: f64,
    /// Minimum separation echoed from the scenario, metres.
    pub d_min_m: f64,
    /// Per vehicle.
    pub vehicles: Vec<PlanVehicle>,
    /// Fleet figures.
    pub fleet: PlanFleet,
    /// Best fitness per iteration.
    pub convergence: Vec<f64>,
}

/// One vehicle's entry in `plan.json`.
#[derive(Debug, Clone, Deserialize)]
pub struct PlanVehicle {
    /// Vehicle id.
    pub id: String,
    /// `[t_s, x, y, z]` samples.
    pub trajectory: Vec<[f64; 4]>,
    /// Reported path length, metres.
    pub length_m: f64,
    /// Reported arrival, seconds.
    pub arrival_s: f64,
    /// Reported largest turn, degrees.
    pub max_turn_deg: f64,
    /// Reported largest |pitch|, degrees.
    pub max_pitch_deg: f64,
    /// Reported slowest leg, m/s.
    pub min_speed_mps: f64,
    /// Reported fastest leg, m/s.
    pub max_speed_mps: f64,
    /// Reported clearance to hard obstacles' surfaces, metres.
    pub min_clearance_m: Option<f64>,
    /// Reported (leg, hard obstacle) collisions.
    pub hard_collisions: usize,
    /// Reported metres inside inflated soft obstacles.
    pub soft_exposure_m: f64,
}

/// Fleet figures in `plan.json`.
#[derive(Debug, Clone, Deserialize)]
pub struct PlanFleet {
    /// Reported smallest separation, metres.
    pub min_separation_m: Option<f64>,
    /// Reported pair at that separation.
    pub min_separation_pair: Option<[String; 2]>,
    /// Reported instant of that separation, seconds.
    pub min_separation_time_s: Option<f64>,
    /// Reported time spent below d_min, seconds.
    pub separation_breach_s: f64,
    /// Reported sum of hard collisions.
    pub hard_collisions: usize,
    /// Reported latest minus earliest arrival, seconds.
    pub arrival_spread_s: f64,
}

/// Parses a scenario file's text.
pub fn parse_scenario(text: &str) -> Result<Scenario, String> {
    toml::from_str(text).map_err(|e| format!("scenario does not parse: {e}"))
}

/// Parses a `plan.json` text.
pub fn parse_plan(text: &str) -> Result<Plan, String> {
    serde_json::from_str(text).map_err(|e| format!("plan.json does not parse: {e}"))
}

// ---------------------------------------------------------------------------------------------
// Geometry, written from scratch.
// ---------------------------------------------------------------------------------------------

/// The checker's own geometry on `[f64; 3]` points and `[t, x, y, z]` trajectories.
pub mod geometry {
    /// A point, metres.
    pub type P3 = [f64; 3];

    /// `a − b`.
    pub fn sub(a: &P3, b: &P3) -> P3 {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }

    /// Dot product.
    pub fn dot(a: &P3, b: &P3) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    /// Euclidean norm.
    pub fn norm(a: &P3) -> f64 {
        dot(a, a).sqrt()
    }

    /// Distance between two points.
    pub fn dist(a: &P3, b: &P3) -> f64 {
        norm(&sub(a, b))
    }

    /// `a + (b − a) s`.
    pub fn lerp(a: &P3, b: &P3, s: f64) -> P3 {
        [
            a[0] + (b[0] - a[0]) * s,
            a[1] + (b[1] - a[1]) * s,
            a[2] + (b[2] - a[2]) * s,
        ]
    }

    /// Parameter in `[0, 1]` of the point of segment `a→b` closest to `p` (0 for a point).
    pub fn closest_param(a: &P3, b: &P3, p: &P3) -> f64 {
        let k = sub(b, a);
        let kk = dot(&k, &k);
        if kk == 0.0 {
            return 0.0;
        }
        (dot(&sub(p, a), &k) / kk).clamp(0.0, 1.0)
    }

    /// Shortest distance from `p` to the segment `a→b`.
    pub fn segment_point_distance(a: &P3, b: &P3, p: &P3) -> f64 {
        dist(&lerp(a, b, closest_param(a, b, p)), p)
    }

    /// Length of the part of segment `a→b` strictly inside the sphere (`c`, `r`).
    pub fn chord_inside_sphere(a: &P3, b: &P3, c: &P3, r: f64) -> f64 {
        let len = dist(a, b);
        if len == 0.0 {
            return 0.0;
        }
        let (s0, s1) = param_interval_within(a, b, c, r);
        (s1 - s0).max(0.0) * len
    }

    /// The sub-interval `[s0, s1]` of `[0, 1]` on which `a + (b − a) s` is within `r` of `c`
    /// (`s1 <= s0` when there is none). For a degenerate segment: all of `[0, 1]` or nothing.
    pub fn param_interval_within(a: &P3, b: &P3, c: &P3, r: f64) -> (f64, f64) {
        let k = sub(b, a);
        let f = sub(a, c);
        let qa = dot(&k, &k);
        let qb = 2.0 * dot(&k, &f);
        let qc = dot(&f, &f) - r * r;
        if qa == 0.0 {
            return if qc < 0.0 { (0.0, 1.0) } else { (0.0, 0.0) };
        }
        let disc = qb * qb - 4.0 * qa * qc;
        if disc <= 0.0 {
            return (0.0, 0.0);
        }
        let sq = disc.sqrt();
        let lo = ((-qb - sq) / (2.0 * qa)).max(0.0);
        let hi = ((-qb + sq) / (2.0 * qa)).min(1.0);
        (lo, hi)
    }

    /// Horizontal heading change at the corner `a→b→c`, degrees in `[0, 180]`; 0 when either leg
    /// has no horizontal extent.
    pub fn heading_change_deg(a: &P3, b: &P3, c: &P3) -> f64 {
        let u = [b[0] - a[0], b[1] - a[1]];
        let v = [c[0] - b[0], c[1] - b[1]];
        let nu = u[0].hypot(u[1]);
        let nv = v[0].hypot(v[1]);
        if nu <= 1e-9 || nv <= 1e-9 {
            return 0.0;
        }
        let cos = ((u[0] * v[0] + u[1] * v[1]) / (nu * nv)).clamp(-1.0, 1.0);
        let sin = (u[0] * v[1] - u[1] * v[0]) / (nu * nv);
        sin.abs().atan2(cos).to_degrees()
    }

    /// |pitch| of the leg `a→b`, degrees in `[0, 90]`; 0 for a leg of zero length.
    pub fn abs_pitch_deg(a: &P3, b: &P3) -> f64 {
        let d = sub(b, a);
        let h = d[0].hypot(d[1]);
        if h == 0.0 && d[2] == 0.0 {
            return 0.0;
        }
        d[2].abs().atan2(h).to_degrees()
    }

    /// Position part of a sample.
    pub fn point(sample: &[f64; 4]) -> P3 {
        [sample[1], sample[2], sample[3]]
    }

    /// Position at time `t`: linear between samples, held before the first and after the last.
    /// At a sample time shared by several samples (a zero-duration leg) the last one is used.
    pub fn position_at(traj: &[[f64; 4]], t: f64) -> P3 {
        let (Some(first), Some(last)) = (traj.first(), traj.last()) else {
            return [f64::NAN; 3];
        };
        if t < first[0] {
            return point(first);
        }
        if t >= last[0] {
            return point(last);
        }
        for w in traj.windows(2) {
            if w[0][0] <= t && t < w[1][0] {
                let s = (t - w[0][0]) / (w[1][0] - w[0][0]);
                return lerp(&point(&w[0]), &point(&w[1]), s);
            }
        }
        point(last)
    }

    /// The straight piece a trajectory flies over `[t0, t1]`, where `(t0, t1)` contains no sample
    /// time: its positions at `t0` and `t1` (limits from inside the interval).
    pub fn piece(traj: &[[f64; 4]], t0: f64, t1: f64) -> (P3, P3) {
        let tm = 0.5 * (t0 + t1);
        let (Some(first), Some(last)) = (traj.first(), traj.last()) else {
            return ([f64::NAN; 3], [f64::NAN; 3]);
        };
        if tm <= first[0] {
            return (point(first), point(first));
        }
        if tm >= last[0] {
            return (point(last), point(last));
        }
        for w in traj.windows(2) {
            let (ta, tb) = (w[0][0], w[1][0]);
            if ta <= tm && tm < tb {
                let (a, b) = (point(&w[0]), point(&w[1]));
                let at = |t: f64| lerp(&a, &b, (t - ta) / (tb - ta));
                return (at(t0), at(t1));
            }
        }
        (point(last), point(last))
    }

    /// Where the last sample of a trajectory is timed (0 for an empty one).
    pub fn arrival(traj: &[[f64; 4]]) -> f64 {
        traj.last().map_or(0.0, |s| s[0])
    }

    /// The instants at which the relative motion of `a` and `b` may change: 0, every sample time
    /// in `[0, T]` of either trajectory and `T`, the later arrival; sorted, without duplicates.
    pub fn breakpoints(a: &[[f64; 4]], b: &[[f64; 4]]) -> Vec<f64> {
        let end = arrival(a).max(arrival(b)).max(0.0);
        let mut ts: Vec<f64> = a
            .iter()
            .chain(b.iter())
            .map(|s| s[0])
            .filter(|t| t.is_finite() && *t >= 0.0 && *t <= end)
            .chain([0.0, end])
            .collect();
        ts.sort_by(f64::total_cmp);
        ts.dedup();
        ts
    }

    /// Closest approach of two vehicles.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct Approach {
        /// Smallest distance, metres.
        pub distance: f64,
        /// An instant at which it occurs, seconds.
        pub time: f64,
    }

    /// Exact closest approach of `a` and `b` over `[0, max arrival]`.
    ///
    /// Between consecutive breakpoints both vehicles move linearly, so their relative position
    /// `d(s) = d0 + (d1 − d0) s`, `s ∈ [0, 1]`, is linear too and its smallest norm is at the
    /// clamped projection of the origin onto that segment.
    pub fn min_separation(a: &[[f64; 4]], b: &[[f64; 4]]) -> Approach {
        let ts = breakpoints(a, b);
        let mut best = Approach {
            distance: dist(&position_at(a, 0.0), &position_at(b, 0.0)),
            time: 0.0,
        };
        for w in ts.windows(2) {
            let (t0, t1) = (w[0], w[1]);
            let (a0, a1) = piece(a, t0, t1);
            let (b0, b1) = piece(b, t0, t1);
            let d0 = sub(&b0, &a0);
            let d1 = sub(&b1, &a1);
            let s = closest_param(&d0, &d1, &[0.0; 3]);
            let d = norm(&lerp(&d0, &d1, s));
            if d < best.distance {
                best = Approach {
                    distance: d,
                    time: t0 + s * (t1 - t0),
                };
            }
        }
        best
    }

    /// Total time in `[0, max arrival]` during which `a` and `b` are strictly closer than `limit`.
    pub fn breach_time(a: &[[f64; 4]], b: &[[f64; 4]], limit: f64) -> f64 {
        let ts = breakpoints(a, b);
        let mut total = 0.0;
        for w in ts.windows(2) {
            let (t0, t1) = (w[0], w[1]);
            let (a0, a1) = piece(a, t0, t1);
            let (b0, b1) = piece(b, t0, t1);
            let d0 = sub(&b0, &a0);
            let d1 = sub(&b1, &a1);
            let (s0, s1) = param_interval_within(&d0, &d1, &[0.0; 3], limit);
            total += (s1 - s0).max(0.0) * (t1 - t0);
        }
        total
    }

    /// Closest approach found by sampling `[0, max arrival]` every `step` seconds (and at the end):
    /// an upper bound of [`min_separation`], for cross-checking it.
    pub fn sampled_min_separation(a: &[[f64; 4]], b: &[[f64; 4]], step: f64) -> Approach {
        let end = arrival(a).max(arrival(b)).max(0.0);
        let n = if step > 0.0 {
            (end / step).ceil() as usize
        } else {
            0
        };
        let mut best = Approach {
            distance: f64::INFINITY,
            time: 0.0,
        };
        for k in 0..=n {
            let t = (k as f64 * step).min(end);
            let d = dist(&position_at(a, t), &position_at(b, t));
            if d < best.distance {
                best = Approach {
                    distance: d,
                    time: t,
                };
            }
        }
        best
    }
}

use geometry::{dist, point, P3};

// ---------------------------------------------------------------------------------------------
// Recomputed figures.
// ---------------------------------------------------------------------------------------------

/// Figures of one vehicle, recomputed from its trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleFigures {
    /// Vehicle id.
    pub id: String,
    /// Sum of leg lengths, metres.
    pub length_m: f64,
    /// Time of the last sample, seconds.
    pub arrival_s: f64,
    /// Largest horizontal heading change, degrees.
    pub max_turn_deg: f64,
    /// Largest |pitch|, degrees.
    pub max_pitch_deg: f64,
    /// Slowest leg of non-zero length, m/s (0 when there is none).
    pub min_speed_mps: f64,
    /// Fastest leg of non-zero length, m/s (0 when there is none).
    pub max_speed_mps: f64,
    /// Smallest (segment distance to centre − radius) over hard obstacles; `None` without any.
    pub min_clearance_m: Option<f64>,
    /// (leg, hard obstacle) pairs closer than radius plus inflation.
    pub hard_collisions: usize,
    /// Metres of path inside inflated soft obstacles, summed over obstacles.
    pub soft_exposure_m: f64,
    /// True when every sample lies inside the scenario bounds (± [`TOL`]).
    pub inside_bounds: bool,
    /// `(leg index, speed m/s)` of every leg of non-zero length (infinite for a jump in no time).
    pub leg_speeds_mps: Vec<(usize, f64)>,
}

/// Fleet figures, recomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetFigures {
    /// Smallest separation over all pairs; `None` for fewer than two vehicles.
    pub min_separation_m: Option<f64>,
    /// Pair at that separation.
    pub min_separation_pair: Option<[String; 2]>,
    /// Instant of that separation.
    pub min_separation_time_s: Option<f64>,
    /// Total time pairs spend closer than d_min, seconds.
    pub separation_breach_s: f64,
    /// Sum of hard collisions.
    pub hard_collisions: usize,
    /// Latest minus earliest arrival, seconds.
    pub arrival_spread_s: f64,
}

/// Recomputes a vehicle's figures from its trajectory against the scenario's obstacles.
pub fn vehicle_figures(id: &str, traj: &[[f64; 4]], scenario: &Scenario) -> VehicleFigures {
    let pts: Vec<P3> = traj.iter().map(point).collect();
    let length_m = pts.windows(2).map(|w| dist(&w[0], &w[1])).sum();
    let max_turn_deg = pts
        .windows(3)
        .map(|w| geometry::heading_change_deg(&w[0], &w[1], &w[2]))
        .fold(0.0, f64::max);
    let max_pitch_deg = pts
        .windows(2)
        .map(|w| geometry::abs_pitch_deg(&w[0], &w[1]))
        .fold(0.0, f64::max);
    let leg_speeds_mps: Vec<(usize, f64)> = traj
        .windows(2)
        .enumerate()
        .filter_map(|(k, w)| {
            let len = dist(&point(&w[0]), &point(&w[1]));
            let dt = w[1][0] - w[0][0];
            if len <= TOL {
                None
            } else if dt > 0.0 {
                Some((k, len / dt))
            } else {
                Some((k, f64::INFINITY))
            }
        })
        .collect();
    let (min_speed_mps, max_speed_mps) = if leg_speeds_mps.is_empty() {
        (0.0, 0.0)
    } else {
        (
            leg_speeds_mps
                .iter()
                .map(|s| s.1)
                .fold(f64::INFINITY, f64::min),
            leg_speeds_mps.iter().map(|s| s.1).fold(0.0, f64::max),
        )
    };
    let mut min_clearance_m: Option<f64> = None;
    let mut hard_collisions = 0;
    let mut soft_exposure_m = 0.0;
    for o in &scenario.obstacles {
        let inflated = o.radius_m + o.inflation_m;
        match o.kind {
            ObstacleKind::Hard => {
                let mut closest = f64::INFINITY;
                if pts.len() == 1 {
                    closest = dist(&pts[0], &o.centre);
                }
                for w in pts.windows(2) {
                    let d = geometry::segment_point_distance(&w[0], &w[1], &o.centre);
                    closest = closest.min(d);
                    if d < inflated {
                        hard_collisions += 1;
                    }
                }
                let c = closest - o.radius_m;
                min_clearance_m = Some(min_clearance_m.map_or(c, |m| m.min(c)));
            }
            ObstacleKind::Soft => {
                soft_exposure_m += pts
                    .windows(2)
                    .map(|w| geometry::chord_inside_sphere(&w[0], &w[1], &o.centre, inflated))
                    .sum::<f64>();
            }
        }
    }
    let (lo, hi) = (scenario.bounds.min, scenario.bounds.max);
    let inside_bounds = pts
        .iter()
        .all(|p| (0..3).all(|k| p[k] >= lo[k] - TOL && p[k] <= hi[k] + TOL));
    VehicleFigures {
        id: id.to_string(),
        length_m,
        arrival_s: geometry::arrival(traj),
        max_turn_deg,
        max_pitch_deg,
        min_speed_mps,
        max_speed_mps,
        min_clearance_m,
        hard_collisions,
        soft_exposure_m,
        inside_bounds,
        leg_speeds_mps,
    }
}

/// Recomputes the fleet figures from the trajectories (`(id, trajectory)` in scenario order).
pub fn fleet_figures(
    trajectories: &[(&str, &[[f64; 4]])],
    d_min: f64,
    hard_collisions: usize,
) -> FleetFigures {
    let mut out = FleetFigures {
        min_separation_m: None,
        min_separation_pair: None,
        min_separation_time_s: None,
        separation_breach_s: 0.0,
        hard_collisions,
        arrival_spread_s: 0.0,
    };
    for (i, (ida, a)) in trajectories.iter().enumerate() {
        for (idb, b) in &trajectories[i + 1..] {
            let m = geometry::min_separation(a, b);
            out.separation_breach_s += geometry::breach_time(a, b, d_min);
            if out.min_separation_m.is_none_or(|best| m.distance < best) {
                out.min_separation_m = Some(m.distance);
                out.min_separation_pair = Some([ida.to_string(), idb.to_string()]);
                out.min_separation_time_s = Some(m.time);
            }
        }
    }
    let arrivals = trajectories.iter().map(|(_, t)| geometry::arrival(t));
    let first = arrivals.clone().fold(f64::INFINITY, f64::min);
    let last = arrivals.fold(f64::NEG_INFINITY, f64::max);
    if !trajectories.is_empty() {
        out.arrival_spread_s = last - first;
    }
    out
}

// ---------------------------------------------------------------------------------------------
// The check.
// ---------------------------------------------------------------------------------------------

/// What the checker found.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// Recomputed per-vehicle figures, scenario order (vehicles missing from the plan skipped).
    pub vehicles: Vec<VehicleFigures>,
    /// Recomputed fleet figures.
    pub fleet: FleetFigures,
    /// Figures where `plan.json` disagrees with the recomputation.
    pub mismatches: Vec<String>,
    /// Broken contract rules and constraints (start/goal, timing, speeds, `feasible` claims).
    pub failures: Vec<String>,
}

impl Report {
    /// True when the plan's figures agree with the recomputation and every rule holds.
    pub fn is_clean(&self) -> bool {
        self.mismatches.is_empty() && self.failures.is_empty()
    }

    /// Mismatches and failures, one line each.
    pub fn problems(&self) -> Vec<String> {
        self.mismatches
            .iter()
            .map(|m| format!("mismatch: {m}"))
            .chain(self.failures.iter().map(|f| format!("failure: {f}")))
            .collect()
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_clean() {
            return write!(f, "plan.json is consistent");
        }
        for line in self.problems() {
            writeln!(f, "{line}")?;
        }
        Ok(())
    }
}

/// True when `a` and `b` agree within `abs` or within [`TOL`] relative.
pub fn close(a: f64, b: f64, abs: f64) -> bool {
    if a == b {
        return true;
    }
    (a - b).abs() <= abs.max(TOL * a.abs().max(b.abs()))
}

/// Parses both files and checks the plan against the scenario.
pub fn check(scenario_toml: &str, plan_json: &str) -> Result<Report, String> {
    let scenario = parse_scenario(scenario_toml)?;
    let plan = parse_plan(plan_json)?;
    Ok(check_parsed(&scenario, &plan))
}

/// Checks a parsed plan against a parsed scenario.
pub fn check_parsed(scenario: &Scenario, plan: &Plan) -> Report {
    let mut mismatches = Vec::new();
    let mut failures = Vec::new();
    let num = |out: &mut Vec<String>, what: String, reported: f64, recomputed: f64, abs: f64| {
        if !close(reported, recomputed, abs) {
            out.push(format!(
                "{what}: reported {reported} but recomputed {recomputed} (difference {:e})",
                reported - recomputed
            ));
        }
    };

    // Echoed scenario values.
    if plan.scenario != scenario.name {
        failures.push(format!(
            "plan.scenario is {:?} but the scenario is named {:?}",
            plan.scenario, scenario.name
        ));
    }
    num(
        &mut mismatches,
        "d_min_m".into(),
        plan.d_min_m,
        scenario.fleet.d_min_m,
        TOL,
    );
    num(
        &mut mismatches,
        "mission_time_s".into(),
        plan.mission_time_s,
        scenario.fleet.mission_time_s,
        TOL,
    );

    // Vehicles: match plan entries to scenario vehicles by id.
    for pv in &plan.vehicles {
        if !scenario.vehicles.iter().any(|v| v.id == pv.id) {
            failures.push(format!("plan vehicle {:?} is not in the scenario", pv.id));
        }
    }
    let plan_ids: Vec<&str> = plan.vehicles.iter().map(|v| v.id.as_str()).collect();
    let scenario_ids: Vec<&str> = scenario.vehicles.iter().map(|v| v.id.as_str()).collect();
    if plan_ids != scenario_ids {
        failures.push(format!(
            "plan vehicles are {plan_ids:?}, expected {scenario_ids:?} (scenario order)"
        ));
    }
    let mut pairs: Vec<(&Vehicle, &PlanVehicle)> = Vec::new();
    for v in &scenario.vehicles {
        match plan.vehicles.iter().find(|p| p.id == v.id) {
            Some(p) => pairs.push((v, p)),
            None => failures.push(format!("vehicle {} is missing from the plan", v.id)),
        }
    }

    let mut figures = Vec::with_capacity(pairs.len());
    for (v, pv) in &pairs {
        let id = &v.id;
        let traj = &pv.trajectory;
        if traj.is_empty() {
            failures.push(format!("{id}: empty trajectory"));
        }
        if traj.iter().flatten().any(|x| !x.is_finite()) {
            failures.push(format!("{id}: trajectory has a non-finite value"));
        }
        let f = vehicle_figures(id, traj, scenario);

        // Reported versus recomputed.
        num(
            &mut mismatches,
            format!("{id}.length_m"),
            pv.length_m,
            f.length_m,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.arrival_s"),
            pv.arrival_s,
            f.arrival_s,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.max_turn_deg"),
            pv.max_turn_deg,
            f.max_turn_deg,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.max_pitch_deg"),
            pv.max_pitch_deg,
            f.max_pitch_deg,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.min_speed_mps"),
            pv.min_speed_mps,
            f.min_speed_mps,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.max_speed_mps"),
            pv.max_speed_mps,
            f.max_speed_mps,
            TOL,
        );
        num(
            &mut mismatches,
            format!("{id}.soft_exposure_m"),
            pv.soft_exposure_m,
            f.soft_exposure_m,
            TOL,
        );
        match (pv.min_clearance_m, f.min_clearance_m) {
            (Some(r), Some(c)) => num(&mut mismatches, format!("{id}.min_clearance_m"), r, c, TOL),
            (None, None) => {}
            (r, c) => mismatches.push(format!(
                "{id}.min_clearance_m: reported {r:?} but recomputed {c:?}"
            )),
        }
        if pv.hard_collisions != f.hard_collisions {
            mismatches.push(format!(
                "{id}.hard_collisions: reported {} but recomputed {}",
                pv.hard_collisions, f.hard_collisions
            ));
        }

        // Contract rules that hold for every plan.
        if let (Some(first), Some(last)) = (traj.first(), traj.last()) {
            let ds = dist(&point(first), &v.start);
            if ds > TOL {
                failures.push(format!(
                    "{id}: trajectory starts at {:?}, {ds} m from its start {:?}",
                    point(first),
                    v.start
                ));
            }
            let dg = dist(&point(last), &v.goal);
            if dg > TOL {
                failures.push(format!(
                    "{id}: trajectory ends at {:?}, {dg} m from its goal {:?}",
                    point(last),
                    v.goal
                ));
            }
            if first[0].abs() > TOL {
                failures.push(format!(
                    "{id}: trajectory starts at t = {} s, not 0",
                    first[0]
                ));
            }
        }
        if let Some(k) = traj.windows(2).position(|w| w[1][0] < w[0][0]) {
            failures.push(format!(
                "{id}: time goes backwards from sample {k} (t = {}) to sample {} (t = {})",
                traj[k][0],
                k + 1,
                traj[k + 1][0]
            ));
        }
        for &(k, s) in &f.leg_speeds_mps {
            if s < v.speed_min_mps - TOL || s > v.speed_max_mps + TOL {
                failures.push(format!(
                    "{id}: leg {k} (sample {k} to {}) at {s} m/s, outside {}–{} m/s",
                    k + 1,
                    v.speed_min_mps,
                    v.speed_max_mps
                ));
            }
        }
        figures.push(f);
    }

    // Fleet.
    let reported_hard: usize = plan.vehicles.iter().map(|v| v.hard_collisions).sum();
    if plan.fleet.hard_collisions != reported_hard {
        mismatches.push(format!(
            "fleet.hard_collisions: reported {} but the vehicles' hard_collisions sum to {reported_hard}",
            plan.fleet.hard_collisions
        ));
    }
    let trajs: Vec<(&str, &[[f64; 4]])> = pairs
        .iter()
        .map(|(v, p)| (v.id.as_str(), p.trajectory.as_slice()))
        .collect();
    let fleet = fleet_figures(
        &trajs,
        scenario.fleet.d_min_m,
        figures.iter().map(|f| f.hard_collisions).sum(),
    );
    if plan.fleet.hard_collisions != fleet.hard_collisions {
        mismatches.push(format!(
            "fleet.hard_collisions: reported {} but recomputed {}",
            plan.fleet.hard_collisions, fleet.hard_collisions
        ));
    }
    num(
        &mut mismatches,
        "fleet.arrival_spread_s".into(),
        plan.fleet.arrival_spread_s,
        fleet.arrival_spread_s,
        TOL,
    );
    num(
        &mut mismatches,
        "fleet.separation_breach_s".into(),
        plan.fleet.separation_breach_s,
        fleet.separation_breach_s,
        SEPARATION_TOL,
    );
    match (plan.fleet.min_separation_m, fleet.min_separation_m) {
        (Some(r), Some(c)) => num(
            &mut mismatches,
            "fleet.min_separation_m".into(),
            r,
            c,
            SEPARATION_TOL,
        ),
        (None, None) => {}
        (r, c) => mismatches.push(format!(
            "fleet.min_separation_m: reported {r:?} but recomputed {c:?}"
        )),
    }
    // The reported pair and instant must realise the reported minimum (ties may pick any pair).
    if let Some(reported) = plan.fleet.min_separation_m {
        let pair = plan.fleet.min_separation_pair.as_ref().and_then(|[x, y]| {
            let a = trajs.iter().find(|(id, _)| id == x)?;
            let b = trajs.iter().find(|(id, _)| id == y)?;
            Some((x, y, a.1, b.1))
        });
        match pair {
            None => failures.push(format!(
                "fleet.min_separation_pair {:?} does not name two vehicles of the plan",
                plan.fleet.min_separation_pair
            )),
            Some((x, y, a, b)) => {
                let exact = geometry::min_separation(a, b).distance;
                num(
                    &mut mismatches,
                    format!("fleet.min_separation_m (as the closest approach of {x} and {y})"),
                    reported,
                    exact,
                    SEPARATION_TOL,
                );
                match plan.fleet.min_separation_time_s {
                    Some(t) => {
                        let at = dist(&geometry::position_at(a, t), &geometry::position_at(b, t));
                        num(
                            &mut mismatches,
                            format!("fleet.min_separation_m (distance of {x} and {y} at the reported t = {t} s)"),
                            reported,
                            at,
                            SEPARATION_TOL,
                        );
                    }
                    None => failures.push("fleet.min_separation_time_s is null".to_string()),
                }
            }
        }
    }

    // `feasible` and `violations`.
    if plan.feasible != plan.violations.is_empty() {
        failures.push(format!(
            "feasible = {} but violations = {:?}",
            plan.feasible, plan.violations
        ));
    }
    let d_min = scenario.fleet.d_min_m;
    // Constraints broken beyond the slack (what a feasible plan must not have) ...
    let mut broken = Vec::new();
    // ... and constraints broken or within the slack of breaking (an infeasible plan needs one).
    let mut marginal = Vec::new();
    for ((v, pv), f) in pairs.iter().zip(&figures) {
        let id = &v.id;
        if f.hard_collisions > 0 {
            broken.push(format!("{id} has {} hard collisions", f.hard_collisions));
        }
        if f.max_turn_deg > v.max_turn_deg + TOL {
            broken.push(format!(
                "{id} turns {}° > {}°",
                f.max_turn_deg, v.max_turn_deg
            ));
        }
        if f.max_turn_deg > v.max_turn_deg - TOL {
            marginal.push(format!("{id} turn"));
        }
        if f.max_pitch_deg > v.max_pitch_deg + TOL {
            broken.push(format!(
                "{id} pitches {}° > {}°",
                f.max_pitch_deg, v.max_pitch_deg
            ));
        }
        if f.max_pitch_deg > v.max_pitch_deg - TOL {
            marginal.push(format!("{id} pitch"));
        }
        if !f.inside_bounds {
            broken.push(format!("{id} leaves the bounds"));
        }
        let ends_ok = pv
            .trajectory
            .first()
            .is_some_and(|s| dist(&point(s), &v.start) <= TOL)
            && pv
                .trajectory
                .last()
                .is_some_and(|s| dist(&point(s), &v.goal) <= TOL);
        if !ends_ok {
            broken.push(format!("{id} does not run from start to goal"));
        }
        if f.leg_speeds_mps
            .iter()
            .any(|&(_, s)| s < v.speed_min_mps + TOL || s > v.speed_max_mps - TOL)
        {
            marginal.push(format!("{id} speed"));
        }
    }
    if let Some(m) = fleet.min_separation_m {
        if m < d_min - SEPARATION_TOL {
            broken.push(format!("min separation {m} m < d_min {d_min} m"));
        }
        if m < d_min + SEPARATION_TOL {
            marginal.push("separation".to_string());
        }
    }
    if fleet.arrival_spread_s > MAX_ARRIVAL_SPREAD_S + TOL {
        broken.push(format!("arrival spread {} s > 1 s", fleet.arrival_spread_s));
    }
    if fleet.arrival_spread_s > MAX_ARRIVAL_SPREAD_S - TOL {
        marginal.push("arrival spread".to_string());
    }
    if plan.feasible && !broken.is_empty() {
        failures.push(format!(
            "plan is marked feasible but the checker finds: {}",
            broken.join("; ")
        ));
    }
    if !plan.feasible && broken.is_empty() && marginal.is_empty() {
        failures.push(format!(
            "plan is marked infeasible ({:?}) but the checker finds every constraint met",
            plan.violations
        ));
    }

    Report {
        vehicles: figures,
        fleet,
        mismatches,
        failures,
    }
}

#[cfg(test)]
mod tests {
    use super::geometry::*;
    use super::*;

    fn approx(a: f64, b: f64, eps: f64) -> bool {
        (a - b).abs() <= eps
    }

    #[test]
    fn segment_distance_by_hand() {
        // Foot inside the segment.
        assert!(approx(
            segment_point_distance(&[0., 0., 0.], &[10., 0., 0.], &[5., 3., 0.]),
            3.0,
            1e-12
        ));
        // Foot beyond the end: the end point (10, 0, 0) is 5 m from (13, 4, 0).
        assert!(approx(
            segment_point_distance(&[0., 0., 0.], &[10., 0., 0.], &[13., 4., 0.]),
            5.0,
            1e-12
        ));
        // Foot before the start, in 3-D: the start (0, 0, 0) is √(4 + 9 + 36) = 7 m away.
        assert!(approx(
            segment_point_distance(&[0., 0., 0.], &[0., 10., 0.], &[-2., -3., 6.]),
            7.0,
            1e-12
        ));
        // A degenerate segment is a point.
        assert!(approx(
            segment_point_distance(&[1., 1., 1.], &[1., 1., 1.], &[1., 1., 3.]),
            2.0,
            1e-12
        ));
    }

    #[test]
    fn chord_by_hand() {
        // Through the centre of a 30 m sphere: 60 m inside.
        assert!(approx(
            chord_inside_sphere(&[0., 0., 0.], &[1000., 0., 0.], &[500., 0., 0.], 30.0),
            60.0,
            1e-9
        ));
        // Offset 18 m from a 30 m sphere: 2·√(30² − 18²) = 48 m.
        assert!(approx(
            chord_inside_sphere(&[0., 0., 0.], &[1000., 0., 0.], &[500., 18., 0.], 30.0),
            48.0,
            1e-9
        ));
        // Ends inside: from the centre outwards only 30 m count; segment too short: 10 m.
        assert!(approx(
            chord_inside_sphere(&[500., 0., 0.], &[1000., 0., 0.], &[500., 0., 0.], 30.0),
            30.0,
            1e-9
        ));
        assert!(approx(
            chord_inside_sphere(&[495., 0., 0.], &[505., 0., 0.], &[500., 0., 0.], 30.0),
            10.0,
            1e-9
        ));
        // Misses.
        assert_eq!(
            chord_inside_sphere(&[0., 0., 0.], &[1000., 0., 0.], &[500., 40., 0.], 30.0),
            0.0
        );
    }

    #[test]
    fn turn_and_pitch_by_hand() {
        // 45° left turn, 90° right turn, U-turn.
        assert!(approx(
            heading_change_deg(&[0., 0., 0.], &[10., 0., 0.], &[20., 10., 0.]),
            45.0,
            1e-9
        ));
        assert!(approx(
            heading_change_deg(&[0., 0., 0.], &[10., 0., 5.], &[10., -10., 9.]),
            90.0,
            1e-9
        ));
        assert!(approx(
            heading_change_deg(&[0., 0., 0.], &[10., 0., 0.], &[0., 0., 0.]),
            180.0,
            1e-9
        ));
        // A vertical leg has no heading: no turn at either end of it.
        assert_eq!(
            heading_change_deg(&[0., 0., 0.], &[10., 0., 0.], &[10., 0., 10.]),
            0.0
        );
        assert_eq!(
            heading_change_deg(&[10., 0., 0.], &[10., 0., 10.], &[10., 10., 10.]),
            0.0
        );
        // Pitch: 45° up, 30° down (dz = −10, horizontal 10√3), vertical, still.
        assert!(approx(
            abs_pitch_deg(&[0., 0., 0.], &[10., 0., 10.]),
            45.0,
            1e-9
        ));
        assert!(approx(
            abs_pitch_deg(&[0., 0., 10.], &[0., 10. * 3f64.sqrt(), 0.]),
            30.0,
            1e-9
        ));
        assert!(approx(
            abs_pitch_deg(&[0., 0., 0.], &[0., 0., -3.]),
            90.0,
            1e-9
        ));
        assert_eq!(abs_pitch_deg(&[1., 2., 3.], &[1., 2., 3.]), 0.0);
    }

    #[test]
    fn position_holds_before_and_after() {
        let t = [[0., 0., 0., 0.], [10., 10., 0., 0.], [20., 10., 20., 0.]];
        assert_eq!(position_at(&t, -5.0), [0., 0., 0.]);
        assert_eq!(position_at(&t, 5.0), [5., 0., 0.]);
        assert_eq!(position_at(&t, 15.0), [10., 10., 0.]);
        assert_eq!(position_at(&t, 20.0), [10., 20., 0.]);
        assert_eq!(position_at(&t, 1e6), [10., 20., 0.]);
    }

    #[test]
    fn head_on_crossing_30_m_apart() {
        // a east along y = 0, b west along y = 30, both at 1 m/s: closest at t = 500, 30 m,
        // between samples (there are none in between).
        let a = [[0., 0., 0., -50.], [1000., 1000., 0., -50.]];
        let b = [[0., 1000., 30., -50.], [1000., 0., 30., -50.]];
        let m = min_separation(&a, &b);
        assert!(approx(m.distance, 30.0, 1e-9), "{m:?}");
        assert!(approx(m.time, 500.0, 1e-9), "{m:?}");
        // Closer than 50 m while the x gap 1000 − 2t is within ±√(50² − 30²) = ±40 m: 40 s.
        assert!(approx(breach_time(&a, &b, 50.0), 40.0, 1e-9));
        assert_eq!(breach_time(&a, &b, 30.0), 0.0);
        // Sampling every second finds the same (t = 500 is a sample).
        assert!(approx(
            sampled_min_separation(&a, &b, 1.0).distance,
            30.0,
            1e-9
        ));
    }

    #[test]
    fn early_arrival_holds_at_goal_while_the_other_passes() {
        // a: (0,0,0) → (100,0,0) by t = 100, then holds. b: (400,20,0) → (0,20,0) at 1 m/s.
        // Before t = 100 the gap is ≥ 200 m; afterwards b passes the parked a at t = 300, 20 m away.
        // A checker that stopped at the earlier arrival would report 200 m.
        let a = [[0., 0., 0., 0.], [100., 100., 0., 0.]];
        let b = [[0., 400., 20., 0.], [400., 0., 20., 0.]];
        let m = min_separation(&a, &b);
        assert!(approx(m.distance, 20.0, 1e-9), "{m:?}");
        assert!(approx(m.time, 300.0, 1e-9), "{m:?}");
        // Symmetric.
        let m2 = min_separation(&b, &a);
        assert!(approx(m2.distance, 20.0, 1e-9) && approx(m2.time, 300.0, 1e-9));
        // Within 25 m while |x − 100| < 15: t in (285, 315): 30 s.
        assert!(approx(breach_time(&a, &b, 25.0), 30.0, 1e-9));
    }

    #[test]
    fn closest_approach_between_samples_of_both() {
        // a has a corner at t = 50, b at t = 70: the merged breakpoints are 0, 50, 70, 100.
        // a: (0,0,0) → (50,0,0) → (50,50,0); b: (100,25,0) → (30,25,0) → (30, 25, 30).
        // On [50, 70] a = (50, t − 50, 0) and b = (100 − t, 25, 0), so b − a = (50 − t, 75 − t, 0),
        // shortest at t = 62.5: 12.5·√2 ≈ 17.7 m. ([0, 50] gives ≥ 25 m, [70, 100] ≥ 20.3 m.)
        let a = [[0., 0., 0., 0.], [50., 50., 0., 0.], [100., 50., 50., 0.]];
        let b = [
            [0., 100., 25., 0.],
            [70., 30., 25., 0.],
            [100., 30., 25., 30.],
        ];
        let m = min_separation(&a, &b);
        assert!(approx(m.distance, 12.5 * 2f64.sqrt(), 1e-9), "{m:?}");
        assert!(approx(m.time, 62.5, 1e-9), "{m:?}");
        let s = sampled_min_separation(&a, &b, 0.5);
        assert!(approx(s.distance, m.distance, 1e-9), "{s:?}");
    }

    /// Deterministic pseudo-random numbers in [0, 1) (no RNG crate needed).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn random_trajectory(rng: &mut Lcg, n: usize, speed: f64) -> Vec<[f64; 4]> {
        let mut t = 0.0;
        let mut p = [rng.next() * 400.0, rng.next() * 400.0, rng.next() * 100.0];
        let mut out = vec![[t, p[0], p[1], p[2]]];
        for _ in 1..n {
            let q = [rng.next() * 400.0, rng.next() * 400.0, rng.next() * 100.0];
            let v = speed * (0.5 + rng.next());
            t += dist(&p, &q) / v;
            p = q;
            out.push([t, p[0], p[1], p[2]]);
        }
        out
    }

    #[test]
    fn exact_separation_agrees_with_dense_sampling() {
        let mut rng = Lcg(7);
        for _ in 0..200 {
            let na = 2 + (rng.next() * 8.0) as usize;
            let nb = 2 + (rng.next() * 8.0) as usize;
            let a = random_trajectory(&mut rng, na, 2.0);
            let b = random_trajectory(&mut rng, nb, 2.0);
            let exact = min_separation(&a, &b);
            // The exact minimum is a lower bound of any sample and realised at its instant.
            let at = dist(&position_at(&a, exact.time), &position_at(&b, exact.time));
            assert!(approx(at, exact.distance, 1e-9), "{exact:?} vs {at}");
            for step in [1.0, 0.1] {
                let dense = sampled_min_separation(&a, &b, step);
                assert!(
                    exact.distance <= dense.distance + 1e-9,
                    "{exact:?} > {dense:?}"
                );
                // Relative speed ≤ 2 · 3 m/s, so the nearest sample is at most 6 · step / 2 worse.
                assert!(
                    dense.distance - exact.distance <= 3.0 * step + 1e-9,
                    "{exact:?} vs {dense:?} at {step} s"
                );
            }
        }
    }

    const SCENARIO: &str = r#"
name = "hand"
description = "two vehicles passing, one hard and one soft obstacle"
[bounds]
min = [0.0, -500.0, 0.0]
max = [1000.0, 500.0, 100.0]
[[obstacles]]
id = "H"
kind = "hard"
centre = [500.0, -60.0, 50.0]
radius_m = 20.0
inflation_m = 10.0
[[obstacles]]
id = "S"
kind = "soft"
centre = [250.0, 200.0, 50.0]
radius_m = 10.0
inflation_m = 10.0
[[vehicles]]
id = "a"
kind = "auv"
start = [0.0, 0.0, 50.0]
goal = [1000.0, 0.0, 50.0]
speed_min_mps = 0.5
speed_max_mps = 2.0
max_turn_deg = 35.0
max_pitch_deg = 20.0
[[vehicles]]
id = "b"
kind = "auv"
start = [1000.0, 200.0, 50.0]
goal = [0.0, 200.0, 50.0]
speed_min_mps = 0.5
speed_max_mps = 2.0
max_turn_deg = 35.0
max_pitch_deg = 20.0
[fleet]
d_min_m = 150.0
mission_time_s = 1000.0
[optimizer]
seed = 4
"#;

    /// A plan for [`SCENARIO`] with hand-computed figures: a passes 60 m from H (clearance 40 m),
    /// b 260 m (clearance 240 m) and straight through S (chord 2 · 20 = 40 m); both fly 1000 m
    /// at 1 m/s and pass 200 m apart at t = 500 s.
    fn plan_json(a_length: f64, feasible: bool, violations: &str, b_goal_x: f64) -> String {
        format!(
            r#"{{
  "scenario": "hand", "algorithm": "amp-pso", "mode": "in-process", "seed": 4,
  "runtime_s": 0.1, "fitness": 1.0, "objective": 1.0, "penalty": 0.0,
  "feasible": {feasible}, "violations": {violations}, "notices": [],
  "mission_time_s": 1000.0, "common_arrival_s": 1000.0, "d_min_m": 150.0,
  "iterations": 1, "evaluations": 1, "termination": "iterations",
  "vehicles": [
    {{"id": "a", "trajectory": [[0, 0, 0, 50], [500, 500, 0, 50], [1000, 1000, 0, 50]],
      "length_m": {a_length}, "arrival_s": 1000, "max_turn_deg": 0, "max_pitch_deg": 0,
      "min_speed_mps": 1, "max_speed_mps": 1, "min_clearance_m": 40, "hard_collisions": 0,
      "soft_exposure_m": 0}},
    {{"id": "b", "trajectory": [[0, 1000, 200, 50], [1000, {b_goal_x}, 200, 50]],
      "length_m": 1000, "arrival_s": 1000, "max_turn_deg": 0, "max_pitch_deg": 0,
      "min_speed_mps": 1, "max_speed_mps": 1, "min_clearance_m": 240, "hard_collisions": 0,
      "soft_exposure_m": 40}}
  ],
  "fleet": {{"min_separation_m": 200, "min_separation_pair": ["a", "b"],
    "min_separation_time_s": 500, "separation_breach_s": 0, "hard_collisions": 0,
    "arrival_spread_s": 0}},
  "convergence": [2.0, 1.0]
}}"#
        )
    }

    #[test]
    fn consistent_plan_is_clean() -> Result<(), String> {
        let r = check(SCENARIO, &plan_json(1000.0, true, "[]", 0.0))?;
        assert!(r.is_clean(), "{r}");
        assert_eq!(
            r.vehicles[0]
                .min_clearance_m
                .map(|c| (c * 1e9).round() / 1e9),
            Some(40.0)
        );
        assert!(approx(r.vehicles[1].soft_exposure_m, 40.0, 1e-9));
        assert_eq!(
            r.fleet.min_separation_pair,
            Some(["a".to_string(), "b".to_string()])
        );
        assert!(approx(
            r.fleet.min_separation_time_s.unwrap_or(f64::NAN),
            500.0,
            1e-9
        ));
        Ok(())
    }

    #[test]
    fn wrong_figure_is_a_mismatch() -> Result<(), String> {
        let r = check(SCENARIO, &plan_json(1001.0, true, "[]", 0.0))?;
        assert!(r.failures.is_empty(), "{r}");
        assert_eq!(r.mismatches.len(), 1, "{r}");
        assert!(r.mismatches[0].contains("a.length_m"), "{r}");
        assert!(r.mismatches[0].contains("1001"), "{r}");
        Ok(())
    }

    #[test]
    fn feasible_with_violations_fails() -> Result<(), String> {
        let r = check(SCENARIO, &plan_json(1000.0, true, r#"["something"]"#, 0.0))?;
        assert!(
            r.failures.iter().any(|f| f.contains("feasible = true")),
            "{r}"
        );
        // Marked infeasible although nothing is broken.
        let r = check(SCENARIO, &plan_json(1000.0, false, r#"["something"]"#, 0.0))?;
        assert!(
            r.failures
                .iter()
                .any(|f| f.contains("every constraint met")),
            "{r}"
        );
        Ok(())
    }

    #[test]
    fn missing_the_goal_fails() -> Result<(), String> {
        // b stops 10 m short: its length, speed and exposure no longer match either.
        let r = check(SCENARIO, &plan_json(1000.0, true, "[]", 10.0))?;
        assert!(
            r.failures.iter().any(|f| f.contains("b: trajectory ends")),
            "{r}"
        );
        assert!(
            r.failures.iter().any(|f| f.contains("marked feasible")),
            "{r}"
        );
        assert!(r.mismatches.iter().any(|m| m.contains("b.length_m")), "{r}");
        Ok(())
    }

    #[test]
    fn breaches_are_found() -> Result<(), String> {
        // Move b to y = 20: it passes 20 m from a (below d_min) and 80 m from H (clearance 60 m);
        // the reported figures were not updated, so they mismatch, and feasible is wrong.
        let text = plan_json(1000.0, true, "[]", 0.0).replace(", 200, 50]", ", 20, 50]");
        let scenario = SCENARIO
            .replace("[1000.0, 200.0, 50.0]", "[1000.0, 20.0, 50.0]")
            .replace("goal = [0.0, 200.0, 50.0]", "goal = [0.0, 20.0, 50.0]");
        let r = check(&scenario, &text)?;
        assert!(
            r.mismatches
                .iter()
                .any(|m| m.contains("fleet.min_separation_m")),
            "{r}"
        );
        assert!(
            r.failures.iter().any(|f| f.contains("min separation 20")),
            "{r}"
        );
        assert!(approx(
            r.fleet.min_separation_m.unwrap_or(f64::NAN),
            20.0,
            1e-9
        ));
        // Closer than 150 m while |1000 − 2t| < √(150² − 20²) ≈ 148.66 m: for 148.66 s.
        let expect = (150f64.powi(2) - 20f64.powi(2)).sqrt();
        assert!(
            approx(r.fleet.separation_breach_s, expect, 1e-6),
            "{}",
            r.fleet.separation_breach_s
        );
        Ok(())
    }

    #[test]
    fn parse_errors_are_errors() {
        assert!(check("name = 1", "{}").is_err());
        assert!(check(SCENARIO, "{\"scenario\": \"hand\"}").is_err());
    }
}
