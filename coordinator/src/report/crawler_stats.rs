//! The crawler figures of one `compare` cell (Lu et al. 2023, Table 9): smoothed length, undulation,
//! energy, slip, hazard intrusions, over every crawler of every run.

use shoal_common::plan::Plan;

/// Crawler figures of one (scenario, algorithm) cell, over every crawler of every run.
#[derive(Debug, Clone, PartialEq)]
pub struct CrawlerStats {
    /// Crawler paths summarised (runs × crawlers).
    pub paths: usize,
    /// Best, mean and sample standard deviation of the smoothed length, metres.
    pub length_m: (f64, f64, f64),
    /// Mean undulation, metres.
    pub mean_undulation_m: f64,
    /// Mean energy, kWh.
    pub mean_energy_kwh: f64,
    /// Mean slip cost.
    pub mean_slip: f64,
    /// Paths that enter a hazard.
    pub intruding: usize,
    /// Smallest hazard clearance over all paths, metres.
    pub min_clearance_m: Option<f64>,
    /// Steepest slope over all paths, degrees.
    pub max_slope_deg: f64,
    /// Mean planning time per run, seconds.
    pub mean_runtime_s: f64,
}

/// Mean and sample standard deviation.
pub fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mean = v.iter().sum::<f64>() / n;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)
    } else {
        0.0
    };
    (mean, var.sqrt())
}

impl CrawlerStats {
    /// The stats of `plans`, or `None` when they have no crawler.
    pub fn of(plans: &[Plan]) -> Option<CrawlerStats> {
        let figures: Vec<_> = plans
            .iter()
            .flat_map(|p| p.vehicles.iter().filter_map(|v| v.crawler))
            .collect();
        if figures.is_empty() {
            return None;
        }
        let lengths: Vec<f64> = figures.iter().map(|f| f.length_m).collect();
        let (mean, std) = mean_std(&lengths);
        let n = figures.len() as f64;
        Some(CrawlerStats {
            paths: figures.len(),
            length_m: (
                lengths.iter().copied().fold(f64::INFINITY, f64::min),
                mean,
                std,
            ),
            mean_undulation_m: figures.iter().map(|f| f.undulation_m).sum::<f64>() / n,
            mean_energy_kwh: figures.iter().map(|f| f.energy_kwh).sum::<f64>() / n,
            mean_slip: figures.iter().map(|f| f.slip_cost).sum::<f64>() / n,
            intruding: figures.iter().filter(|f| f.hazard_intrusions > 0).count(),
            min_clearance_m: figures
                .iter()
                .filter_map(|f| f.min_hazard_clearance_m)
                .reduce(f64::min),
            max_slope_deg: figures.iter().map(|f| f.max_slope_deg).fold(0.0, f64::max),
            mean_runtime_s: plans.iter().map(|p| p.runtime_s).sum::<f64>()
                / plans.len().max(1) as f64,
        })
    }
}
