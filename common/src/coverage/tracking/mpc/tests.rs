use super::super::discrete::{discretise, stage_key};
use super::super::plant::Plant;
use super::super::types::{FlatTerrain, Pose2};
use super::*;
use approx::assert_abs_diff_eq;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

#[test]
fn weights_law_gives_documented_values_at_zero_and_full_curvature() {
    let p = TrackingParams::default();
    let w0 = stage_weights(0.0, &p);
    assert_abs_diff_eq!(w0.q_lat, p.q_lat_straight, epsilon = 1e-12);
    assert_abs_diff_eq!(w0.q_head, p.q_head_straight, epsilon = 1e-12);
    assert_abs_diff_eq!(w0.rd_yaw_rate, p.rd_yaw_rate_straight, epsilon = 1e-12);
    for k in [1.0 / p.min_turn_radius_m, -1.0 / p.min_turn_radius_m, 3.0] {
        let w = stage_weights(k, &p);
        assert_abs_diff_eq!(w.q_lat, p.q_lat_arc, epsilon = 1e-12);
        assert_abs_diff_eq!(w.q_head, p.q_head_arc, epsilon = 1e-12);
        assert_abs_diff_eq!(w.rd_yaw_rate, p.rd_yaw_rate_arc, epsilon = 1e-12);
    }
    // Default values, as documented in TrackingParams::default().
    assert_abs_diff_eq!(w0.q_lat, 2.0, epsilon = 1e-12);
    assert_abs_diff_eq!(w0.q_head, 10.0, epsilon = 1e-12);
    assert_abs_diff_eq!(w0.rd_yaw_rate, 200.0, epsilon = 1e-12);
    let half = stage_weights(0.5 / p.min_turn_radius_m, &p);
    assert_abs_diff_eq!(
        half.q_head,
        0.5 * (p.q_head_straight + p.q_head_arc),
        epsilon = 1e-12
    );
}

#[test]
fn discretisation_matches_closed_forms_on_a_straight() {
    let p = TrackingParams::default();
    let st = StageRef {
        curvature: 0.0,
        efficiency: 0.95,
        drift: 0.0,
    };
    let phi = discretise(stage_key(&st), &p);
    let t = p.control_period_s;
    let a = 0.95 * p.speed_mps;
    let tw = p.yaw_lag_s;
    let decay = (-t / tw).exp();
    assert_abs_diff_eq!(phi[(0, 1)], a * t, epsilon = 1e-9);
    assert_abs_diff_eq!(phi[(1, 1)], 1.0, epsilon = 1e-12);
    assert_abs_diff_eq!(phi[(2, 2)], decay, epsilon = 1e-9);
    // A unit drift integrates into e_y over T.
    assert_abs_diff_eq!(phi[(0, 6)], t, epsilon = 1e-9);
    // A yaw-rate command moves e_ψ by ∫(1 − e^(−t/τ)) = T − τ(1 − e^(−T/τ)).
    assert_abs_diff_eq!(phi[(1, 4)], t - tw * (1.0 - decay), epsilon = 1e-9);
    // The actuated yaw rate moves e_ψ by τ(1 − e^(−T/τ)).
    assert_abs_diff_eq!(phi[(1, 2)], tw * (1.0 - decay), epsilon = 1e-9);
}

fn limits_hold(cmd: Command, prev: Command, p: &TrackingParams, tol: f64) {
    let c = p.max_curvature();
    let dw = p.max_yaw_accel_radps2 * p.control_period_s;
    let dv = p.max_accel_mps2 * p.control_period_s;
    assert!(
        cmd.speed >= p.min_speed_mps - tol && cmd.speed <= p.max_speed_mps + tol,
        "{cmd:?}"
    );
    assert!(
        cmd.yaw_rate.abs() <= c * cmd.speed + tol,
        "curvature: {cmd:?}"
    );
    assert!(
        (cmd.yaw_rate - prev.yaw_rate).abs() <= dw + tol,
        "Δω: {cmd:?} after {prev:?}"
    );
    assert!(
        (cmd.speed - prev.speed).abs() <= dv + tol,
        "Δv: {cmd:?} after {prev:?}"
    );
}

