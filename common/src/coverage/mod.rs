//! Coverage path planning for deep-sea mining crawlers (CPP-DSMV): the first slice, the 2.5D
//! terrain map of §2.1.
//!
//! CPP-DSMV plans in three layers: (1) perception and pre-processing, which turns the 3D seabed
//! into 2.5D kinematic constraints; (2) a Boustrophedon state machine (Straight / Detour / U-turn)
//! with virtual boundaries and analytic arc smoothing, rows `2·R_min` apart; (3) closed-loop
//! tracking (terrain-adaptive EKF and variable-weight MPC) under terrain disturbances. This module
//! holds layer 1:
//!
//! - [`spec`]: the seeded synthetic seabed (Perlin undulation + Gaussian seamounts and trenches,
//!   §2.1 and §3) and the crawler's [`TraversalLimits`] (critical slope, width);
//! - [`perlin`]: Ken Perlin's improved gradient noise with a seeded permutation;
//! - [`edt`]: the exact Euclidean distance transform used for the disc dilation and clearances;
//! - [`terrain25`]: [`TerrainMap25`], slope → impassable → no-go, with clearance queries and the
//!   undulation kept separately for the tracking layer.
//!
//! Frame: x east, y north, z up, metres, as in [`crate::terrain`].

pub mod arcs;
pub mod boustrophedon;
pub mod boxes;
pub mod drive;
pub mod dubins;
pub mod edt;
pub mod fleet;
pub mod hybrid_astar;
pub mod hybrid_detour;
pub mod metrics;
pub mod mission;
pub mod params;
pub mod path;
pub mod perlin;
pub mod reach;
pub mod reroute;
pub mod rows;
pub mod spec;
pub mod sweeps;
pub mod terrain25;
mod terrain25_error;
pub mod tracking;

pub use perlin::{FractalNoise, Perlin};
pub use spec::{
    GaussianPeak, GaussianPit, RandomGaussians, SyntheticSeabed, TerrainSpec, TraversalLimits,
    UndulationSpec,
};
pub use terrain25::{slope_field_deg, TerrainMap25};
pub use terrain25_error::{Terrain25Error, MAX_CELLS};

/// Test maps: an `n × n` grid of 2 m cells from row-major heights (south row first), with the
/// default limits.
#[cfg(test)]
pub(crate) fn test_map(n: usize, z: Vec<f64>) -> TerrainMap25 {
    let grid = match crate::terrain::HeightGrid::new([0.0, 0.0], 2.0, n, n, z) {
        Ok(g) => g,
        Err(e) => panic!("test grid: {e}"),
    };
    match TerrainMap25::from_grid(&grid, &TraversalLimits::default()) {
        Ok(map) => map,
        Err(e) => panic!("test map: {e}"),
    }
}
