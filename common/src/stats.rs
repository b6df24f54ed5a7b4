//! Summary statistics and the Wilcoxon rank-sum test used to compare optimizers over repeated
//! runs, as Lu et al. 2023 does in Table 5 (best, mean, standard deviation of 50 runs) and Table 6
//! (Wilcoxon rank-sum p-values of IPSO against each other algorithm).

/// Arithmetic mean; NaN for no data.
pub fn mean(x: &[f64]) -> f64 {
    if x.is_empty() {
        return f64::NAN;
    }
    x.iter().sum::<f64>() / x.len() as f64
}

/// Sample standard deviation (divisor n − 1); 0 for a single value, NaN for none.
pub fn sample_std(x: &[f64]) -> f64 {
    match x.len() {
        0 => f64::NAN,
        1 => 0.0,
        n => {
            let m = mean(x);
            (x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1) as f64).sqrt()
        }
    }
}

/// Smallest value; NaN for no data.
pub fn min(x: &[f64]) -> f64 {
    x.iter().copied().reduce(f64::min).unwrap_or(f64::NAN)
}

/// Largest value; NaN for no data.
pub fn max(x: &[f64]) -> f64 {
    x.iter().copied().reduce(f64::max).unwrap_or(f64::NAN)
}

/// The `q`-quantile of `x` (0 ≤ q ≤ 1) by linear interpolation between the order statistics
/// at rank `q (n − 1)`; NaN for no data.
pub fn quantile(x: &[f64], q: f64) -> f64 {
    if x.is_empty() {
        return f64::NAN;
    }
    let mut v = x.to_vec();
    v.sort_by(f64::total_cmp);
    let r = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (lo, hi) = (r.floor() as usize, r.ceil() as usize);
    v[lo] + (v[hi] - v[lo]) * (r - lo as f64)
}

/// Ranks 1..n of `x` (ties get the mean of the ranks they span), and Σ (t³ − t) over the tie
/// groups, which the normal approximation's variance needs.
pub fn ranks(x: &[f64]) -> (Vec<f64>, f64) {
    let mut order: Vec<usize> = (0..x.len()).collect();
    order.sort_by(|a, b| x[*a].total_cmp(&x[*b]));
    let mut rank = vec![0.0; x.len()];
    let mut ties = 0.0;
    let mut i = 0;
    while i < order.len() {
        let mut j = i + 1;
        while j < order.len() && x[order[j]] == x[order[i]] {
            j += 1;
        }
        // Positions i..j (0-based) hold equal values: ranks i+1..=j, mean (i + 1 + j) / 2.
        let r = (i + 1 + j) as f64 / 2.0;
        for &k in &order[i..j] {
            rank[k] = r;
        }
        let t = (j - i) as f64;
        ties += t * t * t - t;
        i = j;
    }
    (rank, ties)
}

/// Result of a Wilcoxon rank-sum (Mann–Whitney) test of `x` against `y`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RankSum {
    /// Mann–Whitney U of `x`: the number of (x_i, y_j) pairs with x_i > y_j, ties counting ½.
    /// Small when `x` tends to be lower (better, for costs).
    pub u: f64,
    /// Standardised statistic with tie and continuity corrections; negative when `x` tends to
    /// be lower than `y`.
    pub z: f64,
    /// Two-sided p-value from the normal approximation.
    pub p: f64,
}

