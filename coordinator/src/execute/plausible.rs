//! Plausibility of what fleet members and clients send during an execution. The network's
//! access rules decide who may publish on a key; these checks catch what a member that is
//! allowed to publish (or anyone, on an unsecured lab network) sends that cannot be true:
//!
//! - a telemetry fix farther from the vehicle's last accepted fix than it could have moved,
//!   outside the scenario's bounds, stamped with a mission time far from the coordinator's
//!   clock, or numbered far ahead of what its telemetry rate could have produced;
//! - a published obstacle larger than the whole navigation space or far outside it, one whose
//!   id is already known, one past the per-mission cap, or one over the rate limit.
//!
//! Each is dropped before it touches the fleet picture — never a replan toward an impossible
//! place, never a vehicle "lost" because a forged report numbered past its real ones — counted
//! per reason ([`Refusals`], in the execution report) and reported as an event, at most once
//! per vehicle (or client key) and reason every [`EVENT_EVERY`].

use std::collections::HashMap;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use shoal_common::geometry::Vec3;
use shoal_common::limits;
use shoal_common::scenario::{Bounds, CurrentModel, Obstacle, Scenario};
use shoal_common::wire::open::Telemetry;

/// Fix noise allowed between two fixes on top of the distance a vehicle can drive, metres:
/// two independent fixes of a 2 m per-axis noise (the simulated link's default is 1 m) differ
/// by under 25 m at five standard deviations, and a forged fix worth steering for is hundreds
/// of metres off.
pub const JUMP_NOISE_M: f64 = 25.0;

/// Factor on a vehicle's top speed over the ground between two fixes: covers a current up to
/// the vehicle's own speed (the depth-decay surface current is added on top) and a fix taken a
/// little before its stamp.
pub const JUMP_SPEED_FACTOR: f64 = 2.0;

/// How far outside the scenario's bounds a fix may lie, metres (besides the deviation
/// tolerance): a vehicle tracking a plan that hugs a boundary, plus noise.
pub const BOUNDS_MARGIN_M: f64 = 100.0;

/// How far a report's mission time may be from the coordinator's clock when it came, in wall
/// seconds (times the time scale in mission seconds): delivery latency plus the skew of two
/// NTP-synchronised clocks, with a wide margin.
pub const CLOCK_OFFSET_WALL_S: f64 = 10.0;

/// Reports a vehicle's number may run ahead of its last accepted one besides twice what its
/// telemetry rate produces in the wall time between: reports dropped on a congested link.
pub const SEQ_SLACK: u64 = 100;

/// Shortest wall time between two events for one vehicle (or client) and reason.
pub const EVENT_EVERY: Duration = Duration::from_secs(10);

/// Why a report or an obstacle was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Reason {
    /// A fix farther from the last accepted one than the vehicle could have moved.
    Jump,
    /// A fix outside the scenario's bounds by more than the margin.
    OutOfBounds,
    /// A report numbered far ahead of the vehicle's last accepted one.
    SeqAhead,
    /// A report whose mission time is far from the coordinator's clock.
    ClockOff,
    /// An obstacle larger than the navigation space, or far outside it.
    ObstacleOutOfScale,
    /// An obstacle whose id is already known.
    ObstacleDuplicate,
    /// An obstacle past [`limits::MAX_PUBLISHED_OBSTACLES`].
    ObstacleCap,
    /// An obstacle over [`limits::MAX_OBSTACLES_PER_S`].
    ObstacleRate,
}

impl Reason {
    /// The reason's name in events and counts.
    pub fn name(self) -> &'static str {
        match self {
            Reason::Jump => "jump",
            Reason::OutOfBounds => "out_of_bounds",
            Reason::SeqAhead => "seq_ahead",
            Reason::ClockOff => "clock_off",
            Reason::ObstacleOutOfScale => "obstacle_out_of_scale",
            Reason::ObstacleDuplicate => "obstacle_duplicate",
            Reason::ObstacleCap => "obstacle_cap",
            Reason::ObstacleRate => "obstacle_rate",
        }
    }
}

/// Reports and obstacles refused, per reason (in the execution report).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Refusals {
    /// Fixes farther from the last accepted one than the vehicle could have moved.
    pub jump: u64,
    /// Fixes outside the scenario's bounds.
    pub out_of_bounds: u64,
    /// Reports numbered far ahead of the vehicle's last accepted one.
    pub seq_ahead: u64,
    /// Reports whose mission time is far from the coordinator's clock.
    pub clock_off: u64,
    /// Obstacles larger than the navigation space or far outside it.
    pub obstacle_out_of_scale: u64,
    /// Obstacles whose id was already known.
    pub obstacle_duplicate: u64,
    /// Obstacles past the per-mission cap.
    pub obstacle_cap: u64,
    /// Obstacles over the rate limit.
    pub obstacle_rate: u64,
}

