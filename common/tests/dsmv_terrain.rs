//! The terrain of `scenarios/ipso-dsmv.toml` has the character Lu et al. 2023, §2.1 describes: a
//! seamount summit whose slopes are mostly below 5°, with mountains whose flanks are steeper
//! than 10°; and the fleet model plans a crawler on it as Lu et al. 2023, §2.4 says (B-spline through
//! the control points, draped on the seabed).

use std::path::Path;

use shoal_common::cost::FleetModel;
use shoal_common::scenario::Scenario;

fn dsmv() -> Result<Scenario, Box<dyn std::error::Error>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/ipso-dsmv.toml");
    Ok(Scenario::load(&path)?)
}

#[test]
fn summit_is_gentle_and_mountain_flanks_are_steep() -> Result<(), Box<dyn std::error::Error>> {
    let s = dsmv()?;
    let Some(t) = s.terrain() else {
        panic!("no terrain")
    };
    let Some(seabed) = &s.seabed else {
        panic!("no seabed")
    };
    // Away from every mountain (beyond 2.5 spreads), on a 1 m grid.
    let (mut gentle, mut total) = (0usize, 0usize);
    for i in 0..=200 {
        for j in 0..=200 {
            let (x, y) = (i as f64, j as f64);
            let far = seabed.mountains.iter().all(|m| {
                let u = (x - m.centre[0]) / m.spread_m[0];
                let v = (y - m.centre[1]) / m.spread_m[1];
                u * u + v * v > 2.5 * 2.5
            });
            if far {
                total += 1;
                gentle += usize::from(t.slope_deg(x, y) < 5.0);
            }
            let z = t.elevation(x, y);
            assert!(
                (0.0..=9.5).contains(&z),
                "z = {z} at ({x}, {y}) leaves the 10 m box"
            );
        }
    }
    assert!(total > 10_000);
    assert!(gentle as f64 / total as f64 > 0.95, "{gentle}/{total}");
    // Every mountain has a flank steeper than 10°, one spread/√2 from its peak (where a
    // Gaussian is steepest).
    for m in &seabed.mountains {
        let r = m.spread_m[0] / 2f64.sqrt();
        let steepest = (0..36)
            .map(|k| {
                let a = k as f64 * 10f64.to_radians();
                t.slope_deg(m.centre[0] + r * a.cos(), m.centre[1] + r * a.sin())
            })
            .fold(0.0, f64::max);
        assert!(steepest > 10.0, "{:?}: {steepest}", m.centre);
    }
    Ok(())
}

#[test]
fn a_crawler_chromosome_decodes_to_a_draped_spline() -> Result<(), Box<dyn std::error::Error>> {
    let s = dsmv()?;
    let model = FleetModel::new(&s);
    // z genes are pinned to the bottom of the box (a crawler's z follows the seabed).
    assert_eq!(model.lower[2], model.upper[2]);
    assert_eq!(model.lower[0..2], [0.0, 0.0]);
    // Control points on the straight line; speeds 1.0, 0.9, 0.8 for the 4 control legs.
    let genes = [
        50.0, 50.0, 0.0, 100.0, 100.0, 0.0, 150.0, 150.0, 0.0, 1.0, 0.9, 0.8,
    ];
    let path = model.decode(0, &genes);
    assert_eq!(path.points.len(), s.crawler.samples);
    assert_eq!(path.speeds.len(), s.crawler.samples - 1);
    let Some(t) = s.terrain() else {
        panic!("no terrain")
    };
    for p in &path.points {
        // On the diagonal, and 0.5 m above the seabed.
        assert!((p.x - p.y).abs() < 1e-9);
        assert!((p.z - t.elevation(p.x, p.y) - 0.5).abs() < 1e-12);
    }
    // The first legs take speed gene 1, the last ones gene 3 (the goal leg reuses δ_M).
    assert_eq!(path.speeds[0], 1.0);
    assert_eq!(path.speeds[path.speeds.len() - 1], 0.8);
    let eval = model.evaluate(&genes);
    let Some(c) = eval.vehicles[0].crawler else {
        panic!("no crawler objective")
    };
    // The straight line is the standardisation's reference: length 0.5, energy 0.1, and the
    // straight line crosses hazard pa (slip 1, intrusion penalty).
    assert!(c > 0.5 + 0.1 + 0.2 - 1e-9, "{c}");
    assert!(eval.vehicles[0].hard > 1.0 && eval.vehicles[0].hard_hits == 1);
    Ok(())
}
