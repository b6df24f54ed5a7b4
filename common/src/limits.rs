//! Upper (and a few lower) bounds on every size, count and rate a user or a network client can
//! set. A value outside them is refused with an error naming the file, the field and the value,
//! before anything is allocated: a scenario asking for 10^9 particles or a submission asking
//! for 10^12 iterations would otherwise abort the process on an allocation failure, and a time
//! scale of 10^-6 would hold a mission queue forever.
//!
//! Each bound is several times what any shipped scenario, benchmark or documented use needs;
//! the comment beside it says what sets it.

/// Vehicles in one fleet: 100-vehicle fleets are planned across machines; 256 leaves room
/// while keeping the pairwise coupling terms (n²/2 pairs) affordable.
pub const MAX_VEHICLES: usize = 256;

/// Follower populations of a multi-population swarm (the long benchmark runs use 40).
pub const MAX_POPULATIONS: usize = 256;

/// Particles in one population (the shipped scenarios use 10–100).
pub const MAX_PARTICLES: usize = 10_000;

/// Iterations of one swarm run (the long benchmark runs use 2,000).
pub const MAX_ITERATIONS: usize = 1_000_000;

/// Particles × populations × iterations × vehicles of one plan: about a day of evaluations on
/// one core at the measured 10^5 evaluations per second. Each factor may be within its own
/// bound and the product still absurd.
pub const MAX_EVALUATIONS: u128 = 10_000_000_000;

/// Mission seconds per wall second accepted by `run` and `serve` (tests run at up to 1,000;
/// under 0.1 a 45-minute mission takes over seven hours of wall time).
pub const TIME_SCALE: std::ops::RangeInclusive<f64> = 0.1..=10_000.0;

/// Telemetry reports per wall second and vehicle (MAVLink position streams run at 1–50 Hz).
pub const TELEMETRY_HZ: std::ops::RangeInclusive<f64> = 0.1..=50.0;

/// Bytes of one submission on `shoal/submit` (a shipped scenario is under 10 kB).
pub const MAX_SUBMISSION_BYTES: usize = 1 << 20;

/// Bytes of a scenario file read from disk (the largest shipped one is under 20 kB; seabed
/// grids live in files of their own).
pub const MAX_SCENARIO_BYTES: u64 = 4 << 20;

/// Missions `serve` holds waiting behind the running one; the next is refused with a reason.
pub const MAX_QUEUED_MISSIONS: usize = 8;

/// Bytes of one line of a mission log read back by `replay`.
pub const MAX_LOG_LINE_BYTES: usize = 1 << 20;

/// Obstacles published on a running mission's obstacles key (each one can cost a replan of
/// every vehicle); past it, further ones are dropped and counted.
pub const MAX_PUBLISHED_OBSTACLES: usize = 256;

/// Obstacles a client may publish per wall second on one mission; past it, dropped and counted.
pub const MAX_OBSTACLES_PER_S: f64 = 5.0;

/// Bytes of a data file (seabed grid, current field, coverage heightmap) a scenario submitted
/// to `serve` may name: a 2,000 × 2,000 height grid in ESRI ASCII, at about ten bytes a
/// node, is 40 MB; the shipped data files are under 1 MB.
pub const MAX_DATA_FILE_BYTES: u64 = 64 << 20;
