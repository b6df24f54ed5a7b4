//! The checker's own reading of a measured seabed (`[seabed.grid]`): an ESRI ASCII grid
//! (`.asc`) or a CSV of heights (`.csv`), both written north row first, bilinear between the
//! nodes and clamped to the edge outside them, as the README's scenario format describes. It
//! shares no code with the planner's reader, so a misplaced node or a flipped row shows up as a
//! crawler "leaving the seabed" or a wrong seabed clearance.

use std::path::{Path, PathBuf};

use serde::Deserialize;

/// `[seabed.grid]` as the checker reads it.
#[derive(Debug, Clone, Deserialize)]
pub struct GridRef {
    /// The file, relative to the scenario file's directory.
    pub file: PathBuf,
    /// CSV only: node spacing, metres (default 1).
    #[serde(default)]
    pub cell_m: Option<f64>,
    /// CSV only: position of the south-west node, metres (default the origin).
    #[serde(default)]
    pub origin: Option<[f64; 2]>,
}

/// Heights on a regular lattice: node `(i, j)` at `(x0 + i·cell, y0 + j·cell)`, `j = 0` south.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    x0: f64,
    y0: f64,
    cell: f64,
    cols: usize,
    rows: usize,
    /// Row-major, south row first.
    heights: Vec<f64>,
}

impl Grid {
    /// Reads the file `g` names, relative to `dir`.
    pub fn load(g: &GridRef, dir: &Path) -> Result<Grid, String> {
        let path = dir.join(&g.file);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        let csv = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        let grid = if csv {
            Grid::csv(
                &text,
                g.cell_m.unwrap_or(1.0),
                g.origin.unwrap_or([0.0, 0.0]),
            )
        } else {
            Grid::esri(&text)
        };
        grid.map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Builds a grid from rows given north first.
    fn from_north_rows(x0: f64, y0: f64, cell: f64, north: Vec<Vec<f64>>) -> Result<Grid, String> {
        let cols = north.first().map_or(0, Vec::len);
        if cols == 0 || north.iter().any(|r| r.len() != cols) {
            return Err("rows are empty or of unequal length".into());
        }
        let rows = north.len();
        let heights = north.into_iter().rev().flatten().collect();
        Ok(Grid {
            x0,
            y0,
            cell,
            cols,
            rows,
            heights,
        })
    }

    /// CSV: comma-separated heights, one row per line, north first; blank and `#` lines skipped.
    pub fn csv(text: &str, cell: f64, origin: [f64; 2]) -> Result<Grid, String> {
        let mut north = Vec::new();
        for line in text.lines().map(str::trim) {
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let row: Result<Vec<f64>, _> = line.split(',').map(|v| v.trim().parse()).collect();
            north.push(row.map_err(|e| format!("{line:?}: {e}"))?);
        }
        Grid::from_north_rows(origin[0], origin[1], cell, north)
    }

    /// ESRI ASCII grid: `ncols`, `nrows`, `xllcorner`|`xllcenter`, `yllcorner`|`yllcenter`,
    /// `cellsize`, optional `nodata_value`, then the heights, north row first. A corner origin is
    /// the outer corner of the south-west cell, whose node is half a cell inside it.
    pub fn esri(text: &str) -> Result<Grid, String> {
        let mut words = text.split_whitespace().peekable();
        let mut header = std::collections::HashMap::new();
        while let Some(w) = words.peek() {
            if w.parse::<f64>().is_ok() {
                break;
            }
            let key = w.to_ascii_lowercase();
            words.next();
            let value: f64 = words
                .next()
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("header {key} has no number"))?;
            header.insert(key, value);
        }
        let get = |k: &str| header.get(k).copied();
        let need = |k: &str| get(k).ok_or_else(|| format!("header {k} is missing"));
        let (cols, rows, cell) = (
            need("ncols")? as usize,
            need("nrows")? as usize,
            need("cellsize")?,
        );
        let centre = |axis: &str| match (
            get(&format!("{axis}llcenter")),
            get(&format!("{axis}llcorner")),
        ) {
            (Some(c), _) => Ok(c),
            (None, Some(c)) => Ok(c + cell / 2.0),
            (None, None) => Err(format!("header {axis}llcorner is missing")),
        };
        let (x0, y0) = (centre("x")?, centre("y")?);
        let values: Result<Vec<f64>, _> = words.map(str::parse::<f64>).collect();
        let values = values.map_err(|e| format!("a height is not a number: {e}"))?;
        if values.len() != cols * rows {
            return Err(format!(
                "{} heights for {cols} × {rows} nodes",
                values.len()
            ));
        }
        if let Some(nodata) = get("nodata_value") {
            if values.contains(&nodata) {
                return Err("a NODATA node".into());
            }
        }
        let north = values.chunks(cols).map(<[f64]>::to_vec).collect();
        Grid::from_north_rows(x0, y0, cell, north)
    }

