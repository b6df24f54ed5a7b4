//! The figures of CPP-DSMV, §3, recomputed from a path and the map alone (Table 2 and Figure 7):
//! coverage ratio, and the distributions of clearance to impassable terrain (7a), of the slope
//! under the vehicle (7b) and of the cross-track error (7c).
//!
//! - **Coverage ratio** = area swept by the swath / area of the region. The swath is the row
//!   spacing `2·R_min` (the collector spans the row spacing, so adjacent rows abut, which is the
//!   only reading under which the paper's 68.28 % is reachable with rows `2·R_min` apart). A
//!   raster of `cell_m` cells counts a cell covered when its centre lies within half a swath of a
//!   path sample; samples are taken at most a quarter swath apart, so the union of the discs is
//!   the swept strip to within a few percent of a cell at its edges. The ratio over the passable
//!   area (cells not steeper than the critical slope) is reported beside it.
//! - **Clearance** of a sample = distance to the nearest impassable cell centre, exact (a window
//!   scan) wherever it is below `exact_below`, the EDT estimate above it.

use serde::{Deserialize, Serialize};

use super::boxes::Rect;
use super::path::PathSample;
use super::TerrainMap25;

/// A histogram on fixed edges; values below the first edge and at or above the last are counted
/// apart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Histogram {
    /// Bin edges, ascending.
    pub edges: Vec<f64>,
    /// `counts[k]` = values in `[edges[k], edges[k+1])`.
    pub counts: Vec<usize>,
    /// Values below `edges[0]`.
    pub below: usize,
    /// Values at or above the last edge (including +∞).
    pub above: usize,
}

impl Histogram {
    /// Counts `values` into `bins` equal bins over `[lo, hi)`.
    pub fn new(values: &[f64], lo: f64, hi: f64, bins: usize) -> Self {
        let bins = bins.max(1);
        let width = (hi - lo) / bins as f64;
        let edges: Vec<f64> = (0..=bins).map(|k| lo + width * k as f64).collect();
        let mut counts = vec![0; bins];
        let (mut below, mut above) = (0, 0);
        for &v in values {
            if v.is_nan() || v >= hi {
                above += 1;
            } else if v < lo {
                below += 1;
            } else {
                let k = (((v - lo) / width).floor() as usize).min(bins - 1);
                counts[k] += 1;
            }
        }
        Self {
            edges,
            counts,
            below,
            above,
        }
    }
}

/// Summary of a sample distribution.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Distribution {
    /// Number of values.
    pub count: usize,
    /// Smallest.
    pub min: f64,
    /// 5th percentile.
    pub p5: f64,
    /// Median.
    pub median: f64,
    /// 95th percentile.
    pub p95: f64,
    /// Largest.
    pub max: f64,
    /// Mean.
    pub mean: f64,
    /// The histogram.
    pub histogram: Histogram,
}

impl Distribution {
    /// Summarises `values` (finite values only for the order statistics; +∞ counts in `above`).
    pub fn new(values: &[f64], lo: f64, hi: f64, bins: usize) -> Self {
        let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        finite.sort_by(f64::total_cmp);
        let q = |p: f64| -> f64 {
            if finite.is_empty() {
                return f64::NAN;
            }
            let pos = p * (finite.len() - 1) as f64;
            let (i, f) = (pos.floor() as usize, pos.fract());
            let next = finite.get(i + 1).copied().unwrap_or(finite[i]);
            finite[i] + f * (next - finite[i])
        };
        let mean = if finite.is_empty() {
            f64::NAN
        } else {
            finite.iter().sum::<f64>() / finite.len() as f64
        };
        Self {
            count: values.len(),
            min: finite.first().copied().unwrap_or(f64::NAN),
            p5: q(0.05),
            median: q(0.5),
            p95: q(0.95),
            max: finite.last().copied().unwrap_or(f64::NAN),
            mean,
            histogram: Histogram::new(values, lo, hi, bins),
        }
    }
}

