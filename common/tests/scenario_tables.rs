//! The `[currents]`, `[energy]` and `[inspection]` tables (Zhang et al. 2022 and Hu et al. 2023): the shipped
//! scenarios load, and bad values are refused with the file, the field and the value.

use std::path::{Path, PathBuf};

use shoal_common::scenario::{Algorithm, Scenario};

fn shipped(name: &str) -> (String, PathBuf) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(format!("{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(!text.is_empty(), "cannot read {}", path.display());
    (text, path)
}

/// The error message of `text` (with `from` replaced by `to`), which must fail.
fn refused(name: &str, from: &str, to: &str) -> String {
    let (text, path) = shipped(name);
    assert!(text.contains(from), "{name} has no {from:?}");
    match Scenario::parse(&text.replacen(from, to, 1), &path) {
        Ok(_) => panic!("{name} with {to:?} was accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn shipped_scenarios_load() {
    for name in ["epa-pso", "cages-a", "cages-b", "cages-fleet"] {
        let (text, path) = shipped(name);
        let s = match Scenario::parse(&text, &path) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(s.name, name);
    }
    let (text, path) = shipped("epa-pso");
    let s = Scenario::parse(&text, &path).ok();
    let s = s.as_ref();
    assert_eq!(s.map(|s| s.optimizer.algorithm), Some(Algorithm::EpaPso));
    assert_eq!(s.map(|s| s.energy.path_points), Some(500));
    // Hills alone make a seabed (Zhang et al. 2022, eq. (1)): 45 m at the centre of h1.
    let z = s.and_then(|s| s.terrain()).map(|t| t.elevation(20.0, 20.0));
    assert!(z.is_some_and(|z| z > 45.0 && z < 46.0), "{z:?}");
}

#[test]
fn bad_energy_and_current_values_name_the_field() {
    let e = refused(
        "epa-pso",
        "min_turn_radius_m = 8.0",
        "min_turn_radius_m = -1.0",
    );
    assert!(
        e.contains("epa-pso.toml") && e.contains("energy.min_turn_radius_m") && e.contains("-1"),
        "{e}"
    );
    let e = refused("epa-pso", "path_points = 500", "path_points = 1");
    assert!(e.contains("energy.path_points") && e.contains("= 1"), "{e}");
    let e = refused(
        "epa-pso",
        "surface_velocity_mps = [-1.0, -1.0]",
        "surface_velocity_mps = [nan, -1.0]",
    );
    assert!(e.contains("currents.surface_velocity_mps"), "{e}");
    let e = refused("epa-pso", "mu = 0.5", "mu = 0.5\nspeed = 3");
    assert!(e.contains("speed"), "{e}");
    // A fleet cannot take a single-AUV planner.
    let e = refused(
        "cages-fleet",
        "algorithm = \"de-pso\"",
        "algorithm = \"epa-pso\"",
    );
    assert!(
        e.contains("optimizer.algorithm") && e.contains("2 vehicles"),
        "{e}"
    );
}

#[test]
fn bad_inspection_values_name_the_field() {
    let e = refused("cages-a", "standoff_m = 5.0", "standoff_m = 0.5");
    assert!(
        e.contains("inspection.standoff_m") && e.contains("0.5") && e.contains("inflation_m"),
        "{e}"
    );
    let e = refused(
        "cages-a",
        "standoff_m = 5.0",
        "standoff_m = 5.0\ncages = [\"Z9\"]",
    );
    assert!(e.contains("inspection.cages[0]") && e.contains("Z9"), "{e}");
    let e = refused(
        "cages-a",
        "goal = [0.0, 0.0, 0.0]",
        "goal = [10.0, 0.0, 0.0]",
    );
    assert!(
        e.contains("vehicles[0].goal") && e.contains("returns to its base"),
        "{e}"
    );
    // A tour algorithm needs the [inspection] table.
    let e = refused(
        "epa-pso",
        "algorithm = \"epa-pso\"",
        "algorithm = \"de-pso\"",
    );
    assert!(
        e.contains("optimizer.algorithm") && e.contains("[inspection]"),
        "{e}"
    );
    // And the [inspection] table needs a tour algorithm: another planner would send the AUV
    // nowhere (its goal is its start) and call that feasible.
    for other in ["amp-pso", "ipso", "epa-pso"] {
        let e = refused(
            "cages-a",
            "algorithm = \"de-pso\"",
            &format!("algorithm = \"{other}\""),
        );
        assert!(
            e.contains("optimizer.algorithm")
                && e.contains(other)
                && e.contains("[inspection]")
                && e.contains("de-pso, ldiw-pso or lcpso"),
            "{e}"
        );
    }
}
