//! A gridded ocean current read from a file (a forecast or a measured field), interpolated
//! trilinearly; errors name the file, the line and the offending text.
//!
//! # File format
//!
//! CSV, one line per grid node, with the header `x,y,z,u,v,w`:
//!
//! ```text
//! # Tidal current over the survey box; x east, y north, z up (metres), u v w in m/s.
//! x,y,z,u,v,w
//! 0,0,-50,0.10,-0.20,0.0
//! 100,0,-50,0.12,-0.21,0.0
//! 0,100,-50,0.09,-0.18,0.0
//! 100,100,-50,0.11,-0.19,0.0
//! 0,0,0,0.30,-0.50,0.0
//! 100,0,0,0.32,-0.52,0.0
//! 0,100,0,0.28,-0.47,0.0
//! 100,100,0,0.31,-0.49,0.0
//! ```
//!
//! - `x`, `y`, `z`: position of the node in the scenario's frame, metres (x east, y north, z up,
//!   the same frame as `[bounds]`); `u`, `v`, `w`: the water velocity there, m/s, east, north and
//!   up.
//! - The header is matched case-insensitively, spaces around the names are allowed. Blank lines
//!   and `#` comments (whole lines or the end of a line) are skipped; a leading UTF-8 byte-order
//!   mark is ignored.
//! - The nodes form a regular lattice: the distinct x values (and likewise y and z) must be evenly
//!   spaced (every step within 1e-6 of the mean step, relatively), and every combination of an x,
//!   a y and a z value must have exactly one line. The lines may come in any order.
//! - An axis may have a single value: the field is then constant along it (a single z plane is
//!   a depth-independent current, a single x and y a vertical profile, a single node a uniform
//!   current).
//! - Every value must be a finite number.
//!
//! Inside the lattice the velocity is interpolated trilinearly. **Outside it the position is
//! clamped to the nearest point of the lattice's box**, so the current beyond a face is the current
//! on that face (no extrapolation, and no still water either). A non-finite position gives NaN.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::current::CurrentField;
use crate::geometry::Vec3;

/// The header a current grid file must start with.
pub const HEADER: &str = "x,y,z,u,v,w";

/// Column names, in file order.
const COLUMNS: [&str; 6] = ["x", "y", "z", "u", "v", "w"];

/// Relative tolerance on the spacing of the lattice along each axis.
pub const SPACING_TOLERANCE: f64 = 1e-6;