impl Distribution {
    /// The distribution of several parts' values together, when every part's histogram has the
    /// same edges (None otherwise, or with no parts). Count, extremes and mean are exact; the
    /// 5th percentile, median and 95th percentile are read off the merged histogram by linear
    /// interpolation inside a bin, so they are exact to one bin width.
    pub fn merge(parts: &[&Distribution]) -> Option<Distribution> {
        let first = parts.first()?;
        let edges = &first.histogram.edges;
        if edges.len() < 2 || parts.iter().any(|p| &p.histogram.edges != edges) {
            return None;
        }
        let mut histogram = Histogram {
            edges: edges.clone(),
            counts: vec![0; edges.len() - 1],
            below: 0,
            above: 0,
        };
        for p in parts {
            for (c, &k) in histogram.counts.iter_mut().zip(&p.histogram.counts) {
                *c += k;
            }
            histogram.below += p.histogram.below;
            histogram.above += p.histogram.above;
        }
        let count: usize = parts.iter().map(|p| p.count).sum();
        let weighted: Vec<&&Distribution> = parts.iter().filter(|p| p.mean.is_finite()).collect();
        let weight: usize = weighted.iter().map(|p| p.count).sum();
        let mean = if weight == 0 {
            f64::NAN
        } else {
            weighted
                .iter()
                .map(|p| p.mean * p.count as f64)
                .sum::<f64>()
                / weight as f64
        };
        let min = parts
            .iter()
            .map(|p| p.min)
            .filter(|v| !v.is_nan())
            .fold(f64::INFINITY, f64::min);
        let max = parts
            .iter()
            .map(|p| p.max)
            .filter(|v| !v.is_nan())
            .fold(f64::NEG_INFINITY, f64::max);
        let (min, max) = if min <= max {
            (min, max)
        } else {
            (f64::NAN, f64::NAN)
        };
        let q = |p: f64| histogram.quantile(p, min, max);
        Some(Distribution {
            count,
            min,
            p5: q(0.05),
            median: q(0.5),
            p95: q(0.95),
            max,
            mean,
            histogram: histogram.clone(),
        })
    }
}

impl Histogram {
    /// The `p` quantile of the counted values, interpolated linearly inside its bin; values
    /// below or above the range stand at `min` / `max`.
    fn quantile(&self, p: f64, min: f64, max: f64) -> f64 {
        let total = self.below + self.counts.iter().sum::<usize>() + self.above;
        if total == 0 {
            return f64::NAN;
        }
        let rank = p.clamp(0.0, 1.0) * total as f64;
        let mut seen = self.below as f64;
        if rank < seen {
            return min;
        }
        for (k, &c) in self.counts.iter().enumerate() {
            let c = c as f64;
            if c > 0.0 && rank <= seen + c {
                let (a, b) = (self.edges[k], self.edges[k + 1]);
                return (a + (rank - seen) / c * (b - a)).clamp(min, max);
            }
            seen += c;
        }
        max
    }
}

/// Distance from `(x, y)` to the nearest impassable cell centre, exact when below `exact_below`.
pub fn exact_clearance(map: &TerrainMap25, x: f64, y: f64, exact_below: f64) -> f64 {
    let estimate = map.clearance_to_impassable(x, y);
    let h = map.cell_m();
    // The EDT estimate is off by less than 2·√2·h; only then can the exact value be small.
    let reach = estimate.min(exact_below + 2.0 * std::f64::consts::SQRT_2 * h);
    if !reach.is_finite() || estimate > exact_below + 2.0 * std::f64::consts::SQRT_2 * h {
        return estimate;
    }
    let [ox, oy] = map.origin();
    let lo_i = (((x - reach - ox) / h).floor().max(0.0)) as usize;
    let lo_j = (((y - reach - oy) / h).floor().max(0.0)) as usize;
    let hi_i = ((((x + reach - ox) / h).ceil()).max(0.0) as usize).min(map.nx().saturating_sub(1));
    let hi_j = ((((y + reach - oy) / h).ceil()).max(0.0) as usize).min(map.ny().saturating_sub(1));
    let blocked = map.impassable();
    let mut best = estimate;
    for j in lo_j..=hi_j {
        for i in lo_i..=hi_i {
            if blocked.get(j * map.nx() + i).copied().unwrap_or(false) {
                let [cx, cy] = map.cell_centre(i, j);
                best = best.min((x - cx).hypot(y - cy));
            }
        }
    }
    best
}

