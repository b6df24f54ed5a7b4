//! Why `serve` refuses a submission: the checks' ([`Refusal`]) and the queue's ([`QueueError`])
//! reasons. Their text is the receipt's `error`, so it never quotes a file or says whether a
//! path exists.

use shoal_common::limits;

/// Why a submission was refused; the text is what the client reads in its receipt, so no
/// variant quotes a file or says whether a path exists.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Refusal {
    /// Over [`limits::MAX_SUBMISSION_BYTES`], refused before it is decoded.
    #[error("submission: {0} bytes is over the limit {max}", max = limits::MAX_SUBMISSION_BYTES)]
    TooLarge(usize),
    /// Not the JSON of a [`Submission`].
    #[error("not a submission: {0}")]
    Malformed(String),
    /// Another version of the submission format.
    #[error("submission version {0} (this coordinator reads 1)")]
    Version(u16),
    /// A rate outside its range.
    #[error("submission: {field} = {value} is outside {min} to {max}")]
    OutOfRange {
        /// The submission's field.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The range's start.
        min: f64,
        /// The range's end.
        max: f64,
    },
    /// A count over its limit.
    #[error("submission: {field} = {value} is over the limit {max}")]
    OverLimit {
        /// The submission's field.
        field: &'static str,
        /// Its value.
        value: u128,
        /// The limit.
        max: u128,
    },
    /// The scenario is not valid (its error names the submitted scenario, never a file's
    /// contents).
    #[error("{0}")]
    Scenario(String),
    /// Particles × populations × iterations × vehicles over [`limits::MAX_EVALUATIONS`].
    #[error(
        "submission: particles × populations × iterations × vehicles = {particles} × {populations} × {iterations} × {vehicles} = {product} is over the limit {max}",
        max = limits::MAX_EVALUATIONS
    )]
    Evaluations {
        /// Particles per population.
        particles: usize,
        /// Populations (at least 1).
        populations: usize,
        /// Iterations (the submission's, or the scenario's).
        iterations: usize,
        /// Vehicles.
        vehicles: usize,
        /// Their product.
        product: u128,
    },
    /// The mission would hold the queue longer than the operator allows.
    #[error(
        "submission: fleet.mission_time_s / time_scale = {mission_s} s / {scale} = {wall_s:.0} s of wall time is over this server's limit {max_wall_s:.0} s (--max-mission-hours)"
    )]
    WallTime {
        /// The scenario's mission time, seconds.
        mission_s: f64,
        /// The time scale.
        scale: f64,
        /// Their quotient, seconds.
        wall_s: f64,
        /// The operator's limit, seconds.
        max_wall_s: f64,
    },
    /// The mission id is not one path component and key chunk.
    #[error("submission: {0}")]
    MissionId(String),
    /// The queue did not take it.
    #[error(transparent)]
    Queue(#[from] QueueError),
    /// A check panicked (a bug): refused rather than bringing the server down.
    #[error("submission: could not be checked (the server logged why)")]
    Unchecked,
}

/// Why the queue did not take a mission.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum QueueError {
    /// The id is waiting, running, or already has a directory: its files would be overwritten.
    #[error(
        "submission: mission id {0:?} is already taken (queued, running or run before): choose another"
    )]
    Taken(String),
    /// [`limits::MAX_QUEUED_MISSIONS`] are waiting.
    #[error("queue full: {0} missions waiting (try again later)")]
    Full(usize),
}
