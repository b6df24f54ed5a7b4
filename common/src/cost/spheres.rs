//! The legs of a path against the obstacle spheres: the hard-obstacle penalty and the metres
//! inside soft spheres (F_i(O) of Zhi & Zuo 2024, eq. (9)), in one pass. A model's spheres are
//! indexed once ([`SphereIndex`]); a path is then tested only against the spheres the grid
//! lists near its box (one lookup per path: a lookup per chunk of legs cost more than the
//! chunk tests it spared), chunk by chunk, in the same order as against all of them, so the
//! sums are the same to the last bit.

use std::cell::RefCell;

use crate::broad_phase::spheres::SphereGrid;
use crate::geometry::{
    chord_inside_sphere, larger, lower_corner, upper_corner, Vec3, CONTACT_GUARD_M,
};

/// A sphere the cost functions test against: centre and radius already inflated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Centre, metres.
    pub centre: Vec3,
    /// Radius including the inflation margin, metres.
    pub radius: f64,
}

/// What the legs of a path do to the obstacles.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct SphereTerms {
    /// [`super::hard_penalty`]'s penalty.
    pub hard_penalty: f64,
    /// Leg × hard-sphere intrusions.
    pub hard_hits: usize,
    /// Metres inside soft spheres.
    pub soft_inside: f64,
}

/// Up to this many spheres a path meets all of them: the grid's lookups cost about as much as
/// the chunk boxes they spare (the paper's scenarios have 6–12).
const FEW_SPHERES: usize = 12;

/// Legs per bounding box in the cull.
const CHUNK_LEGS: usize = 6;

/// A model's hard and soft spheres with their horizontal grid (hard ones first, each with the
/// reach it is tested at).
#[derive(Debug, Clone, Default)]
pub(super) struct SphereIndex {
    /// The grid over every sphere, hard ones at indices `0..hard`, then the soft ones.
    grid: SphereGrid,
}

/// A chunk of legs' bounding box (lower, upper corner).
type ChunkBox = (Vec3, Vec3);

thread_local! {
    /// Chunk boxes and sphere marks, reused by every evaluation on this thread.
    static SCRATCH: RefCell<(Vec<ChunkBox>, Vec<u64>)> = const { RefCell::new((Vec::new(), Vec::new())) };
}

impl SphereIndex {
    /// Indexes `hard` then `soft`.
    pub fn new(hard: &[Sphere], soft: &[Sphere]) -> SphereIndex {
        let reaches: Vec<(Vec3, f64)> = hard
            .iter()
            .map(|s| (s.centre, s.radius + CONTACT_GUARD_M))
            .chain(soft.iter().map(|s| (s.centre, s.radius)))
            .collect();
        SphereIndex {
            grid: SphereGrid::new(&reaches),
        }
    }

    /// [`sphere_terms`] of `points` against `hard` and `soft` (the spheres this index was built
    /// from), testing only the spheres near the path.
    pub fn terms(&self, points: &[Vec3], hard: &[Sphere], soft: &[Sphere]) -> SphereTerms {
        if hard.len() + soft.len() <= FEW_SPHERES {
            return sphere_terms(points, hard, soft);
        }
        with_scratch(|boxes, marks| self.terms_with(points, hard, soft, boxes, marks))
    }

    fn terms_with(
        &self,
        points: &[Vec3],
        hard: &[Sphere],
        soft: &[Sphere],
        boxes: &mut Vec<ChunkBox>,
        marks: &mut Vec<u64>,
    ) -> SphereTerms {
        chunk_boxes(points, boxes);
        marks.clear();
        marks.resize(self.grid.words(), 0);
        if let Some(first) = boxes.first() {
            let (lo, hi) = boxes.iter().fold(*first, |(lo, hi), (l, h)| {
                (lower_corner(&lo, l), upper_corner(&hi, h))
            });
            self.grid.mark_near(&lo, &hi, marks);
        }
        let mut out = SphereTerms::default();
        for (w, &word) in marks.iter().enumerate() {
            let mut rest = word;
            while rest != 0 {
                let k = w * 64 + rest.trailing_zeros() as usize;
                rest &= rest - 1;
                match k.checked_sub(hard.len()) {
                    None => add_sphere(&mut out, points, boxes, &hard[k], true),
                    Some(j) => {
                        if let Some(s) = soft.get(j) {
                            add_sphere(&mut out, points, boxes, s, false);
                        }
                    }
                }
            }
        }
        out
    }
}

/// Every leg against every sphere. Legs are grouped in chunks of [`CHUNK_LEGS`] with a bounding
/// box each; a sphere that cannot reach a chunk's box skips all its legs at once. The others get
/// the exact squared distance, and roots and chords are taken only on a hit.
pub(super) fn sphere_terms(points: &[Vec3], hard: &[Sphere], soft: &[Sphere]) -> SphereTerms {
    with_scratch(|boxes, _| {
        chunk_boxes(points, boxes);
        let mut out = SphereTerms::default();
        for s in hard {
            add_sphere(&mut out, points, boxes, s, true);
        }
        for s in soft {
            add_sphere(&mut out, points, boxes, s, false);
        }
        out
    })
}

