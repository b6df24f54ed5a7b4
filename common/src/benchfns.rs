//! The benchmark functions of Lu et al. 2023, §4 (Table 3, f1–f12) and Hu et al.'s Schaffer F6
//! (eq. (26)), each a [`Problem`] with its known optimum value and one location of it, so the
//! optimizers can be compared as in Lu et al. 2023, Tables 5 and 6 (`shoal-coordinator bench-functions`).
//!
//! Search ranges are the papers' (Lu et al. 2023, Table 3, Hu et al. 2023, Table 1), each of which holds a
//! global minimiser. Formulas are the standard ones where the printed tables are garbled:
//! - f4 BentCigar: Table 3 prints the optimum at `[1, …, 1]`; `x1² + 10⁶ Σ x_i²` is 0 at the origin.
//! - f7 Ackley: Table 3 prints only the first term; the full function (Hu et al. 2023, eq. (23)) is used.
//! - f8 "Schaffer": see [`Schwefel`] for the reading and why.
//! - Schaffer F6: Hu et al. 2023, eq. (26) prints the denominator unsquared; the standard F6 squares it.
//!   Both are 0 at the origin.

use crate::swarm::Problem;

/// A benchmark function: a box-bounded [`Problem`] whose global minimum is known.
pub trait Benchmark: Problem {
    /// Command-line key, e.g. `six-hump-camel`.
    fn key(&self) -> &'static str;
    /// Display name, e.g. `Six-Hump Camel`.
    fn name(&self) -> &'static str;
    /// Where it comes from: `f1`…`f12` of Lu et al. 2023, Table 3, `F6` of Hu et al. 2023.
    fn label(&self) -> &'static str;
    /// The global minimum value f*.
    fn optimum(&self) -> f64;
    /// One location x* of the global minimum (f(x*) = f* up to rounding).
    fn optimum_at(&self) -> Vec<f64>;
}

/// Keys of all functions, in table order (f1–f12, then Hu et al.'s F6).
pub const KEYS: [&str; 13] = [
    "sphere",
    "tablet",
    "rosenbrock",
    "bent-cigar",
    "rastrigin",
    "griewank",
    "ackley",
    "schwefel",
    "kowalik",
    "six-hump-camel",
    "branin",
    "hartman6",
    "schaffer-f6",
];

/// All thirteen functions in table order; the scalable ones (f1–f8) in `dim` dimensions.
pub fn all(dim: usize) -> Vec<Box<dyn Benchmark>> {
    KEYS.iter().filter_map(|k| by_key(k, dim)).collect()
}

/// The function of key `key` (or of label `f1`…`f12`, `f6-schaffer`), if there is one.
pub fn by_key(key: &str, dim: usize) -> Option<Box<dyn Benchmark>> {
    let f: Box<dyn Benchmark> = match key.to_ascii_lowercase().as_str() {
        "sphere" | "f1" => Box::new(Sphere::new(dim)),
        "tablet" | "f2" => Box::new(Tablet::new(dim)),
        "rosenbrock" | "f3" => Box::new(Rosenbrock::new(dim)),
        "bent-cigar" | "bentcigar" | "f4" => Box::new(BentCigar::new(dim)),
        "rastrigin" | "f5" => Box::new(Rastrigin::new(dim)),
        "griewank" | "f6" => Box::new(Griewank::new(dim)),
        "ackley" | "f7" => Box::new(Ackley::new(dim)),
        "schwefel" | "f8" => Box::new(Schwefel::new(dim)),
        "kowalik" | "f9" => Box::new(Kowalik::new()),
        "six-hump-camel" | "camel" | "f10" => Box::new(SixHumpCamel::new()),
        "branin" | "f11" => Box::new(Branin::new()),
        "hartman6" | "hartman" | "f12" => Box::new(Hartman6::new()),
        "schaffer-f6" | "f6-schaffer" => Box::new(SchafferF6::new()),
        _ => return None,
    };
    Some(f)
}

