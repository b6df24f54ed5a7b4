//! Unit tests of `execute::repair`.

use super::*;
use shoal_common::coverage::reroute::CrawlerGround;
use shoal_common::scenario::{Obstacle, ObstacleKind};
use std::time::Duration;

fn scenario() -> Result<Scenario, Box<dyn std::error::Error>> {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/amp-pso-1.toml");
    let mut s = Scenario::load(std::path::Path::new(file))?;
    s.bounds.min = [0.0, 0.0, 0.0];
    s.bounds.max = [2000.0, 2000.0, 400.0];
    s.obstacles.clear();
    s.vehicles.truncate(2);
    for v in &mut s.vehicles {
        v.speed_min_mps = 0.5;
        v.speed_max_mps = 2.0;
    }
    Ok(s)
}

/// A square tour from (200, 200): east 1000 m, north 1000 m, back west and south, 1 m/s.
fn tour() -> Trajectory {
    let p = |x: f64, y: f64| Vec3::new(x, y, 200.0);
    Trajectory {
        times: vec![0.0, 1000.0, 2000.0, 3000.0, 4000.0],
        points: vec![
            p(200.0, 200.0),
            p(1200.0, 200.0),
            p(1200.0, 1200.0),
            p(200.0, 1200.0),
            p(200.0, 200.0),
        ],
    }
}

fn request<'a>(s: &'a Scenario, current: &'a Trajectory, others: &'a [Trajectory]) -> Request<'a> {
    Request {
        scenario: s,
        vehicle: 0,
        t0: 500.0,
        p0: Vec3::new(700.0, 200.0, 200.0),
        heading: Some(Vec3::new(1.0, 0.0, 0.0)),
        current,
        resume_s: None,
        others,
        arrival_s: 4000.0,
        budget: Duration::from_millis(100),
        separation_buffer_m: 0.0,
        seed: 1,
        ground: None,
        stop: None,
    }
}

#[test]
fn an_unblocked_tour_is_kept_as_it_is() -> Result<(), Box<dyn std::error::Error>> {
    let s = scenario()?;
    let plan = tour();
    let r = repair(&request(&s, &plan, &[]));
    assert!(r.safe && r.hard_hits == 0);
    // From (700, 200) at t = 500 on: the same corners at the same times.
    assert_eq!(r.trajectory.points[1..], plan.points[1..]);
    for (a, b) in r
        .trajectory
        .times
        .iter()
        .zip([500.0, 1000.0, 2000.0, 3000.0, 4000.0])
    {
        assert!((a - b).abs() < 1e-9, "{:?}", r.trajectory.times);
    }
    Ok(())
}

/// A vehicle that held at (400, 200) from t = 200 s and resumes at t = 2500 s goes on
/// from where it stopped: every corner its plan passed meanwhile is still visited. Taken
/// from t0 instead, the rest would begin past (1200, 200) and (1200, 1200).
#[test]
fn a_held_vehicle_resumes_where_it_stopped() -> Result<(), Box<dyn std::error::Error>> {
    let s = scenario()?;
    let plan = tour();
    let mut q = request(&s, &plan, &[]);
    q.t0 = 2500.0;
    q.p0 = Vec3::new(400.0, 200.0, 200.0);
    q.heading = None;
    q.resume_s = Some(200.0);
    let r = repair(&q);
    assert!(r.safe, "{r:?}");
    assert_eq!(r.trajectory.points[0], q.p0);
    assert_eq!(r.trajectory.points[1..], plan.points[1..]);
    assert!((r.trajectory.times[0] - 2500.0).abs() < 1e-9);
    // 3800 m left at the plan's 1 m/s: late, past the plan's 4000 s.
    assert!(r.trajectory.arrival() > 4000.0, "{:?}", r.trajectory.times);
    q.resume_s = None;
    let skipped = repair(&q);
    assert!(!skipped
        .trajectory
        .points
        .contains(&Vec3::new(1200.0, 200.0, 200.0)));
    Ok(())
}

