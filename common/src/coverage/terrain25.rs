//! The 2.5D terrain map of CPP-DSMV, §2.1: elevation → slope → impassable cells → no-go cells
//! dilated by half the vehicle width, plus the distance to the nearest impassable cell.
//!
//! Lattice: cell `(i, j)` (column i along x, row j along y, row 0 south) has its centre at
//! `origin + (i·h, j·h)`, `h = cell_m`; arrays are row-major, south row first
//! (`index = j·nx + i`), the layout of [`HeightGrid`]. Every per-cell value is the value *at the
//! centre*.
//!
//! Equations (CPP-DSMV, §2.1; the printed ones were lost, these are the standard forms its text
//! describes):
//!
//! 1. Discrete gradient. Interior central differences
//!    `∂Z/∂x ≈ (Z[i+1, j] − Z[i−1, j]) / 2h`, one-sided `(Z[1, j] − Z[0, j]) / h` and
//!    `(Z[nx−1, j] − Z[nx−2, j]) / h` on the first and last columns; likewise along y.
//! 2. Slope angle `θ = atan(√((∂Z/∂x)² + (∂Z/∂y)²))`, degrees: the steepest inclination of the
//!    seabed at the cell, whatever the heading.
//! 3. Binarised obstacle map `M(i, j) = 1 ⇔ θ(i, j) > θ_crit` (strictly steeper is impassable).
//! 4. Dilation `M_dil = M ⊕ D(r_dil)` with the Euclidean disc `D(r) = {(u, v) : u² + v² ≤ r²}`
//!    and `r_dil = W_veh / 2`; on the grid, a cell is no-go when some impassable cell *centre* is
//!    within `r_dil` of its centre, i.e. `EDT(i, j) ≤ r_dil` with
//! 5. `EDT(p) = min_{q ∈ M} ‖p − q‖`, the exact Euclidean distance transform of
//!    Felzenszwalb–Huttenlocher (see [`super::edt`]), computed once per map.
//!
//! Because distances are between centres, the clearance to the physical edge of an impassable
//! cell is half a cell less; the planner's own safety margin (§3: 4 m) covers that.
//!
//! The minor undulation `U` (the Perlin part) is *not* an obstacle: it is kept queryable
//! ([`TerrainMap25::undulation_at`], [`TerrainMap25::undulation_gradient_at`]) for the tracking
//! layer, which treats it as a posture disturbance (CPP-DSMV, §2.1 and §2.3).

use std::path::Path;

use super::edt::{dilate_disc, distance_transform, DistanceField};
use super::spec::{invalid, SyntheticSeabed, TerrainSpec, TraversalLimits};
use super::terrain25_error::{Terrain25Error, MAX_CELLS};
use crate::terrain::{HeightGrid, TerrainError};

/// Where the minor undulation comes from.
#[derive(Debug, Clone, PartialEq)]
enum Undulation {
    /// A measured grid: not separated from the relief; reads as 0.
    Unknown,
    /// The Perlin part of a synthetic seabed, evaluated exactly (not from the grid).
    Synthetic(Box<SyntheticSeabed>),
}

/// The 2.5D constraint map (CPP-DSMV, §2.1). Built once; every field is derived from the
/// elevation, so the fields are read through accessors and cannot drift apart.
#[derive(Debug, Clone, PartialEq)]
pub struct TerrainMap25 {
    cell_m: f64,
    nx: usize,
    ny: usize,
    origin: [f64; 2],
    limits: TraversalLimits,
    elevation: Vec<f64>,
    slope_deg: Vec<f64>,
    impassable: Vec<bool>,
    no_go: Vec<bool>,
    /// EDT of `impassable`, squared, in cells², with the nearest impassable cell.
    distance: DistanceField,
    undulation: Undulation,
}

/// Lower node index along one axis, fraction in its cell, clamped to the grid (as
/// [`HeightGrid`] does); `n ≥ 2`.
fn locate(coord: f64, origin: f64, cell: f64, n: usize) -> (usize, f64) {
    let max = (n - 1) as f64;
    let f = ((coord - origin) / cell).clamp(0.0, max);
    let f = if f.is_nan() { 0.0 } else { f };
    let i = (f.floor() as usize).min(n - 2);
    (i, f - i as f64)
}

