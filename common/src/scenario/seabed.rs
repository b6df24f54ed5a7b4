//! The `[seabed]`, `[[hazards]]` and `[crawler]` tables of a scenario: the terrain crawlers drive
//! on (Lu et al. 2023, eq. (1)–(4)) and the settings of their cost (eq. (5)–(11), §5.1).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::error::over;
use super::error::{Bad, ScenarioError};
use crate::limits;
use crate::terrain::{BaseRelief, HeightGrid, Mountain, Terrain};

/// The seabed: the analytic model of eq. (2) + (3), or a measured height grid from a file.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Seabed {
    /// Base relief of eq. (2) (analytic model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relief: Option<BaseRelief>,
    /// Gaussian mountains of eq. (3), added to the base relief (analytic model).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mountains: Vec<Mountain>,
    /// Measured bathymetry instead of the analytic model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<SeabedGrid>,
    /// Height an AUV of a fleet mission keeps above this seabed, metres: a plan that comes
    /// closer is infeasible (an energy mission keeps `energy.terrain_clearance_m` instead).
    #[serde(default = "auv_clearance")]
    pub auv_clearance_m: f64,
    /// The terrain built from the above when the scenario was loaded (grids are read then).
    #[serde(skip)]
    pub terrain: Option<Terrain>,
}

/// `seabed.auv_clearance_m`'s default: 2 m, the altitude a DVL-aided survey AUV holds when it
/// follows the bottom (none of the seeds gives one; Zhang et al.'s energy missions also keep 2 m),
/// and well above the ±1 m position noise of the simulated fixes.
pub const AUV_CLEARANCE_M: f64 = 2.0;

fn auv_clearance() -> f64 {
    AUV_CLEARANCE_M
}

impl Default for Seabed {
    fn default() -> Self {
        Seabed {
            relief: None,
            mountains: Vec::new(),
            grid: None,
            auv_clearance_m: AUV_CLEARANCE_M,
            terrain: None,
        }
    }
}

/// A height-grid file: ESRI ASCII grid (`.asc`, georeferenced by its header) or CSV (`.csv`,
/// one row of heights per line, north row first, placed by `cell_m` and `origin`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SeabedGrid {
    /// Path of the file; a relative path is taken from the scenario file's directory (and is
    /// stored absolute once loaded, so agents on the same file system find it too).
    pub file: PathBuf,
    /// CSV only: node spacing, metres (default 1).
    #[serde(default = "one_metre")]
    pub cell_m: f64,
    /// CSV only: position of the south-west node, metres (default the origin).
    #[serde(default)]
    pub origin: [f64; 2],
}

fn one_metre() -> f64 {
    1.0
}

/// Settings of the crawler cost; defaults are Lu et al. 2023, §2.3.5 and §5.1.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct CrawlerSettings {
    /// Height of the path (the vehicle's sensor frame) above the seabed, metres (§5.1: 0.5–1 m).
    pub sensor_height_m: f64,
    /// Points the smoothed path is sampled at (eq. (12)); every check uses these points.
    pub samples: usize,
    /// P1 (collection), P2 (travel), P3 (control and perception), kW (§5.1: 90, 50, 5).
    pub power_kw: [f64; 3],
    /// Share of the mission time spent mining (§5.1: 0.6).
    pub mining_share: f64,
    /// `d_safe_min`, `d_safe_max` of eq. (9): slip distance ramp from a hazard's edge, metres.
    pub safe_distance_m: [f64; 2],
    /// ω of eq. (10) for length, undulation, slip, energy (§2.3.5: 0.5, 0.2, 0.2, 0.1).
    pub weights: [f64; 4],
}

impl Default for CrawlerSettings {
    fn default() -> Self {
        CrawlerSettings {
            sensor_height_m: 0.5,
            samples: 100,
            power_kw: [90.0, 50.0, 5.0],
            mining_share: 0.6,
            // The paper gives no distances. 2 m is about half a crawler's width (the "Pioneer
            // No. 1" class is ~4 m wide): closer, a track is on the soft ground's edge; from 10 m
            // on the substrate is taken as firm.
            safe_distance_m: [2.0, 10.0],
            weights: [0.5, 0.2, 0.2, 0.1],
        }
    }
}

