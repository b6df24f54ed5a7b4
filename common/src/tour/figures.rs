//! What `plan.json` reports about an inspection tour (Hu et al. 2023, Table 6 measures).

use serde::{Deserialize, Serialize};

/// One vehicle's tour, as written into `plan.json` (`vehicles[].tour`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TourFigures {
    /// Visiting order: inspection point labels `<cage id>.<1|2>` (1: the first point, 2: its
    /// mirror through the cage's centre).
    pub order: Vec<String>,
    /// Each visited point's position, in visiting order, metres.
    pub points: Vec<[f64; 3]>,
    /// Length of the flown tour, metres.
    pub tour_length_m: f64,
    /// Length of the same visiting order with straight legs, metres.
    pub straight_tour_length_m: f64,
    /// Path growth: flown minus straight, metres (Table 6's "path growth length").
    pub growth_m: f64,
    /// Growth over the straight tour (Table 6's "growth rate").
    pub growth_rate: f64,
    /// Leg lengths: base → first point, …, last point → base, metres.
    pub leg_lengths_m: Vec<f64>,
    /// Segment–cage intersections against the cages inflated by their clearance (0: safe).
    pub cage_intersections: usize,
}
