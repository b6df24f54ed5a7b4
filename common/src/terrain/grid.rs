//! Measured seabed: a height grid from a CSV file or an ESRI ASCII grid, with errors that name
//! the file, the line and the offending text.

use std::path::{Path, PathBuf};

/// Why a height grid could not be built.
#[derive(Debug, thiserror::Error)]
pub enum TerrainError {
    /// The file could not be read.
    /// The reason is in the message, not a `source` (a chained report would print it twice).
    #[error("{}: cannot read: {error}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
    },
    /// [`HeightGrid::load`] does not know the extension.
    #[error("{}: unknown terrain format (expected extension .asc or .csv)", file.display())]
    UnknownFormat {
        /// The file.
        file: PathBuf,
    },
    /// A caller-supplied parameter (cell size, origin) is unusable for this file.
    #[error("{}: {what}", file.display())]
    BadParameter {
        /// The file.
        file: PathBuf,
        /// Which parameter, and why it does not fit.
        what: String,
    },
    /// [`HeightGrid::new`] was given inconsistent data.
    #[error("invalid height grid: {0}")]
    InvalidGrid(String),
    /// Something wrong at a given line (1-based) of a file.
    #[error("{}:{line}: {problem}", file.display())]
    At {
        /// The file.
        file: PathBuf,
        /// The 1-based line.
        line: usize,
        /// What is wrong there.
        problem: Problem,
    },
}

/// What is wrong at a line of a grid file; the offending text is always quoted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Problem {
    /// A row with another number of values than the first (CSV) or the header's `ncols` (ASC).
    #[error("expected {expected} values, found {found}")]
    Ragged {
        /// Values a row must have.
        expected: usize,
        /// Values on this row.
        found: usize,
    },
    /// A value that does not parse as a number (its text).
    #[error("`{0}` is not a number")]
    NotANumber(String),
    /// A value that is infinite or NaN (its text).
    #[error("`{0}` is not a finite number")]
    NonFinite(String),
    /// An ESRI ASCII grid header without this key.
    #[error("header key `{0}` is missing (the header ends before this line)")]
    MissingHeader(&'static str),
    /// An ESRI ASCII grid header line that cannot be read.
    #[error("bad header line `{text}`: {what}")]
    BadHeader {
        /// The line's text.
        text: String,
        /// What is wrong with it.
        what: &'static str,
    },
    /// Fewer or more data rows than the header's `nrows`.
    #[error("header says `nrows {expected}` but the file has {found} data rows")]
    RowCount {
        /// Rows the header announces.
        expected: usize,
        /// Rows in the file.
        found: usize,
    },
    /// Fewer than 2 × 2 heights: nothing to interpolate between.
    #[error("grid of {cols} columns × {rows} rows is too small, need at least 2×2")]
    TooSmall {
        /// Columns in the file.
        cols: usize,
        /// Rows in the file.
        rows: usize,
    },
    /// A cell size of zero or less (its text).
    #[error("cell size `{0}` must be positive")]
    NonPositiveCell(String),
    /// `row` and `col` are 1-based, data row 1 being the first (northernmost) one of the file.
    #[error("data row {row}, column {col} is NODATA (`{text}`); unmeasured seabed is not guessed")]
    NoData {
        /// The data row.
        row: usize,
        /// The column.
        col: usize,
        /// The NODATA value's text.
        text: String,
    },
}

/// Error at `file:line`.
fn at(file: &Path, line: usize, problem: Problem) -> TerrainError {
    TerrainError::At {
        file: file.to_path_buf(),
        line,
        problem,
    }
}

/// A regular grid of seabed heights, bilinearly interpolated.
///
/// Node `(col, row)` stands at `origin + (col·cell_m, row·cell_m)`; row 0 is the southernmost
/// (smallest y), col 0 the westernmost. Outside the grid the position is clamped to the edge.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightGrid {
    /// Position of node (0, 0), the south-west cell centre, metres.
    pub origin: [f64; 2],
    /// Spacing of the nodes along x and y, metres.
    pub cell_m: f64,
    /// Nodes per row (along x).
    pub cols: usize,
    /// Rows of nodes (along y).
    pub rows: usize,
    /// Heights row-major, south row first; private so its length always matches `cols × rows`.
    heights: Vec<f64>,
    /// The highest of `heights`, kept from construction: the seabed's ceiling is asked for
    /// on every fitness evaluation of an AUV over the grid.
    max_height: f64,
}