#[test]
fn a_blocked_leg_is_gone_round_and_every_later_corner_kept(
) -> Result<(), Box<dyn std::error::Error>> {
    let mut s = scenario()?;
    // On the north-bound leg, floor to surface: the way round is east or west of it.
    for z in [100.0, 300.0] {
        s.obstacles.push(Obstacle {
            id: format!("new{z}"),
            kind: ObstacleKind::Hard,
            centre: [1200.0, 700.0, z],
            radius_m: 100.0,
            inflation_m: 50.0,
        });
    }
    let plan = tour();
    let r = repair(&request(&s, &plan, &[]));
    assert!(r.safe, "{r:?}");
    for w in r.trajectory.points.windows(2) {
        assert!(!blocked(&s.obstacles, &w[0], &w[1]));
    }
    // The inspection corners are all still there, in order, after the detour.
    let corners = &plan.points[1..];
    let mut at = 0;
    for p in &r.trajectory.points {
        if at < corners.len() && (p - corners[at]).norm() < 1e-9 {
            at += 1;
        }
    }
    assert_eq!(at, corners.len(), "{:?}", r.trajectory.points);
    // Longer than the plan's 3500 m from (700, 200), flown faster to keep the arrival.
    let length: f64 = r
        .trajectory
        .points
        .windows(2)
        .map(|w| (w[1] - w[0]).norm())
        .sum();
    assert!(length > 3500.0 + 10.0, "{length}");
    assert!((r.trajectory.arrival() - 4000.0).abs() < 1e-6);
    Ok(())
}

#[test]
fn a_repair_that_meets_another_vehicle_is_not_safe() -> Result<(), Box<dyn std::error::Error>> {
    let s = scenario()?;
    let plan = tour();
    // The other vehicle waits at the first corner.
    let p = Vec3::new(1200.0, 200.0, 200.0);
    let other = Trajectory {
        times: vec![0.0, 5000.0],
        points: vec![p, p],
    };
    let others = [plan.clone(), other];
    let r = repair(&request(&s, &plan, &others));
    assert!(!r.safe && r.min_separation_m < 1.0, "{r:?}");
    Ok(())
}

#[test]
fn a_repair_that_only_keeps_d_min_is_retimed_to_keep_the_buffer(
) -> Result<(), Box<dyn std::error::Error>> {
    let s = scenario()?;
    let plan = tour();
    // The other vehicle drives north at 1 m/s along x = 950 and crosses the first leg
    // (y = 200) 55·√2 s after this vehicle does (t = 750): perpendicular at equal speeds,
    // they pass 55 m apart. 5 % faster, this vehicle crosses at 737.5 s and they pass
    // 65.45 m apart; 5 % slower, 45.02 m (both by hand, sampled every 0.01 s).
    let crossing = 750.0 + 55.0 * 2f64.sqrt();
    let other = Trajectory {
        times: vec![0.0, 5000.0],
        points: vec![
            Vec3::new(950.0, 200.0 - crossing, 200.0),
            Vec3::new(950.0, 200.0 + 5000.0 - crossing, 200.0),
        ],
    };
    let others = [plan.clone(), other];
    // Without a buffer the on-time repair (55 m) is kept.
    let r = repair(&request(&s, &plan, &others));
    assert!(r.safe, "{r:?}");
    assert!((r.min_separation_m - 55.0).abs() < 0.05, "{r:?}");
    assert!((r.trajectory.arrival() - 4000.0).abs() < 1e-6);
    // With a 10 m buffer, the first timing that keeps 60 m: the first leg (the closest
    // approach is on it) in 0.95 × 500 s, not 1.05 × (45 m); the three later legs take
    // 3025 s in all, so the arrival stays at 4000 s.
    let mut req = request(&s, &plan, &others);
    req.separation_buffer_m = 10.0;
    let r = repair(&req);
    assert!(r.safe, "{r:?}");
    assert!((r.min_separation_m - 65.45).abs() < 0.05, "{r:?}");
    assert!((r.trajectory.times[1] - 975.0).abs() < 1e-6, "{r:?}");
    assert!((r.trajectory.arrival() - 4000.0).abs() < 1e-6, "{r:?}");
    for (w, t) in r
        .trajectory
        .points
        .windows(2)
        .zip(r.trajectory.times.windows(2))
    {
        let speed = (w[1] - w[0]).norm() / (t[1] - t[0]);
        assert!((0.5..=2.0).contains(&speed), "{speed}");
    }
    // A buffer no timing keeps falls back to the on-time repair, which keeps d_min.
    req.separation_buffer_m = 60.0;
    let r = repair(&req);
    assert!(r.safe && (r.min_separation_m - 55.0).abs() < 0.05, "{r:?}");
    Ok(())
}

