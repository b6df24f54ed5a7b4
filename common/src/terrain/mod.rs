//! Seabed terrain for crawlers (Lu et al. 2023, §2.2): analytic relief with Gaussian mountains, or a
//! measured height grid loaded from CSV / ESRI ASCII; plus soft-substrate hazard cylinders.
//!
//! Frame: x east, y north, z up (metres). A crawler drives *on* the seabed, so the z of its path is
//! [`Terrain::elevation`] plus its sensor height ([`Terrain::crawler_z`]).

use serde::{Deserialize, Serialize};

use crate::geometry::Vec3;

mod grid;
pub use grid::{HeightGrid, Problem, TerrainError};

/// Constants `a…g` of the base relief, Lu et al. 2023, eq. (2). The paper does not give values: they are
/// data of the terrain, supplied by the scenario.
///
/// Eq. (2) read literally in metres (`sin(y + a)` with unit amplitude and a 6.3 m wavelength) has
/// 45° slopes everywhere, which contradicts the gentle seamount summit of §2.1 and the paper's own
/// result (path undulation < 1 m over 283 m, §5.2). Shoal therefore evaluates eq. (2) in scaled
/// coordinates: `Z1(x, y) = height_scale_m · eq2(x / length_scale_m, y / length_scale_m)`. Both
/// scales default to 1 (the literal reading).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseRelief {
    /// Phase of the `sin(y + a)` term, radians.
    pub a: f64,
    /// Amplitude of `sin(x)`, metres.
    pub b: f64,
    /// Amplitude of `cos(d·r)`, metres.
    pub c: f64,
    /// Radial frequency of the cosine ring, rad/m.
    pub d: f64,
    /// Amplitude of `cos(y)`, metres.
    pub e: f64,
    /// Amplitude of `sin(g·r)`, metres.
    pub f: f64,
    /// Radial frequency of the sine ring, rad/m.
    pub g: f64,
    /// Horizontal unit of eq. (2), metres (default 1).
    #[serde(default = "unit_scale")]
    pub length_scale_m: f64,
    /// Vertical unit of eq. (2), metres (default 1).
    #[serde(default = "unit_scale")]
    pub height_scale_m: f64,
    /// Added to eq. (2) so that "the lowest point of the base plane corresponds to Z = 0"
    /// (§2.1). Not read from files: a scenario sets it when loaded ([`BaseRelief::lowest`]).
    #[serde(skip)]
    pub datum_m: f64,
}

fn unit_scale() -> f64 {
    1.0
}

impl BaseRelief {
    /// Lowest elevation over the box `[x0, y0, x1, y1]`, sampled on a grid of at most 0.5 m
    /// (and at most 1000 × 1000 points).
    pub fn lowest(&self, area: [f64; 4]) -> f64 {
        let [x0, y0, x1, y1] = area;
        let steps = |span: f64| ((span / 0.5).ceil() as usize).clamp(1, 1000);
        let (nx, ny) = (steps(x1 - x0), steps(y1 - y0));
        let mut low = f64::INFINITY;
        for i in 0..=nx {
            for j in 0..=ny {
                let x = x0 + (x1 - x0) * i as f64 / nx as f64;
                let y = y0 + (y1 - y0) * j as f64 / ny as f64;
                low = low.min(self.elevation(x, y));
            }
        }
        low
    }

    /// `Z1(x, y)`, Lu et al. 2023, eq. (2), in the scaled coordinates above.
    pub fn elevation(&self, x: f64, y: f64) -> f64 {
        let (x, y) = (x / self.length_scale_m, y / self.length_scale_m);
        let r = x.hypot(y);
        self.datum_m
            + self.height_scale_m
                * ((y + self.a).sin()
                    + self.b * x.sin()
                    + self.c * (self.d * r).cos()
                    + self.e * y.cos()
                    + self.f * (self.g * r).sin())
    }