impl Refusals {
    /// Counts one refusal.
    pub fn count(&mut self, r: Reason) {
        let n = match r {
            Reason::Jump => &mut self.jump,
            Reason::OutOfBounds => &mut self.out_of_bounds,
            Reason::SeqAhead => &mut self.seq_ahead,
            Reason::ClockOff => &mut self.clock_off,
            Reason::ObstacleOutOfScale => &mut self.obstacle_out_of_scale,
            Reason::ObstacleDuplicate => &mut self.obstacle_duplicate,
            Reason::ObstacleCap => &mut self.obstacle_cap,
            Reason::ObstacleRate => &mut self.obstacle_rate,
        };
        *n += 1;
    }

    /// All refusals.
    pub fn total(&self) -> u64 {
        self.jump
            + self.out_of_bounds
            + self.seq_ahead
            + self.clock_off
            + self.obstacle_out_of_scale
            + self.obstacle_duplicate
            + self.obstacle_cap
            + self.obstacle_rate
    }
}

/// What a vehicle's next fix is held against.
#[derive(Debug, Clone, Copy)]
pub struct FixLimits {
    /// Top speed over the ground, m/s: the vehicle's own times [`JUMP_SPEED_FACTOR`], plus the
    /// surface current.
    pub ground_speed_mps: f64,
    /// Telemetry reports per wall second.
    pub telemetry_hz: f64,
    /// Mission seconds per wall second.
    pub time_scale: f64,
    /// Metres a fix may lie outside the bounds.
    pub bounds_margin_m: f64,
}

impl FixLimits {
    /// The limits of vehicle `i` of `scenario`; `deviation_m` widens the bounds' margin.
    pub fn of(scenario: &Scenario, i: usize, hz: f64, scale: f64, deviation_m: f64) -> FixLimits {
        let own = scenario.vehicles.get(i).map_or(0.0, |v| v.speed_max_mps);
        FixLimits {
            ground_speed_mps: JUMP_SPEED_FACTOR * own + surface_current_mps(scenario),
            telemetry_hz: hz,
            time_scale: scale,
            bounds_margin_m: BOUNDS_MARGIN_M + deviation_m.max(0.0),
        }
    }
}

/// Speed of a depth-decay current at the surface (its fastest), m/s; 0 otherwise (a grid's
/// currents are covered by [`JUMP_SPEED_FACTOR`]).
fn surface_current_mps(s: &Scenario) -> f64 {
    match &s.currents {
        Some(c) if c.model == CurrentModel::DepthDecay => c
            .surface_velocity_mps
            .map_or(0.0, |[u, v]| u.hypot(v))
            .max(0.0),
        _ => 0.0,
    }
}

/// The vehicle's last accepted report, as far as the checks need it.
#[derive(Debug, Clone, Copy)]
pub struct LastFix {
    /// Where, metres.
    pub position: [f64; 3],
    /// Its mission time, seconds.
    pub t_s: f64,
    /// Its number.
    pub seq: u64,
    /// Wall seconds since it came.
    pub wall_since_s: f64,
}

/// Whether report `t` can be true, or the reason it cannot and why in words. `last` is the
/// vehicle's last accepted report (`None` before the first: then only the bounds, the clock
/// and the number against `wall_since_start_s` are checked); `mission_now_s` is the
/// coordinator's mission time when the report came.
pub fn check_fix(
    t: &Telemetry,
    last: Option<LastFix>,
    lim: &FixLimits,
    bounds: &Bounds,
    mission_now_s: f64,
    wall_since_start_s: f64,
) -> Result<(), (Reason, String)> {
    let off = (t.state.t_s - mission_now_s).abs();
    let allowed = CLOCK_OFFSET_WALL_S * lim.time_scale;
    if off > allowed {
        return Err((
            Reason::ClockOff,
            format!(
                "its mission time {:.1} s is {off:.1} s from the coordinator's {mission_now_s:.1} s (allowed {allowed:.1} s)",
                t.state.t_s
            ),
        ));
    }
    let outside = distance_outside(t.state.position, bounds);
    if outside > lim.bounds_margin_m {
        return Err((
            Reason::OutOfBounds,
            format!(
                "its fix {:?} is {outside:.1} m outside the scenario's bounds (allowed {:.1} m)",
                t.state.position, lim.bounds_margin_m
            ),
        ));
    }
    let (base, wall) = last.map_or((0, wall_since_start_s), |l| (l.seq, l.wall_since_s));
    let ahead = SEQ_SLACK.saturating_add((2.0 * lim.telemetry_hz * wall.max(0.0)).ceil() as u64);
    if t.seq > base.saturating_add(ahead) {
        return Err((
            Reason::SeqAhead,
            format!(
                "its number {} is more than {ahead} past {base} after {wall:.1} s",
                t.seq
            ),
        ));
    }
    if let Some(l) = last {
        let dt = (t.state.t_s - l.t_s).abs();
        let moved = (Vec3::from(t.state.position) - Vec3::from(l.position)).norm();
        let reach = lim.ground_speed_mps * dt + JUMP_NOISE_M;
        if moved > reach {
            return Err((
                Reason::Jump,
                format!(
                    "its fix is {moved:.1} m from the last one {dt:.1} s before (it can move {reach:.1} m)"
                ),
            ));
        }
    }
    Ok(())
}

