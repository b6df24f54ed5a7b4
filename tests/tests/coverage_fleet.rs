//! Area coverage by several crawlers (CPP-DSMV with a fleet) end to end: the coordinator cuts a
//! shrunken `scenarios/cpp-fleet.toml` into strips, one agent per crawler plans its strip, and
//! the fleet's plan matches the in-process one and keeps `d_min` at every instant. A strip its
//! agent cannot plan (a heightmap the agent cannot read) is planned by the coordinator.

mod common;

use std::time::{Duration, Instant};

use common::coverage::small_fleet;
use common::fleet::Fleet;
use common::{key, plan, read_json, TestResult};
use serde_json::Value;

const LIMIT: Duration = Duration::from_secs(240);

fn num(v: &Value, field: &str) -> f64 {
    match v[field].as_f64() {
        Some(x) => x,
        None => panic!("{field} is not a number in {v}"),
    }
}

#[test]
fn agents_plan_their_strips_and_the_fleet_keeps_its_separation() -> TestResult {
    let mut fleet = Fleet::new();
    let file = small_fleet(fleet.dir(), &|t| t)?;
    let out = fleet.dir().join("out");
    let c = fleet.coordinator_on("coordinator", &file, &out, &[]);
    let r = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    let json = read_json(&out.join("plan.json"))?;
    assert_eq!(key(&json, "kind").as_str(), Some("coverage-fleet"));
    assert_eq!(key(&json, "feasible").as_bool(), Some(true));
    assert_eq!(key(&json, "distributed.messages_dropped").as_u64(), Some(0));
    assert_eq!(
        key(&json, "distributed.degraded").as_array().map(Vec::len),
        Some(0),
        "{}",
        key(&json, "distributed")
    );
    let f = key(&json, "fleet");
    // Two strips of whole 10 m rows: 30 rows -> 15 + 15.
    let strips: Vec<[f64; 2]> = (0..2)
        .map(|k| {
            let s = &f["vehicles"][k]["strip"];
            [num(s, "y0"), num(s, "y1")]
        })
        .collect();
    assert_eq!(strips, vec![[0.0, 150.0], [150.0, 300.0]]);
    assert_eq!(f["samples_below_clearance"].as_u64(), Some(0));
    assert!(num(&f["clearance"], "min") >= 8.0 - 1e-6);
    assert!(num(&f["coverage"], "ratio") > 0.6, "{}", f["coverage"]);
    let sep = &f["separation"];
    assert!(num(sep, "min_distance_m") >= 50.0, "{sep}");
    assert_eq!(num(sep, "breach_s"), 0.0);
    // Each crawler's path stays in its strip (a detour may not leave the area it plans).
    for k in 0..2 {
        let v = &f["vehicles"][k];
        let (y0, y1) = (num(&v["strip"], "y0"), num(&v["strip"], "y1"));
        let path = v["report"]["planned_path"]
            .as_array()
            .cloned()
            .unwrap_or_default();
        assert!(!path.is_empty());
        for p in &path {
            let y = p[1].as_f64().unwrap_or(f64::NAN);
            assert!(
                y >= y0 - 1.0 && y <= y1 + 1.0,
                "crawler {k} at y = {y} outside [{y0}, {y1}]"
            );
        }
    }
    // The strips follow from the scenario: the agents' plans are the ones this process makes.
    let local_out = fleet.dir().join("local");
    let local = plan(&file, &local_out, &[]);
    assert_eq!(local.code(), Some(0), "{}\n{}", local.stdout, local.stderr);
    let local = read_json(&local_out.join("plan.json"))?;
    let lf = key(&local, "fleet");
    assert_eq!(lf["coverage"], f["coverage"]);
    assert_eq!(lf["separation"], f["separation"]);
    for k in 0..2 {
        assert_eq!(
            lf["vehicles"][k]["report"]["planned_path"],
            f["vehicles"][k]["report"]["planned_path"]
        );
    }
    let svg = std::fs::read_to_string(out.join("plan.svg"))?;
    for needle in ["crawler1", "crawler2", "min separation", "no-go boxes"] {
        assert!(svg.contains(needle), "plan.svg lacks {needle:?}");
    }
    fleet.passed();
    Ok(())
}

/// An ESRI ASCII grid of `n × n` cells of 2 m, flat with a 40 m Gaussian mound in the middle.
fn mound_grid(n: usize) -> String {
    let mut s =
        format!("ncols {n}\nnrows {n}\nxllcorner 0\nyllcorner 0\ncellsize 2\nNODATA_value -9999\n");
    let c = n as f64; // centre at (n, n) metres
    for row in 0..n {
        let y = 2.0 * (n - 1 - row) as f64 + 1.0;
        let line: Vec<String> = (0..n)
            .map(|i| {
                let x = 2.0 * i as f64 + 1.0;
                let r2 = (x - c).powi(2) + (y - c).powi(2);
                format!("{:.3}", -6000.0 + 40.0 * (-r2 / (2.0 * 20.0 * 20.0)).exp())
            })
            .collect();
        s.push_str(&line.join(" "));
        s.push('\n');
    }
    s
}

#[test]
fn a_strip_its_agent_cannot_plan_is_planned_by_the_coordinator() -> TestResult {
    let mut fleet = Fleet::new();
    // The heightmap sits beside the scenario; the agents run elsewhere and cannot read it.
    std::fs::write(fleet.dir().join("mound.asc"), mound_grid(150))?;
    let file = small_fleet(fleet.dir(), &|t| {
        t.replace("[coverage]\n", "[coverage]\nheightmap = \"mound.asc\"\n")
    })?;
    let out = fleet.dir().join("out");
    let c = fleet.coordinator_on("coordinator", &file, &out, &[]);
    let r = fleet.wait(c, Instant::now() + LIMIT);
    assert_eq!(r.code(), Some(0), "{}\n{}", r.stdout, r.stderr);
    let json = read_json(&out.join("plan.json"))?;
    assert_eq!(key(&json, "feasible").as_bool(), Some(true));
    let degraded: Vec<&str> = key(&json, "distributed.degraded")
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|d| d["vehicle"].as_str())
        .collect();
    assert_eq!(degraded, ["crawler1", "crawler2"]);
    let notices = key(&json, "notices").to_string();
    assert!(
        notices.contains("crawler1's strip was planned by the coordinator"),
        "{notices}"
    );
    let f = key(&json, "fleet");
    assert!(num(&f["coverage"], "ratio") > 0.6, "{}", f["coverage"]);
    assert!(num(&f["separation"], "min_distance_m") >= 50.0);
    fleet.passed();
    Ok(())
}
