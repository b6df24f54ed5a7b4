use super::*;
use crate::strategies::crossing;
use approx::assert_abs_diff_eq;

fn limits(pitch_deg: f64, turn_deg: f64) -> Limits {
    Limits {
        max_pitch: pitch_deg.to_radians(),
        max_turn: turn_deg.to_radians(),
        clearance_margin: 0.5,
        separation: 10.0,
        d_min: 10.0,
    }
}

/// Every gradient entry of the first row `rows_of` gives equals the central difference of that
/// row's value (the row set must not change under 1e-6 m moves).
fn gradient_matches_differences(points: &[Vec3], rows_of: impl Fn(&[Vec3]) -> Vec<Row>) {
    let rows = rows_of(points);
    assert!(!rows.is_empty());
    let inner = points.len() - 2;
    for (r, row) in rows.iter().enumerate() {
        for var in 0..3 * inner {
            let (k, c) = (var / 3 + 1, var % 3);
            let h = 1e-6;
            let mut up = points.to_vec();
            up[k][c] += h;
            let mut down = points.to_vec();
            down[k][c] -= h;
            let fd = (rows_of(&up)[r].value - rows_of(&down)[r].value) / (2.0 * h);
            let analytic = row
                .gradient
                .iter()
                .find(|(v, _)| *v == var)
                .map_or(0.0, |(_, g)| *g);
            assert_abs_diff_eq!(analytic, fd, epsilon = 1e-6);
        }
    }
}

#[test]
fn a_3_4_5_climb_is_at_sine_0_8_of_pitch() {
    // Leg (0,0,0)→(3,0,4): sin pitch = 4/5; limit 30° (sin 0.5): the row is 0.3 over.
    let points = [
        Vec3::zeros(),
        Vec3::new(3.0, 0.0, 4.0),
        Vec3::new(10.0, 0.0, 3.0),
    ];
    let mut rows = Vec::new();
    pitch_rows(&points, &limits(30.0, 35.0), &mut rows);
    assert_abs_diff_eq!(rows[0].value, 0.3, epsilon = 1e-12);
    // The second leg, 1 m down over 7 m, is far from binding, but above the far cut of −0.5.
    assert_eq!(rows.len(), 2);
    gradient_matches_differences(&points, |p| {
        let mut rows = Vec::new();
        pitch_rows(p, &limits(30.0, 35.0), &mut rows);
        rows
    });
}

#[test]
fn a_right_angle_turn_is_cos_35_over_a_35_degree_limit() {
    let points = [
        Vec3::zeros(),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.5),
        Vec3::new(2.0, 1.5, 0.5),
    ];
    let mut rows = Vec::new();
    turn_rows(&points, &limits(20.0, 35.0), &mut rows);
    // Headings 0° then 90°: cos 35° − cos 90°.
    assert_abs_diff_eq!(rows[0].value, 35f64.to_radians().cos(), epsilon = 1e-12);
    // Then 90° to atan2(0.5, 1) = 26.57°: a 63.43° turn.
    let second = 35f64.to_radians().cos() - (63.434948822922f64).to_radians().cos();
    assert_abs_diff_eq!(rows[1].value, second, epsilon = 1e-9);
    gradient_matches_differences(&points, |p| {
        let mut rows = Vec::new();
        turn_rows(p, &limits(20.0, 35.0), &mut rows);
        rows
    });
}

/// A sphere of radius 2 m centred at (5, 3, 0), beside legs (0,0,0)→(4,0,0)→(10,0,0): √10 m
/// from the first, 3 m from the second.
fn sphere_beside_two_legs() -> (Sphere, [Vec3; 3]) {
    let sphere = Sphere {
        centre: Vec3::new(5.0, 3.0, 0.0),
        radius: 2.0,
    };
    let points = [
        Vec3::zeros(),
        Vec3::new(4.0, 0.0, 0.0),
        Vec3::new(10.0, 0.0, 0.0),
    ];
    (sphere, points)
}