/// Runs `f` on this thread's chunk boxes and sphere marks (fresh ones if they are in use).
fn with_scratch<T>(f: impl FnOnce(&mut Vec<ChunkBox>, &mut Vec<u64>) -> T) -> T {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => {
            let (boxes, marks) = &mut *scratch;
            f(boxes, marks)
        }
        Err(_) => f(&mut Vec::new(), &mut Vec::new()),
    })
}

/// The bounding box of every chunk of [`CHUNK_LEGS`] legs, into `boxes`.
fn chunk_boxes(points: &[Vec3], boxes: &mut Vec<ChunkBox>) {
    boxes.clear();
    let n_legs = points.len().saturating_sub(1);
    boxes.extend((0..n_legs).step_by(CHUNK_LEGS).map(|start| {
        let pts = &points[start..(start + CHUNK_LEGS + 1).min(points.len())];
        let lo = pts.iter().fold(pts[0], |m, p| lower_corner(&m, p));
        let hi = pts.iter().fold(pts[0], |m, p| upper_corner(&m, p));
        (lo, hi)
    }));
}

/// One sphere against every leg whose chunk box it can reach.
fn add_sphere(
    out: &mut SphereTerms,
    points: &[Vec3],
    boxes: &[ChunkBox],
    s: &Sphere,
    is_hard: bool,
) {
    let n_legs = points.len().saturating_sub(1);
    // Hard spheres are tested with the contact guard (see `CONTACT_GUARD_M`).
    let reach = if is_hard {
        s.radius + CONTACT_GUARD_M
    } else {
        s.radius
    };
    let r2 = reach * reach;
    for (chunk, (lo, hi)) in boxes.iter().enumerate() {
        if box_gap2(lo, hi, &s.centre) >= r2 {
            continue;
        }
        let start = chunk * CHUNK_LEGS;
        for j in start..(start + CHUNK_LEGS).min(n_legs) {
            let (a, b) = (points[j], points[j + 1]);
            let k = b - a;
            let len2 = k.norm_squared();
            let q = s.centre - a;
            let u = if len2 > 0.0 {
                (q.dot(&k) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d2 = (q - k * u).norm_squared();
            if d2 < r2 {
                if is_hard {
                    out.hard_penalty += 1.0 + ((s.radius - d2.sqrt()) / s.radius).max(0.0);
                    out.hard_hits += 1;
                } else {
                    out.soft_inside += chord_inside_sphere(&a, &b, &s.centre, s.radius);
                }
            }
        }
    }
}

/// Squared distance from `c` to the box `[lo, hi]` (0 inside): the value of
/// `(lo - c).sup(&(c - hi)).sup(&0).norm_squared()` to the last bit, NaN included (simba's
/// `simd_max` is the same comparison), in plain scalar comparisons, which the 32-vehicle
/// crossing swarm measured 3–4 % faster as a whole.
#[inline]
fn box_gap2(lo: &Vec3, hi: &Vec3, c: &Vec3) -> f64 {
    let mut s = 0.0;
    for d in 0..3 {
        let g = larger(larger(lo[d] - c[d], c[d] - hi[d]), 0.0);
        s += g * g;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_box_gap_by_hand() {
        let (lo, hi) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(10.0, 20.0, 30.0));
        // Inside: no gap.
        assert_eq!(box_gap2(&lo, &hi, &Vec3::new(5.0, 5.0, 5.0)), 0.0);
        // 3 m west, 4 m north of the box, level with it: 5 m.
        assert!((box_gap2(&lo, &hi, &Vec3::new(-3.0, 24.0, 15.0)) - 25.0).abs() < 1e-12);
        // Below a corner by (1, 2, 2): 3 m.
        assert!((box_gap2(&lo, &hi, &Vec3::new(11.0, -2.0, -2.0)) - 9.0).abs() < 1e-12);
    }

    proptest! {
        /// The same as nalgebra's component-wise form, to the last bit, NaN included.
        #[test]
        fn a_box_gap_is_nalgebras(
            a in prop::array::uniform3(prop_oneof![-1e4..1e4f64, Just(f64::NAN)]),
            b in prop::array::uniform3(-1e4..1e4f64),
            c in prop::array::uniform3(prop_oneof![-1e4..1e4f64, Just(f64::NAN)]),
        ) {
            let (a, b, c) = (Vec3::from(a), Vec3::from(b), Vec3::from(c));
            let (lo, hi) = (a.inf(&b), a.sup(&b));
            let reference = (lo - c).sup(&(c - hi)).sup(&Vec3::zeros()).norm_squared();
            let ours = box_gap2(&lo, &hi, &c);
            prop_assert!(ours.to_bits() == reference.to_bits() || (ours.is_nan() && reference.is_nan()),
                "{} against {}", ours, reference);
        }
    }
}
