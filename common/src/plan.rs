//! The plan a planner hands out (`plan.json`) and the assessment that fills its figures.
//!
//! Every figure is computed from the timed trajectories alone — not from the particle or the
//! fitness — so what `plan.json` says is exactly what the vehicles would fly, and an independent
//! checker that reads only the trajectories must get the same numbers.

use serde::{Deserialize, Serialize};

use crate::geometry::{pitch, polyline_length, segment_point_distance, turns};
use crate::scenario::Scenario;
use crate::separation::pair_separation;
use crate::trajectory::{shortest_pitch_feasible_length, Trajectory};

/// Slack for float noise in limit checks (degrees, m/s, metres, seconds).
const TOL: f64 = 1e-6;

/// One vehicle's part of a plan.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct VehiclePlan {
    /// Vehicle id from the scenario.
    pub id: String,
    /// `[t_s, x_m, y_m, z_m]` samples; straight lines at constant speed between them.
    pub trajectory: Vec<[f64; 4]>,
    /// Path length, metres.
    pub length_m: f64,
    /// Time of the last sample, seconds.
    pub arrival_s: f64,
    /// Largest heading change between consecutive legs with a heading, degrees (legs with no
    /// horizontal extent are skipped over, see [`crate::geometry::turns`]).
    pub max_turn_deg: f64,
    /// Largest |pitch| of a leg, degrees.
    pub max_pitch_deg: f64,
    /// Slowest leg speed, m/s.
    pub min_speed_mps: f64,
    /// Fastest leg speed, m/s.
    pub max_speed_mps: f64,
    /// Closest distance to a hard obstacle's physical surface (radius, without inflation),
    /// metres; `null` when there is no hard obstacle. Below the inflation margin is a collision.
    pub min_clearance_m: Option<f64>,
    /// Legs entering a hard obstacle's inflated sphere (leg × obstacle).
    pub hard_collisions: usize,
    /// Metres of path inside inflated soft obstacles.
    pub soft_exposure_m: f64,
    /// An AUV over a seabed: the lowest height of its path above the seabed, metres (sampled
    /// every [`crate::cost::SEABED_STEP_M`]; under the scenario's clearance is a violation).
    /// Absent for a crawler or without a seabed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_seabed_clearance_m: Option<f64>,
    /// Crawlers only: the Lu et al. 2023 figures of the path on the seabed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crawler: Option<crate::crawler::CrawlerFigures>,
    /// Energy-planned AUVs only: Zhang et al.'s figures (q_path, q_e, q_r, q_a, f_f, …).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy: Option<crate::energy::EnergyTerms>,
    /// Inspection tours only: Hu et al.'s figures (visiting order, tour length, path growth).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tour: Option<crate::tour::TourFigures>,
}

/// Fleet-wide figures.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct FleetFigures {
    /// Smallest distance between any two vehicles at the same instant, metres (`null` for a
    /// single vehicle).
    pub min_separation_m: Option<f64>,
    /// The pair at that distance.
    pub min_separation_pair: Option<[String; 2]>,
    /// When it happens, seconds.
    pub min_separation_time_s: Option<f64>,
    /// Total time pairs spend closer than d_min, seconds.
    pub separation_breach_s: f64,
    /// Sum of every vehicle's `hard_collisions`.
    pub hard_collisions: usize,
    /// Latest arrival minus earliest, seconds.
    pub arrival_spread_s: f64,
}

/// Figures and constraint checks of a set of trajectories.
#[derive(Debug, Clone, PartialEq)]
pub struct Assessment {
    /// Per vehicle, in scenario order.
    pub vehicles: Vec<VehiclePlan>,
    /// Fleet figures.
    pub fleet: FleetFigures,
    /// Broken constraints, in plain words. Empty means feasible.
    pub violations: Vec<String>,
}

