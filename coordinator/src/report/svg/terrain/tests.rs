//! Unit tests of the seabed layer: relief, hazards and the figures drawn over it.

use super::*;

#[test]
fn contour_step_keeps_about_a_dozen_contours() {
    assert_eq!(contour_step(6.0), 1.0);
    assert_eq!(contour_step(20.0), 2.0);
    assert_eq!(contour_step(55.0), 5.0);
    assert_eq!(contour_step(130.0), 20.0);
}

#[test]
fn shade_runs_from_sand_to_brown_and_clamps() {
    assert_eq!(shade(0.0), RGBColor(245, 238, 220));
    assert_eq!(shade(1.0), RGBColor(110, 80, 50));
    assert_eq!(shade(2.0), shade(1.0));
    assert_eq!(shade(0.5), RGBColor(178, 159, 135));
}

/// The side view draws the seabed under AUVs of a scenario with both (seabed-fleet), not
/// under a lone crawler (ipso-dsmv) nor without a seabed (amp-pso-1); the picture of a
/// seabed-fleet plan says so.
#[test]
fn the_seabed_is_drawn_under_auvs_only() -> anyhow::Result<()> {
    let load = |name: &str| {
        Scenario::load(std::path::Path::new(&format!(
            "{}/../scenarios/{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        )))
    };
    let fleet = load("seabed-fleet")?;
    assert!(has_swimmer_over_seabed(&fleet));
    assert!(!has_swimmer_over_seabed(&load("ipso-dsmv")?));
    assert!(!has_swimmer_over_seabed(&load("amp-pso-1")?));
    let mut fleet_small = fleet.clone();
    fleet_small.optimizer.iterations = 2;
    let plan = crate::planning::planner::plan_in_process(&fleet_small, None, &mut |_| {});
    let svg = crate::report::svg::render_plan(&fleet_small, &plan)?;
    assert!(svg.contains("dots: seabed"));
    Ok(())
}
