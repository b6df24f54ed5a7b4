//! Coverage missions (CPP-DSMV) from the command line: `plan` on a scenario with a `[coverage]`
//! table, and `bench-coverage`, the paper's Table 2 comparison (arc method vs the Hybrid A*
//! baseline) over seeded maps.

use std::io::Write;
use std::path::Path;
use std::sync::atomic::AtomicBool;

use anyhow::Context;
use serde::Serialize;
use shoal_common::coverage::boxes::Rect;
use shoal_common::coverage::metrics::Distribution;
use shoal_common::coverage::mission::{build_map, run_coverage, CoverageReport};
use shoal_common::coverage::path::CoveragePath;
use shoal_common::coverage::TerrainMap25;
use shoal_common::scenario::{CoverageSettings, Scenario};

use crate::report::svg::coverage::render_coverage;

/// What a planned coverage mission leaves for `run`: whether it passes, and each crawler's
/// exact path and start delay (scenario order) on the map they were planned on.
pub struct PlannedCoverage {
    /// The plan passes ([`passes`]; a fleet's also keeps d_min).
    pub feasible: bool,
    /// Each crawler's path, scenario order.
    pub paths: Vec<CoveragePath>,
    /// Each crawler's start delay, seconds (a fleet's separation timing; 0 alone).
    pub start_delays_s: Vec<f64>,
    /// The seabed map.
    pub map: TerrainMap25,
}

/// `plan.json` of a coverage mission.
#[derive(Debug, Serialize)]
pub struct CoveragePlanFile<'a> {
    /// Scenario name.
    pub scenario: &'a str,
    /// Always `coverage`: tells readers this is not a fleet trajectory plan.
    pub kind: &'static str,
    /// No clearance violation and, when tracked to the end, the vehicle reached it.
    pub feasible: bool,
    /// `Completed`, or `Interrupted` when Ctrl-C cut the tracking simulation short.
    pub termination: CoverageTermination,
    /// Plain-words remarks.
    pub notices: Vec<String>,
    /// The figures.
    pub coverage: &'a CoverageReport,
}

/// How a coverage mission ended (`plan.json`'s `termination`, named as a fleet plan's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum CoverageTermination {
    /// Planned and, when the scenario says so, tracked to the end.
    Completed,
    /// Ctrl-C cut a tracking simulation short; the plan itself is whole.
    Interrupted,
}

impl CoverageTermination {
    /// `Interrupted` when any of `reports` had its tracking cut short.
    pub fn of<'a>(reports: impl IntoIterator<Item = &'a CoverageReport>) -> Self {
        let cut = reports
            .into_iter()
            .any(|r| r.tracking.as_ref().is_some_and(|t| t.interrupted));
        if cut {
            CoverageTermination::Interrupted
        } else {
            CoverageTermination::Completed
        }
    }
}

/// Whether `r` passes: no planned sample closer than the safety clearance and, when tracked to
/// the end, the vehicle reached it (a simulation cut short by Ctrl-C judges nothing).
pub fn passes(r: &CoverageReport) -> bool {
    r.samples_below_clearance == 0
        && r.tracking
            .as_ref()
            .is_none_or(|t| t.reached_end || t.interrupted)
}

/// The area a scenario covers: its bounds' horizontal extent.
pub fn scenario_area(scenario: &Scenario) -> Rect {
    let b = &scenario.bounds;
    Rect::new(b.min[0], b.min[1], b.max[0], b.max[1])
}

