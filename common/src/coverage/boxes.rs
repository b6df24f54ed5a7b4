//! Merged, inflated obstacle bounding boxes `O_new` (CPP-DSMV, §2.2 and Figure 6: "the solid red
//! rectangular zones … the fused and inflated bounding boxes", the absolute no-go regions).
//!
//! Rebuilt from the text (the equations were lost):
//!
//! ```text
//! B_k      = [min xᵢ, max xᵢ] × [min yᵢ, max yᵢ]      over the centres of component k
//! O_k      = B_k ⊕ d_s                                  (grown by the safety clearance d_s)
//! merge    O_a ∪ O_b → bbox(O_a ∪ O_b)  while gap(O_a, O_b) < g_merge
//! ```
//!
//! where the components are the 8-connected groups of impassable cells (steeper than the critical
//! slope), `d_s` is the safety clearance (8 m) and `gap` the axis-aligned distance between two
//! boxes (0 when they overlap). A point outside `O_k` is farther than `d_s` from every impassable
//! cell centre of component k (it is more than `d_s` away along x or along y), which is what makes
//! "outside every box" imply the clearance. Boxes closer than `g_merge` leave a passage the
//! crawler should not thread (one swath by default) and are fused, repeatedly, until no two boxes
//! are that close.

use serde::{Deserialize, Serialize};

use super::TerrainMap25;

/// An axis-aligned rectangle `[x0, y0] – [x1, y1]`, metres.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rect {
    /// West edge.
    pub x0: f64,
    /// South edge.
    pub y0: f64,
    /// East edge.
    pub x1: f64,
    /// North edge.
    pub y1: f64,
}

impl Rect {
    /// A rectangle from its corners (reordered if needed).
    pub fn new(x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        Self {
            x0: x0.min(x1),
            y0: y0.min(y1),
            x1: x0.max(x1),
            y1: y0.max(y1),
        }
    }

    /// Grown by `d` on every side.
    pub fn inflated(&self, d: f64) -> Self {
        Self::new(self.x0 - d, self.y0 - d, self.x1 + d, self.y1 + d)
    }

    /// Whether `(x, y)` lies strictly inside.
    pub fn contains_strictly(&self, x: f64, y: f64) -> bool {
        x > self.x0 && x < self.x1 && y > self.y0 && y < self.y1
    }

    /// Whether `(x, y)` lies inside or on the edge.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }

    /// [`Rect::contains`] up to 1e-9 m of rounding: the test of a vehicle's centre being in the
    /// area (a pose on the area's edge, where rows end, must count as inside).
    pub fn holds(&self, x: f64, y: f64) -> bool {
        const EPS: f64 = 1e-9;
        x >= self.x0 - EPS && x <= self.x1 + EPS && y >= self.y0 - EPS && y <= self.y1 + EPS
    }

    /// Axis-aligned gap to `other`: the larger of the x and y separations, 0 when they touch or
    /// overlap.
    pub fn gap(&self, other: &Rect) -> f64 {
        let gx = (other.x0 - self.x1).max(self.x0 - other.x1).max(0.0);
        let gy = (other.y0 - self.y1).max(self.y0 - other.y1).max(0.0);
        gx.max(gy)
    }

    /// The smallest rectangle holding both.
    pub fn union(&self, other: &Rect) -> Self {
        Self::new(
            self.x0.min(other.x0),
            self.y0.min(other.y0),
            self.x1.max(other.x1),
            self.y1.max(other.y1),
        )
    }

    /// Area, m².
    pub fn area(&self) -> f64 {
        (self.x1 - self.x0) * (self.y1 - self.y0)
    }
}

/// Boxes bucketed in horizontal bands, so a point test looks only at the boxes of its band (the
/// band boxes number in the hundreds and the planner tests millions of points).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BoxIndex {
    y0: f64,
    band: f64,
    buckets: Vec<Vec<usize>>,
}

impl BoxIndex {
    /// Indexes `boxes` in bands of `band` metres.
    pub fn new(boxes: &[Rect], band: f64) -> Self {
        let band = if band.is_finite() && band > 0.0 {
            band
        } else {
            10.0
        };
        let y0 = boxes.iter().map(|b| b.y0).fold(f64::INFINITY, f64::min);
        let y1 = boxes.iter().map(|b| b.y1).fold(f64::NEG_INFINITY, f64::max);
        if !(y0.is_finite() && y1.is_finite()) {
            return Self::default();
        }
        let slot = |y: f64| ((y - y0) / band).floor().max(0.0) as usize;
        let mut buckets = vec![Vec::new(); slot(y1) + 1];
        for (k, b) in boxes.iter().enumerate() {
            for bucket in &mut buckets[slot(b.y0)..=slot(b.y1)] {
                bucket.push(k);
            }
        }
        Self { y0, band, buckets }
    }