/// The "not a number" error for `text` at `file:line` (an empty field is shown as `(empty)`).
fn bad_number(file: &Path, line: usize, text: &str) -> TerrainError {
    let text = if text.is_empty() { "(empty)" } else { text };
    at(file, line, Problem::NotANumber(text.to_string()))
}

/// Parses one finite number, naming file and line otherwise.
fn parse_finite(file: &Path, line: usize, text: &str) -> Result<f64, TerrainError> {
    let value: f64 = text.parse().map_err(|_| bad_number(file, line, text))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(at(file, line, Problem::NonFinite(text.to_string())))
    }
}

/// Number of the last line of `text` (1 for an empty text), for "ended too early" errors.
fn last_line(text: &str) -> usize {
    text.lines().count().max(1)
}

/// Grid coordinate along one axis: lower node index, fraction in its cell, and whether the
/// coordinate lies inside the grid (outside, the clamped value does not change with it).
fn locate(coord: f64, origin: f64, cell: f64, nodes: usize) -> (usize, f64, bool) {
    let max = nodes.saturating_sub(1).max(1) as f64;
    let f = (coord - origin) / cell;
    let fc = f.clamp(0.0, max);
    let i = (fc.floor() as usize).min(nodes.saturating_sub(2));
    (i, fc - i as f64, (0.0..=max).contains(&f))
}

