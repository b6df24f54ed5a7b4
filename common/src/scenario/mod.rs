//! Scenario files: the mission a planner is asked to solve, in TOML with SI units (metres, seconds,
//! metres per second, degrees).
//!
//! Loading never panics on user input: a syntax error, an unknown key or a bad value comes back as
//! a [`ScenarioError`] naming the file, the field and the value.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::geometry::Vec3;

mod coverage;
mod inspection;
mod ocean;
mod optimizer;
mod seabed;
pub use coverage::CoverageSettings;
pub use inspection::{FirstPointMode, InspectionSettings};
pub use ocean::{CurrentModel, Currents, EnergySettings};
pub use optimizer::{Algorithm, DistributedSettings, OptimizerSettings};
pub use seabed::{CrawlerSettings, Seabed, SeabedGrid};

use crate::crawler::CrawlerModel;
use crate::terrain::Hazard;

/// One knot in metres per second (1852 m / 3600 s), for scenario comments and tests.
pub const KNOT_MPS: f64 = 1852.0 / 3600.0;

/// Why a scenario could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read at all.
    /// The reason is in the message and deliberately not a `source`: a chained report (`{:#}`)
    /// would print it twice.
    #[error("{file}: cannot read: {error}")]
    Io {
        file: PathBuf,
        error: std::io::Error,
    },
    /// TOML syntax, an unknown key, a missing key or a value of the wrong type.
    #[error("{file}: {message}")]
    Parse { file: PathBuf, message: String },
    /// A value that parses but makes no sense for a mission.
    #[error("{file}: field `{field}` = {value}: {reason}")]
    Invalid {
        file: PathBuf,
        field: String,
        value: String,
        reason: String,
    },
}

/// A whole mission: where, what is in the way, who goes where, and how to optimise.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name, reported in `plan.json` (e.g. `amp-pso-3`).
    pub name: String,
    /// Free text: where the numbers come from.
    #[serde(default)]
    pub description: String,
    /// The box every waypoint must stay in; z is up and `max[2]` is the sea surface.
    pub bounds: Bounds,
    /// Spheres to avoid (hard) or to spend little time in (soft).
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// The vehicles to plan for, one chromosome each.
    pub vehicles: Vec<Vehicle>,
    /// Coupling between the vehicles: separation and synchronised arrival.
    pub fleet: Fleet,
    /// Which optimizer and with what budget.
    #[serde(default)]
    pub optimizer: OptimizerSettings,
    /// The seabed crawlers drive on (seed 000 §2.2); required when a vehicle is a crawler.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seabed: Option<Seabed>,
    /// Soft-substrate zones crawlers must not enter, vertical cylinders (seed 000 eq. (4)).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub hazards: Vec<Hazard>,
    /// Settings of the crawler cost (seed 000 eq. (5)–(11)).
    #[serde(default)]
    pub crawler: CrawlerSettings,
    /// The ocean current (seed 001 eq. (2)); absent: still water.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub currents: Option<Currents>,
    /// Settings of the energy-saving planner (seed 001, Table 2).
    #[serde(default)]
    pub energy: EnergySettings,
    /// Cage-inspection tours (seed 003); required by the tour planners.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inspection: Option<InspectionSettings>,
    /// Area coverage by a mining crawler (seed 002); its presence makes `plan` cover an area.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<CoverageSettings>,
}

/// Axis-aligned box of the navigation space, metres.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    /// South-west-bottom corner.
    pub min: [f64; 3],
    /// North-east-top corner; `max[2]` is the surface used by the depth term.
    pub max: [f64; 3],
}

/// How an obstacle affects a vehicle (seed 004 §2.1).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ObstacleKind {
    /// Must never be entered (radius plus inflation): a plan touching one is infeasible.
    Hard,
    /// May be crossed at a cost (seston, particulates): the threat term F(O).
    Soft,
}

/// A sphere with a safety inflation margin (seed 004 Fig. 1).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// Name used in reports (e.g. `HObs#1`).
    pub id: String,
    /// Hard or soft.
    pub kind: ObstacleKind,
    /// Centre, metres.
    pub centre: [f64; 3],
    /// Physical radius, metres.
    pub radius_m: f64,
    /// Safety margin added to the radius, metres (seed 004 Table 4: d_hard = d_soft = 50 m).
    pub inflation_m: f64,
}

