//! Seeded 2D gradient noise for the "minor undulation" of the seabed sediment (CPP-DSMV, §2.1:
//! "the base undulations are modeled using continuous Perlin noise"; §3: the 1000 m × 1000 m
//! test map integrates Perlin noise with Gaussian functions).
//!
//! [`Perlin`] is Ken Perlin's *improved noise* (SIGGRAPH 2002) restricted to two dimensions:
//!
//! - lattice cell `(X, Y) = (⌊x⌋, ⌊y⌋)`, offsets `(u, v) = (x − X, y − Y)` in `[0, 1)`;
//! - fade `f(t) = 6t⁵ − 15t⁴ + 10t³` (C² at the lattice lines: `f′ = f″ = 0` at 0 and 1), with
//!   `f′(t) = 30t⁴ − 60t³ + 30t²`;
//! - corner hash `h(i, j) = P[P[(X + i) mod 256] + (Y + j) mod 256]` where `P` is a permutation of
//!   `0..256` **shuffled by the injected seeded RNG** (Perlin's fixed table is one such
//!   permutation), stored twice so that the inner sum needs no second modulo;
//! - corner gradient `g = G[h mod 8]` from the eight directions
//!   `(±1, ±1), (±1, 0), (0, ±1)`, and corner value `n_ij = g · (u − i, v − j)`;
//! - `N(x, y) = lerp(f(v), lerp(f(u), n00, n10), lerp(f(u), n01, n11))`.
//!
//! Properties used by the tests and by the terrain layer: `N = 0` at every lattice point (all
//! four corner terms vanish or are faded out); `N` is C² continuous; and `|N| ≤ 1`. The bound: for
//! unit-length gradients the range of n-dimensional Perlin noise is `±√n / 2` (±0.707 in 2D), and
//! `N` is linear in the gradients, whose longest here is `√2`, so `|N| ≤ √2 · √2 / 2 = 1`.
//!
//! [`FractalNoise`] sums octaves (fractional Brownian motion):
//! `U(x, y) = A · Σₖ pᵏ N_k(2ᵏ x / λ, 2ᵏ y / λ) / Σₖ pᵏ`, `k = 0 … octaves − 1`, with amplitude
//! `A`, wavelength `λ` (of the coarsest octave's lattice) and persistence `p`. Dividing by `Σ pᵏ`
//! keeps `|U| ≤ A` whatever the octave count. Each octave has its own permutation, drawn from
//! the same RNG in octave order, so octaves are not scaled copies of each other. Every point
//! `(mλ, nλ)` is a lattice point of every octave, hence `U = 0` there.

use rand::seq::SliceRandom;
use rand::Rng;

/// Gradient directions of the 2D improved noise, indexed by `hash & 7`.
const GRADIENTS: [(f64, f64); 8] = [
    (1.0, 1.0),
    (-1.0, 1.0),
    (1.0, -1.0),
    (-1.0, -1.0),
    (1.0, 0.0),
    (-1.0, 0.0),
    (0.0, 1.0),
    (0.0, -1.0),
];

/// `6t⁵ − 15t⁴ + 10t³`.
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// `30t⁴ − 60t³ + 30t²`, the derivative of [`fade`].
fn fade_slope(t: f64) -> f64 {
    30.0 * t * t * (t * (t - 2.0) + 1.0)
}

/// Lattice index of a coordinate, modulo 256 (never panics; NaN maps to 0 and saturates).
fn wrap(cell: f64) -> usize {
    (cell as i64).rem_euclid(256) as usize
}

/// One octave of 2D improved Perlin noise with a seeded permutation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Perlin {
    /// The shuffled permutation of `0..256`, twice.
    perm: Vec<usize>,
}

impl Perlin {
    /// Draws the permutation from `rng` (a Fisher–Yates shuffle of `0..256`).
    pub fn new<R: Rng + ?Sized>(rng: &mut R) -> Self {
        let mut base: Vec<usize> = (0..256).collect();
        base.shuffle(rng);
        let perm = base.iter().chain(base.iter()).copied().collect();
        Self { perm }
    }

    /// Hash of lattice corner `(xi, yi)`, both already in `0..256`; in `0..256`.
    fn hash(&self, xi: usize, yi: usize) -> usize {
        let at = |k: usize| self.perm.get(k).copied().unwrap_or(0);
        at(at(xi) + yi)
    }