    /// `∇Z1`, derived by hand from eq. (2). With `r = √(x² + y²)`, the two ring terms give
    /// `(−c·d·sin(d r) + f·g·cos(g r))·(x, y)/r`. At `r = 0` the `sin(g r)` ring is a cone tip (not
    /// differentiable); we return the symmetric value 0 for the radial part there.
    ///
    /// With the scales, the chain rule multiplies the unscaled gradient by `height / length`.
    pub fn gradient(&self, x: f64, y: f64) -> (f64, f64) {
        let k = self.height_scale_m / self.length_scale_m;
        let (x, y) = (x / self.length_scale_m, y / self.length_scale_m);
        let r = x.hypot(y);
        let radial = if r > 0.0 {
            (-self.c * self.d * (self.d * r).sin() + self.f * self.g * (self.g * r).cos()) / r
        } else {
            0.0
        };
        (
            k * (self.b * x.cos() + radial * x),
            k * ((y + self.a).cos() - self.e * y.sin() + radial * y),
        )
    }
}

/// One Gaussian mountain of Lu et al. 2023, eq. (3). Spreads must be positive (a zero spread yields NaN).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mountain {
    /// `(x_i, y_i)`: where the peak stands, metres.
    pub centre: [f64; 2],
    /// `h_i`: peak height above the base relief, metres.
    pub height_m: f64,
    /// `(x_si, y_si)`: attenuation lengths along x and y; at one spread the height is `h·e⁻¹`.
    pub spread_m: [f64; 2],
}

impl Mountain {
    /// `u, v` (normalised offsets) and `h·exp(−u² − v²)`, shared by value and gradient.
    fn parts(&self, x: f64, y: f64) -> (f64, f64, f64) {
        let u = (x - self.centre[0]) / self.spread_m[0];
        let v = (y - self.centre[1]) / self.spread_m[1];
        (u, v, self.height_m * (-u * u - v * v).exp())
    }

    /// This mountain's term of `Z2`, Lu et al. 2023, eq. (3).
    pub fn elevation(&self, x: f64, y: f64) -> f64 {
        self.parts(x, y).2
    }

    /// Gradient of the term: `h·E·(−2u/x_s, −2v/y_s)` with `E = exp(−u² − v²)`.
    pub fn gradient(&self, x: f64, y: f64) -> (f64, f64) {
        let (u, v, he) = self.parts(x, y);
        (
            -2.0 * u / self.spread_m[0] * he,
            -2.0 * v / self.spread_m[1] * he,
        )
    }
}

/// A soft-substrate hazard zone, the vertical cylinder `T_k` of Lu et al. 2023, eq. (4).
///
/// A crawler rides on the seabed and is therefore always within the cylinder's vertical span:
/// only the horizontal clearance ([`hazard_clearance`]) matters for it. `height_m` is kept for
/// swimmers and for display.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hazard {
    /// Name used in reports and logs.
    pub id: String,
    /// `(x_k, y_k)`: centre of the cylinder's cross-section, metres.
    pub centre: [f64; 2],
    /// `r_k`: radius of the cross-section, metres.
    pub radius_m: f64,
    /// `z_k`: height of the cylinder, metres.
    pub height_m: f64,
}

/// The seabed a crawler drives on.
#[derive(Debug, Clone, PartialEq)]
pub enum Terrain {
    /// Lu et al. 2023 model: elevation `Z1 + Z2` (eq. (2) + eq. (3)). The paper's MATLAB tradition takes
    /// `max(Z1, Z2)`; we add instead, which keeps the slope continuous where a mountain meets the
    /// base relief (a `max` has a crease there that a slope limit would see as a step).
    Analytic {
        /// Base relief `Z1`, eq. (2).
        base: BaseRelief,
        /// Mountains summed into `Z2`, eq. (3).
        mountains: Vec<Mountain>,
    },
    /// Zhang et al. 2022, eq. (1): Gaussian hills on a flat floor at z = 0, no base relief.
    Hills(Vec<Mountain>),
    /// Measured bathymetry, bilinearly interpolated.
    Grid(HeightGrid),
}

