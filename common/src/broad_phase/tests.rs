use super::*;
use crate::separation::{closest_within, pair_separation, Motion};
use crate::trajectory::Trajectory;
use approx::assert_abs_diff_eq;
use proptest::prelude::*;

fn boxes_of(horizon: f64, fleet: &[Trajectory]) -> SlabBoxes {
    let mut b = SlabBoxes::new();
    b.reset(horizon);
    for t in fleet {
        b.push(&t.times, &t.points);
    }
    b
}

fn line(t0: f64, from: [f64; 3], t1: f64, to: [f64; 3]) -> Trajectory {
    Trajectory {
        times: vec![t0, t1],
        points: vec![Vec3::from(from), Vec3::from(to)],
    }
}

/// A horizon of 10 s slabs.
const TEN_SECOND_SLABS: f64 = 10.0 * SLABS as f64;

#[test]
fn a_straight_run_has_one_box_per_slab_by_hand() {
    // 1 m/s along x to the horizon: slab k (10 s) spans x = 10k … 10k + 10.
    let h = TEN_SECOND_SLABS;
    let b = boxes_of(h, &[line(0.0, [0., 5., 7.], h, [h, 5., 7.])]);
    assert_eq!(b.len(), 1);
    for k in 0..SLABS {
        assert_abs_diff_eq!(b.lo[k], Vec3::new(10.0 * k as f64, 5., 7.), epsilon = 1e-9);
        assert_abs_diff_eq!(
            b.hi[k],
            Vec3::new(10.0 * (k + 1) as f64, 5., 7.),
            epsilon = 1e-9
        );
    }
}

#[test]
fn a_vehicle_holds_before_its_first_and_after_its_last_sample() {
    // Starts moving at 100 s and stops at 150 s, in a horizon of (at least 16) 10 s slabs.
    let b = boxes_of(
        TEN_SECOND_SLABS,
        &[line(100.0, [0., 0., 0.], 150.0, [50., 0., 0.])],
    );
    assert_abs_diff_eq!(b.hi[0], Vec3::zeros(), epsilon = 1e-12);
    assert_abs_diff_eq!(b.lo[12], Vec3::new(20., 0., 0.), epsilon = 1e-9);
    assert_abs_diff_eq!(b.hi[12], Vec3::new(30., 0., 0.), epsilon = 1e-9);
    assert_abs_diff_eq!(b.lo[SLABS - 1], Vec3::new(50., 0., 0.), epsilon = 1e-12);
}

#[test]
fn parallel_tracks_are_near_only_within_their_spacing() {
    let fleet = [
        line(0.0, [0., 0., 0.], 320.0, [320., 0., 0.]),
        line(0.0, [0., 100., 0.], 320.0, [320., 100., 0.]),
    ];
    let b = boxes_of(320.0, &fleet);
    assert!(!b.near(0, 1, 50.0));
    assert!(!b.near(0, 1, 99.9));
    assert!(b.near(0, 1, 100.1));
}

#[test]
fn tracks_that_cross_at_different_times_are_pruned() {
    // A runs east along y = 0 at 1 m/s; B leaves (160, 0) at t = 0 northwards at 1 m/s. The
    // tracks cross at (160, 0), but A gets there 160 s after B left: the closest approach is
    // 80·√2 = 113.1 m at t = 80 s. The 10 s boxes come within √(80² + 70²) = 106.3 m (slab 7),
    // but both tracks are straight, so their chords are the tracks themselves and prune the
    // pair up to its exact closest approach.
    let fleet = [
        line(0.0, [0., 0., 0.], 320.0, [320., 0., 0.]),
        line(0.0, [160., 0., 0.], 320.0, [160., 320., 0.]),
    ];
    let closest = 80.0 * 2f64.sqrt();
    assert_abs_diff_eq!(
        pair_separation(&fleet[0], &fleet[1], 50.0).min_distance,
        closest,
        epsilon = 1e-9
    );
    let b = boxes_of(TEN_SECOND_SLABS, &fleet);
    assert!(!b.near(0, 1, 50.0));
    assert!(!b.near(0, 1, 106.4));
    assert!(!b.near(0, 1, closest - 1e-3));
    assert!(b.near(0, 1, closest + 1e-3));
    // Only the two slabs that meet at the closest approach (t = 80 s) keep them.
    assert_eq!(b.near_slabs(0, 1, closest + 1e-3), 0b11 << 7);
}