/// Checks `trajectories` (scenario vehicle order) against every constraint of `scenario`.
pub fn assess(scenario: &Scenario, trajectories: &[Trajectory]) -> Assessment {
    let mut violations = Vec::new();
    let mut vehicles = Vec::with_capacity(trajectories.len());
    for (i, (v, t)) in scenario.vehicles.iter().zip(trajectories).enumerate() {
        let pts = &t.points;
        let crawler = scenario
            .crawler_model(i)
            .map(|m| crate::crawler::CrawlerFigures::of(&m, pts));
        if let Some(c) = &crawler {
            violations.extend(c.violations(&v.id));
        }
        let length = polyline_length(pts);
        let max_turn = turns(pts).map(f64::to_degrees).fold(0.0, f64::max);
        let max_pitch = pts
            .windows(2)
            .map(|w| pitch(&w[0], &w[1]).abs().to_degrees())
            .fold(0.0, f64::max);
        // Legs of zero length (a waypoint repeated) have no speed to check.
        let speeds: Vec<f64> = t
            .leg_speeds()
            .into_iter()
            .zip(pts.windows(2))
            .filter(|(_, w)| (w[1] - w[0]).norm() > TOL)
            .map(|(s, _)| s)
            .collect();
        let min_speed = speeds.iter().copied().fold(f64::INFINITY, f64::min);
        let max_speed = speeds.iter().copied().fold(0.0, f64::max);
        let mut clearance: Option<f64> = None;
        let mut hard_collisions = 0;
        for o in scenario.hard_obstacles() {
            let c = o.centre();
            let mut worst = f64::INFINITY;
            for w in pts.windows(2) {
                let d = segment_point_distance(&w[0], &w[1], &c);
                worst = worst.min(d);
                if d < o.inflated_radius() {
                    hard_collisions += 1;
                }
            }
            if pts.len() == 1 {
                worst = (pts[0] - c).norm();
            }
            let surface = worst - o.radius_m;
            clearance = Some(clearance.map_or(surface, |m: f64| m.min(surface)));
            if worst < o.inflated_radius() {
                violations.push(format!(
                    "{} passes {:.1} m from the centre of hard obstacle {} (radius {:.0} m + inflation {:.0} m = {:.0} m)",
                    v.id, worst, o.id, o.radius_m, o.inflation_m, o.inflated_radius()
                ));
            }
        }
        let soft_exposure: f64 = scenario
            .soft_obstacles()
            .map(|o| {
                pts.windows(2)
                    .map(|w| {
                        crate::geometry::chord_inside_sphere(
                            &w[0],
                            &w[1],
                            &o.centre(),
                            o.inflated_radius(),
                        )
                    })
                    .sum::<f64>()
            })
            .sum();
        if max_turn > v.max_turn_deg + TOL {
            violations.push(format!(
                "{} turns {:.1}° at a waypoint; its limit is {:.1}°",
                v.id, max_turn, v.max_turn_deg
            ));
        }
        if max_pitch > v.max_pitch_deg + TOL {
            violations.push(format!(
                "{} pitches {:.1}° on a leg; its limit is {:.1}°",
                v.id, max_pitch, v.max_pitch_deg
            ));
        }
        if !speeds.is_empty()
            && (min_speed < v.speed_min_mps - TOL || max_speed > v.speed_max_mps + TOL)
        {
            violations.push(format!(
                "{} flies legs at {:.3}–{:.3} m/s, outside its range {:.3}–{:.3} m/s",
                v.id, min_speed, max_speed, v.speed_min_mps, v.speed_max_mps
            ));
        }
        let seabed = match (&crawler, scenario.swimmer_seabed()) {
            (None, Some((terrain, keep))) => {
                // The planner's cost samples the same points.
                let lowest = terrain.lowest_height_on_path(pts, crate::cost::SEABED_STEP_M);
                if let Some((h, p)) = lowest.filter(|(h, _)| *h < keep - TOL) {
                    let how = if h < 0.0 {
                        format!("goes {:.1} m into", -h)
                    } else {
                        format!("passes {h:.1} m above")
                    };
                    violations.push(format!(
                        "{} {how} the seabed at ({:.0}, {:.0}) m; it must keep {:.1} m above it ({})",
                        v.id,
                        p.x,
                        p.y,
                        keep,
                        scenario.swimmer_clearance().map_or("", |(_, setting)| setting)
                    ));
                }
                lowest.map(|(h, _)| h)
            }
            _ => None,
        };
        let out_of_bounds = pts.iter().any(|p| {
            (0..3)
                .any(|a| p[a] < scenario.bounds.min[a] - TOL || p[a] > scenario.bounds.max[a] + TOL)
        });
        if out_of_bounds {
            violations.push(format!("{} leaves the scenario bounds", v.id));
        }
        // A crawler's ends are on the seabed below its start and goal.
        let gap = |p: &crate::geometry::Vec3, q: crate::geometry::Vec3| match crawler {
            Some(_) => (p.x - q.x).hypot(p.y - q.y),
            None => (p - q).norm(),
        };
        let ends_ok = pts.first().is_some_and(|p| gap(p, v.start()) <= TOL)
            && pts.last().is_some_and(|p| gap(p, v.goal()) <= TOL);
        if !ends_ok {
            violations.push(format!("{} does not run from its start to its goal", v.id));
        }
        vehicles.push(VehiclePlan {
            id: v.id.clone(),
            trajectory: t
                .times
                .iter()
                .zip(pts)
                .map(|(s, p)| [*s, p.x, p.y, p.z])
                .collect(),
            length_m: length,
            arrival_s: t.arrival(),
            max_turn_deg: max_turn,
            max_pitch_deg: max_pitch,
            min_speed_mps: if speeds.is_empty() { 0.0 } else { min_speed },
            max_speed_mps: max_speed,
            min_clearance_m: clearance,
            hard_collisions,
            soft_exposure_m: soft_exposure,
            min_seabed_clearance_m: seabed,
            crawler,
            energy: None,
            tour: None,
        });
    }

    let d_min = scenario.fleet.d_min_m;
    let mut fleet = FleetFigures {
        min_separation_m: None,
        min_separation_pair: None,
        min_separation_time_s: None,
        separation_breach_s: 0.0,
        hard_collisions: vehicles.iter().map(|v| v.hard_collisions).sum(),
        arrival_spread_s: 0.0,
    };
    for i in 0..trajectories.len() {
        for j in i + 1..trajectories.len() {
            let s = pair_separation(&trajectories[i], &trajectories[j], d_min);
            fleet.separation_breach_s += s.breach_s;
            if fleet.min_separation_m.is_none_or(|m| s.min_distance < m) {
                fleet.min_separation_m = Some(s.min_distance);
                fleet.min_separation_pair = Some([vehicles[i].id.clone(), vehicles[j].id.clone()]);
                fleet.min_separation_time_s = Some(s.min_time);
            }
            if s.min_distance < d_min {
                violations.push(format!(
                    "{} and {} come {:.1} m apart at t = {:.0} s (minimum separation {:.0} m), closer than that for {:.0} s",
                    vehicles[i].id, vehicles[j].id, s.min_distance, s.min_time, d_min, s.breach_s
                ));
            }
        }
    }
    let (first, last) = vehicles
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v.arrival_s), b.max(v.arrival_s))
        });
    fleet.arrival_spread_s = if vehicles.is_empty() {
        0.0
    } else {
        last - first
    };
    if fleet.arrival_spread_s > crate::cost::ARRIVAL_SPREAD_TOLERANCE_S {
        violations.push(format!(
            "arrivals are not synchronised: first at {first:.0} s, last at {last:.0} s"
        ));
    }
    Assessment {
        vehicles,
        fleet,
        violations,
    }
}

