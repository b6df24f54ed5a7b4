//! Unit tests of `scenario`.

use super::*;
use std::path::Path;

const GOOD: &str = r#"
name = "t"
[bounds]
min = [0.0, 0.0, 0.0]
max = [100.0, 100.0, 100.0]
[[obstacles]]
id = "H1"
kind = "hard"
centre = [50.0, 50.0, 50.0]
radius_m = 10.0
inflation_m = 5.0
[[vehicles]]
id = "a"
kind = "auv"
start = [1.0, 1.0, 1.0]
goal = [99.0, 99.0, 99.0]
speed_min_mps = 0.5
speed_max_mps = 1.5
max_turn_deg = 35.0
max_pitch_deg = 20.0
[fleet]
d_min_m = 5.0
mission_time_s = 200.0
"#;

fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::parse(text, Path::new("scenarios/x.toml"))
}

#[test]
fn a_missing_file_is_named_with_its_reason_once() {
    let missing = Path::new("/nonexistent-shoal-dir/m.toml");
    let Err(e) = Scenario::load(missing) else {
        panic!("a missing file loaded");
    };
    let Err(io) = std::fs::read_to_string(missing) else {
        panic!("a missing file was read");
    };
    let reason = io.to_string();
    let text = crate::fixtures::chained(&e);
    assert!(
        text.starts_with("/nonexistent-shoal-dir/m.toml: cannot read: "),
        "{text}"
    );
    // The OS words ("No such file or directory (os error 2)") once, not once per chain link.
    assert_eq!(text.matches(&reason).count(), 1, "{text}");
}

#[test]
fn good_file_parses_with_table5_defaults() -> Result<(), ScenarioError> {
    let s = parse(GOOD)?;
    assert_eq!(s.optimizer.populations, 20);
    assert_eq!(s.optimizer.particles, 50);
    assert_eq!(s.optimizer.iterations, 200);
    assert_eq!(s.optimizer.weights, [0.2, 0.1, 0.3, 0.1, 0.3]);
    assert_eq!(s.obstacles[0].inflated_radius(), 15.0);
    Ok(())
}

#[test]
fn bad_value_names_file_field_and_value() {
    let text = GOOD.replace("speed_max_mps = 1.5", "speed_max_mps = 0.1");
    let msg = parse(&text)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("scenarios/x.toml"), "{msg}");
    assert!(msg.contains("vehicles[0].speed_max_mps"), "{msg}");
    assert!(msg.contains("0.1"), "{msg}");
}

#[test]
fn start_inside_hard_obstacle_is_rejected() {
    let text = GOOD.replace("start = [1.0, 1.0, 1.0]", "start = [45.0, 50.0, 50.0]");
    let msg = parse(&text)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        msg.contains("vehicles[0].start") && msg.contains("H1"),
        "{msg}"
    );
}

#[test]
fn unknown_key_and_wrong_type_are_named() {
    let text = GOOD.replace("max_pitch_deg = 20.0", "max_pitch_deg = 20.0\nmax_pich = 3");
    let msg = parse(&text)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("max_pich"), "{msg}");
    let text = GOOD.replace("radius_m = 10.0", "radius_m = \"ten\"");
    let msg = parse(&text)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("radius_m") && msg.contains("x.toml"), "{msg}");
    assert!(msg.contains("field obstacles[0].radius_m"), "{msg}");
    // An array over several lines: the quoted line shows only the bad element, the path
    // names the field.
    let text = GOOD.replace(
        "centre = [50.0, 50.0, 50.0]",
        "centre = [\n  50.0,\n  \"x\",\n  50.0,\n]",
    );
    let msg = parse(&text)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        msg.contains("x.toml")
            && msg.contains("field obstacles[0].centre[1]")
            && msg.contains("line 11")
            && msg.contains("\"x\""),
        "{msg}"
    );
}

#[test]
fn duplicate_vehicle_and_zero_budget_are_rejected() {
    let dup = GOOD.to_string()
        + r#"
[[vehicles]]
id = "a"
kind = "auv"
start = [2.0, 1.0, 1.0]
goal = [98.0, 99.0, 99.0]
speed_min_mps = 0.5
speed_max_mps = 1.5
max_turn_deg = 35.0
max_pitch_deg = 20.0
"#;
    let msg = parse(&dup).err().map(|e| e.to_string()).unwrap_or_default();
    assert!(
        msg.contains("vehicles[1].id") && msg.contains("duplicates"),
        "{msg}"
    );
    let zero = GOOD.to_string() + "[optimizer]\niterations = 0\n";
    let msg = parse(&zero)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("optimizer.iterations"), "{msg}");
}

