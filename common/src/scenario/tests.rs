//! Unit tests of `scenario`.

use super::*;

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
    // The shipped seed 001 mission: R_AUV = 8 m (Table 2) is what its plan turns on.
    let epa = Scenario::parse(
        include_str!("../../../scenarios/epa-pso.toml"),
        Path::new("scenarios/epa-pso.toml"),
    )?;
    assert_eq!(epa.execution_turn_radius_m(0), Some(8.0));
    // The shipped seed 002 mission: its U-turns are semicircles of R_min = 5 m.
    let cpp = Scenario::parse(
        include_str!("../../../scenarios/cpp-seabed.toml"),
        Path::new("scenarios/cpp-seabed.toml"),
    )?;
    assert_eq!(cpp.execution_turn_radius_m(0), Some(5.0));
    Ok(())
}
