//! A deep-sea mining crawler's path on the seabed (Lu et al. 2023, §2.3–2.4): the particle is the
//! horizontal position of a few B-spline control points between the start and the goal; the
//! path is the smoothed clamped cubic B-spline through [start, control points…, goal], sampled
//! densely and draped on the terrain (z = seabed + sensor height). Every term below is computed
//! on that smoothed path, never on the control polygon.
//!
//! Cost terms (eq. (5)–(11)):
//! - `f_d`, path length, metres (eq. (5));
//! - `f_u`, undulation: the sum of elevation differences between consecutive samples, metres
//!   (eq. (6));
//! - `f_e`, energy, kWh (eq. (7)): `t1 P1 + t2 P2 + (t1 + t2) P3` with the travel time
//!   `t2 = length / speed` and the mining time `t1` such that mining is `mining_share` of the
//!   whole time (§5.1: 60 % mining, 40 % travel, so `t1 = 1.5 t2`);
//! - `f_s`, crawler slip (eq. (8)–(9)): for each hazard (slip rate > 0.5) `D = 1` closer than
//!   `d_safe_min`, `0` from `d_safe_max` on, and linear in between. The printed eq. (9) has
//!   `(d_real − d_min)/(d_max − d_min)`, which grows *away* from the hazard and jumps from 1 to
//!   0 at `d_min`; the text ("the smaller D, the safer") asks for the decreasing ramp
//!   `(d_max − d_real)/(d_max − d_min)`, which Shoal uses. `f_s` is the sum over hazards.
//!
//! Standardisation: the paper z-scores each term over the swarm (`(x − μ)/σ`), which makes a
//! particle's cost depend on the other particles and change between iterations. Shoal divides
//! `f_d` and `f_e` by their values on the straight start→goal line draped on the same terrain
//! (so each is dimensionless and about 1), and divides `f_u` by that line's *length*, not by its
//! undulation: on a gentle summit the straight line's undulation can be a few decimetres, and a
//! ratio to it would weigh a 1 m bump like a 100 m detour. `f_s` stays as it is (in [0, 1] per
//! hazard). The weights are ω = (0.5, 0.2, 0.2, 0.1) as §2.3.5 assigns them (length 0.5,
//! undulation 0.2, slip 0.2, energy 0.1).
//!
//! Constraints, as penalties of weight `penalty_weight`: a path entering a hazard's circle
//! (`1 + min(depth / radius, 1)` per hazard) and a leg steeper than `max_slope_deg`
//! (`1 + excess / limit` per leg).

use crate::bspline;
use crate::geometry::{polyline_length, Vec3};
use crate::swarm::Problem;
use crate::terrain::{hazard_clearance, Hazard, Terrain};

/// Everything the crawler cost needs.
#[derive(Debug, Clone)]
pub struct CrawlerModel {
    /// The seabed.
    pub terrain: Terrain,
    /// Soft-substrate zones (slip rate > 0.5).
    pub hazards: Vec<Hazard>,
    /// Start and goal in the horizontal plane, metres.
    pub start: [f64; 2],
    /// Goal.
    pub goal: [f64; 2],
    /// Horizontal box the control points stay in: min x, min y, max x, max y.
    pub area: [f64; 4],
    /// B-spline control points between start and goal (the particle has twice as many genes).
    pub control_points: usize,
    /// Samples of the smoothed path.
    pub samples: usize,
    /// Height of the path above the seabed, metres.
    pub sensor_height_m: f64,
    /// Travel speed, m/s (§5.1: 1 m/s).
    pub speed_mps: f64,
    /// P1 (collection), P2 (travel), P3 (control and perception), kW (§5.1: 90, 50, 5).
    pub power_kw: [f64; 3],
    /// Share of the mission time spent mining (§5.1: 0.6).
    pub mining_share: f64,
    /// `d_safe_min` and `d_safe_max` of eq. (9), metres from the hazard's edge.
    pub safe_distance_m: [f64; 2],
    /// Steepest slope the crawler may climb or descend, degrees.
    pub max_slope_deg: f64,
    /// ω1..ω4 for length, undulation, slip, energy.
    pub weights: [f64; 4],
    /// Weight of the constraint penalties.
    pub penalty_weight: f64,
}