#[test]
fn vehicle_ids_must_be_usable_on_the_network() {
    for bad in ["", "auv 1", "auv/1", "auv*"] {
        let text = GOOD.replace("id = \"a\"", &format!("id = {bad:?}"));
        let msg = parse(&text)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            msg.contains("vehicles[0].id") && msg.contains("network"),
            "{bad:?}: {msg}"
        );
    }
}

#[test]
fn algorithm_names_round_trip() {
    for a in Algorithm::ALL {
        assert_eq!(a.as_str().parse::<Algorithm>(), Ok(a));
    }
    assert!("ga".parse::<Algorithm>().is_err());
}

#[test]
fn the_velocity_cap_is_the_algorithms_own_unless_the_file_sets_one() -> Result<(), ScenarioError> {
    let unset = parse(GOOD)?;
    assert_eq!(unset.optimizer.max_velocity_fraction, None);
    assert_eq!(unset.optimizer.velocity_cap(0.2), 0.2);
    assert_eq!(unset.optimizer.velocity_cap(0.1), 0.1);
    let set = parse(&(GOOD.to_string() + "[optimizer]\nmax_velocity_fraction = 0.05\n"))?;
    assert_eq!(set.optimizer.velocity_cap(0.2), 0.05);
    assert_eq!(set.optimizer.velocity_cap(0.1), 0.05);
    for bad in ["0.0", "1.5", "-0.1"] {
        let text = GOOD.to_string() + &format!("[optimizer]\nmax_velocity_fraction = {bad}\n");
        let msg = parse(&text)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            msg.contains("optimizer.max_velocity_fraction")
                && msg.contains(bad.trim_end_matches(".0")),
            "{bad}: {msg}"
        );
    }
    Ok(())
}

#[test]
fn plans_are_touched_up_unless_the_file_says_not() -> Result<(), ScenarioError> {
    assert!(parse(GOOD)?.optimizer.touch_up);
    let off = parse(&(GOOD.to_string() + "[optimizer]\ntouch_up = false\n"))?;
    assert!(!off.optimizer.touch_up);
    let msg = parse(&(GOOD.to_string() + "[optimizer]\ntouch_up = \"no\"\n"))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("touch_up"), "{msg}");
    Ok(())
}

#[test]
fn a_vehicle_executes_with_its_own_turn_radius_else_the_radius_its_plan_was_made_for(
) -> Result<(), ScenarioError> {
    // A fleet scenario with no turn radius leaves the simulator's default.
    let fleet = parse(GOOD)?;
    assert_eq!(fleet.execution_turn_radius_m(0), None);
    assert_eq!(fleet.execution_turn_radius_m(1), None);
    let own = parse(&GOOD.replace(
        "max_pitch_deg = 20.0",
        "max_pitch_deg = 20.0\nturn_radius_m = 12.5",
    ))?;
    assert_eq!(own.execution_turn_radius_m(0), Some(12.5));
    // The shipped Zhang et al. 2022 mission: R_AUV = 8 m (Table 2) is what its plan turns on.
    let epa = Scenario::parse(
        include_str!("../../../scenarios/epa-pso.toml"),
        Path::new("scenarios/epa-pso.toml"),
    )?;
    assert_eq!(epa.execution_turn_radius_m(0), Some(8.0));
    // The shipped CPP-DSMV mission: its U-turns are semicircles of R_min = 5 m.
    let cpp = Scenario::parse(
        include_str!("../../../scenarios/cpp-seabed.toml"),
        Path::new("scenarios/cpp-seabed.toml"),
    )?;
    assert_eq!(cpp.execution_turn_radius_m(0), Some(5.0));
    Ok(())
}

