//! `plan.svg` and the coverage charts: [`plan`] draws a plan's views, with the seabed
//! ([`terrain`]), the current ([`current`]) and inspection points ([`tour`]) on the shared
//! [`chart`] helpers.

pub mod chart;
pub mod coverage;
pub mod current;
pub mod plan;
pub mod terrain;
pub mod tour;

pub use plan::render_plan;