/// The raw terms of one path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrawlerTerms {
    /// f_d, metres.
    pub length_m: f64,
    /// f_u, metres.
    pub undulation_m: f64,
    /// f_e, kWh.
    pub energy_kwh: f64,
    /// f_s, dimensionless.
    pub slip: f64,
    /// Smallest horizontal distance from the path to a hazard's edge, metres (negative inside).
    pub min_hazard_clearance_m: f64,
    /// Steepest leg, degrees.
    pub max_slope_deg: f64,
    /// Unweighted hazard-intrusion penalty (0 when admissible).
    pub hazard_penalty: f64,
    /// Unweighted slope penalty (0 when admissible).
    pub slope_penalty: f64,
    /// Hazards the path enters.
    pub hazard_intrusions: usize,
}

impl CrawlerTerms {
    /// Both penalties, unweighted.
    pub fn penalty(&self) -> f64 {
        self.hazard_penalty + self.slope_penalty
    }
}

impl CrawlerModel {
    /// The smoothed path of a particle, draped on the terrain.
    pub fn path(&self, genes: &[f64]) -> Vec<Vec3> {
        self.path_through(genes.chunks_exact(2).map(|xy| [xy[0], xy[1]]))
    }

    /// The smoothed, draped path with the horizontal control points `inner` between start and
    /// goal (clamped cubic B-spline, eq. (12)–(13), `samples` points).
    pub fn path_through(&self, inner: impl Iterator<Item = [f64; 2]>) -> Vec<Vec3> {
        let mut control = Vec::with_capacity(self.control_points + 2);
        control.push(Vec3::new(self.start[0], self.start[1], 0.0));
        control.extend(inner.map(|[x, y]| Vec3::new(x, y, 0.0)));
        control.push(Vec3::new(self.goal[0], self.goal[1], 0.0));
        bspline::sample(&control, 3, self.samples)
            .into_iter()
            .map(|p| {
                Vec3::new(
                    p.x,
                    p.y,
                    self.terrain.elevation(p.x, p.y) + self.sensor_height_m,
                )
            })
            .collect()
    }

    /// Energy of a path of `length` metres, kWh (eq. (7)).
    pub fn energy_kwh(&self, length: f64) -> f64 {
        let t2 = length / self.speed_mps / 3600.0;
        let t1 = t2 * self.mining_share / (1.0 - self.mining_share);
        let [p1, p2, p3] = self.power_kw;
        t1 * p1 + t2 * p2 + (t1 + t2) * p3
    }

    /// Slip of one hazard at horizontal clearance `d` from its edge (eq. (9), as read above).
    pub fn slip_of(&self, d: f64) -> f64 {
        let [lo, hi] = self.safe_distance_m;
        if d < lo {
            1.0
        } else if d >= hi || hi <= lo {
            0.0
        } else {
            (hi - d) / (hi - lo)
        }
    }

    /// Every term of a draped path.
    pub fn terms(&self, path: &[Vec3]) -> CrawlerTerms {
        let length = polyline_length(path);
        let undulation: f64 = path.windows(2).map(|w| (w[1].z - w[0].z).abs()).sum();
        let mut slip = 0.0;
        let mut clearance = f64::INFINITY;
        let (mut hazard_penalty, mut slope_penalty, mut intrusions) = (0.0, 0.0, 0);
        for h in &self.hazards {
            let d = path
                .windows(2)
                .map(|w| hazard_clearance(h, [w[0].x, w[0].y], [w[1].x, w[1].y]))
                .fold(f64::INFINITY, f64::min);
            clearance = clearance.min(d);
            slip += self.slip_of(d);
            // The penalty starts at the contact guard; the reported count is the strict one
            // every checker recomputes.
            if d < crate::geometry::CONTACT_GUARD_M {
                hazard_penalty += 1.0 + (-d / h.radius_m.max(1e-9)).clamp(0.0, 1.0);
            }
            if d < 0.0 {
                intrusions += 1;
            }
        }
        let mut steepest: f64 = 0.0;
        for w in path.windows(2) {
            let horizontal = ((w[1].x - w[0].x).powi(2) + (w[1].y - w[0].y).powi(2)).sqrt();
            let slope = (w[1].z - w[0].z).abs().atan2(horizontal).to_degrees();
            steepest = steepest.max(slope);
            if slope > self.max_slope_deg {
                slope_penalty += 1.0 + (slope - self.max_slope_deg) / self.max_slope_deg;
            }
        }
        CrawlerTerms {
            length_m: length,
            undulation_m: undulation,
            energy_kwh: self.energy_kwh(length),
            slip,
            min_hazard_clearance_m: clearance,
            max_slope_deg: steepest,
            hazard_penalty,
            slope_penalty,
            hazard_intrusions: intrusions,
        }
    }