#[test]
fn a_goal_on_top_of_its_start_is_named() {
    let text = GOOD.replace("goal = [99.0, 99.0, 99.0]", "goal = [1.0, 1.5, 1.0]");
    let msg = parse(&text)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        msg.contains("scenarios/x.toml")
            && msg.contains("vehicles[0].goal")
            && msg.contains("[1.0, 1.5, 1.0]")
            && msg.contains("0.500 m from its start"),
        "{msg}"
    );
    // 1 m apart is a (short) path.
    let text = GOOD.replace("goal = [99.0, 99.0, 99.0]", "goal = [2.0, 1.0, 1.0]");
    assert!(parse(&text).is_ok());
}

/// The shipped Zhi & Zuo 2024 scenarios hold Tables 2–4 (one table unit 100 m, radii in km, 1–3
/// knots), each scenario the obstacles and AUVs §4.1.2 adds to the one before (scenario 3 with
/// HObs#4, which the table lists and the text never adds).
#[test]
fn the_shipped_amp_pso_scenarios_are_amp_pso_tables_2_to_4() -> Result<(), ScenarioError> {
    let obstacles = [
        ("HObs#1", ObstacleKind::Hard, [10.0, 10.0, 10.0], 0.3),
        ("SObs#1", ObstacleKind::Soft, [8.0, 2.0, 12.0], 0.2),
        ("SObs#2", ObstacleKind::Soft, [6.0, 8.0, 4.0], 0.15),
        ("HObs#2", ObstacleKind::Hard, [5.0, 5.0, 17.0], 0.25),
        ("HObs#3", ObstacleKind::Hard, [17.0, 14.0, 4.0], 0.15),
        ("SObs#3", ObstacleKind::Soft, [18.0, 10.0, 4.0], 0.2),
        ("SObs#4", ObstacleKind::Soft, [14.0, 4.0, 6.0], 0.15),
        ("HObs#4", ObstacleKind::Hard, [15.0, 4.0, 10.0], 0.2),
        ("HObs#5", ObstacleKind::Hard, [7.0, 15.0, 9.0], 0.2),
        ("SObs#5", ObstacleKind::Soft, [13.0, 16.0, 15.0], 0.2),
        ("SObs#6", ObstacleKind::Soft, [2.0, 14.0, 8.0], 0.2),
        ("SObs#7", ObstacleKind::Soft, [8.0, 2.0, 6.0], 0.2),
    ];
    let auvs = [
        ("auv1", [1.0, 3.0, 16.0], [18.0, 19.0, 4.0]),
        ("auv2", [3.0, 1.0, 16.0], [19.0, 19.0, 5.0]),
        ("auv3", [1.0, 1.0, 17.0], [18.0, 18.0, 3.0]),
        ("auv4", [5.0, 1.0, 15.0], [19.0, 18.0, 3.0]),
        ("auv5", [1.0, 5.0, 15.0], [18.0, 19.0, 3.0]),
    ];
    let m = |p: [f64; 3]| p.map(|c| c * 100.0);
    // Scenario n: its obstacles' and AUVs' counts, mission time t_e.
    for (n, n_obstacles, n_auvs, t_e) in [(1, 3, 2, 2100.0), (2, 7, 3, 2300.0), (3, 12, 5, 2700.0)]
    {
        let file = format!(
            "{}/../scenarios/amp-pso-{n}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let s = Scenario::load(Path::new(&file))?;
        assert_eq!(
            (s.bounds.min, s.bounds.max),
            ([0.0; 3], [2000.0; 3]),
            "{file}"
        );
        assert_eq!(s.obstacles.len(), n_obstacles, "{file}");
        for (id, kind, centre, radius_km) in &obstacles[..n_obstacles] {
            let o = s.obstacles.iter().find(|o| o.id == *id);
            let o = o.unwrap_or_else(|| panic!("{file}: no {id}"));
            assert_eq!(
                (o.kind, o.centre, o.radius_m, o.inflation_m),
                (*kind, m(*centre), radius_km * 1000.0, 50.0),
                "{file}: {id}"
            );
        }
        assert_eq!(s.vehicles.len(), n_auvs, "{file}");
        for (v, (id, start, goal)) in s.vehicles.iter().zip(&auvs) {
            assert_eq!((v.id.as_str(), v.start, v.goal), (*id, m(*start), m(*goal)));
            assert!((v.speed_min_mps - KNOT_MPS).abs() < 1e-3, "{file}: {id}");
            assert!(
                (v.speed_max_mps - 3.0 * KNOT_MPS).abs() < 1e-3,
                "{file}: {id}"
            );
            assert_eq!(
                (v.max_turn_deg, v.max_pitch_deg),
                (35.0, 20.0),
                "{file}: {id}"
            );
        }
        assert_eq!(
            (s.fleet.mission_time_s, s.fleet.d_min_m),
            (t_e, 50.0),
            "{file}"
        );
        assert_eq!(s.optimizer.waypoints, 30, "{file}");
        assert_eq!(s.optimizer.weights, [0.2, 0.1, 0.3, 0.1, 0.3], "{file}");
    }
    Ok(())
}

/// The message of a scenario that must not parse (empty when it parses).
fn refusal(text: &str) -> String {
    parse(text).err().map(|e| e.to_string()).unwrap_or_default()
}

#[test]
fn a_billion_particles_is_refused_naming_file_field_value_and_limit() {
    let text = GOOD.to_string() + "[optimizer]\nparticles = 1000000000\n";
    assert_eq!(
        refusal(&text),
        "scenarios/x.toml: field `optimizer.particles` = 1000000000: is over the limit 10000 (limits::MAX_PARTICLES)"
    );
    for (line, field) in [
        ("populations = 257", "optimizer.populations"),
        ("iterations = 1000000000000", "optimizer.iterations"),
        ("waypoints = 1000000", "optimizer.waypoints"),
        ("threads = 100000", "optimizer.threads"),
    ] {
        let msg = refusal(&format!("{GOOD}[optimizer]\n{line}\n"));
        assert!(
            msg.contains(field) && msg.contains("over the limit"),
            "{msg}"
        );
    }
}

#[test]
fn budgets_within_their_own_limits_are_refused_when_their_product_is_absurd() {
    // One vehicle: 10,000 particles × 1,000,000 iterations = 10^10 evaluations, exactly the
    // limit, with the single-population PSO; AMP-PSO's 20 populations and 20 leader particles
    // make it (20 × 10,000 + 20) × 10^6 = 200,020,000,000.
    let pso = format!(
        "{GOOD}[optimizer]\nalgorithm = \"pso\"\nparticles = 10000\niterations = 1000000\n"
    );
    assert_eq!(refusal(&pso), "");
    let amp = pso.replace("\"pso\"", "\"amp-pso\"");
    let msg = refusal(&amp);
    assert!(
        msg.contains("optimizer.iterations")
            && msg.contains("200020000000 vehicle evaluations")
            && msg.contains("MAX_EVALUATIONS"),
        "{msg}"
    );
}

#[test]
fn speeds_outside_what_a_vehicle_can_do_are_refused() {
    for (from, to) in [
        ("speed_min_mps = 0.5", "speed_min_mps = 1e-300"),
        ("speed_min_mps = 0.5", "speed_min_mps = 0.009"),
        ("speed_max_mps = 1.5", "speed_max_mps = 20.5"),
        ("speed_max_mps = 1.5", "speed_max_mps = 1e300"),
    ] {
        let msg = refusal(&GOOD.replace(from, to));
        assert!(msg.contains("[0.01, 20] m/s"), "{to}: {msg}");
    }
    // The bounds themselves are speeds a vehicle may have.
    let edge = GOOD
        .replace("speed_min_mps = 0.5", "speed_min_mps = 0.01")
        .replace("speed_max_mps = 1.5", "speed_max_mps = 20.0");
    assert_eq!(refusal(&edge), "");
}

#[test]
fn an_obstacle_or_a_separation_larger_than_the_box_is_refused() {
    // The 100 m cube's diagonal is 173.2 m.
    let msg = refusal(&GOOD.replace("radius_m = 10.0", "radius_m = 1e300"));
    assert!(
        msg.contains("obstacles[0].radius_m") && msg.contains("diagonal 173.2 m"),
        "{msg}"
    );
    let msg = refusal(&GOOD.replace("d_min_m = 5.0", "d_min_m = 174.0"));
    assert!(msg.contains("fleet.d_min_m"), "{msg}");
    assert_eq!(
        refusal(&GOOD.replace("d_min_m = 5.0", "d_min_m = 173.0")),
        ""
    );
    let msg = refusal(&GOOD.replace("mission_time_s = 200.0", "mission_time_s = 1e12"));
    assert!(msg.contains("fleet.mission_time_s") && msg.contains("MAX_MISSION_TIME_S"));
}

#[test]
fn a_scenario_file_over_the_size_limit_or_without_end_is_refused_when_read(
) -> Result<(), Box<dyn std::error::Error>> {
    let dir = tempfile::tempdir()?;
    let big = dir.path().join("big.toml");
    let limit = crate::limits::MAX_SCENARIO_BYTES as usize;
    // GOOD padded with a comment to one byte over the limit.
    let padding = limit + 1 - GOOD.len() - 2;
    std::fs::write(&big, format!("{GOOD}#{}\n", "x".repeat(padding)))?;
    let msg = Scenario::load(&big)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        msg.contains("big.toml") && msg.contains(&format!("limit of {limit} bytes")),
        "{msg}"
    );
    // One byte less is read (and is the good scenario).
    std::fs::write(&big, format!("{GOOD}#{}\n", "x".repeat(padding - 1)))?;
    assert!(Scenario::load(&big).is_ok());
    let zero = Path::new("/dev/zero");
    if zero.exists() {
        let msg = Scenario::load(zero)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            msg.contains("/dev/zero") && msg.contains("limit of"),
            "{msg}"
        );
    }
    Ok(())
}

