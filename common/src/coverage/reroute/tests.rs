use super::*;
use crate::coverage::test_map;
use std::f64::consts::PI;

/// A 198 m × 198 m flat map (2 m cells at height 0), with `block` raised 50 m (a cliff: its
/// edges are impassable), the crawler 8 m clear of impassable ground, turning at 5 m, its
/// reference point 1.5 m over the seabed.
fn ground(block: Option<[usize; 4]>) -> CrawlerGround {
    let n = 100;
    let mut z = vec![0.0; n * n];
    if let Some([i0, i1, j0, j1]) = block {
        for j in j0..j1 {
            for i in i0..i1 {
                z[j * n + i] = 50.0;
            }
        }
    }
    CrawlerGround {
        map: test_map(n, z),
        area: Rect::new(0.0, 0.0, 198.0, 198.0),
        safety_clearance_m: 8.0,
        min_turn_radius_m: 5.0,
        sensor_height_m: 1.5,
    }
}

/// Inside a sphere of radius 20 m round (100, 100, 0).
fn sphere(p: &Vec3) -> bool {
    (p - Vec3::new(100.0, 100.0, 0.0)).norm() < 20.0
}

fn length(points: &[Vec3]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Radius of the circle through three points (∞ when they are in line).
fn circumradius(a: &Vec3, b: &Vec3, c: &Vec3) -> f64 {
    let (ab, bc, ca) = ((b - a).norm(), (c - b).norm(), (a - c).norm());
    let cross = (b - a).cross(&(c - a)).norm();
    if cross < 1e-12 {
        f64::INFINITY
    } else {
        ab * bc * ca / (2.0 * cross)
    }
}

#[test]
fn a_way_round_a_sphere_on_flat_ground_leaves_it_and_rejoins_the_row() -> Result<(), String> {
    let g = ground(None);
    let way = g
        .ways_round(&sphere)
        .between(Pose2::new(20.0, 100.0, 0.0), Pose2::new(180.0, 100.0, 0.0))
        .ok_or("no way round a 20 m sphere on open ground")?;
    let (first, last) = (way[0], way[way.len() - 1]);
    assert!(
        (first - Vec3::new(20.0, 100.0, 1.5)).norm() < 1e-9,
        "{first}"
    );
    assert!(
        (last - Vec3::new(180.0, 100.0, 1.5)).norm() <= 1.0,
        "{last}"
    );
    for p in &way {
        // On the seabed plus the sensor height, outside the sphere, on passable ground.
        assert!((p.z - 1.5).abs() < 1e-9, "{p}");
        assert!(!sphere(p), "{p} inside the sphere");
        assert!(g.passable(p.x, p.y), "{p}");
    }
    // At 1.5 m over the seabed the sphere is a disc of radius ρ = √(20² − 1.5²) = 19.944 m.
    // The shortest way round it from 80 m before its centre to 80 m past: two tangents of
    // √(80² − ρ²) = 77.474 m and the arc between them, ρ(π − 2 acos(ρ/80)) = 10.05 m: 165.00 m.
    // The weighted search is at most 1.5 × the shortest.
    let l = length(&way);
    assert!(l > 164.99 && l < 1.5 * 165.0, "{l}");
    // No turn tighter than the 5 m radius (thinning moves points by at most 5 cm).
    for w in way.windows(3) {
        let r = circumradius(&w[0], &w[1], &w[2]);
        assert!(r > 4.8, "a turn of radius {r} m at {}", w[1]);
    }
    Ok(())
}

#[test]
fn the_way_round_takes_the_side_the_seabed_leaves_open() -> Result<(), String> {
    // A 50 m cliff north of the sphere (cells 40..60 × 60..80: x 80–120 m, y 120–160 m) and
    // its 8 m clearance close the northern way: the crawler goes south.
    let g = ground(Some([40, 60, 60, 80]));
    let way = g
        .ways_round(&sphere)
        .between(Pose2::new(20.0, 100.0, 0.0), Pose2::new(180.0, 100.0, 0.0))
        .ok_or("no way round by the south")?;
    let min_y = way.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    let max_y = way.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
    assert!(
        min_y < 80.0,
        "it did not pass south of the sphere: min y {min_y}"
    );
    assert!(max_y < 110.0, "it went north: max y {max_y}");
    for p in &way {
        assert!(g.passable(p.x, p.y), "{p}");
        assert!(!sphere(p), "{p}");
    }
    Ok(())
}

#[test]
fn a_keep_out_across_the_whole_area_leaves_no_way() {
    let g = ground(None);
    // A band across the area from west to east between the two poses.
    let wall = |p: &Vec3| (p.y - 100.0).abs() < 10.0;
    let way = g.ways_round(&wall).between(
        Pose2::new(100.0, 50.0, PI / 2.0),
        Pose2::new(100.0, 150.0, PI / 2.0),
    );
    assert!(way.is_none(), "{way:?}");
}

#[test]
fn the_crawler_point_is_on_the_map_plus_the_sensor_height() {
    let g = ground(Some([0, 100, 0, 100]));
    // The whole map raised to 50 m.
    assert!((g.point(37.0, 81.0).z - 51.5).abs() < 1e-9);
    // Passable: inside the area and 8 m from impassable cells (none on an even plateau).
    assert!(g.passable(100.0, 100.0));
    assert!(!g.passable(-1.0, 100.0));
    assert!(!g.passable(100.0, 199.0));
}

#[test]
fn a_straight_drive_is_judged_by_the_clearance_it_keeps_from_impassable_ground() {
    // A 50 m cliff across the whole map from x = 120 m (cells 60..100): its foot is
    // impassable, the crawler must keep 8 m from it.
    let g = ground(Some([60, 100, 0, 100]));
    let edge = (0..1200)
        .map(|k| f64::from(k) * 0.1)
        .find(|x| g.map.clearance_to_impassable(*x, 100.0) <= 0.0)
        .unwrap_or(f64::NAN);
    assert!(
        edge > 110.0 && edge < 121.0,
        "the cliff's foot at x = {edge}"
    );
    let at = |x: f64, y: f64| Vec3::new(x, y, 0.0);
    // Far from the cliff: drivable; ending 4 m from its foot (8 m asked, 0.5 m of slack): not.
    assert!(g.drivable(&at(20.0, 100.0), &at(edge - 10.0, 100.0)));
    assert!(!g.drivable(&at(20.0, 100.0), &at(edge - 4.0, 100.0)));
    // A crawler already 5 m from the foot may drive away from it, or along it, not closer.
    assert!(g.drivable(&at(edge - 5.0, 100.0), &at(edge - 30.0, 100.0)));
    assert!(g.drivable(&at(edge - 5.0, 100.0), &at(edge - 5.0, 60.0)));
    assert!(!g.drivable(&at(edge - 5.0, 100.0), &at(edge - 4.0, 100.0)));
    assert!(g.drivable(&at(edge - 5.0, 100.0), &at(edge - 4.6, 100.0)));
    // On the map but never across the cliff's foot, wherever it starts.
    assert!(!g.drivable(&at(20.0, 100.0), &at(180.0, 100.0)));
    // Outside the area (x < 0), it may drive back in but not farther out.
    assert!(g.drivable(&at(-3.0, 100.0), &at(20.0, 100.0)));
    assert!(!g.drivable(&at(20.0, 100.0), &at(-3.0, 100.0)));
    assert!(!g.drivable(&at(-3.0, 100.0), &at(-6.0, 100.0)));
}
