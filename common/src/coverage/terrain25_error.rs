//! Why a 2.5D terrain map could not be built, apart from the map itself so that the spec, the
//! map and the coverage planners share it without depending on each other.

use crate::terrain::TerrainError;

/// Why a 2.5D map could not be built.
#[derive(Debug, thiserror::Error)]
pub enum Terrain25Error {
    /// A field of [`TerrainSpec`](super::TerrainSpec) or
    /// [`TraversalLimits`](super::TraversalLimits) is out of range.
    #[error("terrain spec: `{field}`: {what}")]
    InvalidSpec {
        /// The field, as the scenario names it.
        field: String,
        /// What is wrong with its value.
        what: String,
    },
    /// A coverage-planner setting is out of range.
    #[error("coverage settings: `{field}`: {what}")]
    InvalidParam {
        /// The setting, as the scenario names it.
        field: String,
        /// What is wrong with its value.
        what: String,
    },
    /// The map would have more than [`MAX_CELLS`] cells.
    #[error("a {nx} × {ny} cell map exceeds the {MAX_CELLS} cell limit")]
    TooLarge {
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
    },
    /// The height grid could not be read or built.
    #[error(transparent)]
    Grid(#[from] TerrainError),
}

/// Largest map accepted ([`crate::limits::MAX_MAP_CELLS`]; the map keeps about 34 bytes per cell).
pub const MAX_CELLS: usize = crate::limits::MAX_MAP_CELLS;