    /// Whether a box of `boxes` (the ones indexed) holds `(x, y)` strictly inside.
    pub fn any_contains_strictly(&self, boxes: &[Rect], x: f64, y: f64) -> bool {
        if self.buckets.is_empty() || y.is_nan() || y < self.y0 {
            return false;
        }
        let k = ((y - self.y0) / self.band).floor() as usize;
        self.buckets.get(k).is_some_and(|bucket| {
            bucket
                .iter()
                .any(|&i| boxes.get(i).is_some_and(|b| b.contains_strictly(x, y)))
        })
    }
}

/// Bounding boxes of the 8-connected components of impassable cells, over cell centres.
pub fn impassable_components(map: &TerrainMap25) -> Vec<Rect> {
    components_in_rows(map, 0, map.ny())
}

/// [`impassable_components`] of the cell rows `j_lo..j_hi` alone (connectivity inside them).
fn components_in_rows(map: &TerrainMap25, j_lo: usize, j_hi: usize) -> Vec<Rect> {
    let (nx, ny) = (map.nx(), map.ny());
    let j_hi = j_hi.min(ny);
    let blocked = map.impassable();
    let mut seen = vec![false; blocked.len()];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for start in j_lo * nx..j_hi * nx {
        if !blocked[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let (mut i0, mut j0, mut i1, mut j1) = (usize::MAX, usize::MAX, 0, 0);
        while let Some(k) = stack.pop() {
            let (i, j) = (k % nx, k / nx);
            (i0, j0, i1, j1) = (i0.min(i), j0.min(j), i1.max(i), j1.max(j));
            for dj in -1i64..=1 {
                for di in -1i64..=1 {
                    let (ni, nj) = (i as i64 + di, j as i64 + dj);
                    if ni < 0 || nj < j_lo as i64 || ni >= nx as i64 || nj >= j_hi as i64 {
                        continue;
                    }
                    let n = nj as usize * nx + ni as usize;
                    if blocked[n] && !seen[n] {
                        seen[n] = true;
                        stack.push(n);
                    }
                }
            }
        }
        let [ax, ay] = map.cell_centre(i0, j0);
        let [bx, by] = map.cell_centre(i1, j1);
        out.push(Rect::new(ax, ay, bx, by));
    }
    out
}

/// The obstacles' outline as a staircase: the bounding boxes of the impassable components inside
/// each horizontal band of `band_m` (cell rows), grown by `clearance` and not fused. Around an
/// L-shaped or ring-shaped cluster these hug the shape where one box per component would cover
/// the passable ground inside its corners.
pub fn band_boxes(map: &TerrainMap25, clearance: f64, band_m: f64) -> Vec<Rect> {
    let rows = ((band_m / map.cell_m()).round() as usize).max(1);
    (0..map.ny())
        .step_by(rows)
        .flat_map(|j| components_in_rows(map, j, j + rows))
        .map(|r| r.inflated(clearance))
        .collect()
}

/// Fuses boxes closer than `merge_gap` until no two are (the result does not depend on the
/// input order beyond the final sort, which is by `(x0, y0)`).
pub fn merge_boxes(mut boxes: Vec<Rect>, merge_gap: f64) -> Vec<Rect> {
    loop {
        let mut merged_any = false;
        let mut out: Vec<Rect> = Vec::with_capacity(boxes.len());
        for b in boxes {
            let mut cur = b;
            // Absorb every box already kept that is too close; repeat since growing may reach
            // more of them.
            loop {
                let before = out.len();
                out.retain(|o| {
                    if o.gap(&cur) < merge_gap {
                        cur = cur.union(o);
                        false
                    } else {
                        true
                    }
                });
                if out.len() == before {
                    break;
                }
                merged_any = true;
            }
            out.push(cur);
        }
        boxes = out;
        if !merged_any {
            break;
        }
    }
    boxes.sort_by(|a, b| a.x0.total_cmp(&b.x0).then(a.y0.total_cmp(&b.y0)));
    boxes
}

/// The no-go boxes of a map: components grown by `clearance` and fused below `merge_gap`.
pub fn no_go_boxes(map: &TerrainMap25, clearance: f64, merge_gap: f64) -> Vec<Rect> {
    let grown = impassable_components(map)
        .into_iter()
        .map(|r| r.inflated(clearance))
        .collect();
    merge_boxes(grown, merge_gap)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn gap_is_the_larger_axis_separation_and_zero_on_overlap() {
        let a = Rect::new(0.0, 0.0, 10.0, 10.0);
        assert_abs_diff_eq!(a.gap(&Rect::new(13.0, 2.0, 20.0, 4.0)), 3.0);
        assert_abs_diff_eq!(a.gap(&Rect::new(14.0, 15.0, 20.0, 20.0)), 5.0);
        assert_abs_diff_eq!(a.gap(&Rect::new(5.0, 5.0, 20.0, 20.0)), 0.0);
        assert_abs_diff_eq!(a.area(), 100.0);
        assert!(a.contains_strictly(5.0, 5.0));
        assert!(!a.contains_strictly(10.0, 5.0));
        assert!(a.contains(10.0, 5.0));
    }

    #[test]
    fn close_boxes_fuse_transitively_and_far_ones_stay() {
        let boxes = vec![
            Rect::new(0.0, 0.0, 10.0, 10.0),
            Rect::new(30.0, 0.0, 40.0, 10.0),
            // Bridges the first two (gaps 5 and 5), but only once it has absorbed one of them.
            Rect::new(15.0, 0.0, 25.0, 10.0),
            Rect::new(100.0, 100.0, 110.0, 110.0),
        ];
        let merged = merge_boxes(boxes, 6.0);
        assert_eq!(merged.len(), 2);
        assert_eq!(merged[0], Rect::new(0.0, 0.0, 40.0, 10.0));
        assert_eq!(merged[1], Rect::new(100.0, 100.0, 110.0, 110.0));
        assert_eq!(merge_boxes(merged.clone(), 6.0), merged);
    }

    /// A 20 × 20 grid of 2 m cells with a vertical 10 m wall at cells i = 5 (x = 10 m) from
    /// j = 4 to j = 8, and one isolated cliff cell at (15, 15).
    fn two_cliff_map() -> TerrainMap25 {
        let n = 20;
        let mut z = vec![0.0; n * n];
        for j in 4..=8 {
            for i in 6..n {
                z[j * n + i] = 10.0;
            }
        }
        // A single steep spike: its four neighbours see a 20 m rise over 4 m.
        z[15 * n + 15] = 20.0;
        crate::coverage::test_map(n, z)
    }

    #[test]
    fn components_bound_the_impassable_cells_and_inflation_keeps_the_clearance() {
        let map = two_cliff_map();
        let comps = impassable_components(&map);
        assert!(comps.len() >= 2, "{comps:?}");
        // Every impassable cell centre is inside some component box.
        for j in 0..map.ny() {
            for i in 0..map.nx() {
                if map.impassable()[j * map.nx() + i] {
                    let [x, y] = map.cell_centre(i, j);
                    assert!(comps.iter().any(|r| r.contains(x, y)), "({x}, {y})");
                }
            }
        }
        // Outside the inflated boxes the clearance to impassable cells exceeds 8 m.
        let boxes = no_go_boxes(&map, 8.0, 0.0);
        for k in 0..400 {
            let (x, y) = ((k % 20) as f64 * 2.0 + 0.5, (k / 20) as f64 * 2.0 + 0.5);
            if !boxes.iter().any(|b| b.contains(x, y)) {
                assert!(map.clearance_to_impassable(x, y) > 8.0 - 1e-9, "({x}, {y})");
            }
        }
    }

    #[test]
    fn band_boxes_hug_an_l_shaped_obstacle_and_cover_every_cell() {
        // A 50 x 50 grid of 2 m cells; an L of steep cells: a column at x = 20 m from y = 10 to
        // 80 m, and a foot along y = 10 m from x = 20 to 80 m (one cell thick each).
        let n = 50;
        let mut z = vec![0.0; n * n];
        for k in 5..=40 {
            z[k * n + 10] = 100.0; // the column (i = 10)
            z[5 * n + k] = 100.0; // the foot (j = 5)
        }
        let map = crate::coverage::test_map(n, z);
        let whole = impassable_components(&map);
        assert_eq!(whole.len(), 1, "{whole:?}");
        let bands = band_boxes(&map, 0.0, 10.0);
        let band_area: f64 = bands.iter().map(Rect::area).sum();
        assert!(
            band_area < 0.5 * whole[0].area(),
            "{band_area} vs {}",
            whole[0].area()
        );
        // Every impassable cell centre lies in some band box.
        let blocked = map.impassable();
        for j in 0..n {
            for i in 0..n {
                if blocked[j * n + i] {
                    let [x, y] = map.cell_centre(i, j);
                    assert!(
                        bands.iter().any(|b| b.contains(x, y)),
                        "({x}, {y}) uncovered"
                    );
                }
            }
        }
        // Grown by the clearance.
        let grown = band_boxes(&map, 8.0, 10.0);
        assert_eq!(grown.len(), bands.len());
        assert_abs_diff_eq!(grown[0].x0, bands[0].x0 - 8.0);
    }

    #[test]
    fn the_box_index_answers_as_a_scan_of_every_box() {
        let boxes = vec![
            Rect::new(0.0, 0.0, 10.0, 25.0),
            Rect::new(20.0, 12.0, 30.0, 14.0),
            Rect::new(5.0, 40.0, 50.0, 41.0),
        ];
        let index = BoxIndex::new(&boxes, 10.0);
        for j in -10..=100 {
            for i in -10..=120 {
                let (x, y) = (i as f64 * 0.5, j as f64 * 0.5);
                let scan = boxes.iter().any(|b| b.contains_strictly(x, y));
                assert_eq!(
                    index.any_contains_strictly(&boxes, x, y),
                    scan,
                    "({x}, {y})"
                );
            }
        }
        assert!(!BoxIndex::new(&[], 10.0).any_contains_strictly(&[], 0.0, 0.0));
    }
}