impl Obstacle {
    /// Centre as a vector.
    pub fn centre(&self) -> Vec3 {
        Vec3::from(self.centre)
    }
    /// Radius plus inflation: the sphere the planner keeps out of.
    pub fn inflated_radius(&self) -> f64 {
        self.radius_m + self.inflation_m
    }
}

/// Vehicle type; decides which planner capabilities apply.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum VehicleKind {
    /// Free-swimming AUV.
    Auv,
    /// Tracked seabed crawler (mining vehicle).
    Crawler,
}

/// One vehicle of the fleet and its kinematic limits.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Vehicle {
    /// Unique id (e.g. `auv1`).
    pub id: String,
    /// AUV or crawler.
    pub kind: VehicleKind,
    /// Start point, metres.
    pub start: [f64; 3],
    /// Goal point, metres.
    pub goal: [f64; 3],
    /// Slowest speed through the water on any leg, m/s.
    pub speed_min_mps: f64,
    /// Fastest speed on any leg, m/s.
    pub speed_max_mps: f64,
    /// Largest heading change at a waypoint, degrees (seed 004: 35°).
    pub max_turn_deg: f64,
    /// Largest |pitch| of a leg, degrees (seed 004: 20°).
    pub max_pitch_deg: f64,
    /// Turning radius when executing, metres (the simulated vehicle's). Absent: seed 001's
    /// R_AUV (`energy.min_turn_radius_m`) in an energy mission, whose planner keeps to it, else
    /// the simulator's default of 20 m, a mid-size survey AUV.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turn_radius_m: Option<f64>,
}

impl Vehicle {
    /// Start as a vector.
    pub fn start(&self) -> Vec3 {
        Vec3::from(self.start)
    }
    /// Goal as a vector.
    pub fn goal(&self) -> Vec3 {
        Vec3::from(self.goal)
    }
}

/// Fleet coupling (seed 004 §2.2.2).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Fleet {
    /// Minimum distance between any two vehicles at every instant, metres (eq. (1)).
    pub d_min_m: f64,
    /// Time at which every vehicle should reach its goal, seconds after the start (t_e).
    pub mission_time_s: f64,
}

/// The least distance between a vehicle's start and goal a path planner accepts, metres.
pub const MIN_START_GOAL_DISTANCE_M: f64 = 1.0;