#[test]
fn a_leg_passing_3_m_from_a_2_m_sphere_keeps_a_quarter_radius_to_spare() {
    let (sphere, points) = sphere_beside_two_legs();
    let mut rows = Vec::new();
    hard_rows(&points, &[sphere], &limits(20.0, 35.0), 5.0, &mut rows);
    // First leg: closest at (4, 0, 0), √(1 + 9) away; second: 3 m away. Keep 2.5 m (+ guard).
    assert_eq!(rows.len(), 2);
    assert_abs_diff_eq!(rows[0].value, (2.5 - 10f64.sqrt()) / 2.0, epsilon = 1e-5);
    assert_abs_diff_eq!(rows[1].value, (2.5 - 3.0) / 2.0, epsilon = 1e-5);
    gradient_matches_differences(&points, |p| {
        let mut rows = Vec::new();
        hard_rows(p, &[sphere], &limits(20.0, 35.0), 5.0, &mut rows);
        rows
    });
    // Within 0.1 m of reach, neither leg gives a row.
    let mut none = Vec::new();
    hard_rows(&points, &[sphere], &limits(20.0, 35.0), 0.1, &mut none);
    assert!(none.is_empty());
}

#[test]
fn two_vehicles_crossing_8_m_apart_breach_a_10_m_separation_by_a_fifth() {
    // Mine along x at 2 m/s through (5, 0, 0) at t = 5; the other holds at (5, 8, 0).
    let mine = Trajectory {
        times: vec![0.0, 5.0, 10.0],
        points: vec![
            Vec3::new(-5.0, 0.0, 0.0),
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(15.0, 0.0, 0.0),
        ],
    };
    let other = Trajectory {
        times: vec![0.0, 10.0],
        points: vec![Vec3::new(5.0, 8.0, 0.0), Vec3::new(5.0, 8.0, 0.0)],
    };
    let mut rows = Vec::new();
    separation_rows(
        &mine,
        &other,
        &limits(20.0, 35.0),
        5.0,
        0.0,
        &WHOLE_MISSION,
        &mut rows,
    );
    // Samples at 0, 5, 10 s: only t = 5 s comes within 10 m (8 m: (10 − 8) / 10; the ends
    // are √(10² + 8²) = 12.8 m away).
    assert_eq!(rows.len(), 1);
    assert_abs_diff_eq!(rows[0].value, 0.2, epsilon = 1e-12);
    // At the waypoint (u = 1 of the first leg): moving it 1 m away in y (−y) gives −0.1.
    let g = rows[0]
        .gradient
        .iter()
        .find(|(v, _)| *v == 1)
        .map_or(0.0, |(_, g)| *g);
    assert_abs_diff_eq!(g, 0.1, epsilon = 1e-12);
}

#[test]
fn a_17_m_path_is_seven_tenths_over_a_10_m_limit() -> Result<(), &'static str> {
    let points = [
        Vec3::zeros(),
        Vec3::new(3.0, 4.0, 0.0),
        Vec3::new(3.0, 4.0, 12.0),
    ];
    let row = length_row(&points, 10.0, 1.0).ok_or("not binding")?;
    assert_abs_diff_eq!(row.value, 0.7, epsilon = 1e-12);
    let under = length_row(&points, 20.0, -1.0).ok_or("not binding")?;
    assert_abs_diff_eq!(under.value, 3.0 / 20.0, epsilon = 1e-12);
    assert!(length_row(&points, 100.0, 1.0).is_none());
    gradient_matches_differences(&points, |p| length_row(p, 10.0, 1.0).into_iter().collect());
    Ok(())
}

#[test]
fn a_leg_shorter_than_its_floor_is_over_by_the_shortfall_over_the_floor() {
    // Horizontal extents 5, 0.8 and 7 m against floors of 1 m: only the middle leg is near
    // (0.2 over); the others are far below the cut.
    let points = [
        Vec3::zeros(),
        Vec3::new(3.0, 4.0, 0.0),
        Vec3::new(3.0, 4.8, 1.0),
        Vec3::new(10.0, 4.8, 1.0),
    ];
    let floors = [1.0, 1.0, 1.0];
    let mut rows = Vec::new();
    spacing_rows(&points, &floors, &mut rows);
    assert_eq!(rows.len(), 1);
    assert_abs_diff_eq!(rows[0].value, 0.2, epsilon = 1e-12);
    gradient_matches_differences(&points, |p| {
        let mut rows = Vec::new();
        spacing_rows(p, &floors, &mut rows);
        rows
    });
    // Floors: a third of the mean extent (12.8 / 3 / 3 = 1.422 m), or half a shorter leg.
    let f = spacing_floors(&points);
    assert_abs_diff_eq!(f[0], 12.8 / 9.0, epsilon = 1e-12);
    assert_abs_diff_eq!(f[1], 0.4, epsilon = 1e-12);
    assert_abs_diff_eq!(f[2], 12.8 / 9.0, epsilon = 1e-12);
}

