//! The checker's own minimal view of the input files: serde structs for the scenario TOML and for
//! `plan.json`, and their parsers. Unknown keys are ignored, so only what the checker reads is
//! declared here.

use serde::Deserialize;

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
    /// Seabed for crawlers.
    #[serde(default)]
    pub seabed: Option<crate::sections::Seabed>,
    /// Hazard cylinders crawlers must not enter.
    #[serde(default)]
    pub hazards: Vec<crate::sections::Hazard>,
    /// Crawler cost settings.
    #[serde(default)]
    pub crawler: Option<crate::sections::CrawlerSettings>,
    /// Energy planner settings (Zhang et al. 2022).
    #[serde(default)]
    pub energy: Option<crate::sections::EnergySection>,
    /// Inspection tours (Hu et al. 2023).
    #[serde(default)]
    pub inspection: Option<crate::sections::InspectionSection>,
    /// Ocean current (Zhang et al. 2022).
    #[serde(default)]
    pub currents: Option<crate::sections::CurrentsSection>,
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
    /// `auv` or `crawler`.
    #[serde(default)]
    pub kind: String,
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

impl Vehicle {
    /// True for a seabed crawler.
    pub fn is_crawler(&self) -> bool {
        self.kind == "crawler"
    }

    /// Distance from trajectory sample `s` to `target` (start or goal): horizontal only for a
    /// crawler, whose path lies on the seabed below them.
    pub fn end_distance(&self, s: &[f64; 4], target: &[f64; 3]) -> f64 {
        let (dx, dy, dz) = (s[1] - target[0], s[2] - target[1], s[3] - target[2]);
        if self.is_crawler() {
            dx.hypot(dy)
        } else {
            (dx * dx + dy * dy + dz * dz).sqrt()
        }
    }
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
    /// AUVs over a seabed: reported lowest height above it, metres.
    #[serde(default)]
    pub min_seabed_clearance_m: Option<f64>,
    /// Crawlers: reported seabed figures.
    #[serde(default)]
    pub crawler: Option<crate::sections::PlanCrawler>,
    /// Energy-planned AUVs: reported Zhang et al. 2022 figures.
    #[serde(default)]
    pub energy: Option<crate::sections::PlanEnergy>,
    /// Inspection tours: reported Hu et al. 2023 figures.
    #[serde(default)]
    pub tour: Option<crate::sections::PlanTour>,
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

/// Reads and parses a scenario file, with its measured seabed grid (if any) read relative to
/// the file's directory, so the seabed checks judge it.
pub fn parse_scenario_file(path: &std::path::Path) -> Result<Scenario, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut scenario = parse_scenario(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    if let Some(seabed) = scenario.seabed.as_mut() {
        let dir = path.parent().unwrap_or(std::path::Path::new("."));
        seabed
            .load_grid(dir)
            .map_err(|e| format!("{}: seabed.grid: {e}", path.display()))?;
    }
    Ok(scenario)
}

/// Parses a `plan.json` text.
pub fn parse_plan(text: &str) -> Result<Plan, String> {
    serde_json::from_str(text).map_err(|e| format!("plan.json does not parse: {e}"))
}