/// Plain-words notes that are not violations: why the common arrival differs from the mission
/// time, and capabilities a vehicle would need that are not built yet.
pub fn notices(
    scenario: &Scenario,
    trajectories: &[Trajectory],
    common_arrival: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    let mission = scenario.fleet.mission_time_s;
    for (v, t) in scenario.vehicles.iter().zip(trajectories) {
        let length = polyline_length(&t.points);
        let earliest = length / v.speed_max_mps;
        let latest = length / v.speed_min_mps;
        let shortest = shortest_pitch_feasible_length(v);
        let straight = (v.goal() - v.start()).norm();
        if shortest / v.speed_max_mps > mission + TOL {
            // No path at all gets this vehicle there in time.
            let dz = v.goal()[2] - v.start()[2];
            // z is up: a goal below the start is a descent.
            let change = if dz < 0.0 { "descending" } else { "climbing" };
            let why = if shortest > straight + TOL {
                format!(
                    "{change} {:.0} m within its {:.0}° pitch limit takes at least {shortest:.0} m of path (the straight line is {straight:.0} m)",
                    dz.abs(),
                    v.max_pitch_deg
                )
            } else {
                format!("even the {straight:.0} m straight line is too long")
            };
            out.push(format!(
                "{} cannot arrive by the mission time of {mission:.0} s whatever its path: {why}, {:.0} s at its top speed of {:.3} m/s; every vehicle is timed to arrive at {common_arrival:.0} s instead",
                v.id,
                shortest / v.speed_max_mps,
                v.speed_max_mps
            ));
        } else if earliest > mission + TOL && earliest >= common_arrival - TOL {
            // This vehicle's planned path sets the late arrival, though a shorter one exists.
            out.push(format!(
                "{}'s planned path of {length:.0} m takes at least {earliest:.0} s at its top speed of {:.3} m/s, so the fleet arrives at {common_arrival:.0} s instead of the mission time of {mission:.0} s (the shortest path its pitch limit allows, {shortest:.0} m, would take {:.0} s; obstacles, turn limits and the other vehicles made it longer)",
                v.id,
                v.speed_max_mps,
                shortest / v.speed_max_mps
            ));
        } else if latest < common_arrival - TOL {
            out.push(format!(
                "{} cannot slow down enough to arrive at {common_arrival:.0} s: at its slowest, {:.3} m/s, its {length:.0} m path takes only {latest:.0} s",
                v.id, v.speed_min_mps
            ));
        }
    }
    out
}

