//! Plans on a map: a `plan.json` (with its scenario, when there is one) turned into files that
//! map tools and ground stations read, through the scenario's geodetic origin
//! ([`shoal_common::geo`]). Pure conversions: `export` reads and writes the files.
//!
//! - [`geojson`]: one RFC 7946 FeatureCollection (paths, timed waypoints, obstacles, bounds).
//! - [`qgc`]: one QGroundControl `.plan` per vehicle (mission, geofence, no rally points).
//!
//! Only path plans (a `vehicles[].trajectory` per vehicle) are exported; a coverage mission's
//! `plan.json` has another shape.

pub mod geojson;
pub mod qgc;

use shoal_common::geo::GeoOrigin;
use shoal_common::geometry::Vec3;
use shoal_common::plan::{Plan, VehiclePlan};
use shoal_common::scenario::{Scenario, VehicleKind};

/// Vertices of the polygon that stands for an obstacle's circle (RFC 7946 has no circles): at
/// 64 the polygon strays from the circle by at most 0.12 % of its radius (0.4 m at 350 m).
pub const CIRCLE_VERTICES: usize = 64;

/// Longest distance a vehicle may stop short of a waypoint and count it reached, metres (see
/// [`qgc::acceptance_radius_m`]).
pub const MAX_ACCEPTANCE_RADIUS_M: f64 = 10.0;

/// Smallest change of leg speed worth a speed command, m/s: below what a vehicle's speed
/// control resolves.
pub const SPEED_CHANGE_MPS: f64 = 1e-3;

/// What an export is made of.
#[derive(Debug, Clone, Copy)]
pub struct ExportInput<'a> {
    /// The plan.
    pub plan: &'a Plan,
    /// Where its scenario point (0, 0, 0) is on the Earth.
    pub origin: GeoOrigin,
    /// Its scenario, for obstacles, bounds and vehicle kinds; without it only paths go out.
    pub scenario: Option<&'a Scenario>,
}

impl ExportInput<'_> {
    /// The kind of vehicle `id`, when the scenario is there to say.
    pub fn kind(&self, id: &str) -> Option<VehicleKind> {
        let s = self.scenario?;
        s.vehicles.iter().find(|v| v.id == id).map(|v| v.kind)
    }

    /// Depth of scenario height `z` below mean sea level, metres (negative above it): the
    /// origin's `alt_m` is the altitude of z = 0.
    pub fn depth_m(&self, z: f64) -> f64 {
        -(self.origin.alt_m + z)
    }
}

/// Why a plan cannot be exported as asked.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExportError {
    /// Neither the plan, the scenario nor the command line gives an origin.
    #[error("no origin: the plan and the scenario have none; give one with --origin LAT,LON,ALT (or add an [origin] table to the scenario and plan again)")]
    NoOrigin,
    /// Two given origins differ (each named with where it came from).
    #[error("{first} and {second} differ: give one origin, or the one the plan was made with")]
    OriginsDiffer {
        /// The first origin given, with its source.
        first: String,
        /// The one that differs from it, with its source.
        second: String,
    },
    /// A vehicle id cannot name a file.
    #[error("{0}: a vehicle id must be 1-64 letters, digits, '-', '_' or '.'")]
    BadId(String),
    /// A vehicle has no trajectory.
    #[error("vehicle {0} has no trajectory")]
    NoTrajectory(String),
    /// The scenario given is not the plan's.
    #[error("the plan was made for scenario {plan:?}, not {scenario:?}")]
    OtherScenario {
        /// The plan's scenario name.
        plan: String,
        /// The given scenario's name.
        scenario: String,
    },
    /// The plan has a vehicle the scenario lacks.
    #[error("vehicle {vehicle} is not in scenario {scenario:?}")]
    NotInScenario {
        /// The vehicle id.
        vehicle: String,
        /// The scenario's name.
        scenario: String,
    },
}

