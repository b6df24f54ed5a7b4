//! Sharing the inspection points among several AUVs with balanced tours (not in Hu et al. 2023, which
//! plans one vehicle; Shoal's fleets need it).
//!
//! 1. Sweep: the points are sorted by their horizontal bearing from the base and the circle is cut
//!    at the widest empty sector, so neighbours in the sequence are neighbours around the base.
//! 2. Split: the sequence is cut into `n` contiguous runs minimising the longest tour (dynamic
//!    programming over all cuts), a run's tour being estimated by [`short_tour`].
//! 3. Balance: single points are moved, or pairs swapped, from the vehicle with the longest tour
//!    to another while that shortens the longest tour (then the total), until no move helps.
//!
//! Tour lengths here are straight-line (cage detours are only known after leg planning); each
//! vehicle's share then goes through [`super::plan_tour`] on its own.

use crate::geometry::Vec3;

use super::cages::InspectionPoint;
use super::order::{distance_matrix, open_order_length, two_opt};

/// A short closed tour from `base` through `points` (nearest neighbour, then 2-opt): the indices
/// into `points` in visiting order, and the tour's straight-line length.
pub fn short_tour(base: Vec3, points: &[Vec3]) -> (Vec<usize>, f64) {
    let nodes: Vec<Vec3> = std::iter::once(base)
        .chain(points.iter().copied())
        .collect();
    let dist = distance_matrix(&nodes);
    let mut left: Vec<usize> = (1..nodes.len()).collect();
    let mut order = Vec::with_capacity(left.len());
    let mut at = 0;
    while !left.is_empty() {
        let (k, _) = left
            .iter()
            .enumerate()
            .fold((0, f64::INFINITY), |best, (k, &j)| {
                if dist[at][j] < best.1 {
                    (k, dist[at][j])
                } else {
                    best
                }
            });
        at = left.swap_remove(k);
        order.push(at);
    }
    two_opt(&dist, &mut order);
    let length = open_order_length(&dist, &order);
    (order.into_iter().map(|k| k - 1).collect(), length)
}

/// Splits `points` among `n_vehicles` AUVs starting and ending at `base`, balancing their tour
/// lengths (see the module notes). Returns, per vehicle, indices into `points` in a good visiting
/// order; every point appears exactly once. No vehicle: an empty list.
pub fn split_points(points: &[InspectionPoint], base: Vec3, n_vehicles: usize) -> Vec<Vec<usize>> {
    if n_vehicles == 0 {
        return Vec::new();
    }
    let sweep = sweep_order(points, base);
    let mut groups = contiguous_split(points, base, &sweep, n_vehicles);
    balance(points, base, &mut groups);
    groups
        .into_iter()
        .map(|g| {
            let pos: Vec<Vec3> = g.iter().map(|&i| points[i].position).collect();
            short_tour(base, &pos).0.into_iter().map(|k| g[k]).collect()
        })
        .collect()
}

/// Indices of `points` by bearing from `base`, starting after the widest empty sector.
fn sweep_order(points: &[InspectionPoint], base: Vec3) -> Vec<usize> {
    let bearing = |p: &InspectionPoint| {
        let (dx, dy) = (p.position.x - base.x, p.position.y - base.y);
        if dx.hypot(dy) <= 1e-9 {
            0.0
        } else {
            dy.atan2(dx)
        }
    };
    let mut idx: Vec<usize> = (0..points.len()).collect();
    idx.sort_by(|&a, &b| {
        bearing(&points[a])
            .total_cmp(&bearing(&points[b]))
            .then(a.cmp(&b))
    });
    let n = idx.len();
    if n < 2 {
        return idx;
    }
    let gap = |k: usize| {
        let (a, b) = (bearing(&points[idx[k]]), bearing(&points[idx[(k + 1) % n]]));
        (b - a).rem_euclid(std::f64::consts::TAU)
    };
    let widest = (0..n)
        .max_by(|&a, &b| gap(a).total_cmp(&gap(b)))
        .unwrap_or(n - 1);
    idx.rotate_left((widest + 1) % n);
    idx
}

/// Straight-line tour length of a group of points.
fn group_length(points: &[InspectionPoint], base: Vec3, group: &[usize]) -> f64 {
    let pos: Vec<Vec3> = group.iter().map(|&i| points[i].position).collect();
    short_tour(base, &pos).1
}

/// Cuts `sweep` into `k` contiguous runs minimising (longest tour, total length).
fn contiguous_split(
    points: &[InspectionPoint],
    base: Vec3,
    sweep: &[usize],
    k: usize,
) -> Vec<Vec<usize>> {
    let n = sweep.len();
    // cost[i][j]: tour over sweep[i..j].
    let mut cost = vec![vec![0.0; n + 1]; n + 1];
    for (i, row) in cost.iter_mut().enumerate() {
        for (j, c) in row.iter_mut().enumerate().skip(i + 1) {
            *c = group_length(points, base, &sweep[i..j]);
        }
    }
    // best[v][j] = (max, sum) for the first j points on v vehicles; cut[v][j] = start of run v.
    let inf = (f64::INFINITY, f64::INFINITY);
    let mut best = vec![vec![inf; n + 1]; k + 1];
    let mut cut = vec![vec![0usize; n + 1]; k + 1];
    best[0][0] = (0.0, 0.0);
    for v in 1..=k {
        for j in 0..=n {
            for i in 0..=j {
                let (m, s) = best[v - 1][i];
                if !m.is_finite() {
                    continue;
                }
                let cand = (m.max(cost[i][j]), s + cost[i][j]);
                let b = best[v][j];
                if cand.0 < b.0 - 1e-9 || (cand.0 <= b.0 + 1e-9 && cand.1 < b.1 - 1e-9) {
                    best[v][j] = cand;
                    cut[v][j] = i;
                }
            }
        }
    }
    let mut groups = vec![Vec::new(); k];
    let mut j = n;
    for v in (1..=k).rev() {
        let i = cut[v][j];
        groups[v - 1] = sweep[i..j].to_vec();
        j = i;
    }
    groups
}

