//! The fleet's pair terms, F_i(S) of Zhi & Zuo 2024, eq. (11), and the separation penalty, measured
//! on the pairs the broad phase ([`crate::broad_phase`]) cannot rule out: a pair it prunes is at
//! least d_min apart at every instant, so both its terms are exactly zero. An evaluation keeps
//! its pairs' terms, so one that moves a single vehicle measures only that vehicle's pairs.

use std::cell::RefCell;

use crate::broad_phase::{PairSet, SlabBoxes};
use crate::separation::{closest_within, motion_separation, Motion};
use crate::trajectory::Trajectory;

thread_local! {
    /// The broad phase's boxes and pair set, reused by every evaluation on this thread (the
    /// swarm evaluates on a few worker threads, hundreds of thousands of times).
    static SCRATCH: RefCell<(SlabBoxes, PairSet)> = RefCell::new((SlabBoxes::new(), PairSet::new()));
}

/// F_i(S) of eq. (11) on timed trajectories: eq. (11) is 1 at every instant a pair is closer than
/// d_min; counted once per second, the sum is the breach time in seconds.
pub fn space_term(breach_seconds: f64) -> f64 {
    breach_seconds
}

/// Separation penalty of one pair: `1 + (d_min − closest) / d_min` when the pair ever comes
/// closer than d_min, else 0.
pub fn separation_penalty(min_distance: f64, d_min: f64) -> f64 {
    if min_distance < d_min && d_min > 0.0 {
        1.0 + (d_min - min_distance) / d_min
    } else {
        0.0
    }
}

/// The exact terms of one pair the broad phase kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairTerms {
    /// The pair, `i < j`, in scenario order.
    pub i: u32,
    /// The other vehicle.
    pub j: u32,
    /// Seconds closer than d_min: F(S) of eq. (11) for each of the two.
    pub breach_s: f64,
    /// The pair's separation penalty ([`separation_penalty`]).
    pub penalty: f64,
}

/// The terms of every pair the broad phase cannot rule out, in row order.
pub(super) fn pair_terms(trajectories: &[Trajectory], d_min: f64) -> Vec<PairTerms> {
    if trajectories.len() <= SMALL_FLEET {
        return all_pair_terms(trajectories, d_min);
    }
    with_scratch(|boxes, pairs| {
        boxes_of(trajectories, boxes);
        boxes.close_pairs(d_min, pairs);
        narrow(trajectories, d_min, boxes, pairs.iter())
    })
}

/// [`pair_terms`] after only vehicle `changed` moved: the pairs without it are `base`'s
/// (the terms of an evaluation of the same fleet with `changed` elsewhere); only the pairs with
/// it are found and measured again. Pairs the broad phase keeps but that never come within
/// d_min have terms of exactly zero, so which of them are listed changes no sum.
pub(super) fn pair_terms_changed(
    trajectories: &[Trajectory],
    d_min: f64,
    changed: usize,
    base: &[PairTerms],
) -> Vec<PairTerms> {
    if trajectories.len() <= SMALL_FLEET {
        return all_pair_terms(trajectories, d_min);
    }
    let fresh = with_scratch(|boxes, _| {
        boxes_of(trajectories, boxes);
        let with_changed = (0..trajectories.len())
            .filter(|&j| j != changed)
            .map(|j| (changed.min(j), changed.max(j)));
        narrow(trajectories, d_min, boxes, with_changed)
    });
    let kept = base
        .iter()
        .filter(|p| p.i as usize != changed && p.j as usize != changed);
    let mut out: Vec<PairTerms> = kept.copied().chain(fresh).collect();
    out.sort_unstable_by_key(|p| (p.i, p.j));
    out
}

/// Runs `f` on this thread's broad-phase buffers (fresh ones if they are in use).
fn with_scratch<T>(f: impl FnOnce(&mut SlabBoxes, &mut PairSet) -> T) -> T {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => {
            let (boxes, pairs) = &mut *scratch;
            f(boxes, pairs)
        }
        Err(_) => f(&mut SlabBoxes::new(), &mut PairSet::new()),
    })
}