    /// The straight start→goal path's terms: the scales of the standardisation.
    pub fn reference(&self) -> CrawlerTerms {
        let n = self.control_points;
        let genes: Vec<f64> = (1..=n)
            .flat_map(|j| {
                let f = j as f64 / (n + 1) as f64;
                [
                    self.start[0] + f * (self.goal[0] - self.start[0]),
                    self.start[1] + f * (self.goal[1] - self.start[1]),
                ]
            })
            .collect();
        self.terms(&self.path(&genes))
    }

    /// Eq. (10) with the standardisation above, without the penalties.
    pub fn objective_of(&self, t: &CrawlerTerms, reference: &CrawlerTerms) -> f64 {
        let scale = |v: f64, r: f64| if r > 1e-12 { v / r } else { v };
        let [w1, w2, w3, w4] = self.weights;
        w1 * scale(t.length_m, reference.length_m)
            + w2 * scale(t.undulation_m, reference.length_m)
            + w3 * t.slip
            + w4 * scale(t.energy_kwh, reference.energy_kwh)
    }

    /// [`Self::objective_of`] plus the weighted penalties.
    pub fn cost_of(&self, t: &CrawlerTerms, reference: &CrawlerTerms) -> f64 {
        self.objective_of(t, reference) + self.penalty_weight * t.penalty()
    }
}

/// What `plan.json` reports of a crawler's path (Lu et al. 2023, §5.2's figures), recomputed from the
/// planned trajectory's points.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CrawlerFigures {
    /// 3D length of the smoothed path on the seabed, metres (eq. (5)).
    pub length_m: f64,
    /// Undulation, metres (eq. (6)).
    pub undulation_m: f64,
    /// Energy, kWh (eq. (7), §5.1 powers and 60/40 mining/travel split).
    pub energy_kwh: f64,
    /// Slip cost f_s (eq. (8)–(9)), summed over hazards.
    pub slip_cost: f64,
    /// Smallest horizontal distance to a hazard's edge, metres (`null` without hazards;
    /// negative inside one).
    pub min_hazard_clearance_m: Option<f64>,
    /// Hazards the path enters.
    pub hazard_intrusions: usize,
    /// Steepest leg on the seabed, degrees.
    pub max_slope_deg: f64,
    /// The slope limit (the vehicle's pitch limit), degrees.
    pub slope_limit_deg: f64,
    /// Largest distance of a sample from the seabed plus the sensor height, metres (0 when
    /// the path follows the seabed).
    pub off_seabed_m: f64,
}

impl CrawlerFigures {
    /// The figures of the trajectory points `points` under `model`.
    pub fn of(model: &CrawlerModel, points: &[Vec3]) -> CrawlerFigures {
        let t = model.terms(points);
        let off = points
            .iter()
            .map(|p| (p.z - model.terrain.elevation(p.x, p.y) - model.sensor_height_m).abs())
            .fold(0.0, f64::max);
        CrawlerFigures {
            length_m: t.length_m,
            undulation_m: t.undulation_m,
            energy_kwh: t.energy_kwh,
            slip_cost: t.slip,
            min_hazard_clearance_m: t
                .min_hazard_clearance_m
                .is_finite()
                .then_some(t.min_hazard_clearance_m),
            hazard_intrusions: t.hazard_intrusions,
            max_slope_deg: t.max_slope_deg,
            slope_limit_deg: model.max_slope_deg,
            off_seabed_m: off,
        }
    }

    /// Broken crawler constraints, in plain words (the slope limit is the pitch limit, which
    /// the plan checks for every vehicle).
    pub fn violations(&self, id: &str) -> Vec<String> {
        let mut out = Vec::new();
        if self.hazard_intrusions > 0 {
            out.push(format!(
                "{id} enters {} hazard zone(s) of soft substrate (clearance {:.2} m)",
                self.hazard_intrusions,
                self.min_hazard_clearance_m.unwrap_or(0.0)
            ));
        }
        if self.off_seabed_m > 1e-6 {
            out.push(format!(
                "{id} is a crawler but its path leaves the seabed by {:.3} m",
                self.off_seabed_m
            ));
        }
        out
    }
}