/// Wilcoxon rank-sum test, two-sided, by the normal approximation with the tie correction of the
/// variance and a continuity correction of ½: `U = R_x − n_x (n_x + 1)/2`,
/// `σ² = n_x n_y / 12 · (N + 1 − Σ(t³ − t) / (N (N − 1)))`, `z = sign · max(0, |U − n_x n_y/2| − ½) / σ`,
/// `p = erfc(|z| / √2)`. This is scipy's `mannwhitneyu(method="asymptotic")` and R's
/// `wilcox.test(exact = FALSE)`; for n = 50 per side the approximation is what SPSS's
/// "asymptotic significance" reports too (SPSS, as far as we know, omits the continuity
/// correction, which moves p by about 1 % of itself at that size; Lu et al. 2023, Table 6 used SPSS).
/// If every value is tied, p = 1.
///
/// None when either sample is empty.
pub fn rank_sum(x: &[f64], y: &[f64]) -> Option<RankSum> {
    let (nx, ny) = (x.len() as f64, y.len() as f64);
    if x.is_empty() || y.is_empty() {
        return None;
    }
    let all: Vec<f64> = x.iter().chain(y).copied().collect();
    let (rank, ties) = ranks(&all);
    let rx: f64 = rank[..x.len()].iter().sum();
    let u = rx - nx * (nx + 1.0) / 2.0;
    let n = nx + ny;
    let var = nx * ny / 12.0 * ((n + 1.0) - ties / (n * (n - 1.0)));
    let diff = u - nx * ny / 2.0;
    if var <= 0.0 || !var.is_finite() {
        return Some(RankSum { u, z: 0.0, p: 1.0 });
    }
    let z = diff.signum() * (diff.abs() - 0.5).max(0.0) / var.sqrt();
    let p = erfc(z.abs() / std::f64::consts::SQRT_2).min(1.0);
    Some(RankSum { u, z, p })
}