/// Every trajectory's slab boxes, over the time to the last arrival.
fn boxes_of(trajectories: &[Trajectory], boxes: &mut SlabBoxes) {
    let horizon = trajectories
        .iter()
        .filter_map(|t| t.times.last())
        .fold(0.0f64, |a, b| a.max(*b));
    boxes.reset(horizon);
    for t in trajectories {
        boxes.push(&t.times, &t.points);
    }
}

/// The exact separation (the narrow phase) of `pairs`, in the order given. A pair whose boxes
/// never come within d_min is skipped; one that stays
/// at least d_min apart throughout the slabs where its boxes come near ([`closest_within`],
/// over those windows only) has terms of exactly zero and is left out; the others get
/// [`motion_separation`] over the whole mission, as an all-pairs loop would.
fn narrow(
    trajectories: &[Trajectory],
    d_min: f64,
    boxes: &SlabBoxes,
    pairs: impl Iterator<Item = (usize, usize)>,
) -> Vec<PairTerms> {
    let mut motions: Vec<Option<Motion>> = vec![None; trajectories.len()];
    let mut windows = Vec::new();
    let mut out = Vec::new();
    for (i, j) in pairs {
        boxes.near_windows(i, j, d_min, &mut windows);
        if windows.is_empty() {
            continue;
        }
        for k in [i, j] {
            if motions[k].is_none() {
                motions[k] = Some(Motion::new(&trajectories[k]));
            }
        }
        let (Some(a), Some(b)) = (&motions[i], &motions[j]) else {
            continue;
        };
        let apart = d_min + CLEAR_GUARD_M;
        if windows
            .iter()
            .all(|&(from, to)| closest_within(a, b, from, to) >= apart)
        {
            continue;
        }
        out.push(exact_pair(i, j, a, b, d_min));
    }
    out
}

/// The pair's terms by [`motion_separation`] over the whole mission.
fn exact_pair(i: usize, j: usize, a: &Motion<'_>, b: &Motion<'_>, d_min: f64) -> PairTerms {
    let ps = motion_separation(a, b, d_min, false);
    PairTerms {
        i: i as u32,
        j: j as u32,
        breach_s: ps.breach_s,
        penalty: separation_penalty(ps.min_distance, d_min),
    }
}

/// How far beyond d_min a windowed closest approach must stay for the pair to be left out,
/// metres: the whole-mission separation computes the same positions with other roundings.
const CLEAR_GUARD_M: f64 = 1e-6;

/// Fleets up to this size measure every pair exactly: with ten pairs or fewer the boxes cost
/// more than they save (scenario 3 of Zhi & Zuo 2024, five AUVs, planned 2–4 % slower with
/// them; eight vehicles 16 % faster).
const SMALL_FLEET: usize = 5;

/// Every pair by the exact separation (small fleets, and what the tests check the pruned
/// terms against).
fn all_pair_terms(trajectories: &[Trajectory], d_min: f64) -> Vec<PairTerms> {
    let n = trajectories.len();
    let motions: Vec<Motion> = trajectories.iter().map(Motion::new).collect();
    let mut out = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            out.push(exact_pair(i, j, &motions[i], &motions[j], d_min));
        }
    }
    out
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

        /// The pruned pairs with a non-zero term are the all-pairs ones, in the same order,
        /// with the same terms to the last bit (so every sum over them is the same too).
        #[test]
        fn pruned_pair_terms_equal_all_pairs(
            fleet in prop::collection::vec(crossing(), 2..14),
            d_min in 20.0..200.0f64,
        ) {
            let nonzero = |pairs: Vec<PairTerms>| -> Vec<PairTerms> {
                pairs.into_iter().filter(|p| p.breach_s != 0.0 || p.penalty != 0.0).collect()
            };
            let all = nonzero(all_pair_terms(&fleet, d_min));
            prop_assert_eq!(nonzero(pair_terms(&fleet, d_min)), all);
        }
    }
}