impl Seabed {
    /// Checks the values and builds the terrain (reading a grid file relative to `dir`).
    /// `area` is the scenario's horizontal box (the analytic relief's lowest point in it is
    /// lifted to z = 0, §2.1).
    pub fn resolve(
        &mut self,
        area: [f64; 4],
        dir: &Path,
        file: &Path,
        bad: Bad,
    ) -> Result<(), ScenarioError> {
        if !(self.auv_clearance_m.is_finite() && self.auv_clearance_m >= 0.0) {
            return Err(bad(
                "seabed.auv_clearance_m".into(),
                self.auv_clearance_m.to_string(),
                "must be a non-negative number of metres",
            ));
        }
        if let Some(r) = &self.relief {
            let coefficients = [r.a, r.b, r.c, r.d, r.e, r.f, r.g];
            for (name, v) in ["a", "b", "c", "d", "e", "f", "g"].iter().zip(coefficients) {
                if !v.is_finite() {
                    return Err(bad(
                        format!("seabed.relief.{name}"),
                        v.to_string(),
                        "must be finite",
                    ));
                }
            }
            for (name, v) in [
                ("length_scale_m", r.length_scale_m),
                ("height_scale_m", r.height_scale_m),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(
                        format!("seabed.relief.{name}"),
                        v.to_string(),
                        "must be a positive number of metres",
                    ));
                }
            }
        }
        for (i, m) in self.mountains.iter().enumerate() {
            if !(m.centre.iter().all(|c| c.is_finite()) && m.height_m.is_finite()) {
                return Err(bad(
                    format!("seabed.mountains[{i}]"),
                    format!("{:?} {}", m.centre, m.height_m),
                    "centre and height must be finite",
                ));
            }
            if !m.spread_m.iter().all(|s| s.is_finite() && *s > 0.0) {
                return Err(bad(
                    format!("seabed.mountains[{i}].spread_m"),
                    format!("{:?}", m.spread_m),
                    "must be positive numbers of metres",
                ));
            }
        }
        self.terrain = Some(match (&mut self.grid, &self.relief) {
            (Some(_), Some(_)) => {
                return Err(bad(
                    "seabed.grid".into(),
                    "(set)".into(),
                    "give either seabed.grid or seabed.relief, not both",
                ))
            }
            (Some(_), None) if !self.mountains.is_empty() => {
                return Err(bad(
                    "seabed.mountains".into(),
                    format!("{} mountains", self.mountains.len()),
                    "mountains belong to the analytic relief, not to a measured grid",
                ))
            }
            (Some(g), None) => {
                if !g.file.is_absolute() {
                    g.file = dir.join(&g.file);
                }
                super::error::check_data_file(&g.file, "seabed.grid.file", bad)?;
                let grid = load_grid(g, file, bad)?;
                let cells = grid.rows.saturating_mul(grid.cols);
                if cells > limits::MAX_MAP_CELLS {
                    let bound = limits::MAX_MAP_CELLS;
                    return Err(over(bad, "seabed.grid.file", cells, bound, "MAX_MAP_CELLS"));
                }
                covers(&grid, area, &g.file, bad)?;
                Terrain::Grid(grid)
            }
            (None, Some(r)) => {
                let mut base = BaseRelief { datum_m: 0.0, ..*r };
                base.datum_m = -base.lowest(area);
                Terrain::Analytic {
                    base,
                    mountains: self.mountains.clone(),
                }
            }
            (None, None) if !self.mountains.is_empty() => Terrain::Hills(self.mountains.clone()),
            (None, None) => {
                return Err(bad(
                    "seabed".into(),
                    "{}".into(),
                    "needs a `relief` table (with optional `mountains`), `mountains` alone (hills on a flat floor, Zhang et al. 2022, eq. (1)) or a `grid` file",
                ))
            }
        });
        Ok(())
    }
}