/// A function picked at run time is a problem too, so every solver can run on any of them
/// (the solvers are generic over a sized `P: Problem`).
impl Problem for &dyn Benchmark {
    fn lower(&self) -> &[f64] {
        (**self).lower()
    }
    fn upper(&self) -> &[f64] {
        (**self).upper()
    }
    fn cost(&self, x: &[f64]) -> f64 {
        (**self).cost(x)
    }
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn blocks(&self) -> usize {
        (**self).blocks()
    }
    fn block_range(&self, b: usize) -> std::ops::Range<usize> {
        (**self).block_range(b)
    }
    fn move_groups(&self) -> Vec<std::ops::Range<usize>> {
        (**self).move_groups()
    }
    fn cost_parts(&self, x: &[f64], parts: &mut [f64]) -> f64 {
        (**self).cost_parts(x, parts)
    }
    fn sample(&self, rng: &mut rand::rngs::StdRng) -> Vec<f64> {
        (**self).sample(rng)
    }
}

/// A box `[lo, hi]^n`.
#[derive(Debug, Clone, PartialEq)]
pub struct Domain {
    /// Lower bounds.
    pub lower: Vec<f64>,
    /// Upper bounds.
    pub upper: Vec<f64>,
}

impl Domain {
    /// The same range in each of `n` dimensions.
    pub fn cube(n: usize, lo: f64, hi: f64) -> Domain {
        Domain {
            lower: vec![lo; n],
            upper: vec![hi; n],
        }
    }
}

/// Cost the solvers may rely on: finite. Only Kowalik can overflow (a denominator near zero
/// inside its box); such a point is simply very bad.
fn finite(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        1e300
    }
}

/// Implements [`Problem`] (bounds from `.0`, cost from the type's `value`) and [`Benchmark`].
macro_rules! benchmark {
    ($t:ident, $key:literal, $name:literal, $label:literal, optimum: $opt:expr,
     at: |$s:ident| $at:expr) => {
        impl Problem for $t {
            fn lower(&self) -> &[f64] {
                &self.0.lower
            }
            fn upper(&self) -> &[f64] {
                &self.0.upper
            }
            fn cost(&self, x: &[f64]) -> f64 {
                finite(self.value(x))
            }
        }
        impl Benchmark for $t {
            fn key(&self) -> &'static str {
                $key
            }
            fn name(&self) -> &'static str {
                $name
            }
            fn label(&self) -> &'static str {
                $label
            }
            fn optimum(&self) -> f64 {
                $opt
            }
            fn optimum_at(&self) -> Vec<f64> {
                let $s = self;
                $at
            }
        }
    };
}

