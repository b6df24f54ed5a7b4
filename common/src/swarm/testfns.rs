//! Functions with known optima for the optimizers' convergence tests.

use super::core::Problem;

/// Shifted sphere `Σ (x_d − s_d)²` on `[-10, 10]^n`: minimum 0 at `s`.
pub struct ShiftedSphere {
    /// Lower bounds.
    pub lower: Vec<f64>,
    /// Upper bounds.
    pub upper: Vec<f64>,
    /// Location of the minimum.
    pub shift: Vec<f64>,
}

impl ShiftedSphere {
    /// `n` dimensions, minimum at `(1.5, −2.5, 1.5, −2.5, …)`.
    pub fn new(n: usize) -> ShiftedSphere {
        ShiftedSphere {
            lower: vec![-10.0; n],
            upper: vec![10.0; n],
            shift: (0..n)
                .map(|d| if d % 2 == 0 { 1.5 } else { -2.5 })
                .collect(),
        }
    }
}

impl Problem for ShiftedSphere {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn cost(&self, x: &[f64]) -> f64 {
        x.iter()
            .zip(&self.shift)
            .map(|(a, s)| (a - s) * (a - s))
            .sum()
    }
}

/// Rastrigin `10 n + Σ (x² − 10 cos 2πx)` on `[-5.12, 5.12]^n`: minimum 0 at the origin, with
/// a local minimum near every integer point.
pub struct Rastrigin {
    /// Lower bounds.
    pub lower: Vec<f64>,
    /// Upper bounds.
    pub upper: Vec<f64>,
}

impl Rastrigin {
    /// `n` dimensions.
    pub fn new(n: usize) -> Rastrigin {
        Rastrigin {
            lower: vec![-5.12; n],
            upper: vec![5.12; n],
        }
    }
}

impl Problem for Rastrigin {
    fn lower(&self) -> &[f64] {
        &self.lower
    }
    fn upper(&self) -> &[f64] {
        &self.upper
    }
    fn cost(&self, x: &[f64]) -> f64 {
        let tau = std::f64::consts::TAU;
        10.0 * x.len() as f64
            + x.iter()
                .map(|v| v * v - 10.0 * (tau * v).cos())
                .sum::<f64>()
    }
}
