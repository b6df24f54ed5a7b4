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

/// Bytes of one line of a mission log read back by `replay`. The longest lines are the plan
/// records: every vehicle's timed waypoints, about 100 bytes each, so 256 vehicles of 1,000
/// waypoints write 26 MB; the start record holds the scenario (at most 4 MB).
pub const MAX_LOG_LINE_BYTES: usize = 64 << 20;

/// Bytes of an MCAP mission log read back by `replay` and `export` (every record is kept in
/// memory for the replay). A report is about 400 bytes, so a 45-minute mission of 100 vehicles
/// reporting at 10 Hz logs about 1.1 GB; one MCAP message is one record, so it has
/// [`MAX_LOG_LINE_BYTES`] as its own bound.
pub const MAX_LOG_BYTES: u64 = 4 << 30;

/// Bytes of a `plan.json` read back by `export`: the trajectories take about 100 bytes per
/// waypoint, so 256 vehicles of 1,000 waypoints are 26 MB, with room for the figures.
pub const MAX_PLAN_BYTES: u64 = 64 << 20;

/// Obstacles published on a running mission's obstacles key (each one can cost a replan of
/// every vehicle); past it, further ones are dropped and counted.
pub const MAX_PUBLISHED_OBSTACLES: usize = 256;

/// Obstacles a client may publish per wall second on one mission; past it, dropped and counted.
pub const MAX_OBSTACLES_PER_S: f64 = 5.0;

/// Inner waypoints (control points) per vehicle: Zhi & Zuo's Table 4 uses 30, the crawler scenarios
/// 3–4; at 1,000 a fleet chromosome of 256 vehicles is a million genes per particle.
pub const MAX_WAYPOINTS: usize = 1_000;

/// Points a path is sampled at (`crawler.samples`, `energy.path_points`): the shipped scenarios
/// use 100–500; 100,000 samples a 100 km path every metre.
pub const MAX_PATH_SAMPLES: usize = 100_000;

/// Obstacles, hazards and terrain features (mountains, peaks, pits) listed in one scenario: the
/// shipped ones list under 20. Every path sample is checked against every one of them.
pub const MAX_OBSTACLES: usize = 1_000;

/// Cells of one map (a coverage terrain, a seabed grid, the nodes of a current grid): 2,000 ×
/// 2,000, sixteen times the 500 × 500 cells of CPP-DSMV's 1 km map at 2 m. A map keeps about
/// 40 bytes per cell (height, slope, masks, distance field): 160 MB at the bound.
pub const MAX_MAP_CELLS: usize = 4_000_000;

/// Bytes of a data file a scenario names (seabed grid, current grid, coverage heightmap): a
/// 2,000 × 2,000 ASCII grid at about 10 bytes per height is 40 MB.
pub const MAX_DATA_FILE_BYTES: u64 = 64 << 20;

/// Threads of one planner (`optimizer.threads`): more than the cores of any machine we plan on.
pub const MAX_THREADS: usize = 256;

/// Through-the-water and over-ground speeds, m/s. The slowest shipped vehicle moves at
/// 0.2 m/s; 0.01 m/s (36 m an hour) is below any vehicle's steerage way and makes every leg
/// last days. The fastest AUVs cruise near 5 m/s; 20 m/s (39 knots) is beyond any of them.
pub const SPEED_MPS: std::ops::RangeInclusive<f64> = 0.01..=20.0;

/// Largest current speed at the surface, m/s: the strongest tidal races run near 5 m/s.
pub const MAX_CURRENT_MPS: f64 = 20.0;

/// Largest extent of the scenario's box along any axis, metres: a long-range AUV covers a few
/// hundred kilometres on one charge; 1,000 km keeps every coordinate well inside f64's exact
/// range for the metre-scale checks.
pub const MAX_EXTENT_M: f64 = 1_000_000.0;

/// Longest mission time, seconds: the shipped coverage missions need 2 × 10^5 s (55 h); 30
/// days is beyond any battery vehicle's endurance and any tethered crawler's shift.
pub const MAX_MISSION_TIME_S: f64 = 30.0 * 86_400.0;

/// Smallest spacing of checks along a path, metres (`coverage.planner.check_step_m`,
/// `rollback_step_m`): a centimetre is far below the 2 m map cell the checks read; below it
/// the check count, not the terrain, decides the run time.
pub const MIN_CHECK_STEP_M: f64 = 0.01;

/// Path samples one coverage plan may check at its `check_step_m` (the area divided by the row
/// spacing, over the step): the paper's 1 km² map at 10 m rows and 0.5 m steps needs 2 × 10^5;
/// 10^7 is one centimetre steps on the same map.
pub const MAX_COVERAGE_CHECKS: f64 = 1e7;

/// Widest crawler, metres: deep-sea nodule collectors are 4–12 m wide (CPP-DSMV's is 8 m);
/// 50 m is no vehicle that drives on the seabed.
pub const MAX_VEHICLE_WIDTH_M: f64 = 50.0;

/// Hybrid A* expansions of one coverage plan (`coverage.planner.transit_budget`, and each
/// transit's `transit_expansions`): the default 300,000 is about a second; 10^8 is minutes.
pub const MAX_SEARCH_EXPANSIONS: usize = 100_000_000;

/// The text of the file at `path`, refused with [`std::io::ErrorKind::FileTooLarge`] past
/// `limit` bytes (read through a `take`, so a device or a pipe without end stops there too).
pub fn read_at_most(path: &std::path::Path, limit: u64) -> std::io::Result<String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(limit + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(std::io::Error::new(
            std::io::ErrorKind::FileTooLarge,
            format!("larger than the limit of {limit} bytes"),
        ));
    }
    String::from_utf8(bytes)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e.utf8_error()))
}
