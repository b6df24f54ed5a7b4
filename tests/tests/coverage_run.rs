//! Executing a coverage plan end to end (CPP-DSMV under `run`): two crawlers plan their strips
//! of a shrunken `cpp-fleet`, their agents drive simulated crawlers along the paths on the
//! seabed map at 500× real time, each crawler ends at its own finish, the pair keeps d_min,
//! and `replay` agrees. An obstacle dropped on a crawler's path is driven round on the seabed
//! map; one dropped on its finish ends the crawler's path short of it, and the run says so
//! instead of driving through it or holding with its rows undone.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::coverage::small_fleet;
use common::fleet::{endpoint, free_port, Fleet};
use common::process::{coordinator, root};
use common::{number, read_json, without_shoal_env, TestResult};
use serde_json::Value;

const LIMIT: Duration = Duration::from_secs(240);

/// `run FILE --in-process -q --time-scale 500 --out OUT EXTRA…`.
fn run(file: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut cmd = Command::new(coordinator());
    without_shoal_env(&mut cmd);
    cmd.current_dir(root())
        .arg("run")
        .arg(file)
        .args(["--in-process", "-q", "--time-scale", "500"])
        .args(extra)
        .arg("--out")
        .arg(out);
    cmd
}

#[test]
fn crawlers_drive_their_coverage_paths_and_each_ends_at_its_own_finish() -> TestResult {
    let mut fleet = Fleet::new();
    let file = small_fleet(fleet.dir(), &|t| t)?;
    let out = fleet.dir().join("out");
    let c = fleet.spawn("coordinator", run(&file, &out, &[]));
    let r = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    assert!(r.stdout.contains("  MET: "), "{}", r.stdout);
    // The plan is the coverage plan, timed 10 m over d_min for the tracking error.
    let plan = read_json(&out.join("plan.json"))?;
    assert_eq!(plan["kind"], "coverage-fleet");
    assert_eq!(number(&plan["fleet"]["separation"], "d_min_m"), 60.0);
    let report = read_json(&out.join("execution.json"))?;
    let f = &report["figures"];
    assert!(number(f, "min_separation_m") >= 50.0, "{f}");
    assert_eq!(f["all_arrived_in_window"], Value::Bool(true), "{f}");
    let vehicles = f["vehicles"].as_array().cloned().unwrap_or_default();
    assert_eq!(vehicles.len(), 2);
    let mut due = Vec::new();
    for v in &vehicles {
        // Each crawler is due when its own path ends, and arrived then.
        let planned = number(v, "planned_arrival_s");
        assert!((number(v, "arrived_s") - planned).abs() <= 30.0, "{v}");
        // 15 rows of 300 m at 0.5 m/s take over 2.5 h.
        assert!(planned > 9000.0, "{v}");
        assert!(number(v, "p95_cross_track_m") < 5.0, "{v}");
        assert!(number(v, "reports") > 20.0, "{v}");
        assert_eq!(number(v, "revision"), 0.0, "{v}");
        // On the seabed map: never on impassable ground, a few metres inside the planner's
        // 8 m safety clearance at most.
        assert_eq!(number(v, "impassable_m"), 0.0, "{v}");
        assert!(number(v, "min_ground_clearance_m") > 3.0, "{v}");
        due.push(planned);
    }
    assert!(
        (due[0] - due[1]).abs() > 1.0,
        "both crawlers due at the same time: {due:?}"
    );
    assert!((number(f, "common_arrival_s") - due[0].max(due[1])).abs() < 1e-6);
    // The executed swaths cover about what the planned ones do (88 %), less the tracking error.
    let executed = number(&f["coverage"], "ratio");
    let planned = number(&plan["fleet"]["coverage"], "ratio");
    assert!(
        executed > planned - 0.06 && executed <= planned + 0.01,
        "{executed} vs {planned}"
    );
    // Replay: the same figures from the records alone.
    let rp = fleet.replay(&out.join("mission.ndjson"));
    assert!(rp.stdout.contains("  MET: "), "{}", rp.stdout);
    fleet.passed();
    Ok(())
}