/// (longest tour, total) of an assignment.
fn score(lengths: &[f64]) -> (f64, f64) {
    (
        lengths.iter().copied().fold(0.0, f64::max),
        lengths.iter().sum(),
    )
}

fn better(a: (f64, f64), b: (f64, f64)) -> bool {
    a.0 < b.0 - 1e-9 || (a.0 <= b.0 + 1e-9 && a.1 < b.1 - 1e-9)
}

/// An improving exchange between the longest tour and `other`: both groups' new contents and
/// tour lengths.
struct Exchange {
    from: Vec<usize>,
    to: Vec<usize>,
    other: usize,
    from_len: f64,
    to_len: f64,
}

/// Local search: moves and swaps out of the longest tour while the score improves.
fn balance(points: &[InspectionPoint], base: Vec3, groups: &mut [Vec<usize>]) {
    let mut lengths: Vec<f64> = groups
        .iter()
        .map(|g| group_length(points, base, g))
        .collect();
    for _ in 0..10 * points.len().max(1) {
        let current = score(&lengths);
        let Some(long) = (0..groups.len()).max_by(|&a, &b| lengths[a].total_cmp(&lengths[b]))
        else {
            return;
        };
        let mut found: Option<Exchange> = None;
        'search: for other in (0..groups.len()).filter(|&o| o != long) {
            for a in 0..groups[long].len() {
                // Move, then every swap with a point of `other`.
                let swaps = std::iter::once(None).chain((0..groups[other].len()).map(Some));
                for b in swaps {
                    let mut from = groups[long].clone();
                    let mut to = groups[other].clone();
                    let p = from.remove(a);
                    if let Some(b) = b {
                        let q = to.remove(b);
                        from.push(q);
                    }
                    to.push(p);
                    let (lf, lt) = (
                        group_length(points, base, &from),
                        group_length(points, base, &to),
                    );
                    let mut trial = lengths.clone();
                    trial[long] = lf;
                    trial[other] = lt;
                    if better(score(&trial), current) {
                        found = Some(Exchange {
                            from,
                            to,
                            other,
                            from_len: lf,
                            to_len: lt,
                        });
                        break 'search;
                    }
                }
            }
        }
        let Some(e) = found else {
            return;
        };
        groups[long] = e.from;
        groups[e.other] = e.to;
        lengths[long] = e.from_len;
        lengths[e.other] = e.to_len;
    }
}

#[cfg(test)]
mod tests {
    use super::super::cages::{cage_group_a, inspection_points, Cage, FirstPoint};
    use super::*;

    fn lengths(points: &[InspectionPoint], base: Vec3, split: &[Vec<usize>]) -> Vec<f64> {
        split
            .iter()
            .map(|g| group_length(points, base, g))
            .collect()
    }

    fn assert_partition(split: &[Vec<usize>], n: usize) {
        let mut all: Vec<usize> = split.iter().flatten().copied().collect();
        all.sort_unstable();
        assert_eq!(all, (0..n).collect::<Vec<_>>());
    }

    #[test]
    fn every_point_is_assigned_exactly_once() {
        let pts = inspection_points(&cage_group_a(), 5.0, FirstPoint::Toward(Vec3::zeros()));
        for n in 1..=4 {
            let split = split_points(&pts, Vec3::zeros(), n);
            assert_eq!(split.len(), n);
            assert_partition(&split, pts.len());
        }
        assert!(split_points(&pts, Vec3::zeros(), 0).is_empty());
        assert_eq!(
            split_points(&[], Vec3::zeros(), 2),
            vec![Vec::<usize>::new(); 2]
        );
        // More vehicles than points: still a partition.
        assert_partition(&split_points(&pts[..3], Vec3::zeros(), 5), 3);
    }

    #[test]
    fn two_vehicles_on_a_symmetric_field_get_balanced_tours() {
        // Cages mirrored about the y axis, base on the axis: the halves are equal tours.
        let mut cages = Vec::new();
        for (i, (x, y, r)) in [
            (150.0, 200.0, 30.0),
            (300.0, 100.0, 40.0),
            (80.0, 400.0, 25.0),
        ]
        .into_iter()
        .enumerate()
        {
            cages.push(Cage::new(&format!("R{i}"), x, y, 50.0, r));
            cages.push(Cage::new(&format!("L{i}"), -x, y, 50.0, r));
        }
        let pts = inspection_points(&cages, 5.0, FirstPoint::Azimuth(0.0));
        let base = Vec3::new(0.0, -50.0, 50.0);
        let split = split_points(&pts, base, 2);
        assert_partition(&split, pts.len());
        let l = lengths(&pts, base, &split);
        let (lo, hi) = (l[0].min(l[1]), l[0].max(l[1]));
        assert!(lo > 0.0 && hi <= 1.2 * lo, "{l:?}");
        // Sharing pays: the longer of the two is shorter than one vehicle doing everything.
        let one = lengths(&pts, base, &split_points(&pts, base, 1))[0];
        assert!(hi < one, "{hi} vs {one}");
    }

    #[test]
    fn short_tour_of_a_square_by_hand() {
        let pts = [
            Vec3::new(0.0, 4.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(3.0, 4.0, 0.0),
        ];
        let (order, len) = short_tour(Vec3::zeros(), &pts);
        assert!((len - 14.0).abs() < 1e-12, "{len}");
        assert_eq!(order.len(), 3);
    }
}