/// Runs the mission of `scenario` (which has a `[coverage]` table) into `out`; returns the plan.
/// A raised `stop` (Ctrl-C) cuts the tracking simulation short; the plan is still written,
/// marked `Interrupted`.
pub fn plan_coverage_command(
    scenario_file: &Path,
    scenario: &Scenario,
    settings: &CoverageSettings,
    out: &Path,
    quiet: bool,
    stop: &AtomicBool,
) -> anyhow::Result<PlannedCoverage> {
    let seed = settings.terrain_seed.unwrap_or(scenario.optimizer.seed);
    let dir = scenario_file.parent().unwrap_or(Path::new("."));
    let map = build_map(settings, seed, dir)
        .with_context(|| format!("{}: [coverage] map", scenario_file.display()))?;
    let mut last = -1.0;
    let mut progress = |stage: &str, f: f64| {
        if !quiet && (f - last >= 0.1 || f == 0.0 || f >= 1.0) {
            eprintln!("coverage: {stage} {:.0} %", 100.0 * f);
            last = if f >= 1.0 { -1.0 } else { f };
        }
    };
    let terrain_seed = settings.heightmap.is_none().then_some(seed);
    let (report, plan) = run_coverage(
        settings,
        &map,
        scenario_area(scenario),
        terrain_seed,
        scenario.optimizer.seed,
        Some(stop),
        &mut progress,
    )
    .with_context(|| format!("{}: coverage mission", scenario_file.display()))?;
    let notices = notices(&report);
    let feasible = passes(&report);
    let file = CoveragePlanFile {
        scenario: &scenario.name,
        kind: "coverage",
        feasible,
        termination: CoverageTermination::of([&report]),
        notices: notices.clone(),
        coverage: &report,
    };
    let svg = render_coverage(&report, &map)?;
    write_outputs(out, &file, &svg, summary(&scenario.name, &report), &notices)?;
    Ok(PlannedCoverage {
        feasible,
        paths: vec![plan.path],
        start_delays_s: vec![0.0],
        map,
    })
}

/// Writes `plan.json` (from `file`) and `plan.svg` into `out`, then prints `summary`, the
/// notices and where the files are.
pub fn write_outputs(
    out: &Path,
    file: &impl Serialize,
    svg: &str,
    summary: String,
    notices: &[String],
) -> anyhow::Result<()> {
    let json = serde_json::to_string_pretty(file).context("cannot serialise the plan")?;
    let path = out.join("plan.json");
    std::fs::write(&path, json).with_context(|| format!("cannot write {}", path.display()))?;
    let path = out.join("plan.svg");
    std::fs::write(&path, svg).with_context(|| format!("cannot write {}", path.display()))?;
    let mut text = summary;
    for n in notices {
        text.push_str(&format!("notice: {n}\n"));
    }
    text.push_str(&format!(
        "Wrote {} and {}\n",
        out.join("plan.json").display(),
        out.join("plan.svg").display()
    ));
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
    Ok(())
}

/// What a reader should know that the numbers alone do not say.
pub fn notices(r: &CoverageReport) -> Vec<String> {
    let mut out = Vec::new();
    if r.planned_path.is_empty() {
        out.push(format!(
            "no path was planned: no row of the area has a stretch the crawler can enter and drive {} m from impassable ground; nothing of it is covered",
            r.safety_clearance_m
        ));
    }
    if r.samples_below_clearance > 0 {
        out.push(format!(
            "{} path samples are closer than {} m to impassable terrain (minimum {:.2} m)",
            r.samples_below_clearance, r.safety_clearance_m, r.clearance.min
        ));
    }
    let [_, _, _, transits, unreached, stranded] = r.event_counts;
    if transits > 0 {
        out.push(format!(
            "{transits} transits ({:.0} m) join sweeps the Boustrophedon could not chain",
            r.length_by_kind_m[3]
        ));
    }
    if unreached + stranded > 0 {
        out.push(format!(
            "{unreached} row stretches were not reached and {stranded} sweeps ended in a dead end; that area is left uncovered"
        ));
    }
    if let Some(t) = &r.tracking {
        if t.interrupted {
            out.push(format!(
                "tracking was interrupted after {:.0} s of simulated driving: its figures cover that stretch only, and whether the vehicle reaches the end of the path was not checked",
                t.sim_time_s
            ));
        } else if !t.reached_end {
            out.push("the tracked vehicle did not reach the end of the path in time".into());
        }
        if t.qp_failures > 0 {
            out.push(format!(
                "{} of {} MPC solves failed and held the previous command",
                t.qp_failures, t.qp_solves
            ));
        }
    }
    out
}