#[test]
fn qp_solutions_respect_input_and_rate_limits() {
    let p = TrackingParams::default();
    let mut mpc = Mpc::new(&p);
    let mut rng = StdRng::seed_from_u64(11);
    let c = p.max_curvature();
    let mut prev = Command {
        yaw_rate: 0.0,
        speed: p.speed_mps,
    };
    for i in 0..300 {
        // Large and varied errors, curvatures, drifts and actuator states.
        let kappa = [0.0, 0.2, -0.2, 0.1][i % 4];
        let stages: Vec<StageRef> = (0..=p.horizon_steps)
            .map(|k| StageRef {
                curvature: if k > 3 { kappa } else { 0.0 },
                efficiency: rng.random_range(0.5..1.0),
                drift: rng.random_range(-0.1..0.1),
            })
            .collect();
        let problem = MpcProblem {
            e_lat: rng.random_range(-6.0..6.0),
            e_head: rng.random_range(-0.8..0.8),
            yaw_rate_act: rng.random_range(-0.2..0.2),
            speed_act: rng.random_range(0.2..1.0),
            prev,
            stages: &stages,
        };
        let out = mpc.step(&problem);
        assert!(out.solved, "QP {i} failed");
        // The raw QP optimum itself is feasible (not only after projection).
        let raw = mpc.last_raw.unwrap_or(out.cmd);
        limits_hold(raw, prev, &p, 1e-6);
        limits_hold(out.cmd, prev, &p, 1e-12);
        assert!(out.cmd.yaw_rate.abs() <= c * p.max_speed_mps + 1e-12);
        prev = out.cmd;
    }
}

#[test]
fn failed_solve_falls_back_to_the_previous_command_clamped() {
    let p = TrackingParams {
        qp_max_iter: 1,
        ..TrackingParams::default()
    };
    let mut mpc = Mpc::new(&p);
    let stages = vec![
        StageRef {
            curvature: 0.2,
            efficiency: 0.9,
            drift: 0.05
        };
        p.horizon_steps + 1
    ];
    // A previous command beyond the curvature limit is clamped to it.
    let prev = Command {
        yaw_rate: 0.5,
        speed: 0.8,
    };
    let out = mpc.step(&MpcProblem {
        e_lat: 4.0,
        e_head: 0.3,
        yaw_rate_act: 0.0,
        speed_act: 0.8,
        prev,
        stages: &stages,
    });
    assert!(!out.solved);
    assert_abs_diff_eq!(out.cmd.speed, 0.8, epsilon = 1e-12);
    assert_abs_diff_eq!(out.cmd.yaw_rate, p.max_curvature() * 0.8, epsilon = 1e-12);
}

/// Plant + MPC with perfect state on the x axis (flat, noiseless), from `y0` to the left.
fn straight_offset_run(y0: f64) -> (Vec<(f64, f64)>, Vec<Command>) {
    let p = TrackingParams {
        slip_noise_std: 0.0,
        lateral_noise_std_mps: 0.0,
        yaw_noise_std_radps: 0.0,
        ..TrackingParams::default()
    };
    let mut rng = StdRng::seed_from_u64(5);
    let mut mpc = Mpc::new(&p);
    let mut plant = Plant::new(Pose2::new(0.0, y0, 0.0), p.speed_mps, 0.0);
    let stages = vec![
        StageRef {
            curvature: 0.0,
            efficiency: 1.0 - p.base_slip,
            drift: 0.0
        };
        p.horizon_steps + 1
    ];
    let mut prev = Command {
        yaw_rate: 0.0,
        speed: p.speed_mps,
    };
    let (n, dt) = p.substeps();
    let mut track = Vec::new();
    let mut cmds = Vec::new();
    while plant.pose.x < 120.0 && track.len() < 1000 {
        track.push((plant.pose.x, plant.pose.y));
        let out = mpc.step(&MpcProblem {
            e_lat: plant.pose.y,
            e_head: plant.pose.heading,
            yaw_rate_act: plant.yaw_rate,
            speed_act: plant.track_speed,
            prev,
            stages: &stages,
        });
        assert!(out.solved);
        limits_hold(out.cmd, prev, &p, 1e-12);
        cmds.push(out.cmd);
        prev = out.cmd;
        for _ in 0..n {
            plant
                .step(
                    out.cmd.speed,
                    out.cmd.yaw_rate,
                    dt,
                    &FlatTerrain,
                    &p,
                    &mut rng,
                )
                .unwrap_or_else(|e| panic!("{e}"));
        }
    }
    (track, cmds)
}

#[test]
fn three_metre_offset_decays_within_a_bounded_distance() {
    for y0 in [3.0, -3.0] {
        let (track, _) = straight_offset_run(y0);
        // First x after which |e_y| stays below 0.3 m for the rest of the run.
        let settle = track
            .iter()
            .rposition(|&(_, y)| y.abs() >= 0.3)
            .map(|i| track.get(i + 1).map_or(f64::INFINITY, |s| s.0))
            .unwrap_or(0.0);
        eprintln!("y0 = {y0}: |e_y| < 0.3 m from x = {settle:.1} m on");
        assert!(settle < 25.0, "y0 = {y0}: settles at x = {settle:.1} m");
        let overshoot = track
            .iter()
            .map(|&(_, y)| -y * y0.signum())
            .fold(0.0, f64::max);
        assert!(overshoot < 0.5, "y0 = {y0}: overshoot {overshoot:.2} m");
        let tail = track
            .iter()
            .filter(|(x, _)| *x > 80.0)
            .map(|(_, y)| y.abs());
        assert!(tail.fold(0.0, f64::max) < 0.05);
    }
}