#[test]
fn one_vehicle_following_another_is_pruned_by_the_chords_by_hand() {
    // B follows A along the x axis 15 m behind, both at 1 m/s for 20 s: their boxes of slab 0
    // ([0, 20] and [−15, 5] along x) overlap, but the pair is 15 m apart at every instant,
    // which the chords (straight, so without stray) see.
    let slab = 20.0;
    let fleet = [
        line(0.0, [0., 0., 0.], slab, [20., 0., 0.]),
        line(0.0, [-15., 0., 0.], slab, [5., 0., 0.]),
    ];
    let b = boxes_of(slab * SLABS as f64, &fleet);
    let r2 = guarded2(14.0);
    assert!(gap2(&b.lo[0], &b.hi[0], &b.lo[SLABS], &b.hi[SLABS]) < r2);
    assert!(!b.near(0, 1, 14.0));
    assert!(b.near(0, 1, 15.1));
    assert_eq!(
        b.near_slabs(0, 1, 15.1),
        !0 >> (SlabMask::BITS as usize - SLABS)
    );
}

#[test]
fn a_bent_track_strays_from_its_chord_by_hand() {
    // In slab 0 (20 s) the track goes out to (10, 10) and back to the x axis at (20, 0): its
    // chord runs from (0, 0) to (20, 0) at 1 m/s, so at t = 10 s it strays 10 m. Another
    // vehicle holding at (10, 25) is 15 m from the track's nearest point, and 25 m from the
    // chord: the pair is near for a reach above 15 m only.
    let slab = 20.0;
    let bent = Trajectory {
        times: vec![0.0, 10.0, slab],
        points: vec![
            Vec3::new(0., 0., 0.),
            Vec3::new(10., 10., 0.),
            Vec3::new(20., 0., 0.),
        ],
    };
    let still = line(0.0, [10., 25., 0.], slab, [10., 25., 0.]);
    let b = boxes_of(slab * SLABS as f64, &[bent, still]);
    assert_abs_diff_eq!(b.stray[0], 10.0, epsilon = 1e-12);
    assert_abs_diff_eq!(b.stray[1], 0.0, epsilon = 1e-12);
    assert_abs_diff_eq!(b.stray[SLABS], 0.0, epsilon = 1e-12);
    assert!(!b.near(0, 1, 14.9));
    assert!(b.near(0, 1, 15.1));
}

#[test]
fn a_vehicle_still_moving_past_the_horizon_has_no_last_chord() {
    // The horizon is half the trajectory: the last slab holds everything after it, which no
    // chord spans, so its stray is infinite and only its box decides.
    let fleet = [line(0.0, [0., 0., 0.], 320.0, [320., 0., 0.])];
    let b = boxes_of(160.0, &fleet);
    assert!(b.stray[SLABS - 1].is_infinite());
    assert!(b.stray[..SLABS - 1].iter().all(|s| *s < 1e-9));
}

#[test]
fn a_vehicle_that_starts_late_strays_where_it_starts() {
    // A holds at the origin until 150 s, then runs to x = 100 by 160 s; B stands at x = −40
    // until 140 s and is at x = 60 by 160 s: they meet at x = 0 at 148 s. In slab 7
    // ([140, 160] s) A's chord runs from the origin to x = 100 at 5 m/s, so at 150 s A, still
    // at the origin, is 50 m behind it: a stray the slab must keep.
    let a = Trajectory {
        times: vec![150.0, 160.0],
        points: vec![Vec3::zeros(), Vec3::new(100., 0., 0.)],
    };
    let b = Trajectory {
        times: vec![0.0, 140.0, 160.0, 320.0],
        points: vec![
            Vec3::new(-40., 0., 0.),
            Vec3::new(-40., 0., 0.),
            Vec3::new(60., 0., 0.),
            Vec3::new(60., 0., 0.),
        ],
    };
    let boxes = boxes_of(320.0, &[a, b]);
    assert_abs_diff_eq!(boxes.stray[7], 50.0, epsilon = 1e-9);
    assert_ne!(boxes.near_slabs(0, 1, 20.0) & 1 << 7, 0);
}

