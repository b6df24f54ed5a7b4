//! Is a difference in `compare`'s table real? The first algorithm named is the reference; on
//! each scenario (and mode) its fitness over the seeds is tested against every other algorithm's
//! with the two-sided Wilcoxon rank-sum test of [`shoal_common::stats::rank_sum`] — Lu et al. 2023
//! Table 6's test. A median that is lower but not significantly so is reported as such, so a
//! ten-seed table is not read as more than it shows.

use std::fmt::Write;

use shoal_common::scenario::Algorithm;
use shoal_common::stats::rank_sum;

use crate::report::compare::Cell;

/// Level below which a difference is called significant.
pub const ALPHA: f64 = 0.05;

/// The reference algorithm against one other, on one scenario and mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Significance {
    /// Scenario name.
    pub scenario: String,
    /// `in-process` or `distributed`.
    pub mode: String,
    /// The reference (the first algorithm named).
    pub reference: Algorithm,
    /// The algorithm it is tested against.
    pub other: Algorithm,
    /// The reference's median fitness.
    pub reference_median: f64,
    /// The other's median fitness.
    pub other_median: f64,
    /// Seeds on which the reference's plan has the lower fitness (same seed in both cells).
    pub reference_better_on: usize,
    /// Seeds present in both cells.
    pub paired: usize,
    /// Two-sided p-value.
    pub p: f64,
    /// Negative when the reference's fitness tends to be the lower (better) one.
    pub z: f64,
}

impl Significance {
    /// Plain words for the row.
    pub fn verdict(&self) -> String {
        let (r, o) = (self.reference.as_str(), self.other.as_str());
        if self.p >= ALPHA {
            format!("not told apart (p ≥ {ALPHA})")
        } else if self.z < 0.0 {
            format!("{r} better")
        } else {
            format!("{o} better")
        }
    }
}

/// Tests the first cell of each (scenario, mode) against the later cells of the same pair.
pub fn significance(cells: &[Cell]) -> Vec<Significance> {
    let mut rows = Vec::new();
    for (i, reference) in cells.iter().enumerate() {
        let first_of_group = !cells[..i]
            .iter()
            .any(|c| c.scenario == reference.scenario && c.mode == reference.mode);
        if !first_of_group {
            continue;
        }
        for other in cells[i + 1..]
            .iter()
            .filter(|c| c.scenario == reference.scenario && c.mode == reference.mode)
        {
            let Some(test) = rank_sum(&reference.fitness, &other.fitness) else {
                continue;
            };
            let pairs = reference.fitness.iter().zip(&other.fitness);
            rows.push(Significance {
                scenario: reference.scenario.clone(),
                mode: reference.mode.clone(),
                reference: reference.algorithm,
                other: other.algorithm,
                reference_median: reference.median_fitness(),
                other_median: other.median_fitness(),
                reference_better_on: pairs.clone().filter(|(r, o)| r < o).count(),
                paired: pairs.count(),
                p: test.p,
                z: test.z,
            });
        }
    }
    rows
}

