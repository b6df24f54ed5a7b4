//! Broad phases for the fleet's spatial terms: vehicle–obstacle in [`spheres`]; vehicle–vehicle
//! here, which pairs of timed trajectories can come within `d_min` of each other at all, so
//! only those pay for the exact, continuous separation of [`crate::separation`] (the narrow
//! phase).
//!
//! The mission's time `[0, horizon]` is cut into equal slabs; in each slab every vehicle gets
//! the axis-aligned box of every position it takes there (its trajectory is piecewise linear,
//! so the box of the slab's end positions and the samples between them). Two vehicles closer
//! than `reach` at some instant are, at that instant, inside their boxes of the same slab, so
//! those boxes are closer than `reach`: a pair none of whose slab boxes come that close can be
//! skipped without changing any term, which is what the property test below checks against all
//! pairs. Boxes of vehicles that move together overlap although the vehicles keep apart (one
//! behind the other on a track, or side by side on parallel courses), so a pair whose boxes
//! are near is tested again on its relative motion: each vehicle's straight run across the
//! slab and how far it strays from it. Within a slab a sweep and prune along the axis the
//! boxes spread most over (Baraff 1992, "Dynamic simulation of non-penetrating rigid bodies",
//! §6) finds the close boxes in
//! `O(n log n)` rather than testing all `n²/2` pairs. Hand-written: the crates that do this
//! (`parry`'s BVH, `broccoli`) index static shapes and allocate per query; this reuses its
//! buffers across the swarm's evaluations.

use crate::geometry::{larger, lower_corner, upper_corner, Vec3};

mod pairs;
pub mod spheres;

pub use pairs::{PairSet, SlabMask};

const _: () = assert!(SLABS <= SlabMask::BITS as usize);

/// Time slabs per mission. More slabs give smaller boxes (fewer pairs survive) but more boxes
/// to build and sort; 16 slabs of a one-hour mission keep a box under 350 m along a 3-knot
/// track. Measured on 32-vehicle fleets (the swarm alone, the plans identical): 16 slabs
/// planned 3–9 % faster than 32 on lanes and crossings; 8 slabs 2 % faster than 16 on lanes
/// but 13–18 % slower on crossings, where the longer boxes keep more pairs.
pub const SLABS: usize = 16;

/// Every vehicle's box in every time slab, with the buffers the pair search reuses.
#[derive(Debug, Clone, Default)]
pub struct SlabBoxes {
    /// Length of the time span the slabs cover, seconds (at least one slab's worth of time).
    horizon: f64,
    /// Lower corners, vehicle-major: vehicle `v`, slab `k` at `v * SLABS + k`.
    lo: Vec<Vec3>,
    /// Upper corners, in the same order.
    hi: Vec<Vec3>,
    /// Positions at the slabs' bounds, vehicle-major: vehicle `v` at time `k * slab` at
    /// `v * (SLABS + 1) + k`, the ends of each slab's chord; the last is the final point,
    /// where the vehicle is at the horizon unless it is still moving (then its stray is
    /// infinite).
    bounds: Vec<Vec3>,
    /// How far each slab's positions stray from its chord (the straight run between its bound
    /// positions at constant speed), in the order of `lo`; infinite when the vehicle moves past
    /// the horizon, where the last slab has no chord.
    stray: Vec<f64>,
    /// One slab's boxes in sweep order, reused: contiguous, so the sweep reads no strided
    /// memory, and kept in the previous slab's order, which the next slab changes little.
    sweep: Vec<SweepBox>,
}

/// A vehicle's box in the slab being swept.
#[derive(Debug, Clone, Copy)]
struct SweepBox {
    /// Lower corner.
    lo: [f64; 3],
    /// Upper corner.
    hi: [f64; 3],
    /// The vehicle.
    v: u32,
}

/// Squared distance between two swept boxes, without branches: most box pairs the sweep
/// meets are neither clearly apart nor clearly overlapping, so branching on each axis
/// mispredicts. Each gap is the [`larger`], which takes a third of `f64::max`'s instructions:
/// the same gaps but where a NaN is involved, and there never larger, so no pair `f64::max`
/// would keep is dropped. (Boxes at infinity never get here; see [`SlabBoxes::close_pairs`].)
#[inline]
fn sweep_gap2(a: &SweepBox, b: &SweepBox) -> f64 {
    let mut s = 0.0;
    for d in 0..3 {
        let g = larger(larger(a.lo[d] - b.hi[d], b.lo[d] - a.hi[d]), 0.0);
        s += g * g;
    }
    s
}

