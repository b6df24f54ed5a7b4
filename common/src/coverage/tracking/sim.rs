//! The closed loop (CPP-DSMV, §2.3, Figure 1 execution layer): plant → sensors → TA-AEKF →
//! V-MPC → plant, with the cross-track statistics of §3 Figure 7(c).

use super::ekf::Ekf;
use super::mpc::{project_command, Command, Mpc, MpcProblem, StageRef};
use super::params::TrackingParams;
use super::plant::{attitude, body_velocity, Plant};
use super::reference::Reference;
use super::types::{
    checked_gradient, gaussian, wrap_angle, PathSample, Pose2, TerrainSlope, TrackedSample,
    TrackingError, TrackingResult,
};
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::sync::atomic::{AtomicBool, Ordering};

/// Tracks `reference` over `terrain` from its first pose; deterministic for a given `seed`.
pub fn track(
    reference: &[PathSample],
    terrain: &dyn TerrainSlope,
    params: &TrackingParams,
    seed: u64,
) -> Result<TrackingResult, TrackingError> {
    track_from_pose(reference, terrain, params, seed, None, None, &mut |_| {})
}

/// [`track`] that reports the fraction of the reference done (0..=1, non-decreasing, about every
/// 0.1 % and once with 1.0 at the end) to `progress`. A raised `stop` (Ctrl-C) ends the run
/// after the current control period: the result covers the stretch driven so far and is marked
/// [`TrackingResult::interrupted`].
pub fn track_with_progress(
    reference: &[PathSample],
    terrain: &dyn TerrainSlope,
    params: &TrackingParams,
    seed: u64,
    stop: Option<&AtomicBool>,
    progress: &mut dyn FnMut(f64),
) -> Result<TrackingResult, TrackingError> {
    track_from_pose(reference, terrain, params, seed, None, stop, progress)
}

/// [`track_with_progress`] from a given true start pose (e.g. off the path); `None` starts on the
/// first reference sample. The vehicle starts moving at cruise speed with the yaw rate of the
/// first sample's curvature; the EKF starts from the first (noisy) fix and compass reading.
pub fn track_from_pose(
    reference: &[PathSample],
    terrain: &dyn TerrainSlope,
    params: &TrackingParams,
    seed: u64,
    start: Option<Pose2>,
    stop: Option<&AtomicBool>,
    progress: &mut dyn FnMut(f64),
) -> Result<TrackingResult, TrackingError> {
    params.validate()?;
    let r = Reference::new(reference)?;
    let p = params;
    let first = reference[0];
    let start = start.unwrap_or(Pose2::new(first.x, first.y, first.heading));
    if !(start.x.is_finite() && start.y.is_finite() && start.heading.is_finite()) {
        return Err(TrackingError::InvalidReference {
            index: 0,
            reason: format!("start pose is not finite: {start:?}"),
        });
    }
    let mut rng = StdRng::seed_from_u64(seed);
    let (n_sub, dt) = p.substeps();
    let period = p.control_period_s;
    let v_r = p.speed_mps;
    let mut prev = project_command(
        Command {
            yaw_rate: first.curvature * v_r,
            speed: v_r,
        },
        Command {
            yaw_rate: 0.0,
            speed: v_r,
        },
        p,
        false,
    );
    let mut plant = Plant::new(
        Pose2::new(start.x, start.y, wrap_angle(start.heading)),
        prev.speed,
        prev.yaw_rate,
    );
    let fix0 = [
        start.x + p.fix_std_m * gaussian(&mut rng),
        start.y + p.fix_std_m * gaussian(&mut rng),
    ];
    let heading0 = start.heading + p.heading_std_rad * gaussian(&mut rng);
    let mut ekf = Ekf::new(Pose2::new(fix0[0], fix0[1], wrap_angle(heading0)), p);
    let mut mpc = Mpc::new(p);
    let mut stages: Vec<StageRef> = Vec::with_capacity(p.horizon_steps + 1);

    let length = r.length();
    let t_limit = p.time_limit_factor * length / v_r + 60.0;
    let end = reference[reference.len() - 1];
    let mut truth_cursor = r.start_cursor();
    let mut est_cursor = r.start_cursor();
    let mut max_s = r.start_s();
    let mut samples: Vec<TrackedSample> =
        Vec::with_capacity(((t_limit / period).min(length / (v_r * period) * 1.2 + 16.0)) as usize);
    let mut last_fix = Some(fix0);
    let mut next_fix = p.fix_period_s;
    let mut qp_solves = 0usize;
    let mut qp_failures = 0usize;
    let mut reached_end = false;
    let mut interrupted;
    let mut last_reported = -1.0;
    let mut step: u64 = 0;
    let mut t = 0.0;

    loop {
        // Cross-track error of the TRUE position (CPP-DSMV, §3, Figure 7(c)).
        let tp = r.project(
            &mut truth_cursor,
            plant.pose.x,
            plant.pose.y,
            p.search_back_m,
            p.search_ahead_m,
        );
        max_s = max_s.max(tp.s);
        let dist_end = (plant.pose.x - end.x).hypot(plant.pose.y - end.y);
        if tp.s >= r.end_s()
            || (dist_end <= p.end_tolerance_m && tp.s >= r.end_s() - 2.0 * p.end_tolerance_m)
        {
            reached_end = true;
        }
        interrupted =
            !reached_end && t < t_limit && stop.is_some_and(|s| s.load(Ordering::Relaxed));
        let done = reached_end || interrupted || t >= t_limit;

        let cmd = if done {
            prev
        } else {
            // Errors of the ESTIMATE for the controller.
            let est = ekf.pose();
            let ep = r.project(
                &mut est_cursor,
                est.x,
                est.y,
                p.search_back_m,
                p.search_ahead_m,
            );
            build_stages(&r, ep.s, ep.seg, &ekf, terrain, p, &mut stages)?;
            let problem = MpcProblem {
                e_lat: ep.lateral,
                e_head: wrap_angle(est.heading - ep.heading),
                // Track encoders measure the actuated speed and yaw rate.
                yaw_rate_act: plant.yaw_rate,
                speed_act: plant.track_speed,
                prev,
                stages: &stages,
            };
            qp_solves += 1;
            let out = mpc.step(&problem);
            if !out.solved {
                qp_failures += 1;
            }
            out.cmd
        };
        samples.push(TrackedSample {
            t,
            truth: plant.pose,
            estimate: ekf.pose(),
            fix: last_fix.take(),
            cross_track_m: tp.lateral,
            speed_cmd: cmd.speed,
            yaw_rate_cmd: cmd.yaw_rate,
        });
        if done {
            break;
        }
        prev = cmd;

        // Apply the command over one control period.
        for i in 0..n_sub {
            let readings = plant.step(cmd.speed, cmd.yaw_rate, dt, terrain, p, &mut rng)?;
            let gyro = readings.yaw_rate + p.gyro_std_radps * gaussian(&mut rng);
            ekf.predict(readings.track_speed, gyro, dt, terrain, p)?;
            let ts = step as f64 * period + (i + 1) as f64 * dt;
            if ts >= next_fix - 1e-9 {
                let z = [
                    plant.pose.x + p.fix_std_m * gaussian(&mut rng),
                    plant.pose.y + p.fix_std_m * gaussian(&mut rng),
                ];
                ekf.update_fix(z, p);
                last_fix = Some(z);
                next_fix += p.fix_period_s;
            }
        }
        let compass = plant.pose.heading + p.heading_std_rad * gaussian(&mut rng);
        ekf.update_heading(compass, p);
        step += 1;
        t = step as f64 * period;

        if !(plant.pose.x.is_finite() && plant.pose.y.is_finite() && plant.pose.heading.is_finite())
        {
            return Err(TrackingError::Diverged {
                t,
                what: "plant pose".to_string(),
            });
        }
        if !ekf.x.iter().all(|v| v.is_finite()) {
            return Err(TrackingError::Diverged {
                t,
                what: "EKF state".to_string(),
            });
        }
        let frac = if length > 0.0 {
            ((max_s - r.start_s()) / length).clamp(0.0, 1.0)
        } else {
            1.0
        };
        if frac >= last_reported + 1e-3 {
            progress(frac);
            last_reported = frac;
        }
    }
    if !interrupted {
        progress(1.0);
    }
    Ok(summarise(
        samples,
        qp_solves,
        qp_failures,
        reached_end,
        interrupted,
        t,
    ))
}