/// Complementary error function, fractional error below 1.2e−7 everywhere (Chebyshev fit of
/// Numerical Recipes' `erfcc`): enough for p-values, which are printed to 2–3 digits.
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let x = [4.0, 1.0, 3.0, 2.0, 5.0];
        assert!((quantile(&x, 0.5) - 3.0).abs() < 1e-12);
        assert!((quantile(&x, 0.0) - 1.0).abs() < 1e-12);
        assert!((quantile(&x, 1.0) - 5.0).abs() < 1e-12);
        // rank 0.99 × 4 = 3.96: 4 + 0.96 × (5 − 4)
        assert!((quantile(&x, 0.99) - 4.96).abs() < 1e-12);
        assert!(quantile(&[], 0.5).is_nan());
        // The median of an even sample is the mean of the middle two, in any order.
        assert!((quantile(&[4.0, 1.0, 3.0, 2.0], 0.5) - 2.5).abs() < 1e-12);
        assert!((quantile(&[3.0, 1.0, 2.0], 0.5) - 2.0).abs() < 1e-12);
    }
    use approx::{assert_abs_diff_eq, assert_relative_eq};

    fn test(x: &[f64], y: &[f64]) -> RankSum {
        rank_sum(x, y).unwrap_or_else(|| panic!("empty sample"))
    }

    #[test]
    fn mean_and_sample_std_by_hand() {
        assert_abs_diff_eq!(mean(&[1.0, 2.0, 3.0, 4.0]), 2.5);
        // Squared deviations 2.25 + 0.25 + 0.25 + 2.25 = 5, / 3, √ → 1.2909944…
        assert_abs_diff_eq!(
            sample_std(&[1.0, 2.0, 3.0, 4.0]),
            (5.0f64 / 3.0).sqrt(),
            epsilon = 1e-15
        );
        assert_eq!(sample_std(&[7.0]), 0.0);
        assert!(mean(&[]).is_nan() && sample_std(&[]).is_nan());
        assert_eq!(
            (min(&[3.0, -1.0, 2.0]), max(&[3.0, -1.0, 2.0])),
            (-1.0, 3.0)
        );
    }

    #[test]
    fn ranks_average_ties() {
        let (r, ties) = ranks(&[5.0, 1.0, 2.0, 2.0, 5.0, 5.0]);
        // Sorted: 1 → 1; 2, 2 → 2.5; 5, 5, 5 → 5. Ties: (8 − 2) + (27 − 3) = 30.
        assert_eq!(r, vec![5.0, 1.0, 2.5, 2.5, 5.0, 5.0]);
        assert_eq!(ties, 30.0);
    }

    #[test]
    fn erfc_matches_tabulated_normal_tails() {
        // Two-sided normal tails 2(1 − Φ(z)) = erfc(z/√2): z = 1.96 → 0.04999579, z = 3 →
        // 0.0026997961, z = 8 → 1.2441921e−15.
        let two_sided = |z: f64| erfc(z / std::f64::consts::SQRT_2);
        assert_relative_eq!(
            two_sided(1.96),
            0.049_995_790_296_440_87,
            max_relative = 2e-7
        );
        assert_relative_eq!(
            two_sided(3.0),
            0.002_699_796_063_260_186_6,
            max_relative = 2e-7
        );
        assert_relative_eq!(
            two_sided(8.0),
            1.244_192_114_854_348e-15,
            max_relative = 2e-7
        );
        assert_abs_diff_eq!(erfc(0.0), 1.0, epsilon = 2e-7);
        assert_abs_diff_eq!(erfc(-1.0) + erfc(1.0), 2.0, epsilon = 1e-15);
    }

    #[test]
    fn rank_sum_without_ties_by_hand() {
        // x = (1, 2, 3) all below y = (4, 5, 6): R_x = 6, U = 6 − 6 = 0, E[U] = 4.5,
        // σ² = 9/12 · 7 = 5.25, z = −(4.5 − 0.5)/√5.25 = −1.745743, p = 0.0808556.
        let r = test(&[1.0, 2.0, 3.0], &[4.0, 5.0, 6.0]);
        assert_eq!(r.u, 0.0);
        assert_abs_diff_eq!(r.z, -4.0 / 5.25f64.sqrt(), epsilon = 1e-12);
        assert_relative_eq!(r.p, 0.080_855_598_370_052_24, max_relative = 1e-6);
        // Swapped: U = 9, same p, z positive.
        let s = test(&[4.0, 5.0, 6.0], &[1.0, 2.0, 3.0]);
        assert_eq!(s.u, 9.0);
        assert_abs_diff_eq!(s.z, -r.z, epsilon = 1e-12);
        assert_abs_diff_eq!(s.p, r.p, epsilon = 1e-15);
    }

    #[test]
    fn rank_sum_with_ties_by_hand() {
        // x = (1, 2, 2, 5), y = (3, 4, 5, 6, 7). Ranks of the pooled nine: 1 → 1, 2 → 2.5 (×2),
        // 3 → 4, 4 → 5, 5 → 6.5 (×2), 6 → 8, 7 → 9. R_x = 1 + 2.5 + 2.5 + 6.5 = 12.5,
        // U = 12.5 − 10 = 2.5, E[U] = 10. Ties Σ(t³ − t) = 6 + 6 = 12, so
        // σ² = 20/12 · (10 − 12/72) = 16.388889, σ = 4.0483193; z = −(7.5 − 0.5)/σ = −1.7291126,
        // p = 0.0837889 (scipy 1.17: mannwhitneyu(x, y, method="asymptotic") gives 0.08378894).
        let r = test(&[1.0, 2.0, 2.0, 5.0], &[3.0, 4.0, 5.0, 6.0, 7.0]);
        assert_eq!(r.u, 2.5);
        assert_abs_diff_eq!(r.z, -1.729_112_636_144_498_4, epsilon = 1e-9);
        assert_relative_eq!(r.p, 0.083_788_938_042_391_39, max_relative = 1e-6);
    }

    #[test]
    fn rank_sum_edge_cases() {
        // All tied: nothing to tell apart.
        let r = test(&[0.0; 5], &[0.0; 7]);
        assert_eq!((r.z, r.p), (0.0, 1.0));
        assert!(rank_sum(&[], &[1.0]).is_none());
        // Two samples of 50 that do not overlap: z ≈ −8.6, a p far below any threshold.
        let x: Vec<f64> = (0..50).map(f64::from).collect();
        let y: Vec<f64> = (100..150).map(f64::from).collect();
        let r = test(&x, &y);
        assert_eq!(r.u, 0.0);
        assert!(r.p < 1e-16 && r.p > 0.0, "{}", r.p);
        // Shifted by half the range: scipy gives 5.922449e−11.
        let y: Vec<f64> = (0..50).map(|v| f64::from(v) + 25.5).collect();
        let r = test(&x, &y);
        assert_relative_eq!(r.p, 5.922_449_396_792_082e-11, max_relative = 1e-5);
    }
}