impl SlabBoxes {
    /// Empty, with no buffers yet.
    pub fn new() -> SlabBoxes {
        SlabBoxes::default()
    }

    /// Forgets every vehicle and sets the time span to `[0, horizon]` (keeping the buffers).
    /// Positions after `horizon` fall in the last slab.
    pub fn reset(&mut self, horizon: f64) {
        self.horizon = if horizon.is_finite() && horizon > 0.0 {
            horizon
        } else {
            1.0
        };
        self.lo.clear();
        self.hi.clear();
        self.bounds.clear();
        self.stray.clear();
    }

    /// Vehicles added so far.
    pub fn len(&self) -> usize {
        self.lo.len() / SLABS
    }

    /// True before any vehicle is added.
    pub fn is_empty(&self) -> bool {
        self.lo.is_empty()
    }

    /// Adds the next vehicle: a trajectory through `points` at `times` (non-decreasing from 0,
    /// as every [`crate::trajectory::Trajectory`]), holding at its last point after its last time.
    pub fn push(&mut self, times: &[f64], points: &[Vec3]) {
        let n = times.len().min(points.len());
        if n == 0 {
            // A vehicle without samples is nowhere: a box no other box comes near.
            let far = Vec3::repeat(f64::INFINITY);
            self.lo.extend(std::iter::repeat_n(far, SLABS));
            self.hi.extend(std::iter::repeat_n(far, SLABS));
            self.bounds.extend(std::iter::repeat_n(far, SLABS + 1));
            self.stray.extend(std::iter::repeat_n(f64::INFINITY, SLABS));
            return;
        }
        let slab = self.horizon / SLABS as f64;
        let per_slab = 1.0 / slab;
        let arrival = times[n - 1];
        let mut start = position(times, points, &mut 0, 0.0);
        self.bounds.push(start);
        // Slab 0's samples start at the first: a chain of samples at t = 0 the start position
        // skipped (the separation counts them).
        let mut first = 0usize;
        for k in 0..SLABS {
            let t0 = k as f64 * slab;
            let t1 = if k + 1 == SLABS {
                f64::INFINITY
            } else {
                (k + 1) as f64 * slab
            };
            // The slab's samples: every one at or before t1 not taken by an earlier slab (a
            // chain of samples at one instant too; none in the slabs before a trajectory's
            // first sample, where it holds there).
            let from = first;
            let (mut lo, mut hi) = (start, start);
            while first < n && times[first] <= t1 {
                lo = lower_corner(&lo, &points[first]);
                hi = upper_corner(&hi, &points[first]);
                first += 1;
            }
            // The last sample at or before t1 is the slab's last (the times do not decrease),
            // or the first sample when none is yet: one scan of the times finds both.
            let end = position_on_leg(times, points, first.saturating_sub(1), t1);
            // The positions minus the chord are piecewise linear in time with corners only at
            // the samples, so the farthest a slab strays from its chord is at one of them.
            let run = end - start;
            let mut stray2 = 0.0f64;
            for (p, t) in points[from..first].iter().zip(&times[from..first]) {
                let off = (p - start - run * ((t - t0) * per_slab)).norm_squared();
                if off.is_nan() {
                    stray2 = f64::INFINITY;
                } else if off > stray2 {
                    stray2 = off;
                }
            }
            // The end last: a NaN sample makes the running box forget what came before it.
            self.lo.push(lower_corner(&lo, &end));
            self.hi.push(upper_corner(&hi, &end));
            self.bounds.push(end);
            // The last slab's chord ends at the horizon: past it, one that still moves has none.
            let past_horizon = k + 1 == SLABS && arrival > self.horizon;
            self.stray.push(if past_horizon {
                f64::INFINITY
            } else {
                stray2.sqrt()
            });
            start = end;
        }
    }

    /// Whether vehicle `a` of `self` and vehicle `b` of `other` may come closer than `reach`
    /// in slab `k` (`reach` with its guarded square `r2`): their boxes, then their chords.
    #[inline]
    fn slab_near(
        &self,
        a: usize,
        other: &SlabBoxes,
        b: usize,
        k: usize,
        (r2, reach): (f64, f64),
    ) -> bool {
        let (i, j) = (a * SLABS + k, b * SLABS + k);
        gap2(&self.lo[i], &self.hi[i], &other.lo[j], &other.hi[j]) < r2
            && self.chords_within(a, other, b, k, reach)
    }

