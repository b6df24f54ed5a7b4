//! Fixed vehicles' slab boxes indexed for one moving vehicle: an agent's followers, the
//! touch-up and a replan score one vehicle's candidate paths against the same others thousands
//! of times. Per slab the others' boxes are sorted along one axis, so a candidate's box finds
//! the others that may come near it by bisection, not by testing every other vehicle.

use super::{gap2, guarded2, SlabBoxes, SLABS};

/// The boxes of a [`SlabBoxes`] sorted per slab along the axis where they spread most.
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
                let j = other as usize * SLABS + k;
                if !near[other as usize] && gap2(lo, hi, &indexed.lo[j], &indexed.hi[j]) < r2 {
                    near[other as usize] = true;
                }
            }
        }
    }
}