/// Why a current grid could not be read. Every variant but [`CurrentGridError::Io`] names the
/// file and a 1-based line.
#[derive(Debug, thiserror::Error)]
pub enum CurrentGridError {
    /// The file could not be read.
    /// The reason is in the message, not a `source` (a chained report would print it twice).
    #[error("{}: cannot read: {error}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
    },
    /// The first line that is not blank or a comment is not `x,y,z,u,v,w` (`found` is empty when
    /// the file has no such line).
    #[error("{}:{line}: expected the header `{HEADER}`, found {}", file.display(), quoted(found))]
    Header {
        /// The file.
        file: PathBuf,
        /// The 1-based line blamed.
        line: usize,
        /// The line's text.
        found: String,
    },
    /// A data line without exactly six values.
    #[error("{}:{line}: expected 6 values ({HEADER}), found {found} in `{text}`", file.display())]
    FieldCount {
        /// The file.
        file: PathBuf,
        /// The 1-based line blamed.
        line: usize,
        /// Values on the line.
        found: usize,
        /// The line's text.
        text: String,
    },
    /// A value that does not parse as a number.
    #[error("{}:{line}: column `{column}`: {} is not a number", file.display(), quoted(text))]
    NotANumber {
        /// The file.
        file: PathBuf,
        /// The 1-based line blamed.
        line: usize,
        /// The column (`x`, `y`, `z`, `u`, `v` or `w`).
        column: &'static str,
        /// The value's text, as written.
        text: String,
    },
    /// A number that is infinite or NaN.
    #[error("{}:{line}: column `{column}`: `{text}` is not a finite number", file.display())]
    NonFinite {
        /// The file.
        file: PathBuf,
        /// The 1-based line blamed.
        line: usize,
        /// The column (`x`, `y`, `z`, `u`, `v` or `w`).
        column: &'static str,
        /// The value's text, as written.
        text: String,
    },
    /// A header and no data line: the grid needs at least one node (`line` is the last line).
    #[error("{}:{line}: no data lines after the header: the grid needs at least one node", file.display())]
    NoNodes {
        /// The file.
        file: PathBuf,
        /// The 1-based line blamed.
        line: usize,
    },
    /// The distinct values of one coordinate are not evenly spaced; `value` is the one blamed
    /// (the value on fewest lines, a likely typo, else the end of the first uneven step) and
    /// `line` the first line where it appears.
    #[error(
        "{}:{line}: {axis} = {value} breaks the even spacing of the {axis} values ({values}): \
         steps range from {min_step} to {max_step}, they must agree within {SPACING_TOLERANCE:e} \
         relative",
        file.display()
    )]
    Spacing {
        /// The file.
        file: PathBuf,
        /// The 1-based line blamed.
        line: usize,
        /// The coordinate (`x`, `y` or `z`).
        axis: &'static str,
        /// The value blamed.
        value: f64,
        /// The distinct values around `value`, for the message.
        values: String,
        /// Smallest step between neighbouring values.
        min_step: f64,
        /// Largest step between neighbouring values.
        max_step: f64,
    },
    /// Two lines for the same node; `line` is the later one.
    #[error(
        "{}:{line}: node x = {}, y = {}, z = {} is given twice (first at line {first_line})",
        file.display(), node[0], node[1], node[2]
    )]
    Duplicate {
        /// The file.
        file: PathBuf,
        /// The 1-based line blamed.
        line: usize,
        /// The node's x, y and z.
        node: [f64; 3],
        /// The line that gave it first.
        first_line: usize,
    },
    /// A combination of the x, y and z values with no line; `line` is the last line of the file.
    #[error(
        "{}:{line}: no line for node x = {}, y = {}, z = {} of the {} × {} × {} lattice spanned \
         by the x, y and z values ({rows} data lines for {} nodes)",
        file.display(), node[0], node[1], node[2], lattice[0], lattice[1], lattice[2],
        node_count(lattice)
    )]
    Missing {
        /// The file.
        file: PathBuf,
        /// The 1-based line blamed.
        line: usize,
        /// The missing node's x, y and z.
        node: [f64; 3],
        /// Distinct values along x, y and z.
        lattice: [usize; 3],
        /// Data lines in the file.
        rows: usize,
    },
}

/// `text` in backticks, or a word when it is empty.
fn quoted(text: &str) -> String {
    if text.is_empty() {
        "nothing (empty)".to_string()
    } else {
        format!("`{text}`")
    }
}

/// `nx·ny·nz` for messages, without overflowing.
fn node_count(lattice: &[usize; 3]) -> String {
    lattice
        .iter()
        .try_fold(1u128, |n, &k| n.checked_mul(k as u128))
        .map_or_else(|| "too many".to_string(), |n| n.to_string())
}

/// One axis of the lattice: `count` values `first + i·step`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// Smallest value, metres.
    pub first: f64,
    /// Spacing, metres (0 when the axis has a single value).
    pub step: f64,
    /// Number of distinct values (≥ 1).
    pub count: usize,
}

impl Axis {
    /// Largest value, metres.
    pub fn last(&self) -> f64 {
        self.first + self.step * self.count.saturating_sub(1) as f64
    }

    /// Lower and upper node index around `coord` and the fraction between them, clamped to the
    /// axis; a single-valued axis always gives node 0.
    fn locate(&self, coord: f64) -> (usize, usize, f64) {
        if self.count < 2 {
            return (0, 0, 0.0);
        }
        let max = (self.count - 1) as f64;
        let f = ((coord - self.first) / self.step).clamp(0.0, max);
        // NaN casts to 0; the NaN fraction then makes the result NaN.
        let i = (f.floor() as usize).min(self.count - 2);
        (i, i + 1, f - i as f64)
    }
}

