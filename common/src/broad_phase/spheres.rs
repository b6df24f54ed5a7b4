//! Broad phase for the vehicle–obstacle terms: a uniform grid over the horizontal plane in which
//! each cell lists the spheres whose reach overlaps it, so a path's chunk of legs is tested only
//! against the spheres of the cells its box covers instead of every sphere of the scenario.
//! The spheres are fixed for a planning problem, so the grid is built once per model.

use crate::geometry::Vec3;

/// Cells per sphere the grid aims for: a few, so most cells hold one sphere or none.
const CELLS_PER_SPHERE: f64 = 4.0;
/// Most cells a grid has, whatever the number of spheres (memory stays under a megabyte).
const MAX_CELLS: usize = 1 << 16;

/// Sphere indices by horizontal grid cell, in compressed rows.
#[derive(Debug, Clone, Default)]
pub struct SphereGrid {
    /// Lower corner of the grid (x, y), metres.
    origin: [f64; 2],
    /// Side of a square cell, metres.
    cell: f64,
    /// Cells along x and y.
    size: [usize; 2],
    /// Cell `c`'s spheres are `items[starts[c]..starts[c + 1]]`, ascending.
    starts: Vec<u32>,
    /// Sphere indices.
    items: Vec<u32>,
    /// Spheres indexed.
    count: usize,
}

impl SphereGrid {
    /// Indexes spheres given as (centre, reach): a sphere is listed in every cell its
    /// horizontal square `centre ± reach` overlaps.
    pub fn new(spheres: &[(Vec3, f64)]) -> SphereGrid {
        let count = spheres.len();
        if count == 0 {
            return SphereGrid::default();
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for (c, r) in spheres {
            for d in 0..2 {
                lo[d] = lo[d].min(c[d] - r);
                hi[d] = hi[d].max(c[d] + r);
            }
        }
        let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(1.0);
        let cells = (CELLS_PER_SPHERE * count as f64).clamp(1.0, MAX_CELLS as f64);
        let mut cell = (area / cells).sqrt().max(1e-3);
        let along = |d: usize, cell: f64| (((hi[d] - lo[d]) / cell).floor() as usize + 1).max(1);
        while along(0, cell) * along(1, cell) > MAX_CELLS {
            cell *= 1.5;
        }
        let size = [along(0, cell), along(1, cell)];
        let mut grid = SphereGrid {
            origin: lo,
            cell,
            size,
            starts: Vec::new(),
            items: Vec::new(),
            count,
        };
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); size[0] * size[1]];
        for (k, (c, r)) in spheres.iter().enumerate() {
            let (x, y) = grid.span(&(c - Vec3::repeat(*r)), &(c + Vec3::repeat(*r)));
            for iy in y.0..=y.1 {
                for ix in x.0..=x.1 {
                    lists[iy * size[0] + ix].push(k as u32);
                }
            }
        }
        grid.starts.push(0);
        for list in lists {
            grid.items.extend(list);
            grid.starts.push(grid.items.len() as u32);
        }
        grid
    }

    /// Words of a [`SphereGrid::mark_near`] bit set for this grid.
    pub fn words(&self) -> usize {
        self.count.div_ceil(64)
    }

    /// Sets bit `k` of `marks` for every sphere `k` listed in a cell the box `[lo, hi]` covers
    /// horizontally: a superset of the spheres whose reach the box can touch.
    pub fn mark_near(&self, lo: &Vec3, hi: &Vec3, marks: &mut [u64]) {
        if self.count == 0 {
            return;
        }
        let (x, y) = self.span(lo, hi);
        for iy in y.0..=y.1 {
            let row = iy * self.size[0];
            let cells = self.starts[row + x.0] as usize..self.starts[row + x.1 + 1] as usize;
            for &k in &self.items[cells] {
                marks[k as usize / 64] |= 1 << (k % 64);
            }
        }
    }

    /// The cell ranges (x and y, inclusive) the box covers, clamped to the grid: cells past the
    /// edge hold nothing beyond what the edge cell holds.
    fn span(&self, lo: &Vec3, hi: &Vec3) -> ((usize, usize), (usize, usize)) {
        // Truncation is the floor for the non-negative quotients it is used on, without
        // `floor`'s library call (x86-64 has no rounding instruction before SSE4.1).
        let index = |v: f64, d: usize| {
            let q = (v - self.origin[d]) / self.cell;
            if q >= 0.0 {
                (q as usize).min(self.size[d] - 1)
            } else {
                0
            }
        };
        (
            (index(lo.x, 0), index(hi.x, 0)),
            (index(lo.y, 1), index(hi.y, 1)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_box_finds_the_spheres_it_covers_by_hand() {
        let spheres = [
            (Vec3::new(100.0, 100.0, 0.0), 50.0),
            (Vec3::new(900.0, 900.0, 0.0), 50.0),
            (Vec3::new(500.0, 100.0, 0.0), 80.0),
        ];
        let g = SphereGrid::new(&spheres);
        let mut marks = vec![0u64; g.words()];
        g.mark_near(
            &Vec3::new(0.0, 0.0, 0.0),
            &Vec3::new(160.0, 160.0, 0.0),
            &mut marks,
        );
        assert_eq!(marks[0] & 0b111, 0b001);
        marks[0] = 0;
        // Far outside the grid to the north-east: only the edge cell's sphere.
        g.mark_near(
            &Vec3::new(5000.0, 5000.0, 0.0),
            &Vec3::new(6000.0, 6000.0, 0.0),
            &mut marks,
        );
        assert_eq!(marks[0] & 0b111, 0b010);
        assert_eq!(SphereGrid::new(&[]).words(), 0);
    }

    proptest! {
        /// Every sphere whose horizontal square meets the box is marked.
        #[test]
        fn no_sphere_the_box_reaches_is_missed(
            spheres in prop::collection::vec(((0.0..2000.0f64, 0.0..2000.0f64), 1.0..200.0f64), 1..80),
            corner in (-500.0..2500.0f64, -500.0..2500.0f64),
            extent in (0.0..800.0f64, 0.0..800.0f64),
        ) {
            let spheres: Vec<(Vec3, f64)> =
                spheres.iter().map(|((x, y), r)| (Vec3::new(*x, *y, 0.0), *r)).collect();
            let g = SphereGrid::new(&spheres);
            let lo = Vec3::new(corner.0, corner.1, 0.0);
            let hi = lo + Vec3::new(extent.0, extent.1, 0.0);
            let mut marks = vec![0u64; g.words()];
            g.mark_near(&lo, &hi, &mut marks);
            for (k, (c, r)) in spheres.iter().enumerate() {
                let meets = (0..2).all(|d| c[d] + r >= lo[d] && c[d] - r <= hi[d]);
                if meets {
                    prop_assert!(marks[k / 64] & (1 << (k % 64)) != 0, "sphere {}", k);
                }
            }
        }
    }
}
