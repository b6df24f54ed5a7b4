//! The fleet planning problem as a swarm [`Problem`]: a particle is every vehicle's chromosome
//! (Zhi & Zuo 2024, Fig. 3), its cost the fitness of [`crate::cost`].

use rand::rngs::StdRng;
use rand::Rng;

use crate::cost::{FleetEvaluation, FleetModel};
use crate::geometry::Vec3;
use crate::swarm::Problem;
use crate::trajectory::{required_horizontal_length, GENES_PER_WAYPOINT};

thread_local! {
    /// The evaluation the swarm's calls on this thread score into.
    static EVALUATION: std::cell::RefCell<FleetEvaluation> =
        std::cell::RefCell::new(FleetEvaluation::default());
}

impl Problem for FleetModel {
    fn lower(&self) -> &[f64] {
        &self.lower
    }

    fn upper(&self) -> &[f64] {
        &self.upper
    }

    fn cost(&self, x: &[f64]) -> f64 {
        self.cost_parts(x, &mut [])
    }

    /// One block per vehicle: eq. (12) is a sum over vehicles.
    fn blocks(&self) -> usize {
        self.layout.vehicles
    }

    fn block_range(&self, b: usize) -> std::ops::Range<usize> {
        self.layout.chromosome(b)
    }

    /// A vehicle's waypoints move as one path and its speeds as one profile.
    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        self.layout.move_groups()
    }

    /// Scored into this thread's reused evaluation: the swarm's calls allocate nothing.
    fn cost_parts(&self, x: &[f64], parts: &mut [f64]) -> f64 {
        let mut score = |e: &mut FleetEvaluation| {
            self.evaluate_into(x, e);
            for (p, t) in parts.iter_mut().zip(&e.vehicles) {
                *p = self.share_of(t);
            }
            e.total
        };
        EVALUATION.with(|cell| match cell.try_borrow_mut() {
            Ok(mut e) => score(&mut e),
            Err(_) => score(&mut FleetEvaluation::default()),
        })
    }

    /// Initial particles (Zhi & Zuo 2024, §3.1: uniform draws "adjusting the range"). Each vehicle's
    /// waypoints are the straight line start→goal bent by three sine harmonics (k = 1, 2, 3) with
    /// uniform random coefficients in ±1/k, and depth changing in proportion to the horizontal
    /// distance travelled; speeds are uniform in the vehicle's range. The bend's size is:
    /// - for a vehicle whose climb is steeper than its pitch limit, solved so the horizontal
    ///   length is 1.02–1.25 × what the limit requires (`|Δz| / tan φ_max`): every initial path
    ///   then climbs within the limit;
    /// - otherwise uniform in [2 %, 50 %] of the straight distance.
    ///
    /// Uniform draws over the whole 2 km box would start every path tens of kilometres long and
    /// kinked at every waypoint.
    fn sample(&self, rng: &mut StdRng) -> Vec<f64> {
        let mut x = Vec::with_capacity(self.layout.dim());
        for i in 0..self.scenario.vehicles.len() {
            self.sample_chromosome(i, rng, &mut x);
        }
        x
    }
}

impl FleetModel {
    /// Appends an initial chromosome for vehicle `i` to `x` (see [`Problem::sample`] above for
    /// how it is drawn); a vehicle agent samples its own chromosome alone with it.
    pub fn sample_chromosome(&self, i: usize, rng: &mut StdRng, x: &mut Vec<f64>) {
        let m = self.layout.waypoints;
        let v = &self.scenario.vehicles[i];
        let span = self.straight[i].max(1.0);
        let shape: Vec<Vec3> = (1..=3)
            .map(|k| {
                Vec3::new(
                    rng.random_range(-1.0..=1.0),
                    rng.random_range(-1.0..=1.0),
                    0.1 * rng.random_range(-1.0..=1.0),
                ) / k as f64
            })
            .collect();
        let d = v.goal() - v.start();
        let needed = required_horizontal_length(v);
        let bend = if needed > (d.x * d.x + d.y * d.y).sqrt() * (1.0 + 1e-9) {
            Bend::Covering(needed * rng.random_range(1.02..=1.25))
        } else {
            Bend::Amplitude(rng.random_range(0.02..=0.5) * span)
        };
        self.bent_waypoints(i, &shape, bend, x);
        x.extend((0..m).map(|_| rng.random_range(v.speed_min_mps..=v.speed_max_mps)));
        debug_assert_eq!(x.len() % (m * GENES_PER_WAYPOINT), 0);
    }