impl Terrain {
    /// Seabed elevation at `(x, y)`, metres (Lu et al. 2023, eq. (2) + (3), or the grid).
    pub fn elevation(&self, x: f64, y: f64) -> f64 {
        match self {
            Terrain::Analytic { base, mountains } => {
                base.elevation(x, y) + mountains.iter().map(|m| m.elevation(x, y)).sum::<f64>()
            }
            Terrain::Hills(hills) => hills.iter().map(|m| m.elevation(x, y)).sum(),
            Terrain::Grid(grid) => grid.elevation(x, y),
        }
    }

    /// `(∂z/∂x, ∂z/∂y)`: exact derivative of the analytic model, or of the bilinear patch.
    pub fn gradient(&self, x: f64, y: f64) -> (f64, f64) {
        match self {
            Terrain::Analytic { base, mountains } => {
                mountains.iter().fold(base.gradient(x, y), |(gx, gy), m| {
                    let (mx, my) = m.gradient(x, y);
                    (gx + mx, gy + my)
                })
            }
            Terrain::Hills(hills) => hills.iter().fold((0.0, 0.0), |(gx, gy), m| {
                let (mx, my) = m.gradient(x, y);
                (gx + mx, gy + my)
            }),
            Terrain::Grid(grid) => grid.gradient(x, y),
        }
    }

    /// Steepest slope at `(x, y)`: `atan(|∇z|)` in degrees.
    pub fn slope_deg(&self, x: f64, y: f64) -> f64 {
        let (gx, gy) = self.gradient(x, y);
        gx.hypot(gy).atan().to_degrees()
    }

    /// z of a crawler's sensor at `(x, y)`: the seabed plus the sensor's height above it.
    pub fn crawler_z(&self, x: f64, y: f64, sensor_height_m: f64) -> f64 {
        self.elevation(x, y) + sensor_height_m
    }

    /// An upper bound of the elevation anywhere: eq. (2)'s five terms at their largest
    /// (`height_scale · (1 + |b| + |c| + |e| + |f|)` over the datum) plus every mountain's peak,
    /// or the grid's highest node. A leg above it plus a clearance needs no sampling.
    pub fn ceiling(&self) -> f64 {
        let peaks = |m: &[Mountain]| m.iter().map(|m| m.height_m.max(0.0)).sum::<f64>();
        match self {
            Terrain::Analytic { base, mountains } => {
                let amplitude = 1.0 + base.b.abs() + base.c.abs() + base.e.abs() + base.f.abs();
                base.datum_m + base.height_scale_m.abs() * amplitude + peaks(mountains)
            }
            Terrain::Hills(hills) => peaks(hills),
            Terrain::Grid(grid) => grid.max_height(),
        }
    }

    /// Lowest height above the seabed of the straight leg `a→b` (negative: through it) and
    /// where it is, sampled at both ends and at `⌈|ab| / step⌉ − 1` evenly spaced points
    /// between them. A swimmer's leg is straight but the seabed under it is not, so its ends
    /// alone would miss a hill between two waypoints.
    pub fn lowest_height_along(&self, a: &Vec3, b: &Vec3, step: f64) -> (f64, Vec3) {
        let n = ((b - a).norm() / step.max(1e-6)).ceil().max(1.0) as usize;
        (0..=n)
            .map(|k| a + (b - a) * (k as f64 / n as f64))
            .map(|p| (p.z - self.elevation(p.x, p.y), p))
            .fold(
                (f64::INFINITY, *a),
                |best, h| if h.0 < best.0 { h } else { best },
            )
    }

    /// Lowest height above the seabed of the polyline `points` and where
    /// ([`Terrain::lowest_height_along`] on each leg; a lone point is its own height); `None`
    /// without points. What a plan's AUV path and an executed track are both measured with.
    pub fn lowest_height_on_path(&self, points: &[Vec3], step: f64) -> Option<(f64, Vec3)> {
        let first = points.first()?;
        let start = (first.z - self.elevation(first.x, first.y), *first);
        Some(
            points
                .windows(2)
                .map(|w| self.lowest_height_along(&w[0], &w[1], step))
                .fold(start, |best, h| if h.0 < best.0 { h } else { best }),
        )
    }
}

