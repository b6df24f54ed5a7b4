//! Vector arithmetic on `[f64; 3]` points, point–segment distance and segment–sphere chords:
//! what the turn and pitch of legs and the timed trajectories both build on.

/// A point, metres.
pub type P3 = [f64; 3];

/// `a − b`.
pub fn sub(a: &P3, b: &P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Dot product.
pub fn dot(a: &P3, b: &P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Euclidean norm.
pub fn norm(a: &P3) -> f64 {
    dot(a, a).sqrt()
}

/// Distance between two points.
pub fn dist(a: &P3, b: &P3) -> f64 {
    norm(&sub(a, b))
}

/// `a + (b − a) s`.
pub fn lerp(a: &P3, b: &P3, s: f64) -> P3 {
    [
        a[0] + (b[0] - a[0]) * s,
        a[1] + (b[1] - a[1]) * s,
        a[2] + (b[2] - a[2]) * s,
    ]
}

/// Parameter in `[0, 1]` of the point of segment `a→b` closest to `p` (0 for a point).
pub fn closest_param(a: &P3, b: &P3, p: &P3) -> f64 {
    let k = sub(b, a);
    let kk = dot(&k, &k);
    if kk == 0.0 {
        return 0.0;
    }
    (dot(&sub(p, a), &k) / kk).clamp(0.0, 1.0)
}

/// Shortest distance from `p` to the segment `a→b`.
pub fn segment_point_distance(a: &P3, b: &P3, p: &P3) -> f64 {
    dist(&lerp(a, b, closest_param(a, b, p)), p)
}

/// Length of the part of segment `a→b` strictly inside the sphere (`c`, `r`).
pub fn chord_inside_sphere(a: &P3, b: &P3, c: &P3, r: f64) -> f64 {
    let len = dist(a, b);
    if len == 0.0 {
        return 0.0;
    }
    let (s0, s1) = param_interval_within(a, b, c, r);
    (s1 - s0).max(0.0) * len
}

/// The sub-interval `[s0, s1]` of `[0, 1]` on which `a + (b − a) s` is within `r` of `c`
/// (`s1 <= s0` when there is none). For a degenerate segment: all of `[0, 1]` or nothing.
pub fn param_interval_within(a: &P3, b: &P3, c: &P3, r: f64) -> (f64, f64) {
    let k = sub(b, a);
    let f = sub(a, c);
    let qa = dot(&k, &k);
    let qb = 2.0 * dot(&k, &f);
    let qc = dot(&f, &f) - r * r;
    if qa == 0.0 {
        return if qc < 0.0 { (0.0, 1.0) } else { (0.0, 0.0) };
    }
    let disc = qb * qb - 4.0 * qa * qc;
    if disc <= 0.0 {
        return (0.0, 0.0);
    }
    let sq = disc.sqrt();
    let lo = ((-qb - sq) / (2.0 * qa)).max(0.0);
    let hi = ((-qb + sq) / (2.0 * qa)).min(1.0);
    (lo, hi)
}
