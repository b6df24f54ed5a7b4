//! The limits of one vehicle's path as smooth inequality rows `c(P) ≤ 0` with their analytic
//! gradients in the path's inner waypoints: what the refinement's quadratic programs linearise.
//!
//! Every row is dimensionless (a sine, a cosine or a distance over its limit), so one penalty
//! weight on the rows' slacks weighs a metre of separation and a degree of pitch alike, as the
//! fleet fitness's own penalties do (`1 + excess / limit`, Zhi & Zuo 2024, §3.3.1).
//!
//! The waypoints are the variables; the start and the goal are fixed. Variable `3 (k − 1) + c`
//! is coordinate `c` of point `k` of the path (points `1..=M` are the inner waypoints).

use crate::cost::Sphere;
use crate::geometry::{closest_param, polyline_length, Vec3, CONTACT_GUARD_M, MIN_HEADING_EXTENT};
use crate::trajectory::Trajectory;

/// One linearised limit: its value at the current path (≤ 0 keeps it) and its sparse gradient.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// `c(P)`; positive is a breach.
    pub value: f64,
    /// `(variable, ∂c/∂variable)` pairs, each variable once.
    pub gradient: Vec<(usize, f64)>,
}

impl Row {
    fn new(value: f64) -> Row {
        Row {
            value,
            gradient: Vec::with_capacity(9),
        }
    }

    /// Adds `g` to the gradient of point `k`'s coordinates, if point `k` is a variable.
    fn add(&mut self, k: usize, inner: usize, g: Vec3) {
        if k == 0 || k > inner {
            return;
        }
        for c in 0..3 {
            let var = 3 * (k - 1) + c;
            match self.gradient.iter_mut().find(|(v, _)| *v == var) {
                Some((_, d)) => *d += g[c],
                None => self.gradient.push((var, g[c])),
            }
        }
    }
}

/// The limits with the margins the refinement keeps inside them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest |pitch|, radians, margin taken off.
    pub max_pitch: f64,
    /// Largest heading change between horizontal legs, radians, margin taken off.
    pub max_turn: f64,
    /// Metres added to every hard sphere's inflated radius.
    pub clearance_margin: f64,
    /// Closest the others may come, metres (d_min plus a margin).
    pub separation: f64,
    /// The fleet's d_min, metres: the scale of the separation rows.
    pub d_min: f64,
}

/// Rows whose value is below this are left out of a program: far from binding.
const FAR: f64 = -0.5;

/// Pitch rows: `|Δz| / |Δ| − sin φ ≤ 0` per leg (the pitch test of the fleet fitness, as a sine).
pub fn pitch_rows(points: &[Vec3], limits: &Limits, rows: &mut Vec<Row>) {
    let inner = points.len().saturating_sub(2);
    let sin_max = limits.max_pitch.sin();
    for (k, w) in points.windows(2).enumerate() {
        let d = w[1] - w[0];
        let n = d.norm();
        if n <= 1e-9 {
            continue;
        }
        let sign = if d.z >= 0.0 { 1.0 } else { -1.0 };
        let mut row = Row::new(sign * d.z / n - sin_max);
        if row.value < FAR {
            continue;
        }
        // ∂(d_z / |d|)/∂d = e_z / |d| − d_z d / |d|³.
        let g = (Vec3::z() / n - d * (d.z / (n * n * n))) * sign;
        row.add(k + 1, inner, g);
        row.add(k, inner, -g);
        rows.push(row);
    }
}

/// Turn rows: `cos θ_max − cos θ ≤ 0` for every heading change between consecutive legs with a
/// horizontal extent (legs without one are skipped, as the fleet fitness's turn test does).
pub fn turn_rows(points: &[Vec3], limits: &Limits, rows: &mut Vec<Row>) {
    let inner = points.len().saturating_sub(2);
    let cos_max = limits.max_turn.cos();
    let flat = |v: Vec3| Vec3::new(v.x, v.y, 0.0);
    let mut previous: Option<(usize, Vec3)> = None;
    for (k, w) in points.windows(2).enumerate() {
        let b = flat(w[1] - w[0]);
        let nb = b.norm();
        if nb <= MIN_HEADING_EXTENT {
            continue;
        }
        if let Some((j, a)) = previous {
            let na = a.norm();
            let cos = a.dot(&b) / (na * nb);
            let mut row = Row::new(cos_max - cos);
            // ∂cos/∂a = b / (|a||b|) − cos a / |a|², and alike for b; the row is −cos.
            let ga = -(b / (na * nb) - a * (cos / (na * na)));
            let gb = -(a / (na * nb) - b * (cos / (nb * nb)));
            row.add(j + 1, inner, ga);
            row.add(j, inner, -ga);
            row.add(k + 1, inner, gb);
            row.add(k, inner, -gb);
            rows.push(row);
        }
        previous = Some((k, b));
    }
}