#[test]
fn retiming_keeps_the_arrival_only_where_the_speed_range_allows() {
    // Two 100 m legs at 1 m/s from t = 0; the range is 0.5–1.0 m/s.
    let p = |x: f64| Vec3::new(x, 0.0, 0.0);
    let base = Trajectory {
        times: vec![0.0, 100.0, 200.0],
        points: vec![p(0.0), p(100.0), p(200.0)],
    };
    // The first leg slower (125 s at 0.8 m/s): the second cannot make up 25 s at 1 m/s,
    // so the arrival moves to 225 s.
    let t = retimed(&base, 50.0, 1.25, (0.5, 1.0));
    assert!((t.times[1] - 125.0).abs() < 1e-9 && (t.times[2] - 225.0).abs() < 1e-9);
    // The first leg at 0.8 × its time would need 1.25 m/s: it is flown at 1 m/s.
    let t = retimed(&base, 50.0, 0.8, (0.5, 1.0));
    assert!((t.times[1] - 100.0).abs() < 1e-9 && (t.times[2] - 200.0).abs() < 1e-9);
    // With room in the range (up to 2 m/s): 80 s, then 120 s, arriving at 200 s.
    let t = retimed(&base, 50.0, 0.8, (0.5, 2.0));
    assert!((t.times[1] - 80.0).abs() < 1e-9 && (t.times[2] - 200.0).abs() < 1e-9);
    // A closest approach on the second leg slows both legs (the prefix is every leg that
    // starts before it): nothing is left to make up the time.
    let t = retimed(&base, 150.0, 1.1, (0.5, 2.0));
    assert!((t.times[1] - 110.0).abs() < 1e-9 && (t.times[2] - 220.0).abs() < 1e-9);
}

#[test]
fn long_legs_are_cut_into_equal_pieces_that_keep_their_speed() {
    let p = |x: f64| Vec3::new(x, 0.0, 0.0);
    let (pts, speeds) = split_legs(&[p(0.0), p(25.0), p(28.0)], &[1.0, 2.0], 10.0);
    // 25 m → three pieces of 8.333 m; 3 m stays one.
    assert_eq!(pts.len(), 5);
    assert!((pts[1] - p(25.0 / 3.0)).norm() < 1e-9);
    assert!((pts[3] - p(25.0)).norm() < 1e-9);
    assert!((pts[4] - p(28.0)).norm() < 1e-9);
    assert_eq!(speeds, vec![1.0, 1.0, 1.0, 2.0]);
}

#[test]
fn a_crawlers_blocked_run_is_widened_by_two_turning_radii() -> Result<(), Box<dyn std::error::Error>>
{
    let mut s = scenario()?;
    s.obstacles.push(Obstacle {
        id: "rock".into(),
        kind: ObstacleKind::Hard,
        centre: [500.0, 0.0, 0.0],
        radius_m: 9.5,
        inflation_m: 0.0,
    });
    // Legs of 10 m along the x axis: legs 49 (490–500) and 50 (500–510) enter the 9.5 m sphere.
    let pts: Vec<Vec3> = (0..=100)
        .map(|k| Vec3::new(10.0 * k as f64, 0.0, 0.0))
        .collect();
    let plan = tour();
    let mut r = request(&s, &plan, &[]);
    assert_eq!(blocked_runs(r.scenario, &r, &pts), vec![(49, 50)]);
    // A crawler turning at 5 m: the run takes every leg within 9.5 + 1 + 2 × 5 = 20.5 m of the
    // centre, legs 47 (470–480, 20 m) to 52 (520–530); 46 and 53 are 30 m off.
    let mut crawler = s.clone();
    crawler.coverage = Some(Default::default());
    let grid = shoal_common::terrain::HeightGrid::new([0.0, 0.0], 2.0, 10, 10, vec![0.0; 100])?;
    let ground = shoal_common::coverage::reroute::CrawlerGround {
        map: shoal_common::coverage::TerrainMap25::from_grid(&grid, &Default::default())?,
        area: shoal_common::coverage::boxes::Rect::new(0.0, 0.0, 18.0, 18.0),
        safety_clearance_m: 8.0,
        min_turn_radius_m: 5.0,
        sensor_height_m: 0.0,
    };
    r.scenario = &crawler;
    r.ground = Some(&ground);
    assert_eq!(blocked_runs(r.scenario, &r, &pts), vec![(47, 52)]);
    Ok(())
}