    /// Node height, `j = 0` south.
    fn node(&self, i: usize, j: usize) -> f64 {
        self.heights[j * self.cols + i]
    }

    /// Bilinear height at `(x, y)`, the position clamped to the lattice outside it.
    pub fn z(&self, x: f64, y: f64) -> f64 {
        // Lower node index and fraction along one axis.
        let axis = |v: f64, v0: f64, n: usize| -> (usize, f64) {
            let u = ((v - v0) / self.cell).clamp(0.0, (n - 1) as f64);
            let i = (u.floor() as usize).min(n.saturating_sub(2));
            (i, if n > 1 { u - i as f64 } else { 0.0 })
        };
        let (i, fx) = axis(x, self.x0, self.cols);
        let (j, fy) = axis(y, self.y0, self.rows);
        let (i1, j1) = ((i + 1).min(self.cols - 1), (j + 1).min(self.rows - 1));
        let south = self.node(i, j) * (1.0 - fx) + self.node(i1, j) * fx;
        let north = self.node(i, j1) * (1.0 - fx) + self.node(i1, j1) * fx;
        south * (1.0 - fy) + north * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ESRI: &str =
        "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 10\nNODATA_value -9999\n\
                        4 5 6\n1 2 3\n";

    #[test]
    fn an_esri_grid_is_read_north_first_with_nodes_half_a_cell_in() -> Result<(), String> {
        let g = Grid::esri(ESRI)?;
        // Nodes at x = 5, 15, 25 and y = 5 (south row 1 2 3), 15 (north row 4 5 6).
        assert!((g.z(5.0, 5.0) - 1.0).abs() < 1e-12);
        assert!((g.z(25.0, 15.0) - 6.0).abs() < 1e-12);
        // Bilinear: halfway between 1, 2, 4, 5 is 3.
        assert!((g.z(10.0, 10.0) - 3.0).abs() < 1e-12);
        // Clamped: west of the first column and south of the first row is node (0, 0).
        assert!((g.z(-100.0, -100.0) - 1.0).abs() < 1e-12);
        // x clamped to 25 (column 3), y = 12.5: 3 + 0.75·(6 − 3).
        assert!((g.z(40.0, 12.5) - 5.25).abs() < 1e-12);
        Ok(())
    }

    #[test]
    fn a_csv_grid_is_placed_by_its_origin_and_cell() -> Result<(), String> {
        let g = Grid::csv("# north\n4,5,6\n\n1,2,3\n", 2.0, [100.0, 50.0])?;
        assert!((g.z(100.0, 50.0) - 1.0).abs() < 1e-12);
        assert!((g.z(104.0, 52.0) - 6.0).abs() < 1e-12);
        assert!((g.z(101.0, 51.0) - 3.0).abs() < 1e-12);
        Ok(())
    }

    #[test]
    fn a_grid_with_nodata_or_missing_heights_is_refused() {
        assert!(Grid::esri(&ESRI.replace("4 5 6", "4 -9999 6")).is_err());
        assert!(Grid::esri(&ESRI.replace("4 5 6", "4 5")).is_err());
        assert!(Grid::csv("1,2\n3\n", 1.0, [0.0, 0.0]).is_err());
    }
}