/// The turn off a vehicle's present course `heading` onto the path, for a path that starts
/// under way: `cos θ_max − cos θ ≤ 0` between the heading's horizontal part and the first leg
/// with a horizontal extent (as the fitness's entry turn test), `None` when either has none or
/// the leg ends at the fixed goal.
pub fn entry_turn_row(heading: Vec3, points: &[Vec3], limits: &Limits) -> Option<Row> {
    let inner = points.len().saturating_sub(2);
    let a = Vec3::new(heading.x, heading.y, 0.0);
    let first = points.first()?;
    let na = a.norm();
    if na <= MIN_HEADING_EXTENT {
        return None;
    }
    let (k, b) = points.iter().enumerate().skip(1).find_map(|(k, p)| {
        let b = Vec3::new(p.x - first.x, p.y - first.y, 0.0);
        (b.norm() > MIN_HEADING_EXTENT).then_some((k, b))
    })?;
    if k > inner {
        return None;
    }
    let nb = b.norm();
    let cos = a.dot(&b) / (na * nb);
    let mut row = Row::new(limits.max_turn.cos() - cos);
    let gb = -(a / (na * nb) - b * (cos / (nb * nb)));
    row.add(k, inner, gb);
    Some(row)
}

/// Spacing rows: `(h_min − h) / h_min ≤ 0` for every leg whose horizontal extent `h` could fall
/// under its floor `floors[k]`. A length objective alone lets neighbouring waypoints run
/// together, and a leg of a few centimetres can swing its heading round in one step: the turns
/// at its ends, which the turn rows see only to first order, then jump past any limit.
pub fn spacing_rows(points: &[Vec3], floors: &[f64], rows: &mut Vec<Row>) {
    let inner = points.len().saturating_sub(2);
    for ((k, w), floor) in points.windows(2).enumerate().zip(floors) {
        let d = Vec3::new(w[1].x - w[0].x, w[1].y - w[0].y, 0.0);
        let h = d.norm();
        if *floor <= 0.0 || h <= 1e-9 {
            continue;
        }
        let mut row = Row::new((floor - h) / floor);
        if row.value < FAR {
            continue;
        }
        let g = -d / (h * floor);
        row.add(k + 1, inner, g);
        row.add(k, inner, -g);
        rows.push(row);
    }
}

/// The floors [`spacing_rows`] keeps: a third of the mean horizontal leg, or half of a leg
/// already shorter than that.
pub fn spacing_floors(points: &[Vec3]) -> Vec<f64> {
    let extents: Vec<f64> = points
        .windows(2)
        .map(|w| (w[1].x - w[0].x).hypot(w[1].y - w[0].y))
        .collect();
    let mean = extents.iter().sum::<f64>() / extents.len().max(1) as f64;
    extents.iter().map(|h| (mean / 3.0).min(0.5 * h)).collect()
}

/// Hard-obstacle rows: `(r + margin − distance(leg, centre)) / r ≤ 0` for every leg that comes
/// within `reach` metres of a sphere's surface.
pub fn hard_rows(
    points: &[Vec3],
    hard: &[Sphere],
    limits: &Limits,
    reach: f64,
    rows: &mut Vec<Row>,
) {
    let inner = points.len().saturating_sub(2);
    for s in hard {
        let keep = s.radius + CONTACT_GUARD_M + limits.clearance_margin;
        for (k, w) in points.windows(2).enumerate() {
            let u = closest_param(&w[0], &w[1], &s.centre);
            let q = w[0] + (w[1] - w[0]) * u;
            let away = q - s.centre;
            let distance = away.norm();
            if distance > keep + reach || distance <= 1e-9 {
                continue;
            }
            let mut row = Row::new((keep - distance) / s.radius);
            // The closest point moves with the leg's ends in the ratio (1 − u) : u; its own
            // slide along the leg does not change the distance to first order.
            let g = -away / (distance * s.radius);
            row.add(k, inner, g * (1.0 - u));
            row.add(k + 1, inner, g * u);
            rows.push(row);
        }
    }
}

/// Soft-obstacle rows: `(r − distance(leg, centre)) / r ≤ 0` for every leg that is outside a
/// soft sphere and within `reach` metres of its surface. F(O) pays the chord a leg cuts through
/// the sphere, which grows as the square root of the depth it dips in: its gradient at the
/// surface is unbounded and a difference gradient taken outside does not see it, so a step
/// that shortens a path past a soft sphere would dip in and be refused. A leg already inside
/// one has no row: F(O) itself pulls it out.
pub fn soft_rows(points: &[Vec3], soft: &[Sphere], reach: f64, rows: &mut Vec<Row>) {
    let inner = points.len().saturating_sub(2);
    for s in soft {
        for (k, w) in points.windows(2).enumerate() {
            let u = closest_param(&w[0], &w[1], &s.centre);
            let away = w[0] + (w[1] - w[0]) * u - s.centre;
            let distance = away.norm();
            if distance <= s.radius || distance > s.radius + reach {
                continue;
            }
            let mut row = Row::new((s.radius - distance) / s.radius);
            let g = -away / (distance * s.radius);
            row.add(k, inner, g * (1.0 - u));
            row.add(k + 1, inner, g * u);
            rows.push(row);
        }
    }
}

