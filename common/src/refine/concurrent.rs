//! Refining vehicles that are far apart at the same time.
//!
//! The refinement is block coordinate descent, one vehicle at a time against the others' timed
//! trajectories. Two vehicles whose whole trajectories stay farther apart than any separation
//! row of either can see do not shape each other's programs, so their searches can run side
//! by side from the same fleet position (a Jacobi step over them instead of a Gauss–Seidel
//! one). What couples them still is the fleet's timing (the common arrival), which the merge
//! answers for: each vehicle's result is taken into the fleet in the batch's order only if the
//! true merit of the fleet with it is lower, as every step of the search is. The batches and
//! the merge depend on the fleet alone, never on the threads, so the refinement gives the same
//! plan on any machine.

use super::search::{Arena, Search};
use crate::broad_phase::{boxes_within, extent};
use crate::geometry::Vec3;
use crate::swarm::core::parallel;

/// Vehicles refined side by side at most (a constant, not the machine's cores, so the plan does
/// not depend on the machine).
pub(super) const BATCH: usize = 4;

/// Cuts `order` into batches of up to [`BATCH`] vehicles, each batch's vehicles pairwise apart
/// by at least `reach` (their boxes of `extents`, indexed by vehicle). Greedy in `order`: a
/// batch opens with the first vehicle not yet placed and takes the following ones that are
/// apart from every vehicle in it; the batches keep the order of their first vehicles, and
/// every vehicle is in exactly one.
pub(super) fn far_apart_batches(
    order: &[usize],
    extents: &[(Vec3, Vec3)],
    reach: f64,
) -> Vec<Vec<usize>> {
    let mut placed = vec![false; order.len()];
    let mut batches = Vec::new();
    for first in 0..order.len() {
        if placed[first] {
            continue;
        }
        placed[first] = true;
        let mut batch = vec![order[first]];
        for next in first + 1..order.len() {
            if batch.len() == BATCH {
                break;
            }
            let candidate = order[next];
            if placed[next] {
                continue;
            }
            let apart = batch
                .iter()
                .all(|&b| !boxes_within(&extents[b], &extents[candidate], reach));
            if apart {
                placed[next] = true;
                batch.push(candidate);
            }
        }
        batches.push(batch);
    }
    batches
}

/// Refines the vehicles of `batch` ([`Search::vehicle`]) from the current fleet position, each
/// on a copy of the search, on up to `threads` threads; then takes each one's genes into the
/// fleet, in the batch's order, where the fleet's merit gets lower with them.
pub(super) fn refine_batch<A: Arena + Sync>(search: &mut Search<A>, batch: &[usize], threads: usize)
where
    A::Eval: Send,
{
    if let [only] = batch {
        search.vehicle(*only);
        return;
    }
    let mut forks: Vec<(usize, Search<A>)> = batch.iter().map(|&i| (i, search.fork())).collect();
    parallel::for_each_mut(&mut forks, threads, |(i, fork)| fork.vehicle(*i));
    for (i, fork) in forks {
        search.evaluations += fork.evaluations;
        search.interrupted |= fork.interrupted;
        if fork.steps == 0 {
            continue;
        }
        let genes = search.arena.genes(i);
        let mut trial = search.x.clone();
        trial[genes.clone()].copy_from_slice(&fork.x[genes]);
        let merged = search.arena.evaluate_change(&search.eval, &trial, i);
        search.evaluations += 1;
        if search.arena.merit(&merged) < search.arena.merit(&search.eval) {
            search.steps += fork.steps;
            search.x = trial;
            search.eval = merged;
        }
    }
}

/// The box of every vehicle's trajectory, indexed by vehicle.
pub(super) fn trajectory_extents<A: Arena>(search: &Search<A>) -> Vec<(Vec3, Vec3)> {
    (0..search.arena.model().layout.vehicles)
        .map(|i| extent(search.arena.mine(&search.eval, i).1))
        .collect()
}