/// `plan.json`.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Plan {
    /// Scenario name.
    pub scenario: String,
    /// Optimizer used.
    pub algorithm: String,
    /// `in-process` or `distributed`.
    pub mode: String,
    /// RNG seed.
    pub seed: u64,
    /// Planning wall time, seconds.
    pub runtime_s: f64,
    /// Final fitness (eq. (12) plus weighted penalties); lower is better.
    pub fitness: f64,
    /// eq. (12) alone.
    pub objective: f64,
    /// Unweighted constraint penalty (0 for a feasible plan).
    pub penalty: f64,
    /// True when `violations` is empty.
    pub feasible: bool,
    /// Broken constraints, in plain words.
    pub violations: Vec<String>,
    /// Things a user should know that are not violations (e.g. late common arrival).
    pub notices: Vec<String>,
    /// Mission time from the scenario, seconds.
    pub mission_time_s: f64,
    /// Arrival time every vehicle is timed for, seconds.
    pub common_arrival_s: f64,
    /// Minimum separation from the scenario, metres.
    pub d_min_m: f64,
    /// Iterations run.
    pub iterations: usize,
    /// Fitness evaluations.
    pub evaluations: u64,
    /// Why the optimizer stopped.
    pub termination: String,
    /// Per vehicle.
    pub vehicles: Vec<VehiclePlan>,
    /// Fleet figures.
    pub fleet: FleetFigures,
    /// Best fitness after each iteration.
    pub convergence: Vec<f64>,
    /// Distributed runs only: how the mission went over the network.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distributed: Option<DistributedFigures>,
    /// The scenario's `[origin]`, which ties the trajectories' metres to WGS-84 (map exports,
    /// MAVLink vehicles); absent when the scenario has none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<crate::geo::GeoOrigin>,
}

/// What a distributed run adds to `plan.json`.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct DistributedFigures {
    /// Mission id (the key prefix `shoal/<mission>/…`).
    pub mission: String,
    /// Leader/follower exchanges done.
    pub exchanges: u32,
    /// Messages the coordinator dropped (malformed, wrong version, unknown mission or vehicle,
    /// out of turn).
    pub messages_dropped: u64,
    /// Per agent, in scenario order.
    pub agents: Vec<AgentFigures>,
    /// Vehicles whose followers the coordinator ran itself, and why.
    pub degraded: Vec<DegradedVehicle>,
    /// What a leader/follower round cost the coordinator (absent for one-shot missions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rounds: Option<RoundFigures>,
}

/// The coordinator's time per leader/follower round, averaged over the run's rounds: how the
/// exchange and the leader's own step grow with the fleet.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize, PartialEq)]
pub struct RoundFigures {
    /// Rounds run.
    pub rounds: u32,
    /// Mean wall time from asking for a round's elites to holding every agent's, seconds: the
    /// agents' iterations plus the exchange over the network.
    pub collect_s: f64,
    /// Mean wall time of the leader's step (its populations, the migrants, the context),
    /// seconds.
    pub leader_s: f64,
    /// Mean CPU time of the coordinator's process per round, seconds (Linux; 0 elsewhere).
    pub coordinator_cpu_s: f64,
}

/// One agent's share of a distributed run.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct AgentFigures {
    /// Vehicle id.
    pub vehicle: String,
    /// Iterations its followers ran (in the agent, then in the coordinator if degraded).
    pub iterations: u32,
    /// Elite messages the coordinator received from it.
    pub elites_sent: u32,
    /// Messages the agent dropped (its own count, when it reported one).
    pub messages_dropped: Option<u32>,
    /// True when the coordinator took its followers over.
    pub degraded: bool,
}

/// A vehicle planned in degraded mode.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct DegradedVehicle {
    /// Vehicle id.
    pub vehicle: String,
    /// Exchange round from which the coordinator ran its followers.
    pub from_round: u32,
    /// Why, in plain words.
    pub reason: String,
}

#[cfg(test)]
mod tests;