/// Separation rows against one other vehicle: `(separation − |p(t) − q(t)|) / d_min ≤ 0` at
/// the sample times (every `step` seconds to the later arrival) where the distance has a local
/// minimum within `reach` metres of the limit: the closest approaches, which a small change of
/// path moves by a sample or two, not the whole stretch the two spend near each other.
/// `p(t)` is this vehicle's position on its leg at the fraction its timing gives; the fraction
/// is held fixed in the gradient (a path change also retimes the vehicle; the refinement's
/// acceptance test on the true fitness answers for that).
///
/// Only the samples within `windows` (ascending, apart; `(0, ∞)` for the whole mission) are
/// looked at, each tested against its neighbours as in a sweep of the whole mission: windows
/// outside which the two are known to stay farther than `separation + reach` apart (the
/// broad phase's near slabs) give the same rows.
pub fn separation_rows(
    mine: &Trajectory,
    other: &Trajectory,
    limits: &Limits,
    step: f64,
    reach: f64,
    windows: &[(f64, f64)],
    rows: &mut Vec<Row>,
) {
    let inner = mine.points.len().saturating_sub(2);
    let end = mine.arrival().max(other.arrival());
    if mine.times.len() < 2 || step <= 0.0 {
        return;
    }
    let samples = (end / step).ceil() as usize;
    let at = |s: usize| {
        let t = (s as f64 * step).min(end);
        let (k, u) = leg_at(mine, t);
        let p = mine.points[k] + (mine.points[k + 1] - mine.points[k]) * u;
        (k, u, p - other.position_at(t))
    };
    let mut unvisited = 0;
    for &(from, to) in windows {
        // A sample either side to spare: the window's edges are rounded to samples.
        let first = ((from / step).floor().max(0.0) as usize)
            .saturating_sub(1)
            .max(unvisited);
        let last = ((to / step).ceil().min(samples as f64) as usize + 1).min(samples);
        if first > last {
            continue;
        }
        unvisited = last + 1;
        let mut previous = match first {
            0 => f64::INFINITY,
            s => at(s - 1).2.norm(),
        };
        let mut current = at(first);
        for s in first..=last {
            let next = if s < samples { Some(at(s + 1)) } else { None };
            let (k, u, away) = current;
            let distance = away.norm();
            let following = next.map_or(f64::INFINITY, |n| n.2.norm());
            let closest = distance <= previous && distance <= following;
            if closest && distance <= limits.separation + reach && distance > 1e-9 {
                let mut row = Row::new((limits.separation - distance) / limits.d_min);
                let g = -away / (distance * limits.d_min);
                row.add(k, inner, g * (1.0 - u));
                row.add(k + 1, inner, g * u);
                rows.push(row);
            }
            previous = distance;
            match next {
                Some(n) => current = n,
                None => break,
            }
        }
    }
}

/// The whole mission, as [`separation_rows`]' windows.
pub const WHOLE_MISSION: [(f64, f64); 1] = [(0.0, f64::INFINITY)];

/// The leg a trajectory is on at time `t` and the fraction of it done (the last leg, complete,
/// after the arrival).
fn leg_at(trajectory: &Trajectory, t: f64) -> (usize, f64) {
    let n = trajectory.times.len();
    let k = trajectory
        .times
        .partition_point(|&s| s <= t)
        .clamp(1, n - 1);
    let (t0, t1) = (trajectory.times[k - 1], trajectory.times[k]);
    let u = if t1 > t0 {
        ((t - t0) / (t1 - t0)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    (k - 1, u)
}

/// Length row: `(L − limit) / limit ≤ 0` (`sign` +1) or `(limit − L) / limit ≤ 0` (`sign` −1),
/// for a path that must arrive by a time at its top speed, or not before it at its slowest.
pub fn length_row(points: &[Vec3], limit: f64, sign: f64) -> Option<Row> {
    let inner = points.len().saturating_sub(2);
    let length = polyline_length(points);
    let mut row = Row::new(sign * (length - limit) / limit);
    if row.value < FAR * 0.1 {
        return None;
    }
    for (k, w) in points.windows(2).enumerate() {
        let d = w[1] - w[0];
        let n = d.norm();
        if n > 1e-12 {
            let g = d * (sign / (n * limit));
            row.add(k + 1, inner, g);
            row.add(k, inner, -g);
        }
    }
    Some(row)
}

#[cfg(test)]
mod tests;
