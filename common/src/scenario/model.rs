//! The scenario model: the mission, its bounds, obstacles, vehicles and fleet, and how a file
//! becomes one (read, parse, validate, resolve the data files it names).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::coverage::CoverageSettings;
use super::error::{check_data_file, invalid_in, ScenarioError};
use super::inspection::InspectionSettings;
use super::ocean::{Currents, EnergySettings};
use super::optimizer::OptimizerSettings;
use super::seabed::{CrawlerSettings, Seabed};
use crate::crawler::CrawlerModel;
use crate::geometry::Vec3;
use crate::terrain::Hazard;

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
    /// Where the scenario is on the Earth: the WGS-84 position of its point (0, 0, 0), whose
    /// `alt_m` is the altitude above mean sea level of z = 0. Absent: the scenario is only in
    /// local metres (plans still work; map exports and MAVLink vehicles need an origin).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<crate::geo::GeoOrigin>,
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
    /// The seabed crawlers drive on (Lu et al. 2023, §2.2); required when a vehicle is a crawler.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seabed: Option<Seabed>,
    /// Soft-substrate zones crawlers must not enter, vertical cylinders (Lu et al. 2023, eq. (4)).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub hazards: Vec<Hazard>,
    /// Settings of the crawler cost (Lu et al. 2023, eq. (5)–(11)).
    #[serde(default)]
    pub crawler: CrawlerSettings,
    /// The ocean current (Zhang et al. 2022, eq. (2)); absent: still water.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub currents: Option<Currents>,
    /// Settings of the energy-saving planner (Zhang et al. 2022, Table 2).
    #[serde(default)]
    pub energy: EnergySettings,
    /// Cage-inspection tours (Hu et al. 2023); required by the tour planners.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inspection: Option<InspectionSettings>,
    /// Area coverage by a mining crawler (CPP-DSMV); its presence makes `plan` cover an area.
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

/// How an obstacle affects a vehicle (Zhi & Zuo 2024, §2.1).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum ObstacleKind {
    /// Must never be entered (radius plus inflation): a plan touching one is infeasible.
    Hard,
    /// May be crossed at a cost (seston, particulates): the threat term F(O).
    Soft,
}

/// A sphere with a safety inflation margin (Zhi & Zuo 2024, Fig. 1).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, schemars::JsonSchema)]
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
    /// Safety margin added to the radius, metres (Zhi & Zuo 2024, Table 4: d_hard = d_soft = 50 m).
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
    /// Largest heading change at a waypoint, degrees (Zhi & Zuo 2024: 35°).
    pub max_turn_deg: f64,
    /// Largest |pitch| of a leg, degrees (Zhi & Zuo 2024: 20°).
    pub max_pitch_deg: f64,
    /// Turning radius when executing, metres (the simulated vehicle's). Absent: Zhang et al.'s
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

/// Fleet coupling (Zhi & Zuo 2024, §2.2.2).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Fleet {
    /// Minimum distance between any two vehicles at every instant, metres (eq. (1)).
    pub d_min_m: f64,
    /// Time at which every vehicle should reach its goal, seconds after the start (t_e).
    pub mission_time_s: f64,
}

impl Scenario {
    /// Reads, parses and validates a scenario file. At most
    /// [`crate::limits::MAX_SCENARIO_BYTES`] are read: a larger file (or `/dev/zero`) is refused
    /// before it fills the memory.
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let io = |error| ScenarioError::Io {
            file: path.to_path_buf(),
            error,
        };
        let text =
            crate::limits::read_at_most(path, crate::limits::MAX_SCENARIO_BYTES).map_err(io)?;
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
        let bad = invalid_in(file);
        if let Some(seabed) = &mut scenario.seabed {
            let dir = file.parent().unwrap_or(Path::new("."));
            let b = &scenario.bounds;
            let area = [b.min[0], b.min[1], b.max[0], b.max[1]];
            seabed.resolve(area, dir, file, &bad)?;
        }
        if let Some(currents) = &mut scenario.currents {
            currents.resolve(file.parent().unwrap_or(Path::new(".")), file, &bad)?;
        }
        if let Some(heightmap) = scenario
            .coverage
            .as_ref()
            .and_then(|c| c.heightmap.as_ref())
        {
            // Read when the map is built; a file that is there now must be one to read.
            let path = file.parent().unwrap_or(Path::new(".")).join(heightmap);
            if path.exists() {
                check_data_file(&path, "coverage.heightmap", &bad)?;
            }
        }
        Ok(scenario)
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
    /// a Zhang et al. 2022 energy mission the R_AUV its plan was made for (`energy.min_turn_radius_m`:
    /// the plan's climbing turns are that tight, and a wider-turning vehicle cannot fly them),
    /// for a CPP-DSMV coverage crawler the R_min its U-turns and detour arcs were planned with
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
    /// energy mission's `energy.terrain_clearance_m` (Zhang et al. 2022), else `seabed.auv_clearance_m`;
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