    /// Whether vehicle `a` of `self` and vehicle `b` of `other` may come closer than `reach`
    /// in slab `k` by their chords: at every instant of the slab each lies within its stray of
    /// its chord, and the two chords run over the same times, so the pair's relative position
    /// lies within the sum of the strays of the straight run between its values at the slab's
    /// bounds; a run that passes farther than `reach` plus that sum from the origin proves the
    /// pair apart (the moving-sphere test of Ericson 2005, "Real-Time Collision Detection",
    /// §5.5.7, on the relative motion). Two boxes that overlap because both vehicles sweep the
    /// same stretch of sea one after the other, or side by side, are told apart by it.
    #[inline]
    fn chords_within(&self, a: usize, other: &SlabBoxes, b: usize, k: usize, reach: f64) -> bool {
        let slack = self.stray[a * SLABS + k] + other.stray[b * SLABS + k];
        let (i, j) = (a * (SLABS + 1) + k, b * (SLABS + 1) + k);
        let d0 = other.bounds[j] - self.bounds[i];
        let d1 = other.bounds[j + 1] - self.bounds[i + 1];
        // Kept unless provably apart: every comparison with a NaN or an infinite stray is false.
        !run_apart(&d0, &d1, reach + slack + REACH_GUARD_M)
    }

    /// Whether vehicles `a` and `b` have boxes of some slab closer than `reach`: false proves
    /// they never come closer than `reach` at the same instant.
    pub fn near(&self, a: usize, b: usize, reach: f64) -> bool {
        self.near_other(a, self, b, reach)
    }

    /// The slabs in which vehicles `a` and `b` have boxes closer than `reach`, as a mask (bit
    /// `k` for slab `k`).
    pub fn near_slabs(&self, a: usize, b: usize, reach: f64) -> SlabMask {
        self.near_slabs_other(a, self, b, reach)
    }

    /// The time windows `(from, to)` of the slabs in `mask`, adjacent ones merged, into `out`
    /// (cleared first); the last slab's window ends at infinity (every vehicle holds at its
    /// last point).
    pub fn windows(&self, mask: SlabMask, out: &mut Vec<(f64, f64)>) {
        out.clear();
        let slab = self.horizon / SLABS as f64;
        let mut rest = mask;
        while rest != 0 {
            let first = rest.trailing_zeros() as usize;
            let run = (rest >> first).trailing_ones() as usize;
            let end = first + run;
            let to = if end >= SLABS {
                f64::INFINITY
            } else {
                end as f64 * slab
            };
            out.push((first as f64 * slab, to));
            rest &= if end >= SLABS { 0 } else { !0 << end };
        }
    }

    /// Whether vehicle `a` of `self` and vehicle `b` of `other` (with the same horizon) have
    /// boxes of some slab closer than `reach`.
    pub fn near_other(&self, a: usize, other: &SlabBoxes, b: usize, reach: f64) -> bool {
        self.near_slabs_other(a, other, b, reach) != 0
    }

    /// The slabs in which vehicle `a` of `self` and vehicle `b` of `other` (with the same
    /// horizon) have boxes closer than `reach`, as a mask: outside them the two are at least
    /// `reach` apart.
    pub fn near_slabs_other(&self, a: usize, other: &SlabBoxes, b: usize, reach: f64) -> SlabMask {
        let r2 = guarded2(reach);
        (0..SLABS)
            .filter(|&k| self.slab_near(a, other, b, k, (r2, reach)))
            .fold(0, |m, k| m | 1 << k)
    }

    /// Every pair `(i, j)`, `i < j`, whose boxes of some slab are closer than `reach`, marked
    /// in `pairs` (which is cleared and sized first) with the slabs where they are.
    pub fn close_pairs(&mut self, reach: f64, pairs: &mut PairSet) {
        let n = self.len();
        pairs.reset(n);
        let r2 = guarded2(reach);
        let guarded = r2.sqrt();
        let axis = self.widest_axis(SLABS / 2);
        if self.sweep.len() != n {
            self.sweep.clear();
            self.sweep.extend((0..n as u32).map(|v| SweepBox {
                lo: [f64::INFINITY; 3],
                hi: [f64::INFINITY; 3],
                v,
            }));
        }
        for k in 0..SLABS {
            for e in self.sweep.iter_mut() {
                let i = e.v as usize * SLABS + k;
                e.lo = self.lo[i].into();
                e.hi = self.hi[i].into();
            }
            // Sorted by the boxes' lower ends along the axis. From one slab to the next the
            // vehicles keep nearly the same order, so an insertion sort of the previous
            // slab's order does almost no moves; the first slab starts from a full sort.
            if k == 0 {
                self.sweep
                    .sort_unstable_by(|a, b| a.lo[axis].total_cmp(&b.lo[axis]));
            } else {
                insertion_sort(&mut self.sweep, axis);
            }
            for (p, a) in self.sweep.iter().enumerate() {
                let limit = a.hi[axis] + guarded;
                for b in &self.sweep[p + 1..] {
                    // A box of a vehicle without samples is at infinity: it ends every sweep
                    // before it is tested.
                    if b.lo[axis] >= limit {
                        break;
                    }
                    if sweep_gap2(a, b) < r2
                        && self.chords_within(a.v as usize, self, b.v as usize, k, reach)
                    {
                        pairs.mark(a.v as usize, b.v as usize, k);
                    }
                }
            }
        }
    }

