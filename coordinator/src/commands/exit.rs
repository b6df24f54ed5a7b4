//! The exit statuses every command shares (README).

/// Exit status of a plan with no violations.
pub const EXIT_FEASIBLE: i32 = 0;
/// Exit status of an error (bad input, I/O).
pub const EXIT_ERROR: i32 = 1;
/// Exit status of a plan produced with constraint violations.
pub const EXIT_VIOLATIONS: i32 = 3;
