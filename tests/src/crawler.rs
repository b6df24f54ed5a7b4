//! The checker's own view of crawlers (Lu et al. 2023): a crawler's trajectory must lie on the seabed
//! (analytic terrain: eq. (2) in scaled coordinates lifted so its lowest point in the bounds is
//! 0, plus the Gaussian mountains of eq. (3), plus the sensor height) and stay out of every
//! hazard cylinder (eq. (4)); its reported figures are recomputed here from the samples:
//! length (eq. (5)), undulation Σ|Δz| (eq. (6)), energy (eq. (7) at the vehicle's top speed,
//! with the mining share), slip (eq. (9), decreasing ramp), hazard clearance and steepest leg.
//! A measured (grid) seabed is read by the checker's own [`crate::seabed_grid`] when the scenario
//! was read from its file ([`crate::parse_scenario_file`]); from text alone it is not judged.

use crate::model::{Scenario, Vehicle};
use crate::seabed_grid::Grid;
use crate::sections::{PlanCrawler, Relief, Seabed};

/// Seabed elevation of the analytic model, or `None` for a measured seabed.
pub struct Seafloor<'a> {
    seabed: &'a Seabed,
    relief: &'a Relief,
    lift: f64,
}

impl<'a> Seafloor<'a> {
    /// The analytic seabed of `scenario`, with the lowest point of eq. (2) in the bounds at 0
    /// (sampled every 0.5 m, at most 1000 steps per axis, like the planner's definition).
    pub fn of(scenario: &'a Scenario) -> Option<Seafloor<'a>> {
        let seabed = scenario.seabed.as_ref()?;
        let relief = seabed.relief.as_ref()?;
        let (lo, hi) = (scenario.bounds.min, scenario.bounds.max);
        let steps = |span: f64| ((span / 0.5).ceil() as usize).clamp(1, 1000);
        let (nx, ny) = (steps(hi[0] - lo[0]), steps(hi[1] - lo[1]));
        let mut low = f64::INFINITY;
        for i in 0..=nx {
            for j in 0..=ny {
                let x = lo[0] + (hi[0] - lo[0]) * i as f64 / nx as f64;
                let y = lo[1] + (hi[1] - lo[1]) * j as f64 / ny as f64;
                low = low.min(relief.raw(x, y));
            }
        }
        Some(Seafloor {
            seabed,
            relief,
            lift: -low,
        })
    }

    /// z of the seabed at (x, y).
    pub fn z(&self, x: f64, y: f64) -> f64 {
        let mountains: f64 = self
            .seabed
            .mountains
            .iter()
            .map(|m| {
                let u = (x - m.centre[0]) / m.spread_m[0];
                let v = (y - m.centre[1]) / m.spread_m[1];
                m.height_m * (-(u * u) - v * v).exp()
            })
            .sum();
        self.relief.raw(x, y) + self.lift + mountains
    }
}

/// The seabed's height wherever the checker can tell it.
pub enum Floor<'a> {
    /// Eq. (2) + (3).
    Analytic(Seafloor<'a>),
    /// Zhang et al.'s hills on a flat floor (no relief).
    Hills(&'a Seabed),
    /// A measured grid, read from its file.
    Measured(&'a Grid),
}

impl<'a> Floor<'a> {
    /// The seabed of `scenario`; `None` without one, or for a grid that was not read (the
    /// scenario was parsed from text, not from its file).
    pub fn of(scenario: &'a Scenario) -> Option<Floor<'a>> {
        let seabed = scenario.seabed.as_ref()?;
        if seabed.grid.is_some() {
            return seabed.measured.as_ref().map(Floor::Measured);
        }
        Some(match Seafloor::of(scenario) {
            Some(f) => Floor::Analytic(f),
            None => Floor::Hills(seabed),
        })
    }

    /// z of the seabed at (x, y).
    pub fn z(&self, x: f64, y: f64) -> f64 {
        match self {
            Floor::Analytic(f) => f.z(x, y),
            Floor::Hills(s) => s.hills_elevation(x, y),
            Floor::Measured(g) => g.z(x, y),
        }
    }
}

/// Checks an AUV's trajectory against the seabed: its lowest height above it, every 0.5 m
/// along each leg (the seabed is not straight under a straight leg), must be at least
/// `required` (minus 5 cm: the planner samples every 1 m), and must match the reported
/// `min_seabed_clearance_m` to 5 cm. Any [`Floor`]; a grid that was not read is not judged.
pub fn check_swimmer_seabed(
    scenario: &Scenario,
    id: &str,
    traj: &[[f64; 4]],
    required: f64,
    reported: Option<f64>,
) -> CrawlerFindings {
    const STEP: f64 = 0.5;
    const SLACK: f64 = 0.05;
    let mut out = CrawlerFindings::default();
    let Some(floor) = Floor::of(scenario) else {
        return out;
    };
    let z = |x: f64, y: f64| floor.z(x, y);
    let mut lowest = traj.first().map_or(f64::INFINITY, |s| s[3] - z(s[1], s[2]));
    for w in traj.windows(2) {
        let d = [w[1][1] - w[0][1], w[1][2] - w[0][2], w[1][3] - w[0][3]];
        let n = ((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / STEP)
            .ceil()
            .max(1.0) as usize;
        for k in 1..=n {
            let u = k as f64 / n as f64;
            let p = [w[0][1] + u * d[0], w[0][2] + u * d[1], w[0][3] + u * d[2]];
            lowest = lowest.min(p[2] - z(p[0], p[1]));
        }
    }
    if traj.is_empty() {
        return out;
    }
    if lowest < required - SLACK {
        out.broken.push(format!(
            "{id} is {lowest:.3} m above the seabed at its lowest; it must keep {required} m"
        ));
    }
    match reported {
        Some(r) if (r - lowest).abs() <= SLACK => {}
        r => out.mismatches.push(format!(
            "{id}.min_seabed_clearance_m: reported {r:?} but recomputed {lowest:.3}"
        )),
    }
    out
}

/// Horizontal distance from segment a→b to point c.
fn segment_distance_2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((c[0] - a[0]) * dx + (c[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a[0] + t * dx - c[0]).hypot(a[1] + t * dy - c[1])
}

/// What the crawler checks found for one vehicle.
#[derive(Debug, Default)]
pub struct CrawlerFindings {
    /// Reported figures that disagree with the recomputation.
    pub mismatches: Vec<String>,
    /// Broken crawler constraints (hazard entered, path off the seabed).
    pub broken: Vec<String>,
}

/// Checks crawler `v`'s trajectory and its reported `crawler` block.
pub fn check(
    scenario: &Scenario,
    v: &Vehicle,
    traj: &[[f64; 4]],
    reported: Option<&PlanCrawler>,
) -> CrawlerFindings {
    let mut out = CrawlerFindings::default();
    let id = &v.id;
    let settings = scenario.crawler.clone().unwrap_or_default();
    let xy = |s: &[f64; 4]| [s[1], s[2]];
    let length: f64 = traj
        .windows(2)
        .map(|w| {
            let d = [w[1][1] - w[0][1], w[1][2] - w[0][2], w[1][3] - w[0][3]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .sum();
    let undulation: f64 = traj.windows(2).map(|w| (w[1][3] - w[0][3]).abs()).sum();
    let steepest = traj
        .windows(2)
        .map(|w| {
            let h = (w[1][1] - w[0][1]).hypot(w[1][2] - w[0][2]);
            (w[1][3] - w[0][3]).abs().atan2(h).to_degrees()
        })
        .fold(0.0, f64::max);
    let hours = length / v.speed_max_mps / 3600.0;
    let mining = hours * settings.mining_share / (1.0 - settings.mining_share);
    let [p1, p2, p3] = settings.power_kw;
    let energy = mining * p1 + hours * p2 + (mining + hours) * p3;
    let [lo, hi] = settings.safe_distance_m;
    let (mut slip, mut clearance, mut intrusions) = (0.0, None::<f64>, 0);
    for h in &scenario.hazards {
        let d = traj
            .windows(2)
            .map(|w| segment_distance_2d(xy(&w[0]), xy(&w[1]), h.centre))
            .fold(f64::INFINITY, f64::min)
            - h.radius_m;
        clearance = Some(clearance.map_or(d, |c| c.min(d)));
        slip += if d < lo {
            1.0
        } else if d >= hi {
            0.0
        } else {
            (hi - d) / (hi - lo)
        };
        if d < 0.0 {
            intrusions += 1;
            out.broken.push(format!(
                "{id} enters hazard {} ({d:.3} m inside its edge)",
                h.id
            ));
        }
    }
    if let Some(floor) = Floor::of(scenario) {
        let off = traj
            .iter()
            .map(|s| (s[3] - floor.z(s[1], s[2]) - settings.sensor_height_m).abs())
            .fold(0.0, f64::max);
        if off > 1e-6 {
            out.broken.push(format!(
                "{id} is a crawler but leaves the seabed by {off:.4} m"
            ));
        }
    }
    let Some(r) = reported else {
        out.mismatches.push(format!(
            "{id} is a crawler but plan.json has no crawler figures"
        ));
        return out;
    };
    let mut num = |what: &str, reported: f64, recomputed: f64| {
        if !crate::tolerance::close(reported, recomputed, crate::tolerance::TOL) {
            out.mismatches.push(format!(
                "{id}.crawler.{what}: reported {reported} but recomputed {recomputed}"
            ));
        }
    };
    num("length_m", r.length_m, length);
    num("undulation_m", r.undulation_m, undulation);
    num("energy_kwh", r.energy_kwh, energy);
    num("slip_cost", r.slip_cost, slip);
    num("max_slope_deg", r.max_slope_deg, steepest);
    match (r.min_hazard_clearance_m, clearance) {
        (Some(a), Some(b)) => num("min_hazard_clearance_m", a, b),
        (None, None) => {}
        (a, b) => out.mismatches.push(format!(
            "{id}.crawler.min_hazard_clearance_m: reported {a:?} but recomputed {b:?}"
        )),
    }
    if r.hazard_intrusions != intrusions {
        out.mismatches.push(format!(
            "{id}.crawler.hazard_intrusions: reported {} but recomputed {intrusions}",
            r.hazard_intrusions
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_by_hand() {
        assert!((segment_distance_2d([0.0, 0.0], [10.0, 0.0], [5.0, 3.0]) - 3.0).abs() < 1e-12);
        assert!((segment_distance_2d([0.0, 0.0], [10.0, 0.0], [13.0, 4.0]) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn relief_by_hand() {
        // At the origin with a = π/2: height · (1 + c + e).
        let r = Relief {
            a: std::f64::consts::FRAC_PI_2,
            b: 0.3,
            c: 0.5,
            d: 1.0,
            e: 0.25,
            f: 0.7,
            g: 2.0,
            length_scale_m: 10.0,
            height_scale_m: 2.0,
        };
        assert!((r.raw(0.0, 0.0) - 2.0 * 1.75).abs() < 1e-12);
    }

    /// A 100 m hill (σ = 100 m, hills only) under the middle of a 1000 m leg: at z = 50 the
    /// leg is 50 m into it (broken, required 2 m); at z = 102.5 it keeps 2.5 m; a reported
    /// figure 1 m off is a mismatch; a measured grid is not judged.
    #[test]
    fn an_auv_is_checked_against_the_seabed_between_its_samples() -> Result<(), String> {
        let text = |extra: &str| {
            format!(
                "name = \"s\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [1000.0, 1000.0, 500.0]\n\
                 [[vehicles]]\nid = \"a\"\nkind = \"auv\"\nstart = [0.0, 500.0, 50.0]\n\
                 goal = [1000.0, 500.0, 50.0]\nspeed_min_mps = 0.5\nspeed_max_mps = 1.5\n\
                 max_turn_deg = 35.0\nmax_pitch_deg = 20.0\n[fleet]\nd_min_m = 50.0\n\
                 mission_time_s = 1000.0\n{extra}"
            )
        };
        let hill = "[[seabed.mountains]]\ncentre = [500.0, 500.0]\nheight_m = 100.0\nspread_m = [100.0, 100.0]\n";
        let s = crate::model::parse_scenario(&text(hill))?;
        let leg = |z: f64| [[0.0, 0.0, 500.0, z], [1000.0, 1000.0, 500.0, z]];
        let low = check_swimmer_seabed(&s, "a", &leg(50.0), 2.0, Some(-50.0));
        assert_eq!(low.broken.len(), 1, "{:?}", low.broken);
        assert!(
            low.broken[0].contains("-50.000 m above the seabed"),
            "{:?}",
            low.broken
        );
        assert!(low.mismatches.is_empty(), "{:?}", low.mismatches);
        let high = check_swimmer_seabed(&s, "a", &leg(102.5), 2.0, Some(2.5));
        assert!(high.broken.is_empty() && high.mismatches.is_empty());
        let off = check_swimmer_seabed(&s, "a", &leg(102.5), 2.0, Some(3.5));
        assert_eq!(off.mismatches.len(), 1, "{:?}", off.mismatches);
        let unreported = check_swimmer_seabed(&s, "a", &leg(102.5), 2.0, None);
        assert_eq!(unreported.mismatches.len(), 1);
        // A grid seabed parsed from text alone (its file never read) is not judged.
        let grid = crate::model::parse_scenario(&text("[seabed.grid]\nfile = \"x.asc\"\n"))?;
        let g = check_swimmer_seabed(&grid, "a", &leg(50.0), 2.0, None);
        assert!(g.broken.is_empty() && g.mismatches.is_empty());

        // The same 100 m rise as a measured grid read from the scenario's directory: nodes
        // 500 m apart, 100 m in the middle, so along y = 500 the seabed is a tent peaking at
        // x = 500 and the leg at z = 50 is 50 m into it.
        let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
        let asc = "ncols 3\nnrows 3\nxllcenter 0\nyllcenter 0\ncellsize 500\n\
                   0 0 0\n0 100 0\n0 0 0\n";
        std::fs::write(dir.path().join("rise.asc"), asc).map_err(|e| e.to_string())?;
        let path = dir.path().join("s.toml");
        let grid_toml = text("[seabed.grid]\nfile = \"rise.asc\"\n");
        std::fs::write(&path, grid_toml).map_err(|e| e.to_string())?;
        let s = crate::model::parse_scenario_file(&path)?;
        let low = check_swimmer_seabed(&s, "a", &leg(50.0), 2.0, Some(-50.0));
        assert_eq!(low.broken.len(), 1, "{:?}", low.broken);
        assert!(low.mismatches.is_empty(), "{:?}", low.mismatches);
        let high = check_swimmer_seabed(&s, "a", &leg(102.5), 2.0, Some(2.5));
        assert!(high.broken.is_empty() && high.mismatches.is_empty());
        // A grid file that is not there is an error naming it.
        std::fs::remove_file(dir.path().join("rise.asc")).map_err(|e| e.to_string())?;
        let missing = crate::model::parse_scenario_file(&path);
        assert!(
            missing.as_ref().is_err_and(|e| e.contains("rise.asc")),
            "{missing:?}"
        );
        Ok(())
    }
}