/// A current field given on a regular 3-D lattice, trilinearly interpolated and clamped to the
/// lattice's box outside it (see the [module documentation](self) for the file format).
#[derive(Clone, PartialEq)]
pub struct GridCurrent {
    /// The file it was read from (for messages).
    file: PathBuf,
    /// x, y and z axes.
    axes: [Axis; 3],
    /// Velocity of node `(i, j, k)` at `i + nx·(j + ny·k)`; always `nx·ny·nz` long.
    values: Vec<Vec3>,
}

impl fmt::Debug for GridCurrent {
    /// A summary: the node values of a forecast would swamp a scenario's debug output.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("GridCurrent")
            .field("file", &self.file)
            .field("axes", &self.axes)
            .field("nodes", &self.values.len())
            .finish()
    }
}

/// One data line: its number, position and velocity.
struct Row {
    line: usize,
    xyz: [f64; 3],
    uvw: [f64; 3],
}

/// Index of `v` in the sorted distinct values `values` (`-0.0` matches `0.0`).
fn index_of(values: &[f64], v: f64) -> Option<usize> {
    let i = values.partition_point(|w| *w < v);
    (values.get(i) == Some(&v)).then_some(i)
}

impl GridCurrent {
    /// Reads a current grid file (see the [module documentation](self) for the format).
    pub fn load(path: &Path) -> Result<GridCurrent, CurrentGridError> {
        let text = std::fs::read_to_string(path).map_err(|error| CurrentGridError::Io {
            file: path.to_path_buf(),
            error,
        })?;
        GridCurrent::from_csv(&text, path)
    }

    /// Parses the text of a current grid file; `file` names it in errors.
    pub fn from_csv(text: &str, file: &Path) -> Result<GridCurrent, CurrentGridError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let rows = parse_rows(text, file)?;
        let last_line = text.lines().count().max(1);
        if rows.is_empty() {
            return Err(CurrentGridError::NoNodes {
                file: file.to_path_buf(),
                line: last_line,
            });
        }
        // Distinct sorted values per axis, then their spacing.
        let mut distinct: [Vec<f64>; 3] = Default::default();
        for (a, values) in distinct.iter_mut().enumerate() {
            values.extend(rows.iter().map(|r| r.xyz[a]));
            values.sort_by(f64::total_cmp);
            values.dedup();
        }
        let mut axes = [Axis {
            first: 0.0,
            step: 0.0,
            count: 1,
        }; 3];
        for (a, (axis, values)) in axes.iter_mut().zip(&distinct).enumerate() {
            *axis = check_spacing(values, a, &rows, file)?;
        }
        // Node index of every line; sorting them puts duplicates side by side and shows gaps.
        let mut keys: Vec<([usize; 3], usize, usize)> = Vec::with_capacity(rows.len());
        for (r, row) in rows.iter().enumerate() {
            let mut key = [0; 3];
            // z, y, x: the order the values are stored in.
            for (slot, a) in [2, 1, 0].into_iter().enumerate() {
                // Every value is in `distinct`, so this never falls back.
                key[slot] = index_of(&distinct[a], row.xyz[a]).unwrap_or(0);
            }
            keys.push((key, row.line, r));
        }
        keys.sort_unstable();
        let lattice = [axes[0].count, axes[1].count, axes[2].count];
        let node_at = |key: [usize; 3]| {
            let coord = |a: usize, i: usize| distinct[a].get(i).copied().unwrap_or(f64::NAN);
            [coord(0, key[2]), coord(1, key[1]), coord(2, key[0])]
        };
        let mut duplicate: Option<(usize, usize, [usize; 3])> = None;
        let mut missing: Option<[usize; 3]> = None;
        let mut expected = Some([0usize; 3]);
        let mut run_start_line = 0;
        for (k, &(key, line, _)) in keys.iter().enumerate() {
            if k > 0 && keys.get(k - 1).map(|p| p.0) == Some(key) {
                if duplicate.is_none_or(|(l, _, _)| line < l) {
                    duplicate = Some((line, run_start_line, key));
                }
                continue;
            }
            run_start_line = line;
            if missing.is_none() && expected != Some(key) {
                missing = expected;
            }
            expected = next_key(key, lattice);
        }
        if let Some((line, first_line, key)) = duplicate {
            return Err(CurrentGridError::Duplicate {
                file: file.to_path_buf(),
                line,
                node: node_at(key),
                first_line,
            });
        }
        if let Some(key) = missing.or(expected) {
            return Err(CurrentGridError::Missing {
                file: file.to_path_buf(),
                line: last_line,
                node: node_at(key),
                lattice,
                rows: rows.len(),
            });
        }
        // No duplicate and no gap: the lines are exactly the nodes, in storage order.
        let values = keys
            .iter()
            .filter_map(|&(_, _, r)| rows.get(r))
            .map(|row| Vec3::from(row.uvw))
            .collect();
        Ok(GridCurrent {
            file: file.to_path_buf(),
            axes,
            values,
        })
    }

    /// The file the grid was read from.
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// The x, y and z axes of the lattice.
    pub fn axes(&self) -> &[Axis; 3] {
        &self.axes
    }

    /// Smallest and largest corner of the lattice's box, metres.
    pub fn extent(&self) -> ([f64; 3], [f64; 3]) {
        let [x, y, z] = self.axes;
        ([x.first, y.first, z.first], [x.last(), y.last(), z.last()])
    }

    /// Velocity at node `(i, j, k)` (the i-th x value, j-th y value, k-th z value), if it exists.
    pub fn node(&self, i: usize, j: usize, k: usize) -> Option<Vec3> {
        let [x, y, _] = self.axes;
        if i >= x.count || j >= y.count {
            return None;
        }
        let index = k.checked_mul(y.count)?.checked_add(j)?;
        let index = index.checked_mul(x.count)?.checked_add(i)?;
        self.values.get(index).copied()
    }
}