/// How far `p` lies outside `b`, metres (0 inside).
fn distance_outside(p: [f64; 3], b: &Bounds) -> f64 {
    (0..3)
        .map(|k| (b.min[k] - p[k]).max(p[k] - b.max[k]).max(0.0))
        .map(|d| d * d)
        .sum::<f64>()
        .sqrt()
}

/// Length of the bounds' diagonal, metres.
fn diagonal(b: &Bounds) -> f64 {
    (Vec3::from(b.max) - Vec3::from(b.min)).norm()
}

/// Whether published obstacle `o` fits the navigation space: its inflated radius no larger
/// than the bounds' diagonal, its centre no farther outside them than that diagonal. Either
/// beyond would block everything or nothing, at any cost to the replans.
pub fn check_obstacle_scale(o: &Obstacle, bounds: &Bounds) -> Result<(), OutOfScale> {
    let d = diagonal(bounds);
    let r = o.radius_m + o.inflation_m;
    if r > d {
        return Err(OutOfScale::TooLarge {
            id: o.id.clone(),
            radius_m: r,
            diagonal_m: d,
        });
    }
    let outside = distance_outside(o.centre, bounds);
    if outside > d {
        return Err(OutOfScale::TooFar {
            id: o.id.clone(),
            centre: o.centre,
            outside_m: outside,
            diagonal_m: d,
        });
    }
    Ok(())
}

/// A published obstacle out of all proportion to the navigation space.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OutOfScale {
    /// Larger than the bounds' diagonal: it would block everything.
    #[error("obstacle {id:?}: radius_m + inflation_m = {radius_m} is over the {diagonal_m:.0} m diagonal of the scenario's bounds")]
    TooLarge {
        /// The obstacle's id.
        id: String,
        /// Its inflated radius, metres.
        radius_m: f64,
        /// The bounds' diagonal, metres.
        diagonal_m: f64,
    },
    /// Farther outside the bounds than their diagonal: it would block nothing.
    #[error("obstacle {id:?}: centre {centre:?} is {outside_m:.0} m outside the scenario's bounds (over their {diagonal_m:.0} m diagonal)")]
    TooFar {
        /// The obstacle's id.
        id: String,
        /// Its centre.
        centre: [f64; 3],
        /// How far outside the bounds, metres.
        outside_m: f64,
        /// The bounds' diagonal, metres.
        diagonal_m: f64,
    },
}

/// A token bucket: `rate` tokens a second, at most `capacity` saved up.
#[derive(Debug, Clone)]
pub struct TokenBucket {
    rate: f64,
    capacity: f64,
    tokens: f64,
    at: Option<Instant>,
}

impl TokenBucket {
    /// A full bucket.
    pub fn new(rate: f64, capacity: f64) -> TokenBucket {
        TokenBucket {
            rate,
            capacity,
            tokens: capacity,
            at: None,
        }
    }

    /// Takes a token at `now` if there is one.
    pub fn take(&mut self, now: Instant) -> bool {
        if let Some(at) = self.at {
            let refill = now.saturating_duration_since(at).as_secs_f64() * self.rate;
            self.tokens = (self.tokens + refill).min(self.capacity);
        }
        self.at = Some(now);
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            true
        } else {
            false
        }
    }
}

/// The refusals of one execution: the counts, the obstacle rate limit, and when each event
/// was last told.
#[derive(Debug)]
pub struct Guard {
    /// Counts per reason.
    pub refusals: Refusals,
    /// Published obstacles: [`limits::MAX_OBSTACLES_PER_S`], with a second's worth saved up.
    pub obstacles: TokenBucket,
    /// Obstacles accepted from the obstacles key.
    pub published: usize,
    /// (vehicle or key, reason) → when its event was last told (wall).
    told: HashMap<(String, Reason), Instant>,
    /// When the execution started (wall): bounds a first report's number.
    pub started: Instant,
}

impl Default for Guard {
    fn default() -> Self {
        Guard {
            refusals: Refusals::default(),
            obstacles: TokenBucket::new(limits::MAX_OBSTACLES_PER_S, limits::MAX_OBSTACLES_PER_S),
            published: 0,
            told: HashMap::new(),
            started: Instant::now(),
        }
    }
}

impl Guard {
    /// Counts a refusal of `reason` for `who`; whether its event is due (none for `who` and
    /// `reason` in the last [`EVENT_EVERY`]).
    pub fn refuse(&mut self, who: &str, reason: Reason, now: Instant) -> bool {
        self.refusals.count(reason);
        let key = (who.to_string(), reason);
        let due = self
            .told
            .get(&key)
            .is_none_or(|&t| now.saturating_duration_since(t) >= EVENT_EVERY);
        if due {
            self.told.insert(key, now);
        }
        due
    }
}

#[cfg(test)]
mod tests;
