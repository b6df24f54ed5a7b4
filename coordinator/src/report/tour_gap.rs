//! How far an inspection tour is from its references: its visiting order against the shortest
//! order on the same straight-line distances (Held & Karp's exact programme, the optimum the
//! swap-operator PSO of Hu et al. 2023, §III-B searches for), and its legs against the straight
//! tour (Table 6's growth rate: what going round the cages adds).

use shoal_common::geometry::Vec3;
use shoal_common::tour::{distance_matrix, optimal_tour_length, TourPlan, MAX_EXACT_POINTS};

use super::crawler_gap::gap_percent;

/// The notice for vehicle `id`'s tour `t` from `base` through `points`.
pub fn notice(id: &str, base: Vec3, points: &[Vec3], t: &TourPlan) -> String {
    let nodes: Vec<Vec3> = std::iter::once(base)
        .chain(points.iter().copied())
        .collect();
    let legs = format!(
        "its legs round the cages make it {:.1} m, {:+.2} % over the straight tour (Hu et al. \
         2023, Table 6's growth rate)",
        t.tour_length_m,
        100.0 * t.growth_rate
    );
    match optimal_tour_length(&distance_matrix(&nodes)) {
        Some(best) => format!(
            "{id}: visiting order {:.1} m on straight legs, {:+.2} % against the shortest order \
             ({best:.1} m, Held & Karp's exact programme); {legs}",
            t.straight_tour_length_m,
            gap_percent(t.straight_tour_length_m, best.max(f64::MIN_POSITIVE)),
        ),
        None => format!(
            "{id}: visiting order {:.1} m on straight legs ({} points: over the {MAX_EXACT_POINTS} \
             an exact order is computed for); {legs}",
            t.straight_tour_length_m,
            points.len()
        ),
    }
}