impl CurrentField for GridCurrent {
    /// Trilinear interpolation between the eight nodes around `p`; outside the lattice, the
    /// value at the nearest point of its box.
    fn velocity(&self, p: &Vec3) -> Vec3 {
        let (i0, i1, tx) = self.axes[0].locate(p.x);
        let (j0, j1, ty) = self.axes[1].locate(p.y);
        let (k0, k1, tz) = self.axes[2].locate(p.z);
        let at = |i, j, k| self.node(i, j, k).unwrap_or_else(|| Vec3::repeat(f64::NAN));
        // This form cannot overflow between two finite values.
        let lerp = |a: Vec3, b: Vec3, t: f64| a * (1.0 - t) + b * t;
        let plane = |k| {
            let south = lerp(at(i0, j0, k), at(i1, j0, k), tx);
            let north = lerp(at(i0, j1, k), at(i1, j1, k), tx);
            lerp(south, north, ty)
        };
        lerp(plane(k0), plane(k1), tz)
    }
}

/// Reads the header and the data lines.
fn parse_rows(text: &str, file: &Path) -> Result<Vec<Row>, CurrentGridError> {
    let mut header_seen = false;
    let mut rows = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let fields: Vec<&str> = content.split(',').map(str::trim).collect();
        if !header_seen {
            let is_header = fields.len() == COLUMNS.len()
                && fields
                    .iter()
                    .zip(COLUMNS)
                    .all(|(f, c)| f.eq_ignore_ascii_case(c));
            if !is_header {
                return Err(CurrentGridError::Header {
                    file: file.to_path_buf(),
                    line,
                    found: content.to_string(),
                });
            }
            header_seen = true;
            continue;
        }
        if fields.len() != COLUMNS.len() {
            return Err(CurrentGridError::FieldCount {
                file: file.to_path_buf(),
                line,
                found: fields.len(),
                text: content.to_string(),
            });
        }
        let mut values = [0.0; 6];
        for ((slot, field), column) in values.iter_mut().zip(&fields).zip(COLUMNS) {
            let text = field.to_string();
            let v: f64 = field.parse().map_err(|_| CurrentGridError::NotANumber {
                file: file.to_path_buf(),
                line,
                column,
                text: text.clone(),
            })?;
            if !v.is_finite() {
                return Err(CurrentGridError::NonFinite {
                    file: file.to_path_buf(),
                    line,
                    column,
                    text,
                });
            }
            *slot = v;
        }
        let [x, y, z, u, v, w] = values;
        rows.push(Row {
            line,
            xyz: [x, y, z],
            uvw: [u, v, w],
        });
    }
    if !header_seen {
        return Err(CurrentGridError::Header {
            file: file.to_path_buf(),
            line: text.lines().count().max(1),
            found: String::new(),
        });
    }
    Ok(rows)
}