/// The highest of `heights` (−∞ for none).
fn highest(heights: &[f64]) -> f64 {
    heights.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

impl HeightGrid {
    /// Builds a grid from heights given row-major, south row first.
    pub fn new(
        origin: [f64; 2],
        cell_m: f64,
        cols: usize,
        rows: usize,
        heights: Vec<f64>,
    ) -> Result<Self, TerrainError> {
        let fail = |what: String| Err(TerrainError::InvalidGrid(what));
        if cols < 2 || rows < 2 {
            return fail(format!("{cols}×{rows} nodes, need at least 2×2"));
        }
        if cols.checked_mul(rows) != Some(heights.len()) {
            return fail(format!("{cols}×{rows} nodes but {} heights", heights.len()));
        }
        if !(cell_m.is_finite() && cell_m > 0.0) {
            return fail(format!("cell size {cell_m} must be positive and finite"));
        }
        if !origin.iter().chain(&heights).all(|v| v.is_finite()) {
            return fail("origin and heights must be finite".to_string());
        }
        let max_height = highest(&heights);
        Ok(Self {
            origin,
            cell_m,
            cols,
            rows,
            heights,
            max_height,
        })
    }

    /// Height of node `(col, row)` (row 0 = south), if it exists.
    pub fn node(&self, col: usize, row: usize) -> Option<f64> {
        if col >= self.cols {
            return None;
        }
        self.heights
            .get(row.checked_mul(self.cols)?.checked_add(col)?)
            .copied()
    }

    /// Corners of the cell containing `(x, y)` and the fractions `(tx, ty)` within it; the bool
    /// pair says whether x and y are inside the grid.
    fn patch(&self, x: f64, y: f64) -> ([f64; 4], f64, f64, bool, bool) {
        let (i, tx, in_x) = locate(x, self.origin[0], self.cell_m, self.cols);
        let (j, ty, in_y) = locate(y, self.origin[1], self.cell_m, self.rows);
        let at = |c, r| self.node(c, r).unwrap_or(f64::NAN);
        let z = [at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)];
        (z, tx, ty, in_x, in_y)
    }

    /// The highest node: no bilinear patch, and no clamped position outside the grid, is
    /// higher.
    pub fn max_height(&self) -> f64 {
        self.max_height
    }

    /// Bilinear height at `(x, y)`, clamped to the edge outside the grid.
    pub fn elevation(&self, x: f64, y: f64) -> f64 {
        let ([z00, z10, z01, z11], tx, ty, _, _) = self.patch(x, y);
        let south = z00 + (z10 - z00) * tx;
        let north = z01 + (z11 - z01) * tx;
        south + (north - south) * ty
    }

    /// Derivative of the bilinear patch; 0 along an axis where the position is clamped.
    pub fn gradient(&self, x: f64, y: f64) -> (f64, f64) {
        let ([z00, z10, z01, z11], tx, ty, in_x, in_y) = self.patch(x, y);
        let gx = ((1.0 - ty) * (z10 - z00) + ty * (z11 - z01)) / self.cell_m;
        let gy = ((1.0 - tx) * (z01 - z00) + tx * (z11 - z10)) / self.cell_m;
        (if in_x { gx } else { 0.0 }, if in_y { gy } else { 0.0 })
    }

    /// Assembles rows read north first (like an image) into a south-first grid.
    fn from_north_rows(origin: [f64; 2], cell_m: f64, cols: usize, rows: Vec<Vec<f64>>) -> Self {
        let n = rows.len();
        let heights: Vec<f64> = rows.into_iter().rev().flatten().collect();
        let max_height = highest(&heights);
        Self {
            origin,
            cell_m,
            cols,
            rows: n,
            heights,
            max_height,
        }
    }

    /// Parses a CSV height grid: comma-separated numbers, one row per line, the **first line is
    /// the northernmost row** (like an image). Blank lines and `#` comments are skipped. Node
    /// (0, 0), the south-west one, stands at `origin`; nodes are `cell_m` apart.
    pub fn from_csv(
        text: &str,
        file: &Path,
        cell_m: f64,
        origin: [f64; 2],
    ) -> Result<Self, TerrainError> {
        if !(cell_m.is_finite() && cell_m > 0.0) {
            return Err(TerrainError::BadParameter {
                file: file.to_path_buf(),
                what: format!("cell size {cell_m} must be positive and finite"),
            });
        }
        if !(origin[0].is_finite() && origin[1].is_finite()) {
            return Err(TerrainError::BadParameter {
                file: file.to_path_buf(),
                what: format!("origin {origin:?} must be finite"),
            });
        }
        let mut rows: Vec<Vec<f64>> = Vec::new();
        let mut first_line = 0;
        for (index, raw) in text.lines().enumerate() {
            let line = index + 1;
            let content = raw.split('#').next().unwrap_or("").trim();
            if content.is_empty() {
                continue;
            }
            let row = content
                .split(',')
                .map(|field| parse_finite(file, line, field.trim()))
                .collect::<Result<Vec<f64>, _>>()?;
            match rows.first() {
                None => first_line = line,
                Some(first) if first.len() != row.len() => {
                    let (expected, found) = (first.len(), row.len());
                    return Err(at(file, line, Problem::Ragged { expected, found }));
                }
                Some(_) => {}
            }
            rows.push(row);
        }
        let cols = rows.first().map_or(0, Vec::len);
        if cols < 2 || rows.len() < 2 {
            let line = if rows.is_empty() {
                last_line(text)
            } else {
                first_line
            };
            let rows = rows.len();
            return Err(at(file, line, Problem::TooSmall { cols, rows }));
        }
        Ok(Self::from_north_rows(origin, cell_m, cols, rows))
    }

    /// Parses an ESRI ASCII grid: header keys `ncols`, `nrows`, `xllcorner`|`xllcenter`,
    /// `yllcorner`|`yllcenter`, `cellsize` and optional `NODATA_value` (case-insensitive), then
    /// `nrows` lines of `ncols` whitespace-separated values, **first line = north**.
    ///
    /// A `*corner` origin is the outer corner of the south-west cell, so node (0, 0) lies half a
    /// cell inside it; a `*center` origin is node (0, 0) itself. A NODATA cell is an error: we do
    /// not guess seabed we have not measured.
    pub fn from_esri_ascii(text: &str, file: &Path) -> Result<Self, TerrainError> {
        const KEYS: [&str; 8] = [
            "ncols",
            "nrows",
            "xllcorner",
            "xllcenter",
            "yllcorner",
            "yllcenter",
            "cellsize",
            "nodata_value",
        ];
        // (value text, line) per key in KEYS order.
        let mut header: [Option<(&str, usize)>; 8] = [None; 8];
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l)).peekable();
        while let Some(&(line, raw)) = lines.peek() {
            let mut tokens = raw.split_whitespace();
            let Some(first) = tokens.next() else {
                lines.next();
                continue;
            };
            let Some(k) = KEYS.iter().position(|key| key.eq_ignore_ascii_case(first)) else {
                break;
            };
            let text = raw.trim().to_string();
            let bad = |what| at(file, line, Problem::BadHeader { text, what });
            let (Some(value), None) = (tokens.next(), tokens.next()) else {
                return Err(bad("expected `key value`"));
            };
            if header[k].is_some() {
                return Err(bad("key given twice"));
            }
            header[k] = Some((value, line));
            lines.next();
        }
        let data_line = lines.peek().map_or(last_line(text), |&(line, _)| line);
        let require = |k: usize, alt: Option<usize>| {
            header[k]
                .or_else(|| alt.and_then(|a| header[a]))
                .ok_or_else(|| at(file, data_line, Problem::MissingHeader(KEYS[k])))
        };
        let count = |(text, line): (&str, usize)| {
            text.parse::<usize>()
                .map_err(|_| bad_number(file, line, text))
        };
        let ncols_at = require(0, None)?;
        let nrows_at = require(1, None)?;
        let (ncols, nrows) = (count(ncols_at)?, count(nrows_at)?);
        for (n, line) in [(ncols, ncols_at.1), (nrows, nrows_at.1)] {
            if n < 2 {
                let (cols, rows) = (ncols, nrows);
                return Err(at(file, line, Problem::TooSmall { cols, rows }));
            }
        }
        for (corner, centre) in [(2, 3), (4, 5)] {
            if let (Some(_), Some((_, line))) = (header[corner], header[centre]) {
                let text = KEYS[centre].to_string();
                let what = "give either the corner or the centre of an axis, not both";
                return Err(at(file, line, Problem::BadHeader { text, what }));
            }
        }
        let number = |(text, line): (&str, usize)| parse_finite(file, line, text);
        let cell_at = require(6, None)?;
        let cell = number(cell_at)?;
        if cell <= 0.0 {
            let problem = Problem::NonPositiveCell(cell_at.0.to_string());
            return Err(at(file, cell_at.1, problem));
        }
        let half = |corner: bool| if corner { cell / 2.0 } else { 0.0 };
        let origin = [
            number(require(2, Some(3))?)? + half(header[2].is_some()),
            number(require(4, Some(5))?)? + half(header[4].is_some()),
        ];
        let nodata = header[7].map(number).transpose()?;
        let data: Vec<(usize, &str)> = lines.filter(|(_, l)| !l.trim().is_empty()).collect();
        if data.len() != nrows {
            let line = data.get(nrows).map_or(last_line(text), |d| d.0);
            let (expected, found) = (nrows, data.len());
            return Err(at(file, line, Problem::RowCount { expected, found }));
        }
        let mut rows: Vec<Vec<f64>> = Vec::with_capacity(nrows);
        for (line, raw) in data {
            let fields: Vec<&str> = raw.split_whitespace().collect();
            if fields.len() != ncols {
                let (expected, found) = (ncols, fields.len());
                return Err(at(file, line, Problem::Ragged { expected, found }));
            }
            let mut row = Vec::with_capacity(ncols);
            for (col, field) in fields.iter().enumerate() {
                let value: f64 = field.parse().map_err(|_| bad_number(file, line, field))?;
                if nodata == Some(value) {
                    let (row, col, text) = (rows.len() + 1, col + 1, field.to_string());
                    return Err(at(file, line, Problem::NoData { row, col, text }));
                }
                row.push(parse_finite(file, line, field)?);
            }
            rows.push(row);
        }
        Ok(Self::from_north_rows(origin, cell, ncols, rows))
    }

    /// Reads a grid file, choosing the parser by extension (case-insensitive): `.asc` → ESRI
    /// ASCII; `.csv` → CSV with 1 m cells and node (0, 0) at the origin (0, 0).
    pub fn load(path: &Path) -> Result<Self, TerrainError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let parse: fn(&str, &Path) -> Result<Self, TerrainError> = match ext.as_deref() {
            Some("asc") => Self::from_esri_ascii,
            Some("csv") => |text, file| Self::from_csv(text, file, 1.0, [0.0, 0.0]),
            _ => {
                return Err(TerrainError::UnknownFormat {
                    file: path.to_path_buf(),
                })
            }
        };
        let text = std::fs::read_to_string(path).map_err(|error| TerrainError::Io {
            file: path.to_path_buf(),
            error,
        })?;
        parse(&text, path)
    }
}

#[cfg(test)]
mod tests;