/// The rows as a markdown section (empty when there is nothing to test).
pub fn markdown(rows: &[Significance]) -> String {
    if rows.is_empty() {
        return String::new();
    }
    let mut s = format!(
        "\nWilcoxon rank-sum test of the reference (the first algorithm named that ran in that \
         scenario and mode) against each other algorithm, fitness over the seeds, two-sided, \
         normal approximation with tie and continuity corrections; significant below p = {ALPHA}.\n\n\
         | scenario | mode | reference | against | reference median | its median | reference lower on seeds | p | verdict |\n\
         |---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.4} | {:.4} | {} of {} | {:.3} | {} |",
            r.scenario,
            r.mode,
            r.reference.as_str(),
            r.other.as_str(),
            r.reference_median,
            r.other_median,
            r.reference_better_on,
            r.paired,
            r.p,
            r.verdict()
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn cell(scenario: &str, algorithm: Algorithm, mode: &str, fitness: &[f64]) -> Cell {
        Cell {
            scenario: scenario.into(),
            algorithm,
            mode: mode.into(),
            runs: fitness.len(),
            feasible: fitness.len(),
            collision_free: fitness.len(),
            separated: fitness.len(),
            fitness: fitness.to_vec(),
            median_runtime_s: 0.0,
            median_wall_s: 0.0,
            mean_collisions: 0.0,
            worst_separation_m: f64::INFINITY,
            evals_per_s: 0.0,
            crawler: None,
        }
    }

    #[test]
    fn separated_samples_are_significant_in_the_right_direction() {
        // Reference 1..=5 against 6..=10: U = 0, n = 5 + 5, σ² = 25/12 · 11, z = −(12.5 − ½)/σ
        // = −2.5067, p = erfc(2.5067/√2) = 0.01219.
        let cells = [
            cell("s", Algorithm::AmpPso, "in-process", &[1., 2., 3., 4., 5.]),
            cell("s", Algorithm::MpPso, "in-process", &[6., 7., 8., 9., 10.]),
        ];
        let rows = significance(&cells);
        assert_eq!(rows.len(), 1);
        let r = &rows[0];
        assert_eq!(
            (r.reference, r.other),
            (Algorithm::AmpPso, Algorithm::MpPso)
        );
        assert_abs_diff_eq!(r.z, -2.5067, epsilon = 1e-4);
        assert_abs_diff_eq!(r.p, 0.01219, epsilon = 1e-4);
        assert_eq!((r.reference_better_on, r.paired), (5, 5));
        assert_eq!(r.verdict(), "amp-pso better");
        // Swapped, the other algorithm is the better one.
        let swapped = [cells[1].clone(), cells[0].clone()];
        let r = &significance(&swapped)[0];
        assert_eq!(r.verdict(), "amp-pso better");
        assert_eq!(r.reference, Algorithm::MpPso);
        assert_eq!(r.reference_better_on, 0);
    }

    #[test]
    fn interleaved_samples_are_not_told_apart() {
        // 1 3 5 7 9 against 2 4 6 8 10: U = 10 of 25, z = −(2.5 − ½)/√(275/12) = −0.418, p = 0.676.
        let cells = [
            cell("s", Algorithm::AmpPso, "in-process", &[1., 3., 5., 7., 9.]),
            cell("s", Algorithm::Pso, "in-process", &[2., 4., 6., 8., 10.]),
        ];
        let r = &significance(&cells)[0];
        assert_abs_diff_eq!(r.p, 0.676, epsilon = 1e-3);
        assert_eq!(r.verdict(), "not told apart (p ≥ 0.05)");
        let table = markdown(&significance(&cells));
        assert!(table.contains(
            "| s | in-process | amp-pso | pso | 5.0000 | 6.0000 | 5 of 5 | 0.676 | not told apart"
        ));
    }

    #[test]
    fn each_scenario_and_mode_has_its_own_reference() {
        let f = [1.0, 2.0, 3.0];
        let cells = [
            cell("a", Algorithm::AmpPso, "in-process", &f),
            cell("a", Algorithm::AmpPso, "distributed", &f),
            cell("a", Algorithm::MpPso, "in-process", &f),
            cell("a", Algorithm::MpPso, "distributed", &f),
            cell("b", Algorithm::AmpPso, "in-process", &f),
            cell("b", Algorithm::Pso, "in-process", &f),
            cell("c", Algorithm::AmpPso, "in-process", &f),
        ];
        let rows = significance(&cells);
        let got: Vec<(&str, &str, Algorithm)> = rows
            .iter()
            .map(|r| (r.scenario.as_str(), r.mode.as_str(), r.other))
            .collect();
        assert_eq!(
            got,
            [
                ("a", "in-process", Algorithm::MpPso),
                ("a", "distributed", Algorithm::MpPso),
                ("b", "in-process", Algorithm::Pso),
            ]
        );
        // A single-population first algorithm has no distributed cell: there the first
        // multi-population one is the reference, and the table names it.
        let mixed = [
            cell("d", Algorithm::Pso, "in-process", &f),
            cell("d", Algorithm::AmpPso, "in-process", &f),
            cell("d", Algorithm::AmpPso, "distributed", &f),
            cell("d", Algorithm::MpPso, "distributed", &f),
        ];
        let mixed_rows = significance(&mixed);
        assert_eq!(mixed_rows.len(), 2);
        assert_eq!(mixed_rows[1].reference, Algorithm::AmpPso);
        assert!(markdown(&mixed_rows).contains("| d | distributed | amp-pso | mp-pso |"));
        // Identical samples: every value tied, p = 1.
        assert_abs_diff_eq!(rows[0].p, 1.0, epsilon = 1e-12);
        assert!(markdown(&[]).is_empty());
    }
}