#[test]
fn a_crawler_drives_round_an_obstacle_on_its_coverage_path() -> TestResult {
    let mut fleet = Fleet::new();
    let file = small_fleet(fleet.dir(), &|t| t)?;
    let out = fleet.dir().join("out");
    // By t = 1500 s crawler2 has driven its rows up to y ≈ 205 m (10 m apart, 10 min each,
    // round the seamount at (150, 150)); a 5 m obstacle (55 m inflated by d_min) at (150, 270)
    // blocks its rows from y = 215 m on and keeps clear of those it drove.
    let c = fleet.spawn(
        "coordinator",
        run(&file, &out, &["--inject-obstacle", "1500:150,270,0,5"]),
    );
    let r = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    assert!(r.stdout.contains("  MET: "), "{}", r.stdout);
    let report = read_json(&out.join("execution.json"))?;
    let f = &report["figures"];
    assert!(number(&report, "replans") >= 1.0, "{report}");
    assert_eq!(number(&report, "holds"), 0.0, "{report}");
    let c2 = &f["vehicles"][1];
    assert_eq!(c2["vehicle"], "crawler2");
    assert!(number(c2, "revision") >= 1.0, "{c2}");
    // Round the obstacle: outside its 5 m body by its 50 m inflation less the tracking error
    // (a few metres), never on impassable ground, and still finishing in its window (the
    // longer way is driven faster, within the crawler's 1 m/s).
    assert!(number(c2, "min_obstacle_clearance_m") > 45.0, "{c2}");
    assert_eq!(number(c2, "impassable_m"), 0.0, "{c2}");
    assert_eq!(f["all_arrived_in_window"], Value::Bool(true), "{f}");
    assert!(number(f, "min_separation_m") >= 50.0, "{f}");
    // The ground under the obstacle (its 55 m disc is about a tenth of the 300 m square) is
    // left uncovered: coverage drops from the plan's 88 % by about that much, not to half.
    let executed = number(&f["coverage"], "ratio");
    let plan = read_json(&out.join("plan.json"))?;
    let planned = number(&plan["fleet"]["coverage"], "ratio");
    assert!(
        executed < planned - 0.05 && executed > planned - 0.2,
        "{executed} vs {planned}"
    );
    let log = std::fs::read_to_string(out.join("mission.ndjson"))?;
    assert!(
        log.lines()
            .any(|l| l.contains("\"kind\":\"replanned\"") && l.contains("crawler2")),
        "no replanned event for crawler2"
    );
    fleet.passed();
    Ok(())
}

#[test]
fn a_crawler_whose_finish_an_obstacle_covers_ends_its_path_short_of_it() -> TestResult {
    let mut fleet = Fleet::new();
    let file = small_fleet(fleet.dir(), &|t| t)?;
    let out = fleet.dir().join("out");
    // crawler2's path ends at (5, 195), going west along its last row. At t = 2000 s it is
    // at (210, 202), 250 m from a 5 m obstacle (55 m inflated by d_min) dropped at (−40, 195),
    // just outside the area, whose keep-out covers that end (45 m away); crawler1's path keeps
    // 66 m from it. No way round can end inside the keep-out. Before, crawler2 held where it
    // was to the end of the mission with two thirds of its rows undone (38.9 % of the area
    // covered, NOT MET); now its path ends at (32, 195), before the last stretch.
    let c = fleet.spawn(
        "coordinator",
        run(&file, &out, &["--inject-obstacle=2000:-40,195,0,5"]),
    );
    let r = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    assert!(r.stdout.contains("  MET: "), "{}", r.stdout);
    let report = read_json(&out.join("execution.json"))?;
    let f = &report["figures"];
    assert_eq!(number(&report, "holds"), 0.0, "{report}");
    assert_eq!(f["all_arrived_in_window"], Value::Bool(true), "{f}");
    let c2 = &f["vehicles"][1];
    assert_eq!(c2["vehicle"], "crawler2");
    assert!(number(c2, "revision") >= 1.0, "{c2}");
    // Never into the keep-out (its track before the obstacle came stayed farther from it).
    assert!(number(c2, "min_obstacle_clearance_m") > 50.0, "{c2}");
    // Every row but the last stretch driven: the area covered as without the obstacle
    // (85–88 %), less the ground near the west edge its ways round leave out.
    assert!(number(&f["coverage"], "ratio") > 0.75, "{f}");
    let log = std::fs::read_to_string(out.join("mission.ndjson"))?;
    assert!(
        log.lines().any(|l| l.contains("\"kind\":\"replanned\"")
            && l.contains("its finish (5, 195) is inside injected#1's keep-out: its path now ends at (32, 195)")),
        "no replanned event saying crawler2's finish is given up"
    );
    assert!(number(f, "min_separation_m") >= 50.0, "{f}");
    fleet.passed();
    Ok(())
}

