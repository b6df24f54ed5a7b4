//! The fleet's pair terms, F_i(S) of Zhi & Zuo 2024, eq. (11), and the separation penalty, measured
//! on the pairs the broad phase ([`crate::broad_phase`]) cannot rule out: a pair it prunes is at
//! least d_min apart at every instant, so both its terms are exactly zero. An evaluation keeps
//! its pairs' terms, so one that moves a single vehicle measures only that vehicle's pairs.

use std::cell::RefCell;

use crate::broad_phase::{boxes_within, extent, PairSet, SlabBoxes, SlabMask};
use crate::fleet_trajectories::FleetTrajectories;
use crate::geometry::Vec3;
use crate::separation::{closest_within, motion_separation, Motion};

/// The buffers of the pair terms, reused by every evaluation on a thread (the swarm evaluates
/// on a few worker threads, hundreds of thousands of times), so measuring the pairs allocates
/// nothing once they have grown.
#[derive(Debug, Default)]
struct Scratch {
    /// The broad phase's boxes.
    boxes: SlabBoxes,
    /// The pairs the boxes keep.
    pairs: PairSet,
    /// The vehicles' leg velocities.
    velocities: Velocities,
    /// One pair's near windows.
    windows: Vec<(f64, f64)>,
    /// The vehicles whose boxes were built, in the order of `boxes` (one change's).
    built: Vec<usize>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Every vehicle's leg velocities and top speed ([`Motion::velocities_into`]), computed the
/// first time one of its pairs needs them, in one buffer.
#[derive(Debug, Default)]
struct Velocities {
    /// The velocities, vehicle after vehicle in the order they were needed.
    all: Vec<Vec3>,
    /// Per vehicle: where its velocities are in `all`, and its top speed.
    of: Vec<Option<(usize, usize, f64)>>,
}

impl Velocities {
    /// Forgets every vehicle; `n` vehicles follow.
    fn reset(&mut self, n: usize) {
        self.all.clear();
        self.of.clear();
        self.of.resize(n, None);
    }

    /// Computes vehicle `k`'s velocities from its trajectory, unless they are known.
    fn prepare(&mut self, k: usize, trajectories: &FleetTrajectories) {
        if self.of[k].is_none() {
            let start = self.all.len();
            let (times, points) = (trajectories.times(k), trajectories.points(k));
            let top = Motion::velocities_into(times, points, &mut self.all);
            self.of[k] = Some((start, self.all.len(), top));
        }
    }