impl Scenario {
    /// Reads, parses and validates a scenario file.
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|error| ScenarioError::Io {
            file: path.to_path_buf(),
            error,
        })?;
        Scenario::parse(&text, path)
    }

    /// Parses and validates scenario text; `file` is only used in error messages.
    pub fn parse(text: &str, file: &Path) -> Result<Scenario, ScenarioError> {
        let mut scenario: Scenario =
            serde_path_to_error::deserialize(toml::Deserializer::new(text)).map_err(|e| {
                // The path names the field even where toml's quoted line does not show its key
                // (an element of an array written over several lines); "." is the whole file.
                let field = e.path().to_string();
                let message = e.into_inner().to_string().trim_end().replace('\n', "\n  ");
                ScenarioError::Parse {
                    file: file.to_path_buf(),
                    message: if field == "." {
                        message
                    } else {
                        format!("field {field}: {message}")
                    },
                }
            })?;
        scenario.validate(file)?;
        if let Some(seabed) = &mut scenario.seabed {
            let bad = |field: String, value: String, reason: &str| ScenarioError::Invalid {
                file: file.to_path_buf(),
                field,
                value,
                reason: reason.to_string(),
            };
            let dir = file.parent().unwrap_or(Path::new("."));
            let b = &scenario.bounds;
            let area = [b.min[0], b.min[1], b.max[0], b.max[1]];
            seabed.resolve(area, dir, file, &bad)?;
        }
        if let Some(currents) = &mut scenario.currents {
            let bad = |field: String, value: String, reason: &str| ScenarioError::Invalid {
                file: file.to_path_buf(),
                field,
                value,
                reason: reason.to_string(),
            };
            currents.resolve(file.parent().unwrap_or(Path::new(".")), file, &bad)?;
        }
        Ok(scenario)
    }

    /// Checks every value a planner relies on; the first bad one is reported.
    pub fn validate(&self, file: &Path) -> Result<(), ScenarioError> {
        let bad = |field: String, value: String, reason: &str| ScenarioError::Invalid {
            file: file.to_path_buf(),
            field,
            value,
            reason: reason.to_string(),
        };
        for axis in 0..3 {
            let (lo, hi) = (self.bounds.min[axis], self.bounds.max[axis]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(bad(
                    format!("bounds.max[{axis}]"),
                    format!("{hi}"),
                    &format!("must be finite and greater than bounds.min[{axis}] = {lo}"),
                ));
            }
        }
        let inside =
            |p: &[f64; 3]| (0..3).all(|a| p[a] >= self.bounds.min[a] && p[a] <= self.bounds.max[a]);
        for (i, o) in self.obstacles.iter().enumerate() {
            if !o.centre.iter().all(|c| c.is_finite()) {
                return Err(bad(
                    format!("obstacles[{i}].centre"),
                    format!("{:?}", o.centre),
                    "must be finite",
                ));
            }
            if !(o.radius_m.is_finite() && o.radius_m > 0.0) {
                return Err(bad(
                    format!("obstacles[{i}].radius_m"),
                    o.radius_m.to_string(),
                    "must be a positive number of metres",
                ));
            }
            if !(o.inflation_m.is_finite() && o.inflation_m >= 0.0) {
                return Err(bad(
                    format!("obstacles[{i}].inflation_m"),
                    o.inflation_m.to_string(),
                    "must be zero or a positive number of metres",
                ));
            }
        }
        if self.vehicles.is_empty() {
            return Err(bad(
                "vehicles".into(),
                "[]".into(),
                "at least one vehicle is needed",
            ));
        }
        for (i, v) in self.vehicles.iter().enumerate() {
            if crate::wire::topics::check_id("vehicle", &v.id).is_err() {
                return Err(bad(
                    format!("vehicles[{i}].id"),
                    format!("{:?}", v.id),
                    "must be 1-64 letters, digits, '-', '_' or '.' (it names the vehicle on the network)",
                ));
            }
            if let Some(j) = self.vehicles[..i].iter().position(|w| w.id == v.id) {
                return Err(bad(
                    format!("vehicles[{i}].id"),
                    format!("{:?}", v.id),
                    &format!("duplicates vehicles[{j}].id"),
                ));
            }
            for (name, p) in [("start", &v.start), ("goal", &v.goal)] {
                if !inside(p) {
                    return Err(bad(
                        format!("vehicles[{i}].{name}"),
                        format!("{p:?}"),
                        "lies outside the bounds",
                    ));
                }
                for o in self
                    .obstacles
                    .iter()
                    .filter(|o| o.kind == ObstacleKind::Hard)
                {
                    let d = (Vec3::from(*p) - o.centre()).norm();
                    if d < o.inflated_radius() {
                        return Err(bad(
                            format!("vehicles[{i}].{name}"),
                            format!("{p:?}"),
                            &format!("lies inside hard obstacle {} (radius plus inflation {:.1} m, distance {d:.1} m)", o.id, o.inflated_radius()),
                        ));
                    }
                }
            }
            // A path planner scores a path against its straight start-goal line (F(L) of seed
            // 004 eq. (9), a crawler's standardisation): with the two on top of each other
            // every score is a division by nothing. Tours and coverage have their own ends.
            let straight = (v.goal() - v.start()).norm();
            if self.inspection.is_none()
                && self.coverage.is_none()
                && straight < MIN_START_GOAL_DISTANCE_M
            {
                return Err(bad(
                    format!("vehicles[{i}].goal"),
                    format!("{:?}", v.goal),
                    &format!(
                        "lies {straight:.3} m from its start; a path needs them at least {MIN_START_GOAL_DISTANCE_M} m apart (a round trip is an [inspection] tour)"
                    ),
                ));
            }
            if !(v.speed_min_mps.is_finite() && v.speed_min_mps > 0.0) {
                return Err(bad(
                    format!("vehicles[{i}].speed_min_mps"),
                    v.speed_min_mps.to_string(),
                    "must be a positive speed in m/s",
                ));
            }
            if !(v.speed_max_mps.is_finite() && v.speed_max_mps >= v.speed_min_mps) {
                return Err(bad(
                    format!("vehicles[{i}].speed_max_mps"),
                    v.speed_max_mps.to_string(),
                    "must be at least speed_min_mps",
                ));
            }
            if !(v.max_turn_deg > 0.0 && v.max_turn_deg <= 180.0) {
                return Err(bad(
                    format!("vehicles[{i}].max_turn_deg"),
                    v.max_turn_deg.to_string(),
                    "must be in (0, 180] degrees",
                ));
            }
            if !(v.max_pitch_deg > 0.0 && v.max_pitch_deg <= 90.0) {
                return Err(bad(
                    format!("vehicles[{i}].max_pitch_deg"),
                    v.max_pitch_deg.to_string(),
                    "must be in (0, 90] degrees",
                ));
            }
            if let Some(r) = v.turn_radius_m {
                if !(r.is_finite() && r > 0.0) {
                    return Err(bad(
                        format!("vehicles[{i}].turn_radius_m"),
                        r.to_string(),
                        "must be a positive number of metres",
                    ));
                }
            }
        }
        if !(self.fleet.d_min_m.is_finite() && self.fleet.d_min_m >= 0.0) {
            return Err(bad(
                "fleet.d_min_m".into(),
                self.fleet.d_min_m.to_string(),
                "must be zero or a positive number of metres",
            ));
        }
        if !(self.fleet.mission_time_s.is_finite() && self.fleet.mission_time_s > 0.0) {
            return Err(bad(
                "fleet.mission_time_s".into(),
                self.fleet.mission_time_s.to_string(),
                "must be a positive number of seconds",
            ));
        }
        self.optimizer.validate(&bad)?;
        self.validate_crawlers(&bad)?;
        self.energy.validate(self.currents.as_ref(), &bad)?;
        let algorithm = self.optimizer.algorithm;
        if let Some(inspection) = &self.inspection {
            inspection.validate(self, &bad)?;
        }
        if let Some(coverage) = &self.coverage {
            coverage.validate(&bad)?;
        }
        if algorithm.is_tour_planner() && self.inspection.is_none() {
            return Err(bad(
                "optimizer.algorithm".into(),
                format!("{:?}", algorithm.as_str()),
                "plans inspection tours (seed 003): add an [inspection] table",
            ));
        }
        if algorithm.is_energy_planner() {
            if self.vehicles.len() != 1 {
                return Err(bad(
                    "optimizer.algorithm".into(),
                    format!("{:?}", algorithm.as_str()),
                    &format!(
                        "plans one AUV (seed 001); this scenario has {} vehicles",
                        self.vehicles.len()
                    ),
                ));
            }
            if self.vehicles[0].kind != VehicleKind::Auv {
                return Err(bad(
                    "vehicles[0].kind".into(),
                    format!("{:?}", self.vehicles[0].kind),
                    &format!("{} plans AUVs, not crawlers", algorithm.as_str()),
                ));
            }
        }
        if self.inspection.is_some() && !algorithm.is_tour_planner() {
            // Every vehicle of an inspection scenario returns to its base: any other planner
            // would plan it a path of zero length and call it feasible.
            return Err(bad(
                "optimizer.algorithm".into(),
                format!("{:?}", algorithm.as_str()),
                "plans paths from a start to a goal, but this scenario has an [inspection] table: plan its tours with de-pso, ldiw-pso or lcpso",
            ));
        }
        Ok(())
    }

    /// The crawler parts: hazards, crawler settings, and a seabed for every crawler.
    fn validate_crawlers(
        &self,
        bad: &dyn Fn(String, String, &str) -> ScenarioError,
    ) -> Result<(), ScenarioError> {
        for (i, h) in self.hazards.iter().enumerate() {
            if crate::wire::topics::check_id("hazard", &h.id).is_err() {
                return Err(bad(
                    format!("hazards[{i}].id"),
                    format!("{:?}", h.id),
                    "must be 1-64 letters, digits, '-', '_' or '.'",
                ));
            }
            if !h.centre.iter().all(|c| c.is_finite()) {
                return Err(bad(
                    format!("hazards[{i}].centre"),
                    format!("{:?}", h.centre),
                    "must be finite",
                ));
            }
            for (name, v) in [("radius_m", h.radius_m), ("height_m", h.height_m)] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(
                        format!("hazards[{i}].{name}"),
                        v.to_string(),
                        "must be a positive number of metres",
                    ));
                }
            }
        }
        self.crawler.validate(bad)?;
        for (i, v) in self.vehicles.iter().enumerate() {
            if v.kind != VehicleKind::Crawler {
                continue;
            }
            if self.seabed.is_none() && self.coverage.is_none() {
                return Err(bad(
                    format!("vehicles[{i}].kind"),
                    "\"crawler\"".into(),
                    "a crawler drives on the seabed: add a [seabed] table (relief or grid) or a [coverage] table",
                ));
            }
            for (name, p) in [("start", &v.start), ("goal", &v.goal)] {
                for h in &self.hazards {
                    let d = (p[0] - h.centre[0]).hypot(p[1] - h.centre[1]);
                    if d < h.radius_m {
                        return Err(bad(
                            format!("vehicles[{i}].{name}"),
                            format!("{p:?}"),
                            &format!(
                                "lies inside hazard {} (radius {:.1} m, distance {d:.1} m)",
                                h.id, h.radius_m
                            ),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The seabed the scenario was loaded with, if any.
    pub fn terrain(&self) -> Option<&crate::terrain::Terrain> {
        self.seabed.as_ref().and_then(|s| s.terrain.as_ref())
    }

    /// The crawler cost model of vehicle `i`, or `None` when it is not a crawler (or the
    /// scenario was built without loading, so it has no terrain). Its control points are the
    /// vehicle's M waypoints, its slope limit the vehicle's pitch limit (on the seabed, pitch
    /// is slope), its speed the vehicle's top speed (§5.1: a constant 1 m/s).
    pub fn crawler_model(&self, i: usize) -> Option<CrawlerModel> {
        let v = self.vehicles.get(i)?;
        if v.kind != VehicleKind::Crawler {
            return None;
        }
        let c = &self.crawler;
        Some(CrawlerModel {
            terrain: self.terrain()?.clone(),
            hazards: self.hazards.clone(),
            start: [v.start[0], v.start[1]],
            goal: [v.goal[0], v.goal[1]],
            area: [
                self.bounds.min[0],
                self.bounds.min[1],
                self.bounds.max[0],
                self.bounds.max[1],
            ],
            control_points: self.optimizer.waypoints,
            samples: c.samples,
            sensor_height_m: c.sensor_height_m,
            speed_mps: v.speed_max_mps,
            power_kw: c.power_kw,
            mining_share: c.mining_share,
            safe_distance_m: c.safe_distance_m,
            max_slope_deg: v.max_pitch_deg,
            weights: c.weights,
            penalty_weight: self.optimizer.penalty_weight,
        })
    }

    /// The turning radius vehicle `i` executes with, metres: its own `turn_radius_m`, else for
    /// a seed 001 energy mission the R_AUV its plan was made for (`energy.min_turn_radius_m`:
    /// the plan's climbing turns are that tight, and a wider-turning vehicle cannot fly them),
    /// for a seed 002 coverage crawler the R_min its U-turns and detour arcs were planned with
    /// (`coverage.planner.min_turn_radius_m`), else `None` (the simulator's default).
    pub fn execution_turn_radius_m(&self, i: usize) -> Option<f64> {
        let v = self.vehicles.get(i)?;
        v.turn_radius_m
            .or_else(|| self.coverage.as_ref().map(|c| c.planner.min_turn_radius_m))
            .or_else(|| {
                self.optimizer
                    .algorithm
                    .is_energy_planner()
                    .then_some(self.energy.min_turn_radius_m)
            })
    }

    /// The seabed a swimming vehicle must keep off, with the height it keeps above it: an
    /// energy mission's `energy.terrain_clearance_m` (seed 001), else `seabed.auv_clearance_m`;
    /// `None` without a seabed.
    pub fn swimmer_seabed(&self) -> Option<(&crate::terrain::Terrain, f64)> {
        let terrain = self.seabed.as_ref()?.terrain.as_ref()?;
        Some((terrain, self.swimmer_clearance()?.0))
    }

    /// A swimmer's seabed clearance, metres, and the setting that gives it (for messages);
    /// `None` without a seabed.
    pub fn swimmer_clearance(&self) -> Option<(f64, &'static str)> {
        let seabed = self.seabed.as_ref()?;
        Some(if self.optimizer.algorithm.is_energy_planner() {
            (
                self.energy.terrain_clearance_m,
                "energy.terrain_clearance_m",
            )
        } else {
            (seabed.auv_clearance_m, "seabed.auv_clearance_m")
        })
    }

    /// Hard obstacles only.
    pub fn hard_obstacles(&self) -> impl Iterator<Item = &Obstacle> {
        self.obstacles
            .iter()
            .filter(|o| o.kind == ObstacleKind::Hard)
    }

    /// Soft obstacles only.
    pub fn soft_obstacles(&self) -> impl Iterator<Item = &Obstacle> {
        self.obstacles
            .iter()
            .filter(|o| o.kind == ObstacleKind::Soft)
    }
}

#[cfg(test)]
mod tests;