    /// `N(x, y)` and `∇N(x, y)`, in lattice units.
    pub fn value_and_gradient(&self, x: f64, y: f64) -> (f64, [f64; 2]) {
        let (xf, yf) = (x.floor(), y.floor());
        let (u, v) = (x - xf, y - yf);
        let (xi, yi) = (wrap(xf), wrap(yf));
        let (xj, yj) = ((xi + 1) % 256, (yi + 1) % 256);
        // Corner gradients and corner values n = g · (u − i, v − j).
        let corner = |hx: usize, hy: usize, du: f64, dv: f64| {
            let (gx, gy) = GRADIENTS[self.hash(hx, hy) & 7];
            (gx * du + gy * dv, gx, gy)
        };
        let (n00, gx00, gy00) = corner(xi, yi, u, v);
        let (n10, gx10, gy10) = corner(xj, yi, u - 1.0, v);
        let (n01, gx01, gy01) = corner(xi, yj, u, v - 1.0);
        let (n11, gx11, gy11) = corner(xj, yj, u - 1.0, v - 1.0);
        let (fu, fv) = (fade(u), fade(v));
        let (dfu, dfv) = (fade_slope(u), fade_slope(v));
        // a = lerp(fu, n00, n10) (south edge), b = lerp(fu, n01, n11) (north edge).
        let a = n00 + fu * (n10 - n00);
        let b = n01 + fu * (n11 - n01);
        let value = a + fv * (b - a);
        let da_du = gx00 + dfu * (n10 - n00) + fu * (gx10 - gx00);
        let db_du = gx01 + dfu * (n11 - n01) + fu * (gx11 - gx01);
        let da_dv = gy00 + fu * (gy10 - gy00);
        let db_dv = gy01 + fu * (gy11 - gy01);
        let du = da_du + fv * (db_du - da_du);
        let dv = da_dv + dfv * (b - a) + fv * (db_dv - da_dv);
        (value, [du, dv])
    }

    /// `N(x, y)` in `[−1, 1]`, lattice units (0 at every integer point).
    pub fn noise(&self, x: f64, y: f64) -> f64 {
        self.value_and_gradient(x, y).0
    }
}

/// Octave sum of [`Perlin`] noise in metres: the seabed's minor undulation `U(x, y)`.
#[derive(Debug, Clone, PartialEq)]
pub struct FractalNoise {
    octaves: Vec<Perlin>,
    amplitude_m: f64,
    wavelength_m: f64,
    persistence: f64,
}

impl FractalNoise {
    /// `octaves` permutations drawn from `rng` in order. Parameters are not checked here (the
    /// terrain spec validates them); a non-positive wavelength gives a non-finite field.
    pub fn new<R: Rng + ?Sized>(
        rng: &mut R,
        amplitude_m: f64,
        wavelength_m: f64,
        octaves: usize,
        persistence: f64,
    ) -> Self {
        Self {
            octaves: (0..octaves).map(|_| Perlin::new(rng)).collect(),
            amplitude_m,
            wavelength_m,
            persistence,
        }
    }

    /// `Σ pᵏ` over the octaves (the normaliser).
    fn weight_sum(&self) -> f64 {
        (0..self.octaves.len())
            .map(|k| self.persistence.powi(k as i32))
            .sum()
    }

    /// `U(x, y)` (metres) and `∇U(x, y)` (m/m): `∇U = A · Σ pᵏ (2ᵏ/λ) ∇N_k / Σ pᵏ`.
    pub fn value_and_gradient(&self, x: f64, y: f64) -> (f64, [f64; 2]) {
        let norm = self.weight_sum();
        if self.octaves.is_empty() || norm == 0.0 {
            return (0.0, [0.0, 0.0]);
        }
        let (mut value, mut gx, mut gy) = (0.0, 0.0, 0.0);
        for (k, octave) in self.octaves.iter().enumerate() {
            let weight = self.persistence.powi(k as i32);
            let freq = 2f64.powi(k as i32) / self.wavelength_m;
            let (n, [du, dv]) = octave.value_and_gradient(x * freq, y * freq);
            value += weight * n;
            gx += weight * freq * du;
            gy += weight * freq * dv;
        }
        let k = self.amplitude_m / norm;
        (k * value, [k * gx, k * gy])
    }

    /// `U(x, y)`, metres, with `|U| ≤ amplitude`.
    pub fn value(&self, x: f64, y: f64) -> f64 {
        self.value_and_gradient(x, y).0
    }