#[test]
fn a_crawler_goes_round_a_lost_crawler_when_its_path_comes_near() -> TestResult {
    let mut fleet = Fleet::new();
    let file = small_fleet(fleet.dir(), &|t| t)?;
    let out = fleet.dir().join("out");
    let port = free_port();
    // crawler2's agent never connects: it is lost 2 s + 5 s of wall time into the mission
    // (t ≈ 3500 s) and stands where its plan starts, (11, 155). crawler1's last rows
    // (y 95–145) end at (5, 105), within d_min plus the buffer of it, hours later. Re-timing
    // cannot pass a vehicle that stands on the path: crawler2 is gone round like an obstacle,
    // but only once that stretch comes within the conflict horizon (455 mission seconds at
    // 500×), not at once: a held vehicle is retried every 30 mission seconds and usually goes
    // on long before, and a way round is never undone.
    let cmd = run(
        &file,
        &out,
        &[
            "--agents",
            "external",
            "--lost-after",
            "2",
            "--listen",
            &format!("tcp/127.0.0.1:{port}"),
        ],
    );
    let c = fleet.spawn("coordinator", cmd);
    fleet.agent("crawler1", &endpoint(port), &["--idle-timeout", "5"]);
    let r = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(3), "{}\n{}", r.stdout, r.stderr);
    assert!(r.stdout.contains("crawler2 never arrived"), "{}", r.stdout);
    let report = read_json(&out.join("execution.json"))?;
    let f = &report["figures"];
    let c1 = &f["vehicles"][0];
    assert_eq!(c1["vehicle"], "crawler1");
    assert_eq!(c1["in_window"], Value::Bool(true), "{c1}");
    assert!(number(c1, "revision") >= 1.0, "{c1}");
    assert_eq!(number(c1, "impassable_m"), 0.0, "{c1}");
    assert_eq!(f["vehicles"][1]["lost"], Value::Bool(true), "{f}");
    let log = std::fs::read_to_string(out.join("mission.ndjson"))?;
    let event_at = |kind: &str, text: &str| -> Option<f64> {
        log.lines()
            .filter_map(|l| serde_json::from_str::<Value>(l).ok())
            .find(|e| e["kind"] == kind && e["detail"].as_str().is_some_and(|d| d.contains(text)))
            .and_then(|e| e["t_s"].as_f64())
    };
    let lost = event_at("vehicle_lost", "crawler2 is lost").ok_or("crawler2 was not lost")?;
    // The reaction to the stand: the repair round it, or, when the repair runs past its wall
    // budget on a busy machine, a hold whose retry repairs it ("retrying after a hold").
    let reacted = event_at("replanned", "crawler1 replanned (crawler2 stands")
        .or_else(|| event_at("hold", "crawler1 told to hold (crawler2 stands"))
        .ok_or("crawler1 did not react to the lost crawler2 standing near its path")?;
    let rounded = log
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter(|e| e["kind"] == "replanned")
        .filter(|e| {
            e["detail"]
                .as_str()
                .is_some_and(|d| d.starts_with("crawler1 replanned"))
        })
        .filter_map(|e| e["t_s"].as_f64())
        .find(|&t| t >= reacted)
        .ok_or("crawler1 was not repaired round the lost crawler2")?;
    // Measured: lost at 3524 s, gone round at 5766 s (as soon as it stood: ≈ 3575 s).
    assert!(
        reacted - lost > 1000.0,
        "lost at {lost} s, reacted at {reacted} s, gone round at {rounded} s"
    );
    fleet.passed();
    Ok(())
}

#[test]
fn a_crawler_caught_inside_an_obstacles_margin_is_let_out() -> TestResult {
    let mut fleet = Fleet::new();
    let file = small_fleet(fleet.dir(), &|t| t)?;
    let out = fleet.dir().join("out");
    // At t = 2000 s crawler2 drives west along y ≈ 200 m; a 3 m obstacle (53 m inflated by its
    // 50 m margin) dropped at (240, 210) is on its course: it is told to hold at once and stops
    // about 30 m from the centre, 23 m inside the margin. A way round cannot start inside a
    // keep-out: before the margin was eased for a crawler inside it, it held to the end.
    let c = fleet.spawn(
        "coordinator",
        run(&file, &out, &["--inject-obstacle=2000:240,210,0,3"]),
    );
    let r = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    let report = read_json(&out.join("execution.json"))?;
    let f = &report["figures"];
    assert!(number(&report, "holds") >= 1.0, "{report}");
    let c2 = &f["vehicles"][1];
    assert_eq!(c2["vehicle"], "crawler2");
    assert!(number(c2, "revision") >= 1.0, "{c2}");
    // Out of the margin it was caught in, never into the obstacle's body.
    let clearance = number(c2, "min_obstacle_clearance_m");
    assert!(clearance > 5.0 && clearance < 45.0, "{c2}");
    assert_eq!(number(c2, "impassable_m"), 0.0, "{c2}");
    assert_eq!(f["all_arrived_in_window"], Value::Bool(true), "{f}");
    assert!(number(f, "min_separation_m") >= 50.0, "{f}");
    fleet.passed();
    Ok(())
}