    /// Appends vehicle `i`'s waypoint genes (not its speeds) along its straight line bent by
    /// the sine harmonics `shape` (as the initial particles are), as big as `bend` says, each gene
    /// clamped to its bounds.
    pub fn bent_waypoints(&self, i: usize, shape: &[Vec3], bend: Bend, x: &mut Vec<f64>) {
        let m = self.layout.waypoints;
        let v = &self.scenario.vehicles[i];
        let line = BentLine::new(v.start(), v.goal(), m, shape);
        let amp = match bend {
            Bend::Amplitude(amp) => amp,
            Bend::Covering(target) => {
                bend_for_length(&line, target, 2.0 * self.straight[i].max(1.0))
            }
        };
        // The chromosome's own bounds: a crawler's z genes are pinned.
        let first = self.layout.chromosome(i).start;
        for (j, p) in line.curve(amp)[1..=m].iter().enumerate() {
            for d in 0..3 {
                let g = first + 3 * j + d;
                x.push(p[d].clamp(self.lower[g], self.upper[g]));
            }
        }
    }
}

/// How far a bent path strays from the straight line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bend {
    /// The bend's amplitude, metres.
    Amplitude(f64),
    /// The horizontal distance the path covers, metres (the amplitude is solved for it, up to
    /// twice the straight distance).
    Covering(f64),
}

/// Cumulative horizontal distance along `pts`.
fn horizontal_progress(pts: &[Vec3]) -> Vec<f64> {
    let mut along = vec![0.0; pts.len()];
    for j in 1..pts.len() {
        let d = pts[j] - pts[j - 1];
        along[j] = along[j - 1] + (d.x * d.x + d.y * d.y).sqrt();
    }
    along
}

/// The straight line `a→b` at `m + 2` stations (ends included), to be bent by
/// `amp · Σ shape_k sin(kπf)` with depth following the horizontal distance travelled, so the
/// climb is spread evenly. The stations' sines are computed once for the many amplitudes a
/// bisection tries (they cost more than the rest of a curve).
struct BentLine<'s> {
    a: Vec3,
    b: Vec3,
    shape: &'s [Vec3],
    /// The unbent stations `a + (b − a) f`, `f = j / (m + 1)`.
    stations: Vec<Vec3>,
    /// `sin(kπf)` of harmonic `k` at station `j`, at `j · shape.len() + k − 1`.
    sines: Vec<f64>,
}

