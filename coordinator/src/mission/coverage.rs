//! `run` on a `[coverage]` mission (CPP-DSMV): the coverage plan, then its execution by the
//! agents' vehicles like any other plan ([`crate::execute`]).
//!
//! - **Planning** is `plan`'s ([`super::plan::plan_coverage_mission`]) without its closed-loop
//!   tracking simulation: under `run` the agents' vehicles drive the path, so simulating it
//!   first would only double the time. `plan.json` then has no `tracking` figures; the
//!   execution's are in `execution.json`.
//! - **The start delays** that keep the crawlers apart are found for d_min plus the separation
//!   buffer (`--separation-buffer`, d_min / 5 by default): the delay search stops at the first
//!   timing that keeps its distance, so timed for d_min alone two crawlers pass exactly d_min
//!   apart, and any tracking error (a metre or two) takes them under it.
//! - **Each crawler's trajectory** is its exact path driven at the tracking speed
//!   (`coverage.tracking.speed_mps`) after its start delay (a fleet's separation timing), on
//!   the seabed map ([`drive_trajectory`]).
//! - **The agents** get the scenario with each crawler's start and goal moved to its path's
//!   ends (the scenario's are nominal: a coverage path begins at its first admissible row
//!   point), and a heightmap path made absolute so an agent started elsewhere finds it.
//! - **Each crawler ends when its strip is done**: its arrival window is around its own
//!   finish, not a common one (a crawler does not wait for the others).

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::bail;
use shoal_common::coverage::drive::drive_trajectory;
use shoal_common::scenario::Scenario;
use shoal_common::trajectory::Trajectory;

use super::executable::{executable, with_tracking_room, Executable};
use super::options::MissionOptions;
use super::plan::plan_coverage_mission;
use crate::distributed::DistributedOptions;

/// Plans `scenario`'s coverage into the mission's output directory and returns what the agents execute; `None` (after
/// saying why) when the plan is not to be executed.
pub fn plan(
    m: &MissionOptions,
    scenario: &Scenario,
    options: &DistributedOptions,
    separation_buffer_m: f64,
    shutdown: &Arc<AtomicBool>,
) -> anyhow::Result<Option<Executable>> {
    let Some(settings) = scenario.coverage.as_ref() else {
        bail!("{}: no [coverage] table", m.scenario.display());
    };
    let mut planning = with_tracking_room(scenario, separation_buffer_m);
    if let Some(c) = planning.coverage.as_mut() {
        c.track = false;
    }
    let planned = plan_coverage_mission(m, &planning, shutdown, || Ok(options.clone()))?;
    if !executable(planned.feasible, shutdown) {
        return Ok(None);
    }
    let trajectories: Vec<Trajectory> = planned
        .paths
        .iter()
        .zip(&planned.start_delays_s)
        .map(|(path, delay)| {
            drive_trajectory(
                path,
                &planned.map,
                settings.tracking.speed_mps,
                *delay,
                scenario.crawler.sensor_height_m,
            )
        })
        .collect();
    let dir = m.scenario.parent().unwrap_or(Path::new("."));
    let scenario = for_agents(scenario, &trajectories, dir)?;
    let common_arrival_s = trajectories
        .iter()
        .map(Trajectory::arrival)
        .fold(0.0, f64::max);
    Ok(Some(Executable {
        scenario,
        trajectories,
        common_arrival_s,
    }))
}

/// The scenario the agents get: each crawler starting and ending where its trajectory does,
/// the bounds' z range widened to hold every trajectory (a coverage scenario's z range is
/// nominal: the 2.5-D planner does not use it, the map gives the heights), a heightmap named by
/// an absolute path (`dir` is the scenario file's directory). An empty trajectory (a crawler
/// with nothing to drive) is an error naming it.
fn for_agents(
    scenario: &Scenario,
    trajectories: &[Trajectory],
    dir: &Path,
) -> anyhow::Result<Scenario> {
    let mut out = scenario.clone();
    for (v, t) in out.vehicles.iter_mut().zip(trajectories) {
        let (Some(first), Some(last)) = (t.points.first(), t.points.last()) else {
            bail!(
                "{}'s coverage path is empty: there is nothing for it to drive",
                v.id
            );
        };
        v.start = [first.x, first.y, first.z];
        v.goal = [last.x, last.y, last.z];
        for p in &t.points {
            out.bounds.min[2] = out.bounds.min[2].min(p.z.floor());
            out.bounds.max[2] = out.bounds.max[2].max(p.z.ceil());
        }
    }
    if let Some(c) = out.coverage.as_mut() {
        if let Some(h) = c.heightmap.as_ref().filter(|h| h.is_relative()) {
            let joined = dir.join(h);
            c.heightmap = Some(std::path::absolute(&joined).unwrap_or(joined));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shoal_common::geometry::Vec3;

    fn scenario() -> anyhow::Result<Scenario> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/cpp-fleet.toml");
        Ok(Scenario::load(&path)?)
    }

    fn line(a: [f64; 3], b: [f64; 3], t1: f64) -> Trajectory {
        Trajectory {
            times: vec![0.0, t1],
            points: vec![Vec3::from(a), Vec3::from(b)],
        }
    }

    #[test]
    fn the_agents_start_the_crawlers_where_their_paths_do() -> anyhow::Result<()> {
        let s = scenario()?;
        let n = s.vehicles.len();
        let tr: Vec<Trajectory> = (0..n)
            .map(|i| {
                let y = 10.0 + 100.0 * i as f64;
                line([5.0, y, -1.0], [995.0, y + 20.0, 2.5], 100.0)
            })
            .collect();
        let mut with_file = s.clone();
        if let Some(c) = with_file.coverage.as_mut() {
            c.heightmap = Some("bathymetry.asc".into());
        }
        let out = for_agents(&with_file, &tr, Path::new("scenarios"))?;
        for (i, v) in out.vehicles.iter().enumerate() {
            let y = 10.0 + 100.0 * i as f64;
            assert_eq!(v.start, [5.0, y, -1.0]);
            assert_eq!(v.goal, [995.0, y + 20.0, 2.5]);
        }
        // The box held z from -6000 m to 0 m; the paths reach 2.5 m.
        assert_eq!(out.bounds.min[2], s.bounds.min[2]);
        assert_eq!(out.bounds.max[2], 3.0);
        out.validate(Path::new("for-agents.toml"))?;
        let h = out
            .coverage
            .as_ref()
            .and_then(|c| c.heightmap.clone())
            .unwrap_or_default();
        assert!(
            h.is_absolute() && h.ends_with("scenarios/bathymetry.asc"),
            "{h:?}"
        );
        // Without a file, nothing else changes.
        let plain = for_agents(&s, &tr, Path::new("scenarios"))?;
        assert_eq!(plain.coverage, s.coverage);
        Ok(())
    }

    #[test]
    fn a_crawler_with_nothing_to_drive_is_named() -> anyhow::Result<()> {
        let s = scenario()?;
        let mut tr: Vec<Trajectory> = (0..s.vehicles.len())
            .map(|_| line([5.0, 5.0, 0.0], [50.0, 5.0, 0.0], 90.0))
            .collect();
        tr[1] = Trajectory {
            times: Vec::new(),
            points: Vec::new(),
        };
        let e = for_agents(&s, &tr, Path::new("."))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains(&s.vehicles[1].id) && e.contains("empty"), "{e}");
        Ok(())
    }
}