    /// The axis along which slab `k`'s box centres spread most: the sweep's axis (any axis
    /// gives the same pairs; the widest makes the fewest boxes overlap along it).
    fn widest_axis(&self, k: usize) -> usize {
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for v in 0..self.len() {
            let c = self.lo[v * SLABS + k] + self.hi[v * SLABS + k];
            if c.iter().all(|x| x.is_finite()) {
                lo = lower_corner(&lo, &c);
                hi = upper_corner(&hi, &c);
            }
        }
        let spread = hi - lo;
        if spread.iter().any(|x| !x.is_finite()) {
            return 0;
        }
        spread.imax()
    }
}

/// The box of every position a trajectory through `points` takes (it is piecewise linear and
/// holds at its ends, so the box of its samples): every slab box of it lies inside. A
/// trajectory without samples is nowhere, a box at infinity no other box comes near.
pub fn extent(points: &[Vec3]) -> (Vec3, Vec3) {
    let Some(first) = points.first() else {
        let far = Vec3::repeat(f64::INFINITY);
        return (far, far);
    };
    points.iter().fold((*first, *first), |(lo, hi), p| {
        (lower_corner(&lo, p), upper_corner(&hi, p))
    })
}

/// Whether boxes `a` and `b` (lower, upper corner) are closer than `reach`, by the test the
/// slab boxes use: false for two [`extent`]s proves that no slab box of the one comes within
/// `reach` of one of the other.
pub fn boxes_within(a: &(Vec3, Vec3), b: &(Vec3, Vec3), reach: f64) -> bool {
    gap2(&a.0, &a.1, &b.0, &b.1) < guarded2(reach)
}

/// How much farther than asked the broad phase looks, metres: the narrow phase computes
/// positions with other roundings, so a pair whose closest approach is `reach` to the last
/// bit is kept rather than pruned.
const REACH_GUARD_M: f64 = 1e-6;

/// Whether the straight run from `d0` to `d1` passes at least `limit` from the origin, without
/// a division (the closest point's parameter is a ratio, compared here multiplied out).
#[inline]
fn run_apart(d0: &Vec3, d1: &Vec3, limit: f64) -> bool {
    let limit2 = limit * limit;
    let step = d1 - d0;
    let along = d0.dot(&step);
    if along >= 0.0 {
        return d0.norm_squared() >= limit2;
    }
    if d1.dot(&step) <= 0.0 {
        return d1.norm_squared() >= limit2;
    }
    // The closest point is inside: |d0|² − along² / |step|² ≥ limit², times |step|² > 0.
    let len2 = step.norm_squared();
    d0.norm_squared() * len2 - along * along >= limit2 * len2
}

/// `(reach + guard)²`.
fn guarded2(reach: f64) -> f64 {
    let r = reach + REACH_GUARD_M;
    r * r
}

/// Sorts by the lower end along `axis`, ascending. Linear on an order that is already nearly
/// sorted, which is what the slabs give.
fn insertion_sort(items: &mut [SweepBox], axis: usize) {
    for i in 1..items.len() {
        let item = items[i];
        let key = item.lo[axis];
        let mut j = i;
        while j > 0 && items[j - 1].lo[axis] > key {
            items[j] = items[j - 1];
            j -= 1;
        }
        items[j] = item;
    }
}

/// Squared distance between two axis-aligned boxes (0 when they overlap; infinite for a box of
/// a vehicle without samples).
#[inline]
fn gap2(lo_a: &Vec3, hi_a: &Vec3, lo_b: &Vec3, hi_b: &Vec3) -> f64 {
    let mut s = 0.0;
    for d in 0..3 {
        let g = (lo_a[d] - hi_b[d]).max(lo_b[d] - hi_a[d]);
        if g > 0.0 {
            s += g * g;
        } else if g.is_nan() {
            return f64::INFINITY;
        }
    }
    s
}