    /// The prepared motions of vehicles `i` and `j` of `trajectories`.
    fn pair<'a>(
        &'a mut self,
        trajectories: &'a FleetTrajectories,
        i: usize,
        j: usize,
    ) -> (Motion<'a>, Motion<'a>) {
        for k in [i, j] {
            self.prepare(k, trajectories);
        }
        let this = &*self;
        let motion = |k: usize| {
            // Both were prepared just above.
            let (from, to, top) = this.of[k].unwrap_or((0, 0, 0.0));
            let (times, points) = (trajectories.times(k), trajectories.points(k));
            Motion::prepared(times, points, &this.all[from..to], top)
        };
        (motion(i), motion(j))
    }
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

/// The terms of every pair the broad phase cannot rule out, in row order, into `out` (cleared
/// first), after `time` has given each vehicle its timing (called once per vehicle, in order,
/// with its index and the fleet's times buffer to append its sample times to, as
/// [`FleetTrajectories::time_each`]).
///
/// Each vehicle's slab boxes are built as soon as it is timed, while its samples are still in
/// the first-level cache: a fleet of 32 outgrows that cache, and boxing the fleet in a pass of
/// its own after the timing missed it for most samples (measured with Cachegrind). The slabs
/// end at `horizon`. Any horizon gives the same terms: the broad phase keeps every pair that
/// comes within d_min whatever its slabs, and the pairs it keeps are measured over the whole
/// mission. One just after the last arrival prunes most; when a trajectory ends later than
/// `horizon` the boxes are built again over the time to its arrival.
pub(super) fn pair_terms_into(
    trajectories: &mut FleetTrajectories,
    d_min: f64,
    horizon: f64,
    out: &mut Vec<PairTerms>,
    time: impl FnMut(usize, &mut Vec<f64>),
) {
    out.clear();
    with_scratch(|scratch| {
        let small = trajectories.len() <= SMALL_FLEET;
        scratch.velocities.reset(trajectories.len());
        scratch.boxes.reset(horizon);
        let boxes = &mut scratch.boxes;
        trajectories.time_each(time, |times, points| {
            if !small {
                boxes.push(times, points);
            }
        });
        let trajectories = &*trajectories;
        if small {
            return all_pair_terms_into(trajectories, d_min, &mut scratch.velocities, out);
        }
        if horizon_of(trajectories) > horizon || horizon.is_nan() {
            boxes_of(trajectories, &mut scratch.boxes);
        }
        let Scratch {
            boxes,
            pairs,
            velocities,
            windows,
            ..
        } = scratch;
        boxes.close_pairs(d_min, pairs);
        let kept = pairs.iter().map(|(i, j)| (i, j, pairs.slabs(i, j)));
        let fleet = Fleet {
            trajectories,
            d_min,
            boxes,
        };
        fleet.narrow(kept, velocities, windows, out);
    });
}

/// [`pair_terms_into`] after only vehicle `changed` moved: the pairs without it are `base`'s
/// (the terms of an evaluation of the same fleet with `changed` elsewhere); only the pairs with
/// it are found and measured again. Pairs the broad phase keeps but that never come within
/// d_min have terms of exactly zero, so which of them are listed changes no sum.
///
/// The cost follows the vehicles near the changed one, not the fleet: slab boxes are built
/// only for the others whose whole trajectory's box ([`extent`]) comes within d_min of the
/// changed one's, since no slab box of the rest can. The slabs span the time to the fleet's
/// last arrival.
pub(super) fn pair_terms_changed(
    trajectories: &FleetTrajectories,
    d_min: f64,
    changed: usize,
    base: &[PairTerms],
    out: &mut Vec<PairTerms>,
) {
    with_measure(trajectories, d_min, out, |scratch, out| {
        let Scratch {
            boxes,
            velocities,
            windows,
            built,
            ..
        } = scratch;
        out.extend(
            base.iter()
                .filter(|p| p.i as usize != changed && p.j as usize != changed),
        );
        if changed >= trajectories.len() {
            return;
        }
        let mine = extent(trajectories.points(changed));
        built.clear();
        built.push(changed);
        built.extend((0..trajectories.len()).filter(|&j| {
            j != changed && boxes_within(&mine, &extent(trajectories.points(j)), d_min)
        }));
        boxes.reset(horizon_of(trajectories));
        for &j in built.iter() {
            boxes.push(trajectories.times(j), trajectories.points(j));
        }
        let fleet = Fleet {
            trajectories,
            d_min,
            boxes,
        };
        let with_changed = built.iter().enumerate().skip(1).map(|(k, &j)| {
            let (a, b) = (changed.min(j), changed.max(j));
            (a, b, fleet.boxes.near_slabs(0, k, d_min))
        });
        fleet.narrow(with_changed, velocities, windows, out);
        out.sort_unstable_by_key(|p| (p.i, p.j));
    });
}

/// Clears `out`, then runs `measure` on this thread's buffers (prepared for the fleet's
/// vehicles); a small fleet ([`SMALL_FLEET`]) gets every pair measured instead.
fn with_measure(
    trajectories: &FleetTrajectories,
    d_min: f64,
    out: &mut Vec<PairTerms>,
    measure: impl FnOnce(&mut Scratch, &mut Vec<PairTerms>),
) {
    out.clear();
    with_scratch(|scratch| {
        scratch.velocities.reset(trajectories.len());
        if trajectories.len() <= SMALL_FLEET {
            return all_pair_terms_into(trajectories, d_min, &mut scratch.velocities, out);
        }
        measure(scratch, out);
    });
}

/// Runs `f` on this thread's buffers (fresh ones if they are in use).
fn with_scratch<T>(f: impl FnOnce(&mut Scratch) -> T) -> T {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => f(&mut scratch),
        Err(_) => f(&mut Scratch::default()),
    })
}

/// The time to the last arrival: what the slabs span.
fn horizon_of(trajectories: &FleetTrajectories) -> f64 {
    (0..trajectories.len())
        .map(|i| trajectories.arrival(i))
        .fold(0.0f64, f64::max)
}