/// Slope field (degrees) of a row-major `nx × ny` height array, equations 1–2 of the module doc.
/// Needs `nx, ny ≥ 2` and `heights.len() = nx·ny` (missing values read as NaN).
pub fn slope_field_deg(heights: &[f64], nx: usize, ny: usize, cell_m: f64) -> Vec<f64> {
    let z = |i: usize, j: usize| heights.get(j * nx + i).copied().unwrap_or(f64::NAN);
    // Difference along one axis at index k of n, given the value at any index on that axis.
    let diff = |k: usize, n: usize, at: &dyn Fn(usize) -> f64| -> f64 {
        if k == 0 {
            (at(1) - at(0)) / cell_m
        } else if k == n - 1 {
            (at(n - 1) - at(n - 2)) / cell_m
        } else {
            (at(k + 1) - at(k - 1)) / (2.0 * cell_m)
        }
    };
    let mut out = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let gx = diff(i, nx, &|c| z(c, j));
            let gy = diff(j, ny, &|r| z(i, r));
            out.push(gx.hypot(gy).atan().to_degrees());
        }
    }
    out
}

impl TerrainMap25 {
    /// Samples the seabed of `spec` (drawn with `seed`, see [`TerrainSpec::seabed`]) at every
    /// cell centre and derives the map. The grid covers `size_m` rounded up to whole cells, with
    /// cell `(0, 0)` centred half a cell inside `origin_m`.
    pub fn generate(
        spec: &TerrainSpec,
        limits: &TraversalLimits,
        seed: u64,
    ) -> Result<Self, Terrain25Error> {
        limits.validate()?;
        let seabed = spec.seabed(seed)?;
        let h = spec.cell_m;
        let cells = |size: f64| (size / h - 1e-9).ceil().max(2.0);
        let (fx, fy) = (cells(spec.size_m[0]), cells(spec.size_m[1]));
        if fx * fy > MAX_CELLS as f64 {
            let (nx, ny) = (fx as usize, fy as usize); // saturating casts
            return Err(Terrain25Error::TooLarge { nx, ny });
        }
        let (nx, ny) = (fx as usize, fy as usize);
        let origin = [spec.origin_m[0] + h / 2.0, spec.origin_m[1] + h / 2.0];
        let mut elevation = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let (x, y) = (origin[0] + i as f64 * h, origin[1] + j as f64 * h);
                elevation.push(seabed.elevation(x, y));
            }
        }
        let undulation = Undulation::Synthetic(Box::new(seabed));
        Self::assemble(origin, h, nx, ny, elevation, *limits, undulation)
    }

    /// The map of a measured height grid (nodes become cell centres). A measured grid does not
    /// separate the undulation from the relief: [`Self::undulation_at`] reads 0 on it.
    pub fn from_grid(grid: &HeightGrid, limits: &TraversalLimits) -> Result<Self, Terrain25Error> {
        limits.validate()?;
        let (nx, ny) = (grid.cols, grid.rows);
        if nx.saturating_mul(ny) > MAX_CELLS {
            return Err(Terrain25Error::TooLarge { nx, ny });
        }
        let mut elevation = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let z = grid.node(i, j).ok_or_else(|| {
                    invalid("grid", format!("node ({i}, {j}) missing from {nx} × {ny}"))
                })?;
                elevation.push(z);
            }
        }
        let und = Undulation::Unknown;
        Self::assemble(grid.origin, grid.cell_m, nx, ny, elevation, *limits, und)
    }

    /// [`HeightGrid::load`] (`.asc` or `.csv`) then [`Self::from_grid`].
    pub fn load(path: &Path, limits: &TraversalLimits) -> Result<Self, Terrain25Error> {
        Self::from_grid(&HeightGrid::load(path)?, limits)
    }

    /// Derives slope, obstacles, distance and no-go from the elevation (equations 1–5).
    fn assemble(
        origin: [f64; 2],
        cell_m: f64,
        nx: usize,
        ny: usize,
        elevation: Vec<f64>,
        limits: TraversalLimits,
        undulation: Undulation,
    ) -> Result<Self, Terrain25Error> {
        // The checks of `HeightGrid::new`, so that every map is also a valid height grid.
        if nx < 2 || ny < 2 {
            return Err(invalid(
                "grid",
                format!("{nx} × {ny} cells, need at least 2 × 2"),
            ));
        }
        if !(cell_m.is_finite() && cell_m > 0.0 && origin.iter().all(|v| v.is_finite())) {
            let what = format!("cell {cell_m} m and origin {origin:?} must be finite, cell > 0");
            return Err(invalid("grid", what));
        }
        if elevation.len() != nx * ny || !elevation.iter().all(|z| z.is_finite()) {
            return Err(invalid("elevation", "missing or non-finite heights".into()));
        }
        let slope_deg = slope_field_deg(&elevation, nx, ny, cell_m);
        let impassable = slope_deg
            .iter()
            .map(|&s| s > limits.critical_slope_deg)
            .collect();
        Ok(Self::from_obstacles(
            origin, cell_m, nx, ny, elevation, slope_deg, impassable, limits, undulation,
        ))
    }

    /// Distance transform and dilation of a given obstacle mask.
    #[allow(clippy::too_many_arguments)]
    fn from_obstacles(
        origin: [f64; 2],
        cell_m: f64,
        nx: usize,
        ny: usize,
        elevation: Vec<f64>,
        slope_deg: Vec<f64>,
        impassable: Vec<bool>,
        limits: TraversalLimits,
        undulation: Undulation,
    ) -> Self {
        let distance = distance_transform(&impassable, nx, ny);
        let no_go = dilate_disc(&distance, limits.dilation_radius_m() / cell_m);
        Self {
            cell_m,
            nx,
            ny,
            origin,
            limits,
            elevation,
            slope_deg,
            impassable,
            no_go,
            distance,
            undulation,
        }
    }

    /// Cell size `h`, metres.
    pub fn cell_m(&self) -> f64 {
        self.cell_m
    }

    /// Cells along x.
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Cells along y.
    pub fn ny(&self) -> usize {
        self.ny
    }

    /// Centre of cell (0, 0), metres.
    pub fn origin(&self) -> [f64; 2] {
        self.origin
    }

    /// The limits the map was built with.
    pub fn limits(&self) -> &TraversalLimits {
        &self.limits
    }

    /// Elevation at cell centres, row-major, south row first, metres.
    pub fn elevation(&self) -> &[f64] {
        &self.elevation
    }

    /// Slope `θ` at cell centres, degrees.
    pub fn slope_deg(&self) -> &[f64] {
        &self.slope_deg
    }

    /// `θ > θ_crit` per cell.
    pub fn impassable(&self) -> &[bool] {
        &self.impassable
    }

    /// Impassable dilated by `W_veh / 2` per cell.
    pub fn no_go(&self) -> &[bool] {
        &self.no_go
    }

    /// The seamounts and trenches of a generated map (`None` for a measured grid).
    pub fn seabed(&self) -> Option<&SyntheticSeabed> {
        match &self.undulation {
            Undulation::Synthetic(seabed) => Some(seabed),
            Undulation::Unknown => None,
        }
    }

    /// Row-major index of cell `(i, j)`, if it exists.
    pub fn index(&self, i: usize, j: usize) -> Option<usize> {
        (i < self.nx && j < self.ny).then(|| j * self.nx + i)
    }

    /// Centre of cell `(i, j)`, metres (not checked against the grid size).
    pub fn cell_centre(&self, i: usize, j: usize) -> [f64; 2] {
        [
            self.origin[0] + i as f64 * self.cell_m,
            self.origin[1] + j as f64 * self.cell_m,
        ]
    }

    /// The cell whose square contains `(x, y)` (nearest centre), `None` off the map.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        let fi = ((x - self.origin[0]) / self.cell_m).round();
        let fj = ((y - self.origin[1]) / self.cell_m).round();
        let inside = |f: f64, n: usize| f >= 0.0 && f < n as f64;
        (inside(fi, self.nx) && inside(fj, self.ny)).then_some((fi as usize, fj as usize))
    }

    /// Bilinear interpolation of a per-cell field between centres, clamped at the edges.
    fn bilinear(&self, values: &[f64], x: f64, y: f64) -> f64 {
        let (i, tx) = locate(x, self.origin[0], self.cell_m, self.nx);
        let (j, ty) = locate(y, self.origin[1], self.cell_m, self.ny);
        let at = |c: usize, r: usize| values.get(r * self.nx + c).copied().unwrap_or(f64::NAN);
        let south = at(i, j) + (at(i + 1, j) - at(i, j)) * tx;
        let north = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * tx;
        south + (north - south) * ty
    }

    /// Bilinear elevation, clamped to the edge outside the map (as [`HeightGrid::elevation`]).
    pub fn elevation_at(&self, x: f64, y: f64) -> f64 {
        self.bilinear(&self.elevation, x, y)
    }

    /// Bilinear interpolation of the cell slopes, degrees.
    pub fn slope_at(&self, x: f64, y: f64) -> f64 {
        self.bilinear(&self.slope_deg, x, y)
    }

    /// The minor undulation `U(x, y)`, metres: exact Perlin sum of a generated map, 0 on a
    /// measured grid. Not clamped to the map.
    pub fn undulation_at(&self, x: f64, y: f64) -> f64 {
        self.undulation_gradient_at(x, y).0
    }

    /// `U(x, y)` and its exact gradient `∇U` (m/m), from which a tracking layer gets the
    /// disturbance pitch `atan(∇U · (cos ψ, sin ψ))` and roll `atan(∇U · (−sin ψ, cos ψ))` at
    /// heading ψ.
    pub fn undulation_gradient_at(&self, x: f64, y: f64) -> (f64, [f64; 2]) {
        match &self.undulation {
            Undulation::Synthetic(seabed) => seabed.undulation.value_and_gradient(x, y),
            Undulation::Unknown => (0.0, [0.0, 0.0]),
        }
    }

    /// Whether the cell containing `(x, y)` is no-go; everything off the map is no-go.
    pub fn is_no_go(&self, x: f64, y: f64) -> bool {
        self.cell_of(x, y)
            .and_then(|(i, j)| self.index(i, j))
            .is_none_or(|k| self.no_go.get(k).copied().unwrap_or(true))
    }

    /// Whether the cell containing `(x, y)` is impassable (off the map: `false`, it is unknown).
    pub fn is_impassable(&self, x: f64, y: f64) -> bool {
        self.cell_of(x, y)
            .and_then(|(i, j)| self.index(i, j))
            .is_some_and(|k| self.impassable.get(k).copied().unwrap_or(false))
    }

    /// Exact distance from the centre of cell `(i, j)` to the nearest impassable cell centre,
    /// metres (`+∞` without any impassable cell or outside the grid).
    pub fn cell_clearance(&self, i: usize, j: usize) -> f64 {
        self.index(i, j)
            .and_then(|k| self.distance.squared.get(k))
            .map_or(f64::INFINITY, |d2| d2.sqrt() * self.cell_m)
    }

    /// Distance from `(x, y)` to the nearest impassable cell centre, metres (`+∞` without any).
    ///
    /// From the feature transform computed once: the nearest impassable cells of the (up to) four
    /// cell centres around `(x, y)` are candidates, and the distance to the closest of them is
    /// returned. Exact at cell centres; elsewhere an upper bound that is exact unless the true
    /// nearest obstacle is nobody's nearest among those four centres (error then < √2·h).
    pub fn clearance_to_impassable(&self, x: f64, y: f64) -> f64 {
        let (i, _) = locate(x, self.origin[0], self.cell_m, self.nx);
        let (j, _) = locate(y, self.origin[1], self.cell_m, self.ny);
        let mut best = f64::INFINITY;
        for (c, r) in [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)] {
            let site = self
                .index(c, r)
                .and_then(|k| self.distance.nearest.get(k))
                .copied()
                .unwrap_or(usize::MAX);
            if site != usize::MAX {
                let [sx, sy] = self.cell_centre(site % self.nx, site / self.nx);
                best = best.min((x - sx).hypot(y - sy));
            }
        }
        best
    }

    /// Share of impassable cells, in [0, 1].
    pub fn impassable_fraction(&self) -> f64 {
        fraction(&self.impassable)
    }

    /// Share of no-go cells, in [0, 1].
    pub fn no_go_fraction(&self) -> f64 {
        fraction(&self.no_go)
    }

    /// The elevation as a [`HeightGrid`], e.g. for [`crate::terrain::Terrain::Grid`].
    pub fn to_height_grid(&self) -> Result<HeightGrid, TerrainError> {
        let (o, h, nx, ny) = (self.origin, self.cell_m, self.nx, self.ny);
        HeightGrid::new(o, h, nx, ny, self.elevation.clone())
    }
}

/// Share of `true` in `mask` (0 when empty).
fn fraction(mask: &[bool]) -> f64 {
    if mask.is_empty() {
        return 0.0;
    }
    mask.iter().filter(|&&b| b).count() as f64 / mask.len() as f64
}

#[cfg(test)]
mod tests;