/// Horizontal clearance of segment `a→b` from hazard `h` (Lu et al. 2023, eq. (4)): distance from the
/// exact closest point of the segment to the centre, minus the radius. Negative means the segment
/// enters the cylinder.
pub fn hazard_clearance(h: &Hazard, a: [f64; 2], b: [f64; 2]) -> f64 {
    let (kx, ky) = (b[0] - a[0], b[1] - a[1]);
    let (px, py) = (h.centre[0] - a[0], h.centre[1] - a[1]);
    let len2 = kx * kx + ky * ky;
    let u = if len2 > 0.0 {
        ((px * kx + py * ky) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (px - u * kx).hypot(py - u * ky) - h.radius_m
}

/// Smallest [`hazard_clearance`] over every leg of the polyline `points` and every hazard;
/// `INFINITY` without hazards or points. A single point counts as a zero-length leg.
pub fn path_min_hazard_clearance(hazards: &[Hazard], points: &[[f64; 2]]) -> f64 {
    let legs: Vec<([f64; 2], [f64; 2])> = match points {
        [p] => vec![(*p, *p)],
        _ => points.windows(2).map(|w| (w[0], w[1])).collect(),
    };
    hazards
        .iter()
        .flat_map(|h| legs.iter().map(move |&(a, b)| hazard_clearance(h, a, b)))
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::{E, FRAC_PI_2};

    type TestResult = Result<(), Box<dyn std::error::Error>>;

    /// The ceiling is above every sampled elevation of an analytic seabed with mountains (one
    /// a pit) and equals a lone hill's peak; a grid's is its highest node.
    #[test]
    fn the_ceiling_bounds_the_seabed() -> TestResult {
        let mut base = relief();
        base.datum_m = 1.5;
        let mountains = vec![
            Mountain {
                centre: [30.0, 40.0],
                height_m: 4.0,
                spread_m: [8.0, 6.0],
            },
            Mountain {
                centre: [60.0, 20.0],
                height_m: -3.0,
                spread_m: [5.0, 5.0],
            },
        ];
        let t = Terrain::Analytic { base, mountains };
        let top = t.ceiling();
        let b = relief();
        let expect = 1.5 + b.height_scale_m * (1.0 + b.b + b.c + b.e + b.f) + 4.0;
        assert_abs_diff_eq!(top, expect, epsilon = 1e-12);
        for i in 0..=100 {
            for j in 0..=100 {
                let z = t.elevation(i as f64, j as f64);
                assert!(z <= top, "{z} over {top} at ({i}, {j})");
            }
        }
        let hill = Terrain::Hills(vec![Mountain {
            centre: [0.0, 0.0],
            height_m: 7.0,
            spread_m: [3.0, 3.0],
        }]);
        assert_abs_diff_eq!(hill.ceiling(), 7.0);
        assert_abs_diff_eq!(hill.ceiling(), hill.elevation(0.0, 0.0));
        let grid = HeightGrid::new([0.0, 0.0], 1.0, 2, 2, vec![1.0, 5.0, -2.0, 3.0])?;
        assert_abs_diff_eq!(Terrain::Grid(grid).ceiling(), 5.0);
        Ok(())
    }

    /// A 10 m Gaussian hill (σ = 10 m) at x = 50 under a leg at z = 12 from x = 0 to 100: the
    /// ends are 12 m up (the hill is e^-12.5 ≈ 0 there), the lowest point is over the summit,
    /// 12 − 10 = 2 m up; at z = 8 the leg goes 2 m into it.
    #[test]
    fn the_lowest_height_of_a_leg_is_over_the_hill_between_its_ends() {
        let hill = Terrain::Hills(vec![Mountain {
            centre: [50.0, 0.0],
            height_m: 10.0,
            spread_m: [10.0, 10.0],
        }]);
        let at = |z: f64| (Vec3::new(0.0, 0.0, z), Vec3::new(100.0, 0.0, z));
        let (a, b) = at(12.0);
        let (h, p) = hill.lowest_height_along(&a, &b, 1.0);
        assert_abs_diff_eq!(h, 2.0, epsilon = 1e-9);
        assert_abs_diff_eq!(p.x, 50.0, epsilon = 1e-9);
        let (a, b) = at(8.0);
        assert_abs_diff_eq!(
            hill.lowest_height_along(&a, &b, 1.0).0,
            -2.0,
            epsilon = 1e-9
        );
        // Only the ends (a step longer than the leg): the hill is missed.
        assert!(hill.lowest_height_along(&a, &b, 200.0).0 > 7.9);
        // A zero-length leg is its one point.
        assert_abs_diff_eq!(hill.lowest_height_along(&a, &a, 1.0).0, 8.0, epsilon = 1e-4);
    }

    fn relief() -> BaseRelief {
        BaseRelief {
            a: FRAC_PI_2,
            b: 0.8,
            c: 0.5,
            d: 0.7,
            e: 0.6,
            f: 0.4,
            g: 1.3,
            length_scale_m: 1.0,
            height_scale_m: 1.0,
            datum_m: 0.0,
        }
    }

    #[test]
    fn scaled_relief_stretches_and_lifts_eq2() {
        let unit = relief();
        let scaled = BaseRelief {
            length_scale_m: 40.0,
            height_scale_m: 0.25,
            ..unit
        };
        // Z1(80, 40) scaled = 0.25 · eq2(2, 1).
        assert_abs_diff_eq!(
            scaled.elevation(80.0, 40.0),
            0.25 * unit.elevation(2.0, 1.0),
            epsilon = 1e-12
        );
        let h = 1e-4;
        let (gx, gy) = scaled.gradient(30.0, -12.0);
        let dx =
            (scaled.elevation(30.0 + h, -12.0) - scaled.elevation(30.0 - h, -12.0)) / (2.0 * h);
        let dy =
            (scaled.elevation(30.0, -12.0 + h) - scaled.elevation(30.0, -12.0 - h)) / (2.0 * h);
        assert_abs_diff_eq!(gx, dx, epsilon = 1e-7);
        assert_abs_diff_eq!(gy, dy, epsilon = 1e-7);
        // The datum lifts the lowest point of a box to 0: Z1 = sin(y) over y ∈ [0, 2π].
        let wave = BaseRelief {
            a: 0.0,
            b: 0.0,
            c: 0.0,
            d: 0.0,
            e: 0.0,
            f: 0.0,
            g: 0.0,
            length_scale_m: 1.0,
            height_scale_m: 2.0,
            datum_m: 0.0,
        };
        let low = wave.lowest([0.0, 0.0, 1.0, std::f64::consts::TAU]);
        // Sampled every ~0.48 m along y: within 2·(1 − cos(0.24)) ≈ 0.057 m of the true −2.
        assert!((-2.0..-2.0 + 0.06).contains(&low), "{low}");
        let lifted = BaseRelief {
            datum_m: -low,
            ..wave
        };
        // At the origin eq. (2) gives 0, lifted by −low ≈ 2.
        assert_abs_diff_eq!(lifted.elevation(0.0, 0.0), -low, epsilon = 1e-12);
    }

    fn analytic() -> Terrain {
        let mountains = vec![
            Mountain {
                centre: [3.0, -2.0],
                height_m: 5.0,
                spread_m: [2.0, 3.0],
            },
            Mountain {
                centre: [-4.0, 1.0],
                height_m: 2.5,
                spread_m: [1.5, 1.0],
            },
        ];
        Terrain::Analytic {
            base: relief(),
            mountains,
        }
    }

    #[test]
    fn base_relief_at_origin_is_sin_a_plus_c_plus_e() {
        // sin(π/2) + 0.8·sin 0 + 0.5·cos 0 + 0.6·cos 0 + 0.4·sin 0 = 1 + 0.5 + 0.6
        assert_abs_diff_eq!(relief().elevation(0.0, 0.0), 2.1, epsilon = 1e-12);
    }

    #[test]
    fn mountain_peak_and_one_spread() {
        let m = Mountain {
            centre: [10.0, 20.0],
            height_m: 7.0,
            spread_m: [4.0, 9.0],
        };
        assert_abs_diff_eq!(m.elevation(10.0, 20.0), 7.0, epsilon = 1e-12);
        assert_abs_diff_eq!(m.elevation(14.0, 20.0), 7.0 / E, epsilon = 1e-12);
        assert_abs_diff_eq!(m.elevation(10.0, 11.0), 7.0 / E, epsilon = 1e-12);
    }

    #[test]
    fn analytic_elevation_is_sum_of_relief_and_mountains() {
        let t = analytic();
        // At the first peak: Z1(3, −2) + 5 + the second mountain's tail.
        let tail = 2.5 * (-(7.0_f64 / 1.5).powi(2) - 9.0).exp();
        let expected = relief().elevation(3.0, -2.0) + 5.0 + tail;
        assert_abs_diff_eq!(t.elevation(3.0, -2.0), expected, epsilon = 1e-12);
    }

    #[test]
    fn analytic_gradient_matches_central_differences() {
        let t = analytic();
        let h = 1e-5;
        for &(x, y) in &[
            (0.3, 0.2),
            (3.0, -2.0),
            (-4.2, 1.3),
            (5.5, 7.1),
            (-1.0, -6.0),
        ] {
            let (gx, gy) = t.gradient(x, y);
            let dx = (t.elevation(x + h, y) - t.elevation(x - h, y)) / (2.0 * h);
            let dy = (t.elevation(x, y + h) - t.elevation(x, y - h)) / (2.0 * h);
            assert_abs_diff_eq!(gx, dx, epsilon = 1e-5);
            assert_abs_diff_eq!(gy, dy, epsilon = 1e-5);
        }
        let (gx, gy) = t.gradient(0.0, 0.0);
        assert!(gx.is_finite() && gy.is_finite());
    }

    fn hazard(x: f64, y: f64, r: f64) -> Hazard {
        Hazard {
            id: "soft".to_string(),
            centre: [x, y],
            radius_m: r,
            height_m: 3.0,
        }
    }

    #[test]
    fn hazard_clearance_cases() {
        let h = hazard(0.0, 0.0, 2.0);
        assert_abs_diff_eq!(hazard_clearance(&h, [-5.0, 0.0], [5.0, 0.0]), -2.0);
        assert_abs_diff_eq!(hazard_clearance(&h, [-5.0, 5.0], [5.0, 5.0]), 3.0);
        // Closest point is endpoint b = (3, 4): distance 5, clearance 3.
        assert_abs_diff_eq!(hazard_clearance(&h, [9.0, 12.0], [3.0, 4.0]), 3.0);
        assert_abs_diff_eq!(hazard_clearance(&h, [3.0, 4.0], [3.0, 4.0]), 3.0);
    }

    #[test]
    fn path_min_clearance_over_legs_and_hazards() {
        let hs = [hazard(0.0, 0.0, 2.0), hazard(10.0, 10.0, 1.0)];
        let path = [[-5.0, 5.0], [5.0, 5.0], [5.0, 10.0]];
        // Leg 2 passes 5 m from the second centre (clearance 4); leg 1 is 5 m from the first (3).
        assert_abs_diff_eq!(path_min_hazard_clearance(&hs, &path), 3.0);
        assert_eq!(path_min_hazard_clearance(&[], &path), f64::INFINITY);
        assert_abs_diff_eq!(path_min_hazard_clearance(&hs, &[[0.0, 4.0]]), 2.0);
        assert_eq!(path_min_hazard_clearance(&hs, &[]), f64::INFINITY);
    }

    #[test]
    fn serde_rejects_unknown_fields() -> TestResult {
        let ok: BaseRelief = toml::from_str("a=1\nb=2\nc=3\nd=4\ne=5\nf=6\ng=7")?;
        assert_eq!(ok.g, 7.0);
        assert!(toml::from_str::<BaseRelief>("a=1\nb=2\nc=3\nd=4\ne=5\nf=6\ng=7\nh=8").is_err());
        Ok(())
    }
}