/// Area swept by a path's swath over a region.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct CoverageCount {
    /// Swept area / region area.
    pub ratio: f64,
    /// Swept passable area / passable area of the region.
    pub ratio_of_passable: f64,
    /// Swept area, m².
    pub covered_m2: f64,
    /// Region area, m².
    pub area_m2: f64,
}

/// Counts the area of `region` within `swath / 2` of any sample, on a raster of `cell_m`.
pub fn coverage(
    samples: &[PathSample],
    map: &TerrainMap25,
    region: Rect,
    swath: f64,
    cell_m: f64,
) -> CoverageCount {
    let nx = ((region.x1 - region.x0) / cell_m).ceil().max(1.0) as usize;
    let ny = ((region.y1 - region.y0) / cell_m).ceil().max(1.0) as usize;
    let mut covered = vec![false; nx * ny];
    let half = swath / 2.0;
    let reach = (half / cell_m).ceil() as i64;
    for s in samples {
        let ci = ((s.x - region.x0) / cell_m).floor() as i64;
        let cj = ((s.y - region.y0) / cell_m).floor() as i64;
        for dj in -reach..=reach {
            for di in -reach..=reach {
                let (i, j) = (ci + di, cj + dj);
                if i < 0 || j < 0 || i >= nx as i64 || j >= ny as i64 {
                    continue;
                }
                let cx = region.x0 + (i as f64 + 0.5) * cell_m;
                let cy = region.y0 + (j as f64 + 0.5) * cell_m;
                if (cx - s.x).hypot(cy - s.y) <= half {
                    covered[j as usize * nx + i as usize] = true;
                }
            }
        }
    }
    let (mut hit, mut passable, mut passable_hit) = (0usize, 0usize, 0usize);
    for j in 0..ny {
        for i in 0..nx {
            let cx = region.x0 + (i as f64 + 0.5) * cell_m;
            let cy = region.y0 + (j as f64 + 0.5) * cell_m;
            let c = covered[j * nx + i];
            hit += usize::from(c);
            if !map.is_impassable(cx, cy) {
                passable += 1;
                passable_hit += usize::from(c);
            }
        }
    }
    let cell_area = cell_m * cell_m;
    CoverageCount {
        ratio: hit as f64 / (nx * ny) as f64,
        ratio_of_passable: if passable == 0 {
            0.0
        } else {
            passable_hit as f64 / passable as f64
        },
        covered_m2: hit as f64 * cell_area,
        area_m2: (nx * ny) as f64 * cell_area,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coverage::path::PieceKind;
    use approx::assert_abs_diff_eq;

    fn flat_map(n: usize, cliff: Option<(usize, usize)>) -> TerrainMap25 {
        let mut z = vec![0.0; n * n];
        if let Some((i, j)) = cliff {
            z[j * n + i] = 50.0;
        }
        crate::coverage::test_map(n, z)
    }

    fn line(y: f64, x0: f64, x1: f64) -> Vec<PathSample> {
        let n = ((x1 - x0) / 0.5) as usize;
        (0..=n)
            .map(|k| PathSample {
                s: k as f64 * 0.5,
                x: x0 + k as f64 * 0.5,
                y,
                heading: 0.0,
                curvature: 0.0,
                kind: PieceKind::Straight,
            })
            .collect()
    }

    #[test]
    fn merged_distribution_adds_counts_and_reads_quantiles_off_the_bins() {
        // Part a: 1.5, 2.5 (mean 2); part b: 0.5, 0.5, 3.5, 3.5 (mean 2); bins of 1 over [0, 4).
        let a = Distribution::new(&[1.5, 2.5], 0.0, 4.0, 4);
        let b = Distribution::new(&[0.5, 0.5, 3.5, 3.5], 0.0, 4.0, 4);
        let m = match Distribution::merge(&[&a, &b]) {
            Some(m) => m,
            None => panic!("same edges must merge"),
        };
        assert_eq!(m.count, 6);
        assert_eq!(m.histogram.counts, vec![2, 1, 1, 2]);
        assert_abs_diff_eq!(m.mean, 2.0, epsilon = 1e-12);
        assert_abs_diff_eq!(m.min, 0.5, epsilon = 1e-12);
        assert_abs_diff_eq!(m.max, 3.5, epsilon = 1e-12);
        // Median: rank 3 of 6 ends bin [1, 2) (cumulative 2 + 1) -> its upper edge, 2.0.
        assert_abs_diff_eq!(m.median, 2.0, epsilon = 1e-12);
        // p5: rank 0.3 is 0.15 of the way into bin [0, 1) -> 0.15, clamped to min 0.5.
        assert_abs_diff_eq!(m.p5, 0.5, epsilon = 1e-12);
        // p95: rank 5.7 is 0.85 into the last bin's 2 values -> 3.85, clamped to max 3.5.
        assert_abs_diff_eq!(m.p95, 3.5, epsilon = 1e-12);
        let other = Distribution::new(&[1.0], 0.0, 5.0, 5);
        assert!(Distribution::merge(&[&a, &other]).is_none());
        assert!(Distribution::merge(&[]).is_none());
    }

    #[test]
    fn histogram_counts_bins_and_the_tails() {
        let h = Histogram::new(&[-1.0, 0.0, 0.5, 1.0, 2.9, 3.0, f64::INFINITY], 0.0, 3.0, 3);
        assert_eq!(h.counts, vec![2, 1, 1]);
        assert_eq!((h.below, h.above), (1, 2));
        assert_eq!(h.edges, vec![0.0, 1.0, 2.0, 3.0]);
    }

    #[test]
    fn distribution_quantiles_interpolate() {
        let d = Distribution::new(&[4.0, 1.0, 3.0, 2.0, 5.0], 0.0, 10.0, 10);
        assert_abs_diff_eq!(d.median, 3.0);
        assert_abs_diff_eq!(d.p5, 1.2, epsilon = 1e-12);
        assert_abs_diff_eq!(d.mean, 3.0);
        assert_abs_diff_eq!(d.min, 1.0);
        assert_abs_diff_eq!(d.max, 5.0);
    }

    #[test]
    fn a_line_across_a_square_covers_its_swath() {
        // A 10 m swath along y = 20 across a 40 × 40 m region: 400 m² of 1600 m².
        let map = flat_map(21, None);
        let region = Rect::new(0.0, 0.0, 40.0, 40.0);
        let c = coverage(&line(20.0, -5.0, 45.0), &map, region, 10.0, 1.0);
        assert_abs_diff_eq!(c.covered_m2, 400.0, epsilon = 1e-9);
        assert_abs_diff_eq!(c.ratio, 0.25, epsilon = 1e-12);
        assert_abs_diff_eq!(c.ratio_of_passable, 0.25, epsilon = 1e-12);
    }

    #[test]
    fn exact_clearance_measures_to_the_nearest_impassable_centre() {
        // A spike at node (10, 10) makes its neighbours steep; the nearest impassable centres
        // are within a cell of (20, 20).
        let map = flat_map(21, Some((10, 10)));
        let blocked: Vec<[f64; 2]> = (0..21 * 21)
            .filter(|&k| map.impassable()[k])
            .map(|k| map.cell_centre(k % 21, k / 21))
            .collect();
        assert!(!blocked.is_empty());
        for (x, y) in [(3.3, 7.1), (30.2, 24.9), (20.0, 35.0)] {
            let brute = blocked
                .iter()
                .map(|c| (x - c[0]).hypot(y - c[1]))
                .fold(f64::INFINITY, f64::min);
            assert_abs_diff_eq!(exact_clearance(&map, x, y, 30.0), brute, epsilon = 1e-9);
        }
    }
}