/// Every trajectory's slab boxes, over the time to the last arrival.
fn boxes_of(trajectories: &FleetTrajectories, boxes: &mut SlabBoxes) {
    boxes.reset(horizon_of(trajectories));
    for (times, points) in trajectories.iter() {
        boxes.push(times, points);
    }
}

/// A fleet's trajectories with their slab boxes: what the narrow phase measures.
struct Fleet<'a> {
    trajectories: &'a FleetTrajectories,
    d_min: f64,
    boxes: &'a SlabBoxes,
}

impl Fleet<'_> {
    /// The exact separation (the narrow phase) of `pairs` (each with the slabs where its boxes
    /// come within d_min), in the order given, appended to `out`. A pair with no such slab is
    /// skipped; one that stays at least d_min apart throughout those slabs
    /// ([`closest_within`], over their windows only) has terms of exactly zero and is left
    /// out; the others get [`motion_separation`] over the whole mission, as an all-pairs loop
    /// would.
    fn narrow(
        &self,
        pairs: impl Iterator<Item = (usize, usize, SlabMask)>,
        velocities: &mut Velocities,
        windows: &mut Vec<(f64, f64)>,
        out: &mut Vec<PairTerms>,
    ) {
        let apart = self.d_min + CLEAR_GUARD_M;
        for (i, j, slabs) in pairs {
            if slabs == 0 {
                continue;
            }
            self.boxes.windows(slabs, windows);
            let (a, b) = velocities.pair(self.trajectories, i, j);
            if windows
                .iter()
                .all(|&(from, to)| closest_within(&a, &b, from, to) >= apart)
            {
                continue;
            }
            out.push(exact_pair(i, j, &a, &b, self.d_min));
        }
    }
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
/// terms against), appended to `out`.
fn all_pair_terms_into(
    trajectories: &FleetTrajectories,
    d_min: f64,
    velocities: &mut Velocities,
    out: &mut Vec<PairTerms>,
) {
    let n = trajectories.len();
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = velocities.pair(trajectories, i, j);
            out.push(exact_pair(i, j, &a, &b, d_min));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strategies::crossing;
    use crate::trajectory::Trajectory;
    use proptest::prelude::*;

    /// [`pair_terms_into`] of `fleet` with its slabs ending at `horizon`, each vehicle's
    /// samples given to it by the timing (so boxes built before it would be empty).
    fn pair_terms_at(fleet: &[Trajectory], d_min: f64, horizon: f64) -> Vec<PairTerms> {
        let mut untimed = FleetTrajectories::default();
        for t in fleet {
            untimed.push_path(|points| points.extend_from_slice(&t.points));
        }
        let mut out = Vec::new();
        pair_terms_into(&mut untimed, d_min, horizon, &mut out, |i, times| {
            times.extend_from_slice(&fleet[i].times)
        });
        out
    }

    fn pair_terms(fleet: &[Trajectory], d_min: f64) -> Vec<PairTerms> {
        pair_terms_at(fleet, d_min, horizon_of(&FleetTrajectories::from(fleet)))
    }

    fn all_pair_terms(fleet: &[Trajectory], d_min: f64) -> Vec<PairTerms> {
        let mut out = Vec::new();
        let mut velocities = Velocities::default();
        velocities.reset(fleet.len());
        all_pair_terms_into(&fleet.into(), d_min, &mut velocities, &mut out);
        out
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

        /// Wherever the slabs end (before the last arrival, just after it, long after it, or
        /// nowhere), the terms are the all-pairs ones.
        #[test]
        fn pair_terms_do_not_depend_on_where_the_slabs_end(
            fleet in prop::collection::vec(crossing(), 6..14),
            d_min in 20.0..200.0f64,
            scale in prop_oneof![Just(0.3), Just(1.0 + 1e-9), Just(3.0), Just(f64::NAN)],
        ) {
            let nonzero = |pairs: Vec<PairTerms>| -> Vec<PairTerms> {
                pairs.into_iter().filter(|p| p.breach_s != 0.0 || p.penalty != 0.0).collect()
            };
            let all = nonzero(all_pair_terms(&fleet, d_min));
            let horizon = horizon_of(&FleetTrajectories::from(&fleet[..]));
            let at = pair_terms_at(&fleet, d_min, horizon * scale);
            prop_assert_eq!(nonzero(at), all);
        }
    }
}