/// f1 Sphere `Σ x_i²` on [−100, 100]^D: 0 at the origin (unimodal).
#[derive(Debug, Clone)]
pub struct Sphere(pub Domain);
impl Sphere {
    /// `dim` dimensions.
    pub fn new(dim: usize) -> Sphere {
        Sphere(Domain::cube(dim, -100.0, 100.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        x.iter().map(|v| v * v).sum()
    }
}
benchmark!(Sphere, "sphere", "Sphere", "f1", optimum: 0.0, at: |s| vec![0.0; s.dim()]);

/// f2 Tablet `(1000 x1)² + Σ_{i≥2} x_i²` on [−100, 100]^D: 0 at the origin (ill-conditioned).
#[derive(Debug, Clone)]
pub struct Tablet(pub Domain);
impl Tablet {
    /// `dim` dimensions.
    pub fn new(dim: usize) -> Tablet {
        Tablet(Domain::cube(dim, -100.0, 100.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        let first = x.first().map_or(0.0, |v| 1e6 * v * v);
        first + x.iter().skip(1).map(|v| v * v).sum::<f64>()
    }
}
benchmark!(Tablet, "tablet", "Tablet", "f2", optimum: 0.0, at: |s| vec![0.0; s.dim()]);

/// f3 Rosenbrock `Σ_{i<D} 100 (x_i² − x_{i+1})² + (x_i − 1)²` on [−100, 100]^D: 0 at
/// `(1, …, 1)`, at the end of a long curved valley.
#[derive(Debug, Clone)]
pub struct Rosenbrock(pub Domain);
impl Rosenbrock {
    /// `dim` dimensions (at least 2 for a valley).
    pub fn new(dim: usize) -> Rosenbrock {
        Rosenbrock(Domain::cube(dim, -100.0, 100.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        x.windows(2)
            .map(|w| 100.0 * (w[0] * w[0] - w[1]).powi(2) + (w[0] - 1.0).powi(2))
            .sum()
    }
}
benchmark!(Rosenbrock, "rosenbrock", "Rosenbrock", "f3", optimum: 0.0,
    at: |s| vec![1.0; s.dim()]);

/// f4 BentCigar `x1² + 10⁶ Σ_{i≥2} x_i²` on [−100, 100]^D: 0 at the origin (Table 3's `[1, …, 1]`
/// is a typo: there the value is 10⁶ (D − 1) + 1).
#[derive(Debug, Clone)]
pub struct BentCigar(pub Domain);
impl BentCigar {
    /// `dim` dimensions.
    pub fn new(dim: usize) -> BentCigar {
        BentCigar(Domain::cube(dim, -100.0, 100.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        let first = x.first().map_or(0.0, |v| v * v);
        first + 1e6 * x.iter().skip(1).map(|v| v * v).sum::<f64>()
    }
}
benchmark!(BentCigar, "bent-cigar", "BentCigar", "f4", optimum: 0.0, at: |s| vec![0.0; s.dim()]);

/// f5 Rastrigin `Σ x_i² − 10 cos(2π x_i) + 10` on [−5.12, 5.12]^D: 0 at the origin, a local
/// minimum near every integer point.
#[derive(Debug, Clone)]
pub struct Rastrigin(pub Domain);
impl Rastrigin {
    /// `dim` dimensions.
    pub fn new(dim: usize) -> Rastrigin {
        Rastrigin(Domain::cube(dim, -5.12, 5.12))
    }
    fn value(&self, x: &[f64]) -> f64 {
        let tau = std::f64::consts::TAU;
        x.iter()
            .map(|v| v * v - 10.0 * (tau * v).cos() + 10.0)
            .sum()
    }
}
benchmark!(Rastrigin, "rastrigin", "Rastrigin", "f5", optimum: 0.0, at: |s| vec![0.0; s.dim()]);

/// f6 Griewank `Σ x_i²/4000 − Π cos(x_i/√i) + 1` on [−600, 600]^D: 0 at the origin.
#[derive(Debug, Clone)]
pub struct Griewank(pub Domain);
impl Griewank {
    /// `dim` dimensions.
    pub fn new(dim: usize) -> Griewank {
        Griewank(Domain::cube(dim, -600.0, 600.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        let sum: f64 = x.iter().map(|v| v * v).sum::<f64>() / 4000.0;
        let prod: f64 = x
            .iter()
            .enumerate()
            .map(|(i, v)| (v / ((i + 1) as f64).sqrt()).cos())
            .product();
        sum - prod + 1.0
    }
}
benchmark!(Griewank, "griewank", "Griewank", "f6", optimum: 0.0, at: |s| vec![0.0; s.dim()]);

/// f7 Ackley `−20 exp(−0.2 √(Σ x_i²/D)) − exp(Σ cos(2π x_i)/D) + 20 + e` on [−32, 32]^D: 0 at
/// the origin. Table 3 prints only the first term; this is the standard function (Hu et al. 2023
/// eq. (23)).
#[derive(Debug, Clone)]
pub struct Ackley(pub Domain);
impl Ackley {
    /// `dim` dimensions.
    pub fn new(dim: usize) -> Ackley {
        Ackley(Domain::cube(dim, -32.0, 32.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        let n = x.len().max(1) as f64;
        let sq = x.iter().map(|v| v * v).sum::<f64>() / n;
        let cos = x
            .iter()
            .map(|v| (std::f64::consts::TAU * v).cos())
            .sum::<f64>()
            / n;
        -20.0 * (-0.2 * sq.sqrt()).exp() - cos.exp() + 20.0 + std::f64::consts::E
    }
}
benchmark!(Ackley, "ackley", "Ackley", "f7", optimum: 0.0, at: |s| vec![0.0; s.dim()]);

/// x* of Schwefel 2.26 in each dimension: the root of `sin √x + (√x / 2) cos √x = 0` near 421.
pub const SCHWEFEL_X: f64 = 420.968_746_359_982_1;
/// `−x* sin √x*`: the per-dimension minimum of `−x sin √|x|`, negated (418.98…).
pub const SCHWEFEL_SHIFT: f64 = 418.982_887_272_433_74;

/// f8, printed as "Schaffer" in Lu et al. 2023, Table 3, read as **Schwefel 2.26**:
/// `418.9829 D − Σ x_i sin √|x_i|` on [−500, 500]^D, 0 at `(420.9687, …, 420.9687)`.
///
/// Table 3's row is inconsistent: its formula `78.33 + Σ (x⁴ − 16x² + 5x)/D` is a scaled
/// Styblinski–Tang (minimum about −0.0023 at x_i = −2.9035), but its range [−500, 500], optimum
/// location 420.96 and optimum value 0 are all Schwefel 2.26's, and Schwefel 2.26 is f8 of Yao,
/// Liu & Lin 1999, the usual source of this numbering (f1 sphere … f8 Schwefel, then Rastrigin,
/// Ackley, Griewank, Kowalik, Six-Hump Camel, Branin, Hartman). Three of the four printed facts
/// and the numbering agree, so Shoal reads f8 as Schwefel 2.26, shifted so that f* = 0 (the
/// shift is the exact per-dimension minimum, [`SCHWEFEL_SHIFT`], so f(x*) is 0 to rounding).
/// The name "Schaffer" fits neither; Hu et al.'s Schaffer F6 is [`SchafferF6`].
#[derive(Debug, Clone)]
pub struct Schwefel(pub Domain);
impl Schwefel {
    /// `dim` dimensions.
    pub fn new(dim: usize) -> Schwefel {
        Schwefel(Domain::cube(dim, -500.0, 500.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        x.iter()
            .map(|v| SCHWEFEL_SHIFT - v * v.abs().sqrt().sin())
            .sum()
    }
}
benchmark!(Schwefel, "schwefel", "Schwefel 2.26 (Table 3's \"Schaffer\")", "f8", optimum: 0.0,
    at: |s| vec![SCHWEFEL_X; s.dim()]);

/// Kowalik's data: `a_i`.
const KOWALIK_A: [f64; 11] = [
    0.1957, 0.1947, 0.1735, 0.1600, 0.0844, 0.0627, 0.0456, 0.0342, 0.0323, 0.0235, 0.0246,
];
/// Kowalik's data: `1 / b_i`.
const KOWALIK_B_INV: [f64; 11] = [0.25, 0.5, 1.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0];

/// f9 Kowalik `Σ_{i=1}^{11} (a_i − x1 (b_i² + b_i x2) / (b_i² + b_i x3 + x4))²` on [−5, 5]⁴ (a
/// least-squares fit of an enzyme model): f* = 3.0748598780561e−4 at
/// (0.192833, 0.190836, 0.123117, 0.135766). Table 3 rounds f* to 0.00030.
#[derive(Debug, Clone)]
pub struct Kowalik(pub Domain);
impl Kowalik {
    /// The 4-D function.
    pub fn new() -> Kowalik {
        Kowalik(Domain::cube(4, -5.0, 5.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        KOWALIK_A
            .iter()
            .zip(KOWALIK_B_INV)
            .map(|(a, b_inv)| {
                let b = 1.0 / b_inv;
                let model = x[0] * (b * b + b * x[1]) / (b * b + b * x[2] + x[3]);
                (a - model).powi(2)
            })
            .sum()
    }
}
impl Default for Kowalik {
    fn default() -> Self {
        Kowalik::new()
    }
}
benchmark!(Kowalik, "kowalik", "Kowalik", "f9", optimum: 3.074_859_878_056_055e-4,
    at: |_s| vec![0.192_833_452_679_748_7, 0.190_836_237_309_020_3, 0.123_117_292_378_969_5,
        0.135_765_989_221_434_6]);

/// f10 Six-Hump Camel `4x1² − 2.1x1⁴ + x1⁶/3 + x1 x2 − 4x2² + 4x2⁴` on [−5, 5]²:
/// f* = −1.0316284534898768 at ±(0.0898420, −0.7126564). Table 3 prints the last term as `x2⁴`;
/// the standard function (and its f*) has `4x2⁴`.
#[derive(Debug, Clone)]
pub struct SixHumpCamel(pub Domain);
impl SixHumpCamel {
    /// The 2-D function.
    pub fn new() -> SixHumpCamel {
        SixHumpCamel(Domain::cube(2, -5.0, 5.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        let (a, b) = (x[0], x[1]);
        let (a2, b2) = (a * a, b * b);
        4.0 * a2 - 2.1 * a2 * a2 + a2 * a2 * a2 / 3.0 + a * b - 4.0 * b2 + 4.0 * b2 * b2
    }
}
impl Default for SixHumpCamel {
    fn default() -> Self {
        SixHumpCamel::new()
    }
}
benchmark!(SixHumpCamel, "six-hump-camel", "Six-Hump Camel", "f10",
    optimum: -1.031_628_453_489_876_8,
    at: |_s| vec![0.089_842_006_789_058_11, -0.712_656_410_015_068]);

/// f11 Branin `(x2 − 5.1x1²/(4π²) + 5x1/π − 6)² + 10(1 − 1/(8π)) cos x1 + 10` on [−5, 5]²
/// (Table 3's range; the usual one is [−5, 10] × [0, 15]): f* = 5/(4π) = 0.397887 at
/// (π, 2.275), the one of its three minimisers inside [−5, 5]².
#[derive(Debug, Clone)]
pub struct Branin(pub Domain);
impl Branin {
    /// The 2-D function.
    pub fn new() -> Branin {
        Branin(Domain::cube(2, -5.0, 5.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        use std::f64::consts::PI;
        let (a, b) = (x[0], x[1]);
        let t = 1.0 / (8.0 * PI);
        (b - 5.1 / (4.0 * PI * PI) * a * a + 5.0 / PI * a - 6.0).powi(2)
            + 10.0 * (1.0 - t) * a.cos()
            + 10.0
    }
}
impl Default for Branin {
    fn default() -> Self {
        Branin::new()
    }
}
benchmark!(Branin, "branin", "Branin", "f11", optimum: 1.25 / std::f64::consts::PI,
    at: |_s| vec![std::f64::consts::PI, 2.275]);

/// Hartman 6-D constants `c_i`.
const HARTMAN_C: [f64; 4] = [1.0, 1.2, 3.0, 3.2];
/// Hartman 6-D constants `a_ij`.
const HARTMAN_A: [[f64; 6]; 4] = [
    [10.0, 3.0, 17.0, 3.5, 1.7, 8.0],
    [0.05, 10.0, 17.0, 0.1, 8.0, 14.0],
    [3.0, 3.5, 1.7, 10.0, 17.0, 8.0],
    [17.0, 8.0, 0.05, 10.0, 0.1, 14.0],
];
/// Hartman 6-D constants `p_ij` (× 10⁴).
const HARTMAN_P: [[f64; 6]; 4] = [
    [1312.0, 1696.0, 5569.0, 124.0, 8283.0, 5886.0],
    [2329.0, 4135.0, 8307.0, 3736.0, 1004.0, 9991.0],
    [2348.0, 1451.0, 3522.0, 2883.0, 3047.0, 6650.0],
    [4047.0, 8828.0, 8732.0, 5743.0, 1091.0, 381.0],
];

/// f12 Hartman 6-D `−Σ_{i=1}^4 c_i exp(−Σ_{j=1}^6 a_ij (x_j − p_ij)²)` on [0, 1]⁶:
/// f* = −3.322368011415508 at (0.201690, 0.150011, 0.476874, 0.275332, 0.311652, 0.657301).
#[derive(Debug, Clone)]
pub struct Hartman6(pub Domain);
impl Hartman6 {
    /// The 6-D function.
    pub fn new() -> Hartman6 {
        Hartman6(Domain::cube(6, 0.0, 1.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        -HARTMAN_C
            .iter()
            .zip(HARTMAN_A.iter().zip(&HARTMAN_P))
            .map(|(c, (a, p))| {
                let inner: f64 = (0..6).map(|j| a[j] * (x[j] - 1e-4 * p[j]).powi(2)).sum();
                c * (-inner).exp()
            })
            .sum::<f64>()
    }
}
impl Default for Hartman6 {
    fn default() -> Self {
        Hartman6::new()
    }
}
benchmark!(Hartman6, "hartman6", "Hartman 6-D", "f12", optimum: -3.322_368_011_415_508,
    at: |_s| vec![0.201_689_503_071_596, 0.150_010_682_075_892_7, 0.476_873_967_276_753_8,
        0.275_332_422_141_527_3, 0.311_651_612_840_292_4, 0.657_300_526_605_512_4]);

/// Hu et al.'s Schaffer F6 (eq. (26)) `0.5 + (sin² √(x1² + x2²) − 0.5) / (1 + 0.001 (x1² + x2²))²`
/// on [−5, 5]² (Hu et al. 2023, Table 1): 0 at the origin, ringed by ridges. Eq. (26) prints the
/// denominator unsquared; the standard F6 squares it (same f* and x*).
#[derive(Debug, Clone)]
pub struct SchafferF6(pub Domain);
impl SchafferF6 {
    /// The 2-D function.
    pub fn new() -> SchafferF6 {
        SchafferF6(Domain::cube(2, -5.0, 5.0))
    }
    fn value(&self, x: &[f64]) -> f64 {
        let r2 = x[0] * x[0] + x[1] * x[1];
        let s = r2.sqrt().sin();
        0.5 + (s * s - 0.5) / (1.0 + 0.001 * r2).powi(2)
    }
}
impl Default for SchafferF6 {
    fn default() -> Self {
        SchafferF6::new()
    }
}
benchmark!(SchafferF6, "schaffer-f6", "Schaffer F6 (Hu et al. 2023)", "F6", optimum: 0.0,
    at: |_s| vec![0.0, 0.0]);

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn every_function_reaches_its_optimum_at_its_location_and_nowhere_nearby_lower() {
        let fs = all(30);
        assert_eq!(fs.len(), 13);
        for f in &fs {
            let x = f.optimum_at();
            assert_eq!(x.len(), f.dim(), "{}", f.key());
            assert!(
                x.iter()
                    .zip(f.lower().iter().zip(f.upper()))
                    .all(|(v, (lo, hi))| lo <= v && v <= hi),
                "{}: x* outside the box",
                f.key()
            );
            let value = f.cost(&x);
            assert_abs_diff_eq!(value, f.optimum(), epsilon = 1e-9);
            // A minimum: a small step along any axis does not go lower.
            for d in 0..f.dim() {
                for step in [-1e-4, 1e-4] {
                    let mut y = x.clone();
                    y[d] += step * (f.upper()[d] - f.lower()[d]);
                    assert!(f.cost(&y) >= value - 1e-12, "{} lower along {d}", f.key());
                }
            }
            assert_eq!(by_key(f.key(), 30).map(|g| g.name()), Some(f.name()));
        }
        assert!(by_key("f11", 30).is_some_and(|f| f.key() == "branin"));
        assert!(by_key("schaffer", 30).is_none(), "f8's name is ambiguous");
    }

    #[test]
    fn scalable_functions_by_hand() {
        let x = [1.0, 2.0, 3.0];
        assert_abs_diff_eq!(Sphere::new(3).cost(&x), 14.0);
        // (1000 · 1)² + 4 + 9.
        assert_abs_diff_eq!(Tablet::new(3).cost(&x), 1_000_013.0);
        // 100 (1 − 2)² + 0  +  100 (4 − 3)² + (2 − 1)² = 100 + 101.
        assert_abs_diff_eq!(Rosenbrock::new(3).cost(&x), 201.0);
        // 1 + 10⁶ (4 + 9).
        assert_abs_diff_eq!(BentCigar::new(3).cost(&x), 13_000_001.0);
        // x = 0.5: 0.25 + 10 + 10; x = 1: 1 − 10 + 10.
        assert_abs_diff_eq!(Rastrigin::new(2).cost(&[0.5, 1.0]), 21.25, epsilon = 1e-12);
        // cos(π/2) = 0 kills the product: 1 + (π/2)²/4000 = 1 + π²/16000.
        let pi = std::f64::consts::PI;
        assert_abs_diff_eq!(
            Griewank::new(2).cost(&[pi / 2.0, 0.0]),
            1.0 + pi * pi / 16000.0,
            epsilon = 1e-12
        );
        // √(Σx²/2) = 1, Σcos(2π)/2 = 1: −20 e^−0.2 − e + 20 + e = 20 (1 − e^−0.2) = 3.62538…
        assert_abs_diff_eq!(
            Ackley::new(2).cost(&[1.0, 1.0]),
            3.625_384_938_440_362,
            epsilon = 1e-12
        );
        // At the origin only the shift is left: 2 · 418.98…; at x = π² (√x = π) likewise.
        assert_abs_diff_eq!(Schwefel::new(2).cost(&[0.0, 0.0]), 2.0 * SCHWEFEL_SHIFT);
        assert_abs_diff_eq!(
            Schwefel::new(1).cost(&[pi * pi]),
            SCHWEFEL_SHIFT,
            epsilon = 1e-12
        );
    }

    #[test]
    fn fixed_dimension_functions_by_hand() {
        // x1 = 0 leaves Σ a_i² = 0.14841318.
        assert_abs_diff_eq!(
            Kowalik::new().cost(&[0.0; 4]),
            0.148_413_18,
            epsilon = 1e-12
        );
        // (4 − 2.1 + 1/3) + 1 + (−4 + 4) = 3.2333…
        assert_abs_diff_eq!(
            SixHumpCamel::new().cost(&[1.0, 1.0]),
            1.9 + 1.0 / 3.0 + 1.0,
            epsilon = 1e-12
        );
        // (−6)² + 10 (1 − 1/(8π)) + 10 = 56 − 1.25/π.
        let pi = std::f64::consts::PI;
        assert_abs_diff_eq!(
            Branin::new().cost(&[0.0, 0.0]),
            56.0 - 1.25 / pi,
            epsilon = 1e-12
        );
        // At p_1 (first row of P) the first term is c_1 e⁰ = 1; the others are
        // 1.2 e^−8.4807…, 3 e^−5.5741…, 3.2 e^−12.7976… (Σ_j a_ij (p_1j − p_ij)², by hand).
        let p1: Vec<f64> = HARTMAN_P[0].iter().map(|p| p * 1e-4).collect();
        let by_hand = -(1.0
            + 1.2 * (-8.480_716_048_5f64).exp()
            + 3.0 * (-5.574_105_408f64).exp()
            + 3.2 * (-12.797_618_918_5f64).exp());
        assert_abs_diff_eq!(Hartman6::new().cost(&p1), by_hand, epsilon = 1e-12);
        assert_abs_diff_eq!(by_hand, -1.011_642_378_446_717, epsilon = 1e-12);
        // r = 5: 0.5 + (sin² 5 − 0.5) / 1.025².
        let s5 = 5f64.sin();
        assert_abs_diff_eq!(
            SchafferF6::new().cost(&[3.0, 4.0]),
            0.5 + (s5 * s5 - 0.5) / (1.025 * 1.025),
            epsilon = 1e-12
        );
    }

    #[test]
    fn a_kowalik_pole_costs_a_finite_fortune() {
        // b_3 = 1: the denominator 1 + x3 + x4 vanishes at x3 = −1, x4 = 0.
        let c = Kowalik::new().cost(&[1.0, 0.0, -1.0, 0.0]);
        assert!(c.is_finite() && c >= 1e300);
    }
}
