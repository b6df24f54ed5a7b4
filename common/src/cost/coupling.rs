//! The fleet's pair terms, F_i(S) of Zhi & Zuo 2024, eq. (11), and the separation penalty, summed
//! over the pairs the broad phase ([`crate::broad_phase`]) cannot rule out: a pair it prunes is at
//! least d_min apart at every instant, so both its terms are exactly zero.

use std::cell::RefCell;

use super::{separation_penalty, space_term, VehicleTerms};
use crate::broad_phase::{PairSet, SlabBoxes};
use crate::separation::{motion_separation, Motion};
use crate::trajectory::Trajectory;

thread_local! {
    /// The broad phase's boxes and pair set, reused by every evaluation on this thread (the
    /// swarm evaluates on a few worker threads, hundreds of thousands of times).
    static SCRATCH: RefCell<(SlabBoxes, PairSet)> = RefCell::new((SlabBoxes::new(), PairSet::new()));
}

/// Adds every pair's F(S) (to both vehicles) and half its separation penalty (to each) into
/// `vehicles`, and returns the sum of the pairs' penalties. Pairs are visited in row order, as
/// an all-pairs loop would, so the sums are the same to the last bit.
pub(super) fn add_pair_terms(
    trajectories: &[Trajectory],
    d_min: f64,
    vehicles: &mut [VehicleTerms],
) -> f64 {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => {
            let (boxes, pairs) = &mut *scratch;
            close_pairs(trajectories, d_min, boxes, pairs);
            sum_pairs(trajectories, d_min, pairs.iter(), vehicles)
        }
        // Re-entered on this thread (nothing does today): fall back to fresh buffers.
        Err(_) => {
            let (mut boxes, mut pairs) = (SlabBoxes::new(), PairSet::new());
            close_pairs(trajectories, d_min, &mut boxes, &mut pairs);
            sum_pairs(trajectories, d_min, pairs.iter(), vehicles)
        }
    })
}

/// The pairs whose space-time boxes come within `d_min`.
fn close_pairs(
    trajectories: &[Trajectory],
    d_min: f64,
    boxes: &mut SlabBoxes,
    pairs: &mut PairSet,
) {
    let horizon = trajectories
        .iter()
        .filter_map(|t| t.times.last())
        .fold(0.0f64, |a, b| a.max(*b));
    boxes.reset(horizon);
    for t in trajectories {
        boxes.push(&t.times, &t.points);
    }
    boxes.close_pairs(d_min, pairs);
}

/// The exact narrow phase on `pairs`.
fn sum_pairs(
    trajectories: &[Trajectory],
    d_min: f64,
    pairs: impl Iterator<Item = (usize, usize)>,
    vehicles: &mut [VehicleTerms],
) -> f64 {
    let motions: Vec<Motion> = trajectories.iter().map(Motion::new).collect();
    let mut total = 0.0;
    for (i, j) in pairs {
        let ps = motion_separation(&motions[i], &motions[j], d_min, false);
        // eq. (12) sums F_i(S) over vehicles: a breach counts for both of the pair.
        vehicles[i].space += space_term(ps.breach_s);
        vehicles[j].space += space_term(ps.breach_s);
        let sp = separation_penalty(ps.min_distance, d_min);
        vehicles[i].separation += 0.5 * sp;
        vehicles[j].separation += 0.5 * sp;
        total += sp;
    }
    total
}

/// Every pair, for the tests: what [`add_pair_terms`] must equal.
#[cfg(test)]
pub(super) fn add_all_pair_terms(
    trajectories: &[Trajectory],
    d_min: f64,
    vehicles: &mut [VehicleTerms],
) -> f64 {
    let n = trajectories.len();
    let all = (0..n).flat_map(move |i| (i + 1..n).map(move |j| (i, j)));
    sum_pairs(trajectories, d_min, all, vehicles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;
    use proptest::prelude::*;

    /// A vehicle crossing a 1 km box in 2–5 straight legs at 0.5–2.5 m/s, from t = 0.
    fn crossing() -> impl Strategy<Value = Trajectory> {
        prop::collection::vec(
            ((0.0..1000.0f64, 0.0..1000.0f64, 0.0..300.0f64), 0.5..2.5f64),
            3..7,
        )
        .prop_map(|samples| {
            let mut t = 0.0;
            let mut out = Trajectory {
                times: Vec::new(),
                points: Vec::new(),
            };
            for ((x, y, z), speed) in samples {
                let p = Vec3::new(x, y, z);
                if let Some(q) = out.points.last() {
                    t += (p - q).norm() / speed;
                }
                out.times.push(t);
                out.points.push(p);
            }
            out
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// The pruned sum equals the all-pairs sum to the last bit, term by term.
        #[test]
        fn pruned_pair_terms_equal_all_pairs(
            fleet in prop::collection::vec(crossing(), 2..14),
            d_min in 20.0..200.0f64,
        ) {
            let mut pruned = vec![VehicleTerms::default(); fleet.len()];
            let mut all = pruned.clone();
            let p = add_pair_terms(&fleet, d_min, &mut pruned);
            let a = add_all_pair_terms(&fleet, d_min, &mut all);
            prop_assert_eq!(p.to_bits(), a.to_bits());
            prop_assert_eq!(pruned, all);
        }
    }
}
