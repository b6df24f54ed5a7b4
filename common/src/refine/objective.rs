//! The objective of one vehicle's refinement step: its smooth share of Zhi & Zuo 2024,
//! eq. (12), with a central-difference gradient and the path length's exact Hessian as the
//! quadratic program's model.

use crate::broad_phase::{boxes_within, extent};
use crate::cost::{depth_term, soft_threat_term, time_term, FleetModel, Sphere};
use crate::geometry::{polyline_length, Vec3};

/// Vehicle `i`'s smooth share of eq. (12): λ1 F(L) + λ2 F(D) + λ3 F(O) + λ4 F(T) (F(S) is
/// zero while the separation rows hold), with F(O) measured against `soft`.
fn smooth_objective(model: &FleetModel, i: usize, points: &[Vec3], soft: &[Sphere]) -> f64 {
    let s = &model.scenario;
    let w = &s.optimizer.weights;
    let straight = model.straight[i].max(1e-9);
    let length = polyline_length(points);
    let column = s.bounds.max[2] - s.bounds.min[2];
    w[0] * length / straight
        + w[1] * depth_term(points, s.bounds.max[2], column)
        + w[2] * soft_threat_term(points, soft, straight)
        + w[3] * time_term(length, &s.vehicles[i], s.fleet.mission_time_s)
}

/// Central differences of [`smooth_objective`] in the inner waypoints' coordinates (1 cm
/// steps: the terms bend over tens of metres). F(O) is measured against the soft spheres that
/// reach the path's box grown by the step: the others add nothing to any of the sums, so the
/// gradient is the same to the last bit, and a large fleet's many far spheres are not paid for
/// at every one of the 6 M evaluations.
pub(super) fn objective_gradient(model: &FleetModel, i: usize, points: &[Vec3]) -> Vec<f64> {
    const H: f64 = 0.01;
    let inner = points.len().saturating_sub(2);
    let soft = soft_spheres_reaching(&model.soft, points, H);
    let mut work = points.to_vec();
    let mut gradient = Vec::with_capacity(3 * inner);
    for k in 1..=inner {
        for c in 0..3 {
            let x = work[k][c];
            work[k][c] = x + H;
            let up = smooth_objective(model, i, &work, &soft);
            work[k][c] = x - H;
            let down = smooth_objective(model, i, &work, &soft);
            work[k][c] = x;
            gradient.push((up - down) / (2.0 * H));
        }
    }
    gradient
}

/// The spheres of `soft`, in order, that reach the box of `points` grown by `grow` metres on
/// every side: a sphere that does not cannot contain a point of a leg whose ends move by up to
/// `grow` (each coordinate), since such a leg stays inside that box. The box test is the
/// broad phase's ([`boxes_within`], with its guard), the centre a box of its own.
fn soft_spheres_reaching(soft: &[Sphere], points: &[Vec3], grow: f64) -> Vec<Sphere> {
    let (lo, hi) = extent(points);
    let grown = (lo.add_scalar(-grow), hi.add_scalar(grow));
    soft.iter()
        .filter(|s| boxes_within(&grown, &(s.centre, s.centre), s.radius))
        .copied()
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{scenario, vehicle_toml};

    fn soft(id: &str, centre: [f64; 3], radius: f64) -> String {
        format!(
            "[[obstacles]]\nid = \"{id}\"\nkind = \"soft\"\ncentre = {centre:?}\nradius_m = {radius:?}\ninflation_m = 0.0\n"
        )
    }

    /// A box from (0, 0, 0) to (100, 0, 0), grown by 1 m: a sphere 12 m beyond its end reaches
    /// it with a radius of 11.5 m, not with 10.5 m; one straight above its middle, 20 m up,
    /// reaches it only with a radius over 19 m. The kept ones keep their order.
    #[test]
    fn only_spheres_that_reach_the_grown_box_are_kept_in_order() {
        let points = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(100.0, 0.0, 0.0)];
        let sphere = |x: f64, z: f64, radius: f64| Sphere {
            centre: Vec3::new(x, 0.0, z),
            radius,
        };
        let spheres = [
            sphere(112.0, 0.0, 11.5),
            sphere(112.0, 0.0, 10.5),
            sphere(50.0, 20.0, 19.5),
            sphere(50.0, 20.0, 18.5),
        ];
        let kept = soft_spheres_reaching(&spheres, &points, 1.0);
        assert_eq!(kept, vec![spheres[0], spheres[2]]);
    }

    /// Among fourteen soft spheres, a path cuts through two and passes far from the rest: its
    /// gradient against the near ones is the gradient against all of them, to the last bit.
    #[test]
    fn the_gradient_against_the_near_spheres_is_the_gradient_against_all(
    ) -> Result<(), crate::scenario::ScenarioError> {
        let mut spheres = soft("near1", [300.0, 520.0, 250.0], 60.0);
        spheres += &soft("near2", [700.0, 470.0, 250.0], 60.0);
        for k in 0..12 {
            spheres += &soft(
                &format!("far{k}"),
                [80.0 * k as f64 + 40.0, 100.0, 100.0],
                30.0,
            );
        }
        let vehicle = vehicle_toml("a", [100.0, 500.0, 250.0], [900.0, 500.0, 250.0]);
        let mut s = scenario(1000.0, &spheres, &[vehicle])?;
        s.optimizer.weights = [1.0, 1.0, 1.0, 1.0, 1.0];
        let model = FleetModel::new(&s);
        let points: Vec<Vec3> = (0..8)
            .map(|k| {
                let u = k as f64 / 7.0;
                Vec3::new(
                    100.0 + 800.0 * u,
                    500.0 + 30.0 * (3.0 * u).sin(),
                    250.0 - 20.0 * u,
                )
            })
            .collect();
        assert_eq!(soft_spheres_reaching(&model.soft, &points, 0.01).len(), 2);
        let gradient = objective_gradient(&model, 0, &points);
        let mut work = points.clone();
        let mut all = Vec::new();
        for k in 1..points.len() - 1 {
            for c in 0..3 {
                let x = work[k][c];
                work[k][c] = x + 0.01;
                let up = smooth_objective(&model, 0, &work, &model.soft);
                work[k][c] = x - 0.01;
                let down = smooth_objective(&model, 0, &work, &model.soft);
                work[k][c] = x;
                all.push((up - down) / 0.02);
            }
        }
        assert!(all.iter().any(|g| g.abs() > 1e-4), "{all:?}");
        assert_eq!(gradient, all);
        Ok(())
    }
}
