//! Fleet coverage missions (CPP-DSMV with several crawlers) behind `plan`: the area is cut into
//! strips of whole rows, one per crawler ([`FleetCoverage`]); each strip is planned by its
//! crawler's agent (distributed, the default) or on its own thread (`--in-process`); then the
//! coordinator measures the fleet from the paths and the map, and times the crawlers so every
//! pair keeps `d_min` at every instant ([`shoal_common::coverage::fleet::separate`]).

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::Context;
use serde::Serialize;
use shoal_common::coverage::fleet::{assemble, FleetCoverage, FleetCoverageReport, StripPlan};
use shoal_common::coverage::TerrainMap25;
use shoal_common::plan::DistributedFigures;
use shoal_common::scenario::Scenario;

use crate::distributed::{plan_strips_distributed, DistributedOptions};
use crate::planning::coverage::{
    clearance_words, notices, passes, write_outputs, CoverageTermination, PlannedCoverage,
};
use crate::report::svg::coverage::render_fleet_coverage;

/// `plan.json` of a fleet coverage mission.
#[derive(Debug, Serialize)]
pub struct FleetCoveragePlanFile<'a> {
    /// Scenario name.
    pub scenario: &'a str,
    /// Always `coverage-fleet`.
    pub kind: &'static str,
    /// No clearance violation, every pair kept `d_min`, every crawler tracked to the end
    /// reached it.
    pub feasible: bool,
    /// `Completed`, or `Interrupted` when Ctrl-C cut a crawler's tracking simulation short.
    pub termination: CoverageTermination,
    /// Plain-words remarks.
    pub notices: Vec<String>,
    /// The figures.
    pub fleet: &'a FleetCoverageReport,
    /// Network figures of a distributed run.
    pub distributed: Option<&'a DistributedFigures>,
}

/// Plans `scenario`'s fleet coverage into `out`; `distributed` runs it over agents. Returns
/// the plan. A raised `stop` (Ctrl-C) cuts the crawlers' tracking
/// simulations short, the agents' too; every strip is still planned whole.
pub fn plan_fleet_coverage(
    scenario_file: &Path,
    scenario: &Scenario,
    out: &Path,
    quiet: bool,
    distributed: Option<&DistributedOptions>,
    stop: &Arc<AtomicBool>,
) -> anyhow::Result<PlannedCoverage> {
    let job = FleetCoverage::new(scenario)
        .map_err(|e| anyhow::anyhow!("{}: {e}", scenario_file.display()))?;
    let dir = scenario_file.parent().unwrap_or(Path::new("."));
    let map = job
        .map(dir)
        .with_context(|| format!("{}: [coverage] map", scenario_file.display()))?;
    let say = |line: String| {
        if !quiet {
            eprintln!("{line}");
        }
    };
    say(format!(
        "coverage fleet: {} crawlers, strips of {} rows each or so",
        job.ids.len(),
        ((job.area.y1 - job.area.y0) / job.settings.planner.row_spacing() / job.ids.len() as f64)
            .floor()
    ));
    let (plans, figures) = match distributed {
        None => (plan_in_process(&job, &map, stop, &say)?, None),
        Some(options) => {
            let mut last = usize::MAX;
            let (plans, figures) = plan_strips_distributed(
                scenario,
                job.clone(),
                map.clone(),
                options,
                stop,
                &mut |s| {
                    if s.iteration != last {
                        last = s.iteration;
                        say(format!(
                            "coverage fleet: {}/{} strips planned, {} agents alive",
                            s.iteration, s.vehicles, s.alive
                        ));
                    }
                },
            )?;
            (plans, Some(figures))
        }
    };
    say("coverage fleet: timing the crawlers apart".into());
    let paths = plans.iter().map(|p| p.path.clone()).collect();
    let report = assemble(&job, &map, plans);
    let notices = fleet_notices(&report, scenario, figures.as_ref());
    let sep = &report.separation;
    let feasible = report.samples_below_clearance == 0
        && sep.min_distance_m >= sep.d_min_m
        && report.vehicles.iter().all(|v| passes(&v.report));
    let file = FleetCoveragePlanFile {
        scenario: &scenario.name,
        kind: "coverage-fleet",
        feasible,
        termination: CoverageTermination::of(report.vehicles.iter().map(|v| &v.report)),
        notices: notices.clone(),
        fleet: &report,
        distributed: figures.as_ref(),
    };
    let svg = render_fleet_coverage(&report, &map)?;
    write_outputs(
        out,
        &file,
        &svg,
        fleet_summary(&scenario.name, &report),
        &notices,
    )?;
    Ok(PlannedCoverage {
        feasible,
        paths,
        start_delays_s: report.separation.start_delays_s.clone(),
        map,
    })
}

