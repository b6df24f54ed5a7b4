//! Unit tests of `plan`.

use super::*;
use crate::geometry::Vec3;

fn scenario() -> Result<Scenario, crate::scenario::ScenarioError> {
    Scenario::parse(
        r#"
name = "p"
[bounds]
min = [0.0, 0.0, 0.0]
max = [1000.0, 1000.0, 1000.0]
[[obstacles]]
id = "H"
kind = "hard"
centre = [500.0, 25.0, 0.0]
radius_m = 20.0
inflation_m = 10.0
[[vehicles]]
id = "a"
kind = "auv"
start = [0.0, 0.0, 0.0]
goal = [1000.0, 0.0, 0.0]
speed_min_mps = 0.5
speed_max_mps = 2.0
max_turn_deg = 35.0
max_pitch_deg = 20.0
[[vehicles]]
id = "b"
kind = "auv"
start = [1000.0, 100.0, 0.0]
goal = [0.0, 100.0, 0.0]
speed_min_mps = 0.5
speed_max_mps = 2.0
max_turn_deg = 35.0
max_pitch_deg = 20.0
[fleet]
d_min_m = 150.0
mission_time_s = 1000.0
"#,
        std::path::Path::new("p.toml"),
    )
}

fn line(a: [f64; 3], b: [f64; 3], t: f64) -> Trajectory {
    Trajectory {
        times: vec![0.0, t],
        points: vec![Vec3::from(a), Vec3::from(b)],
    }
}

#[test]
fn figures_by_hand() -> Result<(), crate::scenario::ScenarioError> {
    let s = scenario()?;
    // a along y = 0, b back along y = 100, both at 1 m/s: they pass 100 m apart at t = 500,
    // below d_min = 150 while the x gap is under √(150² − 100²) = 111.8 m: 111.8 s.
    // a passes 25 m from H's centre: clearance 25 − 20 = 5 m, inside the 30 m inflated sphere.
    let t = [
        line(s.vehicles[0].start, s.vehicles[0].goal, 1000.0),
        line(s.vehicles[1].start, s.vehicles[1].goal, 1000.0),
    ];
    let a = assess(&s, &t);
    assert!((a.vehicles[0].length_m - 1000.0).abs() < 1e-9);
    assert_eq!(
        a.vehicles[0]
            .min_clearance_m
            .map(|c| (c * 1e6).round() / 1e6),
        Some(5.0)
    );
    assert_eq!(a.vehicles[0].hard_collisions, 1);
    assert_eq!(a.vehicles[1].hard_collisions, 0);
    assert_eq!(a.fleet.hard_collisions, 1);
    let sep = a.fleet.min_separation_m.unwrap_or(f64::NAN);
    assert!((sep - 100.0).abs() < 1e-9);
    assert!((a.fleet.min_separation_time_s.unwrap_or(f64::NAN) - 500.0).abs() < 1e-9);
    // x gap closes at 2 m/s from +111.8 to −111.8 m: 111.8 s.
    let expect = (150f64.powi(2) - 100f64.powi(2)).sqrt();
    assert!((a.fleet.separation_breach_s - expect).abs() < 1e-6);
    assert_eq!(a.fleet.arrival_spread_s, 0.0);
    assert_eq!(a.violations.len(), 2, "{:?}", a.violations);
    assert!(a.violations[0].contains("hard obstacle H"));
    assert!(a.violations[1].contains("a and b"));
    Ok(())
}

#[test]
fn speed_turn_pitch_and_arrival_violations_are_worded() -> Result<(), crate::scenario::ScenarioError>
{
    let s = scenario()?;
    // a at 2.5 m/s (above 2.0), b arrives 400 s later than a and climbs 45° on a hook.
    let a = line(s.vehicles[0].start, s.vehicles[0].goal, 400.0);
    let b = Trajectory {
        times: vec![0.0, 100.0, 800.0],
        points: vec![
            Vec3::new(1000.0, 100.0, 0.0),
            Vec3::new(950.0, 150.0, 50.0 * 2f64.sqrt()),
            Vec3::new(0.0, 100.0, 0.0),
        ],
    };
    let out = assess(&s, &[a, b]);
    let all = out.violations.join("\n");
    assert!(all.contains("a flies legs at 2.500"), "{all}");
    assert!(all.contains("b pitches 45.0°"), "{all}");
    assert!(all.contains("b turns"), "{all}");
    assert!(all.contains("not synchronised"), "{all}");
    assert!((out.fleet.arrival_spread_s - 400.0).abs() < 1e-9);
    Ok(())
}