/// A crawler's scenario (coverage on) with a 5 m rock at `centre` with a margin of
/// `inflation_m`.
fn crawler_with_rock(
    centre: [f64; 3],
    inflation_m: f64,
) -> Result<Scenario, Box<dyn std::error::Error>> {
    let mut s = scenario()?;
    s.coverage = Some(Default::default());
    s.obstacles.push(Obstacle {
        id: "rock".into(),
        kind: ObstacleKind::Hard,
        centre,
        radius_m: 5.0,
        inflation_m,
    });
    Ok(s)
}

/// East along the row y = 150 from x = 10 to 190 at 0.5 m/s.
fn row_150() -> Trajectory {
    let p = |x: f64| Vec3::new(x, 150.0, 0.0);
    Trajectory {
        times: vec![0.0, 360.0],
        points: vec![p(10.0), p(190.0)],
    }
}

/// A crawler's 198 m square of flat seabed with a 50 m pillar on cells 50..60 × 33..43 (x 100–
/// 120 m, y 66–86 m): the crawler keeps 8 m from impassable ground and turns at 5 m.
fn pillar_ground() -> Result<CrawlerGround, Box<dyn std::error::Error>> {
    let n = 100;
    let mut z = vec![0.0; n * n];
    for j in 33..43 {
        for i in 50..60 {
            z[j * n + i] = 50.0;
        }
    }
    let grid = shoal_common::terrain::HeightGrid::new([0.0, 0.0], 2.0, n, n, z)?;
    Ok(CrawlerGround {
        map: shoal_common::coverage::TerrainMap25::from_grid(&grid, &Default::default())?,
        area: shoal_common::coverage::boxes::Rect::new(0.0, 0.0, 198.0, 198.0),
        safety_clearance_m: 8.0,
        min_turn_radius_m: 5.0,
        sensor_height_m: 0.0,
    })
}

#[test]
fn a_crawlers_rejoin_goes_round_ground_it_may_not_drive() -> Result<(), Box<dyn std::error::Error>>
{
    let mut s = scenario()?;
    s.coverage = Some(Default::default());
    let ground = pillar_ground()?;
    // The plan: east along y = 100 from x = 20 to 180 (14 m north of the pillar), then north.
    let p = |x: f64, y: f64| Vec3::new(x, y, 0.0);
    let plan = Trajectory {
        times: vec![0.0, 160.0, 240.0],
        points: vec![p(20.0, 100.0), p(180.0, 100.0), p(180.0, 180.0)],
    };
    assert!(ground.drivable(&p(20.0, 100.0), &p(180.0, 100.0)));
    // At t = 40 the crawler is 40 m south of its row, heading east: the straight line back to
    // (180, 100) crosses the pillar.
    let mut r = request(&s, &plan, &[]);
    r.t0 = 40.0;
    r.p0 = p(60.0, 60.0);
    r.arrival_s = 240.0;
    r.ground = Some(&ground);
    assert!(!ground.drivable(&r.p0, &p(180.0, 100.0)));
    let repaired = repair(&r);
    assert!(repaired.safe, "{repaired:?}");
    let pts = &repaired.trajectory.points;
    assert!((pts[0] - r.p0).norm() < 1e-9);
    for w in pts.windows(2) {
        assert!(ground.drivable(&w[0], &w[1]), "{} → {}", w[0], w[1]);
    }
    // It still rejoins its plan at (180, 100) and ends where the plan ends.
    assert!(pts.iter().any(|q| (q - p(180.0, 100.0)).norm() < 1e-9));
    assert!((pts[pts.len() - 1] - p(180.0, 180.0)).norm() < 1e-9);

    // 3 m from the pillar's foot, facing it, the crawler has no way it may drive: it holds.
    r.p0 = p(96.0, 76.0);
    let held = repair(&r);
    assert!(!held.safe, "{held:?}");
    assert_eq!(held.trajectory.points, plan.points);
    // The hold says why in words, not as an obstacle intrusion it never had.
    assert_eq!(held.hard_hits, 0);
    assert_eq!(
        held.shortfall(),
        "no way back to its path on ground it may drive"
    );
    Ok(())
}

