//! Fresh ways at the pitch bound for a vehicle the refinement leaves well over its shortest
//! length. The local search keeps the way round the obstacles the swarm chose, and a vehicle
//! that must zigzag to lose height within its pitch limit can take a way that is longer than it
//! needs to be (round the far side of a second obstacle, say) and still be at a local optimum.
//! Every path that covers exactly the horizontal distance the limit requires and climbs evenly
//! is as short as the limit allows, so there are many such ways: a few hundred, drawn as the
//! straight line bent by random sine harmonics (the swarm's own initial shapes, see
//! [`FleetModel::bent_waypoints`]), are scored by the fleet's merit, and the best few are pulled
//! tight by the refinement like any other path.

use rand::rngs::StdRng;
use rand::Rng;

use crate::cost::FleetModel;
use crate::fleet::Bend;
use crate::geometry::Vec3;

/// Ways drawn per vehicle: each costs one fleet evaluation.
pub const DRAWN: usize = 300;
/// Of those, how many the refinement pulls tight (the best by merit).
pub const TRIED: usize = 2;
/// A vehicle is given fresh ways when its path is longer than its pitch bound by this fraction.
pub const SLACK: f64 = 0.01;
/// Degrees kept inside the pitch limit by the drawn ways' even climb: twice the refinement's
/// margin, so a drawn way starts inside the limit.
const PITCH_MARGIN_DEG: f64 = 0.1;
/// A drawn way covers up to this fraction more than the required horizontal distance.
const SPREAD: f64 = 0.05;

/// The horizontal distance vehicle `i` must cover to keep `PITCH_MARGIN_DEG` inside its pitch
/// limit at an even climb, or its straight horizontal distance when that is more.
fn covering(model: &FleetModel, i: usize) -> f64 {
    let v = &model.scenario.vehicles[i];
    let d = v.goal() - v.start();
    let horizontal = d.x.hypot(d.y);
    let pitch = (v.max_pitch_deg - PITCH_MARGIN_DEG).max(0.1).to_radians();
    horizontal.max(d.z.abs() / pitch.tan())
}

/// `count` chromosomes for vehicle `i`, each its straight line bent horizontally by random sine
/// harmonics to cover 1 to 1 + `SPREAD` times the horizontal distance its pitch limit requires
/// (0.1° inside it), climbing evenly; the speed genes are `speeds` (the vehicle's present ones).
pub fn drawn_ways(
    model: &FleetModel,
    i: usize,
    speeds: &[f64],
    count: usize,
    rng: &mut StdRng,
) -> Vec<Vec<f64>> {
    let needed = covering(model, i);
    (0..count)
        .map(|_| {
            let shape: Vec<Vec3> = (1..=3)
                .map(|k| {
                    Vec3::new(
                        rng.random_range(-1.0..=1.0),
                        rng.random_range(-1.0..=1.0),
                        0.0,
                    ) / k as f64
                })
                .collect();
            let target = needed * (1.0 + SPREAD * rng.random::<f64>());
            let mut genes = Vec::with_capacity(3 * speeds.len() + speeds.len());
            model.bent_waypoints(i, &shape, Bend::Covering(target), &mut genes);
            genes.extend_from_slice(speeds);
            genes
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use rand::SeedableRng;

    /// A vehicle that must lose 300 m over 400 m of straight horizontal distance with a 20°
    /// pitch limit: every drawn way covers 300 / tan 19.9° = 828.7 m to 870.2 m horizontally,
    /// climbs at an even pitch inside the limit, ends at the start and goal, and keeps the
    /// speeds given.
    #[test]
    fn drawn_ways_cover_the_required_distance_at_an_even_pitch() -> Result<(), String> {
        let text = format!(
            "name = \"t\"\n[bounds]\nmin = [0.0, 0.0, 0.0]\nmax = [2000.0, 2000.0, 1000.0]\n{}\
             [fleet]\nd_min_m = 50.0\nmission_time_s = 1000.0\n[optimizer]\nwaypoints = 10\n",
            crate::fixtures::vehicle_toml("a", [800.0, 1000.0, 600.0], [1200.0, 1000.0, 300.0])
        );
        let s =
            Scenario::parse(&text, std::path::Path::new("t.toml")).map_err(|e| e.to_string())?;
        let model = FleetModel::new(&s);
        let v = &s.vehicles[0];
        assert!((v.max_pitch_deg - 20.0).abs() < 1e-9, "{}", v.max_pitch_deg);
        let needed = 300.0 / 19.9f64.to_radians().tan();
        assert!((covering(&model, 0) - needed).abs() < 1e-9);
        assert!((needed - 828.74).abs() < 0.01, "{needed}");
        let speeds = vec![1.25; 10];
        let mut rng = StdRng::seed_from_u64(7);
        let ways = drawn_ways(&model, 0, &speeds, 50, &mut rng);
        assert_eq!(ways.len(), 50);
        for genes in &ways {
            assert_eq!(&genes[30..], &speeds[..]);
            let path = model.decode(0, genes);
            let points = &path.points;
            assert_eq!(points.first(), Some(&v.start()));
            assert_eq!(points.last(), Some(&v.goal()));
            let horizontal: f64 = points
                .windows(2)
                .map(|w| (w[1] - w[0]).x.hypot((w[1] - w[0]).y))
                .sum();
            assert!(
                horizontal > needed - 0.01 && horizontal < needed * 1.05 + 0.01,
                "{horizontal}"
            );
            for w in points.windows(2) {
                let d = w[1] - w[0];
                let pitch = d.z.atan2(d.x.hypot(d.y)).to_degrees();
                assert!(pitch.abs() <= 19.9 + 1e-6, "{pitch}");
            }
        }
        Ok(())
    }
}