/// The stages k = 0..=N_p along the predicted progress: s_(k+1) = s_k + T·η_k·v_r. At each
/// reference point the terrain gives θ_k, φ_k (reference heading) and
///   η_k = cosθ_k·(1 − s(θ_k, δŝ)),   w_y,k = −k_d·η_k·v_r·sinφ_k + d̂·e^(−kT/τ_b).
fn build_stages(
    r: &Reference<'_>,
    s0: f64,
    seg0: usize,
    ekf: &Ekf,
    terrain: &dyn TerrainSlope,
    p: &TrackingParams,
    stages: &mut Vec<StageRef>,
) -> Result<(), TrackingError> {
    stages.clear();
    let mut s = s0;
    let mut hint = seg0;
    let decay = (-p.control_period_s / p.ekf_bias_corr_time_s).exp();
    let mut drift_res = ekf.drift_residual();
    for _ in 0..=p.horizon_steps {
        let pt = r.point_at(s, hint);
        hint = pt.seg;
        let g = checked_gradient(terrain, pt.x, pt.y)?;
        let att = attitude(g, pt.heading);
        let body = body_velocity(p.speed_mps, att, ekf.slip_residual(), p);
        stages.push(StageRef {
            curvature: pt.curvature,
            efficiency: body.efficiency,
            drift: body.lateral + drift_res,
        });
        drift_res *= decay;
        s += p.control_period_s * body.efficiency * p.speed_mps;
    }
    Ok(())
}

/// Statistics of |cross-track error| over the samples.
fn summarise(
    samples: Vec<TrackedSample>,
    qp_solves: usize,
    qp_failures: usize,
    reached_end: bool,
    interrupted: bool,
    sim_time_s: f64,
) -> TrackingResult {
    let mut abs: Vec<f64> = samples.iter().map(|s| s.cross_track_m.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let n = abs.len();
    let (max, median, p95, rms) = if n == 0 {
        (0.0, 0.0, 0.0, 0.0)
    } else {
        let median = if n % 2 == 1 {
            abs[n / 2]
        } else {
            0.5 * (abs[n / 2 - 1] + abs[n / 2])
        };
        let rank = ((0.95 * n as f64).ceil() as usize).clamp(1, n);
        let rms = (abs.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
        (abs[n - 1], median, abs[rank - 1], rms)
    };
    TrackingResult {
        samples,
        max_abs_cte_m: max,
        median_abs_cte_m: median,
        p95_abs_cte_m: p95,
        rms_cte_m: rms,
        qp_solves,
        qp_failures,
        reached_end,
        interrupted,
        sim_time_s,
    }
}
