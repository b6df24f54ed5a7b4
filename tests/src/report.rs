//! What the checker found: the recomputed figures, the figures `plan.json` reports differently
//! (mismatches) and the rules it breaks (failures).

use std::fmt;

use crate::figures::{FleetFigures, VehicleFigures};

/// What the checker found.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// Recomputed per-vehicle figures, scenario order (vehicles missing from the plan skipped).
    pub vehicles: Vec<VehicleFigures>,
    /// Recomputed fleet figures.
    pub fleet: FleetFigures,
    /// Figures where `plan.json` disagrees with the recomputation.
    pub mismatches: Vec<String>,
    /// Broken contract rules and constraints (start/goal, timing, speeds, `feasible` claims).
    pub failures: Vec<String>,
}

impl Report {
    /// True when the plan's figures agree with the recomputation and every rule holds.
    pub fn is_clean(&self) -> bool {
        self.mismatches.is_empty() && self.failures.is_empty()
    }

    /// Mismatches and failures, one line each.
    pub fn problems(&self) -> Vec<String> {
        self.mismatches
            .iter()
            .map(|m| format!("mismatch: {m}"))
            .chain(self.failures.iter().map(|f| format!("failure: {f}")))
            .collect()
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_clean() {
            return write!(f, "plan.json is consistent");
        }
        for line in self.problems() {
            writeln!(f, "{line}")?;
        }
        Ok(())
    }
}