#[test]
fn late_arrival_is_explained() -> Result<(), crate::scenario::ScenarioError> {
    let mut s = scenario()?;
    s.fleet.mission_time_s = 300.0;
    let t = [
        line(s.vehicles[0].start, s.vehicles[0].goal, 500.0),
        line(s.vehicles[1].start, s.vehicles[1].goal, 500.0),
    ];
    // Both fly 1000 m flat at 2 m/s at best: no path makes 300 s.
    let n = notices(&s, &t, 500.0);
    assert_eq!(n.len(), 2);
    assert!(
        n[0].contains("a cannot arrive by the mission time of 300 s whatever its path"),
        "{}",
        n[0]
    );
    assert!(
        n[0].contains("even the 1000 m straight line is too long, 500 s"),
        "{}",
        n[0]
    );
    // With 600 s the mission is possible; a detour of two 750 m legs (750 s) is the plan's
    // doing.
    s.fleet.mission_time_s = 600.0;
    let detour = Trajectory {
        times: vec![0.0, 375.0, 750.0],
        points: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(500.0, (750f64.powi(2) - 500f64.powi(2)).sqrt(), 0.0),
            Vec3::new(1000.0, 0.0, 0.0),
        ],
    };
    let n = notices(&s, &[detour, t[1].clone()], 750.0);
    assert_eq!(n.len(), 1, "{n:?}");
    assert!(n[0].starts_with("a's planned path of 1500 m"), "{}", n[0]);
    assert!(n[0].contains("would take 500 s"), "{}", n[0]);
    Ok(())
}

/// An AUV over a seabed hill (100 m high, σ = 100 m, under the middle of its line): at z = 50
/// it goes 50 m into the hill at (500, 500) — a violation naming the place and the field; at
/// z = 102.5 it keeps 2.5 m, over the 2 m default; a crawler gets no such figure.
#[test]
fn an_auv_through_the_seabed_is_a_violation() -> Result<(), crate::scenario::ScenarioError> {
    use crate::fixtures::{scenario, vehicle_toml};
    let hill = "[[seabed.mountains]]\ncentre = [500.0, 500.0]\nheight_m = 100.0\nspread_m = [100.0, 100.0]\n";
    let at = |z: f64| vehicle_toml("a", [0.0, 500.0, z], [1000.0, 500.0, z]);
    let s = scenario(2000.0, hill, &[at(50.0)])?;
    let low = assess(&s, &[line(s.vehicles[0].start, s.vehicles[0].goal, 1000.0)]);
    let h = low.vehicles[0].min_seabed_clearance_m.unwrap_or(f64::NAN);
    assert!((h + 50.0).abs() < 1e-9, "{h}");
    assert_eq!(
        low.violations,
        vec!["a goes 50.0 m into the seabed at (500, 500) m; it must keep 2.0 m above it (seabed.auv_clearance_m)"]
    );
    let s = scenario(2000.0, hill, &[at(102.5)])?;
    let high = assess(&s, &[line(s.vehicles[0].start, s.vehicles[0].goal, 1000.0)]);
    let h = high.vehicles[0].min_seabed_clearance_m.unwrap_or(f64::NAN);
    assert!((h - 2.5).abs() < 1e-9, "{h}");
    assert!(high.violations.is_empty(), "{:?}", high.violations);
    // Without a seabed there is no figure.
    let s = scenario(2000.0, "", &[at(50.0)])?;
    let open = assess(&s, &[line(s.vehicles[0].start, s.vehicles[0].goal, 1000.0)]);
    assert_eq!(open.vehicles[0].min_seabed_clearance_m, None);
    Ok(())
}