/// Position at `t` of the trajectory through `points` at `times`, advancing the leg cursor
/// `seg` (the last sample at or before `t`); held before the first and after the last sample.
fn position(times: &[f64], points: &[Vec3], seg: &mut usize, t: f64) -> Vec3 {
    let n = times.len().min(points.len());
    while *seg + 1 < n && times[*seg + 1] <= t {
        *seg += 1;
    }
    position_on_leg(times, points, *seg, t)
}

/// Position at `t` on the leg from sample `i`, the last at or before `t` (held at the last
/// sample, and at sample `i` before its time).
#[inline]
fn position_on_leg(times: &[f64], points: &[Vec3], i: usize, t: f64) -> Vec3 {
    let n = times.len().min(points.len());
    if i + 1 >= n || t <= times[i] {
        return points[i];
    }
    let dt = times[i + 1] - times[i];
    if dt <= 0.0 {
        return points[i + 1];
    }
    points[i] + (points[i + 1] - points[i]) * ((t - times[i]) / dt)
}

/// Fixed vehicles' slab boxes indexed for one moving vehicle: an agent's followers, the
/// touch-up and a replan score one vehicle's candidate paths against the same others thousands
/// of times. Per slab the others' boxes are sorted along the axis where they spread most, so a
/// candidate's box finds the others that may come near it by bisection, not by testing every
/// other vehicle.
#[derive(Debug, Clone, Default)]
pub struct SlabIndex {
    /// The sort axis.
    axis: usize,
    /// Vehicles indexed.
    n: usize,
    /// Slab-major: slab `k`'s (lower end along the axis, vehicle) at `k * n ..`, ascending.
    order: Vec<(f64, u32)>,
    /// Per slab, the longest box along the axis (the farthest a box's upper end lies past its
    /// lower end).
    longest: Vec<f64>,
}

impl SlabIndex {
    /// Indexes every vehicle of `boxes`.
    pub fn new(boxes: &SlabBoxes) -> SlabIndex {
        let n = boxes.len();
        let axis = boxes.widest_axis(SLABS / 2);
        let mut order = Vec::with_capacity(n * SLABS);
        let mut longest = vec![0.0f64; SLABS];
        for (k, longest) in longest.iter_mut().enumerate() {
            let start = order.len();
            for v in 0..n {
                let (lo, hi) = (boxes.lo[v * SLABS + k][axis], boxes.hi[v * SLABS + k][axis]);
                if lo.is_finite() && hi.is_finite() {
                    order.push((lo, v as u32));
                    *longest = longest.max(hi - lo);
                }
                // A vehicle without samples (or a box that is not finite) is never near
                // anything ([`gap2`]), so it is left out.
            }
            order[start..].sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            // Pad to `n` per slab, past every finite key.
            order.resize(start + n, (f64::INFINITY, u32::MAX));
        }
        SlabIndex {
            axis,
            n,
            order,
            longest,
        }
    }

    /// Marks in `near` (cleared and sized to the indexed vehicles) every indexed vehicle whose
    /// box of some slab is closer than `reach` to vehicle `v`'s box of that slab in `own`
    /// (with the same horizon as `indexed`, the boxes this index was built from): the vehicles
    /// [`SlabBoxes::near_other`] finds near, by the same test.
    pub fn near(
        &self,
        indexed: &SlabBoxes,
        own: &SlabBoxes,
        v: usize,
        reach: f64,
        near: &mut Vec<bool>,
    ) {
        near.clear();
        near.resize(self.n, false);
        let r2 = guarded2(reach);
        // Looser than the exact test, so no box it keeps is missed by the bisection.
        let slack = r2.sqrt() + 1e-6;
        for k in 0..SLABS {
            let (lo, hi) = (&own.lo[v * SLABS + k], &own.hi[v * SLABS + k]);
            let slab = &self.order[k * self.n..(k + 1) * self.n];
            let from = lo[self.axis] - slack - self.longest[k];
            let to = hi[self.axis] + slack;
            let first = slab.partition_point(|e| e.0 < from);
            for &(key, other) in &slab[first..] {
                if key > to || other == u32::MAX {
                    break;
                }
                if !near[other as usize]
                    && own.slab_near(v, indexed, other as usize, k, (r2, reach))
                {
                    near[other as usize] = true;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