/// The one origin of an export, from wherever it is given: the plan's, the scenario's or the
/// command line's. None is an error, and so are two that differ (both named).
pub fn resolve_origin(
    plan: Option<GeoOrigin>,
    scenario: Option<GeoOrigin>,
    flag: Option<GeoOrigin>,
) -> Result<GeoOrigin, ExportError> {
    let given: Vec<(&str, GeoOrigin)> = [
        ("plan.json's origin", plan),
        ("the scenario's [origin]", scenario),
        ("--origin", flag),
    ]
    .into_iter()
    .filter_map(|(name, o)| o.map(|o| (name, o)))
    .collect();
    let Some(&(first_name, first)) = given.first() else {
        return Err(ExportError::NoOrigin);
    };
    for &(name, o) in &given[1..] {
        if !same(&first, &o) {
            return Err(ExportError::OriginsDiffer {
                first: format!("{first_name} {first}"),
                second: format!("{name} {o}"),
            });
        }
    }
    Ok(first)
}

/// Equal to well under a millimetre (the same numbers, read from different files).
fn same(a: &GeoOrigin, b: &GeoOrigin) -> bool {
    a.agrees_with(b, 1e-9, 1e-6)
}

/// Checks that `scenario` is the one `plan` was made for (same name, every vehicle in it) and
/// that every vehicle id can name a file.
pub fn check(plan: &Plan, scenario: Option<&Scenario>) -> Result<(), ExportError> {
    for v in &plan.vehicles {
        shoal_common::wire::topics::check_id("vehicle", &v.id)
            .map_err(|e| ExportError::BadId(e.to_string()))?;
        if v.trajectory.is_empty() {
            return Err(ExportError::NoTrajectory(v.id.clone()));
        }
    }
    let Some(s) = scenario else {
        return Ok(());
    };
    if s.name != plan.scenario {
        return Err(ExportError::OtherScenario {
            plan: plan.scenario.clone(),
            scenario: s.name.clone(),
        });
    }
    if let Some(v) = plan
        .vehicles
        .iter()
        .find(|v| !s.vehicles.iter().any(|w| w.id == v.id))
    {
        return Err(ExportError::NotInScenario {
            vehicle: v.id.clone(),
            scenario: s.name.clone(),
        });
    }
    Ok(())
}

/// The scenario point of sample `[t, x, y, z]`.
pub fn point(sample: &[f64; 4]) -> [f64; 3] {
    [sample[1], sample[2], sample[3]]
}

/// Speed of each leg of a trajectory (sample k to k + 1), m/s; `None` for a leg of no duration.
pub fn leg_speeds(v: &VehiclePlan) -> Vec<Option<f64>> {
    v.trajectory
        .windows(2)
        .map(|w| {
            let dt = w[1][0] - w[0][0];
            (dt > 0.0).then(|| distance(&point(&w[0]), &point(&w[1])) / dt)
        })
        .collect()
}

/// Straight-line distance, metres.
pub fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (Vec3::from(*a) - Vec3::from(*b)).norm()
}

/// The vertices of the [`CIRCLE_VERTICES`]-gon around the horizontal circle of radius `r` at
/// `centre`, counter-clockwise from east, not closed. The polygon circumscribes the circle
/// (vertices at r / cos(π/n)) so that, as a keep-out zone, it covers all of it.
pub fn circle(centre: [f64; 3], r: f64) -> Vec<[f64; 3]> {
    let n = CIRCLE_VERTICES as f64;
    let out = r / (std::f64::consts::PI / n).cos();
    (0..CIRCLE_VERTICES)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n;
            [
                centre[0] + out * a.cos(),
                centre[1] + out * a.sin(),
                centre[2],
            ]
        })
        .collect()
}

/// The corners of the scenario box's footprint at height `z`, counter-clockwise from the
/// south-west, not closed.
pub fn footprint(s: &Scenario, z: f64) -> [[f64; 3]; 4] {
    let (lo, hi) = (s.bounds.min, s.bounds.max);
    [
        [lo[0], lo[1], z],
        [hi[0], lo[1], z],
        [hi[0], hi[1], z],
        [lo[0], hi[1], z],
    ]
}

/// `x` rounded to `decimals` places: 9 for degrees (0.1 mm), 3 for metres, keeping the files
/// readable without losing what the conversion resolves.
pub fn round(x: f64, decimals: i32) -> f64 {
    let k = 10f64.powi(decimals);
    (x * k).round() / k
}

#[cfg(test)]
mod tests;
