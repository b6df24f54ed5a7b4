//! The objective of one vehicle's refinement step: its smooth share of Zhi & Zuo 2024,
//! eq. (12), with a central-difference gradient and the path length's exact Hessian as the
//! quadratic program's model.

use crate::bspline::polyline_length;
use crate::cost::{depth_term, soft_threat_term, time_term, FleetModel};
use crate::geometry::Vec3;

/// Vehicle `i`'s smooth share of eq. (12): λ1 F(L) + λ2 F(D) + λ3 F(O) + λ4 F(T) (F(S) is
/// zero while the separation rows hold).
pub(super) fn smooth_objective(model: &FleetModel, i: usize, points: &[Vec3]) -> f64 {
    let s = &model.scenario;
    let w = &s.optimizer.weights;
    let straight = model.straight[i].max(1e-9);
    let length = polyline_length(points);
    let column = s.bounds.max[2] - s.bounds.min[2];
    w[0] * length / straight
        + w[1] * depth_term(points, s.bounds.max[2], column)
        + w[2] * soft_threat_term(points, &model.soft, straight)
        + w[3] * time_term(length, &s.vehicles[i], s.fleet.mission_time_s)
}

/// Central differences of [`smooth_objective`] in the inner waypoints' coordinates (1 cm
/// steps: the terms bend over tens of metres).
pub(super) fn objective_gradient(model: &FleetModel, i: usize, points: &[Vec3]) -> Vec<f64> {
    const H: f64 = 0.01;
    let inner = points.len().saturating_sub(2);
    let mut work = points.to_vec();
    let mut gradient = Vec::with_capacity(3 * inner);
    for k in 1..=inner {
        for c in 0..3 {
            let x = work[k][c];
            work[k][c] = x + H;
            let up = smooth_objective(model, i, &work);
            work[k][c] = x - H;
            let down = smooth_objective(model, i, &work);
            work[k][c] = x;
            gradient.push((up - down) / (2.0 * H));
        }
    }
    gradient
}

/// The model Hessian: the path length's, exact (each leg adds `(I − û ûᵀ) / |d|` to its ends),
/// weighted as F(L) (and F(T) while the vehicle is late) weigh the length, plus a small ridge
/// that keeps the program strictly convex.
pub(super) fn model_hessian(model: &FleetModel, i: usize, points: &[Vec3]) -> Vec<f64> {
    let s = &model.scenario;
    let v = &s.vehicles[i];
    let w = &s.optimizer.weights;
    let inner = points.len().saturating_sub(2);
    let n = 3 * inner;
    let length = polyline_length(points);
    let mission = s.fleet.mission_time_s;
    let mut scale = w[0] / model.straight[i].max(1e-9);
    if length / v.speed_max_mps > mission {
        scale += w[3] / (v.speed_max_mps * mission);
    }
    let mut h = vec![0.0; n * n];
    let mut add = |a: usize, b: usize, block: &nalgebra::Matrix3<f64>, sign: f64| {
        if a == 0 || b == 0 || a > inner || b > inner {
            return;
        }
        for r in 0..3 {
            for c in 0..3 {
                h[(3 * (a - 1) + r) * n + 3 * (b - 1) + c] += sign * block[(r, c)];
            }
        }
    };
    for (k, p) in points.windows(2).enumerate() {
        let d = p[1] - p[0];
        let l = d.norm();
        if l <= 1e-9 {
            continue;
        }
        let u = d / l;
        let block = (nalgebra::Matrix3::identity() - u * u.transpose()) * (scale / l);
        add(k, k, &block, 1.0);
        add(k + 1, k + 1, &block, 1.0);
        add(k, k + 1, &block, -1.0);
        add(k + 1, k, &block, -1.0);
    }
    let ridge = scale * 1e-4;
    for j in 0..n {
        h[j * n + j] += ridge;
    }
    h
}
