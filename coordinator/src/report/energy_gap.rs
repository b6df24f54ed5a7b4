//! How far an energy plan is from the cheapest path a grid search finds in the same water
//! ([`shoal_common::energy::reference`]: eq. (6)'s length and energy terms), or, for Zhang et
//! al. 2022's length baseline, from the shortest admissible one: the yardstick the plan states
//! next to its own figures.

use shoal_common::energy::problem::{EnergyProblem, Objective};
use shoal_common::energy::reference::{measure, reference};
use shoal_common::energy::EnergyTerms;
use shoal_common::swarm::Problem;

use super::crawler_gap::gap_percent;

/// Lattice cells along the longest side of the bounds: 25 gives a 4 m cell on Zhang et al.'s
/// 100 m cube (17 576 points, 1.6 M states with their headings).
const CELLS_ALONG: f64 = 25.0;

/// The finest cell the reference uses, metres.
const MIN_CELL_M: f64 = 1.0;

/// The notice for the plan of `problem` whose figures are `terms`.
pub fn notice(id: &str, problem: &EnergyProblem, terms: &EnergyTerms) -> String {
    let (lo, hi) = (problem.lower(), problem.upper());
    let side = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    let cell = (side / CELLS_ALONG).max(MIN_CELL_M);
    let Some(r) = reference(problem, cell) else {
        return format!(
            "{id}: no admissible path on a {cell:.1} m lattice within the pitch limits, the \
             seabed clearance and the hard obstacles, so no reference to measure the plan against"
        );
    };
    let planned = measure(problem, terms.q_path, terms.q_e);
    let gap = gap_percent(planned, r.cost.max(f64::MIN_POSITIVE));
    match problem.objective {
        Objective::Length => format!(
            "{id}: length {:.1} m, {gap:+.2} % against the shortest path a grid search finds \
             within the same limits, turning radius included ({:.1} m on a {cell:.1} m lattice, \
             string-pulled)",
            terms.q_path, r.length_m
        ),
        Objective::Full => format!(
            "{id}: length and energy {planned:.4} (eq. (6)'s terms at their initial weights: \
             {:.1} m, {:.0} J), {gap:+.2} % against the cheapest path a grid search finds in the \
             same water within the same limits, turning radius included ({:.4}: {:.1} m, {:.0} J \
             on a {cell:.1} m lattice, string-pulled)",
            terms.q_path, terms.q_e, r.cost, r.length_m, r.energy_j
        ),
    }
}
