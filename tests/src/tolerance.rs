//! How close is equal: the slack the checker allows between a reported figure and its own.

/// Absolute slack for float noise (metres, seconds, degrees, m/s); also used as relative slack.
pub const TOL: f64 = 1e-6;

/// Absolute slack for separation figures, metres (and seconds for the breach time).
pub const SEPARATION_TOL: f64 = 1e-3;

/// Largest arrival spread of a feasible plan, seconds.
pub const MAX_ARRIVAL_SPREAD_S: f64 = 1.0;

/// True when `a` and `b` agree within `abs` or within [`TOL`] relative.
pub fn close(a: f64, b: f64, abs: f64) -> bool {
    if a == b {
        return true;
    }
    (a - b).abs() <= abs.max(TOL * a.abs().max(b.abs()))
}