#[test]
fn a_crawlers_finish_inside_a_keep_out_ends_its_path_before_the_stretch_to_it(
) -> Result<(), Box<dyn std::error::Error>> {
    // A rock of 5 m with a 20 m margin 10 m beyond the row's end (190, 150): the finish is
    // inside its keep-out.
    let s = crawler_with_rock([200.0, 150.0, 0.0], 20.0)?;
    let ground = pillar_ground()?;
    let p = |x: f64, y: f64| Vec3::new(x, y, 0.0);
    let plan = row_150();
    let mut r = request(&s, &plan, &[]);
    r.t0 = 20.0;
    r.p0 = p(20.0, 150.0);
    r.arrival_s = 360.0;
    r.ground = Some(&ground);
    let repaired = repair(&r);
    assert!(repaired.safe, "{repaired:?}");
    // Legs of 10 m from x = 20: 170–180 and 180–190 enter the 25 m sphere; the run is widened
    // over the legs within 25 + 1 + 2 × 5 (its turns) = 36 m, so 160–170 (30 m) too, not
    // 150–160 (40 m). The path ends at x = 160, 30 m short.
    let pts = &repaired.trajectory.points;
    assert_eq!(pts.len(), 15);
    assert!((pts[0] - r.p0).norm() < 1e-9);
    assert!((pts[pts.len() - 1] - p(160.0, 150.0)).norm() < 1e-9);
    assert_eq!(
        repaired.note.as_deref(),
        Some("its finish (190, 150) is inside rock's keep-out: its path now ends at (160, 150), the last 30 m undriven")
    );
    // Re-timed to finish when planned (140 m in 340 s is 0.41 m/s), but no slower than its
    // 0.5 m/s: it finishes at 20 + 140 / 0.5 = 300 s.
    assert!((repaired.trajectory.arrival() - 300.0).abs() < 1e-9);

    // Already on that last stretch, at x = 165: it drives on to 26 m from the rock's centre
    // (its 25 m keep-out and the 1 m margin of a way round), x = 174, 16 m short of the
    // finish, which 9 m at 0.5 m/s reach at 310 + 18 = 328 s. Its 25 m to the finish are cut
    // into three legs of 8.33 m: the first (to x = 173.33) is clear, the second is cut.
    r.t0 = 310.0;
    r.p0 = p(165.0, 150.0);
    let on_it = repair(&r);
    assert!(on_it.safe, "{on_it:?}");
    let pts = &on_it.trajectory.points;
    assert_eq!(pts.len(), 3, "{pts:?}");
    assert!((pts[1] - p(165.0 + 25.0 / 3.0, 150.0)).norm() < 1e-9);
    assert!((pts[2] - p(174.0, 150.0)).norm() < 1e-9, "{pts:?}");
    assert!((on_it.trajectory.arrival() - 328.0).abs() < 1e-9);
    assert_eq!(
        on_it.note.as_deref(),
        Some("its finish (190, 150) is inside rock's keep-out: it is on the last stretch there, and its path now ends at (174, 150), at the keep-out's edge, the last 16 m undriven")
    );
    // At 174.2 m it stands at the edge already: nowhere to go, it holds, and says why.
    r.p0 = p(174.2, 150.0);
    let held = repair(&r);
    assert!(!held.safe);
    assert_eq!(
        held.shortfall(),
        "its finish (190, 150) is inside rock's keep-out, and it stands at the keep-out's edge on the last stretch before it"
    );
    Ok(())
}

#[test]
fn a_tour_whose_goal_is_inside_an_obstacle_holds_and_says_so(
) -> Result<(), Box<dyn std::error::Error>> {
    // A tour's goal is the mission's, not only where its last leg ends: it is never given up.
    let mut s = scenario()?;
    s.obstacles.push(Obstacle {
        id: "rock".into(),
        kind: ObstacleKind::Hard,
        centre: [200.0, 200.0, 200.0],
        radius_m: 20.0,
        inflation_m: 10.0,
    });
    let plan = tour();
    let r = repair(&request(&s, &plan, &[]));
    // The detour's last leg must still end on the goal, inside the rock: not safe.
    assert!(!r.safe);
    assert_eq!(r.note, None);
    assert_eq!(r.hard_hits, 1);
    assert!(
        (r.trajectory.points[r.trajectory.points.len() - 1] - Vec3::new(200.0, 200.0, 200.0))
            .norm()
            < 1e-9
    );
    Ok(())
}

