//! What the benchmark-function suite measured, apart from how it ran: the report the
//! command prints and the Markdown table renders.

/// Share of the iterations at the end of a run [`still_improving`](super::still_improving) looks at.
pub const LATE_SHARE: f64 = 0.1;

/// Follower populations of the multi-population solvers in this suite.
pub const MULTI_POPULATIONS: usize = 5;

/// One (function, algorithm) cell: the best cost of every finished run, in run order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Cell {
    /// Best cost of each run.
    pub values: Vec<f64>,
    /// Evaluations of each run.
    pub evaluations: Vec<u64>,
    /// Whether each run was still improving when its budget ended ([`still_improving`](super::still_improving)).
    pub still_improving: Vec<bool>,
}

/// A function of the suite as the report shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct FunctionInfo {
    /// Command-line key.
    pub key: String,
    /// `f1`…`f12`, `F6`.
    pub label: String,
    /// Display name.
    pub name: String,
    /// Dimensions.
    pub dim: usize,
    /// Known optimum f*.
    pub optimum: f64,
    /// One of f1–f8, whose dimension is `--dim` (the others have a fixed one).
    pub scalable: bool,
}

/// Everything the suite measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The command's settings.
    pub runs: usize,
    /// Particles M.
    pub particles: usize,
    /// Iterations t_max.
    pub iterations: usize,
    /// Base seed.
    pub seed: u64,
    /// Velocity cap given to every solver (`None`: each solver's own).
    pub velocity_cap: Option<f64>,
    /// Functions, in table order.
    pub functions: Vec<FunctionInfo>,
    /// Algorithm names, in table order.
    pub algorithms: Vec<&'static str>,
    /// The algorithms' settings, for the legend.
    pub about: Vec<&'static str>,
    /// `cells[function][algorithm]`.
    pub cells: Vec<Vec<Cell>>,
    /// False if the run was interrupted before every run finished.
    pub complete: bool,
}

impl Report {
    /// The cell of function `key` and algorithm `name`.
    pub fn cell(&self, key: &str, name: &str) -> Option<&Cell> {
        let f = self.functions.iter().position(|f| f.key == key)?;
        let a = self.algorithms.iter().position(|a| *a == name)?;
        self.cells.get(f)?.get(a)
    }
}