/// The clearance figures in words. A path on a map without impassable cells has no clearance
/// to measure (every sample's is infinite, which the distribution's order statistics leave out
/// as NaN).
pub fn clearance_words(d: &Distribution) -> String {
    if d.min.is_finite() {
        format!("min {:.2} m, median {:.1} m", d.min, d.median)
    } else if d.count > 0 {
        "unbounded (no impassable ground on the map)".into()
    } else {
        "not measured (no path)".into()
    }
}

/// The human summary of one mission.
pub fn summary(name: &str, r: &CoverageReport) -> String {
    let mut s = format!(
        "{name}: coverage {:.2} % of the area ({:.2} % of the passable area), planning {:.3} s\n",
        100.0 * r.coverage.ratio,
        100.0 * r.coverage.ratio_of_passable,
        r.planning_time_s
    );
    let [det, vb, skip, tr, unr, st] = r.event_counts;
    s.push_str(&format!(
        "  path {:.1} km in {} sweeps: {det} detours, {vb} virtual boundaries, {skip} row skips, {tr} transits, {unr} unreached, {st} dead ends\n",
        r.path_length_m / 1000.0,
        r.sweeps
    ));
    s.push_str(&format!(
        "  clearance {}; {} samples < {} m; slope median {:.1}°, max {:.1}°; max |κ| {:.3} 1/m\n",
        clearance_words(&r.clearance),
        r.samples_below_clearance,
        r.safety_clearance_m,
        r.slope.median,
        r.slope.max,
        r.max_curvature
    ));
    if let Some(t) = &r.tracking {
        s.push_str(&format!(
            "  tracking: |cte| max {:.2} m, median {:.3} m, rms {:.3} m; {} QPs ({} failed); {:.1} h simulated in {:.1} s\n",
            t.max_abs_cte_m,
            t.median_abs_cte_m,
            t.rms_cte_m,
            t.qp_solves,
            t.qp_failures,
            t.sim_time_s / 3600.0,
            t.wall_time_s
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::coverage::TerrainMap25;
    use shoal_common::terrain::HeightGrid;

    /// An `n × n` grid of 2 m cells rising 10 m per metre eastward: a 84° slope everywhere,
    /// far steeper than any crawler climbs.
    fn impassable_map(n: usize) -> TerrainMap25 {
        let z = (0..n * n).map(|k| 20.0 * (k % n) as f64).collect();
        let grid = HeightGrid::new([0.0, 0.0], 2.0, n, n, z).unwrap_or_else(|e| panic!("{e}"));
        let settings = CoverageSettings::default();
        TerrainMap25::from_grid(&grid, &settings.limits).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn a_mission_without_a_path_says_so() {
        let map = impassable_map(60);
        let settings = CoverageSettings::default();
        let area = Rect::new(0.0, 0.0, 118.0, 118.0);
        let (report, _) = run_coverage(&settings, &map, area, None, 1, None, &mut |_, _| {})
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(report.planned_path.is_empty());
        assert!(report.tracking.is_none());
        let notes = notices(&report);
        assert_eq!(
            notes.first().map(String::as_str),
            Some("no path was planned: no row of the area has a stretch the crawler can enter and drive 8 m from impassable ground; nothing of it is covered"),
            "{notes:?}"
        );
        // A path of no length prints as 0 m, not "-0", and has no clearance to print.
        let text = summary("s", &report);
        assert!(!text.contains("-0"), "{text}");
        assert!(text.contains("clearance not measured (no path)"), "{text}");
    }

    #[test]
    fn clearance_in_words() {
        let some = Distribution::new(&[12.5, f64::INFINITY, 20.0], 0.0, 40.0, 40);
        assert_eq!(clearance_words(&some), "min 12.50 m, median 16.2 m");
        let unbounded = Distribution::new(&[f64::INFINITY; 3], 0.0, 40.0, 40);
        assert_eq!(
            clearance_words(&unbounded),
            "unbounded (no impassable ground on the map)"
        );
        let none = Distribution::new(&[], 0.0, 40.0, 40);
        assert_eq!(clearance_words(&none), "not measured (no path)");
    }
}