    /// Amplitude `A`, the bound on `|U|`, metres.
    pub fn amplitude_m(&self) -> f64 {
        self.amplitude_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use rand::rngs::StdRng;
    use rand::SeedableRng;

    fn perlin(seed: u64) -> Perlin {
        Perlin::new(&mut StdRng::seed_from_u64(seed))
    }

    #[test]
    fn fade_is_smoothstep_of_order_five() {
        assert_eq!(fade(0.0), 0.0);
        assert_eq!(fade(1.0), 1.0);
        assert_abs_diff_eq!(fade(0.5), 0.5, epsilon = 1e-15);
        // 6/32 − 15/16 + 10/8 at t = ½ of the derivative: 30/16 − 60/8 + 30/4 = 1.875.
        assert_abs_diff_eq!(fade_slope(0.5), 1.875, epsilon = 1e-15);
        assert_eq!((fade_slope(0.0), fade_slope(1.0)), (0.0, 0.0));
    }

    #[test]
    fn perlin_is_zero_at_lattice_points() {
        let p = perlin(7);
        for x in -5..=5 {
            for y in [-300, -1, 0, 3, 255, 256, 1000] {
                assert_eq!(p.noise(f64::from(x), f64::from(y)), 0.0, "({x}, {y})");
            }
        }
    }

    #[test]
    fn perlin_is_bounded_on_a_sample() {
        let p = perlin(11);
        let mut rng = StdRng::seed_from_u64(99);
        let mut widest: f64 = 0.0;
        for _ in 0..20_000 {
            let (x, y) = (rng.random_range(-50.0..50.0), rng.random_range(-50.0..50.0));
            let n = p.noise(x, y);
            assert!((-1.0..=1.0).contains(&n), "N({x}, {y}) = {n}");
            widest = widest.max(n.abs());
        }
        // Not a degenerate (all-zero) field.
        assert!(widest > 0.3, "{widest}");
    }

    #[test]
    fn perlin_is_continuous_and_gradient_matches_differences() {
        let p = perlin(3);
        let mut rng = StdRng::seed_from_u64(5);
        let h = 1e-6;
        for _ in 0..500 {
            let (x, y) = (rng.random_range(-20.0..20.0), rng.random_range(-20.0..20.0));
            let (n, [gx, gy]) = p.value_and_gradient(x, y);
            // |∇N| ≤ a few units per lattice cell, so a 1e-6 step moves N by far less than 1e-4,
            // including across lattice lines.
            assert!((p.noise(x + h, y) - n).abs() < 1e-4);
            assert!((p.noise(x, y + h) - n).abs() < 1e-4);
            let dx = (p.noise(x + h, y) - p.noise(x - h, y)) / (2.0 * h);
            let dy = (p.noise(x, y + h) - p.noise(x, y - h)) / (2.0 * h);
            assert_abs_diff_eq!(gx, dx, epsilon = 1e-6);
            assert_abs_diff_eq!(gy, dy, epsilon = 1e-6);
        }
        // Across a lattice line: left and right limits agree.
        assert_abs_diff_eq!(p.noise(4.0 - 1e-12, 2.3), p.noise(4.0, 2.3), epsilon = 1e-9);
    }

    #[test]
    fn same_seed_same_noise_other_seed_differs() {
        let (a, b, c) = (perlin(42), perlin(42), perlin(43));
        assert_eq!(a, b);
        assert_ne!(a, c);
        let differs = (0..100).any(|k| {
            let t = f64::from(k) * 0.37 + 0.1;
            a.noise(t, 1.3 * t) != c.noise(t, 1.3 * t)
        });
        assert!(differs);
    }

    #[test]
    fn fractal_is_bounded_zero_on_coarse_lattice_and_differentiable() {
        let mut rng = StdRng::seed_from_u64(8);
        let u = FractalNoise::new(&mut rng, 2.0, 50.0, 4, 0.5);
        assert_eq!(u.value(100.0, -150.0), 0.0);
        let h = 1e-5;
        for k in 0..200 {
            let (x, y) = (f64::from(k) * 3.7 - 300.0, f64::from(k) * -2.3 + 90.0);
            let (z, [gx, gy]) = u.value_and_gradient(x, y);
            assert!(z.abs() <= 2.0);
            let dx = (u.value(x + h, y) - u.value(x - h, y)) / (2.0 * h);
            let dy = (u.value(x, y + h) - u.value(x, y - h)) / (2.0 * h);
            assert_abs_diff_eq!(gx, dx, epsilon = 1e-7);
            assert_abs_diff_eq!(gy, dy, epsilon = 1e-7);
        }
        // Odd inputs do not panic.
        assert!(u.value(f64::NAN, 0.0).is_nan());
        assert!(u.value(1e300, -1e300).is_finite());
    }
}