/// A grid must cover the scenario's horizontal box `[x_min, y_min, x_max, y_max]` (to within half
/// a cell, for grids registered at cell centres): outside it the seabed would be made up from the
/// edge heights, and a path planned over it would be checked against ground nobody measured.
fn covers(
    grid: &HeightGrid,
    area: [f64; 4],
    grid_file: &Path,
    bad: Bad,
) -> Result<(), ScenarioError> {
    let half = 0.5 * grid.cell_m;
    let x = [
        grid.origin[0],
        grid.origin[0] + (grid.cols.saturating_sub(1)) as f64 * grid.cell_m,
    ];
    let y = [
        grid.origin[1],
        grid.origin[1] + (grid.rows.saturating_sub(1)) as f64 * grid.cell_m,
    ];
    if x[0] - half <= area[0]
        && x[1] + half >= area[2]
        && y[0] - half <= area[1]
        && y[1] + half >= area[3]
    {
        return Ok(());
    }
    Err(bad(
        "seabed.grid.file".into(),
        grid_file.display().to_string(),
        &format!(
            "covers x {:.1}..{:.1} m, y {:.1}..{:.1} m, less than the scenario's bounds x {:.1}..{:.1} m, y {:.1}..{:.1} m (outside a grid its edge heights would stand in for ground nobody measured)",
            x[0], x[1], y[0], y[1], area[0], area[2], area[1], area[3]
        ),
    ))
}

/// Reads the grid file, naming the scenario and the grid file in errors.
fn load_grid(g: &SeabedGrid, file: &Path, bad: Bad) -> Result<HeightGrid, ScenarioError> {
    let is_csv = g
        .file
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    let loaded = if is_csv {
        if !(g.cell_m.is_finite() && g.cell_m > 0.0) {
            return Err(bad(
                "seabed.grid.cell_m".into(),
                g.cell_m.to_string(),
                "must be a positive number of metres",
            ));
        }
        std::fs::read_to_string(&g.file)
            .map_err(|error| crate::terrain::TerrainError::Io {
                file: g.file.clone(),
                error,
            })
            .and_then(|text| HeightGrid::from_csv(&text, &g.file, g.cell_m, g.origin))
    } else {
        HeightGrid::load(&g.file)
    };
    loaded.map_err(|e| ScenarioError::Parse {
        file: file.to_path_buf(),
        message: format!("seabed.grid.file: {e}"),
    })
}

impl CrawlerSettings {
    /// Checks every value.
    pub fn validate(&self, bad: Bad) -> Result<(), ScenarioError> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(bad(
                    format!("crawler.{name}"),
                    v.to_string(),
                    "must be zero or positive",
                ))
            }
        };
        positive("sensor_height_m", self.sensor_height_m)?;
        for p in self.power_kw {
            positive("power_kw", p)?;
        }
        for w in self.weights {
            positive("weights", w)?;
        }
        if self.samples < 4 {
            return Err(bad(
                "crawler.samples".into(),
                self.samples.to_string(),
                "must be at least 4",
            ));
        }
        if self.samples > limits::MAX_PATH_SAMPLES {
            let (n, bound) = (self.samples, limits::MAX_PATH_SAMPLES);
            return Err(over(bad, "crawler.samples", n, bound, "MAX_PATH_SAMPLES"));
        }
        if !(self.mining_share >= 0.0 && self.mining_share < 1.0) {
            return Err(bad(
                "crawler.mining_share".into(),
                self.mining_share.to_string(),
                "must be in [0, 1)",
            ));
        }
        let [lo, hi] = self.safe_distance_m;
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && hi > lo) {
            return Err(bad(
                "crawler.safe_distance_m".into(),
                format!("{:?}", self.safe_distance_m),
                "must be [d_safe_min, d_safe_max] with 0 <= d_safe_min < d_safe_max",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