#[test]
fn entering_a_leg_45_degrees_off_the_course_is_cos_35_minus_cos_45_over() -> Result<(), &'static str>
{
    // Under way northwards; the first leg heads north-east (45°), the turn limit is 35°:
    // cos 35° − cos 45° = 0.819152 − 0.707107 = 0.112045.
    let north = Vec3::new(0.0, 1.0, 0.3);
    let points = [
        Vec3::zeros(),
        Vec3::new(10.0, 10.0, -2.0),
        Vec3::new(20.0, 30.0, -4.0),
        Vec3::new(30.0, 50.0, -4.0),
    ];
    let row = entry_turn_row(north, &points, &limits(20.0, 35.0)).ok_or("no row")?;
    assert_abs_diff_eq!(row.value, 0.112045, epsilon = 1e-6);
    // Only the first leg's end moves the turn; its height does not.
    assert!(row
        .gradient
        .iter()
        .all(|(v, g)| *v < 3 && (*v != 2 || *g == 0.0)));
    gradient_matches_differences(&points, |p| {
        entry_turn_row(north, p, &limits(20.0, 35.0))
            .into_iter()
            .collect()
    });
    // A vertical course, or a first leg that ends at the fixed goal, gives no row.
    assert!(entry_turn_row(Vec3::z(), &points, &limits(20.0, 35.0)).is_none());
    assert!(entry_turn_row(north, &points[..2], &limits(20.0, 35.0)).is_none());
    Ok(())
}

#[test]
fn a_leg_3_m_from_a_2_m_soft_sphere_is_half_a_radius_clear_and_one_inside_has_no_row() {
    let (sphere, points) = sphere_beside_two_legs();
    let mut rows = Vec::new();
    soft_rows(&points, &[sphere], 5.0, &mut rows);
    // First leg: closest at (4, 0, 0), √10 away; second: 3 m away. No margin, no guard.
    assert_eq!(rows.len(), 2);
    assert_abs_diff_eq!(rows[0].value, (2.0 - 10f64.sqrt()) / 2.0, epsilon = 1e-12);
    assert_abs_diff_eq!(rows[1].value, (2.0 - 3.0) / 2.0, epsilon = 1e-12);
    gradient_matches_differences(&points, |p| {
        let mut rows = Vec::new();
        soft_rows(p, &[sphere], 5.0, &mut rows);
        rows
    });
    // The second leg turned towards (10, 4, 0) passes 1.94 m from the centre, inside: F(O)
    // pays for that one, and only the first leg keeps its row.
    let inside = [points[0], points[1], Vec3::new(10.0, 4.0, 0.0)];
    let mut rows = Vec::new();
    soft_rows(&inside, &[sphere], 5.0, &mut rows);
    assert_eq!(rows.len(), 1);
    assert_abs_diff_eq!(rows[0].value, (2.0 - 10f64.sqrt()) / 2.0, epsilon = 1e-12);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]

    /// Sampling only the windows of the slabs where the two vehicles' boxes come within
    /// `separation + reach` finds the rows of a sweep over the whole mission, in the same
    /// order, to the last bit.
    #[test]
    fn rows_within_the_near_windows_are_the_whole_missions(
        mine in crossing(),
        other in crossing(),
        separation in 20.0..200.0f64,
        reach in 0.0..100.0f64,
        step in 0.5..20.0f64,
    ) {
        use crate::broad_phase::SlabBoxes;
        let limits = Limits { separation, d_min: separation, ..limits(20.0, 35.0) };
        let horizon = mine.arrival().max(other.arrival());
        let (mut a, mut b) = (SlabBoxes::new(), SlabBoxes::new());
        a.reset(horizon);
        a.push(&mine.times, &mine.points);
        b.reset(horizon);
        b.push(&other.times, &other.points);
        let mut windows = Vec::new();
        a.windows(a.near_slabs_other(0, &b, 0, separation + reach), &mut windows);
        let (mut near, mut whole) = (Vec::new(), Vec::new());
        separation_rows(&mine, &other, &limits, step, reach, &windows, &mut near);
        separation_rows(&mine, &other, &limits, step, reach, &WHOLE_MISSION, &mut whole);
        proptest::prop_assert_eq!(near, whole);
    }
}