#[test]
fn a_crawler_goes_round_a_vehicle_standing_near_its_path() -> Result<(), Box<dyn std::error::Error>>
{
    let mut s = scenario()?;
    s.coverage = Some(Default::default());
    let ground = pillar_ground()?;
    // East along y = 150 from x = 10 to 190 at 0.5 m/s (north of the pillar); the other
    // vehicle stands 40 m north of that row at x = 100 for the rest of the mission.
    let p = |x: f64, y: f64| Vec3::new(x, y, 0.0);
    let plan = row_150();
    let standing = Trajectory {
        times: vec![0.0, 1000.0],
        points: vec![p(100.0, 190.0), p(100.0, 190.0)],
    };
    let others = [plan.clone(), standing];
    let mut r = request(&s, &plan, &others);
    r.t0 = 20.0;
    r.p0 = p(20.0, 150.0);
    r.arrival_s = 360.0;
    r.budget = Duration::from_secs(2);
    r.separation_buffer_m = 10.0;
    r.ground = Some(&ground);
    let repaired = repair(&r);
    // It goes round: d_min plus the buffer (60 m) from the standing vehicle, every leg on
    // drivable ground, and it still ends at the row's end.
    assert!(repaired.safe, "{repaired:?}");
    assert!(repaired.min_separation_m >= 60.0, "{repaired:?}");
    let pts = &repaired.trajectory.points;
    for w in pts.windows(2) {
        assert!(ground.drivable(&w[0], &w[1]), "{} → {}", w[0], w[1]);
    }
    assert!((pts[pts.len() - 1] - p(190.0, 150.0)).norm() < 1e-9);

    // At x = 65 (53.2 m from it, inside d_min plus the buffer) it goes round at d_min: a
    // sphere any larger would leave it no room to turn away at its 5 m radius.
    r.t0 = 110.0;
    r.p0 = p(65.0, 150.0);
    let near = repair(&r);
    assert!(near.safe, "{near:?}");
    assert!(near.min_separation_m >= 50.0, "{near:?}");

    // At x = 80 (44.7 m, already within d_min) it is not gone round: the row passes 40 m from
    // it at every timing, so the repair is not safe, as before.
    r.t0 = 140.0;
    r.p0 = p(80.0, 150.0);
    let close = repair(&r);
    assert!(!close.safe, "{close:?}");
    Ok(())
}

#[test]
fn a_crawler_inside_an_obstacles_margin_drives_out_of_it() -> Result<(), Box<dyn std::error::Error>>
{
    // A rock of 5 m with a 30 m margin 15 m north of the row y = 150, at x = 60.
    let s = crawler_with_rock([60.0, 165.0, 0.0], 30.0)?;
    let ground = pillar_ground()?;
    let p = |x: f64, y: f64| Vec3::new(x, y, 0.0);
    let plan = row_150();
    // At x = 40 the crawler is 25 m from the rock's centre, 10 m inside its margin. The search
    // cannot start inside a keep-out: before, it held there until the rock was gone. Now the
    // margin is eased to 25 − 1 − 1 − 5 (its turn) − 5 = 13 m, and it goes round outside that.
    let mut r = request(&s, &plan, &[]);
    r.t0 = 60.0;
    r.p0 = p(40.0, 150.0);
    r.arrival_s = 360.0;
    r.budget = Duration::from_secs(2);
    r.ground = Some(&ground);
    let repaired = repair(&r);
    assert!(repaired.safe, "{repaired:?}");
    let pts = &repaired.trajectory.points;
    let rock = p(60.0, 165.0);
    for w in pts.windows(2) {
        assert!(ground.drivable(&w[0], &w[1]), "{} → {}", w[0], w[1]);
        assert!(
            !segment_hits_sphere(&w[0], &w[1], &rock, 18.0),
            "{} → {}",
            w[0],
            w[1]
        );
    }
    assert!((pts[pts.len() - 1] - p(190.0, 150.0)).norm() < 1e-9);
    // Its margin is not eased for a crawler outside it: from x = 10 (51.9 m away), the way
    // round keeps the whole 35 m; from x = 25.1 (38 m away, 2 m outside the keep-out, too near
    // to turn away), it keeps the whole 35 m too, or finds no way and holds.
    r.t0 = 0.0;
    r.p0 = p(10.0, 150.0);
    let outside = repair(&r);
    assert!(outside.safe, "{outside:?}");
    for w in outside.trajectory.points.windows(2) {
        assert!(
            !segment_hits_sphere(&w[0], &w[1], &rock, 35.0),
            "{} → {}",
            w[0],
            w[1]
        );
    }
    r.t0 = 30.2;
    r.p0 = p(60.0 - (38.0f64.powi(2) - 15.0f64.powi(2)).sqrt(), 150.0);
    let near = repair(&r);
    for w in near.trajectory.points.windows(2).filter(|_| near.safe) {
        assert!(
            !segment_hits_sphere(&w[0], &w[1], &rock, 35.0),
            "{} → {}",
            w[0],
            w[1]
        );
    }
    Ok(())
}
