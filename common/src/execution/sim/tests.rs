//! Tests of the simulator ([`super`]).

use super::*;

const A: [f64; 3] = [0.0, 0.0, 100.0];
const EAST: [f64; 3] = [300.0, 0.0, 100.0];
const NORTH: [f64; 3] = [0.0, 300.0, 100.0];

fn vehicle(kind: VehicleKind, start: [f64; 3], goal: [f64; 3]) -> Vehicle {
    let (id, speed_min_mps, speed_max_mps) = ("v".to_string(), 0.5, 1.5);
    let (max_turn_deg, max_pitch_deg) = (35.0, 20.0);
    Vehicle {
        id,
        kind,
        start,
        goal,
        speed_min_mps,
        speed_max_mps,
        max_turn_deg,
        max_pitch_deg,
        turn_radius_m: None,
    }
}

fn line(a: [f64; 3], b: [f64; 3], t0: f64, t1: f64) -> Trajectory {
    let (times, points) = (vec![t0, t1], vec![Vec3::from(a), Vec3::from(b)]);
    Trajectory { times, points }
}

fn auv(start: [f64; 3], goal: [f64; 3], current: Current) -> Simulator {
    auv_with(start, goal, current, SimSettings::default())
}

type Current = Option<Arc<dyn CurrentField>>;
fn auv_with(s: [f64; 3], g: [f64; 3], current: Current, settings: SimSettings) -> Simulator {
    let (v, surface_z) = (vehicle(VehicleKind::Auv, s, g), 200.0);
    Simulator::new(&v, SimModel::Auv { current, surface_z }, settings)
}

fn dist(p: Vec3, q: [f64; 3]) -> f64 {
    (p - Vec3::from(q)).norm()
}

#[derive(Debug)]
struct EastCurrent(f64);
impl CurrentField for EastCurrent {
    fn velocity(&self, _p: &Vec3) -> Vec3 {
        Vec3::new(self.0, 0.0, 0.0)
    }
}

#[test]
fn follows_a_straight_timed_line_and_arrives() {
    let mut sim = auv(A, EAST, None);
    assert_eq!(sim.status(), VehicleStatus::Idle);
    sim.load(line(A, EAST, 0.0, 200.0)); // 1.5 m/s
    assert_eq!(sim.status(), VehicleStatus::Underway);
    sim.advance_to(100.0);
    assert!(dist(sim.position(), [150.0, 0.0, 100.0]) < 1.0);
    sim.advance_to(210.0);
    assert_eq!(sim.status(), VehicleStatus::Arrived);
    assert!(dist(sim.position(), EAST) < 2.0);
    let s = sim.state();
    assert!(s.battery < 1.0 && s.arrived_s.is_some_and(|t| (200.0..=210.0).contains(&t)));
}

#[test]
fn speed_is_limited_and_the_vehicle_lags() {
    let plan = line(A, [3000.0, 0.0, 100.0], 0.0, 300.0); // 10 m/s
    let mut sim = auv(A, EAST, None);
    sim.load(plan.clone());
    sim.advance_to(100.0);
    let x = sim.position().x;
    assert!(x > 140.0 && x <= 150.0 + 1e-6, "went {x} m");
    assert!(x < plan.position_at(100.0).x - 500.0);
}

#[test]
fn yaw_rate_is_limited_by_the_turning_radius() {
    let mut sim = auv(A, EAST, None);
    sim.load(line(A, EAST, 0.0, 200.0)); // under way east
    assert!(sim.heading().abs() < 1e-12);
    sim.load(line(A, NORTH, 0.0, 200.0)); // a replan: now north
    sim.advance_to(1.0);
    let limit = 1.5 / SimSettings::default().turn_radius_m; // v_max / R, rad in 1 s
    let h = sim.heading();
    assert!(h > 0.0 && h <= limit + 1e-9, "{h}");
}