#[test]
fn the_sweep_and_the_pair_test_keep_the_same_slabs_at_the_reach_itself() {
    // B follows A 15 m and 1.5 µm behind: at reach 15 m the pair is apart by more than the
    // guard, for the sweep as for the pair test.
    let fleet = [
        line(0.0, [0., 0., 0.], 20.0, [20., 0., 0.]),
        line(0.0, [-15.000_001_5, 0., 0.], 20.0, [4.999_998_5, 0., 0.]),
    ];
    let mut b = boxes_of(320.0, &fleet);
    let mut pairs = PairSet::new();
    b.close_pairs(15.0, &mut pairs);
    assert_eq!(pairs.slabs(0, 1), b.near_slabs(0, 1, 15.0));
    assert!(!pairs.contains(0, 1));
}

#[test]
fn a_sample_that_is_not_a_number_keeps_the_slab_near() {
    // A has a NaN sample at 1 s, then runs from the origin at 2 s to x = 1000 at 100 s,
    // passing B (holding at x = 30) at about 4.9 s, in slab 0 (6.25 s).
    let a = Trajectory {
        times: vec![0.0, 1.0, 2.0, 100.0],
        points: vec![
            Vec3::zeros(),
            Vec3::repeat(f64::NAN),
            Vec3::zeros(),
            Vec3::new(1000., 0., 0.),
        ],
    };
    let b = line(0.0, [30., 0., 0.], 100.0, [30., 0., 0.]);
    let boxes = boxes_of(100.0, &[a, b]);
    assert!(boxes.hi[0].x >= 43.0, "{:?}", boxes.hi[0]);
    assert!(boxes.stray[0].is_infinite());
    assert_ne!(boxes.near_slabs(0, 1, 10.0) & 1, 0);
}

#[test]
fn pair_sets_iterate_in_row_order() {
    let mut p = PairSet::new();
    p.reset(5);
    for (a, b) in [(3, 1), (0, 4), (2, 3), (0, 1), (4, 4)] {
        p.insert(a, b);
    }
    assert_eq!(
        p.iter().collect::<Vec<_>>(),
        vec![(0, 1), (0, 4), (1, 3), (2, 3)]
    );
    assert!(p.contains(1, 3) && p.contains(3, 1) && !p.contains(1, 2) && !p.contains(4, 4));
    p.reset(3);
    assert_eq!(p.iter().count(), 0);
}

#[test]
fn slab_masks_become_merged_windows_by_hand() {
    // Slabs of 10 s: slabs 0–1, 5 and the last two give [0, 20), [50, 60) and [h − 20, ∞).
    let h = TEN_SECOND_SLABS;
    let b = boxes_of(h, &[line(0.0, [0., 0., 0.], h, [1., 0., 0.])]);
    let mut w = Vec::new();
    b.windows(0b11 | 1 << 5 | 0b11 << (SLABS - 2), &mut w);
    assert_eq!(
        w,
        vec![(0.0, 20.0), (50.0, 60.0), (h - 20.0, f64::INFINITY)]
    );
    b.windows(1 << (SLABS - 1), &mut w);
    assert_eq!(w, vec![(h - 10.0, f64::INFINITY)]);
    b.windows(!0, &mut w);
    assert_eq!(w, vec![(0.0, f64::INFINITY)]);
    b.windows(0, &mut w);
    assert!(w.is_empty());
}

#[test]
fn marked_pairs_keep_their_slabs() {
    let mut p = PairSet::new();
    p.reset(4);
    p.mark(2, 1, 3);
    p.mark(1, 2, SLABS - 1);
    p.insert(0, 3);
    assert_eq!(p.slabs(1, 2), 1 << 3 | 1 << (SLABS - 1));
    assert_eq!(p.slabs(0, 3), 0);
    assert_eq!(p.iter().collect::<Vec<_>>(), vec![(0, 3), (1, 2)]);
}