/// The axis of the sorted distinct `values` of coordinate `a`, or the error blaming one value.
fn check_spacing(
    values: &[f64],
    a: usize,
    rows: &[Row],
    file: &Path,
) -> Result<Axis, CurrentGridError> {
    let (Some(&first), Some(&last)) = (values.first(), values.last()) else {
        // Not reached: there is at least one row.
        return Ok(Axis {
            first: 0.0,
            step: 0.0,
            count: 1,
        });
    };
    let count = values.len();
    if count == 1 {
        return Ok(Axis {
            first,
            step: 0.0,
            count,
        });
    }
    let step = (last - first) / (count - 1) as f64;
    let steps: Vec<f64> = values.windows(2).map(|w| w[1] - w[0]).collect();
    // `step` is finite and positive where this is used, and a step between finite values is
    // never NaN.
    let uneven = |s: &f64| (s - step).abs() > SPACING_TOLERANCE * step;
    let first_bad = if step.is_finite() && step > 0.0 {
        steps.iter().position(uneven)
    } else {
        // A span too wide for f64: blame the last value.
        Some(count - 2)
    };
    let Some(first_bad) = first_bad else {
        return Ok(Axis { first, step, count });
    };
    // Lines per value: a typo makes a value that appears on fewer lines than the others.
    let mut lines_with = vec![0usize; count];
    for r in rows {
        if let Some(c) = index_of(values, r.xyz[a]).and_then(|i| lines_with.get_mut(i)) {
            *c += 1;
        }
    }
    let fewest = lines_with.iter().copied().min().unwrap_or(0);
    let most = lines_with.iter().copied().max().unwrap_or(0);
    let blamed = if fewest < most {
        lines_with.iter().position(|&c| c == fewest).unwrap_or(0)
    } else {
        first_bad + 1
    };
    let value = values.get(blamed).copied().unwrap_or(last);
    let line = rows
        .iter()
        .find(|r| r.xyz[a] == value)
        .map_or(0, |r| r.line);
    let from = blamed.saturating_sub(3);
    let to = (blamed + 4).min(count);
    let mut shown: Vec<String> = values
        .get(from..to)
        .unwrap_or_default()
        .iter()
        .map(|v| v.to_string())
        .collect();
    if from > 0 {
        shown.insert(0, "…".into());
    }
    if to < count {
        shown.push("…".into());
    }
    let min_step = steps.iter().copied().fold(f64::INFINITY, f64::min);
    let max_step = steps.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Err(CurrentGridError::Spacing {
        file: file.to_path_buf(),
        line,
        axis: COLUMNS.get(a).copied().unwrap_or("?"),
        value,
        values: shown.join(", "),
        min_step,
        max_step,
    })
}

/// The node after `key` (`[k, j, i]`, i fastest) in storage order, or `None` past the last one.
fn next_key(key: [usize; 3], lattice: [usize; 3]) -> Option<[usize; 3]> {
    let [k, j, i] = key;
    if i + 1 < lattice[0] {
        Some([k, j, i + 1])
    } else if j + 1 < lattice[1] {
        Some([k, j + 1, 0])
    } else if k + 1 < lattice[2] {
        Some([k + 1, 0, 0])
    } else {
        None
    }
}

#[cfg(test)]
mod tests;