#[test]
fn a_vehicle_is_launched_along_its_first_leg() {
    let mut sim = auv(A, EAST, None); // built facing its goal, east
    assert!(sim.heading().abs() < 1e-12);
    sim.load(line(A, NORTH, 0.0, 200.0));
    assert!((sim.heading() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn pitch_is_limited() {
    let (a, b) = ([0.0, 0.0, 0.0], [50.0, 0.0, 100.0]); // a 63° climb
    let mut sim = auv(a, b, None);
    sim.load(line(a, b, 0.0, 80.0));
    let sin_max = 20f64.to_radians().sin();
    for i in 1..=500 {
        sim.advance_to(0.2 * i as f64);
        let v = sim.velocity(); // = w in still water
        assert!(v.z.abs() <= v.norm() * sin_max + 1e-9, "step {i}: {v:?}");
    }
    assert!(sim.position().z > 10.0);
}

#[test]
fn current_is_compensated_and_station_keeping_cancels_drift() {
    let current: Arc<dyn CurrentField> = Arc::new(EastCurrent(0.3));
    // 1.2 m/s north against 0.3 m/s across: |w| ≈ 1.24 m/s, within v_max.
    let end = [0.0, 240.0, 100.0];
    let mut sim = auv(A, NORTH, Some(current.clone()));
    sim.load(line(A, end, 0.0, 200.0));
    for i in 1..=200 {
        sim.advance_to(i as f64);
        assert!(sim.position().x.abs() < 3.0, "t {i}: {:?}", sim.position());
    }
    assert!(dist(sim.position(), end) < 3.0);

    let mut held = auv(A, NORTH, Some(current));
    held.load(line(A, end, 0.0, 200.0));
    held.advance_to(50.0);
    held.hold();
    let p = held.position();
    held.advance_to(250.0);
    assert_eq!(held.status(), VehicleStatus::Holding);
    assert!((held.position() - p).norm() < 1.0);
}

#[test]
fn crawler_stays_on_the_sloping_seabed_and_slip_makes_it_lag() {
    let seabed: Seabed = Arc::new(|x, _y| 0.1 * x);
    let model = SimModel::Crawler {
        seabed,
        sensor_height_m: 1.0,
        slip: 0.2,
    };
    let (a, b) = ([0.0, 0.0, 1.0], [200.0, 0.0, 21.0]);
    let v = vehicle(VehicleKind::Crawler, a, b);
    let mut sim = Simulator::new(&v, model, SimSettings::default());
    let arrival = dist(Vec3::from(a), b) / v.speed_max_mps; // the plan drives at v_max
    sim.load(line(a, b, 0.0, arrival));
    let off_seabed = |s: &Simulator| (s.position().z - (0.1 * s.position().x + 1.0)).abs();
    assert!(off_seabed(&sim) < 1e-9);
    let mut t = 0.0;
    while t < 2.0 * arrival && sim.status() != VehicleStatus::Arrived {
        t += 0.5;
        sim.advance_to(t);
        assert!(off_seabed(&sim) < 1e-9, "t {t}");
        if (t - arrival).abs() < 0.25 {
            assert_eq!(sim.status(), VehicleStatus::Underway); // lags the plan
        }
    }
    // Ground speed 0.8 v_max: about 1 / 0.8 of the planned time.
    assert_eq!(sim.status(), VehicleStatus::Arrived);
    assert!(
        t > 1.15 * arrival && t < 1.4 * arrival,
        "{t} s, plan {arrival} s"
    );
    let altitude = sim.state().altitude_m;
    assert!(altitude.is_some_and(|h| (h - 1.0).abs() < 1e-9));
}

#[test]
fn position_noise_is_gaussian_and_deterministic() {
    let settings = SimSettings {
        position_noise_m: 2.0,
        seed: 7,
        ..Default::default()
    };
    let make = || auv_with(A, EAST, None, settings.clone());
    let (mut s1, mut s2) = (make(), make());
    let reports: Vec<VehicleState> = (0..2000).map(|_| s1.state()).collect();
    for (axis, truth) in A.iter().enumerate() {
        let e: Vec<f64> = reports.iter().map(|r| r.position[axis] - truth).collect();
        let mean = e.iter().sum::<f64>() / e.len() as f64;
        let var = e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (e.len() - 1) as f64;
        assert!(mean.abs() < 0.2, "axis {axis}: mean {mean}");
        assert!((var.sqrt() - 2.0).abs() < 0.2, "axis {axis}: var {var}");
    }
    let again: Vec<VehicleState> = (0..2000).map(|_| s2.state()).collect();
    assert_eq!(reports, again);
    assert_eq!(reports[0].depth_m, Some(100.0));
}

#[test]
fn hold_then_load_resumes_and_stop_stops() {
    let mut sim = auv(A, EAST, None);
    sim.load(line(A, EAST, 0.0, 200.0));
    sim.advance_to(50.0);
    sim.hold();
    let p = sim.position();
    sim.advance_to(80.0);
    assert_eq!(sim.status(), VehicleStatus::Holding);
    assert!((sim.position() - p).norm() < 1e-9);
    assert_eq!(sim.state().velocity, [0.0; 3]);
    sim.load(line(p.into(), EAST, 80.0, 240.0)); // a replan from where it holds
    assert_eq!(sim.status(), VehicleStatus::Underway);
    sim.advance_to(160.0);
    assert!(sim.position().x > p.x + 50.0);
    sim.stop();
    let (q, s) = (sim.position(), sim.state());
    assert_eq!((s.status, s.velocity), (VehicleStatus::Stopped, [0.0; 3]));
    sim.advance_to(200.0);
    assert_eq!(sim.position(), q);
    sim.load(line(q.into(), EAST, 200.0, 300.0));
    sim.advance_to(310.0);
    assert_eq!(sim.status(), VehicleStatus::Arrived);
}

/// A last leg bent sharper than the turning radius allows, 12 m before the end (a replan's, as
/// seen in the fleet): the AUV cuts the bend and passes its end point 2.1 m to the side, outside
/// the 2 m arrival radius, at 2.4 m/s. Held to that radius it flew 64 s loops round the end
/// (it must keep v_min, and at v_min it turns too slowly to close in), arriving 192 s late or
/// never; passing that close is an arrival.
#[test]
fn an_auv_passing_close_by_its_end_point_arrives_rather_than_circling_it() {
    let points = [
        [991.0, 1735.0, 132.0],
        [998.0, 1839.0, 112.0],
        [1005.0, 1889.0, 101.0],
        [1000.0, 1900.0, 100.0],
    ];
    let mut v = vehicle(VehicleKind::Auv, points[0], points[3]);
    v.speed_max_mps = 2.5;
    let model = SimModel::Auv {
        current: None,
        surface_z: 200.0,
    };
    let mut sim = Simulator::new(&v, model, SimSettings::default());
    let mut times = vec![0.0];
    for w in points.windows(2) {
        times.push(times[times.len() - 1] + dist(Vec3::from(w[0]), w[1]) / 2.4);
    }
    let arrival = times[3];
    let points = points.iter().map(|p| Vec3::from(*p)).collect();
    sim.load(Trajectory { times, points });
    let mut closest = f64::INFINITY;
    let mut t = 0.0;
    while t < arrival + 300.0 && sim.status() != VehicleStatus::Arrived {
        t += 0.5;
        sim.advance_to(t);
        closest = closest.min(dist(sim.position(), [1000.0, 1900.0, 100.0]));
    }
    let s = sim.state();
    assert!(
        s.arrived_s.is_some_and(|a| a <= arrival + 5.0),
        "planned {arrival:.1} s, {:?} at {t} s, closest {closest:.2} m",
        s.status
    );
}

/// The capture radius is for a vehicle going by its end, not one still closing on it: 300 m
/// in 198 s asks 1.52 m/s of a 1.5 m/s vehicle, which is 3 m short at the plan's arrival. It
/// then closes at k e (the reference has stopped): 3 m to 2 m in 5 ln 1.5 = 2.03 s.
#[test]
fn a_vehicle_still_closing_on_its_end_point_arrives_within_the_arrival_radius() {
    let mut sim = auv(A, EAST, None);
    sim.load(line(A, EAST, 0.0, 198.0));
    sim.advance_to(198.0);
    assert!(
        (dist(sim.position(), EAST) - 3.0).abs() < 0.05,
        "{}",
        sim.position()
    );
    assert_eq!(sim.status(), VehicleStatus::Underway);
    sim.advance_to(203.0);
    let arrived = sim.state().arrived_s;
    assert!(
        arrived.is_some_and(|t| (199.8..=200.4).contains(&t)),
        "{arrived:?}"
    );
}