/// The crawler model as a swarm problem: genes are `(x, y)` of each control point.
#[derive(Debug, Clone)]
pub struct CrawlerProblem {
    /// The model.
    pub model: CrawlerModel,
    reference: CrawlerTerms,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl CrawlerProblem {
    /// The problem of `model` (the straight path's terms are computed once here).
    pub fn new(model: CrawlerModel) -> CrawlerProblem {
        let [x0, y0, x1, y1] = model.area;
        let n = model.control_points;
        CrawlerProblem {
            reference: model.reference(),
            lower: [x0, y0].repeat(n),
            upper: [x1, y1].repeat(n),
            model,
        }
    }

    /// Terms of a particle.
    pub fn terms(&self, genes: &[f64]) -> CrawlerTerms {
        self.model.terms(&self.model.path(genes))
    }
}

impl Problem for CrawlerProblem {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn cost(&self, x: &[f64]) -> f64 {
        self.model.cost_of(&self.terms(x), &self.reference)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swarm::ipso::Ipso;
    use crate::swarm::{Executor, SolverState};
    use crate::terrain::{BaseRelief, HeightGrid, Mountain};
    use approx::assert_abs_diff_eq;

    /// `Z1 = sin(y)`: level along y = 0, the line the hill test drives on.
    fn level() -> BaseRelief {
        BaseRelief {
            a: 0.0,
            b: 0.0,
            c: 0.0,
            d: 0.0,
            e: 0.0,
            f: 0.0,
            g: 0.0,
            length_scale_m: 1.0,
            height_scale_m: 1.0,
            datum_m: 0.0,
        }
    }

    /// Level ground: a flat height grid (eq. (2)'s `sin(y + a)` has no coefficient, so no
    /// analytic relief is flat).
    fn flat() -> Terrain {
        match HeightGrid::new([0.0, -50.0], 50.0, 3, 3, vec![0.0; 9]) {
            Ok(g) => Terrain::Grid(g),
            Err(e) => panic!("{e}"),
        }
    }

    fn model(terrain: Terrain, hazards: Vec<Hazard>) -> CrawlerModel {
        CrawlerModel {
            terrain,
            hazards,
            start: [0.0, 0.0],
            goal: [100.0, 0.0],
            area: [0.0, -50.0, 100.0, 50.0],
            control_points: 3,
            samples: 101,
            sensor_height_m: 0.5,
            speed_mps: 1.0,
            power_kw: [90.0, 50.0, 5.0],
            mining_share: 0.6,
            safe_distance_m: [2.0, 10.0],
            max_slope_deg: 15.0,
            weights: [0.5, 0.2, 0.2, 0.1],
            penalty_weight: 10.0,
        }
    }

    fn hazard(x: f64, y: f64, r: f64) -> Hazard {
        Hazard {
            id: "h".into(),
            centre: [x, y],
            radius_m: r,
            height_m: 5.0,
        }
    }

    #[test]
    fn energy_and_slip_by_hand() {
        let m = model(flat(), vec![]);
        // 3600 m at 1 m/s: travel 1 h, mining 1.5 h → 1.5·90 + 1·50 + 2.5·5 = 197.5 kWh.
        assert_abs_diff_eq!(m.energy_kwh(3600.0), 197.5, epsilon = 1e-9);
        assert_eq!(m.slip_of(1.0), 1.0);
        assert_abs_diff_eq!(m.slip_of(6.0), 0.5);
        assert_eq!(m.slip_of(10.0), 0.0);
    }

    #[test]
    fn the_straight_path_on_flat_ground_by_hand() {
        let m = model(flat(), vec![hazard(50.0, 6.0, 2.0)]);
        let r = m.reference();
        // 100 m long, flat, at 4 m from the hazard's edge: D = (10 − 4)/8 = 0.75.
        assert_abs_diff_eq!(r.length_m, 100.0, epsilon = 1e-9);
        assert_abs_diff_eq!(r.undulation_m, 0.0, epsilon = 1e-12);
        assert_abs_diff_eq!(r.min_hazard_clearance_m, 4.0, epsilon = 1e-9);
        assert_abs_diff_eq!(r.slip, 0.75, epsilon = 1e-9);
        assert_eq!((r.penalty(), r.max_slope_deg), (0.0, 0.0));
        assert_abs_diff_eq!(m.energy_kwh(100.0), r.energy_kwh, epsilon = 1e-12);
        // Its standardised cost: 0.5 + 0.2·0 + 0.2·0.75 + 0.1.
        assert_abs_diff_eq!(m.cost_of(&r, &r), 0.75, epsilon = 1e-9);
    }

