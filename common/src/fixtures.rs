//! Test fixtures shared by the unit tests of several modules: small scenarios written as TOML
//! (so they go through the real parser) and hand-built particles.

use crate::cost::FleetModel;
use crate::scenario::{Scenario, ScenarioError};

/// A `[[vehicles]]` block with the limits every fixture uses (0.5–1.5 m/s, 35°, 20°).
pub fn vehicle_toml(id: &str, start: [f64; 3], goal: [f64; 3]) -> String {
    format!(
        "[[vehicles]]\nid = \"{id}\"\nkind = \"auv\"\nstart = {start:?}\ngoal = {goal:?}\n\
         speed_min_mps = 0.5\nspeed_max_mps = 1.5\nmax_turn_deg = 35.0\nmax_pitch_deg = 20.0\n"
    )
}

/// A 1000 × 1000 × 500 m box with 6 waypoints per vehicle, d_min 50 m, the given mission time,
/// extra TOML (obstacles) and vehicles.
pub fn scenario(
    mission_time_s: f64,
    extra: &str,
    vehicles: &[String],
) -> Result<Scenario, ScenarioError> {
    let text = format!(
        "name = \"fixture\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [1000.0, 1000.0, 500.0]\n{extra}\n{}\
         [fleet]\nd_min_m = 50.0\nmission_time_s = {mission_time_s:?}\n[optimizer]\nwaypoints = 6\n",
        vehicles.concat()
    );
    Scenario::parse(&text, std::path::Path::new("fixture.toml"))
}

/// Eight AUVs crossing the box both ways (their paths meet in the middle), a hard and a soft
/// sphere: random particles breach separation, obstacles and limits in many ways.
pub fn crossing_fleet() -> Result<Scenario, ScenarioError> {
    let spheres = "[[obstacles]]\nid = \"H\"\nkind = \"hard\"\ncentre = [500.0, 300.0, 250.0]\nradius_m = 80.0\ninflation_m = 10.0\n\
                   [[obstacles]]\nid = \"S\"\nkind = \"soft\"\ncentre = [500.0, 700.0, 250.0]\nradius_m = 80.0\ninflation_m = 10.0\n";
    let vehicles: Vec<String> = (0..8)
        .map(|k| {
            let y = 100.0 + 110.0 * k as f64;
            let (from, to) = if k % 2 == 0 {
                (50.0, 950.0)
            } else {
                (950.0, 50.0)
            };
            vehicle_toml(&format!("v{k}"), [from, y, 200.0], [to, 1000.0 - y, 300.0])
        })
        .collect();
    scenario(900.0, spheres, &vehicles)
}

/// Every vehicle on its straight line (waypoints evenly spaced) at a requested 1 m/s.
pub fn straight_particle(model: &FleetModel) -> Vec<f64> {
    let m = model.layout.waypoints;
    let mut x = Vec::new();
    for v in &model.scenario.vehicles {
        for j in 1..=m {
            let p = v.start() + (v.goal() - v.start()) * (j as f64 / (m + 1) as f64);
            x.extend_from_slice(&[p.x, p.y, p.z]);
        }
        x.extend(std::iter::repeat_n(1.0, m));
    }
    x
}

/// The report `main` prints (`{:#}`): the error and every `source` below it, joined by ": ".
pub fn chained(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut next = e.source();
    while let Some(s) = next {
        text = format!("{text}: {s}");
        next = s.source();
    }
    text
}