/// A random trajectory in a 400 m cube: 1–6 samples at non-decreasing times from 0, some of
/// them repeated (a leg of zero length and zero duration, as a retimed path has where two
/// waypoints coincide).
fn trajectory() -> impl Strategy<Value = Trajectory> {
    prop::collection::vec(
        (
            (0.0..400.0f64, 0.0..400.0f64, 0.0..400.0f64),
            0..3u8,
            0.0..120.0f64,
        ),
        1..7,
    )
    .prop_map(|samples| {
        let mut out = Trajectory {
            times: Vec::new(),
            points: Vec::new(),
        };
        for ((x, y, z), kind, dt) in samples {
            match (out.times.last().copied(), out.points.last().copied()) {
                (Some(t), Some(p)) if kind == 0 => {
                    out.times.push(t);
                    out.points.push(p);
                }
                (Some(t), _) => {
                    out.times.push(t + dt);
                    out.points.push(Vec3::new(x, y, z));
                }
                _ => {
                    out.times.push(0.0);
                    out.points.push(Vec3::new(x, y, z));
                }
            }
        }
        out
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Every pair the broad phase prunes is at least `d_min` apart at every instant, by the
    /// exact separation; the pairs it keeps include every pair that comes closer.
    #[test]
    fn pruned_pairs_never_come_within_d_min(
        fleet in prop::collection::vec(trajectory(), 2..9),
        d_min in 5.0..150.0f64,
        horizon_scale in 0.3..1.5f64,
    ) {
        let end = fleet.iter().filter_map(|t| t.times.last()).fold(1.0f64, |a, b| a.max(*b));
        let mut b = boxes_of(end * horizon_scale, &fleet);
        let mut pairs = PairSet::new();
        b.close_pairs(d_min, &mut pairs);
        for i in 0..fleet.len() {
            for j in i + 1..fleet.len() {
                let exact = pair_separation(&fleet[i], &fleet[j], d_min);
                prop_assert_eq!(pairs.contains(i, j), b.near(i, j, d_min));
                prop_assert_eq!(pairs.slabs(i, j), b.near_slabs(i, j, d_min));
                if !pairs.contains(i, j) {
                    prop_assert!(exact.min_distance >= d_min, "{} {} {}", i, j, exact.min_distance);
                    prop_assert_eq!(exact.breach_s, 0.0);
                }
                // Each slab left out is one in which the pair stays d_min apart throughout.
                let (a, c) = (Motion::new(&fleet[i]), Motion::new(&fleet[j]));
                let mask = pairs.slabs(i, j);
                let mut apart = Vec::new();
                b.windows(!mask & (!0 >> (SlabMask::BITS as usize - SLABS)), &mut apart);
                for (from, to) in apart {
                    let closest = closest_within(&a, &c, from, to);
                    prop_assert!(closest >= d_min - 1e-6, "{} {} [{}, {}]: {}", i, j, from, to, closest);
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// The index finds exactly the others [`SlabBoxes::near_other`] finds near a vehicle.
    #[test]
    fn the_index_finds_the_others_every_box_test_finds(
        others in prop::collection::vec(trajectory(), 1..12),
        mine in trajectory(),
        reach in 5.0..150.0f64,
        horizon_scale in 0.3..1.5f64,
    ) {
        let end = others.iter().chain([&mine]).filter_map(|t| t.times.last()).fold(1.0f64, |a, b| a.max(*b));
        let indexed = boxes_of(end * horizon_scale, &others);
        let own = boxes_of(end * horizon_scale, std::slice::from_ref(&mine));
        let mut near = Vec::new();
        SlabIndex::new(&indexed).near(&indexed, &own, 0, reach, &mut near);
        let every: Vec<bool> = (0..others.len()).map(|k| own.near_other(0, &indexed, k, reach)).collect();
        prop_assert_eq!(near, every);
    }
}