/// Every strip on its own thread (the machine's cores share them).
fn plan_in_process(
    job: &FleetCoverage,
    map: &TerrainMap25,
    stop: &AtomicBool,
    say: &(dyn Fn(String) + Sync),
) -> anyhow::Result<Vec<StripPlan>> {
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..job.ids.len())
            .map(|i| {
                s.spawn(move || {
                    let plan = job.plan_vehicle(map, i, Some(stop), &mut |_, _| {});
                    if let Ok(p) = &plan {
                        say(format!(
                            "coverage fleet: {}'s strip planned, {:.0} m",
                            job.ids[i],
                            p.path.length()
                        ));
                    }
                    plan
                })
            })
            .collect();
        handles
            .into_iter()
            .zip(&job.ids)
            .map(|(h, id)| match h.join() {
                Ok(r) => r.with_context(|| format!("{id}'s strip")),
                Err(_) => Err(anyhow::anyhow!(
                    "{id}'s strip: the planning thread panicked"
                )),
            })
            .collect()
    })
}

/// What a reader should know that the numbers alone do not say.
fn fleet_notices(
    r: &FleetCoverageReport,
    scenario: &Scenario,
    figures: Option<&DistributedFigures>,
) -> Vec<String> {
    let mut out = Vec::new();
    let sep = &r.separation;
    let id = |k: usize| r.vehicles.get(k).map_or("?", |v| v.vehicle.as_str());
    if sep.min_distance_m < sep.d_min_m {
        out.push(format!(
            "{} and {} come within {:.1} m of each other at t = {:.0} s (d_min {} m, {:.0} s below it in all); no start delay resolved it",
            id(sep.closest_pair[0]),
            id(sep.closest_pair[1]),
            sep.min_distance_m,
            sep.at_s,
            sep.d_min_m,
            sep.breach_s
        ));
    }
    for (k, d) in sep.start_delays_s.iter().enumerate() {
        if *d > 0.0 {
            out.push(format!(
                "{} starts {d:.0} s after the others to keep the minimum separation",
                id(k)
            ));
        }
    }
    let finish = sep.finish_s.iter().copied().fold(0.0, f64::max);
    if finish > scenario.fleet.mission_time_s {
        out.push(format!(
            "the last crawler finishes at {finish:.0} s, after the mission time {} s",
            scenario.fleet.mission_time_s
        ));
    }
    for v in &r.vehicles {
        out.extend(
            notices(&v.report)
                .into_iter()
                .map(|n| format!("{}: {n}", v.vehicle)),
        );
    }
    if let Some(f) = figures {
        for d in &f.degraded {
            out.push(format!(
                "{}'s strip was planned by the coordinator: {}",
                d.vehicle, d.reason
            ));
        }
    }
    out
}

/// The human summary of a fleet mission.
fn fleet_summary(name: &str, r: &FleetCoverageReport) -> String {
    let sep = &r.separation;
    let mut s = format!(
        "{name}: {} crawlers cover {:.2} % of the area ({:.2} % of the passable area); longest strip planning {:.3} s\n",
        r.vehicles.len(),
        100.0 * r.coverage.ratio,
        100.0 * r.coverage.ratio_of_passable,
        r.planning_time_s
    );
    s.push_str(&format!(
        "  separation: min {:.1} m at t = {:.0} s (d_min {} m); clearance {}, {} samples < {} m\n",
        sep.min_distance_m,
        sep.at_s,
        sep.d_min_m,
        clearance_words(&r.clearance),
        r.samples_below_clearance,
        r.safety_clearance_m
    ));
    if let Some(c) = &r.cross_track {
        s.push_str(&format!(
            "  tracking: |cte| max {:.2} m, median {:.2} m over all crawlers\n",
            c.max, c.median
        ));
    }
    for (k, v) in r.vehicles.iter().enumerate() {
        s.push_str(&format!(
            "  {}: strip y {:.0}–{:.0} m, coverage {:.2} %, {:.1} km, start {:.0} s, done {:.1} h\n",
            v.vehicle,
            v.strip.y0,
            v.strip.y1,
            100.0 * v.report.coverage.ratio,
            v.report.path_length_m / 1000.0,
            sep.start_delays_s.get(k).copied().unwrap_or(0.0),
            sep.finish_s.get(k).copied().unwrap_or(0.0) / 3600.0
        ));
    }
    s
}
