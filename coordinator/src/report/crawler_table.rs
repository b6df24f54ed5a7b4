//! The crawler part of `compare` (Lu et al. 2023, Table 9 and Fig. 10): smoothed path length per
//! algorithm over the seeds, hazard intrusions, the other §5.2 figures, and the gap to a
//! reference shortest admissible path found by grid search on the same terrain.

use std::fmt::Write;

use shoal_common::gridsearch::GridSearch;
use shoal_common::scenario::Scenario;

use crate::report::crawler_gap::gap_percent;

pub use crate::report::crawler_stats::{mean_std, CrawlerStats};

/// The reference of one crawler.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// Scenario name.
    pub scenario: String,
    /// Vehicle id.
    pub vehicle: String,
    /// Grid spacing, metres.
    pub cell_m: f64,
    /// Dijkstra length on the grid (32 directions), metres.
    pub grid_m: f64,
    /// After any-angle refinement, metres: the yardstick.
    pub refined_m: f64,
    /// Wall time of the search, seconds.
    pub time_s: f64,
}

/// References of every crawler of every scenario (hazard clearance 0: the same admissibility
/// rule as the crawler cost's penalty).
pub fn references(scenarios: &[Scenario], cell_m: f64) -> Vec<Reference> {
    let mut out = Vec::new();
    for s in scenarios {
        for (i, v) in s.vehicles.iter().enumerate() {
            let started = std::time::Instant::now();
            let reference = s
                .crawler_model(i)
                .and_then(|model| GridSearch::crawler_reference(&model, cell_m, 0.0));
            if let Some((grid, refined)) = reference {
                out.push(Reference {
                    scenario: s.name.clone(),
                    vehicle: v.id.clone(),
                    cell_m,
                    grid_m: grid.length_m,
                    refined_m: refined.length_m,
                    time_s: started.elapsed().as_secs_f64(),
                });
            }
        }
    }
    out
}

/// The crawler table: one row per cell that has crawlers, with the gap of the mean length to
/// the scenario's (first) crawler reference.
pub fn markdown(cells: &[crate::report::compare::Cell], references: &[Reference]) -> String {
    let mut s = String::new();
    if !cells.iter().any(|c| c.crawler.is_some()) {
        return s;
    }
    s.push_str(
        "\n| scenario | algorithm | crawler paths | length best (m) | length mean (m) | length std (m) | mean vs reference | hazard intrusions | min hazard clearance (m) | max slope (°) | mean undulation (m) | mean energy (kWh) | mean slip | mean run time (s) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cells {
        let Some(k) = &c.crawler else { continue };
        let gap = references
            .iter()
            .find(|r| r.scenario == c.scenario)
            .map_or("–".to_string(), |r| {
                format!("{:+.2} %", gap_percent(k.length_m.1, r.refined_m))
            });
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.3} | {:.3} | {:.3} | {} | {} | {} | {:.2} | {:.3} | {:.3} | {:.3} | {:.2} |",
            c.scenario,
            c.algorithm.as_str(),
            k.paths,
            k.length_m.0,
            k.length_m.1,
            k.length_m.2,
            gap,
            k.intruding,
            k.min_clearance_m.map_or("–".into(), |m| format!("{m:.2}")),
            k.max_slope_deg,
            k.mean_undulation_m,
            k.mean_energy_kwh,
            k.mean_slip,
            k.mean_runtime_s
        );
    }
    if !references.is_empty() {
        s.push_str("\n| scenario | crawler | reference: grid search | cell (m) | grid length (m) | refined length (m) | search time (s) |\n|---|---|---|---|---|---|---|\n");
        for r in references {
            let _ = writeln!(
                s,
                "| {} | {} | A* (Dijkstra's lengths), 32 directions, hazard clearance 0, slope limit, then string pulling | {} | {:.3} | {:.3} | {:.2} |",
                r.scenario, r.vehicle, r.cell_m, r.grid_m, r.refined_m, r.time_s
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn mean_and_sample_std_by_hand() {
        // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, squared deviations sum 32, sample variance 32/7.
        let (m, s) = mean_std(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]);
        assert_abs_diff_eq!(m, 5.0, epsilon = 1e-12);
        assert_abs_diff_eq!(s, (32.0f64 / 7.0).sqrt(), epsilon = 1e-12);
        assert_eq!(mean_std(&[3.0]), (3.0, 0.0));
    }
}
