//! What the commands write and print: `plan.json` and `plan.svg` ([`out`], [`svg`]), progress,
//! plan and coverage summaries, the comparison tables ([`compare`], [`significance`],
//! [`crawler_table`]), a crawler plan's gap to its reference path ([`crawler_gap`]) and the
//! exports for maps and ground stations ([`geo_export`]).

pub mod compare;
pub mod crawler_gap;
pub mod crawler_stats;
pub mod crawler_table;
pub mod energy_gap;
pub mod geo_export;
pub mod out;
pub mod progress;
pub mod significance;
pub mod summary;
pub mod svg;
pub mod tour_gap;