    #[test]
    fn the_path_is_draped_and_steep_legs_are_penalised() {
        // A 10 m mountain of spread 5 m on the straight line: legs steeper than 15°.
        let hill = Terrain::Analytic {
            base: level(),
            mountains: vec![Mountain {
                centre: [50.0, 0.0],
                height_m: 10.0,
                spread_m: [5.0, 5.0],
            }],
        };
        let m = model(hill, vec![]);
        let r = m.reference();
        assert!(r.max_slope_deg > 40.0, "{}", r.max_slope_deg);
        assert!(r.slope_penalty > 1.0 && r.hazard_penalty == 0.0);
        assert_abs_diff_eq!(r.undulation_m, 20.0, epsilon = 0.1);
        let p = m.path(&[25.0, 0.0, 50.0, 0.0, 75.0, 0.0]);
        assert_abs_diff_eq!(p[50].z, 10.5, epsilon = 1e-6);
    }

    /// Ground rising `rise` metres per metre along x (nodes at x = 0, 50, 100).
    fn tilted(rise: f64) -> Terrain {
        let row = [0.0, 50.0 * rise, 100.0 * rise];
        match HeightGrid::new([0.0, -50.0], 50.0, 3, 3, row.repeat(3)) {
            Ok(g) => Terrain::Grid(g),
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn undulation_slope_and_their_scales_on_a_tilted_plane_by_hand() {
        // Rising 0.1 m per metre: the straight path climbs 10 m over 100 m.
        let m = model(tilted(0.1), vec![]);
        let r = m.reference();
        let length = (100.0f64 * 100.0 + 10.0 * 10.0).sqrt();
        assert_abs_diff_eq!(r.length_m, length, epsilon = 1e-9);
        assert_abs_diff_eq!(r.undulation_m, 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(r.max_slope_deg, 0.1f64.atan().to_degrees(), epsilon = 1e-9);
        assert_eq!(r.penalty(), 0.0);
        // Undulation is scaled by the reference *length*: 0.5·1 + 0.2·10/100.499 + 0 + 0.1·1.
        assert_abs_diff_eq!(m.cost_of(&r, &r), 0.6 + 0.2 * 10.0 / length, epsilon = 1e-9);
        // Rising 0.5 m per metre (26.57°) against a 15° limit: each of the 100 sample legs pays
        // 1 + (26.57 − 15) / 15.
        let steep = model(tilted(0.5), vec![]).reference();
        let slope = 0.5f64.atan().to_degrees();
        assert_abs_diff_eq!(steep.max_slope_deg, slope, epsilon = 1e-9);
        assert_abs_diff_eq!(
            steep.slope_penalty,
            100.0 * (1.0 + (slope - 15.0) / 15.0),
            epsilon = 1e-6
        );
    }

    #[test]
    fn the_path_is_the_smoothed_curve_not_the_control_polygon() {
        // Start (0, 0), control points (25, 20), (50, 40), (75, 20), goal (100, 0): knots
        // 0 0 0 0 ½ 1 1 1 1. At u = ½ the bases are (0, ¼, ½, ¼, 0): the curve passes (50, 30),
        // 10 m inside the polygon's corner at (50, 40); at u = ¼ they are (1/8, 19/32, 1/4,
        // 1/32, 0): (29.6875, 22.5).
        let m = model(flat(), vec![]);
        let p = m.path(&[25.0, 20.0, 50.0, 40.0, 75.0, 20.0]);
        assert_eq!(p.len(), 101);
        assert_abs_diff_eq!(p[50], Vec3::new(50.0, 30.0, 0.5), epsilon = 1e-9);
        assert_abs_diff_eq!(p[25], Vec3::new(29.6875, 22.5, 0.5), epsilon = 1e-9);
        // The reported length is the curve's, shorter than the polygon's 4 · √(25² + 20²).
        let t = m.terms(&p);
        assert_abs_diff_eq!(t.length_m, polyline_length(&p), epsilon = 1e-12);
        assert!(t.length_m < 4.0 * (25.0f64 * 25.0 + 20.0 * 20.0).sqrt() - 5.0);
    }

    #[test]
    fn ipso_steers_around_a_hazard_on_the_straight_line() {
        let m = model(flat(), vec![hazard(50.0, 0.0, 8.0)]);
        let problem = CrawlerProblem::new(m);
        let straight = problem.model.reference();
        assert!(straight.hazard_penalty > 0.0 && straight.hazard_intrusions == 1);
        let out = Executor::new(100).run(&problem, &mut Ipso::table8(30, 2), |_| {});
        let t = problem.terms(out.state.best_position());
        assert_eq!(t.penalty(), 0.0, "{t:?}");
        assert!(t.min_hazard_clearance_m >= 0.0);
        // Around an 8 m circle the detour is short: well under 20 % longer.
        assert!(t.length_m < 120.0, "{t:?}");
    }
}
