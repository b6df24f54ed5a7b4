//! The scenario and plan sections the checker reads (`[seabed]`, `[crawler]`, `[energy]`,
//! `[currents]`, `[inspection]`, `hazards`, and a plan vehicle's `crawler`, `energy` and `tour`
//! blocks) as plain data: the checker's `model` is made of them, and the checks (`crawler`,
//! `mobility`) read them, so they sit below both.

use serde::Deserialize;

use crate::seabed_grid::{Grid, GridRef};

/// `[seabed]` as far as the checker reads it.
#[derive(Debug, Clone, Deserialize)]
pub struct Seabed {
    /// Eq. (2) constants (analytic model).
    pub relief: Option<Relief>,
    /// Eq. (3) mountains.
    #[serde(default)]
    pub mountains: Vec<Mountain>,
    /// A measured grid: where its file is.
    #[serde(default)]
    pub grid: Option<GridRef>,
    /// The grid's heights, once read relative to the scenario file ([`Seabed::load_grid`]).
    #[serde(skip)]
    pub measured: Option<Grid>,
    /// Height an AUV of a fleet mission keeps above the seabed, metres (default 2).
    #[serde(default)]
    pub auv_clearance_m: Option<f64>,
}

/// Eq. (2).
#[derive(Debug, Clone, Deserialize)]
pub struct Relief {
    pub(crate) a: f64,
    pub(crate) b: f64,
    pub(crate) c: f64,
    pub(crate) d: f64,
    pub(crate) e: f64,
    pub(crate) f: f64,
    pub(crate) g: f64,
    #[serde(default = "one")]
    pub(crate) length_scale_m: f64,
    #[serde(default = "one")]
    pub(crate) height_scale_m: f64,
}

pub(crate) fn one() -> f64 {
    1.0
}

/// Eq. (3), one term.
#[derive(Debug, Clone, Deserialize)]
pub struct Mountain {
    pub(crate) centre: [f64; 2],
    pub(crate) height_m: f64,
    pub(crate) spread_m: [f64; 2],
}

impl Seabed {
    /// Reads the measured grid, if there is one, relative to `dir` (the scenario's directory).
    pub fn load_grid(&mut self, dir: &std::path::Path) -> Result<(), String> {
        if let Some(g) = &self.grid {
            self.measured = Some(Grid::load(g, dir)?);
        }
        Ok(())
    }

    /// The sum of the Gaussian hills alone (Zhang et al. 2022, eq. (1), a seabed without `relief`).
    pub fn hills_elevation(&self, x: f64, y: f64) -> f64 {
        self.mountains
            .iter()
            .map(|m| {
                let u = (x - m.centre[0]) / m.spread_m[0];
                let v = (y - m.centre[1]) / m.spread_m[1];
                m.height_m * (-(u * u) - v * v).exp()
            })
            .sum()
    }
}

/// Eq. (4).
#[derive(Debug, Clone, Deserialize)]
pub struct Hazard {
    /// Name.
    pub id: String,
    /// Centre (x, y), metres.
    pub centre: [f64; 2],
    /// Radius, metres.
    pub radius_m: f64,
}

/// `[crawler]` as far as the checker reads it (defaults: Lu et al. 2023, §5.1).
#[derive(Debug, Clone, Deserialize)]
#[serde(default)]
pub struct CrawlerSettings {
    pub(crate) sensor_height_m: f64,
    pub(crate) power_kw: [f64; 3],
    pub(crate) mining_share: f64,
    pub(crate) safe_distance_m: [f64; 2],
}

impl Default for CrawlerSettings {
    fn default() -> Self {
        CrawlerSettings {
            sensor_height_m: 0.5,
            power_kw: [90.0, 50.0, 5.0],
            mining_share: 0.6,
            safe_distance_m: [2.0, 10.0],
        }
    }
}

/// The crawler block of a `plan.json` vehicle.
#[derive(Debug, Clone, Deserialize)]
pub struct PlanCrawler {
    pub(crate) length_m: f64,
    pub(crate) undulation_m: f64,
    pub(crate) energy_kwh: f64,
    pub(crate) slip_cost: f64,
    pub(crate) min_hazard_clearance_m: Option<f64>,
    pub(crate) hazard_intrusions: usize,
    pub(crate) max_slope_deg: f64,
}

impl Relief {
    /// Eq. (2) at (x, y), before the lift that puts its lowest point at 0.
    pub(crate) fn raw(&self, x: f64, y: f64) -> f64 {
        let (x, y) = (x / self.length_scale_m, y / self.length_scale_m);
        let r = (x * x + y * y).sqrt();
        self.height_scale_m
            * ((y + self.a).sin()
                + self.b * x.sin()
                + self.c * (self.d * r).cos()
                + self.e * y.cos()
                + self.f * (self.g * r).sin())
    }
}

/// `[energy]` as far as the checker reads it.
#[derive(Debug, Clone, Deserialize)]
pub struct EnergySection {
    /// R_AUV, metres.
    #[serde(default = "eight")]
    pub min_turn_radius_m: f64,
    /// Height kept above the seabed, metres.
    #[serde(default = "two")]
    pub terrain_clearance_m: f64,
}

pub(crate) fn eight() -> f64 {
    8.0
}
pub(crate) fn two() -> f64 {
    2.0
}
pub(crate) fn five() -> f64 {
    5.0
}

/// `[currents]` as far as the checker reads it: Zhang et al.'s depth-decay model (eq. (2)); a
/// gridded field (`model = "grid"`, a file) is not recomputed.
#[derive(Debug, Clone, Deserialize)]
pub struct CurrentsSection {
    /// `depth-decay` (the default) or `grid`.
    #[serde(default)]
    pub model: Option<String>,
    /// `(u, v)` at the surface, m/s.
    #[serde(default)]
    pub surface_velocity_mps: Option<[f64; 2]>,
}

/// `[inspection]` as far as the checker reads it.
#[derive(Debug, Clone, Deserialize)]
pub struct InspectionSection {
    /// Cage ids; empty: every hard obstacle.
    #[serde(default)]
    pub cages: Vec<String>,
    /// Monitoring radius minus cage radius, metres.
    #[serde(default = "five")]
    pub standoff_m: f64,
}

/// `vehicles[].energy` of `plan.json`.
#[derive(Debug, Clone, Deserialize)]
pub struct PlanEnergy {
    /// Reported length.
    pub q_path: f64,
    /// Reported turning-radius cost, m².
    pub q_r: f64,
    /// Reported pitch cost, deg².
    pub q_a: f64,
    /// Reported tightest turn.
    pub min_turn_radius_m: f64,
    /// Reported fastest speed through the water, m/s.
    #[serde(default)]
    pub max_water_speed_mps: Option<f64>,
}

/// `vehicles[].tour` of `plan.json`.
#[derive(Debug, Clone, Deserialize)]
pub struct PlanTour {
    /// Point labels in visiting order.
    pub order: Vec<String>,
    /// Their positions.
    pub points: Vec<[f64; 3]>,
    /// Reported tour length.
    pub tour_length_m: f64,
}