/// `[origin]` ties the scenario to WGS-84; it survives the TOML the coordinator sends its agents.
#[test]
fn an_origin_is_read_checked_and_written_back() -> Result<(), ScenarioError> {
    let with = |origin: &str| GOOD.replace("[[obstacles]]", &format!("{origin}\n[[obstacles]]"));
    let s = parse(&with(
        "[origin]\nlat_deg = 31.5\nlon_deg = -22.0\nalt_m = -100.0",
    ))?;
    assert_eq!(
        s.origin,
        Some(crate::geo::GeoOrigin::new(31.5, -22.0, -100.0))
    );
    let Ok(text) = toml::to_string(&s) else {
        panic!("the scenario does not serialise");
    };
    assert_eq!(parse(&text)?, s);
    assert_eq!(parse(GOOD)?.origin, None);
    let cases = [
        (
            "[origin]\nlat_deg = 95.0\nlon_deg = 0.0\nalt_m = 0.0",
            "field `origin.lat_deg` = 95: must be a latitude in [-89, 89] degrees",
        ),
        (
            "[origin]\nlat_deg = 0.0\nlon_deg = 181.0\nalt_m = 0.0",
            "field `origin.lon_deg` = 181: must be a longitude in [-180, 180] degrees",
        ),
        (
            "[origin]\nlat_deg = 0.0\nlon_deg = 0.0\nalt_m = 8950.0",
            "field `origin.alt_m` = 8950: puts bounds.max[2] = 100 at 9050 m above mean sea level",
        ),
        (
            "[origin]\nlat_deg = 0.0\nlon_deg = 0.0\nalt_m = 0.0\ndepth = 1.0",
            "unknown field `depth`",
        ),
    ];
    for (origin, expected) in cases {
        let msg = parse(&with(origin))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(msg.starts_with("scenarios/x.toml: "), "{msg}");
        assert!(msg.contains(expected), "{origin}: {msg}");
    }
    // 200 km of box east of an origin at 89°N reaches over the pole, 111 km away.
    let wide = with("[origin]\nlat_deg = 89.0\nlon_deg = 0.0\nalt_m = -100.0").replace(
        "max = [100.0, 100.0, 100.0]",
        "max = [200000.0, 100.0, 100.0]",
    );
    let msg = parse(&wide)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(msg.contains("field `origin.lat_deg` = 89: the scenario box reaches 200000 m from the origin, over the pole 110574 m away"), "{msg}");
    Ok(())
}

/// Scenario 3 is placed at sea with its surface, z = 2000 m, at 0 m above mean sea level.
#[test]
fn scenario_3_lies_at_sea_with_its_surface_at_sea_level() -> Result<(), ScenarioError> {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-3.toml");
    let s = Scenario::load(Path::new(file))?;
    let Some(o) = s.origin else {
        panic!("{file} has no [origin]");
    };
    assert_eq!(o.alt_m + s.bounds.max[2], 0.0);
    assert!(o.check().is_ok());
    Ok(())
}