impl<'s> BentLine<'s> {
    fn new(a: Vec3, b: Vec3, m: usize, shape: &'s [Vec3]) -> BentLine<'s> {
        let fraction = |j: usize| j as f64 / (m + 1) as f64;
        BentLine {
            a,
            b,
            shape,
            stations: (0..=m + 1).map(|j| a + (b - a) * fraction(j)).collect(),
            sines: (0..=m + 1)
                .flat_map(|j| {
                    (1..=shape.len())
                        .map(move |k| (k as f64 * std::f64::consts::PI * fraction(j)).sin())
                })
                .collect(),
        }
    }

    /// Station `j` bent by `amp`, before its depth is respread.
    fn point(&self, j: usize, amp: f64) -> Vec3 {
        let waves = &self.sines[j * self.shape.len()..(j + 1) * self.shape.len()];
        let mut p = self.stations[j];
        for (h, sine) in self.shape.iter().zip(waves) {
            p += h * (amp * sine);
        }
        p
    }

    /// The horizontal distance the line bent by `amp` covers.
    fn horizontal_length(&self, amp: f64) -> f64 {
        let mut previous = self.point(0, amp);
        let mut along = 0.0;
        for j in 1..self.stations.len() {
            let p = self.point(j, amp);
            let d = p - previous;
            along += (d.x * d.x + d.y * d.y).sqrt();
            previous = p;
        }
        along
    }

    /// The line bent by `amp`, its depth following the horizontal distance travelled.
    fn curve(&self, amp: f64) -> Vec<Vec3> {
        let (a, b) = (self.a, self.b);
        let mut pts: Vec<Vec3> = (0..self.stations.len())
            .map(|j| self.point(j, amp))
            .collect();
        let along = horizontal_progress(&pts);
        let last = pts.len() - 1;
        let total = along[last].max(1e-9);
        for j in 1..last {
            let f = j as f64 / last as f64;
            let bend_z = pts[j].z - (a.z + (b.z - a.z) * f);
            pts[j].z = a.z + (b.z - a.z) * along[j] / total + bend_z;
        }
        pts
    }
}

/// The bend amplitude (in `[0, max_amp]`) whose curve covers `target` metres horizontally, by
/// bisection (the length grows with the amplitude); `max_amp` if even that falls short.
fn bend_for_length(line: &BentLine, target: f64, max_amp: f64) -> f64 {
    let length = |amp: f64| line.horizontal_length(amp);
    if length(max_amp) <= target {
        return max_amp;
    }
    let (mut lo, mut hi) = (0.0, max_amp);
    // 30 halvings: a billionth of the range, far finer than a starting bend needs.
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if length(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures;
    use crate::scenario::Scenario;
    use rand::SeedableRng;

    fn two_vehicle_scenario() -> Result<Scenario, crate::scenario::ScenarioError> {
        let hard = "[[obstacles]]\nid = \"H\"\nkind = \"hard\"\ncentre = [500.0, 500.0, 250.0]\nradius_m = 100.0\ninflation_m = 20.0\n";
        fixtures::scenario(
            1000.0,
            hard,
            &[
                fixtures::vehicle_toml("a", [100.0, 100.0, 250.0], [900.0, 900.0, 250.0]),
                fixtures::vehicle_toml("b", [100.0, 900.0, 250.0], [900.0, 100.0, 250.0]),
            ],
        )
    }

    #[test]
    fn samples_stay_in_bounds_and_have_the_layout_length() -> Result<(), Box<dyn std::error::Error>>
    {
        let model = FleetModel::new(&two_vehicle_scenario()?);
        let mut rng = StdRng::seed_from_u64(5);
        for _ in 0..50 {
            let x = model.sample(&mut rng);
            assert_eq!(x.len(), model.dim());
            for ((v, lo), hi) in x.iter().zip(model.lower()).zip(model.upper()) {
                assert!(lo <= v && v <= hi);
            }
            assert!(model.cost(&x).is_finite());
        }
        Ok(())
    }

    #[test]
    fn a_steep_climb_starts_with_a_long_enough_bend() {
        // Climb 600 m over 400 m horizontally with a 20° limit: 600 / tan 20° = 1648 m needed.
        let (a, b) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(400.0, 0.0, 600.0));
        let shape = [
            Vec3::new(0.3, 1.0, 0.0),
            Vec3::new(-0.2, 0.4, 0.0),
            Vec3::zeros(),
        ];
        let line = BentLine::new(a, b, 30, &shape);
        let amp = bend_for_length(&line, 1700.0, 5000.0);
        let pts = line.curve(amp);
        let along = horizontal_progress(&pts);
        assert!((along[31] - 1700.0).abs() < 1e-3, "{}", along[31]);
        // Depth follows horizontal progress: every leg climbs at atan(600 / 1700) = 19.4°.
        for w in pts.windows(2) {
            let p = crate::geometry::pitch(&w[0], &w[1]).to_degrees();
            assert!(
                (p - (600f64 / 1700.0).atan().to_degrees()).abs() < 1e-6,
                "{p}"
            );
        }
        assert!((pts[0] - a).norm() < 1e-9 && (pts[31] - b).norm() < 1e-9);
    }

    #[test]
    fn straight_paths_through_the_obstacle_and_each_other_are_penalised(
    ) -> Result<(), Box<dyn std::error::Error>> {
        let model = FleetModel::new(&two_vehicle_scenario()?);
        // Both fly their straight diagonals at one speed: they cross the hard sphere and meet
        // in its centre at the same instant.
        let x = fixtures::straight_particle(&model);
        let e = model.evaluate(&x);
        assert!(e.vehicles.iter().all(|t| t.hard_hits > 0));
        assert!(e.separation_penalty > 1.0);
        assert!(e.vehicles.iter().all(|t| t.space > 0.0));
        // The straight path has F(L) = 1 and needs 1131 s at 1 m/s, inside [754, 2263] s.
        assert!((e.vehicles[0].length - 1.0).abs() < 1e-9);
        assert_eq!(e.vehicles[0].time, 0.0);
        assert!((e.common_arrival - 1000.0).abs() < 1e-9);
        assert!(e.total > e.objective + model.scenario.optimizer.penalty_weight * 2.0);
        // The per-vehicle shares add up to the total.
        let mut parts = vec![0.0; model.blocks()];
        let total = model.cost_parts(&x, &mut parts);
        assert!((parts.iter().sum::<f64>() - total).abs() < 1e-9 * total.abs().max(1.0));
        assert!((total - e.total).abs() < 1e-12);
        Ok(())
    }
}
